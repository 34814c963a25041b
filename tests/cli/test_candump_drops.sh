#!/usr/bin/env bash
# A candump log that says it lost frames (candump -d's "DROPCOUNT: dropped N CAN frames on 'IF'
# socket (total drops T)" lines; issue 36) through plinth-monitor --replay and plinth-replay,
# --log-drops warn (the default) and refuse (docs/record-formats.md, "Frames a log lost"):
#  1. logs the real candump wrote under overflow: tests/data/candump/overflow.log (and, with
#     --real-log LOG, another: tests/integration/candump_overflow.sh's live one);
#  2. a quiet sensor's log with frames cut out and a DROPCOUNT line in their place: the bus
#     fault from the frame after it (as a live overflow raises it) and its end, the counts, the
#     summary, exit 3, the sensor's missing samples; twelve of them (ten named, all counted);
#     refuse; malformed DROPCOUNT lines; the option where it means nothing; --log-time and
#     --log-drops each on its own;
#  3. the event recorder: a capture of a run that lost frames holds the DROPCOUNT line and counts
#     the loss in its JSON, and replays with the same loss.
# Environment: PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_SIM, PLINTH_SOURCE_DIR.
# Usage: test_candump_drops.sh [--real-log LOG]   (only section 1, on LOG)
# shellcheck disable=SC2034  # BIN: harness.sh's run takes it
set -u

# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
MONITOR=${PLINTH_MONITOR:-}
REPLAY=${PLINTH_REPLAY:-}
for binary in "$MONITOR" "$REPLAY"; do
  if [[ ! -x "$binary" ]]; then
    echo "PLINTH_MONITOR, PLINTH_REPLAY: '$binary' is not an executable" >&2
    exit 2
  fi
done
ISOLATED=$SCENES/paper-isolated.toml
real_logs=("$SRC/tests/data/candump/overflow.log")
only_real=0
if [[ "${1:-}" == "--real-log" ]]; then
  real_logs=("$(realpath "${2:?usage: $0 [--real-log LOG]}")")
  only_real=1
fi

# ere TEXT: TEXT as an extended regular expression that matches it literally.
# shellcheck disable=SC2016  # a sed expression, not the shell's
ere() { printf '%s' "$1" | sed 's/[].[*^$()+?{}|\\]/\\&/g'; }
# summary EXPR: a Python expression over the summary line `s` of the last run's stdout.
summary() {
  python3 -c 'import json, sys
lines = [json.loads(l) for l in open(sys.argv[1]) if l.startswith("{")]
s = next(l for l in lines if l.get("type") == "summary")
alarms = [l for l in lines if l.get("type") == "alarm"]
alarms_after = [a for a in alarms if a["t"] > 4.5]  # after the start-up (section 2)
print(eval(sys.argv[2]))' "$TMP/stdout" "$1"
}
# expect_equal NAME GOT WANT
expect_equal() {
  if [[ "$2" == "$3" ]]; then pass "$1"; else fail "$1" "got '$2', expected '$3'"; fi
}
# expect_stderr NAME ERE: the last run's stderr has a line matching ERE.
expect_stderr() {
  if grep -qE -- "$2" "$TMP/stderr"; then
    pass "$1"
  else
    fail "$1" "$(head -c 400 "$TMP/stderr")"
  fi
}
# drop_facts LOG: sets reports, lost (all its DROPCOUNT lines) and first_line, first_count,
# first_name (the first one's line number, count and socket).
drop_facts() {
  reports=$(grep -c '^DROPCOUNT: ' "$1")
  lost=$(awk '/^DROPCOUNT: / { n += $3 } END { print n + 0 }' "$1")
  local first
  first=$(grep -n -m 1 '^DROPCOUNT: ' "$1")
  first_line=${first%%:*}
  first_count=$(awk '{ print $3 }' <<<"${first#*:}")
  first_name=$(sed -E "s/.* on '([^']+)' socket.*/\\1/" <<<"$first")
}
# replay_counts: from the last run's plinth-replay --report-json, the log's DROPCOUNT lines, the
# frames they say were lost, the frames sent.
replay_counts() {
  python3 -c 'import json, sys; r = json.loads(open(sys.argv[1]).read().splitlines()[-1])
print(r["log_drop_reports"], r["log_dropped_frames"], r["frames_sent"])' "$TMP/stdout"
}
# frames_word N: "frame" or "frames", as candump and the messages say it.
frames_word() { if (($1 == 1)); then echo frame; else echo frames; fi; }

