// Steppers and features: ns per step of each phase for each stepper, and what each feature of a
// scene costs per step on a run where it never engages ("only what the scene needs", issue 6).
// Linked into plinth-bench with bench_solver.cpp (which has main).
#include <benchmark/benchmark.h>

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <string>

#include "plinth/core/simulator.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace {

using namespace plinth;

struct Variant {
  Stepper stepper;
  bool exact_full_contact;
};

SolverSettings settings_of(Variant v, double dt = 1e-4) {
  SolverSettings s;
  s.stepper = v.stepper;
  s.exact_full_contact = v.exact_full_contact;
  s.step = dt;
  return s;
}

// A phase to stay in: the scene, the mode and state it starts from (no excitation).
struct PhaseStart {
  SceneParams params;
  Mode mode;
  State y;
};

SceneParams isolated_with_stops() {
  SceneParams p = testing::paper_isolated();
  p.has_base_stops = true;
  p.base_stops = {0.2, 0.7};  // sim/scenes/paper-isolated-stops.toml
  return p;
}

// The friction scene of bench_solver.cpp: mu_s, mu_k and a support of clearance 0.1 m.
SceneParams on_support(double mu_s, double mu_k) {
  SceneParams p = testing::paper_isolated();
  p.has_friction = true;
  p.friction = {mu_s, mu_k};
  p.has_support = true;
  p.support = {0.1};
  return p;
}

// theta = 0.05 rad about the left corner; sliding right at 0.5 m/s; x = -0.15 m overhangs.
PhaseStart start_in(Phase phase, const SceneParams& p, int overhang = 0) {
  PhaseStart s{p, {phase, Corner::kLeft}, State::Zero()};
  if (s.mode.rocking()) s.y[kTheta] = 0.05;
  if (s.mode.sliding()) {
    s.mode.slide_direction = 1;
    s.y[kXDot] = 0.5;
  }
  s.mode.overhang = static_cast<std::int8_t>(overhang);
  if (overhang < 0) s.y[kX] = -0.15;
  return s;
}

