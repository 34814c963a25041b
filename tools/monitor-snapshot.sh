#!/usr/bin/env bash
# The monitor's outputs on the bundled replays, written to a folder so that two builds can be
# compared byte for byte (`diff -r BEFORE AFTER`): a refactoring of the box must leave them
# equal. Every scene and record combination the tests and the README replay through
# plinth-monitor (tests/cli/test_plinth_monitor.sh, tools/quickstart.sh, the replay form of
# tools/e2e-can.sh's run, the Cortex-M images' cases): its JSON lines and the frames it sends
# (--frames-out), the event recorder's captures; plinth-eval's rows and report; with
# --network, the Modbus registers mbpoll reads (tests/integration/test_modbus.sh) and the MQTT
# messages a subscriber receives (tests/integration/test_mqtt.sh), their wall-clock fields
# (the heartbeat and uptime registers, the state's "time" and "t") left out; with --mcu, what the
# cross build's images send in QEMU (their cost and stack lines left out: those are measured,
# tools/cortex-m-costs.sh).
#
# Usage: tools/monitor-snapshot.sh OUT_DIR [--build DIR] [--mcu DIR] [--network]
#   OUT_DIR    created (must not exist)
#   --build    the host build tree (default build/release)
#   --mcu      a cortex-m4f build tree whose images to run (e.g. build/cortex-m4f)
#   --network  also the Modbus and MQTT outputs (mbpoll, mosquitto; about 30 s)
# Exit status: 0 written, 1 a run failed, 2 usage.
set -euo pipefail
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
out="" build=$src/build/release mcu="" network=0
usage() { sed -n '/^# Usage:/,/^# Exit status/p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --build) build=${2:?}; shift 2 ;;
    --mcu) mcu=${2:?}; shift 2 ;;
    --network) network=1; shift ;;
    -h | --help) usage ;;
    -*) usage ;;
    *) [ -z "$out" ] || usage; out=$1; shift ;;
  esac
done
[ -n "$out" ] || usage
[ ! -e "$out" ] || { echo "monitor-snapshot: $out exists" >&2; exit 2; }
monitor=$build/firmware/linux/plinth-monitor
evaluate=$build/sim/plinth-eval
for tool in "$monitor" "$evaluate"; do
  [ -x "$tool" ] || { echo "monitor-snapshot: $tool not found: build it first" >&2; exit 1; }
done
mkdir -p "$out/replays" "$out/captures"
out=$(cd "$out" && pwd)
tmp=$(mktemp -d)
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$tmp"' EXIT
cd "$src"
scenes=sim/scenes
records=sim/data/records
brienza=$records/irpinia1980_brienza_000.AT2
brienza_270=$records/irpinia1980_brienza_270.AT2
buia=$records/friuli1976-09-15_buia_000.AT2

# replay NAME ARG...: the JSON lines, stderr and exit status of plinth-monitor ARG..., then the
# same run's frames (--frames-out) and its JSON lines with them.
replay() {
  local name=$1 rc=0
  shift
  "$monitor" "$@" >"$out/replays/$name.jsonl" 2>"$out/replays/$name.stderr" || rc=$?
  echo "$rc" >"$out/replays/$name.rc"
  rc=0
  "$monitor" "$@" --frames-out "$out/replays/$name.frames.log" \
    >"$out/replays/$name.frames.jsonl" 2>/dev/null || rc=$?
  echo "$rc" >>"$out/replays/$name.rc"
}

# tests/cli/test_plinth_monitor.sh
replay isolated-brienza-x20 --scene $scenes/paper-isolated.toml --replay $brienza --scale 20 \
  --status-interval 0.5
replay two-axes-x10 --scene $scenes/paper-isolated.toml --scene-y $scenes/paper-eccentric.toml \
  --replay $brienza --replay-y $brienza_270 --scale 10 --status-interval 1
replay eccentric-brienza-x20 --scene $scenes/paper-eccentric.toml --replay $brienza --scale 20 \
  --status-interval 0.25
