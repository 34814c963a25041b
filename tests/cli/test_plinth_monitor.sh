#!/usr/bin/env bash
# plinth-monitor run as a user would (docs/monitor.md): a record replayed through the box's loop
# gives plinth-sim's phase events and the alarm timeline; two axes; the event recorder's
# captures, replayed as candump logs; then bad inputs, which must end with exit code 1 or 2 and
# a message on stderr naming the problem.
#
# Environment: PLINTH_MONITOR, the plinth-monitor binary; PLINTH_SIM, plinth-sim (the
# reference); PLINTH_SOURCE_DIR, the repository root.
set -u

# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
BIN=${PLINTH_MONITOR:-}
if [[ ! -x "$BIN" ]]; then
  echo "PLINTH_MONITOR=$BIN: not an executable" >&2
  exit 2
fi
ISOLATED=$SCENES/paper-isolated.toml
ECCENTRIC=$SCENES/paper-eccentric.toml
AT2_270=$SRC/sim/data/records/irpinia1980_brienza_270.AT2

# check_output FILE PYTHON: runs a Python check on the monitor's JSON lines; prints the problem.
check_output() {
  python3 - "$1" "$2" 2>&1 <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
ns = {"json": json, "lines": lines, "status": [l for l in lines if l["type"] == "status"],
      "alarms": [l for l in lines if l["type"] == "alarm"],
      "events": [l for l in lines if l["type"] == "event"],
      "summary": [l for l in lines if l["type"] == "summary"]}
for l in ns["status"]:
    for key in ("t", "phase", "risk", "alarm"):
        assert key in l, "status line without %s: %s" % (key, l)
    assert 0.0 <= l["risk"] <= 1.0, l
    assert l["alarm"] in ("normal", "advisory", "warning", "alarm", "fault"), l
assert len(ns["summary"]) == 1 and lines[-1]["type"] == "summary", "one summary, last"
try:
    exec(sys.argv[2], ns)
except AssertionError as e:
    print(str(e) or "an assertion without a message failed")
PY
}

