// plinth-accuracy: the work-precision study of the solver's steppers (docs/accuracy.md). For each
// stepper and steps from 1e-2 s to 1e-5 s, the errors of what users look at (first rocking and
// sliding times, peak theta, u and x, overturned or not, the overturning threshold PGA of a
// bisection) against a reference (RK4 with located events at a step so small its answers stop
// changing: the two finest references are compared), and the cost (ns per step, times faster
// than real time) of the same runs. Writes CSV files, a Markdown table and, with --plot, a
// gnuplot plot (PNG and SVG).
//
// A tool, not a benchmark: most of its time goes into the reference runs, and its results are
// errors as much as timings; Google Benchmark's repetitions would multiply both. ctest runs
// only --quick, which checks the study runs and that RK4's errors shrink.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gnuplot.h"
#include "plinth/core/simulator.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/record_io.h"
#include "plinth/host/scene_toml.h"

namespace {

using plinth::host::InputError;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One stepper as the study varies it.
struct Variant {
  plinth::Stepper stepper;
  bool exact_full_contact;

  // The stepper's name (stepper.h), "+exact" with exact full contact.
  [[nodiscard]] std::string name() const {
    return std::string(plinth::stepper_name(stepper)) + (exact_full_contact ? "+exact" : "");
  }
};

constexpr std::array<Variant, 5> kVariants = {{
    {plinth::Stepper::kRk4Located, false},
    {plinth::Stepper::kRk4Located, true},
    {plinth::Stepper::kRk4StepEnd, false},
    {plinth::Stepper::kHeunLocated, false},
    {plinth::Stepper::kSemiImplicitEuler, false},
}};

// A scene under an input.
struct Case {
  std::string name;
  std::string scene;    // file in sim/scenes, without .toml
  std::string record;   // file in sim/data/records, without .AT2; empty: a sine pulse
  double pulse_period;  // s, for the sine pulse
  double pga_g;         // the record's peak (or the pulse's amplitude), in g
  double t_end;         // s
};

// A threshold search: the smallest PGA (in g) at which the block overturns or falls, bisected
// in [low, high] (found once by a scan with the reference stepper) a fixed number of times, so
// that every stepper walks the same bracket.
struct ThresholdCase {
  Case input;  // pga_g unused
};

struct Options {
  std::string source_dir;  // a checkout; empty: find_data (the install's, or the build's checkout)
  std::string scenes_dir;  // set by find_data
  std::string records_dir;
  std::string out_dir = ".";
  bool plot = false;
  bool quick = false;
};

// What one run shows.
struct Observed {
  double t_rock = kNaN;                                 // first rocking_start, s (NaN: none)
  double t_slide = kNaN;                                // first sliding_start, s
  double peak_theta = 0.0, peak_u = 0.0, peak_x = 0.0;  // rad, m, m
  bool collapsed = false;                               // overturned or fell
  std::int64_t steps = 0;
  double simulated = 0.0;  // s
  double wall = 0.0;       // s, the fastest of the repetitions
};

// The largest |q| of the cubic Hermite interpolant between (q0, rate0) and (q1, rate1) a step
// h apart: the peak between two steps, to the order of the method rather than the grid's (a
// peak sampled at steps only would be off by rate'' h^2 / 8 whatever the stepper).
double peak_between(double q0, double rate0, double q1, double rate1, double h) {
  const double m0 = h * rate0, m1 = h * rate1, d = q0 - q1;
  // p'(s) = a s^2 + b s + c on s in [0, 1]
  const double a = 6.0 * d + 3.0 * m0 + 3.0 * m1;
  const double b = -6.0 * d - 4.0 * m0 - 2.0 * m1;
  const double c = m0;
  const auto value = [&](double s) {
    const double s2 = s * s, s3 = s2 * s;
    return (2.0 * s3 - 3.0 * s2 + 1.0) * q0 + (s3 - 2.0 * s2 + s) * m0 +
           (-2.0 * s3 + 3.0 * s2) * q1 + (s3 - s2) * m1;
  };
  double peak = std::max(std::fabs(q0), std::fabs(q1));
  const auto consider = [&](double s) {
    if (s > 0.0 && s < 1.0) peak = std::max(peak, std::fabs(value(s)));
  };
  if (std::fabs(a) < 1e-300) {
    if (b != 0.0) consider(-c / b);
  } else {
    const double discriminant = b * b - 4.0 * a * c;
    if (discriminant >= 0.0) {
      const double root = std::sqrt(discriminant);
      consider((-b - root) / (2.0 * a));
      consider((-b + root) / (2.0 * a));
    }
  }
  return peak;
}

class FirstEvents final : public plinth::EventSink {
 public:
  void on_event(const plinth::Event& e) override {
    using plinth::EventKind;
    if (e.kind == EventKind::kRockingStart && std::isnan(t_rock)) t_rock = e.t;
    if (e.kind == EventKind::kSlidingStart && std::isnan(t_slide)) t_slide = e.t;
    peak_theta = std::max(peak_theta, std::fabs(e.state[plinth::kTheta]));
    peak_u = std::max(peak_u, std::fabs(e.state[plinth::kU]));
    peak_x = std::max(peak_x, std::fabs(e.state[plinth::kX]));
  }
  double t_rock = kNaN, t_slide = kNaN, peak_theta = 0.0, peak_u = 0.0, peak_x = 0.0;
};

struct Input {
  plinth::Scene scene;
  plinth::host::Record record;  // empty for a pulse
  const Case* c = nullptr;