echo "# 1. logs the real candump wrote under overflow"
for log in "${real_logs[@]}"; do
  name=$(basename "$log")
  drop_facts "$log"
  said="$(ere "$log"):$first_line: candump lost $first_count CAN $(frames_word "$first_count")"
  said+=" on '$(ere "$first_name")' before this line"
  said+=" \\(its socket overflowed; [0-9]+ in all so far\\)"
  BIN=$MONITOR
  run --scene "$ISOLATED" --replay "$log" --startup-window 0.5 --no-events
  expect_equal "$name: monitor, warn: exit 3 (the box cannot vouch for a log that lost frames)" \
    "$RC" 3
  expect_equal "$name: monitor: the summary counts $reports DROPCOUNT lines, $lost frames" \
    "$(summary '(s["alarm"], s["input_fault"], s["log_drops"])')" \
    "('fault', 'log_drops', {'reports': $reports, 'frames': $lost})"
  expect_stderr "$name: monitor: the first loss named with its line and count" \
    "^plinth-monitor: warning: $said\$"
  expect_stderr "$name: monitor: the run's fault names it and the totals" \
    "^plinth-monitor: fault: $said \\($lost frames lost in $reports DROPCOUNT lines in all\\)\$"
  expect_failure "$name: monitor, --log-drops refuse: stops at the first" \
    "^plinth-monitor: error: $said \\(--log-drops refuse\\)\$" -- \
    --scene "$ISOLATED" --replay "$log" --log-drops refuse
  BIN=$REPLAY
  sensor_frames=$(grep -cE '^\([0-9.]+\) [^ ]+ 3[013][1-9A-F]#' "$log")
  if expect_success "$name: replay, warn: sent as logged" --record "$log" --speed max \
    --log "$name.out.log" --report-json; then
    expect_equal "$name: replay: its report counts the loss; every sensor frame sent" \
      "$(replay_counts)" \
      "$reports $lost $sensor_frames"
    expect_stderr "$name: replay: the first loss named with its line and count" \
      "^plinth-replay: warning: $said: not in the log, not sent\$"
    expect_equal "$name: replay: its own log has no DROPCOUNT line (it lost nothing)" \
      "$(grep -c DROPCOUNT "$name.out.log")" 0
  fi
  expect_failure "$name: replay, --log-drops refuse: stops at the first" \
    "^plinth-replay: error: $said \\(--log-drops refuse\\)\$" -- \
    --record "$log" --speed max --log "$name.refused.log" --log-drops refuse
  if [[ -e "$name.refused.log" ]]; then fail "$name: replay, refused: no log" "written"; fi
done
if ((only_real)); then
  echo "$PASSED passed, $FAILED failed"
  ((FAILED == 0))
  exit
fi

echo "# 2. a quiet sensor's log that lost frames"
# 12 s of a resting sensor at 200 Hz with a 1 LSB dither (the stuck-sensor check stays quiet),
# as plinth-replay sends it; then the five frames after line CUT cut out and a DROPCOUNT line
# in their place, 6 s in (the box normal since its start-up: window 2 s, fault held 2 s).
awk 'BEGIN { print "t,quiet [m/s2]"; split("0 1 0 -1", d, " ")
  for (k = 0; k < 2400; k++) printf "%.6f,%.10g\n", k / 200, d[k % 4 + 1] * 0.00025 * 9.80665 }' \
  >quiet.csv
"$REPLAY" --record quiet.csv --speed max --log quiet.log 2>/dev/null
CUT=$(grep -n -m 1 -E '^\(0*[0-9]+\.[0-9]+\) vcan0 301#' quiet.log | cut -d: -f1)
CUT=$((CUT + 6 * 201))  # 6 s: 200 sensor frames and a heartbeat a second
drop_line='DROPCOUNT: dropped 5 CAN frames on '\''vcan0'\'' socket (total drops 5)'
awk -v cut="$CUT" -v drop="$drop_line" 'NR == cut + 1 { print drop } NR <= cut || NR > cut + 5' \
  quiet.log >drops.log
first=$(grep -m 1 -E ' 301#' drops.log)
# relative_t LINE: the time of LINE of drops.log since its first sensor frame (monitor time), s
relative_t() {
  local line
  line=$(sed -n "$1p" drops.log)
  awk -v a="${line%%)*}" -v f="${first%%)*}" 'BEGIN { printf "%.3f", substr(a, 2) - substr(f, 2) }'
}
before_t=$(relative_t "$CUT")       # the last frame before the loss
after_t=$(relative_t $((CUT + 2)))  # the first after it
BIN=$MONITOR
run --scene "$ISOLATED" --replay drops.log --no-events
expect_equal "monitor: a log that lost frames ends exit 3, input fault log_drops" "$RC" 3
expect_equal "monitor: the summary: 1 report, 5 frames; the sensor's 5 samples missing; the \
box's own socket dropped none" \
  "$(summary '(s["input_fault"], s["log_drops"], s["sensor"]["missing"],
               s["bus_dropped_frames"], s["log_time"]["went_back"])')" \
  "('log_drops', {'reports': 1, 'frames': 5}, 5, 0, 0)"
