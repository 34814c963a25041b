#!/usr/bin/env bash
# The solver's step costs of two commits, measured in one run (docs/performance.md, "Comparing
# two commits"): builds each commit's plinth-bench (Release, as the release preset), then runs the
# two binaries in turn, pinned to one core, for several rounds (BASE first in odd rounds, HEAD
# first in even ones), each run the median of a few repetitions. Prints per benchmark the median
# over the rounds of each commit's ns per step, HEAD / BASE, and each against the plain RK4 step
# (BM_PlainRk4Step/rocking_base: a textbook Eigen RK4 step of the rocking equations) measured in
# the same round, as a markdown table. A commit without the plain step is set against the other
# binary's plain step of the same round (the same code, built by the same compiler).
#
# Times are the thread's CPU time per step by default: on a shared machine the other tenants'
# load inflates wall time by whatever share of the core they take, and CPU time far less; --wall
# gives the benchmarks' own ns_per_step counter (wall time) instead. Nothing here is a test: the
# figures are what this machine measured in this run.
#
# Usage: tools/step-cost-compare.sh [options] BASE HEAD
#   BASE, HEAD        commits (anything git rev-parse takes), built from `git archive` in
#                     BUILD_ROOT/<commit>; "." is the working tree's own build (--build); a
#                     path to a plinth-bench binary is run as it is
#   --rounds N        rounds (default 6)
#   --repetitions N   repetitions of each benchmark in one run, whose median the run gives
#                     (default 3)
#   --cpu N           the core to pin to (default the last one)
#   --filter REGEX    the benchmarks (default: the plain RK4 step and the phases' steps below)
#   --wall            wall time (ns_per_step) in place of CPU time
#   --names A,B       the columns' names (default BASE and HEAD as given)
#   --build DIR       the working tree's build for "." (default build/release)
#   --build-root DIR  where the commits are built (default build/step-cost)
#   --out DIR         keep every run's JSON there (default a temporary folder, removed)
#   --table DIR       print the table of the runs an earlier --out kept in DIR, running nothing
#                     (BASE and HEAD then only name the columns)
# Exit status: 0 printed, 1 a build or run failed, 2 usage.
set -euo pipefail
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
names="" table="" rounds=6 repetitions=3 cpu=$(($(nproc) - 1)) clock=cpu out=""
own_build=$src/build/release build_root=$src/build/step-cost
# The plain RK4 steps, each phase's RK4 step (full contact also exactly) and full contact on a
# record.
phases='full_contact_base|rocking_base|rocking_ground|slide_rocking_base'
phases+='|slide_rocking_overhanging_base'
filter="BM_PlainRk4Step/|BM_PhaseStep/($phases)/rk4_located(\\+exact)?/"
filter+='|BM_FullContactOnRecord/rk4_located_exact'
usage() { sed -n '/^# Usage:/,/^# Exit status/p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
commits=()
while [ $# -gt 0 ]; do
  case "$1" in
    --rounds) rounds=${2:?}; shift 2 ;;
    --repetitions) repetitions=${2:?}; shift 2 ;;
    --cpu) cpu=${2:?}; shift 2 ;;
    --filter) filter=${2:?}; shift 2 ;;
    --wall) clock=wall; shift ;;
    --names) names=${2:?}; shift 2 ;;
    --build) own_build=$(cd "${2:?}" && pwd); shift 2 ;;
    --build-root) build_root=${2:?}; shift 2 ;;
    --out) out=${2:?}; shift 2 ;;
    --table) table=${2:?}; shift 2 ;;
    -h | --help) usage ;;
    -*) usage ;;
    *) commits+=("$1"); shift ;;
  esac
