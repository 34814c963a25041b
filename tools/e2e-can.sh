#!/usr/bin/env bash
# End-to-end test on a real CAN bus: plinth-replay sends a bundled record as sensor frames on
# vcan0 in a guest kernel (tools/vcan-bus.sh: user-mode Linux, else QEMU) while plinth-monitor
# listens and candump
# (can-utils, an independent client) logs the bus; then tests/integration/e2e_can.py checks
# what everyone saw and prints the figures. Four runs: the record (phase timeline against
# plinth-sim), the sensor node killed mid-record (fault within the timeout), garbage on the
# plinth identifiers (counted and rejected), a flood of unrelated traffic (no plinth frame
# lost); and a fifth, run alone by ctest's regional_can test: regional alerts from the bridge,
# hostile ones refused, a dangerous one raising warning until it expires. See docs/can-e2e.md.
#
# Usage: tools/e2e-can.sh [--build DIR] [--work DIR] [--speed S] [--keep] [--route R]
#                        [--if-chosen FILE] [--scenarios LIST] [--guest-timeout S]
#   --build DIR   the build tree with plinth-monitor, plinth-replay, plinth-sim (default
#                 build/release; or give them as PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_SIM)
#   --work DIR    keep every file of the run there (bus logs, JSON lines, reports); default a
#                 temporary folder, removed after a passing run
#   --keep        keep the temporary folder of a passing run too
#   --speed S     plinth-replay's speed factor, above 0 and at most 5 (default 2: 400 frames/s
#                 at 200 Hz; faster, the input ends before the monitor's start-up fault is over)
#   --route R     tools/vcan-bus.sh's route: auto (default: $PLINTH_VCAN_ROUTE, else auto), uml,
#                 qemu
#   --if-chosen FILE  run only if FILE (vcan-bus.sh --choose) names the route given with --route
#   --scenarios LIST  the runs, comma-separated, of main, stop, garbage, burst, regional
#                 (default main,stop,garbage,burst: ctest's can_e2e; regional: regional_can)
#   --guest-timeout S  the guest's time, boot included (default 420): runs the rig spoiled are
#                 run again while it lasts (5 times at most each), then the checks name the
#                 rig's losses
# Exit status: 0 all checks passed, 1 a check failed, 2 usage, 77 no route can start here or
# FILE names another route (ctest's SKIP_RETURN_CODE).
# shellcheck disable=SC2153,SC2317  # the guest's settings come from config.env; the scenario_*
#                                   # functions are called through attempt()
set -euo pipefail

