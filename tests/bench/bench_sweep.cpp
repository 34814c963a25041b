// plinth-sweep benchmarks (docs/sweep.md): simulations per second on one core for the Brienza
// record on the paper's scene, and the wall time of a full Fig. 12 kind of map (mu_s from 0.1
// to 1.5 in 50 steps, every event, 2 threads).
#include <benchmark/benchmark.h>

#include <exception>
#include <string>
#include <vector>

#include "plinth/host/job_runner.h"
#include "plinth/host/record_io.h"
#include "plinth/host/sweep_parameter.h"
#include "plinth/host/sweep_plan.h"
#include "plinth/host/sweep_search.h"
#include "test_support.h"

namespace {

using namespace plinth;

const host::Record* brienza() {
  static const host::Record* record = [] {
    try {
      return new host::Record(host::read_at2(
          std::string(PLINTH_SOURCE_DIR) + "/sim/data/records/irpinia1980_brienza_000.AT2",
          kStandardGravity));
    } catch (const std::exception&) {
      return static_cast<host::Record*>(nullptr);
    }
  }();
  return record;
}

// One simulation as the sweep runs it (dt 5e-4 s, every event looked for) on the paper's
// isolated scene with mu_s = 0.5, at a PGA (in g) where nothing happens (1 g: the whole record
// and 2 s more), where the block rocks (2.6 g) and where it overturns (4 g).
void BM_SweepSimulation(benchmark::State& state, double pga_g) {
  if (brienza() == nullptr) {
    state.SkipWithError("cannot read the Brienza record");
    return;
  }
  const Scene scene = host::sweep_scene(testing::paper_isolated(), host::SweepParameter::kMuS, 0.5);
  const host::SweepSettings settings;
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        host::simulate_occurrences(scene, *brienza(), pga_g * scene.g, settings));
  }
  state.SetItemsProcessed(state.iterations());  // items/s: simulations per second, one core
}
BENCHMARK_CAPTURE(BM_SweepSimulation, quiet_1g, 1.0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SweepSimulation, rocking_2_6g, 2.6)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SweepSimulation, overturns_4g, 4.0)->Unit(benchmark::kMillisecond);

// The Fig. 12 kind of map plinth-sweep makes with
//   --scene sim/scenes/paper-isolated.toml --record .../irpinia1980_brienza_000.AT2
//   --param mu_s --from 0.1 --to 1.5 --steps 50 --jobs 2 [--pga-max 5g]
void BM_Fig12Map(benchmark::State& state, double pga_max_g) {
  if (brienza() == nullptr) {
    state.SkipWithError("cannot read the Brienza record");
    return;
  }
  host::SweepSettings settings;
  settings.pga_max_g = pga_max_g;
  const host::SweepPlan plan =
      host::plan_thresholds(testing::paper_isolated(), *brienza(), host::SweepParameter::kMuS,
                            {"mu_s", 0.1, 1.5, 50}, settings);
  host::JobRun run;
  run.jobs = 2;
  const std::vector<std::size_t> all = host::shard_indices(plan.keys.size(), run);
  std::size_t simulations = 0;
  for (auto _ : state) {
    std::vector<std::string> rows;
    host::run_plan(plan, all, run, rows, &simulations);
    benchmark::DoNotOptimize(rows);
  }
  state.counters["simulations"] =
      static_cast<double>(simulations) / static_cast<double>(state.iterations());
}
BENCHMARK_CAPTURE(BM_Fig12Map, pga_max_2g, 2.0)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);
BENCHMARK_CAPTURE(BM_Fig12Map, pga_max_5g, 5.0)
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
