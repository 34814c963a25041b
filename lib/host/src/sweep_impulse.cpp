#include "plinth/host/sweep_impulse.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>

#include "plinth/core/closed_forms.h"
#include "plinth/core/events.h"
#include "plinth/core/simulator.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"

namespace plinth::host {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

void require_base(const Scene& scene, const char* what) {
  if (!scene.has_base()) {
    throw InputError(std::string(what) +
                     ": needs a scene with a [base] (the closed forms of section 5.3.1 are for "
                     "the isolated block)");
  }
}

Simulator impulse_simulator(const Scene& scene, double dt, EventSink* sink) {
  SolverSettings solver;
  solver.step = dt;
  Simulator sim;
  throw_if_simulator_error(Simulator::create(scene, Excitation::none(), solver, sim), scene,
                           solver.step);
  sim.set_event_sink(sink);
  return sim;
}

// Settles the start from the events as they come: sliding first; or rocking first, then
// sliding (slide-rocking) or the end of the first rocking phase (rocking).
class StartSink final : public EventSink {
 public:
  explicit StartSink(const Scene& scene) : scene_(scene) {}

  void on_event(const Event& e) override {
    if (settled) return;
    if (e.kind == EventKind::kLiftOff) {
      settle(ImpulseStart::kLiftedOff);
      return;
    }
    if (!rocking_) {
      if (e.kind == EventKind::kSlidingStart) {
        settle(ImpulseStart::kSliding);
      } else if (e.kind == EventKind::kRockingStart) {
        rocking_ = true;
        result.corner = e.corner;
        alpha_ = scene_.corner(e.corner).critical_angle;
      }
    } else if (e.kind == EventKind::kSlidingStart) {
      settle(ImpulseStart::kSlideRocking);
      result.slide_angle_ratio = std::fabs(e.state[kTheta]) / alpha_;
    } else if (e.kind == EventKind::kImpact || e.kind == EventKind::kRockingStop ||
               e.kind == EventKind::kOverturned) {
      settle(ImpulseStart::kRocking);
    }
  }

  // When the run ends unsettled.
  void finish() {
    if (!settled) settle(rocking_ ? ImpulseStart::kRocking : ImpulseStart::kFullContact);
  }

  SimulatedStart result;
  bool settled = false;

 private:
  void settle(ImpulseStart start) {
    result.start = start;
    settled = true;
  }

  const Scene& scene_;
  bool rocking_ = false;
  double alpha_ = 1.0;
};

// Whether the non-decreasing curve mu = f(I), I in [from, to], passes through the box
// [i_lo, i_hi] x [mu_lo, mu_hi].
template <typename Curve>
bool curve_crosses(double i_lo, double i_hi, double mu_lo, double mu_hi, double from, double to,
                   Curve f) {
  const double lo = std::max(i_lo, from);
  const double hi = std::min(i_hi, to);
  return lo <= hi && f(lo) <= mu_hi && f(hi) >= mu_lo;
}

}  // namespace

SimulatedStart simulate_impulse_start(const Scene& scene, double impulse, double dt) {
  require_base(scene, "--impulse-map");
  StartSink sink(scene);
  Simulator sim = impulse_simulator(scene, dt, &sink);
  sim.start_with_impulse(impulse);
  const double period = scene.params.base.period;
  while (!sink.settled && sim.time() < period - 0.5 * dt && !sim.mode().terminal()) sim.step();
  sink.finish();
  return sink.result;
}

ImpulseCriteria impulse_criteria(const Scene& scene, double impulse_magnitude) {
  require_base(scene, "impulse criteria");
  ImpulseCriteria c;
  c.sliding_impulse = scene.params.has_friction ? sliding_impulse_threshold(scene) : kInfinity;
  c.rocking_impulse = rocking_impulse_threshold(scene, Corner::kLeft);
  c.dividing_friction = slide_rocking_friction_limit(scene, Corner::kLeft);
  c.rocking_slides_below = rocking_to_sliding_friction(scene, Corner::kLeft, impulse_magnitude);
  return c;
}

ImpulseStart predicted_impulse_start(const Scene& scene, double impulse_magnitude) {
  const ImpulseCriteria c = impulse_criteria(scene, impulse_magnitude);
  const double mu_s =
      scene.params.has_friction ? scene.params.friction.static_coefficient : kInfinity;
  if (mu_s < c.dividing_friction && impulse_magnitude > c.sliding_impulse) {
    return ImpulseStart::kSliding;
  }
  if (mu_s > c.dividing_friction && impulse_magnitude > c.rocking_impulse) {
    return mu_s < c.rocking_slides_below ? ImpulseStart::kSlideRocking : ImpulseStart::kRocking;
  }
  return ImpulseStart::kFullContact;
}