# --- Guest: in the guest kernel, vcan0 up, cwd = the work folder ------------------------------
# Every process started in the guest costs tens of ms (exec through hostfs), so the waits below
# use bash builtins only: EPOCHREALTIME for the time, read -t for sleeping, reading the new
# lines of a log for watching the bus.
if [ "${1:-}" = "--guest" ]; then
  cd "$2"
  # shellcheck disable=SC1091
  . ./config.env
  fail() { echo "e2e-can (guest): $*" >&2; exit 1; }
  trap '[ $? -ne 77 ] || exit 1' EXIT  # never 77: vcan-bus's "cannot start", a skip
  # shellcheck source=tools/guest-waits.sh
  . "$(dirname "${BASH_SOURCE[0]}")/guest-waits.sh"  # nap, us, wait_line
  # The witness's receive buffer: candump -r asks SO_RCVBUFFORCE (the guest's init is root), so
  # net.core.rmem_max does not cap it; raised all the same for a witness without CAP_NET_ADMIN
  # (then SO_RCVBUF, capped by it). The kernel doubles the size asked for its bookkeeping.
  read -r rmem_max </proc/sys/net/core/rmem_max
  echo "rmem_max=$rmem_max" >guest.facts
  if ((rmem_max < WITNESS_RCVBUF)); then
    echo "$WITNESS_RCVBUF" >/proc/sys/net/core/rmem_max || true
    read -r rmem_max </proc/sys/net/core/rmem_max
    echo "rmem_max_raised=$rmem_max" >>guest.facts
  fi
  # candump logs the bus (through FILTER if given), with a receive buffer of WITNESS_RCVBUF and
  # its drop counter (-d: DROPCOUNT lines when its socket overflowed); it has bound its socket
  # once a marker frame (0x37F: a plinth identifier no message uses) shows up in its log. The
  # log goes to the guest's own memory (tmpfs), copied to the work folder when the run ends:
  # a write to the work folder goes through hostfs (or 9p), system calls of the host each, and
  # candump writes once per frame.
  bus_dir=$(mktemp -d /dev/shm/e2e-bus.XXXXXX)
  start_capture() {  # NAME [FILTER]
    local log=$bus_dir/$1.bus.log i
    : >"$log"  # now: a retried run's old log must not satisfy the waits below
    candump -L -d -r "$WITNESS_RCVBUF" "vcan0${2:+,$2}" >>"$log" 2>"$1.candump.err" &
    capture_pid=$!
    for ((i = 0; i < 100; i++)); do
      cansend vcan0 37F#E2
      wait_line "$log" '* 37F#E2' 5 && return 0
    done
    fail "candump did not start: $(cat "$1.candump.err")"
  }
  # The end marker (37F#E3) through candump's queue: once it is in the log, so is every frame
  # before it. Stopped at once, a witness behind with its writing lost what it had not written
  # (seen: 1000 and 1500 of 2451 sensor frames, host load 14).
  stop_capture() {  # NAME
    cansend vcan0 37F#E3
    wait_line "$bus_dir/$1.bus.log" '* 37F#E3' 3000 || echo "witness_unfinished=1" >>"$1.extra"
    kill -INT "$capture_pid"
    wait "$capture_pid" || true
    cp "$bus_dir/$1.bus.log" "$1.bus.log"
  }
  # plinth-monitor listens once its start-up AlarmEvent (fault: no data yet) is on the bus.
  start_monitor() {  # NAME [SCENE [ARG...]]
    local name=$1 scene=${2:-$SCENE}
    shift $(($# > 1 ? 2 : 1))
    "$MONITOR" --scene "$scene" --can vcan0 --rate "$RATE" --steps "$STEPS" \
      --startup-window "$STARTUP_WINDOW" --status-interval "$STATUS_INTERVAL" "$@" \
      >"$name.monitor.jsonl" 2>"$name.monitor.err" &
    monitor_pid=$!
    wait_line "$bus_dir/$name.bus.log" '* 330#*' 1000 ||
      fail "plinth-monitor did not start: $(cat "$name.monitor.err")"
  }
  stop_monitor() {  # NAME SIGNAL
    echo "stop_signal=SIG$2" >>"$1.extra"
    kill "-$2" "$monitor_pid" 2>/dev/null || true  # not if it crashed: wait says how
    local rc=0
    wait "$monitor_pid" || rc=$?
    echo "$rc" >"$1.monitor.rc"
  }
  replay() {  # NAME [ARG...]
    local name=$1 rc=0
    shift
    "$REPLAY" --record input.csv --can vcan0 --rate "$RATE" --speed "$run_speed" --report-json \
      "$@" >"$name.replay.json" 2>"$name.replay.err" || rc=$?
    echo "$rc" >"$name.replay.rc"
  }
  # plinth-replay sends RECORD in the background until it ends or stop_replay.
  start_replay() {  # NAME RECORD SPEED
    "$REPLAY" --record "$2" --can vcan0 --rate "$RATE" --speed "$3" --report-json \
      >"$1.replay.json" 2>"$1.replay.err" &
    replay_pid=$!
  }
  stop_replay() {  # NAME SIGNAL
    kill "-$2" "$replay_pid" 2>/dev/null || true
    local rc=0
    wait "$replay_pid" 2>/dev/null || rc=$?
    echo "$rc" >"$1.replay.rc"
  }
  # The monitor's level is back to normal after its start-up (the fault of "no data yet" is held
  # 2 s), at most until 1 s before the input ends.
  wait_normal() {  # NAME
    wait_line "$bus_dir/$1.bus.log" '* 330#40*' "$stop_wait_polls" ||
      echo "no_normal_level=1" >>"$1.extra"
  }
  # The guest's CPU over a stretch of a run: cpu_mark, then cpu_note NAME adds to NAME.extra the
  # share of it the CPU was idle (/proc/stat's ticks, which follow the wall clock in user-mode
  # Linux whether the host runs the guest or not). Below MIN_IDLE_PERCENT the guest could not
  # carry the monitor, candump and plinth-replay: the rig's, not the box's (rig_losses.awk).
  cpu_ticks() {
    local u n s i w q sq st
    read -r _ u n s i w q sq st _ </proc/stat
    ticks=$((u + n + s + i + w + q + sq + st))
    idle=$i
  }
  cpu_mark() { cpu_ticks; mark_ticks=$ticks; mark_idle=$idle; }
  cpu_note() {  # NAME
    cpu_ticks
    local all=$((ticks - mark_ticks)) percent
    percent=$(((idle - mark_idle) * 100 / (all > 0 ? all : 1)))
    echo "guest_idle_percent=$percent" >>"$1.extra"
    echo "idle_percent_$1$n=$percent" >>guest.facts  # every run's, for docs/can-e2e.md
  }
  lap() {  # NAME START_US
    us
    printf '%s=%d.%06d\n' "$1" $(((now - $2) / 1000000)) $(((now - $2) % 1000000)) >>guest.times
  }
  : >guest.times
  us
  run_started=$now
  # The guest's time: vcan-bus.sh's --timeout (GUEST_TIMEOUT_S, from the guest's boot: its
  # uptime) less GUEST_MARGIN_S for the power-off. No run starts that the longest run so far
  # could not finish in it: the checks then name the rig's losses, not a timeout.
  read -r uptime _ </proc/uptime
  deadline_us=$((run_started + (GUEST_TIMEOUT_S - GUEST_MARGIN_S - ${uptime%.*}) * 1000000))
  longest_us=0

  # Runs scenario_NAME until the rig carried it, MAX_ATTEMPTS times at most: a guest starved by
  # a loaded host (seen: plinth-replay 0.5 s late; 3 spoiled runs of 3 at load 20; candump's
  # socket overflowing at load 15) makes silences and losses that are the rig's, not the
  # monitor's. rig_losses.awk judges each run from its files (the witness's DROPCOUNT lines and
  # missing frames, the sensor's silences, plinth-replay's lateness, the bridge's gaps; the
  # checks run it again on the last run) and the reasons go to NAME.rig. The last run's files
  # stay; if the rig spoiled it too, the checks fail naming the rig's losses.
  # A starved guest gets a slower stream on its next run: the record at half plinth-replay's
  # speed (then a quarter), the waits that follow the stream stretched alike. The checks judge
  # the box's logic, not its throughput (monitor_load_host does), so a run is as good at any
  # speed; each run's speed goes to NAME.extra and the checks use it.
  slowdown=1
  set_slowdown() {  # FACTOR
    slowdown=$1
    run_speed=$(awk -v s="$SPEED" -v k="$1" 'BEGIN { printf "%g", s / k }')
    garbage_after=$(awk -v s="$GARBAGE_AFTER" -v k="$1" 'BEGIN { printf "%.3f", s * k }')
    stop_wait_polls=$((STOP_WAIT_POLLS * $1))
    # the stop case kills the sensor once the record is on: its lead-in lasts k times longer
    kill_after_normal=$(awk -v s="$KILL_AFTER_NORMAL" -v l="$LEAD_IN_WALL_S" -v k="$1" \
      'BEGIN { printf "%.3f", s + (k - 1) * l }')
  }
  set_slowdown 1
  attempt() {  # NAME
    local n reasons started
    : >"$1.rig"
    for ((n = 1; n <= MAX_ATTEMPTS; n++)); do
      us
      if ((now + longest_us > deadline_us)); then
        echo "$n: not run: the guest's time (${GUEST_TIMEOUT_S} s, boot included) was spent," \
          "and the longest run so far took $((longest_us / 1000000)) s" >>"$1.rig"
        return 0
      fi
      started=$now
      echo "speed=$run_speed" >"$1.extra"
      echo "$n: not finished: the guest's time (${GUEST_TIMEOUT_S} s, boot included) ran out" \
        "during this run" >"$1.running"
      "scenario_$1"
      : >"$1.running"
      lap "$1$n" "$started"
      us
      ((now - started <= longest_us)) || longest_us=$((now - started))
      echo "attempts=$n" >>"$1.extra"
      reasons=$(awk -f "$RIG_LOSSES_AWK" -v run="$1" -v report="$1.replay.json" \
        -v extra="$1.extra" -v timeout_us="$TIMEOUT_US" -v starved_late_us="$STARVED_LATE_US" \
        -v backlog_late_us="$BACKLOG_LATE_US" -v min_idle_percent="$MIN_IDLE_PERCENT" \
        -v gaps_us="${REGIONAL_GAPS_US:-}" "$1.bus.log") || reasons="rig_losses.awk failed"
      [ -n "$reasons" ] || return 0
      reasons=${reasons//$'\n'/; }
      echo "$n: $reasons" >>"$1.rig"
      echo "e2e-can (guest): $1, run $n: $reasons" >&2
      if [[ "$reasons" == *starved* ]] && ((slowdown < MAX_SLOWDOWN)); then
        set_slowdown $((slowdown * 2))
        echo "e2e-can (guest): the next runs at --speed $run_speed" >&2
      fi
    done
    return 0  # the checks say what went wrong
  }

  # 1. The record, clean bus: the monitor's timeline, every frame, latency, jitter. The sensor
  #    stops at the end of the input: the monitor times out (fault) before it is stopped. The
  #    timeline can only match plinth-sim's if no silence exceeded the monitor's 50 ms sensor
  #    timeout (that restarts the estimator, as it must): a run with one is the rig's, as one
  #    with plinth-replay 45 ms late or the guest's CPU not idle 10 % of the stream.
  scenario_main() {
    start_capture main
    start_monitor main
    cpu_mark
    replay main
    cpu_note main
    nap 0.2
    stop_monitor main INT
    stop_capture main
  }
  # The runs config.env's SCENARIOS names (e2e-can.sh --scenarios).
  wanted() { [[ " $SCENARIOS " == *" $1 "* ]]; }
  ! wanted main || attempt main

  # 2. The sensor node dies mid-record (SIGKILL: no goodbye), once the monitor's level is back
  #    to normal after its start-up (the fault of "no data yet" is held 2 s): the fault must
  #    come within the sensor timeout. Run again if the rig spoiled it (rig_losses.awk: the
  #    sensor silent for more than the timeout before it was killed, the guest's CPU not idle
  #    10 % of the stream, the witness's losses).
  scenario_stop() {
    start_capture stop
    start_monitor stop
    start_replay stop input.csv "$run_speed"
    cpu_mark
    wait_normal stop
    nap "$kill_after_normal"
    stop_replay stop KILL
    cpu_note stop
    nap 0.3
    stop_monitor stop TERM
    stop_capture stop
  }
  ! wanted stop || attempt stop

  # 3. The monitor stalls (SIGSTOP for 150 ms: the frames wait in its socket) while the sensor
  #    sends, then garbage on the plinth identifiers (garbage.in.log, sent by canplayer: wrong
  #    lengths, reserved bits, values outside the DBC's ranges, unknown plinth identifiers, and
  #    RTR and extended frames the kernel filter keeps from the monitor), and random data from
  #    cangen. Run again if plinth-replay was so late (300 ms) that its backlog could overflow
  #    the monitor's socket (278 frames with the kernel's default buffer), or the witness lost
  #    frames.
  scenario_garbage() {
    start_capture garbage
    start_monitor garbage
    replay garbage --t-end "$SHORT_T_END" &
    replay_pid=$!
    nap "$garbage_after"
    kill -STOP "$monitor_pid" 2>/dev/null || true
    nap 0.15
    kill -CONT "$monitor_pid" 2>/dev/null || true
    echo "stalled_s=0.15" >>garbage.extra
    canplayer -t -g 1 -I garbage.in.log &
    player=$!
    cangen vcan0 -I 301 -L 3 -D r -g 1 -n 30 &  # random 3-byte frames on the sensor's id
    gen1=$!
    cangen vcan0 -I 311 -L r -D r -g 1 -n 30 &  # random length and data, heartbeat id
    gen2=$!
    cangen vcan0 -I 30F -L r -D r -g 1 -n 30 &  # another node: counted, not used
    gen3=$!
    wait "$player" "$gen1" "$gen2" "$gen3" || true
    wait "$replay_pid" || true
    nap 0.2
    stop_monitor garbage INT
    stop_capture garbage
  }
  ! wanted garbage || attempt garbage

  # 4. A flood of unrelated traffic (ids outside 0x300-0x37F, as fast as the guest sends) for
  #    the whole replay: no plinth frame may be lost. candump logs the plinth frames only (it
  #    could not keep up with the flood, and must not drop what is checked).
  scenario_burst() {
    start_capture burst 300:C0000780
    start_monitor burst
    local stats=/sys/class/net/vcan0/statistics/tx_packets count
    read -r count <"$stats"
    us
    printf 'tx_before=%s\nflood_start_ns=%s000\n' "$count" "$now" >>burst.extra
    cangen vcan0 -g 0 -i -I 2FF -L 8 -D r &
    flood1=$!
    cangen vcan0 -g 0 -i -e -L r -D r &
    flood2=$!
    nap 0.1
    replay burst --t-end "$SHORT_T_END"
    kill -INT "$flood1" "$flood2" 2>/dev/null || true
    wait "$flood1" "$flood2" || true
    read -r count <"$stats"
    us
    printf 'tx_after=%s\nflood_stop_ns=%s000\n' "$count" "$now" >>burst.extra
    nap 0.2
    stop_monitor burst TERM
    stop_capture burst
  }
  ! wanted burst || attempt burst

  # 5. Regional alerts (tests/integration/e2e_can_regional.py, docs/regional.md): the monitor
  #    on a scene with a [fragility], quiet ground in real time (--speed 1: the alerts' times are
  #    the bus's), and once its level is normal, canplayer sends regional.in.log as timed there:
  #    hostile frames, then a dangerous alert (warning), its duplicate and older version, a
  #    harmless alert and its cancellation; the monitor runs until the dangerous alert has
  #    expired (REGIONAL_WAIT), the sensor is stopped first (its timeout ends the run, as in 1).
  #    Run again if the sensor fell silent before it was stopped (a starved guest's silence
  #    would hide the warning behind a fault), if the witness lost frames, or if the bridge's
  #    frames on the bus missed their gaps in regional.in.log by more than 50 ms (a stall could
  #    pull a pair's frames 100 ms apart, or push the late one's together).
  scenario_regional() {
    start_capture regional
    start_monitor regional "$REGIONAL_SCENE" --config "$REGIONAL_CONFIG"
    start_replay regional quiet.csv 1
    cpu_mark
    wait_normal regional
    nap 0.1
    canplayer -I regional.in.log || fail "canplayer could not send regional.in.log"
    nap "$REGIONAL_WAIT"
    stop_replay regional INT
    cpu_note regional
    nap 0.2
    stop_monitor regional INT
    stop_capture regional
  }
  ! wanted regional || attempt regional
  lap guest "$run_started"
  echo finished >guest.done
  exit 0
fi

# --- Host ---------------------------------------------------------------------------------------
me=e2e-can
if [ "${PLINTH_ASAN:-0}" = 1 ]; then  # ctest's entry in a PLINTH_SANITIZE build
  # ASan needs its shadow memory where user-mode Linux maps the guest's programs (as
  # socketcan_uml in tests/CMakeLists.txt); on the qemu route, ASan's slowdown under emulation
  # would be judged against real-time deadlines.
  echo "$me: skipped: the end-to-end runs are not made for ASan" >&2
  exit 77
fi
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build="$root/build/release"
work=""
speed=2
keep=0
scenarios=main,stop,garbage,burst
guest_timeout=420
guest_margin=20  # s of the guest's time kept for its power-off and vcan-bus.sh's bookkeeping
bus=()  # tools/vcan-bus.sh's --route, --if-chosen
usage() { sed -n '/^# Usage:/,/^# FILE names another/p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=${2:?}; shift 2 ;;
    --work) work=${2:?}; shift 2 ;;
    --speed) speed=${2:?}; shift 2 ;;
    --keep) keep=1; shift ;;
    --scenarios) scenarios=${2:?}; shift 2 ;;
    --guest-timeout) guest_timeout=${2:?}; shift 2 ;;
    --route | --if-chosen) bus+=("$1" "${2:?}"); shift 2 ;;
    -h | --help) usage ;;
    *) echo "$me: unknown argument $1" >&2; usage ;;
  esac
