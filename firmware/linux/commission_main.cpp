// plinth-commission: the check a custodian runs once on site, before the box is trusted
// (docs/commissioning.md). Live on a CAN bus, it prompts for each step of the procedure (rest,
// each ground and plate sensor on a wedge, the statue raised on one side, rest again) and
// records the bus; on a candump log (a site's recording, a test's) it finds the steps in the data
// or takes them from --window. Each sensor's gravity, level, axes, heading and gain, the
// statue sensor's accelerometer and gyroscope against the statue's raise, and every node's
// presence and uniqueness are checked against the box file. The report (JSON), its picture and
// the session's frames go to the recorder's folder, where plinth-monitor reads the newest.
#include <poll.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "commission_checks.h"
#include "commission_report.h"
#include "commission_session.h"
#include "monitor_config.h"
#include "plinth/firmware/record_replay.h"
#include "plinth/hal/candump_log.h"
#include "plinth/hal/pacing.h"
#include "plinth/hal/socketcan.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/version/version.h"
#include "run_identity.h"

namespace {

namespace fw = plinth::firmware;
namespace fs = std::filesystem;
using plinth::host::InputError;

constexpr int kFailedExit = 4;      // the check ran and failed (its report is written)
constexpr double kSettleS = 1.0;    // s after Enter before a window starts (hands away)
constexpr double kStandingS = 3.0;  // s: the statue standing just before and after a raise
constexpr double kCensusS = 2.0;    // s of listening before the first prompt
constexpr int kReceiveTimeoutMs = 20;
// The socket's receive buffer: a session is no real-time loop, and a busy machine must not cost
// it frames (some 4 s of 5 nodes at 1000 Hz).
constexpr int kReceiveBufferBytes = 4 << 20;

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) { g_stop = 1; }

struct Options {
  std::string config_path;
  std::string can_interface;
  std::string log_path;
  std::string record_dir;
  std::string report_path;
  std::vector<std::string> windows;
  std::optional<double> wedge_deg;
  std::optional<double> rest_s;
  std::optional<double> hold_s;
  bool no_picture = false;
};

// "NAME=T0:T1" (s from the log's first frame) for a step's window.
std::pair<std::string, fw::Window> parse_window(const std::string& text,
                                                const std::vector<fw::Step>& steps) {
  const std::size_t eq = text.find('=');
  const std::size_t colon = text.find(':', eq == std::string::npos ? 0 : eq);
  const std::string usage = "--window " + text +
                            ": expected NAME=T0:T1 (s from the log's first "
                            "frame, T0 < T1)";
  if (eq == std::string::npos || colon == std::string::npos) throw InputError(usage);
  const std::string name = text.substr(0, eq);
  bool known = false;
  std::string names;
  for (const fw::Step& step : steps) {
    names += (names.empty() ? "" : ", ") + step.name;
    known = known || name == step.name;
    if (step.kind == fw::StepKind::kStatueRaise) {
      for (const char* part : {"before", "after"}) {
        known = known || name == fw::window_name(step, part);
      }
    }
  }
  if (!known) {
    throw InputError("--window " + text + ": no step " + name + " in this box file's procedure (" +
                     names + "; a statue raise's -before and -after too)");
  }
  char* end = nullptr;
  const std::string t0_text = text.substr(eq + 1, colon - eq - 1);
  const std::string t1_text = text.substr(colon + 1);
  const double t0 = std::strtod(t0_text.c_str(), &end);
  if (end == t0_text.c_str() || *end != '\0') throw InputError(usage);
  const double t1 = std::strtod(t1_text.c_str(), &end);
  if (end == t1_text.c_str() || *end != '\0' || !std::isfinite(t0) || !std::isfinite(t1) ||
      t0 < 0.0 || t1 <= t0) {
    throw InputError(usage);
  }
  return {name, fw::Window{t0, t1, fw::WindowSource::kOption}};
}

// What the custodian does in each step (and the windows it records), live.
struct Prompt {
  std::string window;  // the window's name
  std::string text;
  double seconds = 0.0;
};