done
[ ${#commits[@]} -eq 2 ] || usage
for n in "$rounds" "$repetitions" "$cpu"; do
  [[ "$n" =~ ^[0-9]+$ ]] || { echo "step-cost-compare: '$n' is not a whole number" >&2; exit 2; }
done
[ "$rounds" -ge 1 ] && [ "$repetitions" -ge 1 ] ||
  { echo "step-cost-compare: --rounds and --repetitions must be at least 1" >&2; exit 2; }
[ "$cpu" -lt "$(nproc)" ] ||
  { echo "step-cost-compare: --cpu $cpu: this machine has cores 0-$(($(nproc) - 1))" >&2; exit 2; }
command -v taskset >/dev/null ||
  { echo "step-cost-compare: taskset not found (util-linux)" >&2; exit 1; }

# summarize: the table of the runs in $runs.
summarize() {
python3 - "$runs" "$rounds" "$clock" "$base_label" "$head_label" "$cpu" "$repetitions" <<'PY'
import json
import statistics
import sys

runs, rounds, clock, base_label, head_label, cpu, repetitions = sys.argv[1:]
rounds = int(rounds)
PLAIN = "BM_PlainRk4Step/rocking_base"


def per_step(path):
    """ns per step of each benchmark in one run (its median over the repetitions)."""
    with open(path) as f:
        data = json.load(f)
    costs = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name", "median") != "median" or "ns_per_step" not in b:
            continue
        # The counter is seconds per step, over the benchmark's own time: wall time where it
        # times by hand or in real time (its name says so), CPU time otherwise.
        name = b["run_name"]
        counted_in_wall = name.endswith("/manual_time") or name.endswith("/real_time")
        name = name.removesuffix("/manual_time").removesuffix("/real_time")
        per_step = b["ns_per_step"] * 1e9
        cpu_over_wall = b["cpu_time"] / b["real_time"]  # both in the run's time unit
        if clock == "wall":
            costs[name] = per_step if counted_in_wall else per_step / cpu_over_wall
        else:
            costs[name] = per_step * cpu_over_wall if counted_in_wall else per_step
    return costs


base = [per_step(f"{runs}/base-{r}.json") for r in range(1, rounds + 1)]
head = [per_step(f"{runs}/head-{r}.json") for r in range(1, rounds + 1)]
names = []
for run in base + head:
    names += [n for n in run if n not in names]
names.sort(key=lambda n: (n != PLAIN, not n.startswith("BM_PlainRk4Step"), n))


def plain_of(own, other):
    return own.get(PLAIN, other.get(PLAIN))


def median(values):
    return statistics.median(values) if values else float("nan")


def cell(x, digits=1):
    return "" if x != x else f"{x:.{digits}f}"


print(f"{clock} ns per step, median of {rounds} rounds (each the median of {repetitions} "
      f"repetitions), pinned to core {cpu}; x plain: against {PLAIN} of the same round")
print()
print(f"| benchmark | {base_label} | {head_label} | {head_label} / {base_label} "
      f"| {base_label} x plain | {head_label} x plain |")
print("|---|---|---|---|---|---|")
for n in names:
    b = [r[n] for r in base if n in r]
    h = [r[n] for r in head if n in r]
    b_plain = [r[n] / plain_of(r, o) for r, o in zip(base, head) if n in r and plain_of(r, o)]
    h_plain = [r[n] / plain_of(r, o) for r, o in zip(head, base) if n in r and plain_of(r, o)]
    change = [y / x for x, y in zip((r.get(n) for r in base), (r.get(n) for r in head))
              if x and y]
    print(f"| {n} | {cell(median(b))} | {cell(median(h))} | {cell(median(change), 3)} "
          f"| {cell(median(b_plain), 3)} | {cell(median(h_plain), 3)} |")
PY
}

# bench_of COMMIT: the path of its plinth-bench, built when missing; its label on stdout's last
# line after a tab.
bench_of() {
  local commit=$1
  if [ -f "$commit" ] && [ -x "$commit" ]; then
    printf '%s\t%s\n' "$(cd "$(dirname "$commit")" && pwd)/$(basename "$commit")" "$commit"
    return
  fi
  if [ "$commit" = . ]; then
    cmake --build "$own_build" --target plinth-bench >&2 ||
      { echo "step-cost-compare: building plinth-bench in $own_build failed" >&2; return 1; }
    printf '%s\t%s\n' "$own_build/tests/bench/plinth-bench" "worktree"
    return
  fi
  local sha
  sha=$(git -C "$src" rev-parse --verify --quiet "$commit^{commit}") ||
    { echo "step-cost-compare: '$commit' is not a commit of $src" >&2; return 1; }
  sha=${sha:0:10}
  local tree=$build_root/$sha
  local bench=$tree/build/tests/bench/plinth-bench
  if [ ! -x "$bench" ]; then
    echo "step-cost-compare: building $commit ($sha) in $tree" >&2
    rm -rf "$tree/src"
    mkdir -p "$tree/src"
    git -C "$src" archive "$sha" | tar -x -C "$tree/src"
    local launcher=()
    if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
    # The release preset's settings, spelled out: a commit's presets may differ or be missing.
    { cmake -S "$tree/src" -B "$tree/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
        -DPLINTH_WERROR=ON -DPLINTH_BUILD_TESTS=ON -DPLINTH_BUILD_BENCHMARKS=ON "${launcher[@]}" &&
      cmake --build "$tree/build" --target plinth-bench; } >"$tree/build.log" 2>&1 ||
      { echo "step-cost-compare: building $commit failed; see $tree/build.log" >&2; return 1; }
  fi
  printf '%s\t%s\n' "$bench" "$commit"
}

if [ -n "$table" ]; then
  [ -s "$table/base-1.json" ] || { echo "step-cost-compare: no runs in $table" >&2; exit 2; }
  runs=$(cd "$table" && pwd)
  rounds=$(find "$runs" -name 'head-*.json' | wc -l)
  base_label=${commits[0]} head_label=${commits[1]}
  if [ -n "$names" ]; then IFS=, read -r base_label head_label <<<"$names"; fi
  summarize
  exit 0
fi

IFS=$'\t' read -r base_bench base_label < <(bench_of "${commits[0]}" | tail -n 1)
IFS=$'\t' read -r head_bench head_label < <(bench_of "${commits[1]}" | tail -n 1)
[ -x "${base_bench:-}" ] && [ -x "${head_bench:-}" ] || exit 1
if [ -n "$names" ]; then
  IFS=, read -r base_label head_label <<<"$names"
  [ -n "$base_label" ] && [ -n "$head_label" ] ||
    { echo "step-cost-compare: --names '$names': give two names, A,B" >&2; exit 2; }
fi

if [ -n "$out" ]; then
  mkdir -p "$out"
  runs=$(cd "$out" && pwd)
else
  runs=$(mktemp -d)
  trap 'rm -rf "$runs"' EXIT
fi
run() {  # BENCH FILE
  (cd "$src" && taskset -c "$cpu" "$1" --benchmark_filter="$filter" \
    --benchmark_repetitions="$repetitions" --benchmark_report_aggregates_only=true \
    --benchmark_format=json >"$2" 2>"$2.stderr") ||
    { echo "step-cost-compare: $1 failed; see $2.stderr" >&2; exit 1; }
}
echo "step-cost-compare: $rounds rounds of $repetitions repetitions, pinned to core $cpu" >&2
for ((r = 1; r <= rounds; r++)); do
  echo "step-cost-compare: round $r of $rounds" >&2
  if ((r % 2 == 1)); then
    run "$base_bench" "$runs/base-$r.json"
    run "$head_bench" "$runs/head-$r.json"
  else
    run "$head_bench" "$runs/head-$r.json"
    run "$base_bench" "$runs/base-$r.json"
  fi
done

summarize
