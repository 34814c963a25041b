// plinth-monitor: the box's application on Linux. Sensor samples from a file replay (AT2, CSV
// or a candump log) or a SocketCAN bus (inputs.h); the firmware loop (firmware/monitor)
// estimates the block's phase and overturning risk, raises alarms and hands over the frames to
// send. JSON Lines on stdout (status_json.h, docs/monitor.md): status lines when the monitor
// reports a status, alarm lines, phase events, and a summary at the end. Live, the monitor's
// status and alarm frames also go on the bus.
#include <CLI/CLI.hpp>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "event_recorder.h"
#include "inputs.h"
#include "monitor_config.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/scene_toml.h"
#include "status_json.h"

namespace {

using plinth::host::InputError;
namespace fw = plinth::firmware;
namespace mon = plinth::monitor;

volatile std::sig_atomic_t g_stop = 0;
// Exit code of a replay that ends in an input fault (input_fault below).
constexpr int kInputFaultExit = 3;
extern "C" void on_signal(int) { g_stop = 1; }

struct Options {
  std::string scene_path;
  std::string replay_path;
  std::string replay_y_path;
  std::string vertical_path;
  std::string can_interface;
  std::string pga;
  std::optional<double> scale;
  std::string speed = "max";
  double duration = 0.0;
  std::string record_dir;
  double pre_trigger = 30.0;
  double post_trigger = 60.0;
  bool quiet_events = false;
  fw::MonitorOverrides config;  // --config and the options that override it
};

// --speed: a positive factor of real time, or "max" (0).
double parse_speed(const std::string& text) {
  if (text == "max") return 0.0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(v >= plinth::host::kMinReplaySpeed) ||
      !(v <= plinth::host::kMaxReplaySpeed)) {
    throw InputError("--speed: expected a factor of real time from " +
                     plinth::host::number_text(plinth::host::kMinReplaySpeed) + " to " +
                     plinth::host::number_text(plinth::host::kMaxReplaySpeed) +
                     ", or 'max', got '" + text + "'");
  }
  return v;
}

void print_line(const std::string& line) {
  std::fputs(line.c_str(), stdout);
  std::fputc('\n', stdout);
}

// Phase events of one axis as JSON lines, with monitor times.
class AxisEvents final : public plinth::EventSink {
 public:
  AxisEvents(int axis, const fw::Monitor& monitor, double t_origin, bool print)
      : axis_(axis), monitor_(monitor), t_origin_(t_origin), print_(print) {}
  void on_event(const plinth::Event& e) override {
    ++count;
    if (!print_) return;
    plinth::Event shifted = e;
    shifted.t = e.t + static_cast<double>(monitor_.status().estimator_start_ns) * 1e-9 - t_origin_;
    print_line(fw::event_json(axis_, shifted));
  }
  std::uint64_t count = 0;

 private:
  int axis_;
  const fw::Monitor& monitor_;
  double t_origin_;
  bool print_;
};

// What follows each update: its frames on the bus (live), alarm lines, recorder triggers,
// the status line when the monitor reports a status; and the run's totals.
class Outputs {
 public:
  Outputs(const fw::Monitor& monitor, double t_origin, fw::EventRecorder* recorder,
          plinth::hal::FrameSink* bus)
      : monitor_(monitor), t_origin_(t_origin), recorder_(recorder), bus_(bus) {}

  void handle(const fw::MonitorUpdate& u) {
    const fw::MonitorStatus& s = monitor_.status();
    totals.max_risk = std::fmax(totals.max_risk, s.risk);
    for (std::size_t i = 0; i < u.frame_count; ++i) {
      if (bus_ != nullptr && bus_->send(u.frames[i]) != plinth::hal::IoStatus::kOk) {
        ++totals.bus_send_errors;
      }
    }
    for (std::size_t i = 0; i < u.event_count; ++i) {
      const mon::AlarmEventRecord& e = u.events[i];
      print_line(fw::alarm_json(e, t_origin_));
      ++totals.alarm_events;
      if (e.level == mon::AlarmLevel::kFault) {
        ++totals.fault_events;
      } else if (static_cast<int>(e.level) > static_cast<int>(totals.max_level)) {
        totals.max_level = e.level;
      }
      if (e.level == mon::AlarmLevel::kWarning || e.level == mon::AlarmLevel::kAlarm) trigger(e);
    }
    if (u.status_due) print_line(fw::status_json(s, t_origin_));
  }