std::vector<Prompt> prompts(const fw::Step& step,
                            const std::vector<fw::CommissionedSensor>& sensors,
                            const fw::CommissioningSettings& s) {
  char text[600];
  switch (step.kind) {
    case fw::StepKind::kRest:
      std::snprintf(text, sizeof text,
                    "Rest: nobody touches the plinth, the statue or a sensor; no one walks "
                    "near. Press Enter, then keep still for %.0f s.",
                    s.rest_s);
      return {{step.name, text, s.rest_s}};
    case fw::StepKind::kWedge: {
      const fw::CommissionedSensor& c = sensors[static_cast<std::size_t>(step.sensor)];
      const char* side = step.axis == 0 ? "+x" : "+y";
      std::snprintf(text, sizeof text,
                    "%s: %sput the %.1f deg wedge under the sensor's %s side (the side toward "
                    "the statue's %s mark), so that this side is raised; hands off. Press Enter, "
                    "then keep still for %.0f s.",
                    c.label.c_str(),
                    step.axis == 0 ? "" : "take the wedge from under the +x side and ", s.wedge_deg,
                    side, side, s.hold_s);
      return {{step.name, text, s.hold_s}};
    }
    case fw::StepKind::kStatueRaise: {
      const char* side = step.axis == 0 ? "+x" : "+y";
      const char* edge = step.axis == 0 ? "-x" : "-y";
      std::vector<Prompt> out;
      std::snprintf(text, sizeof text,
                    "Statue, its %s side: every sensor on its marks, hands off the statue. Press "
                    "Enter, then keep still for %.0f s.",
                    side, kStandingS);
      out.push_back({fw::window_name(step, "before"), text, kStandingS});
      std::snprintf(text, sizeof text,
                    "Raise the statue's %s side by 5 to 10 mm (it turns on its %s edge: a "
                    "conservator's jack or lever, as when shims are set) and hold it still. Press "
                    "Enter, then hold it for %.0f s.",
                    side, edge, s.hold_s);
      out.push_back({step.name, text, s.hold_s});
      std::snprintf(text, sizeof text,
                    "Lower the statue back onto its seat; hands off. Press Enter, then keep still "
                    "for %.0f s.",
                    kStandingS);
      out.push_back({fw::window_name(step, "after"), text, kStandingS});
      return out;
    }
    case fw::StepKind::kFinalRest:
      std::snprintf(text, sizeof text,
                    "Final rest: every sensor back on its marks (and fixed), the wedge away, the "
                    "statue on its seat; nobody touches anything. Press Enter, then keep still "
                    "for %.0f s.",
                    s.rest_s);
      return {{step.name, text, s.rest_s}};
  }
  return {};
}

// A live session: the bus recorded while the custodian is prompted through the steps.
class LiveSession {
 public:
  LiveSession(plinth::hal::SocketCanPort port, std::string interface_name)
      : port_(std::move(port)), interface_(std::move(interface_name)) {}

  // Receives for `seconds` (monotonic), or until a line on stdin when `until_line`; the line
  // ("" for Enter). False at a signal or when stdin closed.
  bool listen(double seconds, bool until_line, std::string& line) {
    const std::int64_t end = plinth::hal::monotonic_now_ns() + std::llround(seconds * 1e9);
    std::string typed;
    for (;;) {
      if (g_stop != 0) return false;
      if (!until_line && plinth::hal::monotonic_now_ns() >= end) return true;
      receive();
      if (!until_line) continue;
      pollfd in{STDIN_FILENO, POLLIN, 0};
      if (::poll(&in, 1, 0) <= 0) continue;
      char c = 0;
      const ssize_t n = ::read(STDIN_FILENO, &c, 1);
      if (n <= 0) return false;  // stdin closed
      if (c == '\n') {
        line = typed;
        return true;
      }
      typed.push_back(c);
    }
  }

  // Records a window: `seconds` of frames after kSettleS, counted down on the terminal.
  fw::Window record(double seconds) {
    std::string ignored;
    listen(kSettleS, false, ignored);
    const double t0 = now_s();
    for (double left = seconds; left > 0.0 && g_stop == 0; left -= 1.0) {
      std::printf("\r  recording... %2.0f s ", std::ceil(left));
      std::fflush(stdout);
      listen(std::min(1.0, left), false, ignored);
    }
    std::printf("\r  recorded.          \n");
    return {t0, now_s(), fw::WindowSource::kPrompt};
  }

