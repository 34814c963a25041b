#!/usr/bin/env bash
# plinth-commission (docs/commissioning.md) on sessions made from a box file and the solver's
# block (commission_fixture.cpp: the statue's raise is the rigid block turning on its base edge,
# lib/core block_specific_force): a correct installation passes, its windows found in the data
# where the fixture put them, its report and picture written; each installation fault fails with
# a message naming the sensor and what is wrong, and no other sensor; bad inputs are refused
# naming them. Then plinth-monitor against the reports: a failed one refuses (fault, cause
# commissioning_failed, on every status line and on the bus as AlarmEvent Cause 19), an
# override (option or box-file key) monitors and says why, a passing one for another mounting
# refuses, a passing one written while the box refuses lifts the refusal.
#
# Environment: PLINTH_COMMISSION, PLINTH_COMMISSION_FIXTURE, PLINTH_MONITOR, PLINTH_SOURCE_DIR.
set -u

export PLINTH_SIM=${PLINTH_SIM:-${PLINTH_COMMISSION:-}}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
for bin in "${PLINTH_COMMISSION:-}" "${PLINTH_COMMISSION_FIXTURE:-}" "${PLINTH_MONITOR:-}"; do
  if [[ ! -x "$bin" ]]; then
    echo "PLINTH_COMMISSION, PLINTH_COMMISSION_FIXTURE and PLINTH_MONITOR must be executables" \
      "(got '$bin')" >&2
    exit 2
  fi
done
BIN=$PLINTH_COMMISSION
FIXTURE=$PLINTH_COMMISSION_FIXTURE
MONITOR=$PLINTH_MONITOR

# The site: two ground sensors (node 1 mounted turned 90 deg, as the example box file), a plate
# sensor, the statue sensor (turned 180 deg) on a statue with two axes.
cat >"$TMP/box.toml" <<'EOF'
[monitor]
second_scene = "statue-y.toml"

[[sensor]]
node = 1
sensor_to_statue = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]

[[sensor]]
node = 2

[[sensor]]
node = 3
role = "plate"

[statue_sensor]
node = 4
sensor_to_statue = [[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]]
height_m = 1.2
EOF
# The same box file saying node 1 sends m/s2 (it sends g).
sed '0,/^node = 1$/s//node = 1\nunit = "m\/s2"/' "$TMP/box.toml" >"$TMP/box-unit.toml"

# Python starts slowly on a busy machine: the checks read the programs' lines with grep, the
# reports (indented JSON, a member a line) too.
# has FILE PATTERN...: FILE matches every extended regular expression.
has() {
  local file=$1 pattern
  shift
  for pattern in "$@"; do grep -qE -- "$pattern" "$file" || return 1; done
}
# failures: plinth-commission's failures, "subject: message" a line (from its stdout).
failures() { sed -n 's/^  FAIL //p' "$TMP/stdout"; }

# 1. The correct installation passes; the windows it found are the fixture's holds.
"$FIXTURE" --config "$TMP/box.toml" --out "$TMP/ok.log" --windows "$TMP/ok.windows" ||
  { echo "the fixture failed" >&2; exit 2; }
run --config "$TMP/box.toml" --log "$TMP/ok.log" --record-dir "$TMP/reports"
if ((RC == 0)) && grep -q '^commissioning PASSED' "$TMP/stdout" &&
  has "$TMP/reports/commission-001.json" '^  "result": "pass",$' '^  "failures": \[\],$'; then
  pass "correct installation: exit 0, PASSED, commission-001.json says pass"
else
  fail "correct installation" "exit $RC; $(head -c 600 "$TMP/stdout") $(head -c 300 "$TMP/stderr")"
