#include "plinth/host/sweep_search.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>

#include "plinth/core/events.h"
#include "plinth/core/simulator.h"
#include "plinth/host/input_error.h"
#include "plinth/host/job_runner.h"
#include "plinth/host/parse_name.h"
#include "plinth/host/sweep_table.h"

namespace plinth::host {
namespace {

class OccurrenceSink final : public EventSink {
 public:
  void on_event(const Event& e) override {
    switch (e.kind) {
      case EventKind::kSlidingStart:
        mark(SweepEvent::kSliding);
        break;
      case EventKind::kRockingStart:
        mark(SweepEvent::kRocking);
        break;
      case EventKind::kOutOfBase:
        mark(SweepEvent::kOutOfBase);
        break;
      case EventKind::kBaseStopHit:
        mark(SweepEvent::kBaseStopHit);
        break;
      case EventKind::kSlideStopHit:
        mark(SweepEvent::kSlideStopHit);
        break;
      case EventKind::kFell:
        mark(SweepEvent::kFell);
        break;
      case EventKind::kOverturned:
        mark(SweepEvent::kOverturned);
        break;
      case EventKind::kLiftOff:
        mark(SweepEvent::kLiftOff);
        break;
      default:
        break;
    }
    if (e.phase == Phase::kSlideRocking) mark(SweepEvent::kSlideRocking);
  }

  Occurrences result;
  EventSet seen;

