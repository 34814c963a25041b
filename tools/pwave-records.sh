#!/usr/bin/env bash
# The --record/--vertical pairs of a folder of three-component PEER records, for plinth-eval
# (docs/pwave.md): per station (the RSN<number>_ prefix), each horizontal component with the
# station's vertical one (the file whose name ends in UP, V, DWN or Z before .AT2; horizontals
# end in an azimuth or E, N, W, S).
#   plinth-eval run ... $(tools/pwave-records.sh sim/data/records/pwave)
# --first: only the first horizontal of each station (sorted by name).
set -euo pipefail
first=0
if [[ "${1:-}" == "--first" ]]; then first=1; shift; fi
folder="${1:?usage: pwave-records.sh [--first] FOLDER}"
[[ -d "$folder" ]] || { echo "pwave-records.sh: $folder: no such folder" >&2; exit 2; }
shopt -s nullglob
declare -A vertical
stations=()
for f in "$folder"/RSN*.AT2; do
  name=$(basename "$f")
  rsn=${name%%_*}
  if [[ "$name" =~ (UP|V|DWN|Z)\.AT2$ ]]; then
    [[ -n "${vertical[$rsn]:-}" ]] && { echo "pwave-records.sh: $rsn has two verticals" >&2; exit 2; }
    vertical[$rsn]="$f"
    stations+=("$rsn")
  fi
done
[[ ${#stations[@]} -gt 0 ]] || { echo "pwave-records.sh: $folder: no vertical component" >&2; exit 2; }
for rsn in "${stations[@]}"; do
  count=0
  for f in "$folder"/"$rsn"_*.AT2; do
    [[ "$f" == "${vertical[$rsn]}" ]] && continue
    printf -- '--record %s --vertical %s ' "$f" "${vertical[$rsn]}"
    count=$((count + 1))
    [[ $first == 1 ]] && break
  done
  [[ $count -gt 0 ]] || { echo "pwave-records.sh: $rsn has no horizontal" >&2; exit 2; }
done
echo