fi
found=$(python3 - "$TMP/reports/commission-001.json" "$TMP/ok.windows" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
steps = {s["step"]: s for s in d["steps"]}
bad = []
for line in open(sys.argv[2]):
    name, span = line.strip().split("=")
    t0, t1 = map(float, span.split(":"))
    w = steps[name]["window"]
    if w is None or w["from"] != "data" or abs(w["t0"] - t0) > 1.0 or abs(w["t1"] - t1) > 1.0:
        bad.append("%s %s (fixture %.1f-%.1f)" % (name, w, t0, t1))
names = [s["step"] for s in d["steps"]]
if len(names) != 10 or names[-1] != "final-rest" or steps["final-rest"]["window"] is None:
    bad.append("steps %s" % names)
print("; ".join(bad) or "ok")
PY
)
if [[ "$found" == ok ]]; then
  pass "correct installation: its 10 steps, every hold found in the data within 1 s of the \
fixture's"
else fail "windows found in the data" "$found"; fi
if command -v gnuplot >/dev/null 2>&1; then
  magic=$(head -c 8 "$TMP/reports/commission-001.png" | od -An -tx1 | tr -d ' \n')
  if [[ "$magic" == 89504e470d0a1a0a ]] &&
    has "$TMP/reports/commission-001.json" '^  "picture": "commission-001.png",$'; then
    pass "correct installation: commission-001.png, a PNG, named in the report"
  else fail "the picture" "$(ls -l "$TMP/reports")"; fi
else
  echo "# gnuplot not installed: the picture is not checked"
fi
# The same session again: the next number; the windows given by options.
mapfile -t windows < <(sed 's/^/--window=/' "$TMP/ok.windows")
run --config "$TMP/box.toml" --log "$TMP/ok.log" --record-dir "$TMP/reports" --no-picture \
  "${windows[@]}"
if ((RC == 0)) && [[ -f "$TMP/reports/commission-002.json" ]] &&
  has "$TMP/reports/commission-002.json" '^  "picture": null,$' '"picture_note": "--no-picture"' &&
  [[ "$(grep -c '"from": "option"' "$TMP/reports/commission-002.json")" == 8 ]]; then
  pass "windows given by --window: passes, commission-002.json, the windows from the options"
else fail "--window" "exit $RC; $(head -c 400 "$TMP/stdout") $(head -c 300 "$TMP/stderr")"; fi

# 2. Each fault fails, naming the sensor and what is wrong, and no other sensor.
# expect_fault NAME SUBJECT PATTERN [--box FILE] [FIXTURE ARGS...]
expect_fault() {
  local name=$1 subject=$2 pattern=$3
  shift 3
  local box=$TMP/box.toml
  if [[ "${1:-}" == --box ]]; then
    box=$2
    shift 2
  fi
  if ! "$FIXTURE" --config "$TMP/box.toml" --out "$TMP/fault.log" "$@" 2>"$TMP/fixture.err"; then
    fail "$name" "the fixture failed: $(head -c 200 "$TMP/fixture.err")"
    return
  fi
  rm -f "$TMP/fault.json"  # a report is never written over (commission_report.h)
  run --config "$box" --log "$TMP/fault.log" --report "$TMP/fault.json" --no-picture
  local failures
  failures=$(failures)
  if ((RC != 4)); then
    fail "$name" "exit $RC (4 expected); $(head -c 300 "$TMP/stderr")"
  elif ! has "$TMP/fault.json" '^  "result": "fail",$'; then
    fail "$name" "the report does not say fail"
  elif ! grep -qE -- "^$subject: .*$pattern" <<<"$failures"; then
    fail "$name" "no failure of $subject matching /$pattern/: $failures"
  elif grep -vqE -- "^$subject: " <<<"$failures"; then
    fail "$name" "another sensor failed too: $(grep -vE -- "^$subject: " <<<"$failures" | head -2)"
  else
    pass "$name: $(grep -E -- "^$subject: .*$pattern" <<<"$failures" | head -1 | cut -c 1-150)"
  fi
}
N1='node 1 \(ground, sensor\[0\]\)'
N2='node 2 \(ground, sensor\[1\]\)'
STATUE='statue sensor \(node 4\)'
expect_fault "ground sensor turned 90 deg about the vertical" "$N2" \
  'turned 90 deg counter-clockwise' --fault turned:2:90