bool near_criteria_curves(const Scene& scene, double impulse_magnitude, double margin) {
  return near_curve(scene, impulse_magnitude, margin) != NearCurve::kNone;
}

NearCurve near_curve(const Scene& scene, double impulse_magnitude, double margin) {
  if (!scene.params.has_friction) return NearCurve::kNone;
  const ImpulseCriteria c = impulse_criteria(scene, impulse_magnitude);
  const double mu_s = scene.params.friction.static_coefficient;
  const double i_lo = impulse_magnitude * (1.0 - margin);
  const double i_hi = impulse_magnitude * (1.0 + margin);
  const double mu_lo = mu_s * (1.0 - margin);
  const double mu_hi = mu_s * (1.0 + margin);
  const double xi = scene.params.base.damping_ratio;
  const double peak_per_impulse = scene.omega * peak_acceleration_factor(xi) / scene.g;
  const auto c_s = [&](double i) { return i * peak_per_impulse; };  // Eq 38 as mu_s(|I|)
  const auto c_sr = [&](double) { return c.dividing_friction; };    // Eq 39
  const auto c_rs = [&](double i) {                                 // Eq 41
    return rocking_to_sliding_friction(scene, Corner::kLeft, i);
  };
  const auto at_once = [&](double i) { return 2.0 * xi * scene.omega * i / scene.g; };
  const bool c_r = c.rocking_impulse >= i_lo && c.rocking_impulse <= i_hi &&  // Eq 37, vertical
                   mu_hi >= c.dividing_friction;
  if (c_r || curve_crosses(i_lo, i_hi, mu_lo, mu_hi, 0.0, c.rocking_impulse, c_s) ||
      curve_crosses(i_lo, i_hi, mu_lo, mu_hi, c.rocking_impulse, kInfinity, c_sr) ||
      curve_crosses(i_lo, i_hi, mu_lo, mu_hi, c.rocking_impulse, kInfinity, c_rs)) {
    return NearCurve::kCriteria;
  }
  return curve_crosses(i_lo, i_hi, mu_lo, mu_hi, 0.0, kInfinity, at_once)
             ? NearCurve::kSlidingAtOnce
             : NearCurve::kNone;
}

SweepPlan plan_impulse_map(const SceneParams& base, const GridAxis& mu_axis,
                           const GridAxis& impulse_axis, double dt) {
  if (!base.has_base) {
    throw InputError(
        "--impulse-map: needs a scene with a [base] (the closed forms of section 5.3.1 are for "
        "the isolated block)");
  }
  if (!std::isfinite(dt) || dt <= 0.0) {
    throw InputError("--dt: must be greater than zero, got " + format_value(dt) + " s");
  }
  const std::vector<double> mus = sweep_values(mu_axis.from, mu_axis.to, mu_axis.steps, "--mu-");
  const std::vector<double> impulses =
      sweep_values(impulse_axis.from, impulse_axis.to, impulse_axis.steps, "--impulse-");
  (void)bounded_count(static_cast<double>(mus.size()) * static_cast<double>(impulses.size()),
                      kMaxSweepRows,
                      "--mu-steps " + std::to_string(mus.size()) + " and --impulse-steps " +
                          std::to_string(impulses.size()),
                      "the map would have", "rows");
  if (impulses.front() <= 0.0) {
    throw InputError("--impulse-from: |I| must be greater than zero, got " +
                     format_value(impulses.front()) + " m/s");
  }
  auto scenes =
      std::make_shared<const std::vector<Scene>>(sweep_scenes(base, SweepParameter::kMuS, mus));
  // The step must suit the base: check it once here rather than in every job.
  (void)impulse_simulator(scenes->front(), dt, nullptr);

  SweepPlan plan;
  plan.settings = SettingsLine("impulse_map", {mu_axis, impulse_axis})
                      .add("scene", fingerprint(base))
                      .add("dt", dt)
                      .text();
  plan.header = "mu_s,impulse,simulated,predicted,c_s,c_r,c_sr,c_rs";
  plan.key_columns = 2;
  plan.keys = grid_keys({mu_axis, impulse_axis});
  const std::size_t columns = impulses.size();
  const std::vector<std::string> keys = plan.keys;
  plan.row = [scenes, impulses, columns, dt, keys](std::size_t i, const std::atomic<bool>* stop,
                                                   std::size_t* simulations) {
    if (stop != nullptr && stop->load()) throw JobCancelled();
    const Scene& scene = (*scenes)[i / columns];
    const double impulse = impulses[i % columns];
    const SimulatedStart simulated = simulate_impulse_start(scene, -impulse, dt);
    if (simulations != nullptr) ++*simulations;
    const ImpulseCriteria c = impulse_criteria(scene, impulse);
    return keys[i] + "," + impulse_start_name(simulated.start) + "," +
           impulse_start_name(predicted_impulse_start(scene, impulse)) + "," +
           format_result(c.sliding_impulse) + "," + format_result(c.rocking_impulse) + "," +
           format_result(c.dividing_friction) + "," + format_result(c.rocking_slides_below);
  };
  plan.describe = [mus, impulses, columns](std::size_t i) {
    return "mu_s = " + format_value(mus[i / columns]) +
           ", |I| = " + format_value(impulses[i % columns]) + " m/s";
  };
  return plan;
}

