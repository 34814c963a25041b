#!/usr/bin/env bash
# The box on a Cortex-M4F against the box on Linux: cross-builds the firmware images (preset
# cortex-m4f: one per replay case, firmware/cortex_m/CMakeLists.txt), runs each in QEMU's
# mps2-an386, runs plinth-monitor --replay on the same scene, record and scale, and checks that
# the image sent the same status and alarm frames and found the same phase events
# (tests/cli/mcu_replay_check.py). Prints each image's cost per sample and stack high-water
# mark; without --cases, also runs the cross tree's own tests. See docs/microcontroller.md.
#
# Usage: tools/cortex-m-replay.sh --monitor PLINTH_MONITOR --embed PLINTH_EMBED_RECORD
#                                 --work DIR [--cmake CMAKE] [--launcher CCACHE] [--preset NAME]
#   --monitor, --embed   the host build's plinth-monitor and plinth-embed-record
#   --work DIR           the cross build tree and every file of the run (kept)
#   --launcher PROG      compiler launcher for the cross build (e.g. ccache)
#   --preset NAME        cortex-m4f (default) or cortex-m4f-ensemble (9 members, the forecast)
#   --cases REGEX        only the cases whose names match (grep -E), and only their images built
# Exit status: 0 every case agrees, 1 a case differs or a build or run failed, 2 usage, 77 the
# cross compiler or QEMU is missing (ctest's SKIP_RETURN_CODE; tools/install-deps.sh installs
# them).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
src=$(dirname "$here")
monitor="" embed="" work="" cmake=cmake launcher="" preset=cortex-m4f cases_regex=""
usage() {
  echo "usage: $0 --monitor FILE --embed FILE --work DIR [--cmake CMAKE] [--launcher PROG]" \
       "[--preset NAME] [--cases REGEX]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --monitor) monitor=${2:-}; shift 2 ;;
    --embed) embed=${2:-}; shift 2 ;;
    --work) work=${2:-}; shift 2 ;;
    --cmake) cmake=${2:-}; shift 2 ;;
    --launcher) launcher=${2:-}; shift 2 ;;
    --preset) preset=${2:-}; shift 2 ;;
    --cases) cases_regex=${2:-}; shift 2 ;;
    *) usage ;;
  esac
done
[ -x "$monitor" ] && [ -x "$embed" ] && [ -n "$work" ] || usage

for tool in arm-none-eabi-g++ qemu-system-arm; do
  if ! command -v "$tool" >/dev/null; then
    echo "skipped: $tool not found (tools/install-deps.sh installs gcc-arm-none-eabi," \
         "libnewlib-arm-none-eabi, libstdc++-arm-none-eabi-newlib and qemu-system-arm)"
    exit 77
  fi
done

mkdir -p "$work"
build=$work/build
configure=("$cmake" --preset "$preset" -S "$src" -B "$build" "-DPLINTH_EMBED_RECORD=$embed")
if [ -n "$launcher" ]; then
  configure+=("-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher" "-DCMAKE_C_COMPILER_LAUNCHER=$launcher")
fi
echo "cortex-m-replay: cross build in $build"
(cd "$src" && "${configure[@]}") >"$work/configure.log" 2>&1 ||
  { tail -n 30 "$work/configure.log"; echo "cortex-m-replay: configure failed ($work/configure.log)"; exit 1; }
# The cases (written at configure time), those matching --cases; only their images are built then.
cases=$work/cases.txt
awk -F '\t' -v re="$cases_regex" '$1 ~ re' "$build/firmware/cortex_m/replay_cases.txt" >"$cases"
[ -s "$cases" ] || { echo "cortex-m-replay: no cases${cases_regex:+ matching '$cases_regex'} in $build"; exit 1; }
targets=()
if [ -n "$cases_regex" ]; then targets=(--target $(cut -f 1 "$cases")); fi
"$cmake" --build "$build" "${targets[@]}" >"$work/build.log" 2>&1 ||
  { grep -E "error|FAILED" -A5 "$work/build.log" | head -n 40; echo "cortex-m-replay: build failed ($work/build.log)"; exit 1; }

# plinth-monitor runs the forecast when the images have it (the preset's PLINTH_FORECAST).
forecast_option=(--no-forecast)
if grep -q '^PLINTH_FORECAST:BOOL=ON$' "$build/CMakeCache.txt"; then forecast_option=(); fi
qemu=(qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none
      -semihosting-config enable=on,target=native -icount shift=0)
failed=0
while IFS=$'\t' read -r name image options; do
  read -ra opts <<<"$options"
  if ! (cd "$src" && timeout 600 "${qemu[@]}" -kernel "$image") >"$work/$name.mcu.log" 2>&1; then
    echo "not ok - $name: the image failed in QEMU: $(grep -m 1 -E 'fault|FAILED' "$work/$name.mcu.log" || tail -n 1 "$work/$name.mcu.log")"
    failed=1
    continue
  fi
  if ! (cd "$src" && "$monitor" "${opts[@]}" "${forecast_option[@]}" \
      --frames-out "$work/$name.host.log") \
      >"$work/$name.host.jsonl" 2>"$work/$name.host.err"; then
    echo "not ok - $name: plinth-monitor failed: $(head -n 1 "$work/$name.host.err")"
    failed=1
    continue
  fi
  if result=$(python3 "$src/tests/cli/mcu_replay_check.py" "$work/$name.mcu.log" \
      "$work/$name.host.jsonl" "$work/$name.host.log"); then
    echo "ok - $name: $result"
  else
    echo "not ok - $name: $result"
    failed=1
  fi
  grep -E '^# (cost per_sample|stack)' "$work/$name.mcu.log" | sed 's/^/    /'
  last=$name
done <"$cases"

# A whole tree built (no --cases): its own tests too, the nm and heap checks of every library and
# image, the images in QEMU and the refusals (docs/microcontroller.md, "Build and run").
if [ -z "$cases_regex" ]; then
  ctest_command=ctest  # the one beside --cmake when there is one
  if [ -x "$(dirname "$cmake")/ctest" ]; then ctest_command=$(dirname "$cmake")/ctest; fi
  if "$ctest_command" --test-dir "$build" -j 2 --output-on-failure >"$work/ctest.log" 2>&1; then
    echo "ok - the cross tree's tests: $(grep -E 'tests passed' "$work/ctest.log")"
  else
    echo "not ok - the cross tree's tests ($work/ctest.log):"
    grep -E '^\s+[0-9]+ - ' "$work/ctest.log" | sed 's/^/    /'
    failed=1
  fi
fi

# The comparison can fail: the last case's log with the cause of its last alarm change altered
# (internal_fault), which both rules refuse (tests/cli/test_mcu_replay_check.py tests each rule).
if [ -n "${last:-}" ] && [ -s "$work/$last.mcu.log" ]; then
  tac "$work/$last.mcu.log" |
    awk '!done && / 330#/ { $3 = substr($3, 1, 6) "09" substr($3, 9); done = 1 } 1' |
    tac >"$work/altered.mcu.log"
  if python3 "$src/tests/cli/mcu_replay_check.py" "$work/altered.mcu.log" \
      "$work/$last.host.jsonl" "$work/$last.host.log" >/dev/null; then
    echo "not ok - the check passed a log with an altered alarm change"
    failed=1
  else
    echo "ok - the check refuses a log with an altered alarm change"
  fi
fi
exit "$failed"
