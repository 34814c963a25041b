// plinth-replay: recorded earthquakes sent as plinth sensor frames, on a CAN bus (SocketCAN) or
// into a candump log, paced on absolute deadlines. See hal/README.md.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "frame_schedule.h"
#include "plinth/core/scene.h"
#include "plinth/hal/candump_log.h"
#include "plinth/hal/pacing.h"
#include "plinth/hal/socketcan.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/output_file.h"
#include "plinth/host/parse_name.h"
#include "plinth/host/record_io.h"
#include "plinth/host/record_sampling.h"

namespace {

using plinth::kStandardGravity;
using plinth::host::InputError;

constexpr double kMinRateHz = 100.0;
constexpr double kMaxRateHz = 1000.0;
constexpr int kExitInterrupted = 130;  // 128 + SIGINT, the shell's convention
constexpr std::int64_t kQueueFullWaitNs = 100'000'000;
constexpr long kQueueFullPauseNs = 200'000;  // a frame at 500 kbit/s takes ~250 us

volatile std::sig_atomic_t g_stop = 0;
extern "C" void request_stop(int /*signal*/) { g_stop = 1; }

struct Options {
  std::string record_path;
  std::string record_y_path;
  std::string record_z_path;
  std::vector<std::string> node_records;
  int node = 1;
  std::string pga;
  std::optional<double> scale;
  double rate_hz = 200.0;
  std::string speed = "1";
  std::int64_t loops = 1;
  std::optional<double> t_end_s;
  std::string can_interface;
  std::string log_path;
  std::string log_interface = "vcan0";
  std::string log_time;   // --log-time: warn or refuse; empty: not given (warn)
  std::string log_drops;  // --log-drops: the same
  bool report_json = false;
};

enum Axis : std::size_t { kX = 0, kY = 1, kZ = 2 };
constexpr const char* kAxisNames[] = {"x", "y", "z"};

// One record file feeding one axis of one node.
struct Component {
  int node = 1;
  Axis axis = kX;
  std::string path;
  std::string given_as;  // the option, for messages
};

std::string lowercase_extension(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  const std::size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool is_candump_log(const std::string& path) { return lowercase_extension(path) == "log"; }
bool is_record(const std::string& path) {
  const std::string ext = lowercase_extension(path);
  return ext == "at2" || ext == "csv" || ext == "asc";  // PEER, CSV, ESM/ITACA
}

// "NODE:AXIS:PATH" or "NODE:PATH" (axis x), split at the colons as documented: with two colons
// or more the field between the first two is the axis (a file whose name holds a colon is given
// with its axis, "1:x:a:b.AT2"); each field that is not what it must be is named.
Component parse_node_record(const std::string& text) {
  const std::string usage = "--node-record: expected NODE:AXIS:FILE or NODE:FILE (NODE 1-15, "
                            "AXIS x, y or z), got " + plinth::host::shown(text);
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos) throw InputError(usage);
  Component component;
  component.given_as = "--node-record " + text;
  const std::string node_text = text.substr(0, colon);
  if (node_text.empty() || node_text.size() > 2 ||
      node_text.find_first_not_of("0123456789") != std::string::npos) {
    throw InputError("--node-record: the node " + plinth::host::shown(node_text) + " in " +
                     plinth::host::shown(text) + " is not a number from 1 to 15 (NODE:AXIS:FILE)");
  }
  component.node = std::stoi(node_text);
  if (component.node < plinth::hal::can::kFirstSensorNode ||
      component.node > plinth::hal::can::kLastSensorNode) {
    throw InputError("--node-record: node " + node_text + " is not 1-15 in '" + text + "'");
  }
  std::string rest = text.substr(colon + 1);
  if (const std::size_t second = rest.find(':'); second != std::string::npos) {
    const std::string axis = rest.substr(0, second);
    if (axis != "x" && axis != "y" && axis != "z") {
      throw InputError("--node-record: unknown axis " + plinth::host::shown(axis) + " in " +
                       plinth::host::shown(text) + " (one of x, y, z; NODE:AXIS:FILE)");
    }
    component.axis = static_cast<Axis>(axis[0] - 'x');
    rest = rest.substr(second + 1);
  }
  if (rest.empty()) {
    throw InputError("--node-record: no file in " + plinth::host::shown(text) +
                     " (NODE:AXIS:FILE or NODE:FILE)");
  }
  component.path = rest;
  return component;
}

// Peak |value| of a signal, m/s2.
double peak_of(const plinth::SampledSignal& signal) {
  double peak = 0.0;
  for (std::size_t i = 0; i < signal.count; ++i) peak = std::max(peak, std::fabs(signal.values[i]));
  return peak;
}

// The record-driven schedule: every node's axes, resampled and scaled.
struct RecordPlan {
  std::vector<plinth::hal::replay::SensorNodeSamples> nodes;
  std::string description;
  std::size_t clipped = 0;  // samples clipped to the full scale, all nodes
};

std::vector<Component> components_of(const Options& opt) {
  std::vector<Component> components;
  components.push_back({opt.node, kX, opt.record_path, "--record"});
  if (!opt.record_y_path.empty())
    components.push_back({opt.node, kY, opt.record_y_path, "--record-y"});
  if (!opt.record_z_path.empty())
    components.push_back({opt.node, kZ, opt.record_z_path, "--record-z"});
  for (const std::string& text : opt.node_records) components.push_back(parse_node_record(text));
  return components;
}

// Each node's axes from the components' files, each file read once into `records` (the signals
// point into them).
std::map<int, plinth::hal::replay::SensorNodeInput> node_inputs(
    const std::vector<Component>& components,
    std::map<std::string, plinth::host::Record>& records) {
  std::map<int, plinth::hal::replay::SensorNodeInput> inputs;
  std::map<int, std::array<std::string, 3>> given;  // node -> the option per axis
  for (const Component& c : components) {
    if (is_candump_log(c.path)) {
      throw InputError(c.given_as + ": " + c.path +
                       ": a candump log can only be replayed alone, "
                       "with --record");
    }
    if (!is_record(c.path)) {
      const char* expected =
          c.given_as == "--record" ? ".AT2, .ASC, .csv or a candump .log" : ".AT2, .ASC or .csv";
      throw InputError(c.given_as + ": " + c.path + ": unknown input format (expected " + expected +
                       ")");
    }
    std::string& slot = given[c.node][c.axis];
    if (!slot.empty()) {
      throw InputError(c.given_as + ": node " + std::to_string(c.node) + " axis " +
                       kAxisNames[c.axis] + " is already given by " + slot);
    }
    slot = c.given_as;
    auto found = records.find(c.path);
    if (found == records.end()) {
      found = records.emplace(c.path, plinth::host::read_record(c.path, kStandardGravity)).first;
    }
    plinth::hal::replay::SensorNodeInput& input = inputs[c.node];
    input.node = static_cast<std::uint8_t>(c.node);
    const plinth::SampledSignal signal = found->second.horizontal_signal();
    (c.axis == kX ? input.x : c.axis == kY ? input.y : input.z) = signal;
  }
  // A record with a vertical column (three-column CSV) also drives z of the node whose x it
  // drives, unless z is given.
  for (const Component& c : components) {
    plinth::hal::replay::SensorNodeInput& input = inputs[c.node];
    const plinth::host::Record& record = records.at(c.path);
    if (c.axis == kX && input.z.empty() && !record.vertical.empty())
      input.z = record.vertical_signal();
  }
  return inputs;
}

RecordPlan plan_records(const Options& opt) {
  std::map<std::string, plinth::host::Record> records;
  const std::map<int, plinth::hal::replay::SensorNodeInput> inputs =
      node_inputs(components_of(opt), records);
  const plinth::host::Record& main_record = records.at(opt.record_path);
  const double scale = plinth::host::record_scale(main_record, opt.record_path, opt.pga, opt.scale,
                                                  kStandardGravity);

  double duration_s = 0.0;
  double peak_g = 0.0;
  for (const auto& [node, input] : inputs) {
    for (const plinth::SampledSignal* s : {&input.x, &input.y, &input.z}) {
      duration_s = std::max(duration_s, s->duration());
      if (s != &input.z)
        peak_g = std::max(peak_g, std::fabs(scale) * peak_of(*s) / kStandardGravity);
    }
  }
  if (opt.t_end_s) duration_s = std::min(duration_s, *opt.t_end_s);

  RecordPlan plan;
  for (const auto& [node, input] : inputs) {
    plan.nodes.push_back(plinth::hal::replay::resample(input, scale, opt.rate_hz, duration_s));
  }
  std::size_t clipped = 0;
  for (const plinth::hal::replay::SensorNodeSamples& node : plan.nodes) clipped += node.clipped;
  char text[480];
  const int n =
      std::snprintf(text, sizeof text,
                    "%s: %zu node%s, %.4g s at %g Hz (%zu samples per node), scale %.4g, peak "
                    "horizontal %.4g g%s",
                    main_record.name.c_str(), plan.nodes.size(), plan.nodes.size() == 1 ? "" : "s",
                    duration_s, opt.rate_hz, plan.nodes.front().status.size(), scale, peak_g,
                    opt.pga.empty() ? "" : " (--pga)");
  if (clipped > 0 && n > 0) {
    std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n),
                  "; %zu samples beyond the frames' full scale (-8.192 to +8.192 g) clipped to "
                  "it and flagged saturated: the frames do not carry that peak",
                  clipped);
  }
  plan.description = text;
  plan.clipped = clipped;
  return plan;
}

