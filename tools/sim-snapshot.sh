#!/usr/bin/env bash
# plinth-sim's outputs on the bundled scenes, written to a folder so that two builds can be
# compared byte for byte (`diff -r BEFORE AFTER`): a change to the solver that should leave its
# results alone (docs/performance.md) must leave them equal. Every scene of sim/scenes and
# sim/scenes/eval under records at moderate and strong scales (Bagnoli 000 at 2.5 g: rocking
# with base stops, lift-off), an impulse and a sine pulse, at the default step (0.1 ms) and at
# 1 ms: each run's CSV time history (--out, every 1 ms), its events (--events) and its summary
# (stdout, stderr, exit status; the wall time left out).
#
# Usage: tools/sim-snapshot.sh OUT_DIR [--build DIR]
#   OUT_DIR    created (must not exist)
#   --build    the host build tree holding sim/plinth-sim (default build/release)
# Exit status: 0 written, 1 a tool is missing, 2 usage. A run that fails is an output too (its
# status and stderr are compared).
set -euo pipefail
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out="" build=$src/build/release
usage() { sed -n '/^# Usage:/,/^# Exit status/p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=${2:?}; shift 2 ;;
    -h | --help) usage ;;
    -*) usage ;;
    *) [ -z "$out" ] || usage; out=$1; shift ;;
  esac
done
[ -n "$out" ] || usage
[ ! -e "$out" ] || { echo "sim-snapshot: $out exists" >&2; exit 2; }
sim=$build/sim/plinth-sim
[ -x "$sim" ] || { echo "sim-snapshot: $sim not found: build it first" >&2; exit 1; }
mkdir -p "$out"
out=$(cd "$out" && pwd)
cd "$src"
records=sim/data/records

# NAME:ARGS of each input (ARGS with commas for spaces).
inputs=(
  "brienza-0.5g:--record,$records/irpinia1980_brienza_000.AT2,--pga,0.5g"
  "brienza-2.5g:--record,$records/irpinia1980_brienza_000.AT2,--pga,2.5g"
  "bagnoli-2.5g:--record,$records/irpinia1980_bagnoli_000.AT2,--pga,2.5g"
  "buia-1g:--record,$records/friuli1976-09-15_buia_000.AT2,--pga,1g"
  "elcentro-x2:--record,$records/elcentro1940_180.AT2,--scale,2"
  "impulse-0.4:--impulse,0.4,--t-end,10"
  "sine-0.6g-0.5s:--pulse,sine,--amplitude,0.6g,--period,0.5,--t-end,10"
)
runs=0
for scene in sim/scenes/*.toml sim/scenes/eval/*.toml; do
  scene_name=$(basename "${scene%.toml}")
  [[ "$scene" == */eval/* ]] && scene_name=eval-$scene_name
  for input in "${inputs[@]}"; do
    input_name=${input%%:*}
    IFS=, read -r -a args <<<"${input#*:}"
    for dt in 1e-4 1e-3; do
      name=$scene_name.$input_name.dt$dt
      rc=0
      "$sim" --scene "$scene" "${args[@]}" --dt "$dt" --out "$out/$name.csv" \
        --events "$out/$name.events.jsonl" >"$out/$name.txt" 2>"$out/$name.stderr" || rc=$?
      echo "$rc" >"$out/$name.rc"
      runs=$((runs + 1))
    done
  done
done
# The wall time of a run is not an output.
find "$out" -name '*.txt' -print0 | xargs -0 sed -i -E \
  's/ in [0-9.]+ s \([0-9]+x real time\)/ in W s (X real time)/'
echo "sim-snapshot: $runs runs written to $out"
