#!/usr/bin/env bash
# Every option means something (issue 25, item 3), for every program:
#  1. every option that takes a value, and every positional argument, of every program and
#     subcommand, read from its --help, given an empty value: refused as a usage error (exit 2)
#     naming the option, never taken as absent and never run;
#  2. an option that has no effect in the mode the command line chose: refused, with the reason;
#  3. compound values split as documented, an unknown part named.
# Prints "ok - <name>" or "not ok - <name>: <why>" per check, then "N passed, M failed".
#
# Environment: PLINTH_SIM, PLINTH_SWEEP, PLINTH_EVAL, PLINTH_ACCURACY, PLINTH_MONITOR,
# PLINTH_REPLAY, PLINTH_EMBED, PLINTH_COMMISSION (the binaries); PLINTH_SOURCE_DIR, the
# repository root.
set -u

# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
TIMEOUT=(timeout -k 5 60)
SWEEP=${PLINTH_SWEEP:-}
EVAL=${PLINTH_EVAL:-}
ACCURACY=${PLINTH_ACCURACY:-}
MONITOR=${PLINTH_MONITOR:-}
REPLAY=${PLINTH_REPLAY:-}
EMBED=${PLINTH_EMBED:-}
COMMISSION=${PLINTH_COMMISSION:-}
for binary in "$SWEEP" "$EVAL" "$ACCURACY" "$MONITOR" "$REPLAY" "$EMBED" "$COMMISSION"; do
  if [[ ! -x "$binary" ]]; then
    echo "PLINTH_SWEEP, PLINTH_EVAL, PLINTH_ACCURACY, PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_EMBED," \
      "PLINTH_COMMISSION: '$binary' is not an executable" >&2
    exit 2
  fi
done
S=$SCENES/paper-isolated.toml
cp "$SRC/tests/cli/harness.sh" log.log  # any file: nothing is read before the refusal

# The options of a --help text that take a value (a type after the name), one per line.
value_options() {
  grep -oE '^  +(-[a-z], ?)?--[a-z0-9-]+ +(TEXT|FLOAT|INT|UINT)' | grep -oE -- '--[a-z0-9-]+'
}
# Its positional arguments (a lower-case name with a type, no dashes), one per line.
positionals() {
  sed -n '/^Positionals:/,/^[A-Z]/p' | grep -oE '^  +[a-z_]+ +(TEXT|FLOAT|INT)' | awk '{print $1}'
}