  [[nodiscard]] const fw::SessionRecording& session() const { return session_; }
  [[nodiscard]] const std::string& log_text() const { return log_; }
  [[nodiscard]] std::uint64_t bus_errors() const { return bus_errors_; }
  [[nodiscard]] std::uint64_t dropped() const { return port_.total_dropped_frames(); }

 private:
  // s of the session's clock (the kernel's receive clock) now.
  double now_s() const {
    return session_.started() ? session_.seconds(plinth::hal::realtime_now_ns()) : 0.0;
  }

  // Waits up to kReceiveTimeoutMs for the bus, then takes every frame queued.
  void receive() {
    plinth::hal::TimedFrame frame;
    for (int timeout_ms = kReceiveTimeoutMs;; timeout_ms = 0) {
      const plinth::hal::IoStatus status = port_.receive(frame, timeout_ms);
      if (status == plinth::hal::IoStatus::kOk) {
        session_.take(frame);
        log_ += plinth::hal::format_candump_line(frame.timestamp_ns, interface_, frame.frame);
        log_ += '\n';
      } else if (status == plinth::hal::IoStatus::kBusError ||
                 status == plinth::hal::IoStatus::kOverflow) {
        ++bus_errors_;
      } else if (status == plinth::hal::IoStatus::kIoError) {
        throw InputError("CAN interface " + interface_ +
                         ": receive failed: " + std::strerror(port_.last_error()));
      } else if (status == plinth::hal::IoStatus::kTimeout) {
        return;
      }
    }
  }

  plinth::hal::SocketCanPort port_;
  std::string interface_;
  fw::SessionRecording session_;
  std::string log_;
  std::uint64_t bus_errors_ = 0;
};

void print_checks(const std::vector<fw::CheckResult>& checks) {
  for (const fw::CheckResult& c : checks) {
    std::printf("  %s %s: %s\n", c.passed ? "ok  " : "FAIL", c.subject.c_str(), c.message.c_str());
  }
}

// The census after the first seconds: who is heard, who is missing, who is not expected.
void print_census(const fw::SessionRecording& session,
                  const std::vector<fw::CommissionedSensor>& sensors) {
  std::printf("Heard in %.0f s:", session.duration_s());
  bool any = false;
  for (int id = 1; id < fw::kNodeSlots; ++id) {
    const fw::NodeRecording& node = session.node(id);
    if (node.acceleration_traffic.frames + node.rate_traffic.frames == 0) continue;
    std::printf(" node %d (%.0f Hz)", id, node.acceleration_traffic.rate_hz());
    any = true;
  }
  std::printf("%s\n", any ? "" : " no sensor at all: is the bus up, and the sensors powered?");
  for (const fw::CommissionedSensor& s : sensors) {
    if (session.node(s.node).acceleration_traffic.frames == 0) {
      std::printf("  MISSING %s: not heard yet\n", s.label.c_str());
    }
  }
}

struct Outcome {
  fw::CommissionInput input;
  fw::CommissionResult result;
  std::string log_text;  // live: the session's frames
};

