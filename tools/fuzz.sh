#!/usr/bin/env bash
# Runs one libFuzzer target (docs/fuzzing.md) on its seed corpus, with its dictionary, after
# replaying its regression inputs.
#
#   tools/fuzz.sh TARGET [SECONDS]   a long run (default 600 s) of build/fuzz's fuzzer;
#                                    new inputs accumulate in build/fuzz/work/TARGET/corpus
#   tools/fuzz.sh --list             the targets
#
# Options (before TARGET):
#   --build DIR    the build with PLINTH_FUZZ=ON (default build/fuzz: the fuzz preset)
#   --binary PATH  the fuzzer itself (default DIR/tests/fuzz/fuzz_TARGET)
#   --runs N       stop after N executions (ctest's short runs: fresh work folder, fixed seed)
#   --work DIR     new inputs and crash artifacts (default build/fuzz/work/TARGET)
#   --seed N       libFuzzer's seed (default 1)
#
# Exit status: 0 when nothing broke; non-zero on a crash, a hang (-timeout), a leak, a sanitizer
# report or a broken invariant, with the input saved as WORK/artifacts/crash-* (or timeout-*,
# leak-*, oom-*). Fix the cause, then add the input to tests/fuzz/regressions/TARGET/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
fuzz_dir=$root/tests/fuzz

build=$root/build/fuzz
binary=
runs=
work=
seed=1
while [ $# -gt 0 ]; do
  case $1 in
    --build) build=$2; shift 2 ;;
    --binary) binary=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --list)
      for f in "$fuzz_dir"/fuzz_*.cpp; do basename "$f" .cpp | sed 's/^fuzz_//'; done
      exit 0 ;;
    -h|--help) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) break ;;
  esac
done
target=${1:?usage: tools/fuzz.sh [options] TARGET [SECONDS] (tools/fuzz.sh --list)}
seconds=${2:-600}
[ -f "$fuzz_dir/fuzz_$target.cpp" ] || {
  echo "fuzz.sh: no target '$target' (tools/fuzz.sh --list)" >&2; exit 2; }
[[ $seconds =~ ^[0-9]+$ ]] || { echo "fuzz.sh: SECONDS must be a whole number" >&2; exit 2; }
binary=${binary:-$build/tests/fuzz/fuzz_$target}
[ -x "$binary" ] || {
  echo "fuzz.sh: $binary not built: cmake --preset fuzz && cmake --build --preset fuzz" \
       "--target fuzz_$target" >&2; exit 2; }
work=${work:-$build/work/$target}

# Per-target options: "max_len = N" in TARGET.options (OSS-Fuzz's layout); 4096 bytes otherwise.
max_len=4096
if [ -f "$fuzz_dir/$target.options" ]; then
  max_len=$(sed -n 's/^ *max_len *= *\([0-9][0-9]*\) *$/\1/p' "$fuzz_dir/$target.options")
fi
flags=(-seed="$seed" -max_len="$max_len" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1)
[ -f "$fuzz_dir/$target.dict" ] && flags+=(-dict="$fuzz_dir/$target.dict")

# Every regression input first: each must run through without a report.
regressions=$fuzz_dir/regressions/$target
mkdir -p "$(dirname "$work")"
if [ -d "$regressions" ] && [ -n "$(ls -A "$regressions")" ]; then
  "$binary" -runs=1 "$regressions"/* 2>"$work.regressions.log" || {
    cat "$work.regressions.log" >&2
    echo "fuzz.sh: a regression input of $target fails again" >&2; exit 1; }
fi

if [ -n "$runs" ]; then
  # Short, reproducible: a fresh work corpus, a fixed seed, at most $runs executions and
  # $seconds seconds (ctest passes no SECONDS: the cap is 120 s).
  rm -rf "$work"
  flags+=(-runs="$runs" -max_total_time="${2:-120}")
else
  flags+=(-max_total_time="$seconds")
fi
mkdir -p "$work/corpus" "$work/artifacts"
echo "fuzz.sh: $target: $binary ${flags[*]} $work/corpus $fuzz_dir/corpus/$target"
exec "$binary" "${flags[@]}" -artifact_prefix="$work/artifacts/" \
  "$work/corpus" "$fuzz_dir/corpus/$target"
