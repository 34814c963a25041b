// plinth-monitor: the box's application on Linux. Sensor samples from a file replay (AT2, CSV
// or a candump log) or a SocketCAN bus; the firmware loop (firmware/monitor) estimates the
// block's phase and overturning risk and raises alarms. JSON Lines on stdout (docs/monitor.md):
// status lines at --status-interval and on every alarm change, alarm lines, phase events, and
// a summary at the end. Live, status and alarm frames also go on the bus.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "event_recorder.h"
#include "monitor_config.h"
#include "record_input.h"
#include "plinth/firmware/monitor.h"
#include "plinth/firmware/monitor_frames.h"
#include "plinth/firmware/record_replay.h"
#include "plinth/hal/candump_log.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/pacing.h"
#include "plinth/hal/socketcan.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/record_io.h"
#include "plinth/host/run_output.h"
#include "plinth/host/scene_toml.h"
#include "plinth/host/units.h"

namespace {

using plinth::host::InputError;
namespace fw = plinth::firmware;
namespace can = plinth::can;
namespace mon = plinth::monitor;

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) { g_stop = 1; }

struct Options {
  std::string scene_path;
  std::string scene_y_path;
  std::string replay_path;
  std::string replay_y_path;
  std::string vertical_path;
  std::string can_interface;
  std::string pga;
  std::optional<double> scale;
  std::string speed = "max";
  std::optional<double> rate;
  std::string config_path;
  std::optional<int> steps;
  std::optional<int> node;
  double status_interval = fw::kDefaultStatusIntervalS;
  std::optional<double> startup_window;
  double duration = 0.0;
  std::string record_dir;
  std::string frames_out;
  double pre_trigger = 30.0;
  double post_trigger = 60.0;
  bool quiet_events = false;
  std::optional<int> stuck_samples;
};

const char* axis_name(int axis) { return axis == 0 ? "x" : "y"; }

// --speed: a positive factor of real time, or "max".
double parse_speed(const std::string& text) {
  if (text == "max") return 0.0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || v <= 0.0) {
    throw InputError("--speed: expected a positive factor of real time or 'max', got '" + text +
                     "'");
  }
  return v;
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
    std::string line = plinth::host::event_json(shifted);
    line.insert(1, std::string("\"type\": \"event\", \"axis\": \"") + axis_name(axis_) + "\", ");
    std::fputs(line.c_str(), stdout);
    std::fputc('\n', stdout);
  }
  std::uint64_t count = 0;

 private:
  int axis_;
  const fw::Monitor& monitor_;
  double t_origin_;
  bool print_;
};

std::string phase_text(const plinth::Mode& mode) { return plinth::phase_name(mode.phase); }

// A cross-check's RMS, m/s2, or null while its window is not full (or for the primary).
std::string rms_text(const fw::SensorStatus& sensor) {
  if (sensor.primary || !sensor.window_full) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", sensor.rms_m_s2);
  return text;
}

// The sensors' part of a status line: their state, failovers, the plate's residual, and each
// sensor (docs/monitor.md).
std::string sensors_json(const fw::MonitorStatus& s) {
  char head[160];
  std::snprintf(head, sizeof head,
                ", \"sensors_state\": \"%s\", \"disagreement\": %s, \"failovers\": %llu",
                mon::health_state_name(s.sensors_state), s.disagreement ? "true" : "false",
                static_cast<unsigned long long>(s.failovers));
  std::string line = head;
  if (s.plate >= 0) {
    line += ", \"plate_residual_m_s2\": ";
    line += rms_text(s.sensors[static_cast<std::size_t>(s.plate)]);
    line += s.plate_mismatch ? ", \"plate_mismatch\": true" : ", \"plate_mismatch\": false";
  }
  line += ", \"sensors\": [";
  for (int i = 0; i < s.sensor_count; ++i) {
    const fw::SensorStatus& sensor = s.sensors[static_cast<std::size_t>(i)];
    char text[256];
    std::snprintf(text, sizeof text,
                  "%s{\"node\": %u, \"role\": \"%s\", \"primary\": %s, \"health\": \"%s\", "
                  "\"cause\": \"%s\", \"ready\": %s, \"rms_m_s2\": ",
                  i > 0 ? ", " : "", static_cast<unsigned>(sensor.node),
                  fw::sensor_role_name(sensor.role), sensor.primary ? "true" : "false",
                  mon::health_state_name(sensor.health.state),
                  mon::health_cause_name(sensor.health.cause), sensor.ready ? "true" : "false");
    line += text;
    line += rms_text(sensor);
    line += sensor.disagreeing ? ", \"disagreeing\": true}" : ", \"disagreeing\": false}";
  }
  line += "]";
  return line;
}

