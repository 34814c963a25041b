#!/usr/bin/env bash
# plinth-monitor replaying a three-component record with the P-wave stage (docs/pwave.md,
# docs/monitor.md "[pwave]"): Northridge-01 at Orr (RSN963, bundled), horizontal 090 with
# --vertical UP, scaled to 2.5 g, on the slender statue of the eval scenes (its [fragility]:
# 0.82 g). Checks: with [pwave], warning with cause p_wave before the physics' alarm, on the JSON
# lines and on the bus (AlarmEvent Cause 13), the status's "pwave" with one trigger; the alarm
# the same as without the stage; without [pwave] no "pwave" and no p_wave; refused: a replay
# without a vertical record, a scene without [fragility], a bad [pwave] value (key, line, limit).
#
# Environment: PLINTH_MONITOR, PLINTH_SIM, PLINTH_SOURCE_DIR.
set -u
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
BIN=${PLINTH_MONITOR:?}

R=$SRC/sim/data/records/pwave
H=$R/RSN963_NORTHR_ORR090.AT2
V=$R/RSN963_NORTHR_ORR-UP.AT2
SCENE=$SCENES/eval/ground-slender.toml
printf '[pwave]\n' >"$TMP/box.toml"

# The time and cause of the first event of a level in $TMP/stdout: "T CAUSE".
first_event() {
  grep "\"type\": \"alarm\".*\"level\": \"$1\"" "$TMP/stdout" | head -n 1 |
    sed -E 's/.*"t": ([-0-9.]+).*"cause": "([a-z_]+)".*/\1 \2/'
}

without_alarm=""
if expect_success "the record without the stage replays" --scene "$SCENE" --replay "$H" \
  --vertical "$V" --pga 2.5g --no-events; then
  without_alarm=$(first_event alarm)
  if grep -q '"pwave"' "$TMP/stdout" || grep -q '"cause": "p_wave"' "$TMP/stdout"; then
    fail "no stage without [pwave]" "$(grep -m 1 -o '"pwave": {[^}]*' "$TMP/stdout")"
  else
    pass "without [pwave] the status has no \"pwave\" and no event says p_wave"
  fi
fi

if expect_success "the three-component record replays with [pwave]" --scene "$SCENE" \
  --config "$TMP/box.toml" --replay "$H" --vertical "$V" --pga 2.5g --no-events \
  --frames-out "$TMP/frames.log"; then
  read -r warning_t warning_cause <<<"$(first_event warning)"
  read -r alarm_t alarm_cause <<<"$(first_event alarm)"
  if [[ "$warning_cause" == p_wave ]] && awk -v w="$warning_t" -v a="$alarm_t" \
    'BEGIN { exit !(w >= 0 && a > w + 1) }'; then
    pass "warning, cause p_wave, at $warning_t s, more than 1 s before the alarm at $alarm_t s"
  else
    fail "warning p_wave" "warning: $warning_t $warning_cause; alarm: $alarm_t $alarm_cause"
  fi
  if [[ "$alarm_t $alarm_cause" == "$without_alarm" && "$alarm_cause" != p_wave ]]; then
    pass "the alarm is the physics', as without the stage ($alarm_t s, $alarm_cause)"
  else
    fail "the alarm" "with the stage: $alarm_t $alarm_cause; without: $without_alarm"
  fi
  # AlarmEvent: Level warning (2), PreviousLevel normal (0) -> byte 0 02; Cause 13 -> byte 1 0D.
  if grep -qE ' 330#020D' "$TMP/frames.log"; then
    pass "the bus's AlarmEvent says warning, cause 13 (p_wave)"
  else
    fail "AlarmEvent on the bus" "$(grep ' 330#' "$TMP/frames.log" | head -n 3)"
  fi
  last=$(grep '"type": "status"' "$TMP/stdout" | tail -n 1 | grep -o '"pwave": {.*')
  if [[ "$last" == *'"triggers": 1,'* && "$last" == *'"onset_t": '* &&
    "$last" == *'"predicted_pga_g": '* ]]; then
    pass "the status's \"pwave\" shows one trigger, its onset and prediction"
  else
    fail "status pwave" "$last"
  fi
fi

expect_failure "the vertical channel without a vertical record is refused" \
  'RSN963_NORTHR_ORR090.AT2' 'no vertical record' '--vertical' 'pwave.channel' -- \
  --scene "$SCENE" --config "$TMP/box.toml" --replay "$H" --pga 2.5g

expect_failure "the stage without the scene's [fragility] is refused" \
  'box.toml: pwave' "\[fragility\]" -- \
  --scene "$SCENES/paper-isolated.toml" --config "$TMP/box.toml" --replay "$H" --vertical "$V"

printf '[pwave]\nchannel = "vertical"\nlowpass_hz = 150\n' >"$TMP/bad.toml"
expect_failure "a bad [pwave] value is named with its key, line and limit" \
  'bad.toml:3: pwave.lowpass_hz: must be below half the sample rate \(limit 100\)' -- \
  --scene "$SCENE" --config "$TMP/bad.toml" --replay "$H" --vertical "$V"

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