done
awk -v s="$speed" 'BEGIN { exit !(s + 0 > 0 && s + 0 <= 5) }' ||
  { echo "$me: --speed must be above 0 and at most 5, got '$speed'" >&2; exit 2; }
case "$guest_timeout" in
  '' | *[!0-9]*) echo "$me: --guest-timeout wants whole seconds, got '$guest_timeout'" >&2; exit 2 ;;
esac
((guest_timeout > 2 * guest_margin)) ||
  { echo "$me: --guest-timeout must be above $((2 * guest_margin)) s" >&2; exit 2; }
# Before the preparation: a route that can start here, and the one FILE names (vcan-bus.sh says
# why not: 77 skips; with CI=true and --if-chosen, 1 fails).
status=0
bash "$root/tools/vcan-bus.sh" "${bus[@]}" --which >/dev/null || status=$?
case "$status" in
  0) ;;
  77) exit 77 ;;
  125) exit 2 ;;
  *) exit 1 ;;
esac
monitor=${PLINTH_MONITOR:-$build/firmware/linux/plinth-monitor}
replay=${PLINTH_REPLAY:-$build/hal/replay/plinth-replay}
sim=${PLINTH_SIM:-$build/sim/plinth-sim}
for tool in "$monitor" "$replay" "$sim"; do
  [ -x "$tool" ] || { echo "$me: $tool not found: build it, or give --build DIR" >&2; exit 1; }
