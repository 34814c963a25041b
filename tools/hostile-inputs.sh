#!/usr/bin/env bash
# A hostile-input sweep (issue 17): generated cases through every program, each with a timeout.
# A case passes when the program ends in time, prints no sanitizer report, and either exits 0
# or exits 1, 2 or 3 with a message on stderr that names the option or the file it was given.
#
#   tools/hostile-inputs.sh BUILD_DIR [--short]
#
# BUILD_DIR holds the programs (build/release, or build/sanitize for the ASan + UBSan run);
# --short runs a sample of the cases (ctest: hostile_input_sweep). Prints one line per failure
# and "N cases, M failed". Exit 0 when none failed.
set -u
BUILD=$(cd "${1:?usage: tools/hostile-inputs.sh BUILD_DIR [--short]}" && pwd) || exit 2
SHORT=0
[[ "${2:-}" == --short ]] && SHORT=1
SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
SIM=$BUILD/sim/plinth-sim
SWEEP=$BUILD/sim/plinth-sweep
REPLAY=$BUILD/hal/replay/plinth-replay
MONITOR=$BUILD/firmware/linux/plinth-monitor
for binary in "$SIM" "$SWEEP" "$REPLAY" "$MONITOR"; do
  [[ -x "$binary" ]] || { echo "$binary: not an executable" >&2; exit 2; }
done
SCENE=$SRC/sim/scenes/paper-isolated.toml
AT2=$SRC/sim/data/records/irpinia1980_brienza_000.AT2
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK" || exit 2
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1} UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}

# Hostile files: empty, binary, truncated and lying headers, huge and non-finite values.
: >empty.AT2
head -c 4096 /dev/urandom >binary.AT2
head -n 6 "$AT2" >truncated.AT2
sed '4s/NPTS= *[0-9]*/NPTS= 99999999/' "$AT2" >npts-lies.AT2
sed '4s/DT= *[.0-9]*/DT= 1e300/' "$AT2" >dt-huge.AT2
sed '4s/DT= *[.0-9]*/DT= 1e-20/' "$AT2" >dt-tiny.AT2
sed '5s/^ *[^ ]*/ 1.7E+308/' "$AT2" >value-huge.AT2
sed '5s/^ *[^ ]*/ NaN/' "$AT2" >value-nan.AT2
printf 't,a [g]\n0,0\n0.01,nan\n' >nan.csv
printf 't,a [g]\n0,0\n0.01,0.1\n0.005,0\n' >time-back.csv
printf 't,a [parsecs]\n0,0\n' >unit.csv
printf '[block]\nhalf_width = -1\n' >negative.toml
printf '[block]\nhalf_width = nan\nslenderness = 3\n' >nan.toml
printf 'not toml at all = = =\n' >garbage.toml
printf '(1700000000.000000) vcan0 301#00\n(1699999999.000000) vcan0 301#0000000000000000\n' >back.log
printf '(nan) vcan0 301#0000000000000000\n' >nan.log
head -c 100000 /dev/urandom >binary.log
: >empty.log
mkdir folder.AT2 folder.log folder.toml
mkfifo fifo.AT2 fifo.log
ln -s /dev/zero zero.AT2
ln -s /dev/zero zero.log

NUMBERS=(0 -1 nan inf -inf 1e308 -1e308 1e-308 1e-300 1e300 abc '' 1e 0x10 ' ' 9999999999999999999)
FILES=(empty.AT2 binary.AT2 truncated.AT2 npts-lies.AT2 dt-huge.AT2 dt-tiny.AT2 value-huge.AT2
  value-nan.AT2 nan.csv time-back.csv unit.csv folder.AT2 fifo.AT2 zero.AT2 missing.AT2
  /dev/null)
SCENES=(negative.toml nan.toml garbage.toml folder.toml empty.AT2 /dev/zero fifo.AT2 missing.toml)
LOGS=(back.log nan.log binary.log empty.log folder.log fifo.log zero.log)

