// plinth-sim: one simulation of a scene under a record, an impulse or a pulse.
// Writes a CSV time history (--out), a JSON Lines event log (--events) and a human summary.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "plinth/core/simulator.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/output_file.h"
#include "plinth/host/record_io.h"
#include "plinth/host/record_sampling.h"
#include "plinth/host/run_output.h"
#include "plinth/host/scene_toml.h"
#include "plinth/host/units.h"

namespace {

using plinth::host::InputError;

struct Options {
  std::string scene_path;
  std::string record_path;
  std::string vertical_path;
  std::string pga;
  std::optional<double> scale;
  std::optional<double> impulse;
  std::string pulse;
  std::string amplitude;
  std::optional<double> period;
  double dt = 1e-4;
  std::optional<double> t_end;
  std::string out_path;
  double out_interval = 1e-3;
  std::string events_path;
};

// Phase intervals for the summary, built from the events as they come.
struct TimelineEntry {
  double t;
  std::string what;
};

class RunSink final : public plinth::EventSink {
 public:
  explicit RunSink(std::ostream* events_out) : events_out_(events_out) {}

  void on_event(const plinth::Event& e) override {
    using plinth::EventKind;
    if (events_out_ != nullptr) *events_out_ << plinth::host::event_json(e) << '\n';
    if (e.kind == EventKind::kImpact || e.kind == EventKind::kRockingStop) ++impacts;
    if (e.kind == EventKind::kBaseStopHit) ++base_stop_hits;
    if (e.kind == EventKind::kLiftOff) lift_off = e;
    const char* side = e.side > 0 ? "right" : "left";
    char text[128];
    switch (e.kind) {
      case EventKind::kBaseStopHit:
        std::snprintf(text, sizeof text, "  base hits the %s stop (u' %.3g -> %.3g m/s)", side,
                      e.before, e.after);
        timeline.push_back({e.t, text});
        break;
      case EventKind::kBaseStopHeld:
        timeline.push_back({e.t, std::string("  base rests on the ") + side + " stop"});
        break;
      case EventKind::kBaseStopReleased:
        timeline.push_back({e.t, std::string("  base leaves the ") + side + " stop"});
        break;
      case EventKind::kSlideStopHit:
        std::snprintf(text, sizeof text, "  block hits the %s sliding stop (x' %.3g m/s)", side,
                      e.before);
        timeline.push_back({e.t, text});
        break;
      case EventKind::kOutOfBase:
        timeline.push_back({e.t, std::string("  block overhangs the support's ") + side + " edge"});
        break;
      case EventKind::kBackOnBase:
        timeline.push_back({e.t, std::string("  block back on the support (") + side + " edge)"});
        break;
      default:
        break;
    }
    // One line per change of phase (and of rocking corner or sliding direction at its start).
    std::string phase = plinth::phase_name(e.phase);
    if (e.phase == plinth::Phase::kRocking || e.phase == plinth::Phase::kSlideRocking ||
        e.phase == plinth::Phase::kOverturned) {
      phase += std::string(" about the ") +
               (plinth::pivots_on_support(e.corner, e.overhang) ? "support's " : "") +
               plinth::corner_name(e.corner) + " corner";
    }
    if (e.kind == EventKind::kSlidingStart) {
      phase += e.phase == plinth::Phase::kSliding ? std::string(" ") + side
                                                   : std::string(", sliding ") + side;
    }
    if (e.phase == plinth::Phase::kFell) phase += std::string(" off the ") + side + " edge";
    const bool starts = e.kind == EventKind::kRockingStart || e.kind == EventKind::kSlidingStart;
    if (e.phase != last_phase_ || starts) {
      if (phase != last_text_) timeline.push_back({e.t, phase});
      last_text_ = phase;
    }
    last_phase_ = e.phase;
  }

  std::vector<TimelineEntry> timeline{{0.0, "full_contact"}};
  long impacts = 0;
  long base_stop_hits = 0;
  std::optional<plinth::Event> lift_off;

