// plinth-sweep: the paper's parametric analyses (section 5) for any scene and record
// (docs/sweep.md). For each value of one scene parameter, the smallest PGA at which each kind
// of event first occurs; two-parameter maps of one event; impulse maps and impulse curves;
// shards and their merge; plots with gnuplot.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/job_runner.h"
#include "plinth/host/limits.h"
#include "plinth/host/output_file.h"
#include "plinth/host/record_io.h"
#include "plinth/host/run_progress.h"
#include "plinth/host/scene_toml.h"
#include "plinth/host/sweep_impulse.h"
#include "plinth/host/sweep_plan.h"
#include "plinth/host/sweep_table.h"
#include "plinth/host/units.h"
#include "sweep_output.h"
#include "sweep_plot.h"

namespace {

using plinth::host::InputError;

// Exit code of a run stopped by SIGINT or SIGTERM (128 + SIGINT, as shells report it).
constexpr int kInterruptedExit = 130;

struct Options {
  std::string scene_path;
  std::string record_path;
  std::string param;
  std::optional<double> from, to;
  std::optional<int> steps;
  std::string param2;
  std::optional<double> from2, to2;
  std::optional<int> steps2;
  std::string event = "overturned";
  std::string pga_max = "2g";
  std::string tol = "0.001g";
  bool impulse_map = false;
  std::optional<double> mu_from, mu_to, impulse_from, impulse_to;
  std::optional<int> mu_steps, impulse_steps;
  bool impulse_curve = false;
  double impulse_max = 10.0;
  double impulse_tol = 1e-3;
  std::optional<int> jobs;
  std::string shard = "1/1";
  double dt = 5e-4;
  std::string out_path;
  std::string plot_path;
  bool fresh = false;
  bool compare_ground = false;
};

struct MergeOptions {
  std::string out_path;
  std::vector<std::string> inputs;
  std::string plot_path;
};

struct PlotOptions {
  std::string csv_path;
  std::string plot_path;
};


template <typename T>
T required(const std::optional<T>& value, const char* option, const char* mode) {
  if (!value) throw InputError(std::string(option) + " is required " + mode);
  return *value;
}

void require_text(const std::string& value, const char* option, const char* mode) {
  if (value.empty()) throw InputError(std::string(option) + " is required " + mode);
}

// The grid axis of --<prefix>from/to/steps, checked.
plinth::host::GridAxis axis_of(const std::string& name, const std::optional<double>& from,
                               const std::optional<double>& to, const std::optional<int>& steps,
                               const std::string& prefix, const std::string& suffix,
                               const char* mode) {
  const std::string f = "--" + prefix + "from" + suffix;
  const std::string t = "--" + prefix + "to" + suffix;
  const std::string s = "--" + prefix + "steps" + suffix;
  plinth::host::GridAxis axis{name, required(from, f.c_str(), mode), required(to, t.c_str(), mode),
                              required(steps, s.c_str(), mode)};
  (void)plinth::host::sweep_values(axis.from, axis.to, axis.steps, "--" + prefix, suffix);
  return axis;
}

// Simulations of an impulse last at most this long (sweep_impulse.cpp: 60 s on the ground,
// five base periods on a base), s.
constexpr double kImpulseSimulationBound = 60.0;

// The steps of one simulation and of one bisection, within the limits (limits.h).
void check_work(const Options& opt, double simulated_s, const char* what) {
  using plinth::host::given;
  (void)plinth::host::bounded_count(
      std::ceil(simulated_s / opt.dt), plinth::host::kMaxSweepSimulationSteps,
      given("--dt", opt.dt) + " (" + what + " of " + plinth::host::number_text(simulated_s) + " s)",
      "each simulation would take", "solver steps");
  if (opt.impulse_curve) {
    (void)plinth::host::bounded_count(std::ceil(std::log2(opt.impulse_max / opt.impulse_tol)),
                                      plinth::host::kMaxBisectionSteps,
                                      given("--impulse-tol", opt.impulse_tol) + " with " +
                                          given("--impulse-max", opt.impulse_max),
                                      "each search would take", "bisection steps");
  }
}

void check_bisection(double pga_max_g, double tol_g, const std::string& pga_max,
                     const std::string& tol) {
  (void)plinth::host::bounded_count(
      std::ceil(std::log2(pga_max_g / tol_g)), plinth::host::kMaxBisectionSteps,
      "--tol " + tol + " with --pga-max " + pga_max, "each search would take", "bisection steps");
}

int run_sweep_mode(const Options& opt) {
  // Cheap checks first, so a usage slip does not wait for files to load.
  const char* mode = opt.impulse_map     ? "with --impulse-map"
                     : opt.impulse_curve ? "with --impulse-curve"
                                         : "for a PGA sweep";
  require_text(opt.scene_path, "--scene", mode);
  require_text(opt.out_path, "--out", mode);
  plinth::host::check_output_path("--out", opt.out_path);
  plinth::host::check_distinct_files({{"--out", opt.out_path}},
                                     {{"--scene", opt.scene_path}, {"--record", opt.record_path}});
  plinth::host::JobRun run;
  plinth::host::parse_shard(opt.shard, run.shard_index, run.shard_count);
  run.jobs =
      opt.jobs ? *opt.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  plinth::host::validate(run);
  if (opt.impulse_map && opt.impulse_curve) {
    throw InputError("--impulse-map and --impulse-curve: choose one");
  }
  std::optional<plinth::host::SweepParameter> parameter;
  std::optional<plinth::host::GridAxis> axis;
  if (!opt.impulse_map) {
    require_text(opt.param, "--param", mode);
    parameter = plinth::host::parse_sweep_parameter(opt.param);
    axis = axis_of(opt.param, opt.from, opt.to, opt.steps, "", "", mode);
  }
  if (!opt.plot_path.empty()) {
    (void)plinth::sim::plot_stem(opt.plot_path);
    (void)plinth::sim::find_gnuplot();  // before hours of simulation, not after
  }

  const plinth::Scene scene = plinth::host::load_scene_file(opt.scene_path);
  const double g = scene.g;
  if (opt.impulse_map || opt.impulse_curve) {
    check_work(opt, kImpulseSimulationBound, "an impulse simulation");
    for (const auto& [option, value] :
         {std::pair<const char*, std::optional<double>>{"--impulse-to", opt.impulse_to},
          {"--impulse-from", opt.impulse_from},
          {"--impulse-max", opt.impulse_max}}) {
      if (value && !(std::fabs(*value) <= plinth::host::kMaxImpulse)) {
        throw InputError(plinth::host::given(option, *value) + ": limit " +
                         plinth::host::number_text(plinth::host::kMaxImpulse) + " m/s");
      }
    }
  }
  plinth::host::SweepPlan plan;
  if (opt.impulse_map) {
    const auto mu_axis = axis_of("mu_s", opt.mu_from, opt.mu_to, opt.mu_steps, "mu-", "", mode);
    const auto impulse_axis = axis_of("impulse", opt.impulse_from, opt.impulse_to,
                                      opt.impulse_steps, "impulse-", "", mode);
    plan = plinth::host::plan_impulse_map(scene.params, mu_axis, impulse_axis, opt.dt);
  } else if (opt.impulse_curve) {
    plinth::host::ImpulseSearchSettings settings;
    settings.impulse_max = opt.impulse_max;
    settings.tolerance = opt.impulse_tol;
    settings.dt = opt.dt;
    plan = plinth::host::plan_impulse_curve(scene.params, *parameter, *axis, settings,
                                            opt.compare_ground);
  } else {
    require_text(opt.record_path, "--record", mode);
    const plinth::host::Record record = plinth::host::read_record(opt.record_path, g);
    plinth::host::SweepSettings settings;
    settings.pga_max_g = plinth::host::parse_acceleration(opt.pga_max, g, "--pga-max") / g;
    settings.tolerance_g = plinth::host::parse_acceleration(opt.tol, g, "--tol") / g;
    settings.dt = opt.dt;
    plinth::host::validate(settings);
    check_bisection(settings.pga_max_g, settings.tolerance_g, opt.pga_max, opt.tol);
    check_work(opt, record.duration() + 2.0, "a record");
    if (opt.param2.empty()) {
      plan = plinth::host::plan_thresholds(scene.params, record, *parameter, *axis, settings,
                                           opt.compare_ground);
    } else {
      const auto parameter2 = plinth::host::parse_sweep_parameter(opt.param2, "--param2");
      const auto axis2 =
          axis_of(opt.param2, opt.from2, opt.to2, opt.steps2, "", "2", "with --param2");
      plan = plinth::host::plan_threshold_map(scene.params, record, *parameter, *axis, parameter2,
                                              axis2, plinth::host::parse_sweep_event(opt.event),
                                              settings, opt.compare_ground);
    }
  }

  run.stop = plinth::host::install_stop_handlers("plinth-sweep");
  const plinth::sim::SweepOutcome outcome =
      plinth::sim::run_to_file(plan, run, {opt.out_path, opt.fresh});
  if (outcome.interrupted) {
    std::fprintf(stderr,
                 "plinth-sweep: interrupted: %zu of %zu rows kept in %s (%zu found there "
                 "before); run the same command again to resume\n",
                 outcome.rows_written, outcome.rows_total, opt.out_path.c_str(),
                 outcome.rows_resumed);
    return kInterruptedExit;
  }
  std::printf(
      "plinth-sweep: %zu rows (shard %d/%d of %zu; %zu resumed from %s), %zu "
      "simulations, %d jobs, wall time %.2f s -> %s\n",
      outcome.rows_written, run.shard_index, run.shard_count, plan.keys.size(),
      outcome.rows_resumed, opt.out_path.c_str(), outcome.simulations, run.jobs,
      outcome.wall_seconds, opt.out_path.c_str());
  if (!opt.plot_path.empty()) {
    const std::string images =
        plinth::sim::plot_sweep(plinth::host::read_sweep_table(opt.out_path), opt.plot_path);
    std::printf("plinth-sweep: plotted %s\n", images.c_str());
  }
  return 0;
}

int run_merge(const MergeOptions& opt) {
  plinth::host::check_output_path("--out", opt.out_path);
  std::vector<std::pair<std::string, std::string>> inputs;
  for (const std::string& path : opt.inputs) inputs.emplace_back("input", path);
  plinth::host::check_distinct_files({{"--out", opt.out_path}}, inputs);
  if (!opt.plot_path.empty()) {
    (void)plinth::sim::plot_stem(opt.plot_path);
    (void)plinth::sim::find_gnuplot();
  }
  std::vector<plinth::host::SweepTable> parts;
  for (const std::string& path : opt.inputs) parts.push_back(plinth::host::read_sweep_table(path));
  const plinth::host::SweepTable merged = plinth::host::merge_sweep_tables(parts, opt.inputs);
  plinth::sim::write_table_file(merged, opt.out_path);
  std::printf("plinth-sweep merge: %zu rows from %zu files -> %s\n", merged.rows.size(),
              parts.size(), opt.out_path.c_str());
  if (!opt.plot_path.empty()) {
    std::printf("plinth-sweep: plotted %s\n",
                plinth::sim::plot_sweep(merged, opt.plot_path).c_str());
  }
  return 0;
}

int run_plot(const PlotOptions& opt) {
  (void)plinth::sim::plot_stem(opt.plot_path);
  const std::string images =
      plinth::sim::plot_sweep(plinth::host::read_sweep_table(opt.csv_path), opt.plot_path);
  std::printf("plinth-sweep: plotted %s\n", images.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using plinth::host::kFinite;
  using plinth::host::kFinitePositive;
  CLI::App app{
      "plinth-sweep: the paper's parametric analyses (docs/sweep.md): first-occurrence "
      "PGA of each event against one parameter, two-parameter maps, impulse maps and "
      "impulse curves"};
  app.require_subcommand(0, 1);
  Options opt;
  app.add_option("--scene", opt.scene_path, "scene file (TOML)");
  app.add_option("--record", opt.record_path, "horizontal record (.AT2 or .csv), PGA modes");
  app.add_option("--param", opt.param,
                 "parameter to sweep: mu_s, epsilon, lambda, T, xi, u_max or mass_ratio");
  app.add_option("--from", opt.from, "first value of the parameter")->check(kFinite);
  app.add_option("--to", opt.to, "last value of the parameter")->check(kFinite);
  app.add_option("--steps", opt.steps, "number of values, from..to inclusive");
  app.add_option("--param2", opt.param2, "second parameter: a map of one event (--event)");
  app.add_option("--from2", opt.from2, "first value of --param2")->check(kFinite);
  app.add_option("--to2", opt.to2, "last value of --param2")->check(kFinite);
  app.add_option("--steps2", opt.steps2, "number of values of --param2");
  app.add_option("--event", opt.event, "event of a two-parameter map (default overturned)");
  app.add_option("--pga-max", opt.pga_max, "largest PGA scanned, e.g. 2g (default 2g)");
  app.add_option("--tol", opt.tol, "PGA tolerance of the thresholds, e.g. 0.001g (default)");
  CLI::Option* impulse_map =
      app.add_flag("--impulse-map", opt.impulse_map,
                   "map of the motion an impulse starts with over (|I|, mu_s), with the closed "
                   "forms of section 5.3.1");
  app.add_option("--mu-from", opt.mu_from, "impulse map: first mu_s")->check(kFinite);
  app.add_option("--mu-to", opt.mu_to, "impulse map: last mu_s")->check(kFinite);
  app.add_option("--mu-steps", opt.mu_steps, "impulse map: number of mu_s values");
  app.add_option("--impulse-from", opt.impulse_from, "impulse map: first |I|, m/s")
      ->check(kFinitePositive);
  app.add_option("--impulse-to", opt.impulse_to, "impulse map: last |I|, m/s")
      ->check(kFinitePositive);
  app.add_option("--impulse-steps", opt.impulse_steps, "impulse map: number of |I| values");
  CLI::Option* impulse_curve =
      app.add_flag("--impulse-curve", opt.impulse_curve,
                   "smallest impulses that start rocking and overturn, against --param");
  app.add_option("--impulse-max", opt.impulse_max,
                 "impulse curve: largest |I| scanned, m/s (default 10)")
      ->check(kFinitePositive);
  app.add_option("--impulse-tol", opt.impulse_tol,
                 "impulse curve: tolerance of the thresholds, m/s (default 0.001)")
      ->check(kFinitePositive);
  app.add_option("--jobs", opt.jobs, "threads (default: the hardware's)");
  app.add_option("--shard", opt.shard, "run only part i of N of the rows, as i/N (default 1/1)");
  app.add_option("--dt", opt.dt, "solver step, s (default 5e-4)")->check(kFinitePositive);
  app.add_option("--out", opt.out_path, "CSV file (rows already there are resumed)");
  app.add_option("--plot", opt.plot_path, "also plot: map.png writes map.png and map.svg");
  app.add_flag("--fresh", opt.fresh, "do not resume from rows already in --out");
  app.add_flag("--compare-ground", opt.compare_ground,
               "also the thresholds of the same block on the ground (no base, no stops), in "
               "columns <event>_ground");
  for (const char* option : {"--record", "--param2", "--pga-max", "--tol"}) {
    impulse_map->excludes(option);
    impulse_curve->excludes(option);
  }

  MergeOptions merge;
  CLI::App* merge_command =
      app.add_subcommand("merge", "join the CSVs of the shards of one sweep, in grid order");
  merge_command->add_option("--out", merge.out_path, "merged CSV")->required();
  merge_command->add_option("--plot", merge.plot_path, "also plot the merged CSV");
  merge_command->add_option("inputs", merge.inputs, "the shards' CSV files")->required();

  PlotOptions plot;
  CLI::App* plot_command = app.add_subcommand("plot", "plot a sweep CSV: PNG and SVG with gnuplot");
  plot_command->add_option("csv", plot.csv_path, "a plinth-sweep CSV")->required();
  plot_command->add_option("--out", plot.plot_path, "image: map.png writes map.png and map.svg")
      ->required();
  if (const std::optional<int> exit_code = plinth::host::parse_command_line(app, argc, argv)) {
    return *exit_code;
  }
  if (opt.compare_ground && opt.impulse_map) {
    std::fprintf(stderr,
                 "plinth-sweep: --compare-ground: not with --impulse-map (its closed forms are "
                 "for the isolated block; on the ground every impulse starts rocking); use it "
                 "with --param, --param2 or --impulse-curve\n");
    return 2;
  }
  if (opt.jobs && *opt.jobs < 1) {
    std::fprintf(stderr, "plinth-sweep: --jobs: must be at least 1, got %d\n", *opt.jobs);
    return 2;
  }
  return plinth::host::run_tool("plinth-sweep", [&] {
    if (merge_command->parsed()) return run_merge(merge);
    if (plot_command->parsed()) return run_plot(plot);
    return run_sweep_mode(opt);
  });
}