  [[nodiscard]] plinth::Excitation excitation(double pga_g) const {
    if (record.horizontal.empty()) {
      return plinth::Excitation::sine_pulse(pga_g * scene.g, c->pulse_period);
    }
    return plinth::Excitation::record(record.horizontal_signal(), {},
                                      pga_g * scene.g / record.peak_horizontal());
  }
};

Input load(const Options& opt, const Case& c) {
  Input in;
  in.c = &c;
  in.scene = plinth::host::load_scene_file(opt.scenes_dir + "/" + c.scene + ".toml");
  if (!c.record.empty()) {
    in.record = plinth::host::read_record(opt.records_dir + "/" + c.record + ".AT2",
                                          in.scene.g);
  }
  return in;
}

plinth::SolverSettings settings_of(const Variant& v, double dt) {
  plinth::SolverSettings s;
  s.stepper = v.stepper;
  s.exact_full_contact = v.exact_full_contact;
  s.step = dt;
  return s;
}

// One simulation from rest to t_end (or collapse); nullopt when the stepper refuses the step.
// `min_wall` s: short runs are repeated until they took that long, the fastest one timed.
std::optional<Observed> simulate(const Input& in, double pga_g, double t_end,
                                 const plinth::SolverSettings& settings, double min_wall) {
  const plinth::Excitation ex = in.excitation(pga_g);
  plinth::Simulator sim;
  if (!plinth::Simulator::create(in.scene, ex, settings, sim).ok()) return std::nullopt;
  Observed o;
  o.wall = std::numeric_limits<double>::infinity();
  double total = 0.0;
  const auto steps = static_cast<std::int64_t>(std::llround(t_end / settings.step));
  for (int repetition = 0; repetition < 1000 && (repetition < 1 || total < min_wall);
       ++repetition) {
    FirstEvents sink;
    sim.set_event_sink(&sink);
    sim.start_at_rest();
    double peak_theta = 0.0, peak_u = 0.0, peak_x = 0.0;
    const auto start = std::chrono::steady_clock::now();
    while (sim.step_count() < steps && !sim.mode().terminal()) {
      const plinth::State before = sim.state();
      const std::int64_t events = sim.event_count();
      sim.step();
      const plinth::State& y = sim.state();
      if (sim.event_count() != events) {  // not smooth within the step: the ends (and events)
        peak_theta = std::max(peak_theta, std::fabs(y[plinth::kTheta]));
        peak_u = std::max(peak_u, std::fabs(y[plinth::kU]));
        peak_x = std::max(peak_x, std::fabs(y[plinth::kX]));
        continue;
      }
      const auto between = [&](plinth::StateIndex q, plinth::StateIndex rate) {
        return peak_between(before[q], before[rate], y[q], y[rate], settings.step);
      };
      peak_theta = std::max(peak_theta, between(plinth::kTheta, plinth::kThetaDot));
      peak_u = std::max(peak_u, between(plinth::kU, plinth::kUDot));
      peak_x = std::max(peak_x, between(plinth::kX, plinth::kXDot));
    }
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    total += wall;
    o.wall = std::min(o.wall, wall);
    o.t_rock = sink.t_rock;
    o.t_slide = sink.t_slide;
    o.peak_theta = std::max(peak_theta, sink.peak_theta);
    o.peak_u = std::max(peak_u, sink.peak_u);
    o.peak_x = std::max(peak_x, sink.peak_x);
    o.collapsed = sim.mode().terminal();
    o.steps = sim.step_count();
    o.simulated = sim.time();
  }
  return o;
}

bool collapses(const Input& in, double pga_g, double t_end, const plinth::SolverSettings& s) {
  const std::optional<Observed> o = simulate(in, pga_g, t_end, s, 0.0);
  return o && o->collapsed;
}

// [low, high] in g: the first collapse of a scan every `step_g` with `settings`.
std::optional<std::array<double, 2>> threshold_bracket(const Input& in, double t_end,
                                                       const plinth::SolverSettings& settings,
                                                       double step_g, double max_g) {
  for (double level = step_g; level <= max_g + 1e-9; level += step_g) {
    if (collapses(in, level, t_end, settings)) return std::array<double, 2>{level - step_g, level};
  }
  return std::nullopt;
}

double bisect(const Input& in, double t_end, const plinth::SolverSettings& settings,
              std::array<double, 2> bracket, int iterations) {
  double low = bracket[0], high = bracket[1];
  for (int i = 0; i < iterations; ++i) {
    const double middle = 0.5 * (low + high);
    (collapses(in, middle, t_end, settings) ? high : low) = middle;
  }
  return 0.5 * (low + high);
}

// |a - b|, NaN when exactly one is NaN (an event missed or invented), 0 when both are.
double time_error(double a, double reference) {
  if (std::isnan(a) && std::isnan(reference)) return 0.0;
  if (std::isnan(a) || std::isnan(reference)) return std::numeric_limits<double>::infinity();
  return std::fabs(a - reference);
}

// |a - b| / |b|, or 0 when the reference is 0 and a too (nothing happened).
double relative_error(double a, double reference) {
  if (reference == 0.0) return a == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::fabs(a - reference) / std::fabs(reference);
}

struct Errors {
  double t_rock = 0.0, t_slide = 0.0, peak_theta = 0.0, peak_u = 0.0, peak_x = 0.0;
  bool collapse_differs = false;
};

Errors errors_of(const Observed& o, const Observed& r) {
  return {time_error(o.t_rock, r.t_rock),
          time_error(o.t_slide, r.t_slide),
          relative_error(o.peak_theta, r.peak_theta),
          relative_error(o.peak_u, r.peak_u),
          relative_error(o.peak_x, r.peak_x),
          o.collapsed != r.collapsed};
}

// One row of the raw table: a case (or threshold case), a variant, a step.
struct Row {
  std::string case_name;
  std::string variant;
  double dt = 0.0;
  bool refused = false;
  double ns_per_step = kNaN, x_real_time = kNaN;
  Errors e;
  double threshold_error = kNaN;  // g, threshold cases only
  // A record sampled at a whole number of steps: its piecewise-linear input is linear within
  // every step, which exact full contact propagates exactly.
  bool aligned = false;
};

// v with `significant` digits (%g), or with `decimals` after the point (fixed); "" for NaN and
// "miss" for infinity (an event one run has and the other has not).
std::string number(double v, int significant = 3) {
  if (std::isnan(v)) return "";
  if (std::isinf(v)) return "miss";
  char text[32];
  std::snprintf(text, sizeof text, "%.*g", significant, v);
  return text;
}

std::string fixed(double v, int decimals) {
  if (std::isnan(v)) return "";
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, v);
  return text;
}