// {"type":"status","t":..,"phase":..,"risk":..,"alarm":..,...} (docs/monitor.md).
std::string status_json(const fw::Monitor& monitor, double t_origin) {
  const fw::MonitorStatus& s = monitor.status();
  const double t = static_cast<double>(s.time_ns) * 1e-9 - t_origin;
  char head[256];
  std::snprintf(head, sizeof head, "{\"type\": \"status\", \"t\": %.6f", t);
  std::string line = head;
  const auto per_axis = [&](const char* key, auto value_of) {
    line += std::string(", \"") + key + "\": ";
    if (s.axis_count == 1) {
      line += value_of(s.axes[0]);
      return;
    }
    line += "{";
    for (int i = 0; i < s.axis_count; ++i) {
      if (i > 0) line += ", ";
      line += std::string("\"") + axis_name(i) + "\": " + value_of(s.axes[static_cast<std::size_t>(i)]);
    }
    line += "}";
  };
  const auto quoted = [](const std::string& text) { return "\"" + text + "\""; };
  per_axis("phase", [&](const fw::AxisStatus& a) { return quoted(phase_text(a.mode)); });
  per_axis("corner", [&](const fw::AxisStatus& a) {
    return quoted(a.mode.rocking() ? plinth::corner_name(a.mode.corner) : "none");
  });
  char numbers[512];
  std::snprintf(numbers, sizeof numbers,
                ", \"risk\": %.4f, \"alarm\": \"%s\", \"latched\": \"%s\", \"estimating\": %s, "
                "\"sensor\": \"%s\", \"sensor_cause\": \"%s\"",
                s.risk, can::alarm_level_name(s.alarm), can::alarm_level_name(s.latched),
                s.estimating ? "true" : "false", mon::health_state_name(s.sensor.state),
                mon::health_cause_name(s.sensor.cause));
  line += numbers;
  line += sensors_json(s);
  per_axis("state", [&](const fw::AxisStatus& a) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "{\"u\": %.6g, \"x\": %.6g, \"theta\": %.6g, \"u_dot\": %.6g, \"x_dot\": %.6g, "
                  "\"theta_dot\": %.6g, \"overhang\": %d, \"risk_overturning\": %.4f, "
                  "\"risk_falling\": %.4f, \"risk_base_stops\": %.4f}",
                  a.state[plinth::kU], a.state[plinth::kX], a.state[plinth::kTheta],
                  a.state[plinth::kUDot], a.state[plinth::kXDot], a.state[plinth::kThetaDot],
                  a.mode.overhang, a.risk.overturning, a.risk.falling, a.risk.base_stops);
    return std::string(text);
  });
  return line + "}";
}

std::string alarm_json(const mon::AlarmEventRecord& e, double t_origin) {
  char text[320];
  std::snprintf(text, sizeof text,
                "{\"type\": \"alarm\", \"t\": %.6f, \"level\": \"%s\", \"previous\": \"%s\", "
                "\"cause\": \"%s\", \"latched\": %s, \"sequence\": %u}",
                static_cast<double>(e.time_ns) * 1e-9 - t_origin, can::alarm_level_name(e.level),
                can::alarm_level_name(e.previous_level), can::alarm_cause_name(e.cause),
                e.latched ? "true" : "false", static_cast<unsigned>(e.sequence));
  return text;
}

