#!/usr/bin/env bash
# The real candump losing frames on a real bus (a guest of tools/vcan-bus.sh), and what plinth
# makes of its log (docs/record-formats.md, "Frames a log lost"; issue 36):
#  1. candump -L -d with the kernel's smallest receive buffer (-r 4096: 11 frames) logs
#     plinth-replay's sensor frames (200 Hz, real time) and is stopped twice for 0.5 s: its log
#     gets DROPCOUNT lines. Checked: every frame plinth-replay sent is in the log or counted by a
#     DROPCOUNT line; then tests/cli/test_candump_drops.sh's checks of a real log on it
#     (plinth-monitor --replay and plinth-replay, --log-drops warn and refuse).
#  2. The witness's receive buffer of tools/e2e-can.sh: candump stopped while cangen sends
#     BURST frames, with the kernel's default buffer (frames dropped, DROPCOUNT) and with
#     candump -r WITNESS_RCVBUF (every frame kept). The guest's net.core.rmem_max is noted.
# --keep-log FILE copies the log of 1 there (how tests/data/candump/overflow.log was made).
#
# Usage: tests/integration/candump_overflow.sh [--work DIR] [--route R] [--if-chosen FILE]
#                                              [--keep-log FILE]
# Environment: PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_SIM (the binaries), PLINTH_SOURCE_DIR.
# Exit status: 0 passed, 1 failed, 77 no route can start here (vcan-bus.sh's; a ctest skip).
# shellcheck disable=SC2153  # REPLAY, RECORD, SOURCE_DIR, WITNESS_RCVBUF: the host's guest.env
set -euo pipefail

BURST=2000          # frames sent while the witness is stopped (the default buffer keeps 278)
DROP_RCVBUF=4096    # candump -r for part 1: the kernel's least (SOCK_MIN_RCVBUF), 11 frames
STOP_S=0.5          # each stop of candump in part 1: 100 frames at 200 Hz

# --- Guest ----------------------------------------------------------------------------------
if [ "${1:-}" = "--guest" ]; then
  cd "$2"
  # shellcheck disable=SC1091  # written by the host part
  . ./guest.env
  fail() { echo "candump-overflow (guest): $*" >&2; exit 1; }
  trap '[ $? -ne 77 ] || exit 1' EXIT  # never 77: vcan-bus's "cannot start", a skip
  # shellcheck source=tools/guest-waits.sh
  . "$SOURCE_DIR/tools/guest-waits.sh"
  # Sends FRAME until candump logged it in LOG: its socket is bound, or what was queued before
  # FRAME has been read.
  marker() {  # LOG FRAME
    local i
    for ((i = 0; i < 100; i++)); do
      cansend vcan0 "$2"
      wait_line "$1" "* $2" 10 && return 0
    done
    fail "candump did not log $2 in $1: $(cat "$1.err" 2>/dev/null)"
  }
  read -r rmem_max </proc/sys/net/core/rmem_max
  read -r rmem_default </proc/sys/net/core/rmem_default
  printf 'rmem_max=%s\nrmem_default=%s\n' "$rmem_max" "$rmem_default" >guest.facts

  # 1. DROPCOUNT lines from a stopped candump.
  candump -L -d -r "$DROP_RCVBUF" vcan0 >overflow.log 2>overflow.log.err &
  dump=$!
  marker overflow.log 123#01
  "$REPLAY" --record "$RECORD" --can vcan0 --rate 200 --speed 1 --t-end 3 --report-json \
    >overflow.replay.json 2>overflow.replay.err &
  replay=$!
  wait_line overflow.log '* 301#*' 3000 ||
    fail "plinth-replay sent nothing: $(cat overflow.replay.err)"
  for _ in 1 2; do
    kill -STOP "$dump"
    nap "$STOP_S"
    kill -CONT "$dump"
    nap 0.5
  done
  wait "$replay" || fail "plinth-replay failed: $(cat overflow.replay.err)"
  marker overflow.log 123#02  # a frame after the last loss: candump reports it with that frame
  kill -INT "$dump"
  wait "$dump" || true

  # 2. The witness's buffer, the kernel's default and WITNESS_RCVBUF.
  for buffer in default witness; do
    options=()
    [ "$buffer" = default ] || options=(-r "$WITNESS_RCVBUF")
    candump -L -d "${options[@]}" vcan0 >"buffer-$buffer.log" 2>"buffer-$buffer.log.err" &
    dump=$!
    marker "buffer-$buffer.log" 123#03
    kill -STOP "$dump"
    read -r before </sys/class/net/vcan0/statistics/tx_packets
    cangen vcan0 -I 2AA -L 8 -D i -g 0 -n "$BURST" -i
    read -r after </sys/class/net/vcan0/statistics/tx_packets
    kill -CONT "$dump"
    marker "buffer-$buffer.log" 123#04
    kill -INT "$dump"
    wait "$dump" || true
    echo "${buffer}_sent=$((after - before))" >>guest.facts
  done
  exit 0
fi

# --- Host -----------------------------------------------------------------------------------
me=candump-overflow
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
work=""
keep_log=""
bus=()
while [ $# -gt 0 ]; do
  case "$1" in
    --work) work=${2:?}; shift 2 ;;
    --keep-log) keep_log=${2:?}; shift 2 ;;
    --route | --if-chosen) bus+=("$1" "${2:?}"); shift 2 ;;
    *) echo "$me: unknown argument $1 (see the usage at the top of $0)" >&2; exit 2 ;;
  esac
