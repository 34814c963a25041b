#!/usr/bin/env bash
# The statue sensor's frames through candump logs (issue 24 item 3): a ground sensor's log from
# plinth-replay, the IMU's SensorAcceleration and StatueRotation frames added by
# statue_frames.py (its own encoder), replayed by plinth-replay --log and through plinth-monitor
# with a box file's [statue_sensor]. The standing statue (its accelerometer following the ground:
# corroborated) keeps the box at normal where the box without the sensor raises advisory (the
# nominal member rocks); a sensor swinging on its own, or reading rest while the ground shakes,
# is refused: the trouble statue_unexplained or statue_sensor_fault beside the box's own level,
# on the JSON lines and in the AlarmEvent frames on the bus (--frames-out); a sensor that falls
# silent or sends garbled frames is said and counted, the box going on as one without it with
# the trouble statue_sensor_fault; box files with a bad [statue_sensor] are refused naming the
# key (docs/safety.md).
#
# Environment: PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_SOURCE_DIR.
set -u

export PLINTH_SIM=${PLINTH_SIM:-${PLINTH_MONITOR:-}}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
for bin in "${PLINTH_MONITOR:-}" "${PLINTH_REPLAY:-}"; do
  if [[ ! -x "$bin" ]]; then
    echo "PLINTH_MONITOR and PLINTH_REPLAY must be executables (got '$bin')" >&2
    exit 2
  fi
done
BIN=$PLINTH_MONITOR
HERE=$SRC/tests/cli
FRAMES=$HERE/statue_frames.py
SCENE=$SCENES/eval/ground-slender.toml

# Brienza at 0.3 g on node 1 at 200 Hz: 6997 samples; the IMU on node 2 adds one of each frame
# per sample.
"$PLINTH_REPLAY" --record "$AT2" --pga 0.3g --rate 200 --speed max --log "$TMP/ground.log" \
  2>/dev/null || { echo "plinth-replay failed" >&2; exit 2; }
python3 "$FRAMES" "$TMP/ground.log" "$TMP/standing.log" >/dev/null
python3 "$FRAMES" "$TMP/ground.log" "$TMP/loose.log" --rock-rad-s 0.3 >/dev/null
python3 "$FRAMES" "$TMP/ground.log" "$TMP/silent.log" --silent-after-s 8 --garble-every 100 \
  >/dev/null
python3 "$FRAMES" "$TMP/ground.log" "$TMP/rest.log" --accelerometer rest >/dev/null
SAMPLES=6997
cat >"$TMP/box.toml" <<'EOF'
[statue_sensor]
node = 2
height_m = 1.0
[statue_sensor.health]
stuck_samples = 0
EOF
ARGS=(--scene "$SCENE" --no-events --stuck-samples 0 --startup-window 1)

# field JSONL TYPE EXPR: a Python expression over the last line of TYPE (d), printed.
field() {
  python3 -c "
import json, sys
d = [json.loads(l) for l in open(sys.argv[1]) if json.loads(l)['type'] == sys.argv[2]][-1]
v = ($3)
print(*(v if isinstance(v, tuple) else (v,)))" "$1" "$2"
}
alarms() { grep '"type": "alarm"' "$1" | sed -E 's/.*"level": "([a-z]+)".*"cause": "([a-z_]+)".*/\1 \2/'; }

# 1. plinth-replay sends the log's StatueRotation frames again, as they were.
REPLAY_OUT=$("$PLINTH_REPLAY" --record "$TMP/standing.log" --speed max --log "$TMP/again.log" \
  --report-json 2>"$TMP/replay.err")
if [[ "$REPLAY_OUT" == *"\"rotation_frames\": $SAMPLES"* ]] &&
  [[ "$REPLAY_OUT" == *"\"acceleration_frames\": $((2 * SAMPLES))"* ]] &&
  diff <(grep -o ' 37.#.*' "$TMP/standing.log") <(grep -o ' 37.#.*' "$TMP/again.log") >/dev/null; then
  pass "plinth-replay: $SAMPLES StatueRotation and $((2 * SAMPLES)) SensorAcceleration frames sent again, unchanged"
