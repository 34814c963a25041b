#include "plinth/host/sweep.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <thread>

#include "plinth/core/events.h"
#include "plinth/core/simulator.h"
#include "plinth/host/input_error.h"

namespace plinth::host {
namespace {

constexpr std::array<const char*, kSweepEventCount> kEventNames = {
    "sliding",       "rocking",        "slide_rocking", "out_of_base",
    "base_stop_hit", "slide_stop_hit", "fell",          "overturned"};

constexpr std::array<const char*, 7> kParameterNames = {"mu_s", "epsilon", "lambda",    "T",
                                                        "xi",   "u_max",   "mass_ratio"};

// "a, b, c" of a list of names.
template <std::size_t N>
std::string joined(const std::array<const char*, N>& names) {
  std::string text;
  for (const char* name : names) {
    if (!text.empty()) text += ", ";
    text += name;
  }
  return text;
}

class OccurrenceSink final : public EventSink {
 public:
  void on_event(const Event& e) override {
    switch (e.kind) {
      case EventKind::kSlidingStart: mark(SweepEvent::kSliding); break;
      case EventKind::kRockingStart: mark(SweepEvent::kRocking); break;
      case EventKind::kOutOfBase: mark(SweepEvent::kOutOfBase); break;
      case EventKind::kBaseStopHit: mark(SweepEvent::kBaseStopHit); break;
      case EventKind::kSlideStopHit: mark(SweepEvent::kSlideStopHit); break;
      case EventKind::kFell: mark(SweepEvent::kFell); break;
      case EventKind::kOverturned: mark(SweepEvent::kOverturned); break;
      default: break;
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

void check_record(const Record& record) {
  if (!(record.peak_horizontal() > 0.0)) {
    throw InputError(record.name + ": record is all zeros, cannot scale to a PGA");
  }
}

}  // namespace

const char* sweep_event_name(SweepEvent event) {
  return kEventNames[static_cast<std::size_t>(event)];
}

SweepEvent parse_sweep_event(const std::string& text) {
  for (std::size_t i = 0; i < kEventNames.size(); ++i) {
    if (text == kEventNames[i]) return static_cast<SweepEvent>(i);
  }
  throw InputError("--event: unknown event '" + text + "' (one of " + joined(kEventNames) + ")");
}

EventSet possible_events(const Scene& scene) {
  const Features f = features_of(scene);
  EventSet events;
  events.set(static_cast<std::size_t>(SweepEvent::kRocking));
  events.set(static_cast<std::size_t>(SweepEvent::kOverturned));
  events.set(static_cast<std::size_t>(SweepEvent::kSliding), f.sliding);
  events.set(static_cast<std::size_t>(SweepEvent::kSlideRocking), f.sliding);
  events.set(static_cast<std::size_t>(SweepEvent::kBaseStopHit), f.base_stops);
  events.set(static_cast<std::size_t>(SweepEvent::kOutOfBase), f.support_edge);
  events.set(static_cast<std::size_t>(SweepEvent::kFell), f.support_edge);
  events.set(static_cast<std::size_t>(SweepEvent::kSlideStopHit), f.sliding_stops);
  return events;
}

const char* sweep_parameter_name(SweepParameter parameter) {
  return kParameterNames[static_cast<std::size_t>(parameter)];
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
  check_record(record);
  if (!std::isfinite(pga_mps2) || pga_mps2 < 0.0) {
    throw InputError("PGA must be finite and not negative, got " + format_value(pga_mps2) +
                     " m/s2");
  }
  SolverSettings solver;
  solver.step = settings.dt;
  Simulator sim;
  const Excitation excitation =
      Excitation::record(record.horizontal_signal(), {}, pga_mps2 / record.peak_horizontal());
  throw_if_simulator_error(Simulator::create(scene, excitation, solver, sim));
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
  check_record(record);
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
      if (stop != nullptr && stop->load()) throw SweepCancelled();
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
  check_record(record);
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

bool parameter_needs_base(SweepParameter parameter) {
  return parameter == SweepParameter::kPeriod || parameter == SweepParameter::kXi ||
         parameter == SweepParameter::kMassRatio || parameter == SweepParameter::kUMax;
}

SceneParams ground_counterpart(const SceneParams& params) {
  SceneParams ground;
  ground.gravity = params.gravity;
  ground.block = params.block;
  ground.has_friction = params.has_friction;
  ground.friction = params.friction;
  return ground;
}

GroundScenes ground_scenes(const std::vector<Scene>& scenes) {
  GroundScenes ground;
  for (const Scene& scene : scenes) {
    const SceneParams params = ground_counterpart(scene.params);
    ground.scenes.emplace_back();
    if (const Error e = make_scene(params, ground.scenes.back()); !e.ok()) {
      throw InputError("--compare-ground: the block on the ground: " + std::string(e.field) +
                       ": " + e.reason);
    }
    ground.keys.push_back(fingerprint(params));
  }
  return ground;
}

void require_base_to_compare(const SceneParams& params) {
  if (!params.has_base) {
    throw InputError(
        "--compare-ground: the scene has no [base]: it is already the block on the ground "
        "(compare needs the isolated scene)");
  }
}

SweepParameter parse_sweep_parameter(const std::string& text, const std::string& option) {
  for (std::size_t i = 0; i < kParameterNames.size(); ++i) {
    if (text == kParameterNames[i]) return static_cast<SweepParameter>(i);
  }
  throw InputError(option + ": unknown parameter '" + text + "' (one of " +
                   joined(kParameterNames) + ")");
}

std::string describe_value(const std::string& option, SweepParameter parameter, double value) {
  return option + " " + sweep_parameter_name(parameter) + " = " + format_value(value);
}

SceneParams with_parameter(SceneParams p, SweepParameter parameter, double value,
                           const std::string& option) {
  const std::string what = describe_value(option, parameter, value);
  if (!std::isfinite(value)) throw InputError(what + ": not a finite number");
  if (parameter_needs_base(parameter) && !p.has_base) {
    throw InputError(what + ": the scene has no [base] (a block on the ground)");
  }
  switch (parameter) {
    case SweepParameter::kMuS:
      p.has_friction = true;
      p.friction.static_coefficient = value;
      p.friction.kinetic_coefficient = 0.8 * value;
      break;
    case SweepParameter::kEpsilon: p.block.eccentricity = value * p.block.half_width; break;
    case SweepParameter::kLambda: {
      const double h = value * p.block.half_width;
      const double old_h = p.block.com_height;
      if (old_h > 0.0 && h > 0.0) {
        const double factor = h / old_h;
        p.block.mass *= factor;
        p.base.mass *= factor;  // keeps m_b / m
      }
      p.block.com_height = h;
      p.block.inertia = homogeneous_rectangle_inertia(p.block.mass, p.block.half_width, h);
      break;
    }
    case SweepParameter::kPeriod: p.base.period = value; break;
    case SweepParameter::kXi: p.base.damping_ratio = value; break;
    case SweepParameter::kUMax:
      if (!p.has_base_stops) throw InputError(what + ": the scene has no [base_stops]");
      p.base_stops.max_displacement = value;
      break;
    case SweepParameter::kMassRatio: p.base.mass = value * p.block.mass; break;
  }
  Scene scene;
  if (const Error e = make_scene(p, scene); !e.ok()) {
    throw InputError(what + ": " + e.field + ": " + e.reason);
  }
  return p;
}

void validate(const SweepRun& run) {
  if (run.jobs < 1) {
    throw InputError("--jobs: must be at least 1, got " + std::to_string(run.jobs));
  }
  if (run.shard_count < 1 || run.shard_index < 1 || run.shard_index > run.shard_count) {
    throw InputError("--shard: must be i/N with 1 <= i <= N, got " +
                     std::to_string(run.shard_index) + "/" + std::to_string(run.shard_count));
  }
}

std::vector<std::size_t> shard_indices(std::size_t count, const SweepRun& run) {
  validate(run);
  std::vector<std::size_t> indices;
  const auto shards = static_cast<std::size_t>(run.shard_count);
  for (std::size_t i = static_cast<std::size_t>(run.shard_index - 1); i < count; i += shards) {
    indices.push_back(i);
  }
  return indices;
}

bool run_jobs(const std::vector<std::size_t>& indices, const SweepRun& run,
              const std::function<void(std::size_t)>& job,
              const std::function<std::string(std::size_t)>& describe) {
  validate(run);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> cancelled{false};
  std::mutex done_mutex;
  std::vector<std::exception_ptr> errors(indices.size());
  const auto stopped = [&] { return run.stop != nullptr && run.stop->load(); };
  auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= indices.size()) return;
      if (stopped()) {
        cancelled = true;
        return;
      }
      const std::size_t i = indices[k];
      try {
        job(i);
        if (run.on_done) {
          const std::lock_guard<std::mutex> lock(done_mutex);
          run.on_done(i);
        }
      } catch (const SweepCancelled&) {
        cancelled = true;
        return;
      } catch (const InputError& e) {
        errors[k] = std::make_exception_ptr(InputError(describe(i) + ": " + e.what()));
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  const std::size_t threads =
      std::min(static_cast<std::size_t>(run.jobs), std::max<std::size_t>(indices.size(), 1));
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(threads);
    for (std::size_t t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return !cancelled.load();
}

bool run_plan(const SweepPlan& plan, const std::vector<std::size_t>& indices, const SweepRun& run,
              std::vector<std::string>& rows, std::size_t* simulations) {
  rows.resize(plan.keys.size());
  std::atomic<std::size_t> total{0};
  const bool finished = run_jobs(
      indices, run,
      [&](std::size_t i) {
        std::size_t runs = 0;
        std::string row = plan.row(i, run.stop, &runs);
        total += runs;
        rows[i] = std::move(row);
      },
      plan.describe);
  if (simulations != nullptr) *simulations += total.load();
  return finished;
}

std::vector<Scene> sweep_scenes(const SceneParams& base, SweepParameter parameter,
                                const std::vector<double>& values) {
  std::vector<Scene> scenes(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!make_scene(with_parameter(base, parameter, values[i]), scenes[i]).ok()) {
      throw InputError("internal: make_scene refused a checked scene");
    }
  }
  return scenes;
}

std::string sweep_csv_header(SweepParameter parameter) {
  std::string header = sweep_parameter_name(parameter);
  for (const char* name : kEventNames) {
    header += ',';
    header += name;
  }
  return header;
}

std::string sweep_csv_row(const SweepRow& row) {
  std::string line = format_value(row.value);
  for (const std::optional<double>& t : row.thresholds_g) {
    line += ',';
    line += format_result(t);
  }
  return line;
}

namespace {

// The settings line of a PGA sweep: the scene, the record and the search.
SettingsLine pga_settings(const std::string& mode, const std::vector<GridAxis>& grid,
                          const SceneParams& base, const Record& record, const SweepSettings& s) {
  SettingsLine line(mode, grid);
  line.add("scene", fingerprint(base))
      .add("record", fingerprint(record))
      .add("pga_max_g", s.pga_max_g)
      .add("tol_g", s.tolerance_g)
      .add("scan_points", std::to_string(s.scan_points))
      .add("dt", s.dt);
  return line;
}

using Thresholds = std::array<std::optional<double>, kSweepEventCount>;

// The counterparts on the ground of the scenes of a plan, the events they can have, and the
// thresholds of each distinct one, searched once.
struct GroundPlan {
  GroundScenes ground;
  EventSet events;  // the events they can have, of those searched
  OnceCache<Thresholds> thresholds;
};

std::shared_ptr<GroundPlan> ground_plan(const std::vector<Scene>& scenes,
                                        const EventSet& searched) {
  auto plan = std::make_shared<GroundPlan>();
  plan->ground = ground_scenes(scenes);
  // Friction, the only feature of the ground's that may differ, is the same for every value.
  plan->events = possible_events(plan->ground.scenes.front()) & searched;
  return plan;
}

// The thresholds of the ground counterpart of scene i, computed once per distinct one.
Thresholds ground_thresholds(GroundPlan& plan, std::size_t i, const Record& record,
                             const SweepSettings& settings, const std::atomic<bool>* stop,
                             std::size_t* simulations) {
  return plan.thresholds.get(plan.ground.keys[i], [&] {
    try {
      return first_occurrence_thresholds(plan.ground.scenes[i], record, settings, simulations,
                                         stop);
    } catch (const InputError& e) {
      throw InputError(std::string("the block on the ground: ") + e.what());
    }
  });
}

std::string ground_header(const EventSet& events) {
  std::string header;
  for (std::size_t e = 0; e < kSweepEventCount; ++e) {
    if (!events[e]) continue;
    header += ',';
    header += kEventNames[e];
    header += kGroundSuffix;
  }
  return header;
}

std::string ground_fields(const EventSet& events, const Thresholds& thresholds) {
  std::string fields;
  for (std::size_t e = 0; e < kSweepEventCount; ++e) {
    if (!events[e]) continue;
    fields += ',';
    fields += format_result(thresholds[e]);
  }
  return fields;
}

// Why the block on the ground cannot have `event`.
std::string why_ground_lacks(SweepEvent event) {
  switch (event) {
    case SweepEvent::kSliding:
    case SweepEvent::kSlideRocking: return "the scene has no [friction]";
    case SweepEvent::kOutOfBase:
    case SweepEvent::kFell: return "it has no support's edge to leave";
    case SweepEvent::kBaseStopHit: return "it has no base stops";
    case SweepEvent::kSlideStopHit: return "it has no sliding stops";
    default: return "it cannot";
  }
}

}  // namespace

SweepPlan plan_thresholds(const SceneParams& base, const Record& record, SweepParameter parameter,
                          const GridAxis& axis, const SweepSettings& settings,
                          bool compare_ground) {
  validate(settings);
  check_record(record);
  if (compare_ground) require_base_to_compare(base);
  const std::vector<double> values = sweep_values(axis.from, axis.to, axis.steps);
  auto scenes = std::make_shared<const std::vector<Scene>>(sweep_scenes(base, parameter, values));
  const std::shared_ptr<GroundPlan> ground =
      compare_ground ? ground_plan(*scenes, settings.events) : nullptr;
  auto shared_record = std::make_shared<const Record>(record);
  SweepPlan plan;
  SettingsLine line = pga_settings("thresholds", {axis}, base, record, settings);
  plan.header = sweep_csv_header(parameter);
  if (ground) {
    line.add("compare", "ground");
    plan.header += ground_header(ground->events);
  }
  plan.settings = line.text();
  plan.keys = grid_keys({axis});
  plan.row = [scenes, ground, shared_record, values, settings](
                 std::size_t i, const std::atomic<bool>* stop, std::size_t* simulations) {
    const SweepRow row{values[i], first_occurrence_thresholds((*scenes)[i], *shared_record,
                                                              settings, simulations, stop)};
    std::string text = sweep_csv_row(row);
    if (ground) {
      text += ground_fields(ground->events, ground_thresholds(*ground, i, *shared_record, settings,
                                                              stop, simulations));
    }
    return text;
  };
  plan.describe = [parameter, values](std::size_t i) {
    return describe_value("--param", parameter, values[i]);
  };
  return plan;
}

SweepPlan plan_threshold_map(const SceneParams& base, const Record& record,
                             SweepParameter parameter1, const GridAxis& axis1,
                             SweepParameter parameter2, const GridAxis& axis2, SweepEvent event,
                             SweepSettings settings, bool compare_ground) {
  validate(settings);
  check_record(record);
  if (compare_ground) require_base_to_compare(base);
  if (parameter1 == parameter2) {
    throw InputError(std::string("--param2: must differ from --param (both ") +
                     sweep_parameter_name(parameter1) + ")");
  }
  const std::vector<double> values1 = sweep_values(axis1.from, axis1.to, axis1.steps);
  const std::vector<double> values2 = sweep_values(axis2.from, axis2.to, axis2.steps, "--", "2");
  auto scenes = std::make_shared<std::vector<Scene>>();
  scenes->reserve(values1.size() * values2.size());
  for (const double v1 : values1) {
    const SceneParams row_params = with_parameter(base, parameter1, v1);
    for (const double v2 : values2) {
      scenes->emplace_back();
      if (!make_scene(with_parameter(row_params, parameter2, v2, "--param2"), scenes->back())
               .ok()) {
        throw InputError("internal: make_scene refused a checked scene");
      }
    }
  }
  settings.events.reset();
  settings.events.set(static_cast<std::size_t>(event));
  const std::shared_ptr<GroundPlan> ground =
      compare_ground ? ground_plan(*scenes, settings.events) : nullptr;
  if (ground && ground->events.none()) {
    throw InputError(std::string("--compare-ground: the block on the ground cannot have ") +
                     sweep_event_name(event) + " (" + why_ground_lacks(event) +
                     "); it can have rocking, overturned, and with friction sliding and "
                     "slide_rocking");
  }
  auto shared_record = std::make_shared<const Record>(record);
  SweepPlan plan;
  SettingsLine line = pga_settings("threshold_map", {axis1, axis2}, base, record, settings);
  line.add("event", sweep_event_name(event));
  plan.header = std::string(sweep_parameter_name(parameter1)) + "," +
                sweep_parameter_name(parameter2) + "," + sweep_event_name(event);
  if (ground) {
    line.add("compare", "ground");
    plan.header += ground_header(ground->events);
  }
  plan.settings = line.text();
  plan.key_columns = 2;
  plan.keys = grid_keys({axis1, axis2});
  const std::vector<std::string> keys = plan.keys;
  plan.row = [scenes, ground, shared_record, settings, event, keys](
                 std::size_t i, const std::atomic<bool>* stop, std::size_t* simulations) {
    const auto thresholds =
        first_occurrence_thresholds((*scenes)[i], *shared_record, settings, simulations, stop);
    std::string text = keys[i] + "," + format_result(thresholds[static_cast<std::size_t>(event)]);
    if (ground) {
      text += ground_fields(ground->events, ground_thresholds(*ground, i, *shared_record, settings,
                                                              stop, simulations));
    }
    return text;
  };
  const std::size_t columns = values2.size();
  plan.describe = [=](std::size_t i) {
    return describe_value("--param", parameter1, values1[i / columns]) + ", " +
           describe_value("--param2", parameter2, values2[i % columns]);
  };
  return plan;
}

std::vector<SweepRow> run_sweep(const SceneParams& base, SweepParameter parameter,
                                const std::vector<double>& values, const Record& record,
                                const SweepSettings& settings, int jobs, int shard_index,
                                int shard_count, SweepStats* stats) {
  SweepRun run;
  run.jobs = jobs;
  run.shard_index = shard_index;
  run.shard_count = shard_count;
  validate(run);
  validate(settings);
  check_record(record);
  const std::vector<std::size_t> indices = shard_indices(values.size(), run);
  // Every value of this shard is checked before anything runs.
  std::vector<double> shard_values;
  for (const std::size_t i : indices) shard_values.push_back(values[i]);
  const std::vector<Scene> scenes = sweep_scenes(base, parameter, shard_values);

  std::vector<SweepRow> rows(shard_values.size());
  std::atomic<std::size_t> simulations{0};
  std::vector<std::size_t> all(rows.size());
  for (std::size_t k = 0; k < all.size(); ++k) all[k] = k;
  SweepRun local = run;
  local.shard_index = local.shard_count = 1;
  (void)run_jobs(
      all, local,
      [&](std::size_t k) {
        std::size_t runs = 0;
        rows[k] = {shard_values[k],
                   first_occurrence_thresholds(scenes[k], record, settings, &runs)};
        simulations += runs;
      },
      [&](std::size_t k) { return describe_value("--param", parameter, shard_values[k]); });
  if (stats != nullptr) stats->simulations += simulations.load();
  return rows;
}

void write_sweep_csv(std::ostream& out, SweepParameter parameter,
                     const std::vector<SweepRow>& rows) {
  out << sweep_csv_header(parameter) << '\n';
  for (const SweepRow& row : rows) out << sweep_csv_row(row) << '\n';
}

}  // namespace plinth::host