done
command -v python3 >/dev/null ||
  { echo "$me: python3 not found (tools/install-deps.sh)" >&2; exit 1; }
for tool in candump cansend cangen canplayer; do  # the guest runs the host's programs
  command -v "$tool" >/dev/null ||
    { echo "$me: $tool not found: install can-utils (tools/install-deps.sh)" >&2; exit 1; }
done
if [ -z "$work" ]; then
  work=$(mktemp -d /tmp/plinth-e2e-can.XXXXXX)  # /tmp: the guest sees it through hostfs
else
  mkdir -p "$work"
  work=$(cd "$work" && pwd)
  rm -f "$work"/*.log "$work"/*.jsonl "$work"/*.json "$work"/*.rc "$work"/*.err "$work"/*.extra \
    "$work"/*.rig "$work"/*.running "$work"/*.csv "$work"/guest.times "$work"/guest.facts \
    "$work"/guest.done "$work"/config.env
  keep=1
fi
case "$work" in
  /dev/shm/*) echo "$me: the guest cannot see /dev/shm: use another --work" >&2; exit 2 ;;
esac

python3 "$root/tests/integration/e2e_can.py" prepare --work "$work" \
  --record "$root/sim/data/records/irpinia1980_brienza_000.AT2" --scale 20 \
  --scene "$root/sim/scenes/paper-isolated.toml" --dbc "$root/hal/can_codec/plinth.dbc" \
  --monitor "$(realpath "$monitor")" --replay "$(realpath "$replay")" --sim "$(realpath "$sim")" \
  --speed "$speed" --scenarios "$scenarios" \
  --regional-scene "$root/sim/scenes/eval/ground-slender.toml"
printf 'GUEST_TIMEOUT_S=%s\nGUEST_MARGIN_S=%s\n' "$guest_timeout" "$guest_margin" \
  >>"$work/config.env"

started=$(date +%s%N)
status=0
# Two virtual CPUs on the qemu route: replay, monitor, candump and the floods run at once (the
# uml route has one).
bash "$root/tools/vcan-bus.sh" "${bus[@]}" --timeout "$guest_timeout" --cpus 2 -- \
  bash "$root/tools/e2e-can.sh" --guest "$work" || status=$?
if [ "$status" -eq 77 ]; then
  echo "$me: SKIPPED: no route can start here (above: why); the end-to-end test needs the" \
    "packages of one route: user-mode-linux, or qemu-system-x86, linux-image-amd64 and" \
    "busybox-static; and can-utils, kmod, iproute2 (tools/install-deps.sh)" >&2
  [ "$keep" -eq 1 ] || rm -rf "$work"
  exit 77
fi
# A guest whose time ran out (124): the checks name the run it was in, and those it never began,
# as the rig's (NAME.running, no guest.done).
if [ "$status" -ne 0 ] && [ "$status" -ne 124 ]; then
  echo "$me: the runs on the bus failed (status $status); files in $work" >&2
  exit 1
fi
echo "$me: bus runs took $(awk -v s="$started" -v e="$(date +%s%N)" \
  'BEGIN { printf "%.1f", (e - s) / 1e9 }') s (boot included)"
[ "$status" -eq 0 ] || echo "$me: the guest's $guest_timeout s ran out; the checks follow" >&2
status=0
python3 "$root/tests/integration/e2e_can.py" check --work "$work" || status=$?
if [ "$status" -ne 0 ] || [ ! -e "$work/guest.done" ]; then
  echo "$me: FAILED; the run's files are in $work" >&2
  exit 1
fi
[ "$keep" -eq 1 ] || rm -rf "$work"
exit 0