CASES=0
FAILED=0
# check NAME NEEDLE -- COMMAND...: runs one case; NEEDLE (the option or file) must appear on
# stderr when the exit code is not 0.
check() {
  local name=$1 needle=$2
  shift 3
  CASES=$((CASES + 1))
  if ((SHORT)) && ((CASES % 5 != 0)); then return; fi
  timeout -k 5 30 "$@" </dev/null >out.txt 2>err.txt
  local rc=$?
  local why=""
  if ((rc == 124 || rc == 137)); then
    why="did not end within 30 s"
  elif grep -qE 'AddressSanitizer|runtime error:|LeakSanitizer' err.txt; then
    why="sanitizer report: $(grep -m1 -E 'AddressSanitizer|runtime error:|LeakSanitizer' err.txt)"
  elif ((rc >= 128)); then
    why="killed by signal $((rc - 128))"
  elif ((rc != 0 && rc != 1 && rc != 2 && rc != 3)); then
    why="exit $rc"
  elif ((rc != 0)) && ! grep -qF -- "$needle" err.txt; then
    why="exit $rc, the message does not name '$needle': $(head -c 200 err.txt)"
  elif ((rc == 0)) && grep -qiE '(^|[^a-z])(nan|inf)([^a-z]|$)' out.txt; then
    why="exit 0 with a non-finite number in the output"
  fi
  if [[ -n "$why" ]]; then
    FAILED=$((FAILED + 1))
    echo "FAIL $name: $why"
  fi
  rm -f ./*.csv.partial* ./*.log.partial* out.csv out.jsonl
}

base_sim=(--scene "$SCENE" --record "$AT2" --t-end 2)
for option in --dt --t-end --scale --out-interval; do
  for value in "${NUMBERS[@]}"; do
    check "sim $option '$value'" "$option" -- "$SIM" "${base_sim[@]}" "$option" "$value" --out out.csv
  done
done
for value in "${NUMBERS[@]}"; do
  check "sim --pga '${value}g'" "--pga" -- "$SIM" "${base_sim[@]}" --pga "${value}g"
  check "sim --impulse '$value'" "--impulse" -- "$SIM" --scene "$SCENE" --impulse "$value" --t-end 1
  check "sim --amplitude '${value}g'" "--amplitude" -- "$SIM" --scene "$SCENE" --pulse sine \
    --amplitude "${value}g" --period 0.5 --t-end 1
done
for file in "${FILES[@]}"; do
  check "sim --record $file" "$file" -- "$SIM" --scene "$SCENE" --record "$file" --t-end 2
  check "sim --vertical $file" "$file" -- "$SIM" "${base_sim[@]}" --vertical "$file"
  check "sweep --record $file" "$file" -- "$SWEEP" --scene "$SCENE" --record "$file" --param T \
    --from 1 --to 2 --steps 2 --pga-max 0.3g --tol 0.05g --out out.csv
  check "replay --record $file" "$file" -- "$REPLAY" --record "$file" --log out.log --speed max
  check "monitor --replay $file" "$file" -- "$MONITOR" --scene "$SCENE" --replay "$file"
done
for scene in "${SCENES[@]}"; do
  check "sim --scene $scene" "$scene" -- "$SIM" --scene "$scene" --record "$AT2" --t-end 2
  check "monitor --scene $scene" "$scene" -- "$MONITOR" --scene "$scene" --replay "$AT2"
  check "monitor --config $scene" "$scene" -- "$MONITOR" --scene "$SCENE" --config "$scene" \
    --replay "$AT2"
done
for log in "${LOGS[@]}"; do
  check "monitor --replay $log" "$log" -- "$MONITOR" --scene "$SCENE" --replay "$log"
  check "replay --record $log" "$log" -- "$REPLAY" --record "$log" --log out.log --speed max
done
sweep_base=(--scene "$SCENE" --record "$AT2" --param T --from 1 --to 2 --steps 2 --pga-max 0.3g
  --tol 0.05g --out out.csv)
for option in --dt --from --to --steps --jobs; do
  for value in "${NUMBERS[@]}"; do
    check "sweep $option '$value'" "$option" -- "$SWEEP" "${sweep_base[@]}" "$option" "$value"
  done
done
for option in --tol --pga-max; do
  for value in "${NUMBERS[@]}"; do
    check "sweep $option '${value}g'" "$option" -- "$SWEEP" "${sweep_base[@]}" "$option" "${value}g"
  done
done
for option in --rate --speed --t-end --scale --loop; do
  for value in "${NUMBERS[@]}"; do
    check "replay $option '$value'" "$option" -- "$REPLAY" --record "$AT2" --log out.log \
      --t-end 1 "$option" "$value"
  done
done
for option in --status-interval --startup-window --rate --steps --speed --scale --stuck-samples; do
  for value in "${NUMBERS[@]}"; do
    check "monitor $option '$value'" "$option" -- "$MONITOR" --scene "$SCENE" --replay "$AT2" \
      --no-events "$option" "$value"
  done
done
for output in /nonexistent/x.csv folder.AT2 fifo.log "$AT2"; do
  check "sim --out $output" "$output" -- "$SIM" "${base_sim[@]}" --out "$output"
  check "sim --events $output" "$output" -- "$SIM" "${base_sim[@]}" --events "$output"
  check "replay --log $output" "$output" -- "$REPLAY" --record "$AT2" --log "$output" --speed max
  check "sweep --out $output" "$output" -- "$SWEEP" "${sweep_base[@]/out.csv/$output}"
done
check "sim --no-such-flag" "--no-such-flag" -- "$SIM" "${base_sim[@]}" --no-such-flag
check "sweep --no-such-flag" "--no-such-flag" -- "$SWEEP" "${sweep_base[@]}" --no-such-flag
check "replay --no-such-flag" "--no-such-flag" -- "$REPLAY" --record "$AT2" --log out.log \
  --no-such-flag
check "monitor --no-such-flag" "--no-such-flag" -- "$MONITOR" --scene "$SCENE" --replay "$AT2" \
  --no-such-flag
check "sim --dt twice" "--dt" -- "$SIM" "${base_sim[@]}" --dt 1e-4 --dt 2e-4
check "monitor --scene twice" "--scene" -- "$MONITOR" --scene "$SCENE" --scene "$SCENE" \
  --replay "$AT2"
echo "$CASES cases$( ((SHORT)) && echo " (1 in 5 run: --short)"), $FAILED failed"
((FAILED == 0))
