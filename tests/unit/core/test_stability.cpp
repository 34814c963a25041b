// Stability at the extremes of the scene's parameters: every run ends, nothing is NaN or
// infinite, and the results are deterministic.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "plinth/core/stability.h"
#include "test_support.h"

namespace plinth {
namespace {

struct Extreme {
  double lambda, epsilon, period, xi, mass_ratio, mu;  // mu < 0: no [friction]
  int stops;                                           // 0 none, 1 base, 2 base + support
  double pga_g;
};

SceneParams scene_for(const Extreme& x) {
  SceneParams p;
  p.block.half_width = 0.3;
  p.block.com_height = 0.3 * x.lambda;
  p.block.eccentricity = 0.3 * x.epsilon;
  p.block.mass = 2000.0 * 0.6 * 0.6 * x.lambda;
  p.block.inertia = homogeneous_rectangle_inertia(p.block.mass, 0.3, p.block.com_height);
  p.has_base = true;
  p.base = {x.mass_ratio * p.block.mass, x.period, x.xi};
  if (x.mu >= 0.0) {
    p.has_friction = true;
    p.friction = {x.mu, 0.8 * x.mu};
  }
  if (x.stops >= 1) {
    p.has_base_stops = true;
    p.base_stops = {0.2, 0.7};
  }
  if (x.stops == 2 && x.mu >= 0.0) {
    p.has_support = true;
    p.support = {0.1};
  }
  return p;
}

struct Result {
  State state;
  Phase phase;
  std::size_t events;
  bool finite;
};

Result run(const Extreme& x) {
  const Scene s = testing::make(scene_for(x));
  SolverSettings settings;
  settings.step = std::min(1e-3, 0.9 * largest_stable_step(s));
  testing::RecordingSink sink;
  Simulator sim;
  if (!Simulator::create(s, Excitation::sine_pulse(x.pga_g * kStandardGravity, 0.5), settings,
                         sim).ok()) {
    return {State::Zero(), Phase::kFullContact, 0, false};
  }
  sim.set_event_sink(&sink);
  sim.start_at_rest();
  bool finite = true;
  while (sim.time() < 2.0 && !sim.mode().terminal() && finite) {
    sim.step();
    finite = sim.state().allFinite();
  }
  return {sim.state(), sim.mode().phase, sink.events.size(), finite};
}

// Slenderness just above 1/sqrt(2) to 20, |epsilon| up to 0.95, T from 0.05 to 10 s, xi from 0
// to 0.99, m_b/m from 0.01 to 100, mu from 0 to 2 (and none), PGA from 1e-4 g to 5 g.
TEST(Stability, ExtremeScenesRunToTheEndFiniteAndDeterministic) {
  std::vector<Extreme> grid;
  for (const double lambda : {0.75, 3.0, 20.0})
    for (const double epsilon : {-0.95, 0.0, 0.95})
      for (const double period : {0.05, 2.0, 10.0})
        for (const double xi : {0.0, 0.99})
          for (const double ratio : {0.01, 100.0})
            for (const double mu : {-1.0, 0.0, 2.0})
              for (const int stops : {0, 2})
                for (const double pga : {1e-4, 5.0})
                  grid.push_back({lambda, epsilon, period, xi, ratio, mu, stops, pga});
  int collapsed = 0;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const Extreme& x = grid[i];
    const Result a = run(x);
    ASSERT_TRUE(a.finite) << "lambda " << x.lambda << " epsilon " << x.epsilon << " T "
                          << x.period << " xi " << x.xi << " ratio " << x.mass_ratio << " mu "
                          << x.mu << " stops " << x.stops << " pga " << x.pga_g;
    collapsed += a.phase == Phase::kOverturned || a.phase == Phase::kFell ? 1 : 0;
    if (i % 7 == 0) {  // determinism, on a sample of the grid
      const Result b = run(x);
      EXPECT_EQ(a.events, b.events);
      EXPECT_EQ(a.phase, b.phase);
      EXPECT_TRUE(a.state == b.state) << "run " << i << " is not repeatable";
    }
  }
  std::printf("%zu extreme scenes, %d collapsed\n", grid.size(), collapsed);
  EXPECT_GT(collapsed, 0) << "the grid must reach collapses too";
}

}  // namespace
}  // namespace plinth
