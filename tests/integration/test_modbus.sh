#!/usr/bin/env bash
# plinth-monitor's Modbus TCP server against the real mbpoll client on loopback
# (docs/integration.md): the input registers equal the JSON status lines, several clients at
# once, a coil write refused while writes are off, acknowledge and reset when they are on, and
# bad addresses refused with a message naming the key or flag.
#
# Environment: PLINTH_MONITOR, PLINTH_SIM, PLINTH_SOURCE_DIR. Exit 77 (skip) when mbpoll is
# missing, unless CI=true.
set -u

# shellcheck source=tests/integration/outputs_harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/outputs_harness.sh"
require_tools mbpoll
ISOLATED=$SCENES/paper-isolated.toml

# registers PORT: the 32 input registers, one "address value" a line.
registers() {
  mbpoll -m tcp -t 3 -0 -r 0 -c 32 -1 -o 2 -p "$1" 127.0.0.1 2>/dev/null |
    sed -n 's/^\[\([0-9]*\)\]:[[:space:]]*\([0-9]*\).*/\1 \2/p'
}
# register PORT ADDRESS
register() { registers "$1" | awk -v a="$2" '$1 == a { print $2 }'; }

# wait_listening PORT: until the server answers.
wait_listening() {
  local i
  for ((i = 0; i < 300; i++)); do
    [[ -n "$(register "$1" 31)" ]] && return 0
    sleep 0.1
  done
  return 1
}

# Checks the registers read in $TMP/regs against the newest status line and alarm line of
# $TMP/box.out; the heartbeat lies between the status counts before and after the read.
check_registers() {
  python3 - "$TMP/regs" "$TMP/box.out" "$1" "$2" <<'PY'
import json, sys
regs = dict(tuple(map(int, l.split())) for l in open(sys.argv[1]) if l.strip())
lines = [json.loads(l) for l in open(sys.argv[2]) if l.startswith("{")]
status = [l for l in lines if l["type"] == "status"][-1]
alarm = [l for l in lines if l["type"] == "alarm"][-1]
levels = ["normal", "advisory", "warning", "alarm", "fault"]
phases = ["full_contact", "sliding", "rocking", "slide_rocking", "overturned", "fell"]
causes = ["none", "risk_threshold", "phase_change", "overturn_detected", "sensor_timeout",
          "sensor_fault", "sensor_disagreement", "acknowledged", "bus_error", "internal_fault",
          "collapse_forecast", "not_calibrated", "outside_model"]
def check(name, address, expected):
    assert regs.get(address) == expected, "%s (register %d): %s, status line says %s" % (
        name, address, regs.get(address), expected)
check("alarm level", 0, levels.index(status["alarm"]))
check("risk x 10000", 2, round(status["risk"] * 10000))
check("latched", 3, levels.index(status["latched"]))
check("cause", 4, causes.index(alarm["cause"]))
check("event sequence", 5, alarm["sequence"])
check("axis count", 6, 1)
check("phase x", 7, phases.index(status["phase"]))
check("phase y", 8, 65535)
check("estimating", 9, int(status["estimating"]))
check("sensor health", 10, ["ok", "degraded", "fault"].index(status["sensor"]))
check("map version", 31, 1)
before, after = int(sys.argv[3]), int(sys.argv[4])
assert before <= regs[1] <= after, "heartbeat %d not within the status lines %d..%d" % (
    regs[1], before, after)
PY
}
status_count() { grep -c '"type": "status"' "$TMP/box.out"; }

# 1. Writes off: the registers against the status lines after the overturn (a steady state:
#    alarm latched, risk 1, for the record's last 24 s, 12 s at --speed 2: time for the reads below
#    even on a loaded machine), three clients polling at once, a coil write refused.
PORT=$(free_port)
"$BIN" --scene "$ISOLATED" --replay "$AT2" --scale 20 --speed 2 --no-events \
  --modbus "127.0.0.1:$PORT" >"$TMP/box.out" 2>"$TMP/box.err" &
BOX=$!
if ! wait_listening "$PORT"; then
  fail "modbus: the server answers" "no answer on port $PORT; stderr: $(head -c 300 "$TMP/box.err")"