expect_fault "a gain of 0.5 on one axis" "$N1" \
  'gain of 0\.(49|50|51) on its statue y axis \(sensor axis \+x\)' --fault gain:1:x:0.5
expect_fault "unit: the box file says m/s2, the sensor sends g" "$N1" 'unit error' \
  --box "$TMP/box-unit.toml"
expect_fault "unit: the sensor sends m/s2, the box file says g" "$N1" 'full scale.*m/s2 sent' \
  --fault ms2:1
expect_fault "an axis's sign flipped" "$N2" 'statue y axis \(sensor axis \+y\) reads backwards' \
  --fault gain:2:y:-1
expect_fault "a missing node" "$N2" 'never heard' --fault missing:2
expect_fault "an unexpected node" 'node 7' 'names no sensor on node 7' --fault extra:7
expect_fault "a duplicated node" "$N2" 'two devices answer to this node' --fault duplicate:2
expect_fault "a statue sensor fixed to the plinth" "$STATUE" 'not fixed to the statue' \
  --fault statue-on-plinth
expect_fault "a statue gyroscope with the wrong sign" "$STATUE" 'gyroscope.*sign is reversed' \
  --fault gyro-gain:-1
expect_fault "a statue gyroscope at half gain" "$STATUE" 'gyroscope gain of 0\.[3-6]' \
  --fault gyro-gain:0.5
expect_fault "a statue gyroscope in deg/s" "$STATUE" 'sends deg/s' --fault gyro-gain:57.29578

# 3. Bad inputs, refused naming them.
expect_failure "no input" 'exactly one input' -- --config "$TMP/box.toml"
expect_failure "--window of no step" 'tilt-x:9' 'no step' -- --config "$TMP/box.toml" \
  --log "$TMP/ok.log" --window tilt-x:9=1:2
expect_failure "--window backwards" 'T0 < T1' -- --config "$TMP/box.toml" --log "$TMP/ok.log" \
  --window rest=5:2
printf '[commissioning]\nwedge_deg = 45\n' >"$TMP/steep.toml"
expect_failure "a wedge steeper than 30 deg" 'steep\.toml:2' 'commissioning\.wedge_deg' \
  '\[1, 30\]' -- --config "$TMP/steep.toml" --log "$TMP/ok.log"
printf '[commissioning]\noverride = ""\n' >"$TMP/empty-override.toml"
expect_failure "an override without its reason" 'commissioning\.override' 'reason' -- \
  --config "$TMP/empty-override.toml" --log "$TMP/ok.log"
head -n 2000 "$TMP/ok.log" >"$TMP/back.log"
head -n 1 "$TMP/ok.log" >>"$TMP/back.log"
expect_failure "a log whose time goes back" 'back\.log:2001' 'goes back' -- \
  --config "$TMP/box.toml" --log "$TMP/back.log"

# 4. plinth-monitor and the reports. One ground sensor; a quiet minute-long log of it at rest.
BIN=$MONITOR
printf '[[sensor]]\nnode = 1\n' >"$TMP/gate.toml"
"$FIXTURE" --config "$TMP/gate.toml" --out "$TMP/gate-ok.log" &&
  "$FIXTURE" --config "$TMP/gate.toml" --out "$TMP/gate-bad.log" --fault turned:1:90 ||
  { echo "the fixture failed" >&2; exit 2; }
python3 - "$TMP/quiet.log" <<'PY'
import random, sys
rng = random.Random(7)
with open(sys.argv[1], "w") as f:
    for n in range(200 * 25):  # 25 s at 200 Hz, node 1 at rest, 1 g up
        raw = [round(rng.gauss(0, 0.0005) / 0.00025), round(rng.gauss(0, 0.0005) / 0.00025),
               round((1 + rng.gauss(0, 0.0005)) / 0.00025)]
        word = sum((v & 0xFFFF) << (16 * i) for i, v in enumerate(raw)) | (n % 256) << 48
        f.write("(%d.%06d) can0 301#%s\n" % (1700000000 + n // 200, (n % 200) * 5000,
                                           word.to_bytes(8, "little").hex().upper()))
