#!/usr/bin/env bash
# plinth-replay run as a user would, writing candump logs (--log; the bus is the end-to-end
# tests' business): frame counts, decoded values against the resampled records
# (replay_log_check.py rebuilds every frame independently), sequence wrap, heartbeats, looping,
# log input, pacing (jitter printed, bounded only generously), Ctrl-C, then bad inputs, which
# must end with exit code 1 or 2 and a message on stderr naming the problem.
#
# Environment: PLINTH_REPLAY, the plinth-replay binary; PLINTH_SOURCE_DIR, the repository root.
set -u

# harness.sh wants PLINTH_SIM; this test needs no simulator, so plinth-replay stands in.
export PLINTH_SIM=${PLINTH_SIM:-${PLINTH_REPLAY:-}}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
BIN=${PLINTH_REPLAY:-}
if [[ ! -x "$BIN" ]]; then
  echo "PLINTH_REPLAY=$BIN: not an executable" >&2
  exit 2
fi
REPLAY=$BIN
AT2_270=$SRC/sim/data/records/irpinia1980_brienza_270.AT2
CHECK=$SRC/tests/cli/replay_log_check.py

# json_field NAME: the value of NAME in the --report-json line on stdout.
json_field() { grep -oE "\"$1\": [^,}]*" "$TMP/stdout" | head -n 1 | sed 's/^[^:]*: //'; }

HAVE_PYTHON=0
if command -v python3 >/dev/null 2>&1; then HAVE_PYTHON=1; fi

# check_log NAME LOG ARGS...: replay_log_check.py LOG ARGS must say ok.
check_log() {
  local name=$1
  shift
  if ((!HAVE_PYTHON)); then
    echo "ok - $name # SKIP no python3"
    return
  fi
  local result
  result=$(python3 "$CHECK" "$@" 2>&1)
  if [[ "$result" == ok:* ]]; then
    pass "$name ($result)"
  else
    fail "$name" "$result"
  fi
}

# ---------------------------------------------------------------------------------------------
# Good runs.

# Brienza 000 lasts 12063 x 0.0029 s = 34.9827 s: at 200 Hz, floor(34.9827 x 200) + 1 = 6997
# samples, and heartbeats at 0, 1, ..., 34 s.
if expect_success "one node, Brienza at 0.3g, --speed max: exit 0" --record "$AT2" --pga 0.3g \
  --rate 200 --speed max --log "$TMP/one.log" --report-json; then
  lines=$(wc -l <"$TMP/one.log")
  if ((lines == 6997 + 35)) && [[ "$(json_field frames_sent)" == 7032 ]] &&
    [[ "$(json_field acceleration_frames)" == 6997 ]] &&
    [[ "$(json_field heartbeat_frames)" == 35 ]]; then
    pass "one node: 6997 samples + 35 heartbeats, in the log and the report"
  else
    fail "one node: 6997 samples + 35 heartbeats, in the log and the report" \
      "$lines lines; report: $(head -c 300 "$TMP/stdout")"
  fi
  wall=$(json_field wall_time_s)
  if awk -v wall="$wall" 'BEGIN { exit !(wall < 10) }'; then
    pass "--speed max is fast: 35 s of record in $wall s"
  else
    fail "--speed max is fast" "35 s of record took $wall s"
  fi
  if [[ "$(json_field jitter_p99_us)" == null && "$(json_field speed)" == '"max"' ]]; then
    pass "--speed max: no jitter in the report"
  else
    fail "--speed max: no jitter in the report" "$(head -c 300 "$TMP/stdout")"
  fi
  check_log "one node: every frame decodes to the resampled record, sequence wraps 255 -> 0" \
    "$TMP/one.log" --rate 200 --pga 0.3 --axis "1:x:$AT2"
  # The counter of the 257th sample is 0 again: it wrapped.
  seq_257=$(grep ' 301#' "$TMP/one.log" | sed -n 257p | cut -c 43-44)
  if [[ "$seq_257" == 00 ]]; then
    pass "sequence of the 257th sample is 00"
  else
    fail "sequence of the 257th sample is 00" "got '$seq_257'"
  fi
  # At rest the sensor reads +1 g up: az of the first sample is 4000 x 0.25 mg = 0x0FA0.
  if head -n 2 "$TMP/one.log" | grep -qE ' 301#[0-9A-F]{8}A00F'; then
    pass "az reads +1 g at rest"
  else
    fail "az reads +1 g at rest" "$(head -n 2 "$TMP/one.log" | tr '\n' ' ')"
  fi
