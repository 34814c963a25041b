#include "plinth/host/sweep.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iterator>
#include <map>
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

constexpr std::array<const char*, 7> kParameterNames = {"mu_s", "epsilon", "lambda",   "T",
                                                        "xi",   "u_max",   "mass_ratio"};

std::string format_number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.10g", value);
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

 private:
  void mark(SweepEvent e) { result.occurred[static_cast<std::size_t>(e)] = true; }
};

// Simulations of one scene, each PGA (in g) run once.
class OccurrenceCache {
 public:
  OccurrenceCache(const Scene& scene, const Record& record, const SweepSettings& settings)
      : scene_(scene), record_(record), settings_(settings) {}

  bool occurs(double pga_g, std::size_t event) {
    if (pga_g <= 0.0) return false;  // assumed: nothing happens without ground motion
    auto it = runs_.find(pga_g);
    if (it == runs_.end()) {
      it = runs_.emplace(pga_g, simulate_occurrences(scene_, record_, pga_g * scene_.g, settings_))
               .first;
    }
    return it->second.occurred[event];
  }

  // Largest PGA below `hi` known not to show the event (0 when none is known).
  [[nodiscard]] double known_absent_below(double hi, std::size_t event) const {
    for (auto it = std::make_reverse_iterator(runs_.lower_bound(hi)); it != runs_.rend(); ++it) {
      if (!it->second.occurred[event]) return it->first;
    }
    return 0.0;
  }

  // Smallest PGA in (lo, hi] known to show the event (`hi` is one).
  [[nodiscard]] double known_present_above(double lo, double hi, std::size_t event) const {
    for (auto it = runs_.upper_bound(lo); it != runs_.end() && it->first <= hi; ++it) {
      if (it->second.occurred[event]) return it->first;
    }
    return hi;
  }

  [[nodiscard]] std::size_t size() const { return runs_.size(); }

 private:
  const Scene& scene_;
  const Record& record_;
  const SweepSettings& settings_;
  std::map<double, Occurrences> runs_;
};

}  // namespace

const char* sweep_event_name(SweepEvent event) {
  return kEventNames[static_cast<std::size_t>(event)];
}

const char* sweep_parameter_name(SweepParameter parameter) {
  return kParameterNames[static_cast<std::size_t>(parameter)];
}

void validate(const SweepSettings& s) {
  if (!std::isfinite(s.pga_max_g) || s.pga_max_g <= 0.0) {
    throw InputError("--pga-max: must be greater than zero, got " + format_number(s.pga_max_g) +
                     " g");
  }
  if (!std::isfinite(s.tolerance_g) || s.tolerance_g <= 0.0) {
    throw InputError("--tol: must be greater than zero, got " + format_number(s.tolerance_g) +
                     " g");
  }
  if (s.scan_points < 1) {
    throw InputError("scan points: must be at least 1, got " + std::to_string(s.scan_points));
  }
  if (!std::isfinite(s.dt) || s.dt <= 0.0) {
    throw InputError("--dt: must be greater than zero, got " + format_number(s.dt) + " s");
  }
}

Occurrences simulate_occurrences(const Scene& scene, const Record& record, double pga_mps2,
                                 const SweepSettings& settings) {
  const double peak = record.peak_horizontal();
  if (!(peak > 0.0)) throw InputError(record.name + ": record is all zeros, cannot scale to a PGA");
  if (!std::isfinite(pga_mps2) || pga_mps2 < 0.0) {
    throw InputError("PGA must be finite and not negative, got " + format_number(pga_mps2) +
                     " m/s2");
  }
  SolverSettings solver;
  solver.step = settings.dt;
  Simulator sim;
  const Excitation excitation =
      Excitation::record(record.horizontal_signal(), {}, pga_mps2 / peak);
  throw_if_simulator_error(Simulator::create(scene, excitation, solver, sim));
  OccurrenceSink sink;
  sim.set_event_sink(&sink);
  sim.start_at_rest();
  const double t_end = record.duration() + 2.0;
  while (sim.time() < t_end && !sim.mode().terminal()) sim.step();
  return sink.result;
}

std::array<std::optional<double>, kSweepEventCount> first_occurrence_thresholds(
    const Scene& scene, const Record& record, const SweepSettings& settings,
    std::size_t* simulations) {
  validate(settings);
  OccurrenceCache cache(scene, record, settings);
  const double tol = settings.tolerance_g;
  const int n = settings.scan_points;
  auto grid = [&](int k) { return settings.pga_max_g * static_cast<double>(k) / n; };

  std::array<std::optional<double>, kSweepEventCount> out;
  std::array<int, kSweepEventCount> first{};  // first grid index showing the event, 0: none
  for (int k = 1; k <= n; ++k) {
    bool pending = false;
    for (std::size_t e = 0; e < kSweepEventCount; ++e) {
      if (first[e] == 0 && cache.occurs(grid(k), e)) first[e] = k;
      pending = pending || first[e] == 0;
    }
    if (!pending) break;
  }
  for (std::size_t e = 0; e < kSweepEventCount; ++e) {
    if (first[e] == 0) continue;
    double hi = grid(first[e]);  // the event occurs here
    for (;;) {
      // The tightest bracket the runs so far give: absent at lo, present at hi.
      const double lo = cache.known_absent_below(hi, e);
      hi = cache.known_present_above(lo, hi, e);
      double a = lo;
      while (hi - a > tol) {
        const double mid = 0.5 * (a + hi);
        if (cache.occurs(mid, e)) {
          hi = mid;
        } else {
          a = mid;
        }
      }
      // Behaviour need not be monotonic in the PGA: make sure the event is absent one
      // tolerance below, else look again below that point.
      const double below = hi - tol;
      if (below <= 0.0 || !cache.occurs(below, e)) break;
      hi = below;
    }
    out[e] = hi;
  }
  if (simulations != nullptr) *simulations += cache.size();
  return out;
}

