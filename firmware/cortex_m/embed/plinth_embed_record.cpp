// plinth-embed-record: a record replay (scenes, records, scale, rate) as a C++ source for the
// microcontroller image (firmware/cortex_m, docs/microcontroller.md). It takes plinth-monitor's
// replay options and reads the files the same way (record_input.h), so that the image replays
// exactly the samples plinth-monitor --replay feeds its loop: every double is written bit for
// bit (hex floats), the scenes field by field (scene_source), converted to the image's Real.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "plinth/firmware/monitor.h"
#include "plinth/firmware/record_replay.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/scene_toml.h"
#include "record_input.h"

namespace {

using plinth::host::InputError;
namespace fw = plinth::firmware;

static_assert(std::is_trivially_copyable_v<plinth::SceneParams>);

struct Options {
  std::string name;
  std::string scene_path;
  std::string scene_y_path;
  fw::RecordReplayOptions input;
  std::optional<int> steps;
  bool no_forecast = false;
  bool statue_sensor = false;
  std::string out_path;
};

std::string hex_double(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%a", value);
  return text;
}

// A C++ string literal of `text` (quotes and backslashes escaped).
std::string literal(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// A SceneParams constant, field by field: each number a double written bit for bit (hex float)
// and converted to the image's Real (plinth/core/real.h), as the host converts a scene file's
// numbers, so a float image gets the nearest floats and a double image the host's bits.
// kSceneParamsBytes: a field added to SceneParams stops this build until it is written here.
constexpr std::size_t kSceneParamsBytes = 160;
static_assert(sizeof(plinth::SceneParams) == kSceneParamsBytes,
              "SceneParams changed: write its new fields in scene_source");

std::string real(double value) { return "Real(" + hex_double(value) + ")"; }
const char* boolean(bool value) { return value ? "true" : "false"; }

std::string scene_source(const plinth::SceneParams& p) {
  std::ostringstream out;
  out << "SceneParams{\n        .gravity = " << real(p.gravity) << ",\n"
      << "        .block = {.half_width = " << real(p.block.half_width)
      << ", .com_height = " << real(p.block.com_height)
      << ", .eccentricity = " << real(p.block.eccentricity) << ", .mass = " << real(p.block.mass)
      << ", .inertia = " << real(p.block.inertia) << "},\n"
      << "        .has_base = " << boolean(p.has_base) << ",\n"
      << "        .base = {.mass = " << real(p.base.mass) << ", .period = " << real(p.base.period)
      << ", .damping_ratio = " << real(p.base.damping_ratio) << "},\n"
      << "        .has_friction = " << boolean(p.has_friction) << ",\n"
      << "        .friction = {.static_coefficient = " << real(p.friction.static_coefficient)
      << ", .kinetic_coefficient = " << real(p.friction.kinetic_coefficient) << "},\n"
      << "        .has_base_stops = " << boolean(p.has_base_stops) << ",\n"
      << "        .base_stops = {.max_displacement = " << real(p.base_stops.max_displacement)
      << ", .restitution = " << real(p.base_stops.restitution) << "},\n"
      << "        .has_support = " << boolean(p.has_support) << ",\n"
      << "        .support = {.clearance = " << real(p.support.clearance) << "},\n"
      << "        .has_sliding_stops = " << boolean(p.has_sliding_stops) << ",\n"
      << "        .sliding_stops = {.restitution = " << real(p.sliding_stops.restitution) << "}}";
  return out.str();
}

// The statues of one axis as an array of SceneParams, the nominal one first.
void write_members(std::ostream& out, const char* name, const std::vector<plinth::Scene>& members) {
  out << "const SceneParams " << name << "[" << members.size() << "] = {";
  for (const plinth::Scene& member : members) out << "\n    " << scene_source(member.params) << ",";
  out << "\n};\n";
}

// `values` as an array in the RECORD region (the linker script), 4 to a line.
void write_array(std::ostream& out, const char* name, const std::vector<double>& values) {
  out << "__attribute__((section(\".record\"))) const double " << name << "[" << values.size()
      << "] = {";
  for (std::size_t i = 0; i < values.size(); ++i) {
    out << (i % 4 == 0 ? "\n    " : " ") << hex_double(values[i]) << ",";
  }
  out << "\n};\n";
}

// A number as plinth-monitor's options take it, exactly (17 significant digits).
std::string exact(double value) {
  char text[40];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// The options of plinth-monitor that replay the same case.
std::string monitor_command(const Options& opt) {
  std::ostringstream out;
  out << "--scene " << opt.scene_path;
  if (!opt.scene_y_path.empty()) out << " --scene-y " << opt.scene_y_path;
  out << " --replay " << opt.input.path;
  if (!opt.input.y_path.empty()) out << " --replay-y " << opt.input.y_path;
  if (!opt.input.vertical_path.empty()) out << " --vertical " << opt.input.vertical_path;
  if (!opt.input.pga.empty()) out << " --pga " << opt.input.pga;
  if (opt.input.scale) out << " --scale " << exact(*opt.input.scale);
  if (opt.input.rate_hz) out << " --rate " << exact(*opt.input.rate_hz);
  if (opt.steps) out << " --steps " << *opt.steps;
  if (opt.no_forecast) out << " --no-forecast";
  return out.str();
}

int run(const Options& opt) {
  // Each axis's ensemble as plinth-monitor builds it: the scene file's [uncertainty] design.
  const plinth::host::UncertainScene scene_x =
      plinth::host::load_uncertain_scene_file(opt.scene_path);
  std::optional<plinth::host::UncertainScene> scene_y;
  if (!opt.scene_y_path.empty()) {
    scene_y = plinth::host::load_uncertain_scene_file(opt.scene_y_path);
  }
  if (!opt.input.y_path.empty() && !scene_y) {
    throw InputError("--replay-y needs a second axis: --scene-y");
  }
  const double gravity = plinth::kStandardGravity;
  const fw::RecordSamples record = fw::record_samples(opt.input, gravity);
  // The image starts the box with these settings: refuse here what it would refuse there.
  fw::MonitorConfig config = fw::box_defaults();
  config.axis_count = scene_y ? 2 : 1;
  if (opt.steps) config.estimator.steps_per_sample = *opt.steps;
  if (opt.no_forecast) config.forecast.enabled = false;
  fw::configure_record_replay(config, record.rate_hz);
  if (opt.statue_sensor) fw::configure_replay_statue_sensor(config);
  const auto monitor = std::make_unique<fw::Monitor>();
  if (const plinth::Error e = monitor->start(
          config, {std::span<const plinth::Scene>(scene_x.members),
                   scene_y ? std::span<const plinth::Scene>(scene_y->members)
                           : std::span<const plinth::Scene>()});
      !e.ok()) {
    throw InputError(std::string("monitor settings: ") + e.field + " " + e.reason);
  }

  std::vector<double> x, y, z;
  bool any_y = false, any_vertical = false;
  for (const Eigen::Vector3d& a : record.samples) {
    x.push_back(a.x());
    y.push_back(a.y());
    z.push_back(a.z());
    any_y = any_y || a.y() != 0.0;
    any_vertical = any_vertical || a.z() != gravity;
  }
  std::ostringstream source;
  source << "// Generated by plinth-embed-record: do not edit.\n"
         << "// plinth-monitor " << monitor_command(opt) << "\n"
         << "#include \"plinth/firmware/replay_case.h\"\n\n"
         << "namespace plinth::firmware {\nnamespace {\n\n";
  write_members(source, "kMembersX", scene_x.members);
  if (scene_y) write_members(source, "kMembersY", scene_y->members);
  write_array(source, "kX", x);
  if (any_y) write_array(source, "kY", y);
  if (any_vertical) write_array(source, "kZ", z);
  source << "\n}  // namespace\n\n"
         << "const ReplayCase kReplayCase{\n"
         << "    .name = " << literal(opt.name) << ",\n"
         << "    .command = " << literal(monitor_command(opt)) << ",\n"
         << "    .x = kMembersX,\n"
         << "    .y = " << (scene_y ? "kMembersY" : "{}") << ",\n"
         << "    .steps_per_sample = " << (opt.steps ? *opt.steps : 0) << ",\n"
         << "    .forecast = " << boolean(!opt.no_forecast) << ",\n"
         << "    .statue_sensor = " << boolean(opt.statue_sensor) << ",\n"
         << "    .record = {.description = " << literal(opt.input.path) << ",\n"
         << "               .sample_rate_hz = " << hex_double(record.rate_hz) << ",\n"
         << "               .count = " << record.samples.size() << ",\n"
         << "               .x = kX,\n"
         << "               .y = " << (any_y ? "kY" : "nullptr") << ",\n"
         << "               .z = " << (any_vertical ? "kZ" : "nullptr") << "},\n"
         << "};\n\n}  // namespace plinth::firmware\n";
  std::ofstream out(opt.out_path);
  out << source.str();
  if (!out.flush()) throw InputError(opt.out_path + ": cannot write");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "plinth-embed-record: a record replay as a C++ source for the microcontroller image"};
  Options opt;
  app.add_option("--name", opt.name, "the case's name, printed by the image")->required();
  app.add_option("--scene", opt.scene_path, "scene file (TOML), the statue's first axis")
      ->required();
  app.add_option("--scene-y", opt.scene_y_path, "scene of the second axis");
  app.add_option("--replay", opt.input.path, "record (.AT2, .csv) of axis x")->required();
  app.add_option("--replay-y", opt.input.y_path, "second horizontal record (axis y)");
  app.add_option("--vertical", opt.input.vertical_path, "vertical record");
  app.add_option("--pga", opt.input.pga, "scale the record to this PGA, e.g. 0.3g");
  app.add_option("--scale", opt.input.scale, "scale factor of the record")
      ->check(plinth::host::kFinite)
      ->excludes("--pga");
  app.add_option("--rate", opt.input.rate_hz, "sensor rate, Hz (default: the record's, or 200)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--steps", opt.steps, "solver steps per sample (default 4)")
      ->check(CLI::Range(1, 64));
  app.add_flag("--no-forecast", opt.no_forecast,
               "the box without the forecast (in a build that has it), as plinth-monitor's");
  app.add_flag("--statue-sensor", opt.statue_sensor,
               "the image feeds a statue sensor the nominal statue's rotation (its update's "
               "load; no plinth-monitor replay compares with it)");
  app.add_option("--out", opt.out_path, "the C++ source to write")->required();
  if (const std::optional<int> exit_code = plinth::host::parse_command_line(app, argc, argv)) {
    return *exit_code;
  }
  try {
    return run(opt);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "plinth-embed-record: %s\n", error.what());
    return 1;
  }
}