else
  fail "plinth-replay of the IMU's frames" "$REPLAY_OUT $(head -c 300 "$TMP/replay.err")"
fi

# 2. The standing statue: measured, full contact, no advisory; the box without the sensor, on
#    the same log, raises advisory (phase_change) and counts the IMU's frames as another node's.
if expect_success "standing statue: replay exit 0" "${ARGS[@]}" --config "$TMP/box.toml" \
  --replay "$TMP/standing.log"; then
  cp "$TMP/stdout" "$TMP/standing.jsonl"
  counts=$(field "$TMP/standing.jsonl" summary \
    "d['frames']['statue_rates'], d['frames']['statue_accelerations'], d['frames']['rejected']")
  if [[ "$counts" == "$SAMPLES $SAMPLES 0" ]]; then
    pass "standing statue: every IMU frame decoded ($counts)"
  else fail "standing statue: frames counted" "$counts"; fi
  state=$(field "$TMP/standing.jsonl" status \
    "d['statue_sensor']['rate']['health'], d['statue_sensor']['acceleration']['health'], d['statue_sensor']['ready'], d['statue_sensor']['weights']['measured'], d['phase']")
  if [[ "$state" == "ok ok True True full_contact" ]]; then
    pass "standing statue: both streams ok, offset known, measured, full contact"
  else fail "standing statue: the status's statue_sensor" "$state"; fi
  if [[ -z "$(alarms "$TMP/standing.jsonl" |
    grep -v -e '^fault sensor_timeout' -e '^fault not_calibrated' -e '^normal none')" ]]; then
    pass "standing statue: no level raised (the measured phase is full contact)"
  else fail "standing statue: levels" "$(alarms "$TMP/standing.jsonl" | tr '\n' ';')"; fi
fi
if expect_success "the same log without [statue_sensor]" "${ARGS[@]}" --replay "$TMP/standing.log"; then
  other=$(field "$TMP/stdout" summary "d['frames']['other_nodes']")
  if alarms "$TMP/stdout" | grep -q '^advisory phase_change' && ((other == 2 * SAMPLES)) &&
    ! grep -q '"statue_sensor"' "$TMP/stdout"; then
    pass "without the sensor: advisory (phase_change), the IMU's $other frames another node's"
  else fail "without the sensor" "other nodes $other; $(alarms "$TMP/stdout" | tr '\n' ';')"; fi
fi

# 3. A sensor swinging on its own (3 Hz, 0.3 rad/s about y): its accelerometer does not read the
#    swing and no member explains it: refused, the trouble statue_unexplained or
#    statue_sensor_fault named on the JSON lines and on the bus (AlarmEvent Cause 14 or 16 with
#    the Trouble bit), beside the box's own level.
if expect_success "loose sensor: replay exit 0" "${ARGS[@]}" --config "$TMP/box.toml" \
  --replay "$TMP/loose.log" --frames-out "$TMP/loose-frames.log"; then
  if alarms "$TMP/stdout" | grep -qE '^[a-z]+ statue_(unexplained|sensor_fault)' &&
    [[ "$(grep -c '"corroborated": false' "$TMP/stdout")" -gt 0 ]]; then
    pass "loose sensor: refused, the trouble named"
  else fail "loose sensor" "$(alarms "$TMP/stdout" | tr '\n' ';')"; fi
  # AlarmEvent: Cause 14 or 16 in bits 8-15, Trouble (bit 17) in byte 2.
  if grep -qE ' 330#[0-9A-F]{2}(0E|10)0[23]' "$TMP/loose-frames.log"; then
    pass "loose sensor: AlarmEvent with Cause 14 or 16 and the Trouble bit on the bus"
  else fail "loose sensor: frames" "no AlarmEvent naming the statue sensor"; fi
fi

# 3b. A sensor reading rest while the ground shakes (come off the statue): refused, the box
#     shows what it shows without the sensor (advisory: the nominal member rocks), the trouble
#     statue_sensor_fault beside it. Its accelerometer minus the ground's never settles, so its
#     offset is never known (no_accelerometer); once known, it does_not_follow_base.
if expect_success "resting sensor: replay exit 0" "${ARGS[@]}" --config "$TMP/box.toml" \
  --replay "$TMP/rest.log"; then
  refutation=$(field "$TMP/stdout" status "d['statue_sensor']['weights']['refutation']")
  if alarms "$TMP/stdout" | grep -q '^advisory phase_change' &&
    alarms "$TMP/stdout" | grep -q 'statue_sensor_fault' &&
    [[ "$refutation" == "does_not_follow_base" || "$refutation" == "no_accelerometer" ]]; then
    pass "resting sensor: refused ($refutation), advisory as without it, trouble named"
  else fail "resting sensor" "$refutation; $(alarms "$TMP/stdout" | tr '\n' ';')"; fi
fi

# 4. Silent after 8 s, every 100th StatueRotation cut to 7 bytes: refused and counted, bridged
#    as a gap, then a timeout said on the status line; the box shows the trouble
#    statue_sensor_fault (the level fault while the box without the sensor would say normal).
if expect_success "silent sensor: replay exit 0" "${ARGS[@]}" --config "$TMP/box.toml" \
  --replay "$TMP/silent.log"; then
  summary=$(field "$TMP/stdout" summary \
    "d['frames']['rejected'], d['frames']['last_error'], d['statue_sensor']['rate']['bridged'], d['statue_sensor']['rate']['timeouts']")
  if [[ "$summary" == "16 frame length is not 8 bytes 16 1" ]]; then
    pass "silent sensor: 16 garbled frames refused and bridged, one timeout ($summary)"
  else fail "silent sensor: counters" "$summary"; fi
  at_10=$(python3 -c "
import json, sys
d = next(json.loads(l) for l in open(sys.argv[1]) if '\"t\": 10.000000' in l and '\"status\"' in l)
print(d['statue_sensor']['rate']['health'], d['statue_sensor']['rate']['cause'], d['statue_sensor']['weights']['measured'], d['alarm'], d['trouble'])" "$TMP/stdout")
  if [[ "$at_10" == "fault timeout False fault statue_sensor_fault" ]]; then
    pass "silent sensor: at 10 s its rate stream timed out, not measured, the trouble named"
  else fail "silent sensor: status at 10 s" "$at_10"; fi
fi

# 5. Box files the monitor refuses, naming the key.
printf '[statue_sensor]\nheight_m = 1\n' >"$TMP/no-node.toml"
expect_failure "[statue_sensor] without node" 'no-node\.toml:1' 'statue_sensor' 'node' -- \
  "${ARGS[@]}" --config "$TMP/no-node.toml" --replay "$TMP/standing.log"
printf '[statue_sensor]\nnode = 1\n' >"$TMP/ground-node.toml"
expect_failure "[statue_sensor] on the ground sensor's node" 'ground-node\.toml:2' \
  'statue_sensor\.node' "accelerometer's node" -- "${ARGS[@]}" --config "$TMP/ground-node.toml" \
  --replay "$TMP/standing.log"
printf '[statue_sensor]\nnode = 2\n[statue_sensor.health]\nrate_max_valid_rad_s = 1\n' \
  >"$TMP/range.toml"
expect_failure "rate_max_valid_rad_s below full scale" 'range\.toml:4' \
  'statue_sensor\.health\.rate_max_valid_rad_s' 'rate_full_scale_rad_s' -- "${ARGS[@]}" \
  --config "$TMP/range.toml" --replay "$TMP/standing.log"

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