// Where frames go, with what to say when a send fails.
struct Destination {
  std::unique_ptr<plinth::hal::CandumpLogWriter> log;  // when the sink is a log
  std::unique_ptr<plinth::hal::SocketCanPort> port;    // when the sink is a bus
  plinth::hal::FrameSink* sink = nullptr;              // the one of the two
  std::string name;                                    // "vcan0", "out.log"
  std::string temporary;                               // a log: the file written until complete

  // Sends; a full transmit queue (the bus is slower than the schedule, as at --speed max on a
  // real controller) is waited out for up to kQueueFullWaitNs rather than the frame dropped.
  [[nodiscard]] plinth::hal::IoStatus send(const plinth::hal::can::CanFrame& frame) const {
    plinth::hal::IoStatus status = sink->send(frame);
    const std::int64_t give_up_ns = plinth::hal::monotonic_now_ns() + kQueueFullWaitNs;
    while (status == plinth::hal::IoStatus::kIoError && port != nullptr &&
           port->transmit_queue_full() && plinth::hal::monotonic_now_ns() < give_up_ns) {
      const timespec pause{0, kQueueFullPauseNs};
      nanosleep(&pause, nullptr);
      status = sink->send(frame);
    }
    return status;
  }

  [[nodiscard]] std::string error_text(plinth::hal::IoStatus status) const {
    if (log != nullptr && !log->error().empty()) return log->error();
    if (port != nullptr && port->last_error() != 0) {
      return name + ": " + std::strerror(port->last_error()) +
             (port->transmit_queue_full() ? " (transmit queue full)" : "");
    }
    return name + ": " + plinth::hal::io_status_name(status);
  }
};