// The largest finite value, "miss" when any is infinite, empty when none.
struct Worst {
  double value = kNaN;
  int missed = 0;

  void add(double v) {
    if (std::isnan(v)) return;
    if (std::isinf(v)) {
      ++missed;
      return;
    }
    value = std::isnan(value) ? v : std::max(value, v);
  }
  [[nodiscard]] std::string text() const {
    std::string out = number(value);
    if (missed > 0) out += (out.empty() ? "" : ", ") + std::to_string(missed) + " miss";
    return out;
  }
};

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return kNaN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Summary {
  std::string variant;
  double dt = 0.0;
  double ns_per_step = kNaN, x_real_time = kNaN, ms_per_simulated_s = kNaN;
  Worst t_rock, t_slide, peak_theta, peak_u, peak_x, threshold;
  int collapse_differs = 0, cases = 0, refused = 0;
};

std::vector<Summary> summarize(const std::vector<Row>& rows, const std::vector<double>& steps,
                               bool aligned_only = false) {
  std::vector<Summary> out;
  for (const Variant& v : kVariants) {
    for (const double dt : steps) {
      Summary s;
      s.variant = v.name();
      s.dt = dt;
      std::vector<double> ns, speed;
      for (const Row& r : rows) {
        if (r.variant != v.name() || r.dt != dt || (aligned_only && !r.aligned)) continue;
        if (r.refused) {
          ++s.refused;
          continue;
        }
        if (!std::isnan(r.threshold_error)) {
          s.threshold.add(r.threshold_error);
          continue;
        }
        ++s.cases;
        ns.push_back(r.ns_per_step);
        speed.push_back(r.x_real_time);
        s.t_rock.add(r.e.t_rock);
        s.t_slide.add(r.e.t_slide);
        s.peak_theta.add(r.e.peak_theta);
        s.peak_u.add(r.e.peak_u);
        s.peak_x.add(r.e.peak_x);
        s.collapse_differs += r.e.collapse_differs ? 1 : 0;
      }
      s.ns_per_step = median(ns);
      s.x_real_time = median(speed);
      s.ms_per_simulated_s = 1e3 / s.x_real_time;
      out.push_back(s);
    }
  }
  return out;
}