SweepParameter parse_sweep_parameter(const std::string& text) {
  for (std::size_t i = 0; i < kParameterNames.size(); ++i) {
    if (text == kParameterNames[i]) return static_cast<SweepParameter>(i);
  }
  std::string names;
  for (const char* name : kParameterNames) {
    if (!names.empty()) names += ", ";
    names += name;
  }
  throw InputError("--param: unknown parameter '" + text + "' (one of " + names + ")");
}

SceneParams with_parameter(SceneParams p, SweepParameter parameter, double value) {
  const std::string what =
      std::string("--param ") + sweep_parameter_name(parameter) + " = " + format_number(value);
  if (!std::isfinite(value)) throw InputError(what + ": not a finite number");
  const bool needs_base = parameter == SweepParameter::kPeriod ||
                          parameter == SweepParameter::kXi ||
                          parameter == SweepParameter::kMassRatio ||
                          parameter == SweepParameter::kUMax;
  if (needs_base && !p.has_base) {
    throw InputError(what + ": the scene has no [base] (a block on the ground)");
  }
  switch (parameter) {
    case SweepParameter::kMuS:
      p.has_friction = true;
      p.friction.static_coefficient = value;
      p.friction.kinetic_coefficient = 0.8 * value;
      break;
    case SweepParameter::kEpsilon:
      p.block.eccentricity = value * p.block.half_width;
      break;
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
    case SweepParameter::kPeriod:
      p.base.period = value;
      break;
    case SweepParameter::kXi:
      p.base.damping_ratio = value;
      break;
    case SweepParameter::kUMax:
      if (!p.has_base_stops) throw InputError(what + ": the scene has no [base_stops]");
      p.base_stops.max_displacement = value;
      break;
    case SweepParameter::kMassRatio:
      p.base.mass = value * p.block.mass;
      break;
  }
  Scene scene;
  if (const Error e = make_scene(p, scene); !e.ok()) {
    throw InputError(what + ": " + e.field + ": " + e.reason);
  }
  return p;
}

std::vector<double> sweep_values(double from, double to, int steps) {
  if (steps < 1) throw InputError("--steps: must be at least 1, got " + std::to_string(steps));
  if (!std::isfinite(from)) throw InputError("--from: must be a finite number");
  if (!std::isfinite(to)) throw InputError("--to: must be a finite number");
  if (from > to) {
    throw InputError("--from " + format_number(from) + " is greater than --to " +
                     format_number(to));
  }
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(steps));
  for (int i = 0; i < steps; ++i) {
    values.push_back(i == 0 ? from
                     : i == steps - 1
                         ? to
                         : from + (to - from) * static_cast<double>(i) / (steps - 1));
  }
  return values;
}

std::vector<SweepRow> run_sweep(const SceneParams& base, SweepParameter parameter,
                                const std::vector<double>& values, const Record& record,
                                const SweepSettings& settings, int jobs, int shard_index,
                                int shard_count, SweepStats* stats) {
  if (jobs < 1) throw InputError("--jobs: must be at least 1, got " + std::to_string(jobs));
  if (shard_count < 1 || shard_index < 1 || shard_index > shard_count) {
    throw InputError("--shard: must be i/N with 1 <= i <= N, got " + std::to_string(shard_index) +
                     "/" + std::to_string(shard_count));
  }
  validate(settings);
  if (!(record.peak_horizontal() > 0.0)) {
    throw InputError(record.name + ": record is all zeros, cannot scale to a PGA");
  }

  // Every value of this shard is checked before anything runs.
  std::vector<SweepRow> rows;
  std::vector<Scene> scenes;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i % static_cast<std::size_t>(shard_count) != static_cast<std::size_t>(shard_index - 1)) {
      continue;
    }
    Scene scene;
    if (!make_scene(with_parameter(base, parameter, values[i]), scene).ok()) {
      throw InputError("internal: make_scene refused a checked scene");
    }
    scenes.push_back(scene);
    SweepRow row;
    row.value = values[i];
    rows.push_back(row);
  }

  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> simulations{0};
  std::vector<std::exception_ptr> errors(rows.size());
  auto worker = [&] {
    for (;;) {
      const std::size_t i = next.fetch_add(1);
      if (i >= rows.size()) return;
      try {
        std::size_t runs = 0;
        rows[i].thresholds_g = first_occurrence_thresholds(scenes[i], record, settings, &runs);
        simulations += runs;
      } catch (const InputError& e) {
        errors[i] = std::make_exception_ptr(
            InputError(std::string("--param ") + sweep_parameter_name(parameter) + " = " +
                       format_number(rows[i].value) + ": " + e.what()));
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  const std::size_t threads =
      std::min(static_cast<std::size_t>(jobs), std::max<std::size_t>(rows.size(), 1));
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
  if (stats != nullptr) stats->simulations += simulations.load();
  return rows;
}

void write_sweep_csv(std::ostream& out, SweepParameter parameter,
                     const std::vector<SweepRow>& rows) {
  out << sweep_parameter_name(parameter);
  for (const char* name : kEventNames) out << ',' << name;
  out << '\n';
  char text[64];
  for (const SweepRow& row : rows) {
    out << format_number(row.value);
    for (const std::optional<double>& t : row.thresholds_g) {
      out << ',';
      if (t) {
        std::snprintf(text, sizeof text, "%.6g", *t);
        out << text;
      }
    }
    out << '\n';
  }
}

}  // namespace plinth::host