void validate(const ImpulseSearchSettings& s) {
  if (!std::isfinite(s.impulse_max) || s.impulse_max <= 0.0) {
    throw InputError("--impulse-max: must be greater than zero, got " +
                     format_value(s.impulse_max) + " m/s");
  }
  if (!std::isfinite(s.tolerance) || s.tolerance <= 0.0) {
    throw InputError("--impulse-tol: must be greater than zero, got " + format_value(s.tolerance) +
                     " m/s");
  }
  if (s.scan_points < 1) {
    throw InputError("scan points: must be at least 1, got " + std::to_string(s.scan_points));
  }
  if (!std::isfinite(s.dt) || s.dt <= 0.0) {
    throw InputError("--dt: must be greater than zero, got " + format_value(s.dt) + " s");
  }
}

Occurrences simulate_impulse_occurrences(const Scene& scene, double impulse, double dt,
                                         EventSet events) {
  // Only rocking, overturning and lift-off are looked for; the block's own rest ends a run on
  // the ground.
  class Sink final : public EventSink {
   public:
    void on_event(const Event& e) override {
      if (e.kind == EventKind::kRockingStart) mark(SweepEvent::kRocking);
      if (e.kind == EventKind::kOverturned) mark(SweepEvent::kOverturned);
      if (e.kind == EventKind::kLiftOff) mark(SweepEvent::kLiftOff);
      if (e.kind == EventKind::kRockingStop) at_rest = true;
    }
    void mark(SweepEvent e) {
      result.occurred[static_cast<std::size_t>(e)] = true;
      seen.set(static_cast<std::size_t>(e));
    }
    Occurrences result;
    EventSet seen;
    bool at_rest = false;
  } sink;
  Simulator sim = impulse_simulator(scene, dt, &sink);
  sim.start_with_impulse(impulse);
  const bool on_base = scene.has_base();
  const double t_end = on_base ? 5.0 * scene.params.base.period : 60.0;
  events &= EventSet{}
                .set(static_cast<std::size_t>(SweepEvent::kRocking))
                .set(static_cast<std::size_t>(SweepEvent::kOverturned))
                .set(static_cast<std::size_t>(SweepEvent::kLiftOff));
  while (sim.time() < t_end && !sim.mode().terminal() && (sink.seen & events) != events &&
         (on_base || !sink.at_rest)) {
    sim.step();
  }
  return sink.result;
}

double ground_overturning_impulse(const Scene& scene) {
  // The smallest theta' about a corner that carries C over it: 1/2 I_i theta'^2 = m g (r_i - h).
  const auto overturning_rate = [&](const CornerGeometry& c) {
    return std::sqrt(2.0 * scene.m * scene.g * (c.radius - scene.h) / c.inertia);
  };
  const double first = overturning_rate(scene.corner1);
  // Back at theta = 0 with the same speed, the impact (ratio J / I_2 on fixed ground, Eq 23)
  // throws it on corner 2, which may be the easier one to overturn about.
  const double ratio = scene.impact_inertia / scene.corner2.inertia;
  const double second = ratio > 0.0 ? overturning_rate(scene.corner2) / ratio : first;
  return std::min(first, second) * scene.corner1.inertia / (scene.m * scene.h);
}