void write_rows_csv(const std::string& path, const std::vector<Row>& rows) {
  std::ofstream out(path);
  out << "case,variant,dt_s,refused,ns_per_step,x_real_time,err_t_rock_s,err_t_slide_s,"
         "err_peak_theta_rel,err_peak_u_rel,err_peak_x_rel,collapse_differs,err_threshold_g\n";
  for (const Row& r : rows) {
    out << r.case_name << ',' << r.variant << ',' << number(r.dt, 6) << ',' << r.refused << ','
        << number(r.ns_per_step) << ',' << number(r.x_real_time) << ',' << number(r.e.t_rock) << ','
        << number(r.e.t_slide) << ',' << number(r.e.peak_theta) << ',' << number(r.e.peak_u) << ','
        << number(r.e.peak_x) << ',' << r.e.collapse_differs << ',' << number(r.threshold_error)
        << '\n';
  }
  if (!out.flush()) throw InputError(path + ": write failed");
}

// The bisection's resolution, g: thresholds are bisected this many times in a bracket this wide.
constexpr int kBisections = 16;
constexpr double kBracketWidthG = 0.05;
constexpr double kThresholdResolutionG = kBracketWidthG / (1 << kBisections);

// The summary as gnuplot reads it: one block per variant (two blank lines between), columns
// cost (ms per simulated s), then each error; errors below kPlotFloor (the thresholds: below
// half the bisection's resolution) drawn at it, as log axes need (located event times and the
// same bisection paths give 0); misses and nothing as "nan".
constexpr double kPlotFloor = 1e-12;
std::string summary_data(const std::vector<Summary>& summary) {
  std::string out;
  std::string current;
  const auto cell = [](const Worst& w, double floor = kPlotFloor) {
    if (w.missed > 0 || std::isnan(w.value)) return std::string("nan");
    return number(std::max(w.value, floor), 4);
  };
  for (const Summary& s : summary) {
    if (s.variant != current) {
      if (!current.empty()) out += "\n\n";
      out += "# " + s.variant + "\n# dt ms_per_s t_rock peak_theta peak_u threshold_g\n";
      current = s.variant;
    }
    if (std::isnan(s.ms_per_simulated_s)) continue;
    out += number(s.dt, 6) + ' ' + number(s.ms_per_simulated_s, 4) + ' ' + cell(s.t_rock) + ' ' +
           cell(s.peak_theta) + ' ' + cell(s.peak_u) + ' ' +
           cell(s.threshold, 0.5 * kThresholdResolutionG) + '\n';
  }
  return out;
}