void print_line(const std::string& line) {
  std::fputs(line.c_str(), stdout);
  std::fputc('\n', stdout);
}

// Everything after the monitor has digested an input: alarm lines, recorder triggers, status
// lines (and frames when live) at the status interval.
class Outputs {
 public:
  Outputs(fw::Monitor& monitor, double t_origin, double status_interval,
          fw::EventRecorder* recorder, plinth::hal::FrameSink* bus)
      : monitor_(monitor), t_origin_(t_origin), recorder_(recorder),
        frames_(monitor, std::llround(status_interval * 1e9), bus) {}

  void handle(const fw::MonitorUpdate& u) {
    const fw::MonitorStatus& s = monitor_.status();
    max_risk = std::fmax(max_risk, s.risk);
    for (std::size_t i = 0; i < u.event_count; ++i) {
      const mon::AlarmEventRecord& e = u.events[i];
      print_line(alarm_json(e, t_origin_));
      ++alarm_events;
      if (static_cast<int>(e.level) > static_cast<int>(max_level) &&
          e.level != can::AlarmLevel::kFault) {
        max_level = e.level;
      }
      if (e.level == can::AlarmLevel::kFault) ++fault_events;
      frames_.send_alarm(e);
      if (recorder_ != nullptr && (e.level == can::AlarmLevel::kWarning ||
                                   e.level == can::AlarmLevel::kAlarm)) {
        fw::TriggerInfo info;
        info.t = static_cast<double>(e.time_ns) * 1e-9 - t_origin_;
        info.level = can::alarm_level_name(e.level);
        info.cause = can::alarm_cause_name(e.cause);
        char detail[96];
        std::snprintf(detail, sizeof detail, "\"risk\": %.4f, \"phase\": \"%s\"", s.risk,
                      plinth::phase_name(s.axes[0].mode.phase));
        info.detail = detail;
        recorder_->trigger(info, last_frame_ns);
      }
    }
    // At the status interval, at every alarm change, and at the alarm policy's heartbeat.
    if (frames_.status_due(u)) {
      print_line(status_json(monitor_, t_origin_));
      frames_.send_status();
    }
  }

  [[nodiscard]] std::uint64_t bus_send_errors() const { return frames_.send_errors(); }

  double max_risk = 0.0;
  can::AlarmLevel max_level = can::AlarmLevel::kNormal;
  std::uint64_t alarm_events = 0;
  std::uint64_t fault_events = 0;
  std::int64_t last_frame_ns = 0;  // receive time of the newest frame (the recorder's clock)

 private:
  fw::Monitor& monitor_;
  double t_origin_;
  fw::EventRecorder* recorder_;
  fw::MonitorFrames frames_;
};

struct Summary {
  std::uint64_t samples = 0;
  std::string source;
  std::uint64_t bus_errors = 0;      // error frames reported by the controller (live)
  std::uint64_t overflows = 0;       // times the kernel reported dropped frames (live)
  std::uint64_t dropped_frames = 0;  // frames the kernel dropped before we read them (live)
};