Destination open_bus(const std::string& interface_name) {
  // A sender: no receive filters, no error frames.
  plinth::hal::SocketCanOptions options;
  options.filters = {};
  options.error_frames = false;
  plinth::hal::SocketCanOpenResult opened =
      plinth::hal::SocketCanPort::open(interface_name, options);
  if (!opened.ok()) throw InputError("--can: " + opened.message);
  auto port = std::make_unique<plinth::hal::SocketCanPort>(std::move(*opened.port));
  Destination destination;
  destination.sink = port.get();
  destination.port = std::move(port);
  destination.name = interface_name;
  return destination;
}

struct Report {
  std::int64_t frames_sent = 0;
  std::int64_t acceleration_frames = 0;
  std::int64_t heartbeat_frames = 0;
  std::int64_t rotation_frames = 0;  // StatueRotation, from a log
  std::int64_t send_errors = 0;
  std::int64_t skipped_log_lines = 0;
  std::int64_t log_drop_reports = 0;    // the log's DROPCOUNT lines
  std::int64_t log_dropped_frames = 0;  // the frames they say it lost (not sent)
  std::size_t clipped_samples = 0;
  std::string first_send_error;
  double virtual_time_s = 0.0;
  double wall_time_s = 0.0;
  bool interrupted = false;
};