 private:
  std::ostream* events_out_;
  plinth::Phase last_phase_ = plinth::Phase::kFullContact;
  std::string last_text_ = "full_contact";
};

// Set by SIGINT and SIGTERM: the run stops at the next step and leaves no output behind.
volatile std::sig_atomic_t g_stop = 0;
extern "C" void request_stop(int /*signal*/) { g_stop = 1; }

// Exit code of a run stopped by SIGINT or SIGTERM (128 + SIGINT, as shells report it).
constexpr int kInterruptedExit = 130;

std::string describe_scene(const plinth::Scene& s) {
  char text[320];
  int n = std::snprintf(text, sizeof text, "block b=%g m, h=%g m, e=%g m, m=%g kg", s.b, s.h,
                        s.params.block.eccentricity, s.m);
  if (s.has_base()) {
    n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                       "; base m_b=%g kg, T=%g s, xi=%g", s.params.base.mass,
                       s.params.base.period, s.params.base.damping_ratio);
    if (s.params.has_base_stops) {
      std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                    "; base stops u_max=%g m, eta_i=%g", s.params.base_stops.max_displacement,
                    s.params.base_stops.restitution);
    }
  } else {
    n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), "; on the ground");
  }
  std::string out = text;
  const plinth::SceneParams& p = s.params;
  char more[160];
  if (p.has_friction) {
    std::snprintf(more, sizeof more, "; friction mu_s=%g, mu_k=%g", p.friction.static_coefficient,
                  p.friction.kinetic_coefficient);
    out += more;
  }
  if (p.has_support) {
    std::snprintf(more, sizeof more, "; support x_hat=%g m%s", p.support.clearance,
                  p.has_sliding_stops ? "" : " (the block may leave it)");
    out += more;
  }
  if (p.has_sliding_stops) {
    std::snprintf(more, sizeof more, "; sliding stops eta_s=%g", p.sliding_stops.restitution);
    out += more;
  }
  return out;
}

// The record (and its vertical motion: --vertical, else the record's own vertical column) as
// the excitation, scaled as asked; `text` describes it.
plinth::Excitation record_excitation(const Options& opt, double g, plinth::host::Record& record,
                                     plinth::host::Record& vertical, std::string& text) {
  record = plinth::host::read_record(opt.record_path, g);
  std::string vertical_text = record.vertical.empty() ? "" : "; vertical: its own column";
  plinth::SampledSignal vertical_signal = record.vertical_signal();
  if (!opt.vertical_path.empty()) {
    vertical = plinth::host::read_record(opt.vertical_path, g);
    if (std::fabs(vertical.dt - record.dt) > 1e-9 * record.dt) {
      throw InputError("--vertical " + opt.vertical_path + ": sampling interval " +
                       plinth::host::number_text(vertical.dt) +
                       " s differs from the horizontal record's " +
                       plinth::host::number_text(record.dt) + " s");
    }
    vertical_signal = vertical.horizontal_signal();
    vertical_text = "; vertical: " + opt.vertical_path +
                    (record.vertical.empty() ? "" : " (in place of the record's own column)");
  }
  if (record.dt < opt.dt) {  // said, not refused: the run is still the record's low-passed view
    std::fprintf(stderr,
                 "plinth-sim: note: %s is sampled every %s s, finer than --dt %s: the integration "
                 "sees the record at its steps only (a --dt of at most %s follows every sample)\n",
                 plinth::host::shown(opt.record_path).c_str(),
                 plinth::host::number_text(record.dt).c_str(),
                 plinth::host::number_text(opt.dt).c_str(),
                 plinth::host::number_text(record.dt).c_str());
  }
  const double gamma = plinth::host::record_scale(record, opt.record_path, opt.pga, opt.scale, g);
  if (!opt.vertical_path.empty()) {
    plinth::host::check_scaled_peak(
        gamma, vertical.peak_horizontal(), g,
        opt.pga.empty() ? plinth::host::given("--scale", gamma) : "--pga " + opt.pga);
  }
  char line[256];
  std::snprintf(line, sizeof line, "%s, PGA %.4g g (scale %.4g), dt %g s, %.2f s",
                record.name.c_str(), gamma * record.peak_horizontal() / g, gamma, record.dt,
                record.duration());
  text = line + vertical_text;
  return plinth::Excitation::record(record.horizontal_signal(), vertical_signal, gamma);
}