void plot(const Options& opt, const std::vector<Summary>& summary) {
  const std::string stem = opt.out_dir + "/accuracy";
  const std::string data = stem + "-summary.dat";
  {
    std::ofstream out(data);
    out << summary_data(summary);
    if (!out.flush()) throw InputError(data + ": write failed");
  }
  std::string script =
      "# Drawn by plinth-accuracy (docs/accuracy.md); file names are arguments: gnuplot -c "
      "accuracy.gp accuracy-summary.dat accuracy.png accuracy.svg\n"
      "set logscale xy\nset format y '10^{%L}'\nset grid\nset key bottom left font ',9'\n"
      "set xlabel 'cost: wall time per simulated second (ms/s)'\n";
  const char* panels[][3] = {
      {"3", "error of the first rocking time (s)", "time of first rocking"},
      {"4", "relative error of the peak {/Symbol q}", "peak {/Symbol q}"},
      {"5", "relative error of the peak u", "peak u (base)"},
      {"6", "error of the overturning PGA (g)", "overturning threshold PGA"}};
  std::string body =
      "set multiplot layout 2,2 title 'plinth steppers: error (worst case) against cost'\n";
  for (const auto& p : panels) {
    body += std::string("set title '") + p[2] + "'\nset ylabel '" + p[1] + "'\nplot ";
    for (std::size_t i = 0; i < kVariants.size(); ++i) {
      body += "ARG1 index " + std::to_string(i) + " using 2:" + p[0] + " with linespoints pt " +
              std::to_string(i + 4) + " title '" + kVariants[i].name() + "' noenhanced" +
              (i + 1 < kVariants.size() ? ", " : "\n");
    }
  }
  body += "unset multiplot\n";
  script += "set terminal pngcairo size 1400,1000 font ',10'\nset output ARG2\n" + body +
            "set terminal svg size 1400,1000 dynamic font ',10'\nset output ARG3\n" + body +
            "set output\n";
  const std::string gp = stem + ".gp";
  {
    std::ofstream out(gp);
    out << script;
    if (!out.flush()) throw InputError(gp + ": write failed");
  }
  plinth::sim::run_gnuplot(gp, {data, stem + ".png", stem + ".svg"});  // names as data
}