replay two-axes-x10-no-forecast --scene $scenes/paper-isolated.toml \
  --scene-y $scenes/paper-eccentric.toml --replay $brienza --replay-y $brienza_270 --scale 10 \
  --no-forecast
"$monitor" --scene $scenes/paper-isolated.toml --replay $brienza --scale 20 \
  --record-dir "$out/captures/isolated-brienza-x20" --pre-trigger 12.5 --post-trigger 2 \
  --no-events >"$out/replays/recorder.jsonl"
capture=$out/captures/isolated-brienza-x20/event-001.log
log_args=(--rate 344.8275862068966 --startup-window 1 --status-interval 1 --stuck-samples 0)
replay capture-log --scene $scenes/paper-isolated.toml --replay "$capture" "${log_args[@]}"
# The logs test_plinth_monitor.sh makes of the capture: another box's CollapseForecast frames,
# two ground sensors with a failover; and a plate sensor beside the ground one (the model's base
# acceleration against the ground's: a mismatch), a redundant ground sensor that steps away (a
# disagreement).
logs=tests/cli/monitor_logs.py
for case in forecast-frames failover plate step; do
  python3 $logs $case "$capture" "$tmp/$case.log"
done
replay forecast-frames-log --scene $scenes/paper-isolated.toml --replay "$tmp/forecast-frames.log" \
  "${log_args[@]}"
printf '[[sensor]]\nnode = 1\n\n[[sensor]]\nnode = 2\nrole = "ground"\n' >"$tmp/two.toml"
replay two-sensors-failover --scene $scenes/paper-isolated.toml --replay "$tmp/failover.log" \
  --config "$tmp/two.toml" "${log_args[@]}"
printf '[[sensor]]\nnode = 1\n\n[[sensor]]\nnode = 3\nrole = "plate"\n' >"$tmp/plate.toml"
replay plate-sensor --scene $scenes/paper-isolated.toml --replay "$tmp/plate.log" \
  --config "$tmp/plate.toml" "${log_args[@]}"
printf '[plate]\nraises_fault = true\n' >>"$tmp/plate.toml"
replay plate-sensor-raises-fault --scene $scenes/paper-isolated.toml --replay "$tmp/plate.log" \
  --config "$tmp/plate.toml" "${log_args[@]}"
replay disagreeing-ground-sensor --scene $scenes/paper-isolated.toml --replay "$tmp/step.log" \
  --config "$tmp/two.toml" "${log_args[@]}"
# tools/quickstart.sh, and the recorder's capture replayed as tools/plinth-event-plot does.
"$monitor" --scene $scenes/paper-eccentric.toml --replay $buia --scale 6.5 \
  --record-dir "$out/captures/quickstart" --trace "$out/replays/quickstart.trace" \
  >"$out/replays/quickstart.jsonl"
replay quickstart-capture --scene $scenes/paper-eccentric.toml \
  --replay "$out/captures/quickstart/event-001.log" --stuck-samples 0
# The Cortex-M images' cases (firmware/cortex_m/CMakeLists.txt), with the ensemble's.
replay eccentric-buia-x6.5 --scene $scenes/paper-eccentric.toml --replay $buia --scale 6.5
replay eccentric-buia-x6.5-1khz --scene $scenes/paper-eccentric.toml --replay $buia --scale 6.5 \
  --rate 1000
replay ground-elcentro-x2 --scene $scenes/non-isolated.toml --replay $records/elcentro1940_180.AT2 \
  --scale 2
replay ensemble-buia-x6.5 --scene $scenes/eval/isolated-stops.toml --replay $buia --scale 6.5
replay ensemble-buia-x6.5-no-forecast --scene $scenes/eval/isolated-stops.toml --replay $buia \
  --scale 6.5 --no-forecast
replay ensemble-two-axes --scene $scenes/eval/isolated.toml --scene-y $scenes/eval/ground-slender.toml \
  --replay $brienza --replay-y $brienza_270 --scale 8