else
  pass "modbus: the server answers mbpoll"
  pollers=()
  for i in 1 2 3; do
    timeout 3 mbpoll -m tcp -t 3 -0 -r 0 -c 32 -l 20 -p "$PORT" 127.0.0.1 >"$TMP/poller$i" 2>&1 &
    pollers+=($!)
  done
  if wait_for "$TMP/box.out" '"phase": "overturned"' 30; then
    before=$(status_count)
    registers "$PORT" >"$TMP/regs"
    after=$(status_count)
    problem=$(check_registers "$before" "$after" 2>&1)
    if [[ -z "$problem" ]]; then pass "modbus: registers equal the status and alarm lines"
    else fail "modbus: registers" "$problem"; fi
    first=$(register "$PORT" 1)
    sleep 0.5
    second=$(register "$PORT" 1)
    if ((second > first)); then pass "modbus: the heartbeat counts ($first, then $second)"
    else fail "modbus: heartbeat" "$first, then $second"; fi
  else
    fail "modbus: replay" "no overturn within 30 s"
  fi
  mbpoll -m tcp -t 0 -0 -r 0 -1 -p "$PORT" 127.0.0.1 1 >"$TMP/write.out" 2>&1
  rc=$?
  if ((rc != 0)) && grep -q "Illegal function" "$TMP/write.out"; then
    pass "modbus: a coil write is refused (Illegal function) while writes are off"
  else
    fail "modbus: refused write" "exit $rc: $(tail -n 2 "$TMP/write.out")"
  fi
  coils=$(mbpoll -m tcp -t 0 -0 -r 0 -c 2 -1 -p "$PORT" 127.0.0.1 2>&1 | grep -c '^\[[01]\]:[[:space:]]*0')
  if [[ "$coils" == 2 ]]; then pass "modbus: the coils read 0"
  else fail "modbus: coils" "$coils of 2 read 0"; fi
  wait "${pollers[@]}"
  polled=0
  for i in 1 2 3; do
    (($(grep -c '^\[31\]:' "$TMP/poller$i") >= 5)) && polled=$((polled + 1))
  done
  if ((polled == 3)); then pass "modbus: three clients polling at once all got answers"
  else fail "modbus: several clients" "$polled of 3 pollers got 5 answers or more"; fi
fi
# Checked: stop the replay (SIGINT: it writes its summary) rather than wait for its end.
kill -INT "$BOX" 2>/dev/null
wait "$BOX" 2>/dev/null
problem=$(python3 - "$TMP/box.out" 2>&1 <<'PY'
import json, sys
summary = json.loads(open(sys.argv[1]).read().splitlines()[-1])
m = summary["modbus"]
assert m["writes"] is False and m["writes_refused"] >= 1, m
assert m["most_clients_at_once"] >= 3 and m["connections"] >= 6, m
assert m["commands"] == 0, m
PY
)
if [[ -z "$problem" ]]; then pass "modbus: the summary counts clients and refused writes"
else fail "modbus: summary" "$problem"; fi

# 2. Writes on (the configuration file): acknowledge releases the latch (the collapse holds the
#    alarm), reset starts the monitor again.
PORT=$(free_port)
cat >"$TMP/box.toml" <<EOF
[modbus]
listen = "127.0.0.1:$PORT"
writes = true
EOF
"$BIN" --scene "$ISOLATED" --replay "$AT2" --scale 20 --speed 2 --no-events \
  --config "$TMP/box.toml" >"$TMP/box.out" 2>"$TMP/box.err" &