lost_five="drops\\.log:$((CUT + 1)): candump lost 5 CAN frames on 'vcan0' before this line"
expect_stderr "monitor: the loss named with its line" \
  "^plinth-monitor: warning: $lost_five \\(its socket overflowed; 5 in all so far\\)\$"
# As a live box sees its socket overflow: reported with the first frame after the loss, the
# fault (cause bus_error) raised at the newest frame's time before it; cleared once 2 s of
# frames have passed (kInputFaultHoldS), the level normal again after its 2 s fall. Between,
# the level stays fault while its cause changes (the samples missing, the estimator's restart:
# an event each, docs/safety.md).
expect_equal "monitor: after the start-up, the fault (bus_error) first, fault until normal again" \
  "$(summary '(alarms_after[0]["cause"], {a["level"] for a in alarms_after[:-1]},
               alarms_after[-1]["level"])')" \
  "('bus_error', {'fault'}, 'normal')"
raised=$(summary 'alarms_after[0]["t"]')
cleared=$(summary 'alarms_after[-1]["t"]')
if awk -v r="$raised" -v b="$before_t" -v a="$after_t" -v c="$cleared" \
  'BEGIN { exit !(r >= b && r < a && c >= a + 2 && c <= a + 4.1) }'; then
  pass "monitor: the fault at $raised s (the loss between $before_t and $after_t s), normal at \
$cleared s"
else
  fail "monitor: the fault at the loss, normal 2-4 s later" \
    "fault at $raised s, normal at $cleared s; the loss between $before_t and $after_t s"
fi
expect_failure "monitor: --log-drops refuse stops at the loss" \
  "^plinth-monitor: error: $lost_five .*\\(--log-drops refuse\\)\$" \
  -- --scene "$ISOLATED" --replay drops.log --log-drops refuse
run --scene "$ISOLATED" --replay drops.log --log-time refuse --no-events
expect_equal "monitor: --log-time refuse leaves the loss to --log-drops (warn: exit 3)" "$RC" 3

# Twelve losses: the first ten named, every one counted.
awk -v cut="$CUT" 'NR > cut && NR <= cut + 12 * 50 && (NR - cut) % 50 == 0 {
  n++; printf "DROPCOUNT: dropped %d CAN frame%s on '\''vcan0'\'' socket (total drops %d)\n", n,
  (n > 1 ? "s" : ""), n * (n + 1) / 2 } { print }' quiet.log >many.log
run --scene "$ISOLATED" --replay many.log --no-events
expect_equal "monitor: 12 losses: 10 named, the last of them says the rest are counted" \
  "$(grep -c 'warning: many\.log:.*candump lost' "$TMP/stderr") $(grep -c \
    'further ones are counted in the summary' "$TMP/stderr")" \
  "10 1"
expect_equal "monitor: 12 losses, 78 frames, all counted" "$(summary 's["log_drops"]')" \
  "{'reports': 12, 'frames': 78}"

# A malformed DROPCOUNT line is refused whatever the policy, naming the line.
zero_line="DROPCOUNT: dropped 0 CAN frames on 'vcan0' socket (total drops 0)"
awk -v cut="$CUT" -v zero="$zero_line" 'NR == cut { print zero } { print }' quiet.log >zero.log
sed "${CUT}i DROPCOUNT: dropped 5 CAN frames on vcan0" quiet.log >cut-short.log
for policy in warn refuse; do
  expect_failure "monitor, --log-drops $policy: a DROPCOUNT count of 0 is refused" \
    "zero\\.log:$CUT: DROPCOUNT line: the count '0' is not a number of frames from 1 to \
4294967295" \
    -- --scene "$ISOLATED" --replay zero.log --log-drops "$policy"
done
expect_failure "monitor: a DROPCOUNT line cut short is refused" \
  "cut-short\\.log:$CUT: expected a DROPCOUNT line as candump -d writes it" \
  -- --scene "$ISOLATED" --replay cut-short.log
expect_failure "monitor: --log-drops with a record is refused" \
  '--log-drops: applies to a candump log' -- --scene "$ISOLATED" --replay "$AT2" --log-drops warn
expect_failure "monitor: an unknown --log-drops" \
  "--log-drops: unknown policy 'ignore' \\(one of warn, refuse\\)" \
  -- --scene "$ISOLATED" --replay drops.log --log-drops ignore