// Items (steps) and the ns_per_step counter of a run of `steps` steps.
void set_ns_per_step(benchmark::State& state, std::int64_t steps) {
  state.SetItemsProcessed(steps);
  state.counters["ns_per_step"] = benchmark::Counter(
      static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// ns per step in one phase: each iteration runs from the start until the phase ends (impacts
// included) or kMaxSteps, timed by hand (UseManualTime) so that the restart is not.
void BM_PhaseStep(benchmark::State& state, PhaseStart start, Variant variant) {
  constexpr std::int64_t kMaxSteps = 100'000;  // 10 s
  const Scene scene = testing::make(start.params);
  Simulator sim;
  if (!Simulator::create(scene, Excitation::none(), settings_of(variant), sim).ok()) {
    state.SkipWithError("Simulator::create failed");
    return;
  }
  std::int64_t steps = 0;
  for (auto _ : state) {
    sim.start_from(start.mode, start.y);
    const auto begin = std::chrono::steady_clock::now();
    while (sim.step_count() < kMaxSteps && sim.mode().phase == start.mode.phase) sim.step();
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
    steps += sim.step_count();
  }
  set_ns_per_step(state, steps);
}

// Every phase of bench_solver.cpp's BM_Step, with every stepper (and full contact also
// propagated exactly): BM_PhaseStep/<phase>/<stepper>.
const bool kPhaseStepsRegistered = [] {
  struct PhaseCase {
    const char* name;
    PhaseStart start;
  };
  const PhaseCase phases[] = {
      {"full_contact_base", start_in(Phase::kFullContact, testing::paper_isolated())},
      {"full_contact_base_stops", start_in(Phase::kFullContact, isolated_with_stops())},
      {"rocking_base", start_in(Phase::kRocking, testing::paper_isolated())},
      {"rocking_ground", start_in(Phase::kRocking, testing::paper_block())},
      {"sliding_base", start_in(Phase::kSliding, on_support(0.25, 0.2))},
      {"slide_rocking_base", start_in(Phase::kSlideRocking, on_support(0.5, 0.4))},
      {"slide_rocking_overhanging_base", start_in(Phase::kSlideRocking, on_support(0.5, 0.4), -1)},
  };
  for (const PhaseCase& phase : phases) {
    for (const Stepper stepper : kAllSteppers) {
      for (const bool exact : {false, true}) {
        if (exact &&
            (phase.start.mode.phase != Phase::kFullContact || stepper != Stepper::kRk4Located)) {
          continue;
        }
        const std::string name = std::string("BM_PhaseStep/") + phase.name + "/" +
                                 stepper_name(stepper) + (exact ? "+exact" : "");
        benchmark::RegisterBenchmark(name.c_str(), BM_PhaseStep, phase.start,
                                     Variant{stepper, exact})
            ->UseManualTime();
      }
    }
  }
  return true;
}();

// ---------------------------------------------------------------------------------------------
// The yardstick the step costs are given against (docs/performance.md,
// tools/step-cost-compare.sh): a plain fixed-size Eigen RK4 step of the rocking equations on the
// base (Eq 8 about corner 1, the paper's isolated scene, no excitation) as a textbook integrator
// writes it, BM_PlainRk4Step/rocking_base: the solver's State (an Eigen 6-vector), at every stage
// the lever arms (Eq 9) from std::sin and std::cos and the 2x2 mass matrix solved by Eigen's LU
// (partialPivLu, what Matrix::lu() gives), dy/dt assembled as a 6-vector, and
// y + h/6 (k1 + 2 k2 + 2 k3 + k4); no guards, no events, no reuse of the last stage.
// BM_PlainRk4Step/rocking_base_inverse is the leanest plain form: the state (u, theta, u',
// theta') alone and the 2x2's closed-form inverse. Each iteration rocks from theta = 0.05 rad
// (start_in's) until theta reaches 0, where the solver's rocking_base has its first impact,
// timed by hand like BM_PhaseStep.
template <int kSize>
struct PlainRocking {
  using Vector = Eigen::Matrix<double, kSize, 1>;
  // Where theta, u' and theta' sit in the state.
  static constexpr Eigen::Index kAngle = kSize == 6 ? Eigen::Index{kTheta} : 1;
  static constexpr Eigen::Index kRate = kSize == 6 ? Eigen::Index{kUDot} : 2;
  static constexpr Eigen::Index kAngleRate = kSize == 6 ? Eigen::Index{kThetaDot} : 3;

  double m, total_mass, damping, stiffness, g, h, offset, inertia;

  explicit PlainRocking(const Scene& s)
      : m(s.m),
        total_mass(s.total_mass),
        damping(s.damping),
        stiffness(s.stiffness),
        g(s.g),
        h(s.h),
        offset(s.corner1.offset),
        inertia(s.corner1.inertia) {}

  // dy/dt by Eq 8: [M, -m h'; -m h', I_1] (u'', theta'') = (-c u' - k u + m theta'^2 b',
  // -m g b'), the ground still.
  [[nodiscard]] Vector derivative(const Vector& y) const {
    const double sin_t = std::sin(y[kAngle]);
    const double cos_t = std::cos(y[kAngle]);
    const double arm_h = offset * cos_t - h * sin_t;  // b'_1
    const double arm_v = offset * sin_t + h * cos_t;  // h'_1
    Eigen::Matrix2d mass;
    mass << total_mass, -m * arm_v, -m * arm_v, inertia;
    const Eigen::Vector2d force(
        -damping * y[kRate] - stiffness * y[0] + m * y[kAngleRate] * y[kAngleRate] * arm_h,
        -m * g * arm_h);
    Vector d;
    if constexpr (kSize == 6) {
      const Eigen::Vector2d acc = mass.partialPivLu().solve(force);
      d << y.template tail<3>(), acc[0], 0.0, acc[1];
    } else {
      const Eigen::Vector2d acc = mass.inverse() * force;
      d << y[kRate], y[kAngleRate], acc[0], acc[1];
    }
    return d;
  }

  [[nodiscard]] Vector step(const Vector& y, double dt) const {
    const Vector k1 = derivative(y);
    const Vector k2 = derivative(y + 0.5 * dt * k1);
    const Vector k3 = derivative(y + 0.5 * dt * k2);
    const Vector k4 = derivative(y + dt * k3);
    return y + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
};

template <int kSize>
void BM_PlainRk4Step(benchmark::State& state) {
  const Scene scene = testing::make(testing::paper_isolated());
  const PlainRocking<kSize> rocking(scene);
  using Vector = typename PlainRocking<kSize>::Vector;
  const double theta0 = start_in(Phase::kRocking, scene.params).y[kTheta];
  constexpr double kStep = 1e-4;  // s, the solver's default
  std::int64_t steps = 0;
  for (auto _ : state) {
    Vector y = Vector::Zero();
    y[PlainRocking<kSize>::kAngle] = theta0;
    const auto begin = std::chrono::steady_clock::now();
    while (y[PlainRocking<kSize>::kAngle] > 0.0) {
      y = rocking.step(y, kStep);
      ++steps;
    }
    state.SetIterationTime(
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count());
    benchmark::DoNotOptimize(y);
  }
  set_ns_per_step(state, steps);
}
BENCHMARK(BM_PlainRk4Step<6>)->Name("BM_PlainRk4Step/rocking_base")->UseManualTime();
BENCHMARK(BM_PlainRk4Step<4>)->Name("BM_PlainRk4Step/rocking_base_inverse")->UseManualTime();

// ---------------------------------------------------------------------------------------------
// Only what the scene needs: the same run (Brienza 000, 12 s, the block rocking) with the
// features a scene may add and this input never engages; ns per step over the whole run.

enum class Extra { kNone, kFarStops, kStickingFriction, kFarSupportEdge, kFarSlidingStops, kAll };

SceneParams with_extra(SceneParams p, Extra extra) {
  const bool stops = extra == Extra::kFarStops || extra == Extra::kAll;
  const bool friction = extra != Extra::kNone && extra != Extra::kFarStops;
  if (stops && p.has_base) {
    p.has_base_stops = true;
    p.base_stops = {10.0, 0.7};  // never reached
  }
  if (friction) {
    p.has_friction = true;
    p.friction = {10.0, 8.0};  // never lets go on this input
  }
  if (extra == Extra::kFarSupportEdge || extra == Extra::kFarSlidingStops || extra == Extra::kAll) {
    p.has_support = true;
    p.support = {10.0};
  }
  if (extra == Extra::kFarSlidingStops || extra == Extra::kAll) {
    p.has_sliding_stops = true;
    p.sliding_stops = {0.7};
  }
  return p;
}

// Brienza 000 in m/s2, read once; nullptr when it cannot be read (*error says why).
const host::Record* brienza_000(std::string* error) {
  static std::string failure;
  static const host::Record* const record = []() -> const host::Record* {
    try {
      static const host::Record r = host::read_at2(
          std::string(PLINTH_SOURCE_DIR) + "/sim/data/records/irpinia1980_brienza_000.AT2",
          kStandardGravity);
      return &r;
    } catch (const std::exception& e) {
      failure = e.what();
      return nullptr;
    }
  }();
  *error = failure;
  return record;
}

// `sim` made for `scene` under Brienza 000 scaled to `pga_g`; false, the benchmark skipped with
// the reason, when the record cannot be read or the settings are refused.
bool on_brienza(benchmark::State& state, const Scene& scene, double pga_g,
                const SolverSettings& settings, Simulator& sim) {
  std::string error;
  const host::Record* record = brienza_000(&error);
  if (record == nullptr) {
    state.SkipWithError(error.c_str());
    return false;
  }
  const Excitation ex = Excitation::record(record->horizontal_signal(), {},
                                           pga_g * kStandardGravity / record->peak_horizontal());
  if (!Simulator::create(scene, ex, settings, sim).ok()) {
    state.SkipWithError("Simulator::create failed");
    return false;
  }
  return true;
}

// The first 12 s from rest (or to a collapse); the number of steps taken.
std::int64_t run_12_s(Simulator& sim) {
  constexpr std::int64_t kSteps = 120'000;
  sim.start_at_rest();
  while (sim.step_count() < kSteps && !sim.mode().terminal()) sim.step();
  return sim.step_count();
}

void BM_FeatureRun(benchmark::State& state, bool on_base, Extra extra) {
  const SceneParams base = on_base ? testing::paper_isolated() : testing::paper_block();
  const double pga_g = on_base ? 3.0 : 0.5;  // rocking with impacts, no collapse
  const Scene scene = testing::make(with_extra(base, extra));
  Simulator sim;
  if (!on_brienza(state, scene, pga_g, settings_of({Stepper::kRk4Located, false}), sim)) return;
  std::int64_t steps = 0;
  for (auto _ : state) steps += run_12_s(sim);
  set_ns_per_step(state, steps);
  state.counters["events"] = static_cast<double>(sim.event_count());
}

// Full contact driven by a record: Brienza 000 at 0.1 g keeps the block on the isolated base in
// full contact for the whole 12 s (checked), so every step reads the record; ns per step.
void BM_FullContactOnRecord(benchmark::State& state, Variant variant) {
  const Scene scene = testing::make(testing::paper_isolated());
  Simulator sim;
  if (!on_brienza(state, scene, 0.1, settings_of(variant), sim)) return;
  std::int64_t steps = 0;
  for (auto _ : state) {
    steps += run_12_s(sim);
    if (sim.mode().phase != Phase::kFullContact || sim.event_count() != 0) {
      state.SkipWithError("the block left full contact");
      return;
    }
  }
  set_ns_per_step(state, steps);
}
BENCHMARK_CAPTURE(BM_FullContactOnRecord, rk4_located, Variant{Stepper::kRk4Located, false})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_FullContactOnRecord, rk4_located_exact, Variant{Stepper::kRk4Located, true})
    ->Unit(benchmark::kMillisecond);

// BM_FeatureRun/<scene>+<feature>: the run on the ground and on the base, with each feature.
const bool kFeatureRunsRegistered = [] {
  struct FeatureCase {
    const char* name;
    bool on_base;
    Extra extra;
  };
  const FeatureCase cases[] = {
      {"ground", false, Extra::kNone},
      {"ground+friction", false, Extra::kStickingFriction},
      {"ground+support_edge", false, Extra::kFarSupportEdge},
      {"ground+sliding_stops", false, Extra::kFarSlidingStops},
      {"base", true, Extra::kNone},
      {"base+stops", true, Extra::kFarStops},
      {"base+friction", true, Extra::kStickingFriction},
      {"base+support_edge", true, Extra::kFarSupportEdge},
      {"base+sliding_stops", true, Extra::kFarSlidingStops},
      {"base+everything", true, Extra::kAll},
  };
  for (const FeatureCase& c : cases) {
    benchmark::RegisterBenchmark((std::string("BM_FeatureRun/") + c.name).c_str(), BM_FeatureRun,
                                 c.on_base, c.extra)
        ->Unit(benchmark::kMillisecond);
  }
  return true;
}();

}  // namespace