# tools/e2e-can.sh's input and settings, replayed from its file (the bus run itself is paced by
# the wall clock).
python3 tests/integration/e2e_can.py prepare --work "$tmp/e2e" --record $brienza --scale 20 \
  --scene $scenes/paper-isolated.toml --dbc hal/can_codec/plinth.dbc --monitor "$monitor" \
  --replay none --sim none >/dev/null
replay e2e-can-input --scene $scenes/paper-isolated.toml --replay "$tmp/e2e/input.csv" --rate 200 \
  --steps 4 --startup-window 1 --status-interval 0.02
# Bad input ends with a fault.
printf '(1.000000) can0 301#0000000000000000\n' >"$tmp/one.log"
replay one-frame --scene $scenes/paper-isolated.toml --replay "$tmp/one.log"

# plinth-eval (tests/cli/test_plinth_eval.sh's small run) and its report.
mkdir -p "$out/eval"
eval_args=(--scene $scenes/eval/isolated.toml --scene $scenes/eval/ground-slender.toml
  --record $brienza --record $records/eval/RSN1605_DUZCE_DZC270.AT2 --pga-steps 4 --jobs 2
  --statues 2 --pga-from 0.3g --pga-to 1.5g)
"$evaluate" run "${eval_args[@]}" --out "$out/eval/runs.csv" >"$out/eval/run.txt"
"$evaluate" report "$out/eval/runs.csv" --json "$out/eval/report.json" >"$out/eval/report.txt"

# The Cortex-M images: their frames and events (not their measured costs).
if [ -n "$mcu" ]; then
  mkdir -p "$out/mcu"
  images=$mcu/firmware/cortex_m
  for name in $(cut -f 1 "$images/replay_cases.txt"); do
    timeout 600 qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none \
      -semihosting-config enable=on,target=native -icount shift=0 -kernel "$images/$name.elf" |
      grep -vE '^# (cost|step|stack) ' >"$out/mcu/$name.log"
  done
fi

if [ "$network" = 1 ]; then
  mkdir -p "$out/modbus" "$out/mqtt"
  free_port() {
    python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
  }
  wait_for() {  # FILE PATTERN SECONDS
    local i
    for ((i = 0; i < $3 * 10; i++)); do
      grep -qE "$2" "$1" 2>/dev/null && return 0
      sleep 0.1
    done
    echo "monitor-snapshot: no '$2' in $1 within $3 s" >&2
    return 1
  }
  # The input registers 0-38 but those that count with the wall clock (1 heartbeat, 12-13
  # uptime, 14-15 samples fed: the replay goes on), the files' 71-81 (the scenes' given and
  # digest, the box file's given; not its digest, 82-85: the file holds a free port), then the
  # discrete inputs (one per level), "input|discrete address value" (the git description,
  # registers 39-70, is the build's).
  registers() {
    local t
    for t in 3:input:0:39 3:input:71:11 1:discrete:0:5; do
      IFS=: read -r fn table first count <<<"$t"
      mbpoll -m tcp -t "$fn" -0 -r "$first" -c "$count" -1 -o 2 -p "$1" 127.0.0.1 2>/dev/null |
        sed -n "s/^\\[\\([0-9]*\\)\\]:[[:space:]]*\\([0-9]*\\).*/$table \\1 \\2/p"
    done | grep -vE '^input (1|12|13|14|15) '
  }
  # test_modbus.sh: after the overturn (a steady state), then the acknowledge coil; the lines
  # but the acknowledgement's times (the command comes at a wall-clock moment).
  port=$(free_port)
  printf '[modbus]\nlisten = "127.0.0.1:%s"\nwrites = true\n' "$port" >"$tmp/modbus.toml"
  "$monitor" --scene $scenes/paper-isolated.toml --replay $brienza --scale 20 --speed 2 \
    --no-events --config "$tmp/modbus.toml" >"$tmp/modbus.out" 2>"$tmp/modbus.err" &
  box=$!
  wait_for "$tmp/modbus.out" '"phase": "overturned"' 60
  sleep 0.5
  registers "$port" >"$out/modbus/registers-overturned.txt"
  mbpoll -m tcp -t 0 -0 -r 0 -1 -p "$port" 127.0.0.1 1 >/dev/null
  wait_for "$tmp/modbus.out" '"command": "acknowledge"' 10
  sleep 0.5
  registers "$port" >"$out/modbus/registers-acknowledged.txt"
  kill -INT "$box"
  wait "$box" || true
  python3 - "$tmp/modbus.out" >"$out/modbus/lines.jsonl" <<'PY'