std::string markdown(const std::vector<Summary>& summary) {
  std::string out =
      "| stepper | dt (s) | ns/step | x real time | first rocking (s) | first sliding (s) | "
      "peak theta (rel) | peak u (rel) | peak x (rel) | collapse differs | threshold PGA (g) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Summary& s : summary) {
    if (s.cases == 0 && s.refused == 0 && s.threshold.missed == 0 &&
        std::isnan(s.threshold.value)) {
      continue;  // no case at this step (the aligned table)
    }
    out += "| " + s.variant + " | " + number(s.dt, 6) + " | ";
    if (s.cases == 0) {
      out +=
          s.refused > 0 ? "refused (unstable) | | | | | | | | |\n" : "no case | | | | | | | | |\n";
      continue;
    }
    out += fixed(s.ns_per_step, 0) + " | " + fixed(s.x_real_time, 0) + " | " + s.t_rock.text() +
           " | " + s.t_slide.text() + " | " + s.peak_theta.text() + " | " + s.peak_u.text() +
           " | " + s.peak_x.text() + " | " + std::to_string(s.collapse_differs) + "/" +
           std::to_string(s.cases) + " | " + s.threshold.text() + " |\n";
  }
  return out;
}

int run(const Options& opt) {
  std::vector<Case> cases;
  std::vector<ThresholdCase> thresholds;
  std::vector<double> steps;
  std::array<double, 2> reference_steps{};  // finer, coarser
  int bisections = kBisections;
  if (opt.quick) {
    cases = {{"ground / sine 0.5 s 0.5 g", "non-isolated", "", 0.5, 0.5, 4.0}};
    thresholds = {{{"ground / sine 0.5 s", "non-isolated", "", 0.5, 0.0, 4.0}}};
    steps = {1e-2, 1e-3};
    reference_steps = {5e-5, 1e-4};
    bisections = 8;
  } else {
    cases = {
        {"ground / El Centro 0.6 g", "non-isolated", "elcentro1940_180", 0.0, 0.6, 30.0},
        {"ground / Calitri 0.45 g", "non-isolated", "irpinia1980_calitri_000", 0.0, 0.45, 40.0},
        {"ground / sine 0.5 s 0.5 g", "non-isolated", "", 0.5, 0.5, 10.0},
        {"isolated+stops / Brienza 2.5 g", "paper-isolated-stops", "irpinia1980_brienza_000", 0.0,
         2.5, 40.0},
        {"eccentric+stops / Calitri 1.2 g", "paper-eccentric", "irpinia1980_calitri_000", 0.0, 1.2,
         40.0},
        {"fig14a sliding / Brienza 1.5 g", "fig14a-sliding-held-by-stops",
         "irpinia1980_brienza_000", 0.0, 1.5, 40.0},
        {"fig14b out of base / Brienza 1.5 g", "fig14b-leaves-the-base", "irpinia1980_brienza_000",
         0.0, 1.5, 40.0},
        {"fig14c slide-rocking / Brienza 2.3 g", "fig14c-slide-rocking-base-stops",
         "irpinia1980_brienza_000", 0.0, 2.3, 40.0},
        {"isolated+stops / El Centro 0.8 g", "paper-isolated-stops", "elcentro1940_180", 0.0, 0.8,
         30.0},
        {"fig14d rocking+stops / El Centro 1.5 g", "fig14d-pure-rocking", "elcentro1940_180", 0.0,
         1.5, 30.0},
        {"fig14d rocking+stops / Brienza 1.8 g", "fig14d-pure-rocking", "irpinia1980_brienza_000",
         0.0, 1.8, 40.0},
    };
    thresholds = {
        {{"ground / sine 0.5 s", "non-isolated", "", 0.5, 0.0, 8.0}},
        {{"isolated+stops / sine 1.5 s", "paper-isolated-stops", "", 1.5, 0.0, 8.0}},
        {{"ground / El Centro 15 s", "non-isolated", "elcentro1940_180", 0.0, 0.0, 15.0}}};
    steps = {1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5};
    reference_steps = {2.5e-6, 5e-6};
  }
  const Variant& reference_variant = kVariants[0];
  constexpr double kMinWall = 0.05;  // s: short runs repeated at least this long
  std::vector<Row> rows;
  std::string convergence =
      "| case | input sampled every (s) | first rocking (s) | first sliding (s) | peak theta (rad) "
      "| peak u (m) | peak x (m) | collapsed | difference between the references |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  for (const Case& c : cases) {
    const Input in = load(opt, c);
    std::fprintf(stderr, "%s: references...\n", c.name.c_str());
    const auto fine =
        simulate(in, c.pga_g, c.t_end, settings_of(reference_variant, reference_steps[0]), 0.0);
    const auto coarse =
        simulate(in, c.pga_g, c.t_end, settings_of(reference_variant, reference_steps[1]), 0.0);
    if (!fine || !coarse) throw InputError(c.name + ": the reference step is refused");
    const Errors d = errors_of(*coarse, *fine);
    convergence += "| " + c.name + " | " +
                   (c.record.empty() ? std::string("(sine)") : number(in.record.dt, 3)) + " | " +
                   fixed(fine->t_rock, 6) + " | " + fixed(fine->t_slide, 6) + " | " +
                   number(fine->peak_theta, 5) + " | " + number(fine->peak_u, 5) + " | " +
                   number(fine->peak_x, 5) + " | " + (fine->collapsed ? "yes" : "no") + " | " +
                   number(d.t_rock) + " s, " + number(d.t_slide) + " s; rel. " +
                   number(d.peak_theta) + ", " + number(d.peak_u) + ", " + number(d.peak_x) +
                   (d.collapse_differs ? "; collapse differs" : "") + " |\n";
    for (const Variant& v : kVariants) {
      for (const double dt : steps) {
        Row r;
        r.case_name = c.name;
        r.variant = v.name();
        r.dt = dt;
        if (!c.record.empty()) {
          const double steps_per_sample = in.record.dt / dt;
          r.aligned = std::fabs(steps_per_sample - std::round(steps_per_sample)) < 1e-9 &&
                      steps_per_sample >= 0.5;
        }
        const auto o = simulate(in, c.pga_g, c.t_end, settings_of(v, dt), kMinWall);
        if (!o) {
          r.refused = true;
        } else {
          r.ns_per_step = 1e9 * o->wall / static_cast<double>(std::max<std::int64_t>(o->steps, 1));
          r.x_real_time = o->simulated / o->wall;
          r.e = errors_of(*o, *fine);
        }
        rows.push_back(r);
      }
    }
  }
  std::string threshold_table =
      "| threshold case | bracket (g) | reference threshold (g) | difference between the "
      "references (g) |\n|---|---|---|---|\n";
  for (const ThresholdCase& tc : thresholds) {
    const Input in = load(opt, tc.input);
    std::fprintf(stderr, "%s: threshold bracket and references...\n", tc.input.name.c_str());
    const auto bracket = threshold_bracket(in, tc.input.t_end, settings_of(reference_variant, 1e-4),
                                           kBracketWidthG, 3.0);
    if (!bracket) throw InputError(tc.input.name + ": no collapse up to 3 g");
    const double fine =
        bisect(in, tc.input.t_end, settings_of(reference_variant, reference_steps[0]), *bracket,
               bisections);
    const double coarse =
        bisect(in, tc.input.t_end, settings_of(reference_variant, reference_steps[1]), *bracket,
               bisections);
    threshold_table += "| " + tc.input.name + " | " + fixed((*bracket)[0], 2) + " to " +
                       fixed((*bracket)[1], 2) + " | " + fixed(fine, 6) + " | " +
                       number(std::fabs(fine - coarse)) + " |\n";
    for (const Variant& v : kVariants) {
      for (const double dt : steps) {
        Row r;
        r.case_name = tc.input.name;
        r.variant = v.name();
        r.dt = dt;
        plinth::Simulator probe;
        if (!plinth::Simulator::create(in.scene, in.excitation(1.0), settings_of(v, dt), probe)
                 .ok()) {
          r.refused = true;
        } else {
          r.threshold_error = std::fabs(
              bisect(in, tc.input.t_end, settings_of(v, dt), *bracket, bisections) - fine);
        }
        rows.push_back(r);
      }
    }
  }
  std::filesystem::create_directories(opt.out_dir);
  write_rows_csv(opt.out_dir + "/accuracy-runs.csv", rows);
  const std::vector<Summary> summary = summarize(rows, steps);
  const std::string md = "## The references\n\n" + convergence + "\n" + threshold_table +
                         "\n## Errors (worst case over the cases) and cost (median)\n\n" +
                         markdown(summary) +
                         "\n## The same over the records sampled at a whole number of steps\n\n" +
                         markdown(summarize(rows, steps, true));
  const std::string md_path = opt.out_dir + "/accuracy-tables.md";
  {
    std::ofstream out(md_path);
    out << md;
    if (!out.flush()) throw InputError(md_path + ": write failed");
  }
  std::printf("%s", md.c_str());
  if (opt.plot) plot(opt, summary);
  // The smoke check: RK4 with located events converges (its errors at the finer step are
  // smaller), and agrees with the reference on collapse.
  for (const Summary& s : summary) {
    if (s.variant != reference_variant.name() || s.dt != steps.back()) continue;
    for (const Summary& coarser : summary) {
      if (coarser.variant != s.variant || coarser.dt != steps.front()) continue;
      if (!(s.peak_theta.value < coarser.peak_theta.value) || s.collapse_differs != 0 ||
          s.peak_theta.missed + s.t_rock.missed > 0) {
        std::fprintf(stderr, "plinth-accuracy: RK4's errors do not shrink with the step\n");
        return 3;
      }
    }
  }
  return 0;
}

