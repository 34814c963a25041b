#!/usr/bin/env bash
# Per-sample latency of plinth-monitor (a sample's arrival to its status being ready:
# plinth-monitor --latency) with Modbus pollers and an MQTT subscriber hammering the box,
# against none, in one run of this tool (docs/integration.md, "Latency"). Three replays of the
# same record at the same speed:
#   off     no Modbus server, no MQTT
#   idle    both on, nobody polls or subscribes
#   loaded  POLLERS mbpoll clients polling the 32 input registers every 11 ms, a mosquitto_sub
#           on the box's topics, the state published at every status (0.01 s)
# It starts its own mosquitto broker on a free loopback port and stops everything it started.
# Prints each run's median, 99th percentile and maximum, from arrival and from the deadline the
# replay's pacing set (--latency's latency_from_due: the wake-up's lateness included), then the
# ratios loaded/off and loaded/idle.
#   --policy   the monitor's scheduling (the others' stay as they are): other (default), nice
#              (nice -n -10, as Nice=-10 would), fifo (chrt --fifo --reset-on-fork 50: the loop's
#              thread alone, as the unit's CPUSchedulingPolicy=fifo, CPUSchedulingPriority=50,
#              CPUSchedulingResetOnFork=yes); docs/install.md, "Real-time scheduling"
#   --hogs N   N busy loops (one process each, at the default priority) for the whole run: other
#              work competing for the cores
#
# Usage: tools/latency-under-load.sh [--monitor PATH] [--speed FACTOR] [--pollers N]
#                                    [--policy other|nice|fifo] [--hogs N]
set -euo pipefail
cd "$(dirname "$0")/.."
MONITOR=build/release/firmware/linux/plinth-monitor
SPEED=2
POLLERS=4
POLICY=other
HOGS=0
while (($# > 0)); do
  case $1 in
    --monitor) MONITOR=$2; shift 2 ;;
    --speed) SPEED=$2; shift 2 ;;
    --pollers) POLLERS=$2; shift 2 ;;
    --policy) POLICY=$2; shift 2 ;;
    --hogs) HOGS=$2; shift 2 ;;
    *) echo "usage: $0 [--monitor PATH] [--speed FACTOR] [--pollers N] [--policy other|nice|fifo] [--hogs N]" >&2
       exit 2 ;;
  esac
done
case $POLICY in
  other) SCHED=() ;;
  nice) SCHED=(nice -n -10) ;;
  fifo) SCHED=(chrt --fifo --reset-on-fork 50) ;;
  *) echo "--policy: other, nice or fifo, got '$POLICY'" >&2; exit 2 ;;
esac
[[ -x "$MONITOR" ]] || { echo "$MONITOR: not an executable (build plinth-monitor)" >&2; exit 2; }
for tool in mbpoll mosquitto_sub python3; do
  command -v "$tool" >/dev/null || { echo "$tool is missing (tools/install-deps.sh)" >&2; exit 2; }
done
MOSQUITTO=$(command -v mosquitto || echo /usr/sbin/mosquitto)
[[ -x "$MOSQUITTO" ]] || { echo "mosquitto is missing (tools/install-deps.sh)" >&2; exit 2; }

WORK=$(mktemp -d)
PIDS=()
cleanup() {
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  rm -rf "$WORK"
}
trap cleanup EXIT
free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

for ((h = 0; h < HOGS; h++)); do
  bash -c 'while :; do :; done' &
  PIDS+=($!)
done

BROKER=$(free_port)
printf 'listener %s 127.0.0.1\nallow_anonymous true\npersistence false\n' "$BROKER" \
  >"$WORK/broker.conf"
"$MOSQUITTO" -c "$WORK/broker.conf" >"$WORK/broker.log" 2>&1 &
PIDS+=($!)
for ((i = 0; i < 100; i++)); do
  mosquitto_pub -h 127.0.0.1 -p "$BROKER" -t ping -m x 2>/dev/null && break
  sleep 0.1
done

RECORD=sim/data/records/irpinia1980_brienza_000.AT2
common=(--scene sim/scenes/paper-isolated.toml --replay "$RECORD" --scale 20 --speed "$SPEED"
        --status-interval 0.01 --no-events --latency)