import json, sys
for line in open(sys.argv[1]):
    d = json.loads(line)
    if d["type"] == "command" or (d["type"] == "alarm" and d["cause"] == "acknowledged"):
        d.pop("t", None)
        d.pop("time_ms", None)
        print(json.dumps(d))
    elif d["type"] == "alarm":
        print(line.rstrip("\n"))
PY
  # test_mqtt.sh's broker (plain, anonymous here): every event payload, and the retained state
  # at the end but its times.
  port=$(free_port)
  mkdir -p "$tmp/db"
  printf 'persistence false\nallow_anonymous true\nlistener %s 127.0.0.1\n' "$port" \
    >"$tmp/broker.conf"
  /usr/sbin/mosquitto -c "$tmp/broker.conf" >"$tmp/broker.log" 2>&1 &
  broker=$!
  for ((i = 0; i < 100; i++)); do
    mosquitto_pub -h 127.0.0.1 -p "$port" -t ping -m x 2>/dev/null && break
    sleep 0.1
  done
  mosquitto_sub -h 127.0.0.1 -p "$port" -q 1 -v -t plinth/snap/events >"$tmp/events.out" &
  watcher=$!
  sleep 1
  "$monitor" --scene $scenes/paper-isolated.toml --replay $brienza --scale 20 --speed 4 \
    --no-events --mqtt "127.0.0.1:$port" --mqtt-box-id snap >"$tmp/mqtt.out" 2>"$tmp/mqtt.err"
  sleep 1
  kill "$watcher"
  wait "$watcher" 2>/dev/null || true
  cp "$tmp/events.out" "$out/mqtt/events.txt"
  mosquitto_sub -h 127.0.0.1 -p "$port" -C 2 -W 5 -v -t plinth/snap/state \
    -t plinth/snap/availability 2>/dev/null | sort |
    python3 -c '
import json, sys
for line in sys.stdin:
    topic, payload = line.rstrip("\n").split(" ", 1)
    if topic.endswith("/state"):
        d = json.loads(payload)
        for key in ("time", "t", "heartbeat", "version"):
            d.pop(key, None)
        payload = json.dumps(d)
    print(topic, payload)' >"$out/mqtt/retained.txt"
  kill "$broker"
  wait "$broker" 2>/dev/null || true
  grep -v '"type": "status"' "$tmp/mqtt.out" | python3 -c '
import json, sys
for line in sys.stdin:
    d = json.loads(line)
    if d["type"] == "summary":
        d["mqtt"] = {k: v for k, v in d["mqtt"].items() if k.startswith("events")}
    print(json.dumps(d))' >"$out/mqtt/lines.jsonl"
fi
# Where this run's files were, the wall time and the build's version (the first status line's
# and each capture's "version") are not outputs.
find "$out" -type f \( -name '*.jsonl' -o -name '*.json' -o -name '*.txt' -o -name '*.stderr' \) -print0 |
  xargs -0 sed -i -e "s|$out|OUT|g" -e "s|$tmp|TMP|g" -e 's/wall time [0-9.]* s/wall time W s/' \
    -e 's/"version": "[^"]*"/"version": "V"/g'
echo "monitor-snapshot: written to $out ($(find "$out" -type f | wc -l) files)"