void print_report(const Options& opt, const Report& r, const plinth::hal::Pacer& pacer,
                  const std::string& destination) {
  std::fprintf(
      stderr,
      "plinth-replay: %lld frames sent to %s (%lld SensorAcceleration, %lld "
      "SensorHeartbeat, %lld StatueRotation), %lld send errors; %.3f s of virtual time in %.3f s "
      "(speed %s)%s\n",
      static_cast<long long>(r.frames_sent), destination.c_str(),
      static_cast<long long>(r.acceleration_frames), static_cast<long long>(r.heartbeat_frames),
      static_cast<long long>(r.rotation_frames), static_cast<long long>(r.send_errors),
      r.virtual_time_s, r.wall_time_s, opt.speed.c_str(), r.interrupted ? "; interrupted" : "");
  if (r.skipped_log_lines > 0) {
    std::fprintf(stderr, "plinth-replay: %lld log lines skipped (not sensor frames)\n",
                 static_cast<long long>(r.skipped_log_lines));
  }
  if (!r.first_send_error.empty()) {
    std::fprintf(stderr, "plinth-replay: first send error: %s\n", r.first_send_error.c_str());
  }
  const plinth::hal::LatenessHistogram& lateness = pacer.lateness();
  if (pacer.paced()) {
    std::fprintf(stderr,
                 "plinth-replay: pacing jitter (send time - deadline): median %.0f us, p99 %.0f "
                 "us, max %.0f us over %lld sends\n",
                 lateness.percentile_us(0.5), lateness.percentile_us(0.99), lateness.max_us(),
                 static_cast<long long>(lateness.count()));
  } else {
    std::fprintf(stderr, "plinth-replay: no pacing (--speed max)\n");
  }
  if (!opt.report_json) return;
  char jitter[160] = "\"jitter_median_us\": null, \"jitter_p99_us\": null, \"jitter_max_us\": null";
  if (pacer.paced()) {
    std::snprintf(jitter, sizeof jitter,
                  "\"jitter_median_us\": %.1f, \"jitter_p99_us\": %.1f, \"jitter_max_us\": %.1f",
                  lateness.percentile_us(0.5), lateness.percentile_us(0.99), lateness.max_us());
  }
  std::printf(
      "{\"frames_sent\": %lld, \"acceleration_frames\": %lld, \"heartbeat_frames\": %lld, "
      "\"rotation_frames\": %lld, \"send_errors\": %lld, \"skipped_log_lines\": %lld, "
      "\"log_drop_reports\": %lld, \"log_dropped_frames\": %lld, "
      "\"clipped_samples\": %zu, \"virtual_time_s\": %.6f, "
      "\"wall_time_s\": %.6f, \"speed\": %s, \"loops\": %lld, \"interrupted\": %s, %s}\n",
      static_cast<long long>(r.frames_sent), static_cast<long long>(r.acceleration_frames),
      static_cast<long long>(r.heartbeat_frames), static_cast<long long>(r.rotation_frames),
      static_cast<long long>(r.send_errors), static_cast<long long>(r.skipped_log_lines),
      static_cast<long long>(r.log_drop_reports), static_cast<long long>(r.log_dropped_frames),
      r.clipped_samples, r.virtual_time_s, r.wall_time_s,
      opt.speed == "max" ? "\"max\"" : opt.speed.c_str(), static_cast<long long>(opt.loops),
      r.interrupted ? "true" : "false", jitter);
  std::fflush(stdout);
}

// The speed factor; 0 for "max" (no pacing). `text` has passed kSpeed.
double parse_speed(const std::string& text) {
  double speed = 0.0;
  if (text == "max" || !CLI::detail::lexical_cast(text, speed)) return 0.0;
  return speed;
}

const CLI::Validator kSpeed(
    [](const std::string& text) -> std::string {
      double speed = 0.0;
      if (text != "max" &&
          (!CLI::detail::lexical_cast(text, speed) || !(speed >= plinth::host::kMinReplaySpeed) ||
           !(speed <= plinth::host::kMaxReplaySpeed))) {
        return "must be a factor of real time from " +
               plinth::host::number_text(plinth::host::kMinReplaySpeed) + " to " +
               plinth::host::number_text(plinth::host::kMaxReplaySpeed) + ", or 'max', got '" +
               text + "'";
      }
      return {};
    },
    "SPEED");

