// plinth-sweep: for each value of one scene parameter, the smallest PGA at which each kind of
// event first occurs under a record. Writes a CSV map (--out) and a one-line summary.
#include "cli_validators.h"
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "plinth/host/input_error.h"
#include "plinth/host/record_io.h"
#include "plinth/host/scene_toml.h"
#include "plinth/host/sweep.h"
#include "plinth/host/units.h"

namespace {

using plinth::host::InputError;

struct Options {
  std::string scene_path;
  std::string record_path;
  std::string param;
  double from = 0.0;
  double to = 0.0;
  int steps = 0;
  std::string pga_max = "2g";
  std::string tol = "0.001g";
  std::optional<int> jobs;
  std::string shard = "1/1";
  double dt = 5e-4;
  std::string out_path;
};

// "i/N" with 1 <= i <= N.
void parse_shard(const std::string& text, int& index, int& count) {
  const auto fail = [&] {
    return InputError("--shard: expected i/N with 1 <= i <= N, got '" + text + "'");
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) throw fail();
  const std::string a = text.substr(0, slash);
  const std::string b = text.substr(slash + 1);
  const auto digits = [](const std::string& s) {
    return !s.empty() && s.size() <= 6 &&
           s.find_first_not_of("0123456789") == std::string::npos;
  };
  if (!digits(a) || !digits(b)) throw fail();
  index = std::stoi(a);
  count = std::stoi(b);
  if (count < 1 || index < 1 || index > count) throw fail();
}

int run(const Options& opt) {
  // Cheap checks first, so a usage slip does not wait for files to load.
  const plinth::host::SweepParameter parameter = plinth::host::parse_sweep_parameter(opt.param);
  const std::vector<double> values = plinth::host::sweep_values(opt.from, opt.to, opt.steps);
  int shard_index = 1;
  int shard_count = 1;
  parse_shard(opt.shard, shard_index, shard_count);

  const plinth::Scene scene = plinth::host::load_scene_file(opt.scene_path);
  const double g = scene.g;
  const plinth::host::Record record = plinth::host::read_record(opt.record_path, g);

  plinth::host::SweepSettings settings;
  settings.pga_max_g = plinth::host::parse_acceleration(opt.pga_max, g, "--pga-max") / g;
  settings.tolerance_g = plinth::host::parse_acceleration(opt.tol, g, "--tol") / g;
  settings.dt = opt.dt;
  plinth::host::validate(settings);
  const int jobs =
      opt.jobs ? *opt.jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));

  std::ofstream out(opt.out_path);
  if (!out) throw InputError(opt.out_path + ": cannot open the sweep map for writing");

  const auto start = std::chrono::steady_clock::now();
  plinth::host::SweepStats stats;
  const std::vector<plinth::host::SweepRow> rows =
      plinth::host::run_sweep(scene.params, parameter, values, record, settings, jobs,
                              shard_index, shard_count, &stats);
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  plinth::host::write_sweep_csv(out, parameter, rows);
  out.close();
  if (!out) throw InputError(opt.out_path + ": cannot write the sweep map");

  std::printf("plinth-sweep: %zu rows of %s (shard %d/%d of %zu values), %zu simulations, "
              "%d jobs, wall time %.2f s -> %s\n",
              rows.size(), opt.param.c_str(), shard_index, shard_count, values.size(),
              stats.simulations, jobs, wall, opt.out_path.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plinth-sweep: for each value of one scene parameter, the smallest PGA at which "
               "each event first occurs under a record"};
  Options opt;
  app.add_option("--scene", opt.scene_path, "scene file (TOML)")->required();
  app.add_option("--record", opt.record_path, "horizontal record (.AT2 or .csv)")->required();
  app.add_option("--param", opt.param,
                 "parameter to sweep: mu_s, epsilon, lambda, T, xi, u_max or mass_ratio")
      ->required();
  app.add_option("--from", opt.from, "first value of the parameter")->required()->check(plinth::cli::kFinite);
  app.add_option("--to", opt.to, "last value of the parameter")->required()->check(plinth::cli::kFinite);
  app.add_option("--steps", opt.steps, "number of values, from..to inclusive")->required();
  app.add_option("--pga-max", opt.pga_max, "largest PGA scanned, e.g. 2g (default 2g)");
  app.add_option("--tol", opt.tol, "PGA tolerance of the thresholds, e.g. 0.001g (default)");
  app.add_option("--jobs", opt.jobs, "threads (default: the hardware's)");
  app.add_option("--shard", opt.shard, "run only part i of N of the values, as i/N (default 1/1)");
  app.add_option("--dt", opt.dt, "solver step, s (default 5e-4)")->check(plinth::cli::kFinitePositive);
  app.add_option("--out", opt.out_path, "CSV map of the thresholds")->required();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end here with 0; every usage error exits with 2.
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (opt.jobs && *opt.jobs < 1) {
    std::fprintf(stderr, "plinth-sweep: --jobs: must be at least 1, got %d\n", *opt.jobs);
    return 2;
  }
  try {
    return run(opt);
  } catch (const InputError& e) {
    std::fprintf(stderr, "plinth-sweep: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "plinth-sweep: error: %s\n", e.what());
    return 1;
  }
}