BIN=$REPLAY
if expect_success "replay: a log that lost frames is sent as logged" --record drops.log \
  --speed max --log drops-out.log --report-json; then
  expect_equal "replay: the report counts the loss" \
    "$(replay_counts)" \
    "1 5 $(grep -c ' 3[01]1#' drops.log)"
  expect_stderr "replay: the loss named with its line" \
    "^plinth-replay: warning: $lost_five .*: not in the log, not sent\$"
  expect_stderr "replay: and counted" \
    "^plinth-replay: warning: drops\\.log: 5 frames lost in 1 DROPCOUNT lines, not sent \
\\(--log-drops refuse stops at the first\\)\$"
fi
expect_failure "replay: --log-drops refuse stops at the loss" \
  "$lost_five .*\\(--log-drops refuse\\)" \
  -- --record drops.log --speed max --log refused.log --log-drops refuse
expect_failure "replay: a DROPCOUNT count of 0 is refused" \
  "zero\\.log:$CUT: DROPCOUNT line: the count '0'" -- --record zero.log --speed max --log z.log
expect_failure "replay: --log-drops with a record is refused" \
  '--log-drops: applies to a candump log' -- --record "$AT2" --speed max --log r.log \
  --log-drops refuse

echo "# 3. the event recorder's capture of a run that lost frames"
# The quick start's record (paper-eccentric, Buia x6.5: warning, then alarm) after 3 s of the
# quiet sensor (the box's start-up), as plinth-replay sends it; five frames lost 1 s before the
# first warning, inside the capture's 5 s before it.
EXCITED=$SCENES/paper-eccentric.toml
python3 - "$SRC/sim/data/records/friuli1976-09-15_buia_000.AT2" >quake.csv <<'PY'
import re, sys
lines = open(sys.argv[1]).read().splitlines()
npts, dt = re.search(r"NPTS=\s*(\d+), DT=\s*([.0-9]+)", lines[3]).groups()
values = [float(x) for line in lines[4:] for x in line.split()][:int(npts)]
print("t,buia x6.5 [m/s2]")
for k in range(600):  # 3 s at 200 Hz, a 1 LSB dither
    print("%.6f,%.10g" % (k / 200, (0, 1, 0, -1)[k % 4] * 0.00025 * 9.80665))
for i, v in enumerate(values):
    print("%.6f,%.10g" % (3 + i * float(dt), 6.5 * v * 9.80665))
PY
"$REPLAY" --record quake.csv --speed max --log quake.log 2>/dev/null
BIN=$MONITOR
run --scene "$EXCITED" --replay quake.log --no-events
warning_t=$(summary 'next(a["t"] for a in alarms if a["level"] in ("warning", "alarm"))')
first=$(grep -m 1 -E ' 301#' quake.log)
cut=$(awk -v w="$warning_t" -v f="${first%%)*}" '$3 ~ /^301#/ &&
  substr($1, 2, length($1) - 2) - substr(f, 2) >= w - 1 { print NR; exit }' quake.log)
awk -v cut="$cut" -v drop="$drop_line" 'NR == cut + 1 { print drop } NR <= cut || NR > cut + 5' \
  quake.log >quake-drops.log
run --scene "$EXCITED" --replay quake-drops.log --no-events --record-dir events --pre-trigger 5 \
  --post-trigger 2
expect_equal "recorder: one capture written of the run that lost frames" \
  "$RC $(summary 's["recorder"]["captures_written"]')" "3 1"
capture_json=$(find events -name 'event-*.json' | head -n 1)
capture_log=${capture_json%.json}.log
expect_equal "recorder: the capture's JSON counts the loss" \
  "$(python3 -c 'import json, sys; d = json.load(open(sys.argv[1]))
print(d["input_frames_lost"], d["input_loss_reports"])' "$capture_json")" \
  "5 1"
# The frame before the loss (line cut), then in the capture (interface can0) the line after it.
read -r stamp _ frame < <(sed -n "${cut}p" quake-drops.log)
expect_equal "recorder: the capture has candump's DROPCOUNT line where the frames were lost" \
  "$(awk -v t="$stamp" -v f="$frame" 'found { print; exit } $1 == t && $3 == f { found = 1 }' \
    "$capture_log")" "DROPCOUNT: dropped 5 CAN frames on 'can0' socket (total drops 5)"
run --scene "$EXCITED" --replay "$capture_log" --no-events
expect_equal "recorder: the capture replays with the same loss" \
  "$RC $(summary 's["log_drops"]')" "3 {'reports': 1, 'frames': 5}"

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