  fw::RunTotals totals;
  std::int64_t last_frame_ns = 0;  // receive time of the newest frame (the recorder's clock)

 private:
  void trigger(const mon::AlarmEventRecord& e) {
    if (recorder_ == nullptr) return;
    const fw::MonitorStatus& s = monitor_.status();
    fw::TriggerInfo info;
    info.t = static_cast<double>(e.time_ns) * 1e-9 - t_origin_;
    info.level = mon::alarm_level_name(e.level);
    info.cause = mon::alarm_cause_name(e.cause);
    char detail[96];
    std::snprintf(detail, sizeof detail, "\"risk\": %.4f, \"phase\": \"%s\"", s.risk,
                  plinth::phase_name(s.axes[0].mode.phase));
    info.detail = detail;
    recorder_->trigger(info, last_frame_ns);
  }

  const fw::Monitor& monitor_;
  double t_origin_;
  fw::EventRecorder* recorder_;
  plinth::hal::FrameSink* bus_;
};

// The monitor takes one input item.
void take(const fw::InputItem& item, fw::Monitor& monitor, Outputs& outputs,
          fw::EventRecorder* recorder) {
  switch (item.kind) {
    case fw::InputItem::Kind::kSample:
      if (recorder != nullptr && item.has_frame) recorder->on_frame(item.frame);
      outputs.last_frame_ns = item.sample.receive_time_ns;
      outputs.handle(monitor.on_sample(item.sample));
      ++outputs.totals.samples;
      break;
    case fw::InputItem::Kind::kFrame:
      if (recorder != nullptr) recorder->on_frame(item.frame);
      outputs.last_frame_ns = item.frame.timestamp_ns;
      outputs.handle(monitor.on_frame(item.frame));
      break;
    case fw::InputItem::Kind::kTick:
      outputs.handle(monitor.on_tick(item.time_ns));
      break;
    case fw::InputItem::Kind::kBusFault:
      monitor.set_bus_fault(item.bus_fault);
      break;
  }
}

// The command-line option that sets a monitor setting, "" for settings only a file sets.
std::string option_of(const std::string& field) {
  static const std::pair<const char*, const char*> kOptions[] = {
      {"status_interval", "--status-interval"},
      {"startup_window", "--startup-window"},
      {"sample_rate", "--rate"},
      {"steps_per_sample", "--steps"},
      {"stuck_samples", "--stuck-samples"},
      {"node", "--node"}};
  for (const auto& [key, option] : kOptions) {
    if (field.find(key) != std::string::npos) return option;
  }
  return "";
}

// Monitor::start's error, naming the option or the file that gave the setting.
void start_monitor(fw::Monitor& monitor, const fw::MonitorConfig& config,
                   const plinth::Scene& scene_x, const std::optional<plinth::Scene>& scene_y,
                   const CLI::App& app, const std::string& config_path) {
  const plinth::Error e = monitor.start(config, {&scene_x, scene_y ? &*scene_y : nullptr});
  if (e.ok()) return;
  const std::string option = option_of(e.field);
  std::string where;
  if (!option.empty() && app.count(option) > 0) {
    where = option + " " + app[option]->as<std::string>() + " (" + e.field + ")";
  } else if (!config_path.empty()) {
    where = config_path + ": " + e.field;
  } else {
    where = std::string("monitor setting ") + e.field;
  }
  std::string message = where + ": " + e.reason;
  if (e.limit != 0.0 && std::isfinite(e.limit) && message.find('[') == std::string::npos) {
    message += " (limit " + plinth::host::number_text(e.limit) + ")";
  }
  throw InputError(message);
}