fi

# Three nodes: node 1 carries both horizontals, node 2 the 270 component on x, node 3 the 000
# component as vertical; all at 500 Hz for 3 s.
if expect_success "three nodes, --record-y and --node-record: exit 0" --record "$AT2" \
  --record-y "$AT2_270" --node-record "2:x:$AT2_270" --node-record "3:z:$AT2" --scale 2 \
  --rate 500 --t-end 3 --speed max --log "$TMP/three.log" --log-interface can1; then
  check_log "three nodes: every frame of every node" "$TMP/three.log" --rate 500 --scale 2 \
    --t-end 3 --interface can1 --axis "1:x:$AT2" --axis "1:y:$AT2_270" --axis "2:x:$AT2_270" \
    --axis "3:z:$AT2"
fi

if expect_success "--loop 3 --t-end 1: exit 0" --record "$AT2" --t-end 1 --loop 3 --speed max \
  --log "$TMP/loop.log"; then
  check_log "--loop 3: samples, sequence and heartbeats run on across loops" "$TMP/loop.log" \
    --rate 200 --t-end 1 --loops 3 --axis "1:x:$AT2"
fi

# A CSV with a vertical column drives z of the same node; --scale 100 (30 g) saturates.
printf 't,a [g],v [g]\n0,0,0\n0.01,0.1,-0.2\n0.02,-0.05,0.3\n0.03,0,0\n' >"$TMP/vertical.csv"
if expect_success "CSV with a vertical column: exit 0" --record "$TMP/vertical.csv" --rate 100 \
  --speed max --log "$TMP/vertical.log"; then
  check_log "CSV with a vertical column: az = 1 g + v" "$TMP/vertical.log" --rate 100 \
    --axis "1:x:$TMP/vertical.csv" --axis "1:z:$TMP/vertical.csv:v"
fi
if expect_success "--scale 100 (beyond full scale): exit 0" --record "$TMP/vertical.csv" \
  --rate 100 --scale 100 --speed max --log "$TMP/saturated.log"; then
  check_log "--scale 100: clamped to full scale with the saturated flag" "$TMP/saturated.log" \
    --rate 100 --scale 100 --axis "1:x:$TMP/vertical.csv" --axis "1:z:$TMP/vertical.csv:v"
fi

# A candump log as input: its sensor frames go out again at their logged times.
{
  echo "(1700000000.000000) vcan0 12345678#00"
  echo "(1700000000.000100) vcan0 320#0000000000000000"
  cat "$TMP/loop.log"
} >"$TMP/mixed.log"
if expect_success "candump log input: exit 0" --record "$TMP/mixed.log" --speed max \
  --log "$TMP/again.log" --report-json; then
  check_log "candump log input: the same frames at the same relative times" "$TMP/again.log" \
    --same-as "$TMP/loop.log"
  if [[ "$(json_field skipped_log_lines)" == 2 ]]; then
    pass "candump log input: the extended and the monitor frame are skipped and counted"
  else
    fail "candump log input: the extended and the monitor frame are skipped and counted" \
      "$(head -c 300 "$TMP/stdout")"
  fi
fi

# Pacing in real time: 0.5 s at 1000 Hz is 501 deadlines 1 ms apart.
if expect_success "--speed 1, 0.5 s at 1000 Hz: exit 0" --record "$AT2" --t-end 0.5 --rate 1000 \
  --speed 1 --log "$TMP/paced.log" --report-json; then
  wall=$(json_field wall_time_s)
  p50=$(json_field jitter_median_us)
  p99=$(json_field jitter_p99_us)
  max=$(json_field jitter_max_us)
  echo "# pacing jitter at --speed 1, 1000 Hz, 0.5 s: median $p50 us, p99 $p99 us," \
    "max $max us; wall $wall s"
  if awk -v w="$wall" 'BEGIN { exit !(w >= 0.49 && w < 2.0) }'; then
    pass "--speed 1 takes real time (0.5 s of record in $wall s)"
  else
    fail "--speed 1 takes real time" "0.5 s of record in $wall s"
  fi
  # Generous: a loaded CI machine may be late by milliseconds, never by 50.
  if awk -v p="$p99" 'BEGIN { exit !(p != "" && p != "null" && p < 50000) }'; then
    pass "--speed 1: jitter p99 under 50 ms"
  else
    fail "--speed 1: jitter p99 under 50 ms" "p99 '$p99'"
  fi