Outcome run_live(const Options& opt, fw::CommissionInput input) {
  plinth::hal::SocketCanOptions options;
  options.receive_buffer_bytes = kReceiveBufferBytes;
  plinth::hal::SocketCanOpenResult opened =
      plinth::hal::SocketCanPort::open(opt.can_interface, options);
  if (!opened.ok()) throw InputError(opened.message);
  LiveSession live(std::move(*opened.port), opt.can_interface);
  std::printf(
      "plinth-commission on %s: %zu steps. Stop the box first (systemctl stop "
      "plinth-monitor@%s): to it a tilted sensor is shaking.\n",
      opt.can_interface.c_str(), input.steps.size(), opt.can_interface.c_str());
  std::string line;
  if (!live.listen(kCensusS, false, line)) throw InputError("stopped");
  print_census(live.session(), input.sensors);
  std::size_t number = 0;
  for (const fw::Step& step : input.steps) {
    ++number;
    for (;;) {
      for (const Prompt& p : prompts(step, input.sensors, input.settings)) {
        std::printf("\n[%zu/%zu] %s\n> ", number, input.steps.size(), p.text.c_str());
        std::fflush(stdout);
        if (!live.listen(0.0, true, line)) {
          throw InputError("stopped at step " + step.name +
                           " (stdin closed or a signal): no "
                           "report written");
        }
        input.given[p.window] = live.record(p.seconds);
      }
      input.session = &live.session();
      const std::vector<fw::CheckResult> checks = fw::check_step(input, step);
      print_checks(checks);
      const bool passed = std::all_of(checks.begin(), checks.end(),
                                      [](const fw::CheckResult& c) { return c.passed; });
      if (passed) break;
      std::printf("This step failed. Press Enter to go on, or r and Enter to do it again.\n> ");
      std::fflush(stdout);
      if (!live.listen(0.0, true, line)) throw InputError("stopped at step " + step.name);
      if (line != "r" && line != "R") break;
    }
  }
  input.session = &live.session();
  Outcome out{input, fw::commission(input), live.log_text()};
  if (live.bus_errors() + live.dropped() > 0) {
    out.result.checks.push_back(
        {"bus", "bus-errors", false,
         std::to_string(live.bus_errors()) + " error reports, " + std::to_string(live.dropped()) +
             " frames dropped",
         "none",
         "the bus reported errors or the kernel dropped frames during the session: check the "
         "wiring and termination, then commission again"});
    out.result.passed = false;
  }
  return out;
}

fw::SessionRecording read_log(const std::string& path) {
  plinth::hal::CandumpLogReaderOpenResult opened = plinth::hal::CandumpLogReader::open(path);
  if (!opened.ok()) throw InputError(opened.message);
  plinth::hal::CandumpLogReader& reader = *opened.reader;
  fw::SessionRecording session;
  plinth::hal::LogTimeCheck time;
  plinth::hal::TimedFrame frame;
  for (;;) {
    const plinth::hal::IoStatus status = reader.receive(frame, 0);
    if (status == plinth::hal::IoStatus::kEndOfInput) break;
    if (status == plinth::hal::IoStatus::kIoError) throw InputError(reader.error());
    if (status != plinth::hal::IoStatus::kOk) continue;
    const plinth::hal::LogTimeStep step = time.check(frame.timestamp_ns, frame.frame.id);
    if (step.problem == plinth::hal::LogTimeProblem::kWentBack ||
        step.problem == plinth::hal::LogTimeProblem::kStoodStill) {
      throw InputError(path + ":" + std::to_string(reader.line_number()) + ": " +
                       time.describe(step, frame.timestamp_ns) +
                       ": a commissioning takes a log in time order");
    }
    time.take(frame.timestamp_ns, frame.frame.id);
    session.take(frame);
  }
  if (!session.started()) throw InputError(path + ": no frame in the log");
  return session;
}

// Writes the report, its picture and (live) the session's frames; returns the report's path.
std::string write_report(const Options& opt, const Outcome& outcome, fw::ReportContext context) {
  std::string directory;
  std::string stem;
  if (!opt.report_path.empty()) {
    const fs::path p(opt.report_path);
    directory = p.has_parent_path() ? p.parent_path().string() : ".";
    stem = p.stem().string();
  } else {
    directory = opt.record_dir;
    stem = fw::report_stem(fw::newest_report_index(directory) + 1);
  }
  std::string error;
  if (!outcome.log_text.empty()) {
    context.record_name = stem + ".log";
    if (!fw::write_report_file(directory, context.record_name, outcome.log_text, error)) {
      throw InputError(error);
    }
  }
  if (!opt.no_picture) {
    const std::string title = std::string("plinth-commission: ") +
                              (outcome.result.passed ? "PASSED" : "FAILED") + ", " +
                              context.time_utc;
    const std::string png = fw::draw_picture(outcome.result, title, context.picture_note);
    if (!png.empty()) {
      context.picture_name = stem + ".png";
      if (!fw::write_report_file(directory, context.picture_name, png, error)) {
        throw InputError(error);
      }
    }
  } else {
    context.picture_note = "--no-picture";
  }
  // The JSON last: plinth-monitor takes the newest JSON, which comes with its files.
  const std::string name = stem + ".json";
  if (!fw::write_report_file(directory, name, fw::report_json(outcome.result, context), error)) {
    throw InputError(error);
  }
  if (!context.picture_note.empty() && context.picture_note != "--no-picture") {
    std::fprintf(stderr, "plinth-commission: warning: %s\n", context.picture_note.c_str());
  }
  return (fs::path(directory) / name).string();
}