# run NAME ARGS...: one replay; its summary's latency into $WORK/NAME.json.
run() {
  local name=$1
  shift
  "${SCHED[@]}" "$MONITOR" "${common[@]}" "$@" >"$WORK/$name.out" 2>"$WORK/$name.err" ||
    { echo "$name: plinth-monitor failed: $(head -c 300 "$WORK/$name.err")" >&2; exit 1; }
  tail -n 1 "$WORK/$name.out" >"$WORK/$name.json"
}

outputs() {
  MODBUS=$(free_port)
  printf '[mqtt]\nbroker = "127.0.0.1:%s"\nbox_id = "bench"\nstate_interval_s = 0.01\n' \
    "$BROKER" >"$WORK/box.toml"
  printf '[modbus]\nlisten = "127.0.0.1:%s"\n' "$MODBUS" >>"$WORK/box.toml"
}

run off
outputs
run idle --config "$WORK/box.toml"

outputs
"${SCHED[@]}" "$MONITOR" "${common[@]}" --config "$WORK/box.toml" >"$WORK/loaded.out" 2>"$WORK/loaded.err" &
BOX=$!
PIDS+=("$BOX")
mosquitto_sub -h 127.0.0.1 -p "$BROKER" -t 'plinth/bench/#' -v >"$WORK/sub.out" 2>&1 &
PIDS+=($!)
for ((i = 0; i < 100; i++)); do
  mbpoll -m tcp -t 3 -0 -r 0 -c 1 -1 -p "$MODBUS" 127.0.0.1 >/dev/null 2>&1 && break
  sleep 0.05
done
for ((p = 0; p < POLLERS; p++)); do
  mbpoll -m tcp -t 3 -0 -r 0 -c 32 -l 11 -p "$MODBUS" 127.0.0.1 >"$WORK/poller$p.out" 2>&1 &
  PIDS+=($!)
done
wait "$BOX" || { echo "loaded: plinth-monitor failed: $(head -c 300 "$WORK/loaded.err")" >&2; exit 1; }
tail -n 1 "$WORK/loaded.out" >"$WORK/loaded.json"
polls=$(cat "$WORK"/poller*.out | grep -c '^\[31\]:' || true)
messages=$(wc -l <"$WORK/sub.out")

python3 - "$WORK" "$polls" "$messages" "$SPEED" "$POLLERS" "$POLICY" "$HOGS" <<'PY'
import json, sys
work, polls, messages, speed, pollers = sys.argv[1:6]
runs = {n: json.load(open("%s/%s.json" % (work, n))) for n in ("off", "idle", "loaded")}
lat = {n: r["latency"] for n, r in runs.items()}
print("per-sample latency, arrival to status ready (plinth-monitor --latency), replay at "
      "--speed %s, policy %s, %s busy loops:" % (speed, sys.argv[6], sys.argv[7]))
print("%-7s %8s %10s %10s %10s" % ("run", "samples", "median_us", "p99_us", "max_us"))
for n in ("off", "idle", "loaded"):
    l = lat[n]
    print("%-7s %8d %10.3f %10.3f %10.3f" % (n, l["samples"], l["median_us"], l["p99_us"],
                                            l["max_us"]))
print("the same from each sample's deadline (the replay's pacing: the wake-up's lateness "
      "included):")
for n in ("off", "idle", "loaded"):
    l = runs[n]["latency_from_due"]
    print("%-7s %8d %10.3f %10.3f %10.3f" % (n, l["samples"], l["median_us"], l["p99_us"],
                                            l["max_us"]))
m = runs["loaded"]
print("loaded: %s Modbus pollers answered %s reads (the server counted %d requests), "
      "the subscriber got %s messages (%d states published)" % (
          pollers, polls, m["modbus"]["requests"], messages, m["mqtt"]["states_published"]))
for base in ("off", "idle"):
    print("ratio loaded/%-4s median %.2f, p99 %.2f" % (
        base, lat["loaded"]["median_us"] / lat[base]["median_us"],
        lat["loaded"]["p99_us"] / lat[base]["p99_us"]))
PY