# 1. Brienza x20 on the paper's isolated block: rocking, overturning, the alarm timeline, and
#    the same events as plinth-sim at the same step (dt = 0.0029 s / 4).
if expect_success "replay: Brienza x20 runs" --scene "$ISOLATED" --replay "$AT2" --scale 20 \
    --status-interval 0.5; then
  cp "$TMP/stdout" "$TMP/monitor.jsonl"
  "$SIM" --scene "$ISOLATED" --record "$AT2" --scale 20 --dt 0.000725 --events "$TMP/sim.jsonl" \
    >/dev/null 2>&1
  problem=$(check_output "$TMP/monitor.jsonl" '
levels = [a["level"] for a in alarms]
# Rising to the alarm (the warning is skipped when its threshold and that of the alarm are crossed
# within one raise hold).
assert levels[-1] == "alarm" and "advisory" in levels, levels
rank = {"normal": 0, "advisory": 1, "warning": 2, "alarm": 3}
rising = [rank[l] for l in levels if l in rank][1:]
assert rising == sorted(rising), levels
assert summary[0]["final_phase"] == "overturned", summary
ref = [json.loads(l) for l in open("'"$TMP/sim.jsonl"'") if "\"end\"" not in l]
assert [e["event"] for e in events] == [r["event"] for r in ref], (events, ref)
for e, r in zip(events, ref):
    assert abs(e["t"] - r["t"]) < 1e-6, (e, r)
overturn = [e["t"] for e in events if e["event"] == "overturned"][0]
alarm = [a["t"] for a in alarms if a["level"] == "alarm"][0]
assert alarm < overturn, (alarm, overturn)
')
  if [[ -z "$problem" ]]; then pass "replay: events equal plinth-sim's, alarm before the overturn"
  else fail "replay: events and alarms" "$problem"; fi
fi

# 2. Two axes: phase is an object per axis.
if expect_success "replay: two axes" --scene "$ISOLATED" --scene-y "$ECCENTRIC" --replay "$AT2" \
    --replay-y "$AT2_270" --scale 10 --status-interval 1; then
  problem=$(check_output "$TMP/stdout" '
assert all(set(s["phase"]) == {"x", "y"} for s in status), status[0]
assert all(set(s["state"]) == {"x", "y"} for s in status), status[0]
assert {e["axis"] for e in events} <= {"x", "y"}
')
  if [[ -z "$problem" ]]; then pass "two axes: per-axis phase and state"
  else fail "two axes" "$problem"; fi
fi

# 2b. --frames-out: the status and alarm frames a replay sends, as a candump log, say what the
#     JSON lines say (tests/cli/monitor_frames.py decodes them from the DBC's layout); one axis
#     and two.
FRAMES_CHECK=$(dirname "${BASH_SOURCE[0]}")/monitor_frames.py
LOGS=$(dirname "${BASH_SOURCE[0]}")/monitor_logs.py
if expect_success "replay: --frames-out, one axis" --scene "$ECCENTRIC" --replay "$AT2" \
    --scale 20 --status-interval 0.25 --frames-out "$TMP/frames1.log"; then
  cp "$TMP/stdout" "$TMP/frames1.jsonl"
  if problem=$(python3 "$FRAMES_CHECK" "$TMP/frames1.log" --json "$TMP/frames1.jsonl"); then
    pass "--frames-out, one axis: frames agree with the JSON lines"
  else fail "--frames-out, one axis" "$problem"; fi
fi
# Two axes without the forecast: the status line's probability is the highest of the axes, so
# the frames' per-axis forecast is checked on one axis (above) and in test_can_frames.
if expect_success "replay: --frames-out, two axes" --scene "$ISOLATED" --scene-y "$ECCENTRIC" \
    --replay "$AT2" --replay-y "$AT2_270" --scale 10 --no-forecast --frames-out "$TMP/frames2.log"; then
  if problem=$(python3 "$FRAMES_CHECK" "$TMP/frames2.log" --json "$TMP/stdout"); then
    pass "--frames-out, two axes: frames agree with the JSON lines"
  else fail "--frames-out, two axes" "$problem"; fi
fi
# The check can fail: the first alarm frame dropped.
awk '/ 330#/ && !dropped { dropped = 1; next } 1' "$TMP/frames1.log" >"$TMP/frames-short.log"
if python3 "$FRAMES_CHECK" "$TMP/frames-short.log" --json "$TMP/frames1.jsonl" >/dev/null; then
  fail "--frames-out check" "a log without its first alarm frame passed"
else pass "--frames-out check refuses a log missing an alarm frame"; fi
expect_failure "--frames-out with --can" 'frames-out|can' -- --scene "$ISOLATED" --can vcan0 \
  --frames-out "$TMP/x.log"
expect_failure "--frames-out into a missing directory" 'nowhere' -- --scene "$ISOLATED" \
  --replay "$AT2" --frames-out "$TMP/nowhere/frames.log"

# 3. The event recorder: a capture around the warning, a candump log and a JSON summary; the
#    log replayed through plinth-monitor as sensor frames.
if expect_success "recorder: captures written" --scene "$ISOLATED" --replay "$AT2" --scale 20 \
    --record-dir "$TMP/captures" --pre-trigger 12.5 --post-trigger 2 --no-events; then
  log=$TMP/captures/event-001.log
  if [[ -s "$log" && -s "$TMP/captures/event-001.json" ]] &&
      python3 -c 'import json,sys; d=json.load(open(sys.argv[1])); assert d["level"] in ("warning", "alarm") and d["frames"]>0' \
      "$TMP/captures/event-001.json" 2>/dev/null &&
      tail -n 1 "$TMP/stdout" | grep -q '"recorder": {"captures_written": 1, "captures_dropped": 0'; then
    pass "recorder: log and summary"
  else
    fail "recorder: log and summary" "missing or wrong: $(ls "$TMP/captures" 2>&1)"
  fi
  frames=$(wc -l <"$log")
  if expect_success "candump log replay runs" --scene "$ISOLATED" --replay "$log" --rate 344.8275862068966 \
      --startup-window 1 --status-interval 1 --stuck-samples 0; then
    problem=$(check_output "$TMP/stdout" '
s = summary[0]
assert s["frames"]["sensor_samples"] == '"$frames"', s
assert s["sensor"]["missing"] == 0 and s["sensor"]["long_gaps"] == 0, s
assert s["max_risk"] > 0.0, s
')
    if [[ -z "$problem" ]]; then pass "candump log replay: every frame a sample, none missing"
    else fail "candump log replay" "$problem"; fi
  fi
  # Another box's CollapseForecast frames in the log (0x350 + axis): two valid ones counted as
  # monitor frames, a probability above 1 and a worst member beyond the members rejected; the
  # status lines carry the forecast (probability, collapse_forecast_t, members, worst_member).
  python3 "$LOGS" forecast-frames "$log" "$TMP/forecast.log"
  if expect_success "candump log with CollapseForecast frames" --scene "$ISOLATED" \
      --replay "$TMP/forecast.log" --rate 344.8275862068966 --startup-window 1 \
      --status-interval 1 --stuck-samples 0; then
    problem=$(check_output "$TMP/stdout" '
s = summary[0]
f = s["frames"]
assert f["sensor_samples"] == '"$frames"' and f["monitor_frames"] == 2 and f["rejected"] == 2, f
assert f["not_encoded"] == 0, f
assert all(0.0 <= x["probability"] <= 1.0 for x in status), status[-1]
assert all(x["collapse_forecast_t"] is None or x["collapse_forecast_t"] >= 0.0 for x in status)
assert all(x["state"]["members"] == 1 and x["state"]["worst_member"] == 0 for x in status)
')
    if [[ -z "$problem" ]]; then
      pass "candump log: CollapseForecast frames counted or rejected, forecast in the status"
    else fail "candump log: CollapseForecast frames" "$problem"; fi
  fi
  # Two ground sensors (node 2: node 1's frames 0.5 ms later); node 1 falls silent at 60 % of
  # the log: the estimators fail over to node 2 and continue, the summary reports each sensor.
  python3 "$LOGS" failover "$log" "$TMP/two.log"
  printf '[[sensor]]\nnode = 1\n\n[[sensor]]\nnode = 2\nrole = "ground"\n' >"$TMP/two.toml"
  if expect_success "two ground sensors, failover" --scene "$ISOLATED" --replay "$TMP/two.log" \
      --config "$TMP/two.toml" --rate 344.8275862068966 --startup-window 1 --status-interval 1 \
      --stuck-samples 0 --no-events; then
    problem=$(check_output "$TMP/stdout" '
s = summary[0]
assert [x["node"] for x in s["sensors"]] == [1, 2], s
assert s["failovers"] == 1 and s["failovers_continued"] == 1, s
assert s["estimator_restarts"] == 1, s
assert s["sensors_state"] == "degraded" and s["sensors"][0]["state"] == "fault", s
assert s["sensors"][1]["primary"] and s["sensors"][1]["pairs"] > 0, s
assert s["sensors"][1]["disagreements"] == 0, s
assert all(len(x["sensors"]) == 2 for x in status), status[-1]
assert status[-1]["sensors"][1]["primary"] and status[-1]["failovers"] == 1, status[-1]
')
    if [[ -z "$problem" ]]; then pass "two ground sensors: failover, the estimators continue"
    else fail "two ground sensors" "$problem"; fi
  fi
  expect_failure "--node with [[sensor]] tables" '--node' -- --scene "$ISOLATED" \
    --replay "$TMP/two.log" --config "$TMP/two.toml" --node 3
  head -n 5 "$log" >"$TMP/garbled.log"
  echo "(12.500000) can0 301#00112233445566778899" >>"$TMP/garbled.log"
  expect_failure "candump log: a garbled line" 'garbled\.log:6' -- \
    --scene "$ISOLATED" --replay "$TMP/garbled.log"
fi

# 4. Bad inputs.
expect_failure "no input" '--replay|--can' -- --scene "$ISOLATED"
expect_failure "two inputs" 'exactly one' -- --scene "$ISOLATED" --replay "$AT2" --can vcan0
expect_failure "--speed 0" '--speed' -- --scene "$ISOLATED" --replay "$AT2" --speed 0
expect_failure "--speed fast" '--speed' -- --scene "$ISOLATED" --replay "$AT2" --speed fast
expect_failure "--rate 50" 'sample_rate_hz|rate' -- --scene "$ISOLATED" --replay "$AT2" --rate 50
expect_failure "--steps 0" '--steps' -- --scene "$ISOLATED" --replay "$AT2" --steps 0
expect_failure "missing scene" 'nowhere\.toml' -- --scene "$TMP/nowhere.toml" --replay "$AT2"
expect_failure "missing record" 'nowhere\.AT2' -- --scene "$ISOLATED" --replay "$TMP/nowhere.AT2"
expect_failure "--pga nan" '--pga' -- --scene "$ISOLATED" --replay "$AT2" --pga nan
expect_failure "--scale nan" '--scale' -- --scene "$ISOLATED" --replay "$AT2" --scale nan
expect_failure "--replay-y without --scene-y" 'scene-y' -- --scene "$ISOLATED" --replay "$AT2" \
  --replay-y "$AT2_270"
# A recorder folder that cannot be made never stops the box: said at start, failed in every
# status line and the summary, its capture counted lost (docs/monitor.md, "Event recorder").
if expect_success "recorder folder under a file: the box runs" --scene "$ISOLATED" \
    --replay "$AT2" --scale 20 --record-dir /dev/null/captures --no-events; then
  problem=$(check_output "$TMP/stdout" '
assert all(x["recorder"]["health"] == "failed" and x["recorder"]["problem"] == "folder_missing"
           for x in status), status[0]
r = summary[0]["recorder"]
assert r["health"] == "failed" and r["captures_lost"] == 1 and r["captures_written"] == 0, r
')
  if [[ -z "$problem" ]] &&
      grep -q "cannot create the folder /dev/null/captures: Not a directory (folder_missing)" \
        "$TMP/stderr"; then
    pass "recorder folder under a file: said, shown failed, its capture lost"
  else
    fail "recorder folder under a file" "$problem $(first_stderr_line)"
  fi
fi
expect_failure "--pre-trigger -1" 'pre-trigger' -- --scene "$ISOLATED" --replay "$AT2" \
  --record-dir "$TMP/c2" --pre-trigger -1
expect_failure "CAN interface missing or no CAN in the kernel" 'plinth9|CAN' -- \
  --scene "$ISOLATED" --can plinth9

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