const CLI::Validator kSensorRate(
    [](const std::string& text) -> std::string {
      double rate = 0.0;
      if (!CLI::detail::lexical_cast(text, rate) || !std::isfinite(rate) || rate < kMinRateHz ||
          rate > kMaxRateHz) {
        return "must be 100 to 1000 Hz, got '" + text + "'";
      }
      return {};
    },
    "HZ");

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = request_stop;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: the signal must cut the pacing sleep short
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

// What to send: a candump log's sensor frames, or frames made from records.
struct Input {
  std::unique_ptr<plinth::hal::replay::FrameSchedule> schedule;
  std::string description;
  std::size_t clipped_samples = 0;
  std::int64_t skipped_log_lines = 0;
  std::int64_t log_drop_reports = 0;
  std::int64_t log_dropped_frames = 0;
};

Input open_input(const Options& opt, const CLI::App& app) {
  Input input;
  if (!is_candump_log(opt.record_path)) {
    if (app.count("--log-time") > 0) {
      throw InputError("--log-time: applies to a candump log input only (" + opt.record_path +
                       " is a record: its samples' time is its sampling interval)");
    }
    if (app.count("--log-drops") > 0) {
      throw InputError("--log-drops: applies to a candump log input only (" + opt.record_path +
                       " is a record: it has no DROPCOUNT lines)");
    }
    RecordPlan plan = plan_records(opt);
    input.description = plan.description;
    input.clipped_samples = plan.clipped;
    input.schedule = std::make_unique<plinth::hal::replay::RecordSchedule>(std::move(plan.nodes),
                                                                      opt.rate_hz, opt.loops);
    return input;
  }
  for (const char* option :
       {"--pga", "--scale", "--rate", "--record-y", "--record-z", "--node-record", "--node"}) {
    if (app.count(option) > 0) {
      throw InputError(std::string(option) + ": does not apply to a candump log input (" +
                       opt.record_path + "): its sensor frames are sent again as logged");
    }
  }
  const auto policy = [](const std::string& text, const char* option) {
    return text.empty() ? plinth::hal::LogPolicy::kWarn
                        : plinth::host::parse_name<plinth::hal::kLogPolicyNames>(text, option,
                                                                                 "policy");
  };
  plinth::hal::replay::LoggedFrames logged = plinth::hal::replay::read_logged_sensor_frames(
      opt.record_path, opt.t_end_s.value_or(-1.0), policy(opt.log_time, "--log-time"),
      policy(opt.log_drops, "--log-drops"));
  for (const std::string& warning : logged.time_warnings) {
    std::fprintf(stderr, "plinth-replay: warning: %s\n", warning.c_str());
  }
  for (const std::string& warning : logged.drop_warnings) {
    std::fprintf(stderr, "plinth-replay: warning: %s\n", warning.c_str());
  }
  if (logged.drop_reports > 0) {
    std::fprintf(stderr,
                 "plinth-replay: warning: %s: %lld frames lost in %lld DROPCOUNT lines, not sent "
                 "(--log-drops refuse stops at the first)\n",
                 opt.record_path.c_str(), static_cast<long long>(logged.dropped_frames),
                 static_cast<long long>(logged.drop_reports));
  }
  input.log_drop_reports = logged.drop_reports;
  input.log_dropped_frames = logged.dropped_frames;
  if (logged.went_back + logged.jumps > 0) {
    std::fprintf(stderr,
                 "plinth-replay: warning: %s: %lld timestamps went back, %lld jumped forward "
                 "beyond %g s (--log-time refuse stops at the first)\n",
                 opt.record_path.c_str(), static_cast<long long>(logged.went_back),
                 static_cast<long long>(logged.jumps), plinth::hal::kMaxLogGapS);
  }
  input.skipped_log_lines = logged.skipped;
  char text[200];
  std::snprintf(text, sizeof text, "%s: %zu sensor frames over %.4g s", opt.record_path.c_str(),
                logged.frames.size(), static_cast<double>(logged.frames.back().virtual_ns) * 1e-9);
  input.description = text;
  input.schedule =
      std::make_unique<plinth::hal::replay::LogSchedule>(std::move(logged.frames), opt.loops);
  return input;
}