void print_summary(const fw::Monitor& monitor, const Outputs& outputs, const Summary& summary,
                   const fw::EventRecorder* recorder, double t_origin,
                   const std::vector<std::unique_ptr<AxisEvents>>& sinks) {
  const fw::MonitorStatus& s = monitor.status();
  const fw::FrameCounters& f = monitor.frames();
  const mon::SensorCounters& c = s.sensor.counters;
  char text[1400];
  std::snprintf(
      text, sizeof text,
      "{\"type\": \"summary\", \"source\": \"%s\", \"t\": %.6f, \"samples\": %llu, "
      "\"final_phase\": \"%s\", \"max_risk\": %.4f, \"max_alarm\": \"%s\", \"alarm\": \"%s\", "
      "\"alarm_events\": %llu, \"fault_events\": %llu, \"phase_events\": %llu, "
      "\"frames\": {\"received\": %llu, \"sensor_samples\": %llu, \"other_nodes\": %llu, "
      "\"heartbeats\": %llu, \"acknowledgements\": %llu, \"rejected\": %llu, "
      "\"unknown_identifiers\": %llu, \"last_error\": \"%s\"}, "
      "\"sensor\": {\"state\": \"%s\", \"fed\": %llu, \"bridged\": %llu, \"missing\": %llu, "
      "\"long_gaps\": %llu, \"duplicates\": %llu, \"out_of_order\": %llu, \"rejected\": %llu, "
      "\"saturated\": %llu, \"timeouts\": %llu, \"faults\": %llu}, "
      "\"estimator_restarts\": %llu, \"bus_send_errors\": %llu, \"bus_errors\": %llu, "
      "\"bus_dropped_frames\": %llu",
      summary.source.c_str(), static_cast<double>(s.time_ns) * 1e-9 - t_origin,
      static_cast<unsigned long long>(summary.samples), plinth::phase_name(s.axes[0].mode.phase),
      outputs.max_risk, can::alarm_level_name(outputs.max_level), can::alarm_level_name(s.alarm),
      static_cast<unsigned long long>(outputs.alarm_events),
      static_cast<unsigned long long>(outputs.fault_events),
      static_cast<unsigned long long>(sinks.empty() ? 0 : sinks[0]->count +
                                                             (sinks.size() > 1 ? sinks[1]->count : 0)),
      static_cast<unsigned long long>(f.received), static_cast<unsigned long long>(f.sensor_samples),
      static_cast<unsigned long long>(f.other_nodes), static_cast<unsigned long long>(f.heartbeats),
      static_cast<unsigned long long>(f.acknowledgements), static_cast<unsigned long long>(f.rejected),
      static_cast<unsigned long long>(f.unknown_identifiers), can::codec_error_text(f.last_error),
      mon::health_state_name(s.sensor.state), static_cast<unsigned long long>(c.fed),
      static_cast<unsigned long long>(c.bridged), static_cast<unsigned long long>(c.missing),
      static_cast<unsigned long long>(c.long_gaps), static_cast<unsigned long long>(c.duplicates),
      static_cast<unsigned long long>(c.out_of_order),
      static_cast<unsigned long long>(c.non_finite + c.out_of_range + c.undefined_status),
      static_cast<unsigned long long>(c.saturated), static_cast<unsigned long long>(c.timeouts),
      static_cast<unsigned long long>(c.faults),
      static_cast<unsigned long long>(s.estimator_restarts),
      static_cast<unsigned long long>(outputs.bus_send_errors()),
      static_cast<unsigned long long>(summary.bus_errors),
      static_cast<unsigned long long>(summary.dropped_frames));
  std::string line = text;
  const auto count = [](std::uint64_t value) { return static_cast<unsigned long long>(value); };
  char totals[200];
  std::snprintf(totals, sizeof totals,
                ", \"sensors_state\": \"%s\", \"failovers\": %llu, \"failovers_continued\": %llu, "
                "\"sensors\": [",
                mon::health_state_name(s.sensors_state), count(s.failovers),
                count(s.failovers_continued));
  line += totals;
  for (int i = 0; i < s.sensor_count; ++i) {
    const fw::SensorStatus& sensor = s.sensors[static_cast<std::size_t>(i)];
    const mon::SensorCounters& k = sensor.health.counters;
    char one[512];
    std::snprintf(
        one, sizeof one,
        "%s{\"node\": %u, \"role\": \"%s\", \"primary\": %s, \"state\": \"%s\", "
        "\"received\": %llu, \"fed\": %llu, \"bridged\": %llu, \"missing\": %llu, "
        "\"long_gaps\": %llu, \"rejected\": %llu, \"timeouts\": %llu, \"faults\": %llu, "
        "\"pairs\": %llu, \"unpaired\": %llu, \"disagreements\": %llu, \"max_rms_m_s2\": %.4g}",
        i > 0 ? ", " : "", static_cast<unsigned>(sensor.node), fw::sensor_role_name(sensor.role),
        sensor.primary ? "true" : "false", mon::health_state_name(sensor.health.state),
        count(k.received), count(k.fed), count(k.bridged), count(k.missing), count(k.long_gaps),
        count(k.non_finite + k.out_of_range + k.undefined_status), count(k.timeouts),
        count(k.faults), count(sensor.pairs), count(sensor.unpaired), count(sensor.disagreements),
        sensor.max_rms_m_s2);
    line += one;
  }
  line += "]";
  if (recorder != nullptr) {
    char rec[160];
    std::snprintf(rec, sizeof rec,
                  ", \"recorder\": {\"captures_written\": %llu, \"captures_dropped\": %llu, "
                  "\"write_errors\": %llu}",
                  static_cast<unsigned long long>(recorder->captures_written()),
                  static_cast<unsigned long long>(recorder->captures_dropped()),
                  static_cast<unsigned long long>(recorder->write_errors()));
    line += rec;
  }
  print_line(line + "}");
}

