#!/usr/bin/env bash
# plinth-commission live on a real SocketCAN bus (vcan0 in a guest kernel: tools/vcan-bus.sh):
# plinth-commission-fixture --can sends a site (one ground sensor) on the bus in real time while
# plinth-commission --can vcan0 prompts for the steps (rest, the sensor's +x side on the wedge,
# its +y side, the final rest); a driver plays the custodian: at each prompt it moves the site to
# the step (the fixture stands there until told to go on) and presses Enter. No step depends on
# the machine's speed. The check passes on the prompts' windows and writes its report, picture
# and the session's frames (commission-001.log). About 25 s in the guest, and its boot.
#
# Usage: commission_live.sh --route uml|qemu --if-chosen FILE --work DIR   (host: boots the guest)
#        commission_live.sh --guest DIR                                   (in the guest)
# Environment: PLINTH_COMMISSION, PLINTH_COMMISSION_FIXTURE (the binaries).
# Exit status: 0 passed, 1 failed, 77 skipped (no guest route here, or another route chosen).
set -u
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)

if [ "${1:-}" = "--guest" ]; then
  work=${2:?}
  cd "$work" || exit 1
  trap '[ $? -ne 77 ] || exit 1' EXIT  # never 77 from here: vcan-bus's "cannot start"
  # 100 Hz: a guest's system calls are slow, and the site and the check make several a frame.
  printf '[estimator]\nsample_rate_hz = 100.0\n[[sensor]]\nnode = 1\n' >box.toml
  rm -rf reports answers site
  mkfifo answers site
  # wait_for FILE PATTERN COUNT: until FILE has COUNT lines matching PATTERN (at most 120 s).
  wait_for() {
    for _ in $(seq 600); do
      [ "$(grep -c -- "$2" "$1" 2>/dev/null)" -ge "$3" ] && return 0
      sleep 0.2
    done
    echo "timed out waiting for '$2' in $1: $(tail -c 600 "$1")" >&2
    return 1
  }
  # The site: the session sent on vcan0, standing at each step until told to go on.
  "$PLINTH_COMMISSION_FIXTURE" --config box.toml --can vcan0 --short <site >site.txt 2>&1 &
  site=$!
  exec 4>site
  wait_for site.txt '^hold rest$' 1 || exit 1
  "$PLINTH_COMMISSION" --config box.toml --can vcan0 --record-dir reports --rest-s 3 --hold-s 3 \
    <answers >out.txt 2>err.txt &
  commission=$!
  exec 3>answers
  # The custodian: at each prompt the site goes to the step (the wedge under the sensor, ...),
  # then Enter once it stands there; a failed step is not done again (Enter: go on), so that the
  # report says what failed.
  ok=0
  failed=0
  for step in 1 2 3 4; do
    wait_for out.txt "^\[$step/4\]" 1 || { ok=1; break; }
    if [ "$step" -gt 1 ]; then
      echo >&4
      wait_for site.txt '^hold ' "$step" || { ok=1; break; }
    fi
    echo >&3
    wait_for out.txt 'recorded\.' "$step" || { ok=1; break; }
    for _ in $(seq 600); do
      grep -qE "^\[$((step + 1))/4\]|^commissioning (PASSED|FAILED)" out.txt && break
      if [ "$(grep -c '^This step failed' out.txt)" -gt "$failed" ]; then
        failed=$((failed + 1))
        echo >&3
      fi
      sleep 0.2
    done
  done
  wait "$commission"
  status=$?
  exec 3>&- 4>&-
  wait "$site"
  echo "plinth-commission exit $status; the site: $(tr '\n' ';' <site.txt)"
  cat out.txt err.txt
  # Frames lost in a starved guest are the rig's failure, not plinth-commission's (which says
  # so, as it must): exit 3, the host tries once more.
  if [ $status -eq 4 ] && ! grep '^  FAIL ' out.txt | grep -qvE 'samples lost|dropped frames'; then
    echo "the rig lost frames (the guest starved): $(grep '^  FAIL ' out.txt | head -1)"
    exit 3
  fi
  check() {
    if eval "$2"; then echo "ok - $1"; else echo "not ok - $1"; ok=1; fi
  }
  check "live on vcan0: exit 0, PASSED" "[ $status -eq 0 ] && grep -q '^commissioning PASSED' out.txt"
  check "the report: pass, the interface, 4 windows from the prompts" \
    "grep -q '^  \"result\": \"pass\",\$' reports/commission-001.json &&
     grep -q '\"interface\": \"vcan0\"' reports/commission-001.json &&
     [ \$(grep -c '\"from\": \"prompt\"' reports/commission-001.json) -eq 4 ]"
  check "the session's frames kept as commission-001.log" \
    "[ \$(grep -c ' 301#' reports/commission-001.log) -gt 1000 ]"
  if command -v gnuplot >/dev/null 2>&1; then
    check "its picture: commission-001.png" "[ -s reports/commission-001.png ]"
  fi
  exit $ok
fi

bus=()
work=""
while [ $# -gt 0 ]; do
  case "$1" in
    --route | --if-chosen) bus+=("$1" "${2:?}"); shift 2 ;;
    --work) work=${2:?}; shift 2 ;;
    *) echo "commission_live.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -n "$work" ] || { echo "commission_live.sh: --work DIR" >&2; exit 2; }
for bin in "${PLINTH_COMMISSION:-}" "${PLINTH_COMMISSION_FIXTURE:-}"; do
  [ -x "$bin" ] || { echo "PLINTH_COMMISSION and PLINTH_COMMISSION_FIXTURE: '$bin'" >&2; exit 2; }
done
rm -rf "$work"
mkdir -p "$work"
for attempt in 1 2; do
  status=0
  bash "$root/tools/vcan-bus.sh" "${bus[@]}" --timeout 240 -- \
    bash "$root/tests/integration/commission_live.sh" --guest "$work" || status=$?
  [ $status -eq 3 ] || exit $status
  echo "attempt $attempt: the guest lost frames; $([ $attempt -eq 1 ] && echo once more)"
done
exit 1