PY
SCENE=$SCENES/eval/ground-slender.toml
MON=(--scene "$SCENE" --replay "$TMP/quiet.log" --no-events --stuck-samples 0 --startup-window 1)
# alarms FILE: the alarm lines' level/cause, in order.
alarms() {
  grep '"type": "alarm"' "$1" | sed -E 's/.*"level": "([a-z]+)".*"cause": "([a-z_]+)".*/\1\/\2/' |
    tr '\n' ' ' | sed 's/ $//'
}
# statuses FILE PATTERN: how many status lines of FILE there are, and how many match PATTERN.
statuses() {
  echo "$(grep -c '"type": "status"' "$1") $(grep '"type": "status"' "$1" | grep -cE -- "$2")"
}
last_status() { grep '"type": "status"' "$1" | tail -n 1; }
BIN=$PLINTH_COMMISSION
run --config "$TMP/gate.toml" --log "$TMP/gate-bad.log" --record-dir "$TMP/box-dir" --no-picture
((RC == 4)) || fail "a failed report for the gate" "exit $RC"
BIN=$MONITOR
if expect_success "failed report: the box runs (exit 0)" "${MON[@]}" --config "$TMP/gate.toml" \
  --record-dir "$TMP/box-dir" --frames-out "$TMP/frames.log"; then
  read -r lines refused < <(statuses "$TMP/stdout" \
    '"alarm": "fault".*"commissioning": \{"state": "refused", "cause": "commissioning_failed"')
  if [[ "$(alarms "$TMP/stdout")" == "fault/commissioning_failed" ]] && ((lines > 200)) &&
    ((refused == lines)); then
    pass "failed report: fault, cause commissioning_failed, on every status line, never normal"
  else fail "failed report: the status" "$(alarms "$TMP/stdout")"; fi
  if grep -q 'fault: commissioning: .*commission-001.json failed.*node 1 (ground, sensor\[0\])' \
    "$TMP/stderr"; then
    pass "failed report: stderr (the journal) names the report and the sensor"
  else fail "failed report: stderr" "$(head -c 300 "$TMP/stderr")"; fi
  # AlarmEvent: Level 4 (fault), PreviousLevel 0, Cause 19 (0x13).
  if grep -qE ' 330#0413' "$TMP/frames.log"; then
    pass "failed report: AlarmEvent with Level fault, Cause 19 (commissioning_failed) on the bus"
  else fail "failed report: the AlarmEvent frame" "$(grep -m2 ' 330#' "$TMP/frames.log")"; fi
fi
if expect_success "override by option: exit 0" "${MON[@]}" --config "$TMP/gate.toml" \
  --record-dir "$TMP/box-dir" --commissioning-override "node 1 to be turned on Monday"; then
  if ! grep -q commissioning_failed <(alarms "$TMP/stdout") &&
    grep -q 'overridden by --commissioning-override ("node 1 to be turned on Monday")' \
      "$TMP/stderr" &&
    last_status "$TMP/stdout" |
    grep -qE '"alarm": "normal".*"commissioning": \{"state": "overridden"'; then
    pass "override by option: monitors (normal), the reason logged and on every status line"
  else fail "override by option" "$(alarms "$TMP/stdout"); $(head -c 300 "$TMP/stderr")"; fi