int run(const Options& opt) {
  const int sources = (opt.replay_path.empty() ? 0 : 1) + (opt.can_interface.empty() ? 0 : 1);
  if (sources != 1) throw InputError("give exactly one input: --replay FILE or --can INTERFACE");
  const double speed = parse_speed(opt.speed);
  // Defaults, then the configuration file, then the command line.
  fw::MonitorConfig config = fw::box_defaults();
  std::string scene_y_path = opt.scene_y_path;
  if (!opt.config_path.empty()) {
    const fw::MonitorFile file = fw::load_monitor_file(opt.config_path, config);
    config = file.config;
    if (scene_y_path.empty()) scene_y_path = file.second_scene_path;
  }
  if (opt.steps) config.estimator.steps_per_sample = *opt.steps;
  if (opt.node) {
    if (config.sensor_count > 0) {
      throw InputError(std::string("--node names the single ground sensor; ") + opt.config_path +
                       " lists [[sensor]] tables (give the nodes there)");
    }
    config.ground_node = static_cast<std::uint8_t>(*opt.node);
  }
  // The command line's sensor settings apply to every sensor.
  const auto each_sensor = [&config](auto apply) {
    apply(config.conditioning, config.sensor_health);
    for (int i = 0; i < config.sensor_count && i < fw::kMaxSensors; ++i) {
      fw::SensorConfig& sensor = config.sensors[static_cast<std::size_t>(i)];
      apply(sensor.conditioning, sensor.sensor_health);
    }
  };
  if (opt.startup_window) {
    each_sensor([&](mon::ConditioningSettings& c, mon::SensorHealthSettings&) {
      c.startup_window_s = *opt.startup_window;
    });
  }
  if (opt.stuck_samples) {
    each_sensor([&](mon::ConditioningSettings&, mon::SensorHealthSettings& h) {
      h.stuck_samples = *opt.stuck_samples;
    });
  }
  if (!opt.replay_y_path.empty() && scene_y_path.empty()) {
    throw InputError("--replay-y needs a second axis: --scene-y or monitor.second_scene");
  }
  const plinth::Scene scene_x = plinth::host::load_scene_file(opt.scene_path);
  std::optional<plinth::Scene> scene_y;
  if (!scene_y_path.empty()) scene_y = plinth::host::load_scene_file(scene_y_path);
  const double gravity = plinth::kStandardGravity;
  const std::string extension = std::filesystem::path(opt.replay_path).extension().string();
  const bool replay_log = !opt.replay_path.empty() && (extension == ".log" || extension == ".LOG");
  const bool replay_record = !opt.replay_path.empty() && !replay_log;
  if (!replay_record && (!opt.pga.empty() || opt.scale || !opt.replay_y_path.empty() ||
                         !opt.vertical_path.empty())) {
    throw InputError("--pga, --scale, --replay-y and --vertical apply to an AT2 or CSV record");
  }

  config.axis_count = scene_y ? 2 : 1;
  fw::RecordSamples record;
  double t_origin = 0.0;
  if (replay_record) {
    record = fw::record_samples({opt.replay_path, opt.replay_y_path, opt.vertical_path, opt.pga,
                                 opt.scale, opt.rate},
                                gravity);
    fw::configure_record_replay(config, record.rate_hz);
    t_origin = fw::record_replay_origin_s(config);
  } else {
    if (opt.rate) config.estimator.sample_rate_hz = *opt.rate;
  }
  fw::Monitor monitor;
  const plinth::Error e =
      monitor.start(config, {&scene_x, scene_y ? &*scene_y : static_cast<const plinth::Scene*>(nullptr)});
  if (!e.ok()) {
    std::string message = std::string("monitor settings: ") + e.field + " " + e.reason;
    if (std::isfinite(e.limit)) message += " (limit " + std::to_string(e.limit) + ")";
    throw InputError(message);
  }
  std::vector<std::unique_ptr<AxisEvents>> sinks;
  for (int i = 0; i < config.axis_count; ++i) {
    sinks.push_back(std::make_unique<AxisEvents>(i, monitor, t_origin, !opt.quiet_events));
    monitor.set_event_sink(i, sinks.back().get());
  }

  std::optional<plinth::hal::SocketCanPort> port;
  if (!opt.can_interface.empty()) {
    plinth::hal::SocketCanOpenResult opened = plinth::hal::SocketCanPort::open(opt.can_interface);
    if (!opened.ok()) throw InputError(opened.message);
    port = std::move(opened.port);
  }
  std::unique_ptr<fw::EventRecorder> recorder;
  if (!opt.record_dir.empty()) {
    fw::EventRecorderSettings rs;
    rs.directory = opt.record_dir;
    rs.interface_name = opt.can_interface.empty() ? "can0" : opt.can_interface;
    rs.pre_trigger_s = opt.pre_trigger;
    rs.post_trigger_s = opt.post_trigger;
    rs.frame_rate_hz = 2.0 * config.estimator.sample_rate_hz + 100.0;
    recorder = std::make_unique<fw::EventRecorder>(rs);
  }
  // --frames-out: the frames the replay sends, stamped with the time of the input that caused
  // them (the bus's candump would show the same).
  const Outputs* frames_clock = nullptr;
  std::optional<plinth::hal::CandumpLogWriter> frames_log;
  if (!opt.frames_out.empty()) {
    frames_log.emplace(opt.frames_out, "can0",
                       [&frames_clock] { return frames_clock->last_frame_ns; });
  }
  Outputs outputs(monitor, t_origin, opt.status_interval, recorder.get(),
                  port ? static_cast<plinth::hal::FrameSink*>(&*port)
                       : (frames_log ? &*frames_log : nullptr));
  frames_clock = &outputs;
  Summary summary;
  const std::int64_t wall_start = plinth::hal::monotonic_now_ns();
  const auto pace = [&](std::int64_t stream_ns) {
    if (speed > 0.0) {
      // Cut short by Ctrl-C: the loops look at g_stop.
      (void)plinth::hal::sleep_until_ns(
          wall_start + std::llround(static_cast<double>(stream_ns) / speed), g_stop);
    }
  };

  if (replay_record) {
    summary.source = opt.replay_path;
    // Quiet lead-in, then the record (record_replay.h).
    const auto lead_in = static_cast<std::size_t>(fw::record_replay_lead_in(config));
    const std::size_t total = lead_in + record.samples.size();
    for (std::size_t n = 0; n < total && !g_stop; ++n) {
      const mon::SensorSample sample = fw::record_replay_sample(
          config, static_cast<std::int64_t>(n),
          n < lead_in ? Eigen::Vector3d::Zero() : record.samples[n - lead_in], gravity);
      pace(sample.receive_time_ns);
      if (recorder) {
        can::SensorAcceleration m;
        m.node = config.ground_node;
        m.ax_g = sample.acceleration_g.x() / gravity;
        m.ay_g = sample.acceleration_g.y() / gravity;
        m.az_g = sample.acceleration_g.z() / gravity;
        m.sequence = sample.sequence;
        plinth::hal::TimedFrame frame;
        frame.timestamp_ns = sample.receive_time_ns;
        if (can::encode(m, frame.frame).ok()) recorder->on_frame(frame);  // beyond +-8 g: not kept
      }
      outputs.last_frame_ns = sample.receive_time_ns;
      outputs.handle(monitor.on_sample(sample));
      ++summary.samples;
    }
  } else if (replay_log) {
    summary.source = opt.replay_path;
    plinth::hal::CandumpLogReader reader(opt.replay_path);
    plinth::hal::TimedFrame frame;
    std::optional<std::int64_t> first_ns;
    std::int64_t next_tick = 0;
    const std::int64_t tick_ns = 10'000'000;
    for (;;) {
      if (g_stop) break;
      const plinth::hal::IoStatus status = reader.receive(frame, 0);
      if (status == plinth::hal::IoStatus::kEndOfInput) break;
      if (status == plinth::hal::IoStatus::kIoError) {
        throw InputError(reader.error());  // "file:line: what"
      }
      if (status != plinth::hal::IoStatus::kOk) continue;  // extended, RTR, FD: not ours
      if (!first_ns) {
        first_ns = frame.timestamp_ns;
        next_tick = frame.timestamp_ns + tick_ns;
      }
      pace(frame.timestamp_ns - *first_ns);
      while (next_tick < frame.timestamp_ns) {  // timeouts inside gaps of the log
        outputs.handle(monitor.on_tick(next_tick));
        next_tick += tick_ns;
      }
      if (recorder) recorder->on_frame(frame);
      outputs.last_frame_ns = frame.timestamp_ns;
      const std::uint64_t before = monitor.frames().sensor_samples;
      outputs.handle(monitor.on_frame(frame));
      summary.samples += monitor.frames().sensor_samples - before;
    }
  } else {
    summary.source = opt.can_interface;
    plinth::hal::TimedFrame frame;
    const std::int64_t end_ns =
        opt.duration > 0.0 ? wall_start + std::llround(opt.duration * 1e9) : INT64_MAX;
    std::int64_t bus_fault_until = 0;
    while (!g_stop && plinth::hal::monotonic_now_ns() < end_ns) {
      const plinth::hal::IoStatus status = port->receive(frame, 10);
      const std::int64_t now_ns = plinth::hal::realtime_now_ns();
      switch (status) {
        case plinth::hal::IoStatus::kOk: {
          if (recorder) recorder->on_frame(frame);
          outputs.last_frame_ns = frame.timestamp_ns;
          const std::uint64_t before = monitor.frames().sensor_samples;
          outputs.handle(monitor.on_frame(frame));
          summary.samples += monitor.frames().sensor_samples - before;
          break;
        }
        case plinth::hal::IoStatus::kBusError:
        case plinth::hal::IoStatus::kOverflow:
          ++(status == plinth::hal::IoStatus::kBusError ? summary.bus_errors : summary.overflows);
          bus_fault_until = now_ns + 2'000'000'000;  // held 2 s after the latest report
          monitor.set_bus_fault(true);
          break;
        case plinth::hal::IoStatus::kIoError:
          throw InputError(std::string("CAN interface ") + opt.can_interface +
                           ": receive failed: " + std::strerror(port->last_error()));
        default:
          break;
      }
      if (bus_fault_until != 0 && now_ns > bus_fault_until) {
        bus_fault_until = 0;
        monitor.set_bus_fault(false);
      }
      // Tick at the newest frame's receive time: frames still queued in the socket are newer,
      // and a monitor that fell behind must not count its own delay as a sensor timeout. Only
      // with nothing to read is the wall clock the right time.
      outputs.handle(monitor.on_tick(status == plinth::hal::IoStatus::kTimeout
                                         ? now_ns
                                         : std::max(outputs.last_frame_ns, frame.timestamp_ns)));
    }
    summary.dropped_frames = port->total_dropped_frames();
  }
  if (recorder) recorder->close();  // every capture is on disk before the summary
  if (frames_log && !frames_log->flush()) throw InputError(frames_log->error());
  print_summary(monitor, outputs, summary, recorder.get(), t_origin, sinks);
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plinth-monitor: the early-warning box's estimator, risk and alarms"};
  Options opt;
  app.add_option("--scene", opt.scene_path, "scene file (TOML), the statue's first axis")->required();
  app.add_option("--scene-y", opt.scene_y_path, "scene of the second axis (two planar models)");
  app.add_option("--config", opt.config_path, "the box's configuration file (TOML; docs/monitor.md)");
  app.add_option("--replay", opt.replay_path, "replay a record (.AT2, .csv) or a candump log (.log)");
  app.add_option("--replay-y", opt.replay_y_path, "second horizontal record (axis y)");
  app.add_option("--vertical", opt.vertical_path, "vertical record");
  app.add_option("--can", opt.can_interface, "listen on a SocketCAN interface, e.g. can0");
  app.add_option("--pga", opt.pga, "scale the record to this PGA, e.g. 0.3g")->excludes("--can");
  app.add_option("--scale", opt.scale, "scale factor of the record")
      ->check(plinth::host::kFinite)->excludes("--pga");
  app.add_option("--speed", opt.speed, "replay speed: a factor of real time, or max (default)");
  app.add_option("--rate", opt.rate, "sensor rate, Hz (100-1000; default: the record's, or 200)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--steps", opt.steps, "solver steps per sample (default 4)")->check(CLI::Range(1, 64));
  app.add_option("--node", opt.node, "CAN node of the single ground sensor (default 1; not with [[sensor]] tables)")->check(CLI::Range(1, 15));
  app.add_option("--status-interval", opt.status_interval, "s between status lines (default 0.1)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--startup-window", opt.startup_window,
                 "s of quiet input that estimate the sensor offset (default 2)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--duration", opt.duration, "live: stop after this many seconds")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--record-dir", opt.record_dir, "event recorder: write captures here");
  app.add_option("--frames-out", opt.frames_out,
                 "replay: write the status and alarm frames sent to this candump log")
      ->excludes("--can");
  app.add_option("--pre-trigger", opt.pre_trigger, "s kept before an alarm (default 30)")
      ->check(plinth::host::kFinite);
  app.add_option("--post-trigger", opt.post_trigger, "s kept after an alarm (default 60)")
      ->check(plinth::host::kFinite);
  app.add_flag("--no-events", opt.quiet_events, "leave out the phase event lines");
  app.add_option("--stuck-samples", opt.stuck_samples,
                 "identical samples that mean a stuck sensor (default 50; 0: off, for noise-free "
                 "synthetic logs)")
      ->check(CLI::Range(0, 100000));
  if (const std::optional<int> exit_code = plinth::host::parse_command_line(app, argc, argv)) {
    return *exit_code;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  try {
    return run(opt);
  } catch (const InputError& error) {
    std::fprintf(stderr, "plinth-monitor: %s\n", error.what());
    return 1;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "plinth-monitor: %s\n", error.what());
    return 1;
  }
}