// The fewest solver steps in a pulse's period (a one-sine pulse sampled 20 times: its peak
// within 1.3 %).
constexpr double kMinStepsPerPulse = 20.0;

// The steps of the run and between CSV rows, within the limits (limits.h).
struct StepPlan {
  std::int64_t steps = 0;
  std::int64_t out_every = 1;
};

// `t_end`: --t-end, or the excitation's duration + 5 s (at least 10 s), whose input a message
// about the run's length names: the pulse's --period or the record.
StepPlan plan_steps(const Options& opt, double t_end, double excitation_duration) {
  using plinth::host::given;
  std::string run_of = " (a run of " + plinth::host::number_text(t_end) + " s";
  if (!opt.t_end && excitation_duration + 5.0 > 10.0) {
    const std::string source = !opt.record_path.empty()
                                   ? "the record " + plinth::host::shown(opt.record_path)
                                   : "the pulse of " + given("--period", opt.period.value_or(0.0));
    run_of += ": " + source + " lasts " + plinth::host::number_text(excitation_duration) +
              " s, and 5 s after it; --t-end shortens it";
  }
  const std::string subject =
      given("--dt", opt.dt) + (opt.t_end ? " and " + given("--t-end", t_end) : run_of + ")");
  StepPlan plan;
  plan.steps = plinth::host::bounded_count(std::round(t_end / opt.dt), plinth::host::kMaxRunSteps,
                                           subject, "the run would take", "solver steps");
  if (opt.out_path.empty()) return plan;
  if (opt.out_interval > t_end) {
    throw InputError(given("--out-interval", opt.out_interval) + ": longer than the run (" +
                     plinth::host::number_text(t_end) + " s); the CSV would hold one row");
  }
  plan.out_every = std::max<std::int64_t>(1, std::llround(opt.out_interval / opt.dt));
  (void)plinth::host::bounded_count(
      static_cast<double>(plan.steps / plan.out_every), plinth::host::kMaxTimeHistoryRows,
      given("--out-interval", opt.out_interval) + " with " + given("--dt", opt.dt),
      "the time history would have", "rows");
  return plan;
}

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool finite_state(const plinth::State& y) { return y.allFinite(); }

