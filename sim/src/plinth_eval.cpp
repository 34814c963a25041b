// plinth-eval: how good the box's warning is (docs/forecast.md). Over records x a PGA grid x
// scenes x true statues drawn inside each scene's declared [uncertainty], the truth from the
// solver on the true statue against the box's timeline (the scene file's ensemble, nominal
// first) on the same motion; per alarm level hits, misses, false alarms, near misses, the lead
// and the ROC; thresholds calibrated on half of the records and reported on the other half; the
// alarms by collapse margin, and the statues' fragility curves.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "eval_case.h"
#include "eval_fault.h"
#include "eval_fault_report.h"
#include "eval_fragility.h"
#include "eval_pwave.h"
#include "eval_pwave_report.h"
#include "eval_regional_report.h"
#include "eval_report.h"
#include "plinth/host/cli.h"
#include "plinth/host/eval_metrics.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/job_runner.h"
#include "plinth/host/record_io.h"
#include "plinth/host/run_progress.h"
#include "plinth/host/scene_toml.h"
#include "plinth/host/units.h"

namespace {

using plinth::host::EvalRun;
using plinth::host::EvalTable;
using plinth::host::InputError;

constexpr int kInterruptedExit = 130;  // 128 + SIGINT, as shells report it
constexpr int kMaxStatues = 1000;
constexpr int kMaxPgaSteps = 200;
// The fault statue_neighbour's statues: drawn as the true statues, from another seed.
constexpr unsigned kNeighbourSeedSalt = 0x6e656967U;  // "neig"

struct RunOptions {
  std::vector<std::string> scene_paths;
  std::vector<std::string> record_paths;
  std::vector<std::string> vertical_paths;  // the i-th for the i-th record (eval_pwave.h)
  std::string pwave = "off";
  std::string regional = "off";  // regional alerts simulated (docs/regional.md, "Evaluation")
  std::string record_info_path;  // each record's source, matched by RSN
  plinth::host::RegionalAlertModel regional_model;
  std::string out_path;
  std::string pga_from = "0.2g";
  std::string pga_to = "2.5g";
  int pga_steps = 12;
  int statues = 20;
  unsigned seed = 2026;
  bool all_scales = false;
  double rate_hz = 200.0;
  int steps_per_sample = 4;
  bool box_knows_statue = false;
  bool statue_sensor = false;
  std::string motion_path;  // --motion-out
  // The box's own continuation unless told (plinth::ForecastSettings, docs/forecast.md).
  std::string forecast = plinth::kContinuationNames.name(plinth::ForecastSettings{}.continuation);
  double horizon_s = 4.0;
  double raise_hold_s = plinth::monitor::AlarmPolicySettings{}.raise_hold_s;
  double truth_step_s = 5e-4;
  std::optional<int> jobs;
  std::string shard = "1/1";
  std::string fault = "none";  // KIND[:PARAM] (eval_fault.h)
  std::string fault_at = "start";
  bool collapses_only = false;
  std::string collapses_of;  // run only the runs that collapsed in this runs file
};

struct ReportOptions {
  std::string runs_path;
  std::string json_path;
  std::string plot_path;
  bool frontier = false;  // also the frontier of the rules (make_report)
  std::string pwave_calibrate_on;  // choose the P-wave threshold on this runs file
  std::string regional_calibrate_on;  // choose the regional threshold on this runs file
  std::string calibration_path;  // choose the rules on this other runs file
  std::string false_alarm =
      plinth::host::false_alarm_name(plinth::sim::CalibrationTargets{}.false_alarm);
};

struct FragilityOptions {
  std::string runs_path;
  std::string json_path;
  std::string plot_path;
  std::string collapse_intensity = "interval";
};

struct FaultReportOptions {
  std::vector<std::string> runs_paths;
  std::string against_path;
  std::string json_path;
  int list_silenced = 10;
};

struct MergeOptions {
  std::vector<std::string> inputs;
  std::string out_path;
};

std::string file_name(const std::string& path) {
  return std::filesystem::path(path).filename().string();
}

plinth::host::PgaGrid pga_grid(const RunOptions& opt) {
  const double g = plinth::kStandardGravity;
  const double from = plinth::host::parse_acceleration(opt.pga_from, g, "--pga-from") / g;
  const double to = plinth::host::parse_acceleration(opt.pga_to, g, "--pga-to") / g;
  if (!(from > 0.0)) throw InputError("--pga-from: must be above 0 g, got " + opt.pga_from);
  if (!(to >= from)) throw InputError("--pga-to " + opt.pga_to + " is below --pga-from " + opt.pga_from);
  if (to > 10.0) throw InputError("--pga-to: at most 10 g, got " + opt.pga_to);
  if (opt.pga_steps < 1 || opt.pga_steps > kMaxPgaSteps) {
    throw InputError("--pga-steps: expected 1 to " + std::to_string(kMaxPgaSteps) + ", got " +
                     std::to_string(opt.pga_steps));
  }
  if (to == from && opt.pga_steps > 1) {
    throw InputError("--pga-steps: a grid from " + opt.pga_from + " to " + opt.pga_to +
                     " has one point, got " + std::to_string(opt.pga_steps));
  }
  return {from, to, opt.pga_steps};
}

// The runs file names a case by its files' names: two paths of one name would be one case.
void refuse_repeated_names(const std::vector<std::string>& paths, const char* option) {
  std::set<std::string> names;
  for (const std::string& path : paths) {
    if (!names.insert(file_name(path)).second) {
      throw InputError(std::string(option) + ": two files named " + file_name(path) +
                       " (the runs file names them by file name; rename one)");
    }
  }
}

plinth::sim::BoxSettings box_settings(const RunOptions& opt) {
  plinth::sim::BoxSettings box;
  box.rate_hz = opt.rate_hz;
  box.steps_per_sample = opt.steps_per_sample;
  box.knows_true_statue = opt.box_knows_statue;
  box.statue_sensor = opt.statue_sensor;
  if (opt.forecast == "off") {
    box.forecast.enabled = false;
  } else if (!plinth::kContinuationNames.parse(opt.forecast, box.forecast.continuation)) {
    throw InputError("--forecast: expected strongest_window, recent_window or off, got '" +
                     opt.forecast + "'");
  }
  box.forecast.horizon_s = opt.horizon_s;
  box.raise_hold_s = opt.raise_hold_s;
  box.forecast.rate_hz = std::min(box.forecast.rate_hz, opt.rate_hz);
  if (opt.pwave != "on" && opt.pwave != "off") {
    throw InputError("--pwave: expected on or off, got '" + opt.pwave + "'");
  }
  box.pwave = opt.pwave == "on";
  box.fault = plinth::sim::parse_fault(opt.fault);
  box.fault.onset = plinth::sim::parse_fault_onset(opt.fault_at);
  if (plinth::sim::needs_statue_sensor(box.fault.kind) && !box.statue_sensor) {
    throw InputError("--fault " + opt.fault + ": a fault of the statue sensor needs "
                     "--statue-sensor");
  }
  if (plinth::sim::happens_at_an_instant(box.fault.kind) &&
      box.fault.onset.anchor == plinth::sim::FaultAnchor::kBoxStart) {
    throw InputError("--fault " + opt.fault + ": needs --fault-at, when it happens (a time in s, "
                     "strong, motion or alarm+S): at the box's start it changes nothing");
  }
  if (opt.regional != "on" && opt.regional != "off") {
    throw InputError("--regional: expected on or off, got '" + opt.regional + "'");
  }
  if (opt.regional == "on") {
    if (opt.record_info_path.empty()) {
      throw InputError("--regional on needs --record-info FILE.csv: each record's magnitude and "
                       "distance (tools/pwave-stations.py writes it; docs/regional.md)");
    }
    box.regional = opt.regional_model;
    box.regional->declared_sigma_ln = box.regional->error_sigma_ln;  // the alert tells its scatter
    plinth::host::validate(*box.regional);
  }
  return box;
}

// The true statues of a scene: `count` points drawn uniformly inside its declared ranges (the
// same statues for every record), each a valid scene.
std::vector<plinth::Scene> draw_statues(const plinth::host::UncertainScene& scene, int count,
                                        unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<plinth::Scene> statues;
  for (int j = 0; j < count; ++j) {
    std::vector<double> u(scene.uncertain.size());
    for (double& x : u) x = unit(rng);
    statues.push_back(scene.statue(u));
  }
  return statues;
}

void write_runs(const std::string& path, const plinth::host::CrossingGrids& grids,
                const std::vector<std::vector<EvalRun>>& results, bool with_grid = true,
                bool with_faults = true) {
  const std::string temporary = path + ".tmp";
  std::FILE* out = std::fopen(temporary.c_str(), "w");
  if (out == nullptr) throw InputError(path + ": cannot write (does its folder exist?)");
  plinth::host::write_eval_csv_header(out, grids, with_grid, with_faults);
  for (const std::vector<EvalRun>& job : results) {
    for (const EvalRun& run : job) plinth::host::write_eval_csv_row(out, run);
  }
  const bool ok = std::fflush(out) == 0 && std::ferror(out) == 0;
  std::fclose(out);
  std::error_code ec;
  if (ok) std::filesystem::rename(temporary, path, ec);
  if (!ok || ec) {
    std::filesystem::remove(temporary, ec);
    throw InputError(path + ": cannot write");
  }
}

// --motion-out: per run, when the true statue first left full contact beside when each level
// was first shown (docs/forecast.md: the alarms a statue sensor cannot take away).
void write_motion(const std::string& path, const std::vector<std::vector<EvalRun>>& results) {
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (out == nullptr) throw InputError(path + ": cannot write (does its folder exist?)");
  std::fprintf(out, "record,scene,statue,seed,scale_g,collapsed,first_motion_s,"
                    "first_advisory_s,first_warning_s,first_alarm_s\n");
  for (const std::vector<EvalRun>& job : results) {
    for (const EvalRun& r : job) {
      std::fprintf(out, "%s,%s,%d,%u,%.6g,%d,%.6g,%.6g,%.6g,%.6g\n", r.record.c_str(),
                   r.scene.c_str(), r.statue, r.seed, r.scale_g, r.collapsed ? 1 : 0,
                   r.first_motion_s, r.first_shown_s[0], r.first_shown_s[1], r.first_shown_s[2]);
    }
  }
  const bool ok = std::fflush(out) == 0 && std::ferror(out) == 0;
  if (std::fclose(out) != 0 || !ok) throw InputError(path + ": cannot write");
}

// --collapses-of FILE: per case index (`case_key(index)`: record|scene|statue), the grid points
// at which the file's runs collapsed. The file must be of this run's seed and grid.
template <class CaseKey>
std::map<std::size_t, std::set<int>> collapsing_points(const RunOptions& opt,
                                                      const plinth::host::PgaGrid& grid,
                                                      std::size_t job_count,
                                                      CaseKey case_key) {
  const EvalTable table = plinth::host::read_eval_csv(opt.collapses_of);
  if (!table.has_grid) {
    throw InputError(opt.collapses_of + ": no seed and pga grid columns (a plinth-eval before "
                     "the collapse margin wrote it): --collapses-of needs them");
  }
  std::map<std::string, std::size_t> index_of;
  for (std::size_t i = 0; i < job_count; ++i) index_of.emplace(case_key(i), i);
  std::map<std::size_t, std::set<int>> points;
  for (const EvalRun& r : table.runs) {
    if (!r.collapsed) continue;
    if (r.seed != opt.seed || !(r.grid == grid)) {
      throw InputError(opt.collapses_of + ": " + r.record + ", " + r.scene + ", statue " +
                       std::to_string(r.statue) + " ran with --seed " + std::to_string(r.seed) +
                       " on another grid or seed than this run's (--seed " +
                       std::to_string(opt.seed) + ", --pga-from/--pga-to/--pga-steps)");
    }
    const auto it = index_of.find(r.record + "|" + r.scene + "|" + std::to_string(r.statue));
    if (it == index_of.end()) continue;  // a case this run does not have (another shard's)
    points[it->second].insert(grid.index_of(r.scale_g));
  }
  return points;
}

int run_eval(const RunOptions& opt) {
  const plinth::host::PgaGrid grid = pga_grid(opt);
  refuse_repeated_names(opt.scene_paths, "--scene");
  refuse_repeated_names(opt.record_paths, "--record");
  if (opt.statues < 1 || opt.statues > kMaxStatues) {
    throw InputError("--statues: expected 1 to " + std::to_string(kMaxStatues) + ", got " +
                     std::to_string(opt.statues));
  }
  const plinth::sim::BoxSettings box = box_settings(opt);
  plinth::sim::TruthSettings truth;
  truth.step_s = opt.truth_step_s;
  std::vector<plinth::host::UncertainScene> scenes;
  std::vector<std::vector<plinth::Scene>> statues;
  std::vector<std::vector<plinth::Scene>> neighbours;  // the fault statue_neighbour's
  for (std::size_t s = 0; s < opt.scene_paths.size(); ++s) {
    scenes.push_back(plinth::host::load_uncertain_scene_file(opt.scene_paths[s]));
    const unsigned seed = opt.seed + 7919U * static_cast<unsigned>(s);
    statues.push_back(draw_statues(scenes.back(), opt.statues, seed));
    if (box.fault.kind == plinth::sim::FaultKind::kStatueNeighbour) {
      neighbours.push_back(draw_statues(scenes.back(), opt.statues, seed ^ kNeighbourSeedSalt));
    }
  }
  const std::vector<plinth::host::Record> records =
      plinth::sim::read_records(opt.record_paths, opt.vertical_paths);
  std::vector<plinth::host::RecordPhases> phases;
  for (const plinth::host::Record& r : records) phases.push_back(plinth::host::record_phases(r));
  std::map<int, plinth::host::RecordSource> record_info;
  std::vector<const plinth::host::RecordSource*> sources(records.size(), nullptr);
  if (box.regional) {
    record_info = plinth::host::read_record_info(opt.record_info_path);
    for (std::size_t r = 0; r < records.size(); ++r) {
      sources[r] = &plinth::host::record_source(record_info, file_name(opt.record_paths[r]),
                                                opt.record_info_path);
    }
  }
  plinth::host::JobRun run;
  plinth::host::parse_shard(opt.shard, run.shard_index, run.shard_count);
  run.jobs = opt.jobs ? *opt.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  plinth::host::validate(run);
  // One job: a record, a scene and a statue over the PGA grid, up to its first collapse.
  const std::size_t per_record = scenes.size() * static_cast<std::size_t>(opt.statues);
  const std::size_t job_count = records.size() * per_record;
  const std::vector<std::size_t> indices = plinth::host::shard_indices(job_count, run);
  plinth::host::CrossingGrids grids = plinth::host::default_crossing_grids();
  if (box.pwave) grids.pwave = plinth::host::default_pwave_grid();
  grids.regional = box.regional.has_value();
  std::vector<std::vector<EvalRun>> results(job_count);
  const auto case_of = [&](std::size_t index, double pga) {
    const std::size_t r = index / per_record;
    const std::size_t s = index % per_record / static_cast<std::size_t>(opt.statues);
    const auto j = static_cast<int>(index % static_cast<std::size_t>(opt.statues));
    const auto statue = static_cast<std::size_t>(j);
    return plinth::sim::EvalCase{&records[r],
                                 file_name(opt.record_paths[r]),
                                 &scenes[s],
                                 file_name(opt.scene_paths[s]),
                                 j,
                                 opt.seed,
                                 grid,
                                 &statues[s][statue],
                                 pga,
                                 phases[r],
                                 sources[r],
                                 neighbours.empty() ? nullptr : &neighbours[s][statue]};
  };
  const bool collapses_only = opt.collapses_only || !opt.collapses_of.empty();
  const plinth::sim::BoxRuns box_runs =
      collapses_only ? plinth::sim::BoxRuns::kCollapses : plinth::sim::BoxRuns::kAll;
  // --collapses-of: the grid points of each case that collapsed there (by case index).
  std::map<std::size_t, std::set<int>> collapsing;  // read by the jobs only once filled
  if (!opt.collapses_of.empty()) {
    collapsing = collapsing_points(opt, grid, job_count, [&](std::size_t index) {
      const plinth::sim::EvalCase c = case_of(index, 0.0);
      return c.record_name + "|" + c.scene_name + "|" + std::to_string(c.statue);
    });
  }
  run.stop = plinth::host::install_stop_handlers("plinth-eval");
  plinth::host::ProgressBar progress(indices.size(), 0, "cases");
  std::size_t done = 0;
  run.on_done = [&](std::size_t) { progress.update(++done); };
  const auto start = std::chrono::steady_clock::now();
  const bool finished = plinth::host::run_jobs(
      indices, run,
      [&](std::size_t index) {
        std::vector<EvalRun> job;
        for (int i = 0; i < grid.steps; ++i) {
          if (run.stop->load()) throw plinth::host::JobCancelled();
          if (!opt.collapses_of.empty()) {
            const auto points = collapsing.find(index);
            if (points == collapsing.end() || points->second.count(i) == 0) continue;
          }
          std::optional<EvalRun> r =
              plinth::sim::run_case(case_of(index, grid.at(i)), box, truth, grids, box_runs);
          if (!r && !opt.collapses_of.empty()) {
            throw InputError(opt.collapses_of + ": says " + case_of(index, 0.0).record_name +
                             ", " + case_of(index, 0.0).scene_name + ", statue " +
                             std::to_string(case_of(index, 0.0).statue) + " collapsed at " +
                             plinth::host::number_text(grid.at(i)) +
                             " g; here its truth stood (another --truth-step?)");
          }
          if (!r) continue;  // --collapses-only: the truth stood
          job.push_back(std::move(*r));
          if (job.back().collapsed && !opt.all_scales) break;
        }
        results[index] = std::move(job);
      },
      [&](std::size_t index) {
        const plinth::sim::EvalCase c = case_of(index, 0.0);
        return c.record_name + ", " + c.scene_name + ", statue " + std::to_string(c.statue);
      });
  progress.finish();
  if (!finished) {
    std::fprintf(stderr, "plinth-eval: stopped; nothing written\n");
    return kInterruptedExit;
  }
  write_runs(opt.out_path, grids, results);
  if (!opt.motion_path.empty()) write_motion(opt.motion_path, results);
  std::size_t runs = 0;
  std::size_t outside_model = 0;
  for (const auto& job : results) {
    runs += job.size();
    for (const EvalRun& r : job) outside_model += r.outside_model() ? 1U : 0U;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("plinth-eval: %zu runs of %zu cases (shard %d/%d), %d jobs, wall time %.1f s -> %s\n",
              runs, indices.size(), run.shard_index, run.shard_count, run.jobs, wall,
              opt.out_path.c_str());
  if (outside_model > 0) {
    std::printf("plinth-eval: %zu runs left the model (the true statue lifted off; their "
                "model_valid_until_s says when): no truth, counted in no outcome\n",
                outside_model);
  }
  return 0;
}

// `text` into `path` through path.tmp.
void write_text(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  std::FILE* out = std::fopen(temporary.c_str(), "w");
  if (out == nullptr) throw InputError(path + ": cannot write (does its folder exist?)");
  std::fputs(text.c_str(), out);
  const bool ok = std::fclose(out) == 0;
  std::error_code ec;
  if (ok) std::filesystem::rename(temporary, path, ec);
  if (!ok || ec) throw InputError(path + ": cannot write");
}

// A runs file of collapses alone (run --collapses-only) cannot be scored by `what`.
void refuse_collapses_only(const EvalTable& table, const std::string& path, const char* what) {
  if (table.collapses_only) {
    throw InputError(path + ": holds only the runs whose truth collapsed (plinth-eval run "
                     "--collapses-only), and " + what + "; fault-report reads it");
  }
}

int run_report(const ReportOptions& opt) {
  plinth::sim::CalibrationTargets targets;
  if (!plinth::host::parse_false_alarm(opt.false_alarm, targets.false_alarm)) {
    throw InputError("--false-alarm: expected margin or peak, got '" + opt.false_alarm + "'");
  }
  const EvalTable table = plinth::host::read_eval_csv(opt.runs_path);
  if (table.runs.empty()) throw InputError(opt.runs_path + ": no runs");
  refuse_collapses_only(table, opt.runs_path, "report scores the runs that stood too");
  plinth::sim::require_margins(table, targets, opt.runs_path);
  EvalTable calibration;
  if (!opt.calibration_path.empty()) {
    calibration = plinth::host::read_eval_csv(opt.calibration_path);
    if (calibration.runs.empty()) throw InputError(opt.calibration_path + ": no runs");
    refuse_collapses_only(calibration, opt.calibration_path, "a calibration needs every run");
    plinth::sim::require_margins(calibration, targets, opt.calibration_path + " (--calibrate-on)");
  }
  const plinth::sim::Report report = plinth::sim::make_report(
      table, targets, opt.frontier, opt.calibration_path.empty() ? nullptr : &calibration);
  std::fputs(plinth::sim::report_text(report, table.grids).c_str(), stdout);
  if (!table.grids.pwave.empty() || !opt.pwave_calibrate_on.empty()) {
    std::optional<EvalTable> other;
    if (!opt.pwave_calibrate_on.empty()) other = plinth::host::read_eval_csv(opt.pwave_calibrate_on);
    std::fputs(plinth::sim::pwave_report_text(
                   plinth::sim::make_pwave_report(table, other ? &*other : nullptr))
                   .c_str(),
               stdout);
  }
  if (table.grids.regional || !opt.regional_calibrate_on.empty()) {
    std::optional<EvalTable> other;
    if (!opt.regional_calibrate_on.empty()) {
      other = plinth::host::read_eval_csv(opt.regional_calibrate_on);
    }
    std::fputs(plinth::sim::regional_report_text(
                   plinth::sim::make_regional_report(table, other ? &*other : nullptr))
                   .c_str(),
               stdout);
  }
  if (!opt.json_path.empty()) {
    write_text(opt.json_path, plinth::sim::report_json(report, table.grids));
  }
  if (!opt.plot_path.empty()) plinth::sim::plot_roc(table, opt.plot_path);
  return 0;
}

int run_fragility(const FragilityOptions& opt) {
  plinth::sim::CollapseIntensityRule rule{};
  if (!plinth::sim::parse_collapse_intensity(opt.collapse_intensity, rule)) {
    throw InputError("--collapse-intensity: expected interval or grid, got '" +
                     opt.collapse_intensity + "'");
  }
  const EvalTable table = plinth::host::read_eval_csv(opt.runs_path);
  if (table.runs.empty()) throw InputError(opt.runs_path + ": no runs");
  refuse_collapses_only(table, opt.runs_path, "a fragility needs the runs that stood");
  const std::vector<plinth::sim::SceneFragility> scenes =
      plinth::sim::scene_fragilities(table, opt.runs_path, rule);
  std::fputs(plinth::sim::fragility_text(scenes, rule).c_str(), stdout);
  if (!opt.json_path.empty()) write_text(opt.json_path, plinth::sim::fragility_json(scenes, rule));
  if (!opt.plot_path.empty()) plinth::sim::plot_fragility(scenes, opt.plot_path);
  return 0;
}

// Shards of one run share its fault, and a file of collapses alone holds a run once.
void refuse_other_faults(const std::vector<EvalRun>& runs, const std::vector<std::string>& inputs) {
  std::set<std::string> seen;
  for (const EvalRun& r : runs) {
    if (!r.faults) return;
    const EvalRun::Faults& f = *r.faults;
    const EvalRun::Faults& first = *runs.front().faults;
    if (f.fault != first.fault || f.param != first.param || f.at != first.at) {
      throw InputError("merge: " + r.record + ", " + r.scene + ", statue " +
                       std::to_string(r.statue) + ": fault " + f.fault + " (" + f.param + ", " +
                       f.at + "), where the first run has " + first.fault + " (" + first.param +
                       ", " + first.at + "): the inputs are not shards of one run");
    }
    if (f.collapses_only) {
      const std::string key = r.record + "|" + r.scene + "|" + std::to_string(r.statue) + "|" +
                              std::to_string(r.seed) + "|" + plinth::host::number_text(r.scale_g);
      if (!seen.insert(key).second) {
        throw InputError("merge (a run in two inputs?): " + r.record + ", " + r.scene +
                         ", statue " + std::to_string(r.statue) + " at " +
                         plinth::host::number_text(r.scale_g) + " g twice among " +
                         std::to_string(inputs.size()) + " inputs");
      }
    }
  }
}

int run_fault_report(const FaultReportOptions& opt) {
  std::optional<EvalTable> against;
  if (!opt.against_path.empty()) against = plinth::host::read_eval_csv(opt.against_path);
  std::vector<plinth::sim::FaultClassReport> reports;
  for (const std::string& path : opt.runs_paths) {
    reports.push_back(plinth::sim::make_fault_report(plinth::host::read_eval_csv(path), path,
                                                     against ? &*against : nullptr,
                                                     opt.against_path));
  }
  std::fputs(plinth::sim::fault_report_text(reports, opt.against_path, opt.list_silenced).c_str(),
             stdout);
  if (!opt.json_path.empty()) {
    write_text(opt.json_path, plinth::sim::fault_report_json(reports, opt.against_path));
  }
  return 0;
}

int run_merge(const MergeOptions& opt) {
  EvalTable merged;
  for (std::size_t i = 0; i < opt.inputs.size(); ++i) {
    EvalTable part = plinth::host::read_eval_csv(opt.inputs[i]);
    if (i == 0) {
      merged.grids = part.grids;
      merged.has_grid = part.has_grid;
      merged.has_faults = part.has_faults;
      merged.collapses_only = part.collapses_only;
    } else if (part.has_faults != merged.has_faults) {
      throw InputError(opt.inputs[i] + ": " + (part.has_faults ? "has" : "has no") +
                       " fault columns, " + opt.inputs[0] + " " +
                       (part.has_faults ? "has none" : "has them") +
                       " (a plinth-eval before fault injection wrote one of them)");
    } else if (part.collapses_only != merged.collapses_only) {
      throw InputError(opt.inputs[i] + ": " +
                       (part.collapses_only ? "collapses only" : "every run") + ", " +
                       opt.inputs[0] + " " +
                       (merged.collapses_only ? "collapses only" : "every run") +
                       " (run --collapses-only wrote one of them)");
    } else if (part.grids.risk != merged.grids.risk ||
               part.grids.probability != merged.grids.probability ||
               part.grids.pwave != merged.grids.pwave ||
               part.grids.regional != merged.grids.regional) {
      throw InputError(opt.inputs[i] + ": its threshold columns differ from " + opt.inputs[0] +
                       "'s (another plinth-eval version)");
    } else if (part.has_grid != merged.has_grid) {
      throw InputError(opt.inputs[i] + ": " + (part.has_grid ? "has" : "has no") +
                       " seed and pga grid columns, " + opt.inputs[0] + " " +
                       (part.has_grid ? "has none" : "has them") +
                       " (a plinth-eval before the collapse margin wrote one of them)");
    }
    for (EvalRun& r : part.runs) merged.runs.push_back(std::move(r));
  }
  // A case in two inputs (shards of one run never share one) would not be one case.
  if (merged.has_grid && !merged.collapses_only) {
    (void)plinth::host::eval_cases(merged.runs, "merge (a case in two inputs?)");
  }
  refuse_other_faults(merged.runs, opt.inputs);
  write_runs(opt.out_path, merged.grids, {merged.runs}, merged.has_grid, merged.has_faults);
  std::printf("plinth-eval merge: %zu runs from %zu files -> %s\n", merged.runs.size(),
              opt.inputs.size(), opt.out_path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  using plinth::host::kFinitePositive;
  CLI::App app{"plinth-eval: the box's warning measured against the solver's truth (docs/forecast.md)"};
  app.require_subcommand(1);
  RunOptions opt;
  CLI::App* run = app.add_subcommand("run", "run the cases and write one row per run");
  run->add_option("--scene", opt.scene_paths, "scene files with their [uncertainty] (repeat)")
      ->required();
  run->add_option("--record", opt.record_paths, "records: AT2, ESM or CSV (repeat)")->required();
  run->add_option("--vertical", opt.vertical_paths,
                  "their vertical components, the i-th for the i-th --record (repeat)");
  run->add_option("--pwave", opt.pwave,
                  "on: the P-wave stage beside the box, its crossings in the runs file (needs "
                  "the scenes' [fragility]; default off)");
  run->add_option("--regional", opt.regional,
                  "on: a simulated regional alert per run (latency and intensity error of "
                  "published early-warning performance, docs/regional.md), its columns in the "
                  "runs file (needs --record-info and the scenes' [fragility]; default off)");
  run->add_option("--record-info", opt.record_info_path,
                  "CSV of each record's source by RSN (rsn,earthquake,station,magnitude,rrup_km,"
                  "rjb_km,rhyp_km,vs30_m_s: tools/pwave-stations.py)");
  run->add_option("--regional-latency", opt.regional_model.latency_median_s,
                  "the alert's median time after the origin, s (default 6.9: ShakeAlert, "
                  "Ridgecrest 2019)");
  run->add_option("--regional-latency-sd", opt.regional_model.latency_sd_s,
                  "its standard deviation, s (default 2, an assumption)");
  run->add_option("--regional-bias", opt.regional_model.error_bias_ln,
                  "mean of ln(predicted / true PGA) (default 0)");
  run->add_option("--regional-sigma", opt.regional_model.error_sigma_ln,
                  "standard deviation of ln(predicted / true PGA) (default ln 2: Minson et al. "
                  "2019); the alert declares the same");
  run->add_option("--out", opt.out_path, "runs CSV")->required();
  run->add_option("--pga-from", opt.pga_from, "smallest PGA of the grid (default 0.2g)");
  run->add_option("--pga-to", opt.pga_to, "largest PGA of the grid (default 2.5g)");
  run->add_option("--pga-steps", opt.pga_steps, "PGA grid points (default 12)");
  run->add_option("--statues", opt.statues, "true statues per scene (default 20)");
  run->add_option("--seed", opt.seed, "seed of the statues' draw (default 2026)");
  run->add_flag("--all-scales", opt.all_scales, "go on past a case's first collapse");
  run->add_option("--rate", opt.rate_hz, "the box's sample rate, Hz (default 200)")
      ->check(kFinitePositive);
  run->add_option("--steps", opt.steps_per_sample, "the box's solver steps per sample (default 4)");
  run->add_flag("--box-knows-statue", opt.box_knows_statue,
                "give the box the true statue, not the scene file: what knowing it would buy");
  run->add_option("--motion-out", opt.motion_path,
                  "also write, per run, when the true statue first left full contact and when "
                  "each level was first shown (CSV)");
  run->add_flag("--statue-sensor", opt.statue_sensor,
                "give the box a gyroscope on the statue (a BMI088's noise, offset and delay, "
                "simulated from the truth: docs/forecast.md)");
  run->add_option("--forecast", opt.forecast,
                  "strongest_window, recent_window or off (default the box's, " + opt.forecast +
                      ")");
  run->add_option("--horizon", opt.horizon_s, "forecast horizon, s (default 4)")
      ->check(kFinitePositive);
  run->add_option("--raise-hold", opt.raise_hold_s,
                  "the box's alarm_policy.raise_hold_s, s (default the box's, " +
                      plinth::host::number_text(opt.raise_hold_s) + ")")
      ->check(CLI::Range(0.0, 10.0));
  run->add_option("--truth-step", opt.truth_step_s, "the truth's solver step, s (default 5e-4)")
      ->check(kFinitePositive);
  run->add_option("--fault", opt.fault,
                  "one fault injected into the box's inputs, KIND[:PARAM] (docs/safety.md, "
                  "\"Fault injection\"): " +
                      std::string(plinth::joined_names<plinth::sim::kFaultKindNames>("").data()));
  run->add_option("--fault-at", opt.fault_at,
                  "when the fault begins: start (default), a time in s from the record's start, "
                  "or strong, motion or alarm (the record's strong motion, the true statue's "
                  "first motion, the box's first alarm), each with an optional +S (or -S)");
  run->add_flag("--collapses-only", opt.collapses_only,
                "run the box only where the truth collapses and write those runs alone (what "
                "fault-report needs; report refuses such a file)");
  run->add_option("--collapses-of", opt.collapses_of,
                  "run only the runs that collapsed in this runs file of the same cases (its "
                  "truth: no other scale is simulated); implies --collapses-only");
  run->add_option("--jobs", opt.jobs, "threads (default: the hardware's)");
  run->add_option("--shard", opt.shard, "run only part i of N of the cases, as i/N");
  ReportOptions report;
  CLI::App* report_command = app.add_subcommand("report", "levels, ROC and calibration of a runs CSV");
  report_command->add_option("runs", report.runs_path, "a plinth-eval runs CSV")->required();
  report_command->add_option("--json", report.json_path, "also write the report as JSON");
  report_command->add_option("--plot", report.plot_path, "also draw the ROC as a PNG");
  report_command->add_option("--pwave-calibrate-on", report.pwave_calibrate_on,
                             "choose the P-wave stage's threshold on this runs file (default: "
                             "on the one reported)");
  report_command->add_option("--regional-calibrate-on", report.regional_calibrate_on,
                             "choose the regional alerts' threshold on this runs file (default: "
                             "on the one reported)");
  report_command->add_flag("--frontier", report.frontier,
                           "also the rule with the fewest false alarms under each of the alarm's "
                           "targets, on the worst member's and on the nominal statue's risk");
  report_command->add_option("--calibrate-on", report.calibration_path,
                             "also choose each level's rule on this other runs CSV and report it "
                             "on these runs");
  report_command->add_option("--false-alarm", report.false_alarm,
                             "what calibration and frontier count as false: margin (alarms in runs "
                             "whose collapse margin is >= 2) or peak (in runs below half the "
                             "overturning angle); default margin");
  FragilityOptions fragility;
  CLI::App* fragility_command = app.add_subcommand(
      "fragility", "per scene, the lognormal fragility P(collapse | PGA) of a runs CSV's statues");
  fragility_command->add_option("runs", fragility.runs_path, "a plinth-eval runs CSV")->required();
  fragility_command->add_option("--json", fragility.json_path, "also write the fits as JSON");
  fragility_command->add_option("--plot", fragility.plot_path,
                                "also draw the curves and the empirical points as a PNG");
  fragility_command->add_option("--collapse-intensity", fragility.collapse_intensity,
                                "interval (between the grid point below the lowest collapsing PGA "
                                "and it; default) or grid (the lowest collapsing PGA itself)");
  FaultReportOptions fault_report;
  CLI::App* fault_report_command = app.add_subcommand(
      "fault-report", "per fault class (run --fault), its silenced collapses and lost lead");
  fault_report_command->add_option("runs", fault_report.runs_paths,
                                   "runs CSVs, one fault class each")->required();
  fault_report_command->add_option("--against", fault_report.against_path,
                                   "the runs CSV of the box to measure the lead against (the same "
                                   "cases, e.g. without the fault or without the statue sensor)");
  fault_report_command->add_option("--json", fault_report.json_path,
                                   "also write the report as JSON");
  fault_report_command->add_option("--list", fault_report.list_silenced,
                                   "silenced collapses listed per class (default 10)")
      ->check(CLI::Range(0, 1000000));
  MergeOptions merge;
  CLI::App* merge_command = app.add_subcommand("merge", "join the runs CSVs of shards");
  merge_command->add_option("--out", merge.out_path, "merged CSV")->required();
  merge_command->add_option("inputs", merge.inputs, "the shards' CSV files")->required();
  const plinth::sim::Subcommand pwave_fit = plinth::sim::add_pwave_fit(app);
  const auto checks = [&] {
    plinth::host::refuse_without_effect(*run, {"--horizon"}, opt.forecast != "off",
                                        "sets the forecast's horizon, and --forecast is off");
    plinth::host::refuse_without_effect(
        *run,
        {"--record-info", "--regional-latency", "--regional-latency-sd", "--regional-bias",
         "--regional-sigma"},
        opt.regional != "off", "sets the simulated regional alerts, and --regional is off");
    plinth::host::refuse_without_effect(*run, {"--fault-at"}, opt.fault != "none",
                                        "says when the fault begins, and no --fault is given");
  };
  if (const std::optional<int> exit_code =
          plinth::host::parse_command_line(app, argc, argv, checks)) {
    return *exit_code;
  }
  return plinth::host::run_tool("plinth-eval", [&] {
    if (report_command->parsed()) return run_report(report);
    if (fragility_command->parsed()) return run_fragility(fragility);
    if (merge_command->parsed()) return run_merge(merge);
    if (fault_report_command->parsed()) return run_fault_report(fault_report);
    if (pwave_fit.command->parsed()) return pwave_fit.run();
    return run_eval(opt);
  });
}