# walk NAME BINARY [SUBCOMMAND] -- BASE...: each value option of BINARY [SUBCOMMAND] with an
# empty value after BASE (whose own value for it is dropped), then each positional empty. In
# BASE, @ stands for the positional: a.csv for the options, empty for the positional's case.
walk() {
  local name=$1 binary=$2
  shift 2
  local sub=()
  if [[ "$1" != "--" ]]; then
    sub=("$1")
    shift
  fi
  shift
  local base=("${@/#@/a.csv}")
  local empty_positional=("${@/#@/}")
  local help
  help=$("$binary" "${sub[@]}" --help 2>&1)
  local options
  options=$(value_options <<<"$help")
  if [[ -z "$options" && -z "$(positionals <<<"$help")" ]]; then
    fail "$name: its --help lists options" "none found"
    return
  fi
  local option
  for option in $options; do
    # BASE without OPTION and its value.
    local args=() i=0
    while ((i < ${#base[@]})); do
      if [[ "${base[i]}" == "$option" ]]; then
        i=$((i + 2))
        continue
      fi
      args+=("${base[i]}")
      i=$((i + 1))
    done
    BIN=$binary
    run "${sub[@]}" "${args[@]}" "$option" ""
    if ((RC != 2)); then
      fail "$name $option ''" "exit $RC, expected 2 (a usage error); stderr: $(first_stderr_line)"
    elif ! grep -qF -- "$option" "$TMP/stderr"; then
      fail "$name $option ''" "the message does not name $option: $(first_stderr_line)"
    else
      pass "$name $option '' is refused, naming it"
    fi
  done
  local positional
  for positional in $(positionals <<<"$help"); do
    BIN=$binary
    if [[ "${empty_positional[*]}" == "${base[*]}" ]]; then
      run "${sub[@]}" "${base[@]}" ""  # a list of them: one more, empty
    else
      run "${sub[@]}" "${empty_positional[@]}"
    fi
    if ((RC == 2)) && grep -qF -- "$positional: empty value" "$TMP/stderr"; then
      pass "$name: an empty $positional is refused, naming it"
    else
      fail "$name: an empty $positional" "exit $RC; stderr: $(first_stderr_line)"
    fi
  done
}

echo "# 1. an empty value, every option of every program"
walk plinth-sim "$SIM" -- --scene "$S" --record "$AT2"
walk plinth-sweep "$SWEEP" -- --scene "$S" --record "$AT2" --param T --from 1 --to 2 --steps 2 \
  --out out.csv
walk "plinth-sweep merge" "$SWEEP" merge -- --out merged.csv a.csv
walk "plinth-sweep plot" "$SWEEP" plot -- @ --out a.png
walk "plinth-eval run" "$EVAL" run -- --scene "$S" --record "$AT2" --out runs.csv
walk "plinth-eval report" "$EVAL" report -- @
walk "plinth-eval merge" "$EVAL" merge -- --out merged.csv a.csv
walk plinth-accuracy "$ACCURACY" -- --quick
walk plinth-monitor "$MONITOR" -- --scene "$S" --replay "$AT2"
walk plinth-replay "$REPLAY" -- --record "$AT2" --log out.log
walk plinth-embed-record "$EMBED" -- --name n --scene "$S" --replay "$AT2" --out out.cpp
walk plinth-commission "$COMMISSION" -- --config box.toml --log log.log

echo "# 2. an option with no effect in the mode chosen: refused with the reason"
# refused NAME BINARY PATTERN -- ARGS...: exit 1 or 2, stderr matching PATTERN.
refused() {
  local name=$1
  BIN=$2
  shift 2
  expect_failure "$name" "$@"
}
refused "sim: --out-interval without --out" "$SIM" '--out-interval: .*without --out' \
  -- --scene "$S" --record "$AT2" --out-interval 0.01
refused "sweep: --event in a one-parameter sweep" "$SWEEP" '--event: .*two-parameter map' \
  -- --scene "$S" --record "$AT2" --param T --from 1 --to 2 --steps 2 --event rocking --out o.csv
refused "sweep: --from2 without --param2" "$SWEEP" '--from2: .*--param2 is not given' \
  -- --scene "$S" --record "$AT2" --param T --from 1 --to 2 --steps 2 --from2 3 --out o.csv
refused "sweep: --mu-steps without --impulse-map" "$SWEEP" '--mu-steps: .*impulse map' \
  -- --scene "$S" --record "$AT2" --param T --from 1 --to 2 --steps 2 --mu-steps 3 --out o.csv
refused "sweep: --impulse-max without --impulse-curve" "$SWEEP" '--impulse-max: .*impulse curve' \
  -- --scene "$S" --record "$AT2" --param T --from 1 --to 2 --steps 2 --impulse-max 3 --out o.csv
refused "sweep: --param with --impulse-map" "$SWEEP" "--param: .*impulse map's axes" \
  -- --scene "$S" --impulse-map --param T --mu-from 0.1 --mu-to 0.2 --mu-steps 2 \
  --impulse-from 0.1 --impulse-to 1 --impulse-steps 2 --out o.csv
refused "sweep: its own option beside merge" "$SWEEP" "--jobs: has no effect with the subcommand 'merge'" \
  -- --jobs 2 merge --out m.csv a.csv
refused "eval: --horizon with --forecast off" "$EVAL" '--horizon: .*--forecast is off' \
  -- run --scene "$S" --record "$AT2" --out r.csv --forecast off --horizon 3
refused "monitor: --duration with --replay" "$MONITOR" '--duration: stops a live run' \
  -- --scene "$S" --replay "$AT2" --duration 3
refused "monitor: --speed with --can" "$MONITOR" '--speed: paces a replay' \
  -- --scene "$S" --can vcan0 --speed 2
refused "monitor: --pga with a candump log" "$MONITOR" '--pga: scales or completes a record' \
  -- --scene "$S" --replay log.log --pga 0.3g
refused "monitor: --vertical on a bus" "$MONITOR" '--vertical: scales or completes a record' \
  -- --scene "$S" --can vcan0 --vertical "$AT2"
refused "monitor: --pre-trigger without --record-dir" "$MONITOR" \
  "--pre-trigger: sets the event recorder's captures, which is off" \
  -- --scene "$S" --replay "$AT2" --pre-trigger 5
refused "monitor: --mqtt-box-id without a broker" "$MONITOR" \
  '--mqtt-box-id: sets the MQTT publisher, which is off' -- --scene "$S" --replay "$AT2" \
  --mqtt-box-id box1
refused "monitor: --modbus-writes without a server" "$MONITOR" \
  '--modbus-writes: .*the server is off' -- --scene "$S" --replay "$AT2" --modbus-writes
refused "replay: --rate with a candump log" "$REPLAY" '--rate: does not apply to a candump log' \
  -- --record log.log --log out.log --rate 200
refused "commission: --hold-s on a log" "$COMMISSION" "--hold-s: times a live session's" \
  -- --config box.toml --log log.log --hold-s 5
refused "commission: --window live" "$COMMISSION" "--window: gives a step's window in a log" \
  -- --config box.toml --can vcan0 --window rest=0:10

echo "# 3. compound values: split as documented, an unknown part named"
refused "replay: --node-record with an unknown axis" "$REPLAY" \
  "--node-record: unknown axis 'q' in '2:q:.*' \\(one of x, y, z" \
  -- --record "$AT2" --log out.log --node-record "2:q:$AT2"
refused "replay: --node-record without a node" "$REPLAY" \
  "--node-record: the node '' in ':x:.*' is not a number from 1 to 15" \
  -- --record "$AT2" --log out.log --node-record ":x:$AT2"
refused "replay: --node-record with a tab in the node" "$REPLAY" \
  "--node-record: the node '1\\\\t' in " -- --record "$AT2" --log out.log \
  --node-record $'1\t:x:'"$AT2"
refused "replay: --node-record without a file" "$REPLAY" "--node-record: no file in '2:z:'" \
  -- --record "$AT2" --log out.log --node-record "2:z:"
BIN=$REPLAY
cp "$AT2" "$TMP/a:b.AT2"
expect_success "replay: --node-record NODE:AXIS:FILE with a colon in the file's name" \
  --record "$AT2" --log colon.log --speed max --t-end 0.1 --node-record "2:y:$TMP/a:b.AT2"
refused "sweep: --shard with an unknown part" "$SWEEP" "--shard" \
  -- --scene "$S" --record "$AT2" --param T --from 1 --to 2 --steps 2 --shard 1/2/3 --out o.csv

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