 private:
  void mark(SweepEvent e) {
    result.occurred[static_cast<std::size_t>(e)] = true;
    seen.set(static_cast<std::size_t>(e));
  }
};

}  // namespace

void require_scalable(const Record& record) {
  if (!(record.peak_horizontal() > 0.0)) {
    throw InputError(record.name + ": record is all zeros, cannot scale to a PGA");
  }
}

SweepEvent parse_sweep_event(const std::string& text) {
  return parse_name<kSweepEventNames>(text, "--event", "event");
}

EventSet possible_events(const Scene& scene) {
  const Features f = features_of(scene);
  EventSet events;
  events.set(static_cast<std::size_t>(SweepEvent::kRocking));
  events.set(static_cast<std::size_t>(SweepEvent::kOverturned));
  events.set(static_cast<std::size_t>(SweepEvent::kLiftOff));
  events.set(static_cast<std::size_t>(SweepEvent::kSliding), f.sliding);
  events.set(static_cast<std::size_t>(SweepEvent::kSlideRocking), f.sliding);
  events.set(static_cast<std::size_t>(SweepEvent::kBaseStopHit), f.base_stops);
  events.set(static_cast<std::size_t>(SweepEvent::kOutOfBase), f.support_edge);
  events.set(static_cast<std::size_t>(SweepEvent::kFell), f.support_edge);
  events.set(static_cast<std::size_t>(SweepEvent::kSlideStopHit), f.sliding_stops);
  return events;
}

void validate(const SweepSettings& s) {
  if (!std::isfinite(s.pga_max_g) || s.pga_max_g <= 0.0) {
    throw InputError("--pga-max: must be greater than zero, got " + format_value(s.pga_max_g) +
                     " g");
  }
  if (!std::isfinite(s.tolerance_g) || s.tolerance_g <= 0.0) {
    throw InputError("--tol: must be greater than zero, got " + format_value(s.tolerance_g) + " g");
  }
  if (s.scan_points < 1) {
    throw InputError("scan points: must be at least 1, got " + std::to_string(s.scan_points));
  }
  if (!std::isfinite(s.dt) || s.dt <= 0.0) {
    throw InputError("--dt: must be greater than zero, got " + format_value(s.dt) + " s");
  }
}

Occurrences simulate_occurrences(const Scene& scene, const Record& record, double pga_mps2,
                                 const SweepSettings& settings) {
  require_scalable(record);
  if (!std::isfinite(pga_mps2) || pga_mps2 < 0.0) {
    throw InputError("PGA must be finite and not negative, got " + format_value(pga_mps2) +
                     " m/s2");
  }
  SolverSettings solver;
  solver.step = settings.dt;
  Simulator sim;
  const Excitation excitation =
      Excitation::record(record.horizontal_signal(), {}, pga_mps2 / record.peak_horizontal());
  throw_if_simulator_error(Simulator::create(scene, excitation, solver, sim), scene, solver.step);
  OccurrenceSink sink;
  sim.set_event_sink(&sink);
  sim.start_at_rest();
  // Once every event searched for has been seen, the rest of the run cannot change the answer.
  const EventSet wanted = settings.events & possible_events(scene);
  const double t_end = record.duration() + 2.0;
  while (sim.time() < t_end && !sim.mode().terminal() && (sink.seen & wanted) != wanted) {
    sim.step();
  }
  return sink.result;
}

double quiet_pga_g(const Scene& scene, const Record& record, double dt) {
  require_scalable(record);
  const SceneParams& p = scene.params;
  double acceleration_limit = scene.g * std::min(scene.b1, scene.b2) / scene.h;  // Eq 16
  if (p.has_friction) {
    acceleration_limit = std::min(acceleration_limit, p.friction.static_coefficient * scene.g);
  }
  const double displacement_limit =
      p.has_base_stops ? p.base_stops.max_displacement : std::numeric_limits<double>::infinity();
  // Eq 16 holds from equality on: keep a margin, and more for peaks sampled once per step.
  constexpr double kMargin = 0.02;
  if (!p.has_base) return (1.0 - kMargin) * acceleration_limit / scene.g;  // the ground itself

  // The base alone under the record scaled to a PGA of 1 m/s2: the same m + m_b, k and c
  // (Eq 26), a block too squat to rock (b/h = 1000), no friction, stops or support.
  SceneParams linear;
  linear.gravity = p.gravity;
  linear.block.half_width = p.block.half_width;
  linear.block.com_height = 1e-3 * p.block.half_width;
  linear.block.mass = p.block.mass;
  linear.block.inertia =
      homogeneous_rectangle_inertia(p.block.mass, p.block.half_width, linear.block.com_height);
  linear.has_base = true;
  linear.base = p.base;
  Scene base_alone;
  if (!make_scene(linear, base_alone).ok()) return 0.0;
  SolverSettings solver;
  solver.step = dt;
  Simulator sim;
  const Excitation unit =
      Excitation::record(record.horizontal_signal(), {}, 1.0 / record.peak_horizontal());
  if (!Simulator::create(base_alone, unit, solver, sim).ok()) return 0.0;
  sim.start_at_rest();
  double peak_acceleration = 0.0;  // |u'' + u_G''| per m/s2 of PGA
  double peak_displacement = 0.0;  // |u| per m/s2 of PGA
  const double t_end = record.duration() + 2.0;
  while (sim.time() < t_end) {
    sim.step();
    if (sim.mode().phase != Phase::kFullContact) return 0.0;
    peak_acceleration = std::max(
        peak_acceleration, std::fabs(sim.accelerations().u + sim.ground(sim.time()).horizontal));
    peak_displacement = std::max(peak_displacement, std::fabs(sim.state()[kU]));
  }
  const double omega_dt = scene.omega * dt;
  const double margin = std::min(0.5, kMargin + omega_dt * omega_dt);
  const double quiet =
      std::min(acceleration_limit / peak_acceleration, displacement_limit / peak_displacement);
  return (1.0 - margin) * quiet / scene.g;
}

std::array<std::optional<double>, kSweepEventCount> first_occurrences(
    const std::function<Occurrences(double level)>& simulate, const SearchGrid& grid,
    EventSet events, const std::atomic<bool>* stop, std::size_t* simulations) {
  std::map<double, Occurrences> runs;  // every level simulated, once
  const auto run = [&](double level) -> const Occurrences& {
    auto it = runs.find(level);
    if (it == runs.end()) {
      if (stop != nullptr && stop->load()) throw JobCancelled();
      const Occurrences none{};
      it = runs.emplace(level, level <= grid.quiet_below ? none : simulate(level)).first;
      if (simulations != nullptr && level > grid.quiet_below) ++*simulations;
    }
    return it->second;
  };
  const double tol = grid.tolerance;
  const int n = grid.scan_points;
  const auto scan_level = [&](int k) { return grid.level_max * static_cast<double>(k) / n; };

  std::array<int, kSweepEventCount> first{};  // first grid index showing the event, 0: none
  for (int k = 1; k <= n && (events.any()); ++k) {
    bool pending = false;
    for (std::size_t e = 0; e < kSweepEventCount; ++e) {
      if (!events[e] || first[e] != 0) continue;
      if (run(scan_level(k)).occurred[e]) {
        first[e] = k;
      } else {
        pending = true;
      }
    }
    if (!pending) break;
  }

  std::array<std::optional<double>, kSweepEventCount> out;
  for (std::size_t e = 0; e < kSweepEventCount; ++e) {
    if (first[e] == 0) continue;
    // What this event's search knows: the scan up to its first showing, and its own runs.
    std::map<double, bool> known;
    for (int k = 1; k <= first[e]; ++k) known[scan_level(k)] = run(scan_level(k)).occurred[e];
    const auto occurs = [&](double level) {
      if (level <= 0.0) return false;  // assumed: nothing happens without excitation
      return known[level] = run(level).occurred[e];
    };
    double hi = scan_level(first[e]);  // the event occurs here
    for (;;) {
      // The tightest bracket known: absent at lo, present at hi.
      double lo = 0.0;
      for (auto it = std::make_reverse_iterator(known.lower_bound(hi)); it != known.rend(); ++it) {
        if (!it->second) {
          lo = it->first;
          break;
        }
      }
      for (auto it = known.upper_bound(lo); it != known.end() && it->first <= hi; ++it) {
        if (it->second) {
          hi = it->first;
          break;
        }
      }
      double a = lo;
      while (hi - a > tol) {
        const double mid = 0.5 * (a + hi);
        (occurs(mid) ? hi : a) = mid;
      }
      // Behaviour need not be monotonic: make sure the event is absent one tolerance below,
      // else look again below that point.
      const double below = hi - tol;
      if (below <= 0.0 || !occurs(below)) break;
      hi = below;
    }
    out[e] = hi;
  }
  return out;
}

std::array<std::optional<double>, kSweepEventCount> first_occurrence_thresholds(
    const Scene& scene, const Record& record, const SweepSettings& settings,
    std::size_t* simulations, const std::atomic<bool>* stop) {
  validate(settings);
  require_scalable(record);
  SearchGrid grid;
  grid.level_max = settings.pga_max_g;
  grid.scan_points = settings.scan_points;
  grid.tolerance = settings.tolerance_g;
  if (settings.skip_quiet_scan) {
    grid.quiet_below = quiet_pga_g(scene, record, settings.dt);
    if (simulations != nullptr && scene.has_base()) ++*simulations;  // the base-alone run
  }
  const auto simulate = [&](double pga_g) {
    return simulate_occurrences(scene, record, pga_g * scene.g, settings);
  };
  return first_occurrences(simulate, grid, settings.events & possible_events(scene), stop,
                           simulations);
}

}  // namespace plinth::host