int run(const Options& opt) {
  // Outputs first: a slip in a file name is reported before any work.
  plinth::host::check_distinct_files({{"--out", opt.out_path}, {"--events", opt.events_path}},
                                     {{"--scene", opt.scene_path},
                                      {"--record", opt.record_path},
                                      {"--vertical", opt.vertical_path}});
  if (!opt.out_path.empty()) plinth::host::check_output_path("--out", opt.out_path);
  if (!opt.events_path.empty()) plinth::host::check_output_path("--events", opt.events_path);
  const plinth::Scene scene = plinth::host::load_scene_file(opt.scene_path);
  const double g = scene.g;

  plinth::host::Record record;
  plinth::host::Record vertical;
  plinth::Excitation excitation;
  std::string excitation_text = "none";
  if (!opt.record_path.empty()) {
    excitation = record_excitation(opt, g, record, vertical, excitation_text);
  } else if (!opt.pulse.empty()) {
    const double amplitude = plinth::host::parse_acceleration(opt.amplitude, g, "--amplitude");
    if (!(std::fabs(amplitude) / g <= plinth::host::kMaxScaledPeakG)) {
      throw InputError("--amplitude " + opt.amplitude + ": limit " +
                       plinth::host::number_text(plinth::host::kMaxScaledPeakG) + " g");
    }
    // A pulse the step cannot follow would be sampled at a few points, or at none: outside
    // what the integration assumes (docs/model.md, "Other limits of the model").
    if (*opt.period < kMinStepsPerPulse * opt.dt) {
      throw InputError(plinth::host::given("--period", *opt.period) + ": a pulse shorter than " +
                       plinth::host::number_text(kMinStepsPerPulse) + " solver steps (" +
                       plinth::host::given("--dt", opt.dt) +
                       ") is not followed by the integration; a smaller --dt or a longer --period");
    }
    excitation = opt.pulse == "sine" ? plinth::Excitation::sine_pulse(amplitude, *opt.period)
                                     : plinth::Excitation::cosine_pulse(amplitude, *opt.period);
    char text[160];
    std::snprintf(text, sizeof text, "one-%s pulse, amplitude %.4g g, period %g s",
                  opt.pulse.c_str(), amplitude / g, *opt.period);
    excitation_text = text;
  } else if (opt.impulse) {
    if (!(std::fabs(*opt.impulse) <= plinth::host::kMaxImpulse)) {
      throw InputError(plinth::host::given("--impulse", *opt.impulse) + ": limit " +
                       plinth::host::number_text(plinth::host::kMaxImpulse) + " m/s");
    }
    char text[96];
    std::snprintf(text, sizeof text, "impulse I = %g m/s (Eq 34)", *opt.impulse);
    excitation_text = text;
  }

  plinth::SolverSettings settings;
  settings.step = opt.dt;
  plinth::Simulator sim;
  plinth::host::throw_if_simulator_error(
      plinth::Simulator::create(scene, excitation, settings, sim), scene, settings.step);

  const double t_end = opt.t_end ? *opt.t_end : std::max(10.0, excitation.duration() + 5.0);
  const StepPlan plan = plan_steps(opt, t_end, excitation.duration());
  std::optional<plinth::host::OutputFile> csv_file;
  std::optional<plinth::host::OutputFile> events_file;
  if (!opt.out_path.empty()) csv_file.emplace("--out", opt.out_path);
  if (!opt.events_path.empty()) events_file.emplace("--events", opt.events_path);
  std::optional<plinth::host::TimeHistoryCsv> csv;
  if (csv_file) csv.emplace(csv_file->stream());
  RunSink sink(events_file ? &events_file->stream() : nullptr);
  sim.set_event_sink(&sink);

  if (opt.impulse) {
    sim.start_with_impulse(*opt.impulse);
  } else {
    sim.start_at_rest();
  }
  install_stop_handlers();
  double peak_theta = 0.0;
  double peak_u = 0.0;
  double peak_x = 0.0;
  const auto wall_start = std::chrono::steady_clock::now();
  for (std::int64_t i = 0; i <= plan.steps; ++i) {
    const plinth::State& y = sim.state();
    if (!finite_state(y)) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "the solver's state is not finite at t = %.6g s (an overflow): no result "
                    "(try a smaller --dt, or check the excitation)",
                    sim.time());
      throw InputError(text);
    }
    if (g_stop != 0) {
      std::fprintf(stderr, "plinth-sim: interrupted at t = %.4f s: no output written\n",
                   sim.time());
      return kInterruptedExit;
    }
    peak_theta = std::max(peak_theta, std::fabs(y[plinth::kTheta]));
    peak_u = std::max(peak_u, std::fabs(y[plinth::kU]));
    peak_x = std::max(peak_x, std::fabs(y[plinth::kX]));
    const bool last = sim.mode().terminal() || i == plan.steps;
    if (csv && (i % plan.out_every == 0 || last)) {
      csv->write_row(sim.time(), excitation.at(sim.time()).horizontal, y, sim.mode().phase);
    }
    if (last) break;
    sim.step();
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  const plinth::host::Outcome outcome = plinth::host::outcome_of(sim.mode().phase);
  if (events_file) {
    events_file->stream() << plinth::host::end_json(sim.time(), outcome,
                                                     sink.lift_off ? sink.lift_off->t : 0.0)
                          << '\n';
  }
  if (csv_file) csv_file->commit();
  if (events_file) events_file->commit();

  std::printf("scene:      %s (%s)\n", opt.scene_path.c_str(), describe_scene(scene).c_str());
  std::printf("excitation: %s\n", excitation_text.c_str());
  std::printf("solver:     RK4, dt %g s, %lld steps to t = %.3f s in %.3f s (%.0fx real time)\n",
              opt.dt, static_cast<long long>(sim.step_count()), sim.time(), wall,
              wall > 0.0 ? sim.time() / wall : 0.0);
  std::printf("phase timeline (and stop and support events):\n");
  for (const TimelineEntry& entry : sink.timeline) {
    std::printf("  %10.4f s  %s\n", entry.t, entry.what.c_str());
  }
  const double alpha = std::min(scene.corner1.critical_angle, scene.corner2.critical_angle);
  if (sink.lift_off) {
    std::printf("outside the model: at t = %.6g s the block lost contact with its support (%s; "
                "g + v_G'' = %.4g m/s2). The model has no free flight: this run ends there, and "
                "neither survival nor collapse is known after it.\n",
                sink.lift_off->t,
                sink.lift_off->before < 0.0 ? "the ground falls faster than gravity"
                                            : "the rocking unloads its pivot, Eq 12",
                sink.lift_off->before);
  }
  std::printf("outcome:    %s at t = %.4f s; peak |theta| %.4g rad (%.3g of alpha), peak |u| %.4g m,"
              " peak |x| %.4g m; %ld impacts, %ld base stop hits\n",
              plinth::host::outcome_name(outcome), sim.time(), peak_theta, peak_theta / alpha,
              peak_u, peak_x, sink.impacts, sink.base_stop_hits);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plinth-sim: simulate a block on an isolated base (or the ground) under a "
               "record, an impulse or a pulse"};
  Options opt;
  app.add_option("--scene", opt.scene_path, "scene file (TOML)")->required();
  auto* record = app.add_option("--record", opt.record_path, "horizontal record (.AT2 or .csv)");
  app.add_option("--vertical", opt.vertical_path, "vertical record (same dt)")->needs(record);
  auto* pga = app.add_option("--pga", opt.pga, "scale the record to this PGA, e.g. 0.3g")->needs(record);
  app.add_option("--scale", opt.scale, "scale factor gamma of the record")
      ->needs(record)
      ->excludes(pga)
      ->check(plinth::host::kFinite);
  auto* impulse = app.add_option("--impulse", opt.impulse, "impulse I, m/s (Eq 34)")
                      ->excludes(record)
                      ->check(plinth::host::kFinite);
  auto* pulse = app.add_option("--pulse", opt.pulse, "one-period pulse: sine or cosine")
                    ->check(CLI::IsMember({"sine", "cosine"}))
                    ->excludes(record)
                    ->excludes(impulse);
  app.add_option("--amplitude", opt.amplitude, "pulse amplitude, e.g. 0.5g")->needs(pulse);
  app.add_option("--period", opt.period, "pulse period, s")->needs(pulse)->check(plinth::host::kFinitePositive);
  app.add_option("--dt", opt.dt, "solver step, s")->check(plinth::host::kFinitePositive);
  app.add_option("--t-end", opt.t_end, "end time, s (default: the input's length + 5 s, at least 10 s)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--out", opt.out_path, "CSV time history");
  app.add_option("--out-interval", opt.out_interval, "time between CSV rows, s (whole steps)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--events", opt.events_path, "JSON Lines event log");
  const auto checks = [&] {
    plinth::host::refuse_without_effect(
        app, {"--out-interval"}, !opt.out_path.empty(),
        "sets the time between the rows of --out's CSV; without --out there is no CSV");
  };
  if (const std::optional<int> exit_code =
          plinth::host::parse_command_line(app, argc, argv, checks)) {
    return *exit_code;
  }
  if (!opt.pulse.empty() && (opt.amplitude.empty() || !opt.period)) {
    std::fprintf(stderr, "plinth-sim: --pulse needs --amplitude and --period\n");
    return 2;
  }
  return plinth::host::run_tool("plinth-sim", [&] { return run(opt); });
}