std::unique_ptr<fw::EventRecorder> make_recorder(const Options& opt,
                                                 const fw::MonitorConfig& config) {
  if (opt.record_dir.empty()) return nullptr;
  fw::EventRecorderSettings rs;
  rs.directory = opt.record_dir;
  rs.interface_name = opt.can_interface.empty() ? "can0" : opt.can_interface;
  rs.pre_trigger_s = opt.pre_trigger;
  rs.post_trigger_s = opt.post_trigger;
  rs.frame_rate_hz = 2.0 * config.estimator.sample_rate_hz + 100.0;
  return std::make_unique<fw::EventRecorder>(rs);
}

fw::InputOptions input_options(const Options& opt) {
  fw::InputOptions in;
  in.replay_path = opt.replay_path;
  in.replay_y_path = opt.replay_y_path;
  in.vertical_path = opt.vertical_path;
  in.can_interface = opt.can_interface;
  in.pga = opt.pga;
  in.scale = opt.scale;
  in.rate_hz = opt.config.rate_hz;
  in.speed = parse_speed(opt.speed);
  in.duration_s = opt.duration;
  in.recorder_frames = !opt.record_dir.empty();
  return in;
}

// The summary's totals besides the monitor's own counters.
fw::RunTotals run_totals(const Outputs& outputs, fw::MonitorInput& input,
                         const fw::Monitor& monitor, const fw::EventRecorder* recorder,
                         const std::vector<AxisEvents>& sinks) {
  fw::RunTotals t = outputs.totals;
  t.source = input.source();
  t.samples += monitor.frames().sensor_samples;
  for (const AxisEvents& sink : sinks) t.phase_events += sink.count;
  const fw::InputTimeCounters time = input.time_counters();
  t.log_time_back = time.went_back;
  t.log_time_still = time.stood_still;
  t.log_time_gaps = time.gaps;
  const fw::BusCounters bus = input.bus_counters();
  t.bus_errors = bus.bus_errors;
  t.bus_dropped_frames = bus.dropped_frames;
  if (input.sink() != nullptr) t.bus_send_errors += monitor.frames().not_encoded;
  if (recorder != nullptr) {
    t.recorder = true;
    t.captures_written = recorder->captures_written();
    t.captures_dropped = recorder->captures_dropped();
    t.recorder_write_errors = recorder->write_errors();
  }
  return t;
}

// A file replay that ends without the box vouching for it: no estimator ever ran (an empty
// log, no usable sensor frame), or the log's time could not be monitor time. Says why on
// stderr; "" when the run is sound (a live bus is judged by its own fault levels).
std::string input_fault(fw::MonitorInput& input, bool estimated) {
  const fw::InputTimeCounters time = input.time_counters();
  if (time.total() > 0) {
    std::fprintf(stderr,
                 "plinth-monitor: fault: %s (%llu timestamps back, %llu standing still, %llu "
                 "gaps beyond %g s in all)\n",
                 time.first.c_str(), static_cast<unsigned long long>(time.went_back),
                 static_cast<unsigned long long>(time.stood_still),
                 static_cast<unsigned long long>(time.gaps), fw::kMaxLogGapS);
    return "log_time";
  }
  if (!estimated && input.sink() == nullptr) {
    std::fprintf(stderr,
                 "plinth-monitor: fault: %s: no usable sensor data, the estimator never ran\n",
                 input.source().c_str());
    return "no_sensor_data";
  }
  return "";
}

