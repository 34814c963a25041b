// Solver benchmarks: cost per step in each phase and scene, the flows alone, a whole record.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <exception>
#include <string>

#include "plinth/core/internal/flows.h"
#include "plinth/core/simulator.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace {

using namespace plinth;
using plinth::internal::full_contact_flow;
using plinth::internal::Pivot;
using plinth::internal::pivot_of;
using plinth::internal::rocking_flow;
using plinth::internal::slide_rocking_flow;

SceneParams with_stops(SceneParams p) {
  p.has_base_stops = true;
  p.base_stops = {0.2, 0.7};  // u_max = 0.2 m, eta_i = 0.7 (sim/scenes/paper-isolated-stops.toml)
  return p;
}

struct Setup {
  SceneParams params;
  Mode mode;
  State y = State::Zero();
};

// Free rocking about the left corner from theta = 0.05 rad, at rest otherwise.
Setup rocking(const SceneParams& p) {
  Setup s{p, {Phase::kRocking, Corner::kLeft, 0}};
  s.y[kTheta] = 0.05;
  return s;
}

// ns per step with no excitation; whenever the phase measured ends, the run starts again
// outside the timed region.
void BM_Step(benchmark::State& state, const Setup& setup) {
  const Scene scene = testing::make(setup.params);
  Simulator sim;
  if (!Simulator::create(scene, Excitation::none(), SolverSettings{}, sim).ok()) {
    state.SkipWithError("Simulator::create failed");
    return;
  }
  sim.start_from(setup.mode, setup.y);
  std::int64_t restarts = 0;
  for (auto _ : state) {
    sim.step();
    if (sim.mode().phase != setup.mode.phase) {
      state.PauseTiming();
      sim.start_from(setup.mode, setup.y);
      ++restarts;
      state.ResumeTiming();
    }
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["ns_per_step"] = benchmark::Counter(
      1.0, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["restarts"] = static_cast<double>(restarts);
}
BENCHMARK_CAPTURE(BM_Step, full_contact_base, Setup{testing::paper_isolated(), {}});
BENCHMARK_CAPTURE(BM_Step, rocking_base, rocking(testing::paper_isolated()));
BENCHMARK_CAPTURE(BM_Step, rocking_ground, rocking(testing::paper_block()));
BENCHMARK_CAPTURE(BM_Step, full_contact_base_stops, Setup{with_stops(testing::paper_isolated()), {}});

// mu_k = 0.4 > b/h: a sliding block decelerates enough to tip (slide-rocking); mu_k = 0.2 does
// not (pure sliding).
SceneParams with_friction(SceneParams p, double mu_s = 0.5, double mu_k = 0.4) {
  p.has_friction = true;
  p.friction = {mu_s, mu_k};
  p.has_support = true;
  p.support = {0.1};  // the block may overhang the support
  return p;
}

// Sliding right at 0.5 m/s, or slide-rocking (theta = 0.05 rad) on the support or overhanging
// its left edge; kinetic friction brings it to rest within about 0.1 s.
Setup sliding(const SceneParams& p, bool rocking_too, int overhang) {
  Setup s{rocking_too ? with_friction(p) : with_friction(p, 0.25, 0.2),
          {rocking_too ? Phase::kSlideRocking : Phase::kSliding, Corner::kLeft, 0}};
  s.mode.slide_direction = 1;
  s.mode.overhang = static_cast<std::int8_t>(overhang);
  s.y[kX] = overhang < 0 ? -0.15 : 0.0;
  s.y[kXDot] = 0.5;
  if (rocking_too) s.y[kTheta] = 0.05;
  return s;
}
BENCHMARK_CAPTURE(BM_Step, sliding_base, sliding(testing::paper_isolated(), false, 0));
BENCHMARK_CAPTURE(BM_Step, slide_rocking_base, sliding(testing::paper_isolated(), true, 0));
BENCHMARK_CAPTURE(BM_Step, slide_rocking_overhanging_base,
                  sliding(testing::paper_isolated(), true, -1));

void BM_FullContactFlow(benchmark::State& state) {
  const Scene scene = testing::make(testing::paper_isolated());
  State y = State::Zero();
  y[kU] = 0.05;
  y[kUDot] = 0.1;
  GroundAcceleration ag{1.0, 0.0};
  for (auto _ : state) {
    benchmark::DoNotOptimize(y);
    benchmark::DoNotOptimize(ag);
    Accelerations a = full_contact_flow(scene, y, ag);
    benchmark::DoNotOptimize(a);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_FullContactFlow);

// Coupled to a moving base (2x2 solve) or on fixed ground.
void BM_RockingFlow(benchmark::State& state, bool on_base) {
  const Scene scene =
      testing::make(on_base ? testing::paper_isolated() : testing::paper_block());
  State y = State::Zero();
  y[kU] = 0.05;
  y[kTheta] = 0.05;
  y[kUDot] = 0.1;
  y[kThetaDot] = -0.2;
  GroundAcceleration ag{1.0, 0.0};
  for (auto _ : state) {
    benchmark::DoNotOptimize(y);
    benchmark::DoNotOptimize(ag);
    Accelerations a = rocking_flow(scene, scene.corner1, y, ag, on_base);
    benchmark::DoNotOptimize(a);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(BM_RockingFlow, on_base, true);

// Eqs 10-12 (on the support) or 13-14 (overhanging): a 3x3 solve.
void BM_SlideRockingFlow(benchmark::State& state, bool overhanging) {
  const Scene scene = testing::make(with_friction(testing::paper_isolated()));
  State y;
  y << 0.05, overhanging ? -0.15 : 0.0, 0.05, 0.1, 0.3, -0.2;
  const Pivot pivot = pivot_of(scene, Corner::kLeft, overhanging ? -1 : 0, y[kX]);
  GroundAcceleration ag{1.0, 0.0};
  for (auto _ : state) {
    benchmark::DoNotOptimize(y);
    benchmark::DoNotOptimize(ag);
    Accelerations a = slide_rocking_flow(scene, pivot.geometry, overhanging, 1, y, ag, true);
    benchmark::DoNotOptimize(a);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(BM_SlideRockingFlow, on_support, false);
BENCHMARK_CAPTURE(BM_SlideRockingFlow, overhanging, true);
BENCHMARK_CAPTURE(BM_RockingFlow, on_ground, false);

// Brienza 000 at PGA 1 g on the isolated scene with stops, dt = 1e-4 s, 40 s.
void BM_Record(benchmark::State& state) {
  host::Record record;
  try {
    record = host::read_at2(
        std::string(PLINTH_SOURCE_DIR) + "/sim/data/records/irpinia1980_brienza_000.AT2",
        kStandardGravity);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  const Scene scene = testing::make(with_stops(testing::paper_isolated()));
  const Excitation ex = Excitation::record(record.horizontal_signal(), {},
                                           kStandardGravity / record.peak_horizontal());
  SolverSettings settings;
  settings.step = 1e-4;
  Simulator sim;
  if (!Simulator::create(scene, ex, settings, sim).ok()) {
    state.SkipWithError("Simulator::create failed");
    return;
  }
  constexpr std::int64_t kSteps = 400'000;  // 40 s
  double simulated = 0.0;
  std::int64_t steps = 0;
  for (auto _ : state) {
    sim.start_at_rest();
    while (sim.step_count() < kSteps && !sim.mode().terminal()) sim.step();
    simulated += sim.time();
    steps += sim.step_count();
  }
  state.SetItemsProcessed(steps);
  // Simulated seconds per wall second (the benchmark uses real time).
  state.counters["x_real_time"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.counters["steps"] = static_cast<double>(sim.step_count());
}
BENCHMARK(BM_Record)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