fi
# expect_gate NAME ALARMS STDERR BOX DIR: plinth-monitor with box file BOX and recorder folder
# DIR replays the quiet log; its alarm lines must be ALARMS ("monitors": no commissioning_failed
# among them) and its stderr match STDERR.
expect_gate() {
  local name=$1 expected=$2 pattern=$3
  expect_success "$name: exit 0" "${MON[@]}" --config "$4" --record-dir "$5" || return
  local got
  got=$(alarms "$TMP/stdout")
  if { [[ "$expected" == monitors ]] && ! grep -q commissioning_failed <<<"$got"; } ||
    [[ "$got" == "$expected" ]] && grep -qE -- "$pattern" "$TMP/stderr"; then
    pass "$name"
  else fail "$name" "alarms: $got; $(head -c 300 "$TMP/stderr")"; fi
}
printf '[[sensor]]\nnode = 1\n[commissioning]\noverride = "waiting for the wedge"\n' \
  >"$TMP/gate-override.toml"
expect_gate "override by commissioning.override: monitors, the reason logged" monitors \
  'overridden by commissioning.override \("waiting for the wedge"\)' "$TMP/gate-override.toml" \
  "$TMP/box-dir"
# A passing report: the box monitors; for another mounting (node 1 turned in the box file) it
# refuses.
BIN=$PLINTH_COMMISSION
run --config "$TMP/gate.toml" --log "$TMP/gate-ok.log" --record-dir "$TMP/box-dir" --no-picture
((RC == 0)) || fail "a passing report for the gate" "exit $RC $(head -c 300 "$TMP/stdout")"
BIN=$MONITOR
if expect_success "passing report: exit 0" "${MON[@]}" --config "$TMP/gate.toml" \
  --record-dir "$TMP/box-dir"; then
  if grep -m 1 '"type": "status"' "$TMP/stdout" | grep -q '"commissioning": {"state": "passed"' &&
    last_status "$TMP/stdout" | grep -q '"alarm": "normal"' &&
    ! last_status "$TMP/stdout" | grep -q '"commissioning"'; then
    pass "passing report (commission-002): normal; the first status line says passed"
  else fail "passing report" "$(alarms "$TMP/stdout")"; fi
fi
printf 'sensor_to_statue = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]\n' |
  cat "$TMP/gate.toml" - >"$TMP/gate-turned.toml"
expect_gate "a report of another mounting (sensor_to_statue changed since): refused" \
  fault/commissioning_failed 'passed for another mounting' "$TMP/gate-turned.toml" "$TMP/box-dir"
printf '[[sensor]]\nnode = 1\n[commissioning]\nrequired = true\n' >"$TMP/gate-required.toml"
expect_gate "commissioning.required without a report: refused" fault/commissioning_failed \
  'commissioning.required, and no report' "$TMP/gate-required.toml" "$TMP/empty-dir"
expect_gate "no report, not required: monitors, saying there is none" monitors \
  'warning: no commissioning report \(none in' "$TMP/gate.toml" "$TMP/empty-dir"
# A passing report written while the box refuses: within kGateRescanS (2 s) of wall clock the
# refusal lifts. The replay at twice real time (12 s); the report written once the box refuses.
mkdir -p "$TMP/live-dir"
cp "$TMP/box-dir/commission-001.json" "$TMP/live-dir/"
"$MONITOR" "${MON[@]}" --config "$TMP/gate.toml" --record-dir "$TMP/live-dir" --speed 2 \
  >"$TMP/live.out" 2>"$TMP/live.err" &
monitor_pid=$!
for _ in $(seq 300); do  # until the box refuses (at most 30 s)
  grep -q '"cause": "commissioning_failed"' "$TMP/live.out" 2>/dev/null && break
  sleep 0.1
done
"$PLINTH_COMMISSION" --config "$TMP/gate.toml" --log "$TMP/gate-ok.log" \
  --record-dir "$TMP/live-dir" --no-picture >/dev/null 2>&1
wait "$monitor_pid"
if [[ "$(alarms "$TMP/live.out")" == "fault/commissioning_failed normal/none" ]] &&
  grep -q 'commissioning: .*commission-002.json passed' "$TMP/live.err"; then
  pass "a passing report written while refusing: the box goes normal, saying so"
else fail "the refusal lifted" "$(alarms "$TMP/live.out"); $(head -c 400 "$TMP/live.err")"; fi

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