fi
if expect_success "--speed 2: exit 0" --record "$AT2" --t-end 0.5 --rate 1000 --speed 2 \
  --log "$TMP/fast.log" --report-json; then
  wall=$(json_field wall_time_s)
  if awk -v w="$wall" 'BEGIN { exit !(w >= 0.245 && w < 1.5) }'; then
    pass "--speed 2 takes half the time (0.5 s of record in $wall s)"
  else
    fail "--speed 2 takes half the time" "0.5 s of record in $wall s"
  fi
  check_log "--speed 2: the log keeps the record's times" "$TMP/fast.log" --same-as "$TMP/paced.log"
fi

# Ctrl-C: stops at once, with the report, exit 130, and a log that is whole up to there, kept
# as interrupted.log.partial (never under the name of a complete log).
"$REPLAY" --record "$AT2" --speed 1 --log "$TMP/interrupted.log" --report-json \
  >"$TMP/stdout" 2>"$TMP/stderr" &
replay_pid=$!
# Interrupted once some frames are logged (on a loaded machine the start-up alone can take a
# while): poll the log being written (interrupted.log.partial-PID until it ends) for up to
# 120 s rather than sleeping a fixed time.
for _ in $(seq 1200); do
  (($(cat "$TMP"/interrupted.log.partial-* 2>/dev/null | wc -l) > 100)) && break
  sleep 0.1
done
kill -INT "$replay_pid"
wait "$replay_pid"
RC=$?
if ((RC == 130)) && [[ "$(json_field interrupted)" == true ]] &&
  grep -q "frames sent" "$TMP/stderr"; then
  pass "Ctrl-C: exit 130 with the report"
else
  fail "Ctrl-C: exit 130 with the report" "exit $RC; stdout: $(head -c 200 "$TMP/stdout")"
fi
PARTIAL=$TMP/interrupted.log.partial
if [[ -e "$TMP/interrupted.log" ]]; then
  fail "Ctrl-C: no log under the complete log's name" "interrupted.log exists"
else
  pass "Ctrl-C: no log under the complete log's name"
fi
if ((HAVE_PYTHON)) && [[ -f "$PARTIAL" ]] &&
  python3 "$CHECK" "$PARTIAL" --same-as "$PARTIAL" >/dev/null && (($(wc -l <"$PARTIAL") > 100)); then
  pass "Ctrl-C: the log is whole up to the stop ($(wc -l <"$PARTIAL") lines, in .partial)"
elif ((HAVE_PYTHON)); then
  fail "Ctrl-C: the log is whole up to the stop" "$(wc -l <"$PARTIAL" 2>&1) lines"
fi

# ---------------------------------------------------------------------------------------------
# Bad inputs.

NOFILE='cannot open|no such file|not found|does not exist'
LOG=(--speed max --log "$TMP/bad.log")

sed '10s/^\( *\)[-+.0-9Ee]*/\1NaN/' "$AT2" >"$TMP/poisoned.AT2"
{
  head -n 5 "$TMP/loop.log"
  echo "(1700000000.123456) vcan0 301#0011223344556"
} >"$TMP/malformed.log"
printf '(1700000000.123456) vcan0 301#00112233445566778899\n' >"$TMP/long.log"
printf '(1700000000.12345) vcan0 301#0011223344556677\n' >"$TMP/timestamp.log"
printf '(1700000000.123456) vcan0 320#0000000000000000\n' >"$TMP/no-sensor.log"
cp "$TMP/vertical.csv" "$TMP/record.txt"

expect_failure "missing record file" 'no-such\.AT2' "$NOFILE" -- \
  --record "$TMP/no-such.AT2" "${LOG[@]}"
expect_failure "missing --record-y file" 'no-such-y\.AT2' "$NOFILE" -- --record "$AT2" \
  --record-y "$TMP/no-such-y.AT2" "${LOG[@]}"
expect_failure "NaN in an AT2 record" 'poisoned\.AT2:10' 'finite|not a number|nan' -- \
  --record "$TMP/poisoned.AT2" "${LOG[@]}"