// The bundled scenes and records: --source-dir's checkout; else, installed (PREFIX/bin/
// plinth-accuracy), PREFIX/share/plinth's; else the checkout holding the build tree the program
// runs from (the first folder above it with sim/scenes). No path is compiled in.
void find_data(Options& opt) {
  namespace fs = std::filesystem;
  const auto use_checkout = [&opt](const fs::path& root) {
    opt.scenes_dir = (root / "sim" / "scenes").string();
    opt.records_dir = (root / "sim" / "data" / "records").string();
  };
  if (!opt.source_dir.empty()) {
    use_checkout(opt.source_dir);
    return;
  }
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("cannot find the bundled scenes (/proc/self/exe: " + ec.message() +
                           "): give --source-dir");
  const fs::path installed = program.parent_path().parent_path() / "share" / "plinth";
  if (fs::is_directory(installed / "scenes") && fs::is_directory(installed / "records")) {
    opt.scenes_dir = (installed / "scenes").string();
    opt.records_dir = (installed / "records").string();
    return;
  }
  for (fs::path dir = program.parent_path(); !dir.empty() && dir != dir.parent_path();
       dir = dir.parent_path()) {
    if (fs::is_directory(dir / "sim" / "scenes")) {
      use_checkout(dir);
      return;
    }
  }
  throw InputError("the bundled scenes and records are neither in " + installed.string() +
                   " nor in a checkout above " + program.parent_path().string() +
                   ": give --source-dir");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plinth-accuracy: error against cost of the solver's steppers (docs/accuracy.md)"};
  Options opt;
  app.add_option("--source-dir", opt.source_dir,
                 "a plinth checkout (scenes, records); default: the install's share/plinth");
  app.add_option("--out-dir", opt.out_dir, "where the CSV, Markdown and plot files go");
  app.add_flag("--plot", opt.plot, "draw accuracy.png and accuracy.svg with gnuplot");
  app.add_flag("--quick", opt.quick, "one case, two steps: a smoke test (seconds)");
  if (const std::optional<int> exit_code = plinth::host::parse_command_line(app, argc, argv)) {
    return *exit_code;
  }
  return plinth::host::run_tool("plinth-accuracy", [&] {
    find_data(opt);
    return run(opt);
  });
}