BOX=$!
if wait_listening "$PORT" && wait_for "$TMP/box.out" '"phase": "overturned"' 30; then
  latched=$(register "$PORT" 3)
  mbpoll -m tcp -t 0 -0 -r 0 -1 -p "$PORT" 127.0.0.1 1 >"$TMP/write.out" 2>&1
  rc=$?
  if ((rc == 0)) && wait_for "$TMP/box.out" '"command": "acknowledge"' 5; then
    sleep 0.3
    registers "$PORT" >"$TMP/regs"
    problem=$(python3 - "$TMP/box.out" "$TMP/regs" "$latched" 2>&1 <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
regs = dict(tuple(map(int, l.split())) for l in open(sys.argv[2]) if l.strip())
command = [l for l in lines if l["type"] == "command"][0]
assert int(sys.argv[3]) == 3, "latched before: %s" % sys.argv[3]
raised = [l for l in lines if l["type"] == "alarm" and l["level"] == "alarm"][0]
assert command["level"] == "alarm" and command["sequence"] == raised["sequence"], command
assert command["outcome"] == "released, condition holds", command
ack = [l for l in lines if l["type"] == "alarm"][-1]
assert ack["cause"] == "acknowledged" and ack["latched"] is False, ack
assert ack["level"] == "alarm", ack
assert regs[3] == 0 and regs[0] == 3, "latched %d, level %d" % (regs[3], regs[0])
assert regs[28] == 2 and regs[29] == 1, "outcome %d, commands %d" % (regs[28], regs[29])
assert regs[4] == 7 and regs[5] == ack["sequence"], "cause %d, sequence %d (the line's %d)" % (
    regs[4], regs[5], ack["sequence"])
PY
)
    if [[ -z "$problem" ]]; then pass "modbus: the acknowledge coil releases the latch"
    else fail "modbus: acknowledge" "$problem"; fi
  else
    fail "modbus: acknowledge" "exit $rc: $(tail -n 2 "$TMP/write.out")"
  fi
  mbpoll -m tcp -t 0 -0 -r 1 -1 -p "$PORT" 127.0.0.1 1 >"$TMP/write.out" 2>&1
  if wait_for "$TMP/box.out" '"command": "reset"' 5; then
    sleep 0.3
    registers "$PORT" >"$TMP/regs"
    problem=$(python3 - "$TMP/regs" 2>&1 <<'PY'
import sys
regs = dict(tuple(map(int, l.split())) for l in open(sys.argv[1]) if l.strip())
assert regs[29] == 2, "commands %d" % regs[29]
assert regs[7] == 0 and regs[3] == 0, "phase %d, latched %d after the reset" % (regs[7], regs[3])
PY
)
    if [[ -z "$problem" ]]; then pass "modbus: the reset coil starts the monitor again"
    else fail "modbus: reset" "$problem"; fi
  else
    fail "modbus: reset" "no reset line: $(tail -n 2 "$TMP/write.out")"
  fi
else
  fail "modbus: writes on" "no server or no overturn; stderr: $(head -c 300 "$TMP/box.err")"
fi
kill -INT "$BOX" 2>/dev/null
wait "$BOX" 2>/dev/null

# 3. Bad input: a message naming the key or flag.
run_args=(--scene "$ISOLATED" --replay "$AT2")
expect_failure "modbus: no port" "--modbus" "HOST:PORT" -- "${run_args[@]}" --modbus 127.0.0.1
expect_failure "modbus: port out of range" "--modbus" "65535" -- \
  "${run_args[@]}" --modbus 127.0.0.1:70000
expect_failure "modbus: IPv6 without brackets" "--modbus" "brackets" -- \
  "${run_args[@]}" --modbus ::1:1502
expect_failure "modbus: host that does not resolve" "--modbus" "cannot listen" -- \
  "${run_args[@]}" --modbus no-such-host.invalid:1502
printf '[monitor]\nquiet_risk = 1e-3\n[modbus]\nlisten = "localhost"\n' >"$TMP/bad.toml"
expect_failure "modbus: bad listen in the file" "bad.toml:4" "modbus.listen" "HOST:PORT" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[modbus]\nwrites = "yes"\n' >"$TMP/bad.toml"
expect_failure "modbus: writes not a boolean" "bad.toml:2" "modbus.writes" "true or false" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[modbus]\nmax_clients = 0\n' >"$TMP/bad.toml"
expect_failure "modbus: max_clients out of range" "bad.toml:2" "modbus.max_clients" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
PORT=$(free_port)
python3 -c 'import socket, sys, time
s = socket.socket(); s.bind(("127.0.0.1", int(sys.argv[1]))); s.listen(1)
open(sys.argv[2], "w").write("listening\n"); time.sleep(60)' "$PORT" "$TMP/holder" &
HOLDER=$!
wait_for "$TMP/holder" listening 30
expect_failure "modbus: port in use" "--modbus" "in use" -- \
  "${run_args[@]}" --modbus "127.0.0.1:$PORT"
kill "$HOLDER" 2>/dev/null
wait "$HOLDER" 2>/dev/null

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