int run(const Options& opt) {
  const bool live = !opt.can_interface.empty();
  if (live == !opt.log_path.empty()) {
    throw InputError("give exactly one input: --can INTERFACE (live) or --log FILE (a recording)");
  }
  fw::MonitorFile file = fw::load_monitor_file(opt.config_path, fw::box_defaults());
  fw::CommissioningSettings settings = file.commissioning;
  if (opt.wedge_deg) settings.wedge_deg = *opt.wedge_deg;
  if (opt.rest_s) settings.rest_s = *opt.rest_s;
  if (opt.hold_s) settings.hold_s = *opt.hold_s;
  if (const std::optional<fw::SettingError> e = fw::validate(settings)) {
    throw InputError(e->message + " (the box file's [commissioning], or the option)");
  }
  const int axis_count = file.second_scene_path.empty() ? 1 : 2;
  fw::CommissionInput input;
  input.sensors = fw::commissioned_sensors(file.config);
  input.steps = fw::plan_steps(input.sensors, axis_count);
  input.settings = settings;
  input.sample_rate_hz = file.config.estimator.sample_rate_hz;
  for (const std::string& w : opt.windows) input.given.insert(parse_window(w, input.steps));

  Options where = opt;
  if (live && where.record_dir.empty() && where.report_path.empty()) {
    where.record_dir = "/var/lib/plinth-monitor/" + opt.can_interface + "/events";
  }
  const bool writes = !where.record_dir.empty() || !where.report_path.empty();
  if (!where.record_dir.empty()) {  // before the session: a custodian's work is not lost
    std::error_code ec;
    fs::create_directories(where.record_dir, ec);
    if (::access(where.record_dir.c_str(), W_OK) != 0) {
      throw InputError("--record-dir " + where.record_dir + ": cannot write there (" +
                       std::strerror(errno) + "; run as the service's user: sudo -u plinth ...)");
    }
  }

  fw::SessionRecording recording;
  Outcome outcome;
  if (live) {
    outcome = run_live(opt, input);
  } else {
    recording = read_log(opt.log_path);
    input.session = &recording;
    outcome = Outcome{input, fw::commission(input), ""};
  }
  std::fputs(fw::summary_text(outcome.result).c_str(), stdout);

  fw::ReportContext context;
  context.version = plinth::version::kVersionText;
  context.time_utc = fw::utc_now();
  context.box_file = opt.config_path;
  context.box_file_sha256 = fw::hex(fw::file_sha256(opt.config_path));
  context.mounting_sha256 = fw::mounting_sha256(file.config);
  context.interface_name = opt.can_interface;
  if (!live) {
    context.log_path = opt.log_path;
    context.log_sha256 = fw::hex(fw::file_sha256(opt.log_path));
  }
  context.settings = settings;
  context.sample_rate_hz = input.sample_rate_hz;
  context.axis_count = axis_count;
  if (writes) {
    const std::string report = write_report(where, outcome, context);
    std::printf("report: %s\n", report.c_str());
  } else {
    std::printf("no report written (give --record-dir DIR or --report FILE.json)\n");
  }
  return outcome.result.passed ? 0 : kFailedExit;
}