// The log (stamped by `clock`) or the bus.
Destination open_destination(const Options& opt, plinth::hal::CandumpLogWriter::Clock clock) {
  if (opt.log_path.empty()) return open_bus(opt.can_interface);
  // Written beside the target and renamed once complete (finish_log).
  const std::string temporary = opt.log_path + ".partial-" + std::to_string(::getpid());
  plinth::hal::CandumpLogWriterOpenResult opened =
      plinth::hal::CandumpLogWriter::open(temporary, opt.log_interface, std::move(clock));
  if (!opened.ok()) throw InputError("--log " + opt.log_path + ": " + opened.message);
  auto writer = std::make_unique<plinth::hal::CandumpLogWriter>(std::move(*opened.writer));
  Destination destination;
  destination.sink = writer.get();
  destination.log = std::move(writer);
  destination.name = opt.log_path;
  destination.temporary = temporary;
  return destination;
}

// The log renamed into place when every frame went into it. An interrupted run keeps what it
// sent as "<log>.partial"; a failed one keeps nothing: no log that looks complete is left.
void finish_log(const Destination& destination, const Report& report) {
  if (destination.log == nullptr) return;
  std::error_code error;
  if (report.send_errors == 0) {
    const std::string target =
        report.interrupted ? destination.name + ".partial" : destination.name;
    std::filesystem::rename(destination.temporary, target, error);
    if (!error) {
      if (report.interrupted) {
        std::fprintf(stderr, "plinth-replay: interrupted: the frames sent are in %s\n",
                     target.c_str());
      }
      return;
    }
    std::fprintf(stderr, "plinth-replay: --log %s: cannot replace it: %s\n", target.c_str(),
                 error.message().c_str());
  }
  std::filesystem::remove(destination.temporary, error);
  std::fprintf(stderr, "plinth-replay: --log %s not written (the run failed)\n",
               destination.name.c_str());
}

// Every frame of the schedule at its deadline; `current_virtual_ns` follows the frame being sent
// (the log's clock).
void send_all(plinth::hal::replay::FrameSchedule& schedule, const Destination& destination,
              plinth::hal::Pacer& pacer, std::int64_t& current_virtual_ns, Report& report) {
  plinth::hal::replay::ScheduledFrame next;
  while (schedule.next(next)) {
    if (!pacer.wait_until(next.virtual_ns, g_stop)) {
      report.interrupted = true;
      break;
    }
    current_virtual_ns = next.virtual_ns;
    pacer.record_send();
    const plinth::hal::IoStatus status = destination.send(next.frame);
    report.virtual_time_s = static_cast<double>(next.virtual_ns) * 1e-9;
    if (status != plinth::hal::IoStatus::kOk) {
      if (report.send_errors++ == 0) report.first_send_error = destination.error_text(status);
      if (destination.log != nullptr) break;  // a file does not recover from a failed write
      continue;
    }
    ++report.frames_sent;
    using plinth::hal::replay::FrameKind;
    ++(next.kind == FrameKind::kHeartbeat  ? report.heartbeat_frames
       : next.kind == FrameKind::kRotation ? report.rotation_frames
                                           : report.acceleration_frames);
  }
}