done
for tool in "${PLINTH_MONITOR:-}" "${PLINTH_REPLAY:-}" "${PLINTH_SIM:-}"; do
  [ -x "$tool" ] ||
    { echo "$me: PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_SIM must be set" >&2; exit 2; }
done
status=0
bash "$root/tools/vcan-bus.sh" "${bus[@]}" --which >/dev/null || status=$?
case "$status" in 0) ;; 77) exit 77 ;; *) exit 1 ;; esac
for tool in candump cansend cangen; do
  command -v "$tool" >/dev/null || { echo "$me: $tool not found: install can-utils" >&2; exit 1; }
done
if [ -z "$work" ]; then
  work=$(mktemp -d /tmp/plinth-candump-overflow.XXXXXX)  # /tmp: the guest sees it
  trap 'rm -rf "$work"' EXIT
else
  mkdir -p "$work"
  work=$(cd "$work" && pwd)
  rm -f "$work"/*.log "$work"/*.err "$work"/*.json "$work"/guest.*
fi
witness_rcvbuf=$(cd "$root/tests/integration" &&
  python3 -c 'import e2e_can; print(e2e_can.WITNESS_RCVBUF)')
{
  printf 'REPLAY=%q\n' "$(realpath "$PLINTH_REPLAY")"
  printf 'RECORD=%q\n' "$root/sim/data/records/irpinia1980_brienza_000.AT2"
  printf 'SOURCE_DIR=%q\n' "$root"
  printf 'DROP_RCVBUF=%q\nSTOP_S=%q\nBURST=%q\n' "$DROP_RCVBUF" "$STOP_S" "$BURST"
  printf 'WITNESS_RCVBUF=%q\n' "$witness_rcvbuf"
} >"$work/guest.env"
status=0
bash "$root/tools/vcan-bus.sh" "${bus[@]}" --timeout 200 -- \
  bash "$root/tests/integration/candump_overflow.sh" --guest "$work" || status=$?
[ "$status" -ne 77 ] || exit 77
if [ "$status" -ne 0 ]; then
  echo "$me: the guest's runs failed (status $status); files in $work" >&2
  trap - EXIT
  exit 1
fi
[ -z "$keep_log" ] || cp "$work/overflow.log" "$keep_log"

# shellcheck source=tests/cli/checks.sh
source "$root/tests/cli/checks.sh"
# frames LOG PATTERN: the frame lines of LOG whose frame matches PATTERN (ERE).
frames() { grep -cE "^\([0-9.]+\) vcan0 $2\$" "$1" || true; }
# dropped LOG: the frames LOG's DROPCOUNT lines say were lost.
dropped() {
  awk '/^DROPCOUNT: dropped [0-9]+ CAN frames? on / { n += $3 } END { print n + 0 }' "$1"
}
# fact KEY: from guest.facts.
fact() { sed -n "s/^$1=//p" "$work/guest.facts"; }

log=$work/overflow.log
report=$(tail -n 1 "$work/overflow.replay.json")
sent=$(python3 -c 'import json, sys; r = json.loads(sys.argv[1])
print(r["acceleration_frames"] + r["heartbeat_frames"])' "$report")
logged=$(frames "$log" '3[01]1#[0-9A-F]{16}')
lost=$(dropped "$log")
reports=$(grep -c '^DROPCOUNT: ' "$log" || true)
check "candump wrote DROPCOUNT lines when stopped ($reports lines, $lost frames lost)" \
  "$((reports > 0 ? 0 : 1))" "$(head -c 300 "$log.err")"
check "every frame plinth-replay sent is logged or counted lost: $logged + $lost = $sent" \
  "$((logged + lost == sent ? 0 : 1))"
status=0
PLINTH_SOURCE_DIR=$root bash "$root/tests/cli/test_candump_drops.sh" --real-log "$log" || status=$?
check "tests/cli/test_candump_drops.sh --real-log on the live log" "$status"

for buffer in default witness; do
  blog=$work/buffer-$buffer.log
  bsent=$(fact "${buffer}_sent")
  kept=$(frames "$blog" '2AA#[0-9A-F]{16}')
  blost=$(dropped "$blog")
  echo "# candump stopped while $bsent frames were sent, $buffer buffer: $kept kept, $blost dropped"
  check "$buffer buffer: every frame kept or counted lost ($kept + $blost = $bsent)" \
    "$((kept + blost == bsent ? 0 : 1))"
done
default_kept=$(frames "$work/buffer-default.log" '2AA#[0-9A-F]{16}')
witness_kept=$(frames "$work/buffer-witness.log" '2AA#[0-9A-F]{16}')
check "the kernel's default buffer overflowed: the witness needs more" \
  "$(($(dropped "$work/buffer-default.log") > 0 ? 0 : 1))"
check "candump -r $witness_rcvbuf kept all $witness_kept frames, more than the default's" \
  "$(($(dropped "$work/buffer-witness.log") == 0 && witness_kept > default_kept ? 0 : 1))" \
  "$(head -c 300 "$work/buffer-witness.log.err")"
echo "# guest: net.core.rmem_max $(fact rmem_max), rmem_default $(fact rmem_default)"
finish