constexpr const char* kFooter = R"(PROCEDURE (docs/commissioning.md)
  Stop the box first (systemctl stop plinth-monitor@can0): a tilted sensor is shaking to it.
  1. rest         nobody touches anything, rest_s (10 s): each accelerometer's gravity (its unit
                  and vertical gain), its level, its noise; the statue gyroscope's spread.
  2. tilt-x:N     for each ground and plate sensor N in the box file's order: a wedge of
     tilt-y:N     wedge_deg (5 deg) under its +x side, then under its +y side, hold_s (5 s):
                  the raise must read wedge_deg +- wedge_tolerance_deg toward +x, then +y:
                  heading (a sensor turned about the vertical), each horizontal axis's sign
                  and gain.
  3. statue-x     the statue's +x side raised by 5 to 10 mm and held (statue-y too, with a
     statue-y     second axis), its sensor standing before and after: the statue sensor must
                  tilt by statue_min_tilt_deg at least, toward +x (+y), its gyroscope turn as its
                  accelerometer tilts (sign, gain, deg/s for rad/s), the statue back on its seat.
  4. final-rest   everything back: each sensor level again, the statue seated as at the start.
  Throughout: every configured node heard at estimator.sample_rate_hz, none duplicated (two
  devices on one id), no node the box file does not name, no status flag, no frame lost.
  Live, each step is checked at once and may be done again (r, Enter). From a log, each step's
  window is found in the data (the first rest, each sensor's first and second leaning hold, the
  statue sensor's holds), or given: --window tilt-x:2=31.5:36 (s from the log's first frame).

WHAT ONE CHECK CANNOT SEE
  A sensor turned or moved after its step (bolting it down turned), a gain error common to a
  statue sensor's gyroscope and accelerometer, a statue sensor glued to the plinth when nobody
  raised the statue: docs/commissioning.md says what each step can and cannot detect.

FILES
  With --can IF the report goes to /var/lib/plinth-monitor/IF/events (the service's recorder
  folder; run as its user: sudo -u plinth plinth-commission ...), else to --record-dir DIR or
  --report FILE.json: commission-NNN.json (the report), .png (its picture, by gnuplot), .log (the
  session's frames, live). plinth-monitor reads the newest commission-NNN.json of its
  --record-dir at start and every 2 s: a failed one (or none, with commissioning.required) makes
  it show fault, cause commissioning_failed, unless overridden (commissioning.override or
  --commissioning-override REASON).

EXIT STATUS
  0 the check passed; 4 it failed (the report says why); 1 bad input, or the session stopped
  before its end (no report); 2 usage.)";

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "plinth-commission: check the box's sensors on site against its box file (gravity, level, "
      "axes, heading, gain, node ids, the statue sensor on the statue) and write the report "
      "plinth-monitor needs"};
  app.footer(kFooter);
  Options opt;
  app.add_option("--config", opt.config_path, "the box file (TOML; docs/monitor.md)")->required();
  app.add_option("--can", opt.can_interface, "live: the CAN interface, prompts on the terminal");
  app.add_option("--log", opt.log_path, "a candump log of a session (a site's recording)");
  app.add_option("--record-dir", opt.record_dir,
                 "write commission-NNN.json, .png (and .log, live) here (default with --can IF: "
                 "/var/lib/plinth-monitor/IF/events)");
  app.add_option("--report", opt.report_path,
                 "write the report to this file (the picture beside it)")
      ->excludes("--record-dir");
  app.add_option("--window", opt.windows,
                 "a step's window in a log, NAME=T0:T1 (s from its first frame); others are "
                 "found in the data");
  app.add_option("--wedge-deg", opt.wedge_deg, "the wedge's angle, deg (commissioning.wedge_deg)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--rest-s", opt.rest_s, "s of each rest, live (commissioning.rest_s)")
      ->check(plinth::host::kFinitePositive);
  app.add_option("--hold-s", opt.hold_s, "s of each raise held, live (commissioning.hold_s)")
      ->check(plinth::host::kFinitePositive);
  app.add_flag("--no-picture", opt.no_picture, "write no picture (no gnuplot on this machine)");
  const auto checks = [&] {
    const bool live = !opt.can_interface.empty();
    plinth::host::refuse_without_effect(app, {"--rest-s", "--hold-s"}, live,
                                        "times a live session's prompted windows; a log's windows "
                                        "are found in its data or given by --window");
    plinth::host::refuse_without_effect(app, {"--window"}, !live,
                                        "gives a step's window in a log; a live session takes "
                                        "its windows from the prompts");
  };
  if (const std::optional<int> exit_code =
          plinth::host::parse_command_line(app, argc, argv, checks)) {
    return *exit_code;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  return plinth::host::run_tool("plinth-commission", [&] { return run(opt); });
}