int run(const Options& opt, const CLI::App& app) {
  const double speed = parse_speed(opt.speed);
  if (!opt.log_path.empty()) {
    plinth::host::check_output_path("--log", opt.log_path);
    std::vector<std::pair<std::string, std::string>> inputs = {{"--record", opt.record_path},
                                                               {"--record-y", opt.record_y_path},
                                                               {"--record-z", opt.record_z_path}};
    for (const std::string& text : opt.node_records) inputs.emplace_back("--node-record", text);
    plinth::host::check_distinct_files({{"--log", opt.log_path}}, inputs);
  }
  const Input input = open_input(opt, app);
  // The log's timestamps are the frames' virtual send times (at speed 1) from now, so that
  // canplayer -I replays the log in real time whatever --speed wrote it.
  std::int64_t current_virtual_ns = 0;
  const std::int64_t log_epoch_ns = plinth::hal::realtime_now_ns();
  const Destination destination = open_destination(
      opt, [&current_virtual_ns, log_epoch_ns] { return log_epoch_ns + current_virtual_ns; });

  std::fprintf(stderr, "plinth-replay: %s; %lld loop%s to %s\n", input.description.c_str(),
               static_cast<long long>(opt.loops), opt.loops == 1 ? "" : "s",
               destination.name.c_str());
  install_stop_handlers();
  Report report;
  report.skipped_log_lines = input.skipped_log_lines;
  report.log_drop_reports = input.log_drop_reports;
  report.log_dropped_frames = input.log_dropped_frames;
  report.clipped_samples = input.clipped_samples;
  plinth::hal::Pacer pacer(speed);
  pacer.start();
  send_all(*input.schedule, destination, pacer, current_virtual_ns, report);
  report.wall_time_s = pacer.elapsed_s();
  if (destination.log != nullptr && !destination.log->flush()) {
    ++report.send_errors;
    if (report.first_send_error.empty()) report.first_send_error = destination.log->error();
  }
  print_report(opt, report, pacer, destination.name);
  finish_log(destination, report);
  if (report.interrupted) return kExitInterrupted;
  return report.send_errors == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "plinth-replay: send recorded earthquakes as plinth sensor frames on a CAN bus "
      "(SocketCAN) or into a candump log, in real time"};
  Options opt;
  app.add_option("--record", opt.record_path,
                 "x axis of --node: a record (.AT2, .ASC, .csv), or a candump log (.log) to "
                 "send again")
      ->required();
  app.add_option("--record-y", opt.record_y_path, "y axis of --node (.AT2, .ASC, .csv)");
  app.add_option("--record-z", opt.record_z_path,
                 "z axis of --node: vertical ground acceleration, positive up (.AT2, .ASC, .csv)");
  app.add_option("--node-record", opt.node_records,
                 "another node's axis: NODE:AXIS:FILE or NODE:FILE (axis x); repeatable")
      ->allow_extra_args(false);
  app.add_option("--node", opt.node, "sensor node of --record, --record-y, --record-z (1-15)")
      ->check(CLI::Range(1, 15));
  auto* pga = app.add_option("--pga", opt.pga,
                             "scale every record by the factor that gives --record this PGA, "
                             "e.g. 0.3g");
  app.add_option("--scale", opt.scale, "scale factor of every record")
      ->excludes(pga)
      ->check(plinth::host::kFinite);
  app.add_option("--rate", opt.rate_hz, "sensor output rate, Hz (100-1000)")->check(kSensorRate);
  app.add_option("--speed", opt.speed, "speed factor: 1 real time, 2 twice as fast, max no pacing")
      ->check(kSpeed);
  app.add_option("--loop", opt.loops, "send the input this many times")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000000}));
  app.add_option("--t-end", opt.t_end_s, "send only the first T-END seconds of the input")
      ->check(plinth::host::kFinitePositive);
  auto* can = app.add_option("--can", opt.can_interface, "SocketCAN interface, e.g. vcan0");
  auto* log = app.add_option("--log", opt.log_path, "write a candump log instead of using a bus")
                  ->excludes(can);
  app.add_option("--log-interface", opt.log_interface,
                 "interface name written in the log (default vcan0)")
      ->needs(log);
  app.add_option("--log-time", opt.log_time,
                 "a candump log's timestamps that go back or jump beyond 10 s: warn (default: "
                 "named on stderr, sent at the previous time / as a 10 s gap) or refuse");
  app.add_option("--log-drops", opt.log_drops,
                 "a candump log's DROPCOUNT lines (frames its logger lost, which cannot be "
                 "sent): warn (default: named on stderr, counted) or refuse");
  app.add_flag("--report-json", opt.report_json,
               "also print the report as one JSON line on stdout");
  if (const std::optional<int> exit_code = plinth::host::parse_command_line(app, argc, argv)) {
    return *exit_code;
  }
  if (opt.can_interface.empty() && opt.log_path.empty()) {
    std::fprintf(stderr,
                 "plinth-replay: give --can INTERFACE (a bus) or --log FILE (a candump log)\n");
    return 2;
  }
  return plinth::host::run_tool("plinth-replay", [&] { return run(opt, app); });
}