int run(const Options& opt, const CLI::App& app) {
  const int sources = (opt.replay_path.empty() ? 0 : 1) + (opt.can_interface.empty() ? 0 : 1);
  if (sources != 1) throw InputError("give exactly one input: --replay FILE or --can INTERFACE");
  const fw::InputOptions input_settings = input_options(opt);
  fw::MonitorFile file = fw::configure_monitor(opt.config);
  if (!opt.replay_y_path.empty() && file.second_scene_path.empty()) {
    throw InputError("--replay-y needs a second axis: --scene-y or monitor.second_scene");
  }
  const plinth::Scene scene_x = plinth::host::load_scene_file(opt.scene_path);
  std::optional<plinth::Scene> scene_y;
  if (!file.second_scene_path.empty())
    scene_y = plinth::host::load_scene_file(file.second_scene_path);
  fw::MonitorConfig& config = file.config;
  config.axis_count = scene_y ? 2 : 1;
  const std::unique_ptr<fw::MonitorInput> input = fw::open_input(input_settings, config, g_stop);

  fw::Monitor monitor;
  start_monitor(monitor, config, scene_x, scene_y, app, opt.config.config_path);
  std::vector<AxisEvents> sinks;
  sinks.reserve(static_cast<std::size_t>(config.axis_count));
  for (int i = 0; i < config.axis_count; ++i) {
    sinks.emplace_back(i, monitor, input->t_origin(), !opt.quiet_events);
    monitor.set_event_sink(i, &sinks.back());
  }
  const std::unique_ptr<fw::EventRecorder> recorder = make_recorder(opt, config);
  Outputs outputs(monitor, input->t_origin(), recorder.get(), input->sink());
  fw::InputItem item;
  bool estimated = false;  // the estimators ran at some point
  while (g_stop == 0 && input->next(item)) {
    take(item, monitor, outputs, recorder.get());
    estimated = estimated || monitor.status().estimating;
  }
  if (recorder) recorder->close();  // every capture is on disk before the summary
  fw::RunTotals totals = run_totals(outputs, *input, monitor, recorder.get(), sinks);
  totals.input_fault = input_fault(*input, estimated);
  print_line(fw::summary_json(monitor, totals, input->t_origin()));
  std::fflush(stdout);
  return totals.input_fault.empty() || g_stop != 0 ? 0 : kInputFaultExit;
}

void add_options(CLI::App& app, Options& opt) {
  fw::MonitorOverrides& c = opt.config;
  app.add_option("--scene", opt.scene_path, "scene file (TOML), the statue's first axis")->required();
  app.add_option("--scene-y", c.scene_y_path, "scene of the second axis (two planar models)");
  app.add_option("--config", c.config_path, "the box's configuration file (TOML; docs/monitor.md)");
  app.add_option("--replay", opt.replay_path, "replay a record (.AT2, .csv) or a candump log (.log)");
  app.add_option("--replay-y", opt.replay_y_path, "second horizontal record (axis y)");
  app.add_option("--vertical", opt.vertical_path, "vertical record");
  app.add_option("--can", opt.can_interface, "listen on a SocketCAN interface, e.g. can0");
  app.add_option("--pga", opt.pga, "scale the record to this PGA, e.g. 0.3g")->excludes("--can");
  app.add_option("--scale", opt.scale, "scale factor of the record")
      ->check(plinth::host::kFinite)->excludes("--pga");
  app.add_option("--speed", opt.speed, "replay speed: a factor of real time, or max (default)");
  app.add_option("--rate", c.rate_hz, "sensor rate, Hz (100-1000; default: the record's, or 200)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--steps", c.steps, "solver steps per sample (default 4)")
      ->check(CLI::Range(1, 64));
  app.add_option("--node", c.node,
                 "CAN node of the single ground sensor (default 1; not with [[sensor]] tables)")
      ->check(CLI::Range(1, 15));
  app.add_option("--status-interval", c.status_interval_s, "s between status lines (default 0.1)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--startup-window", c.startup_window_s,
                 "s of quiet input that estimate the sensor offset (default 2)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--duration", opt.duration, "live: stop after this many seconds")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--record-dir", opt.record_dir, "event recorder: write captures here");
  app.add_option("--pre-trigger", opt.pre_trigger, "s kept before an alarm (default 30)")
      ->check(plinth::host::kFinite);
  app.add_option("--post-trigger", opt.post_trigger, "s kept after an alarm (default 60)")
      ->check(plinth::host::kFinite);
  app.add_flag("--no-events", opt.quiet_events, "leave out the phase event lines");
  app.add_option("--stuck-samples", c.stuck_samples,
                 "identical samples that mean a stuck sensor (default 50; 0: off, for noise-free "
                 "synthetic logs)")
      ->check(CLI::Range(0, 100000));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plinth-monitor: the early-warning box's estimator, risk and alarms"};
  Options opt;
  add_options(app, opt);
  if (const std::optional<int> exit_code = plinth::host::parse_command_line(app, argc, argv)) {
    return *exit_code;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  return plinth::host::run_tool("plinth-monitor", [&] { return run(opt, app); });
}