ImpulseThresholds impulse_thresholds(const Scene& scene, const ImpulseSearchSettings& settings,
                                     std::size_t* simulations, const std::atomic<bool>* stop) {
  validate(settings);
  SearchGrid grid;
  grid.level_max = settings.impulse_max;
  grid.scan_points = settings.scan_points;
  grid.tolerance = settings.tolerance;
  EventSet events;
  events.set(static_cast<std::size_t>(SweepEvent::kOverturned));
  events.set(static_cast<std::size_t>(SweepEvent::kLiftOff));
  if (scene.has_base()) events.set(static_cast<std::size_t>(SweepEvent::kRocking));
  const auto found = first_occurrences(
      [&](double magnitude) {
        return simulate_impulse_occurrences(scene, -magnitude, settings.dt, events);
      },
      grid, events, stop, simulations);
  ImpulseThresholds out;
  out.rocking = scene.has_base() ? found[static_cast<std::size_t>(SweepEvent::kRocking)] : 0.0;
  out.overturned = found[static_cast<std::size_t>(SweepEvent::kOverturned)];
  out.lift_off = found[static_cast<std::size_t>(SweepEvent::kLiftOff)];
  return out;
}

SweepPlan plan_impulse_curve(const SceneParams& base, SweepParameter parameter,
                             const GridAxis& axis, const ImpulseSearchSettings& settings,
                             bool compare_ground) {
  validate(settings);
  if (compare_ground) require_base_to_compare(base);
  const std::vector<double> values = sweep_values(axis.from, axis.to, axis.steps);
  auto scenes = std::make_shared<const std::vector<Scene>>(sweep_scenes(base, parameter, values));
  for (const Scene& scene : *scenes) (void)impulse_simulator(scene, settings.dt, nullptr);
  // The counterparts on the ground, and their thresholds, searched once per distinct scene.
  struct Ground {
    explicit Ground(GroundScenes scenes)
        : on_ground(std::move(scenes)), thresholds(on_ground.distinct.size()) {}
    GroundScenes on_ground;
    OnceCache<ImpulseThresholds> thresholds;
  };
  std::shared_ptr<Ground> ground;
  if (compare_ground) {
    ground = std::make_shared<Ground>(ground_scenes(*scenes));
    for (const Scene& scene : ground->on_ground.distinct) {
      (void)impulse_simulator(scene, settings.dt, nullptr);
    }
  }
  SweepPlan plan;
  SettingsLine line("impulse_curve", {axis});
  line.add("scene", fingerprint(base))
      .add("impulse_max", settings.impulse_max)
      .add("impulse_tol", settings.tolerance)
      .add("scan_points", std::to_string(settings.scan_points))
      .add("dt", settings.dt);
  plan.header = std::string(sweep_parameter_name(parameter)) +
                ",rocking,overturned,rocking_closed_form,overturned_closed_form,lift_off";
  if (ground) {
    line.add("compare", "ground");
    plan.header += std::string(",overturned") + kGroundSuffix + ",overturned_closed_form" +
                   kGroundSuffix + ",lift_off" + kGroundSuffix;
  }
  plan.settings = line.text();
  plan.keys = grid_keys({axis});
  const std::vector<std::string> keys = plan.keys;
  plan.row = [scenes, ground, settings, keys](std::size_t i, const std::atomic<bool>* stop,
                                              std::size_t* simulations) {
    const Scene& scene = (*scenes)[i];
    const ImpulseThresholds found = impulse_thresholds(scene, settings, simulations, stop);
    const bool on_base = scene.has_base();
    const std::optional<double> rocking_closed_form =
        on_base ? rocking_impulse_threshold(scene, Corner::kLeft) : 0.0;
    const std::optional<double> overturned_closed_form =
        on_base ? std::nullopt : std::optional<double>(ground_overturning_impulse(scene));
    std::string row = keys[i] + "," + format_result(found.rocking) + "," +
                      format_result(found.overturned) + "," + format_result(rocking_closed_form) +
                      "," + format_result(overturned_closed_form) + "," +
                      format_result(found.lift_off);
    if (ground) {
      const std::size_t k = ground->on_ground.of[i];
      const Scene& on_ground = ground->on_ground.distinct[k];
      const ImpulseThresholds g = ground->thresholds.get(k, [&] {
        try {
          return impulse_thresholds(on_ground, settings, simulations, stop);
        } catch (const InputError& e) {
          throw InputError(std::string("the block on the ground: ") + e.what());
        }
      });
      row += ',';
      row += format_result(g.overturned);
      row += ',';
      row += format_result(ground_overturning_impulse(on_ground));
      row += ',';
      row += format_result(g.lift_off);
    }
    return row;
  };
  plan.describe = [parameter, values](std::size_t i) {
    return describe_value("--param", parameter, values[i]);
  };
  return plan;
}

}  // namespace plinth::host