expect_failure "unknown record format" 'record\.txt' 'AT2|csv|log' -- \
  --record "$TMP/record.txt" "${LOG[@]}"
expect_failure "malformed log line (truncated hex)" 'malformed\.log:6' \
  'odd number of hex digits' -- \
  --record "$TMP/malformed.log" "${LOG[@]}"
expect_failure "log line with 10 data bytes" 'long\.log:1' '10 data bytes' -- \
  --record "$TMP/long.log" "${LOG[@]}"
expect_failure "log line with a 5-decimal timestamp" 'timestamp\.log:1' 'timestamp' -- \
  --record "$TMP/timestamp.log" "${LOG[@]}"
expect_failure "log without sensor frames" 'no-sensor\.log' 'no sensor frames' -- \
  --record "$TMP/no-sensor.log" "${LOG[@]}"
expect_failure "--rate with a log input" '--rate' 'candump log' -- --record "$TMP/loop.log" \
  --rate 500 "${LOG[@]}"
expect_failure "--rate 50 (below 100 Hz)" '--rate' '100' -- --record "$AT2" --rate 50 "${LOG[@]}"
expect_failure "--rate 2000 (above 1000 Hz)" '--rate' '1000' -- \
  --record "$AT2" --rate 2000 "${LOG[@]}"
expect_failure "--rate nan" '--rate' -- --record "$AT2" --rate nan "${LOG[@]}"
expect_failure "--rate abc" '--rate' -- --record "$AT2" --rate abc "${LOG[@]}"
expect_failure "--pga without a unit" '--pga' 'unit' -- --record "$AT2" --pga 0.3 "${LOG[@]}"
expect_failure "--pga with an unknown unit" '--pga' 'furlongs' -- \
  --record "$AT2" --pga 0.3furlongs "${LOG[@]}"
expect_failure "--pga negative" '--pga' 'greater than zero' -- \
  --record "$AT2" --pga -0.3g "${LOG[@]}"
expect_failure "--pga nan" '--pga' -- --record "$AT2" --pga nang "${LOG[@]}"
expect_failure "--pga with --scale" '--pga|--scale' -- \
  --record "$AT2" --pga 0.3g --scale 2 "${LOG[@]}"
expect_failure "--scale nan" '--scale' -- --record "$AT2" --scale nan "${LOG[@]}"
expect_failure "--speed 0" '--speed' "from 0.001 to 1e\+06, or 'max'" -- --record "$AT2" --speed 0 \
  --log "$TMP/bad.log"
expect_failure "--speed fast" '--speed' "'fast'" -- \
  --record "$AT2" --speed fast --log "$TMP/bad.log"
expect_failure "--node 16" '--node' -- --record "$AT2" --node 16 "${LOG[@]}"
expect_failure "--node 0" '--node' -- --record "$AT2" --node 0 "${LOG[@]}"
expect_failure "--node-record without a node" '--node-record' 'NODE' -- --record "$AT2" \
  --node-record "$AT2" "${LOG[@]}"
expect_failure "--node-record node 16" '--node-record' '16' -- --record "$AT2" \
  --node-record "16:x:$AT2" "${LOG[@]}"
expect_failure "--node-record for an axis given twice" 'node 1 axis x' 'already' -- \
  --record "$AT2" --node-record "1:x:$AT2_270" "${LOG[@]}"
expect_failure "--loop 0" '--loop' -- --record "$AT2" --loop 0 "${LOG[@]}"
expect_failure "--t-end 0" '--t-end' -- --record "$AT2" --t-end 0 "${LOG[@]}"
expect_failure "neither --can nor --log" '--can' '--log' -- --record "$AT2"
expect_failure "both --can and --log" '--can|--log' -- --record "$AT2" --can vcan0 "${LOG[@]}"
expect_failure "unwritable --log" '/nonexistent/dir/x\.log' 'cannot open|does not exist' -- --record "$AT2" \
  --speed max --log /nonexistent/dir/x.log
expect_failure "--log-interface too long" 'interface' '15' -- --record "$AT2" \
  --log-interface a_very_long_interface "${LOG[@]}"
# No such interface (or no CAN at all in this kernel): the socket's reason, naming it.
expect_failure "--can on an interface that does not exist" 'nosuchcan0' -- --record "$AT2" \
  --speed max --can nosuchcan0

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
