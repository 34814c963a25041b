// Shared helpers of the core test suites: scenes built in code and a recording event sink.
#pragma once

#include <vector>

#include "plinth/core/estimator.h"
#include "plinth/core/forecast.h"
#include "plinth/core/scene.h"
#include "plinth/core/simulator.h"

namespace plinth::testing {

// The paper's block (b = 0.3 m, lambda = 3, rho = 2000 kg/m3, 1 m deep, homogeneous I_C),
// with eccentricity ratio `epsilon`, on the ground.
inline SceneParams paper_block(double epsilon = 0.0) {
  SceneParams p;
  p.block.half_width = 0.3;
  p.block.com_height = 0.9;
  p.block.eccentricity = epsilon * 0.3;
  p.block.mass = 2000.0 * 0.6 * 1.8;
  p.block.inertia = homogeneous_rectangle_inertia(p.block.mass, 0.3, 0.9);
  return p;
}

// The same block on the paper's base: m_b = m, T = 2 s, xi = 0.2.
inline SceneParams paper_isolated(double epsilon = 0.0, double period = 2.0, double xi = 0.2) {
  SceneParams p = paper_block(epsilon);
  p.has_base = true;
  p.base.mass = p.block.mass;
  p.base.period = period;
  p.base.damping_ratio = xi;
  return p;
}

inline Scene make(const SceneParams& p) {
  Scene s;
  const Error e = make_scene(p, s);
  if (!e.ok()) __builtin_trap();
  return s;
}

// A block twice as wide as the paper's (uplift at 2g/3): it stands where the paper's rocks.
inline Scene wide_block() {
  SceneParams wide = paper_block();
  wide.block.half_width = 0.6;
  wide.block.inertia = homogeneous_rectangle_inertia(wide.block.mass, 0.6, 0.9);
  return make(wide);
}

// The ensembles' tests' estimator (200 Hz, 4 steps a sample) and no forecast.
inline EstimatorSettings ensemble_estimator_settings() {
  EstimatorSettings e;
  e.sample_rate_hz = 200.0;
  e.steps_per_sample = 4;
  return e;
}

inline ForecastSettings no_forecast() {
  ForecastSettings f;
  f.enabled = false;
  return f;
}

class RecordingSink final : public EventSink {
 public:
  void on_event(const Event& e) override { events.push_back(e); }

  [[nodiscard]] const Event* first(EventKind kind) const {
    for (const Event& e : events) {
      if (e.kind == kind) return &e;
    }
    return nullptr;
  }
  [[nodiscard]] int count(EventKind kind) const {
    int n = 0;
    for (const Event& e : events) n += e.kind == kind ? 1 : 0;
    return n;
  }

  std::vector<Event> events;
};

// Runs a simulation from rest (or from an impulse when `impulse` != 0) until `t_end` or a
// terminal phase; returns the simulator in its final state.
inline Simulator run(const Scene& scene, const Excitation& excitation, double t_end,
                     double dt, EventSink* sink, double impulse = 0.0,
                     SolverSettings settings = {}) {
  settings.step = dt;
  Simulator sim;
  if (!Simulator::create(scene, excitation, settings, sim).ok()) __builtin_trap();
  sim.set_event_sink(sink);
  if (impulse != 0.0) {
    sim.start_with_impulse(impulse);
  } else {
    sim.start_at_rest();
  }
  while (sim.time() < t_end - 0.5 * dt && !sim.mode().terminal()) sim.step();
  return sim;
}

// Bisects on a monotone predicate: `occurs(high)` holds and `occurs(low)` does not; returns the
// middle of the final bracket, narrower than `width`.
template <typename Predicate>
double bisect_threshold(Predicate occurs, double low, double high, double width) {
  while (high - low > width) {
    const double mid = 0.5 * (low + high);
    (occurs(mid) ? high : low) = mid;
  }
  return 0.5 * (low + high);
}

// The scene with Coulomb friction between block and base: static mu_s, kinetic mu_k.
inline SceneParams with_friction(SceneParams p, double mu_s, double mu_k) {
  p.has_friction = true;
  p.friction = {mu_s, mu_k};
  return p;
}

}  // namespace plinth::testing
