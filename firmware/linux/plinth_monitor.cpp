// plinth-monitor: the box's application on Linux. Sensor samples from a file replay (AT2, CSV
// or a candump log) or a SocketCAN bus (inputs.h); the firmware loop (firmware/monitor)
// estimates the block's phase and overturning risk, raises alarms and hands over the frames to
// send. JSON Lines on stdout (status_json.h, docs/monitor.md): status lines when the monitor
// reports a status, alarm lines, phase events, and a summary at the end. Live, the monitor's
// status and alarm frames also go on the bus; a replay writes them to a candump log with
// --frames-out.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "box_state_store.h"
#include "commission_gate.h"
#include "event_recorder.h"
#include "inputs.h"
#include "latency_log.h"
#include "log_text.h"
#include "modbus_map.h"
#include "modbus_server.h"
#include "monitor_config.h"
#include "mqtt_publisher.h"
#include "plinth/firmware/can_frames.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/firmware/monitor.h"
#include "plinth/hal/candump_log.h"
#include "plinth/hal/pacing.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/parse_name.h"
#include "plinth/host/scene_toml.h"
#include "relay_gpiod.h"
#include "relay_outputs.h"
#include "run_identity.h"
#include "sample_trace.h"
#include "status_json.h"
#include "supervisor.h"

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
  std::string log_time;   // --log-time: warn or refuse; empty: not given (warn)
  std::string log_drops;  // --log-drops: the same
  double duration = 0.0;
  std::string record_dir;
  std::string state_dir;
  std::string frames_out;
  std::string trace_path;
  double pre_trigger = 30.0;
  double post_trigger = 60.0;
  bool quiet_events = false;
  bool latency = false;
  std::string commissioning_override;  // --commissioning-override REASON
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
// the status line when the monitor reports a status, a snapshot and the alarm events for the
// outputs off the loop (status_outputs.h); and the run's totals.
class Outputs {
 public:
  Outputs(const fw::Monitor& monitor, double t_origin, fw::EventRecorder* recorder,
          plinth::hal::FrameSink* bus, fw::RelayOutputs* relays,
          std::vector<fw::StatusOutput*> outputs)
      : monitor_(monitor),
        t_origin_(t_origin),
        recorder_(recorder),
        bus_(bus),
        relays_(relays),
        outputs_(std::move(outputs)),
        start_ns_(fw::monotonic_ns()) {
    post_snapshot(monitor.status());
  }

  void handle(const fw::MonitorUpdate& u) {
    const fw::BoxStatus& s = *u.status;
    if (relays_ != nullptr) {  // first: the alarm panel's contacts
      relays_->update(s.alarm, s.latched,
                      s.sensors_state == mon::HealthState::kFault || s.disagreement ||
                          s.trouble != mon::AlarmCause::kNone);
    }
    totals.max_risk = std::fmax(totals.max_risk, s.risk);
    for (std::size_t i = 0; i < u.frame_count; ++i) {
      if (bus_ != nullptr && bus_->send(u.frames[i]) != plinth::hal::IoStatus::kOk) {
        ++totals.bus_send_errors;
      }
    }
    if (u.regional_received) print_line(fw::regional_json(u.regional, s));  // before its events
    for (std::size_t i = 0; i < u.event_count; ++i) {
      const mon::AlarmEventRecord& e = u.events[i];
      print_line(fw::alarm_json(e, t_origin_));
      ++totals.alarm_events;
      if (e.level == mon::AlarmLevel::kFault) {
        ++totals.fault_events;
      } else if (static_cast<int>(e.level) > static_cast<int>(totals.max_level)) {
        totals.max_level = e.level;
      }
      if (e.level == mon::AlarmLevel::kWarning || e.level == mon::AlarmLevel::kAlarm) trigger(s, e);
      if (supervisor != nullptr) {
        supervisor->alarm_changed(e, static_cast<double>(e.time_ns) * 1e-9 - t_origin_);
      }
      post_alarm(e);
    }
    if (u.frames_lost > 0) note_frames_lost(s, u.frames_lost);
    if (state_ != nullptr) save_state();
    if (u.status_due) {
      // The first status line says what runs: the version, the scene and box files' digests,
      // the commissioning; every line the commissioning while it refuses or is overridden.
      std::string line = fw::status_json(s, t_origin_);
      if (snapshot_.statuses == 0) {
        line = fw::with_members(line, identity);
      } else if (!status_extra.empty()) {
        line = fw::with_members(line, status_extra);
      }
      if (recorder_ != nullptr) {
        const std::string health = fw::recorder_status_json(recorder_->status());
        line = fw::with_members(line, std::string("\"recorder\": ").append(health));
      }
      print_line(line);
      ++snapshot_.statuses;
    }
    if (trace != nullptr) trace->after_update(u, monitor_);
    post_snapshot(s);
  }

  // The outputs' operator commands, carried out on the loop: an acknowledgement and a statement
  // that the statue stands are the monitor's (as those from the bus); a reset starts the monitor
  // again (`restart`) with its memory (the latch, any collapse), refused while an alarm is
  // latched and unacknowledged.
  template <typename Restart>
  void carry_out_commands(fw::Monitor& monitor, Restart restart) {
    for (fw::StatusOutput* output : outputs_) {
      // Regional alerts (MQTT): at the loop's time now, relative to their receipt.
      fw::RegionalRequest r;
      while (output->mailbox().take_regional(r)) {
        handle(r.refusal != mon::RegionalRefusal::kNone
                   ? monitor.regional_alert_refused(r.refusal, r.field)
                   : monitor.on_regional_alert(r.alert));
      }
      fw::CommandRequest c;
      while (output->mailbox().take_command(c)) {
        ++snapshot_.commands;
        if (c.command == fw::OperatorCommand::kReset) {
          const bool refused = monitor.status().latched == mon::AlarmLevel::kAlarm;
          if (!refused) {
            const fw::BoxMemory memory = monitor.memory();
            restart();
            monitor.restore(memory);
            ++snapshot_.resets;
            snapshot_.any_event = false;
            snapshot_.cause = mon::AlarmCause::kNone;
          }
          print_line(command_line("reset", output->name())
                         .text("outcome", refused ? "refused: an alarm is latched, acknowledge "
                                                    "it first"
                                                  : "done")
                         .close());
          post_snapshot(monitor.status());
          output->mailbox().post_result({c.id, mon::AckOutcome::kNone,
                                         mon::StandsOutcome::kNone, refused});
          if (!refused) handle(monitor.poll());  // the restored level, at once
          continue;
        }
        if (c.command == fw::OperatorCommand::kStatueStands) {
          const fw::MonitorUpdate u = monitor.statue_stands(c.event_sequence);
          print_line(command_line("statue_stands", output->name())
                         .count("sequence", c.event_sequence)
                         .text("outcome", mon::stands_outcome_name(u.statue_stands))
                         .close());
          handle(u);
          output->mailbox().post_result({c.id, mon::AckOutcome::kNone, u.statue_stands});
          continue;
        }
        const fw::MonitorUpdate u = monitor.acknowledge({c.level, c.event_sequence});
        snapshot_.last_ack = u.acknowledgement;
        print_line(command_line("acknowledge", output->name())
                       .text("level", mon::alarm_level_name(c.level))
                       .count("sequence", c.event_sequence)
                       .text("outcome", mon::ack_outcome_name(u.acknowledgement))
                       .close());
        handle(u);
        output->mailbox().post_result({c.id, u.acknowledgement});
      }
    }
  }

  // The saved state (--state-dir): what the monitor must not forget, written when it changes.
  void keep_state_in(fw::BoxStateStore* state) { state_ = state; }

  // A line for an Acknowledge frame from the bus (unauthenticated: docs/monitor.md), as for a
  // command from MQTT or Modbus; the refused and the ignored (the bus locked out after refusals)
  // at most kBusRefusalLines a minute, the next line shown saying how many were not.
  void bus_acknowledgement(const plinth::hal::can::CanFrame& frame, const fw::MonitorUpdate& u,
                           const fw::FrameCounters& before, const fw::FrameCounters& after) {
    plinth::hal::can::Acknowledge ack;
    if (!plinth::hal::can::decode(frame, ack).ok()) return;
    const bool released = u.acknowledgement == mon::AckOutcome::kReleased ||
                          u.acknowledgement == mon::AckOutcome::kReleasedConditionHolds;
    const std::int64_t now = fw::monotonic_ns();
    if (!released && !bus_refusals_.allow(now)) return;
    const mon::Acknowledgement a = fw::acknowledgement_of(ack);
    fw::JsonObject line;
    line.text("type", "command")
        .text("command", "acknowledge")
        .text("source", "can")
        .count("source_id", ack.source_id)
        .text("level", mon::alarm_level_name(a.level))
        .count("sequence", a.event_sequence)
        .text("outcome", after.acknowledgements_ignored != before.acknowledgements_ignored
                             ? "ignored: bus acknowledgements locked out"
                             : mon::ack_outcome_name(u.acknowledgement));
    if (after.acknowledgement_lockouts != before.acknowledgement_lockouts) {
      line.flag("locks_out_the_bus", true);
      std::fprintf(stderr,
                   "plinth-monitor: can: %d acknowledgements refused within %g s: the bus's are "
                   "ignored while %s stays latched (acknowledge at the box, over MQTT or Modbus)\n",
                   fw::kRefusedStatementsBeforeLockout,
                   static_cast<double>(fw::kRefusedStatementWindowNs) * 1e-9,
                   mon::alarm_level_name(monitor_.status().latched));
    }
    if (!released) line.count("not_shown", bus_refusals_.take_not_shown());
    print_line(line.close());
  }

  // A line for a StatueStands frame from the bus (unauthenticated, guarded as acknowledgements
  // are: docs/monitor.md); the refused and the ignored share bus_acknowledgement's line budget.
  void bus_statue_stands(const plinth::hal::can::CanFrame& frame, const fw::MonitorUpdate& u,
                         const fw::FrameCounters& before, const fw::FrameCounters& after) {
    plinth::hal::can::StatueStands stands;
    if (!plinth::hal::can::decode(frame, stands).ok()) return;
    const bool cleared = u.statue_stands == mon::StandsOutcome::kCleared;
    if (!cleared && !bus_refusals_.allow(fw::monotonic_ns())) return;
    fw::JsonObject line = command_line("statue_stands", "can:" + std::to_string(stands.source_id));
    line.count("sequence", stands.event_sequence)
        .text("outcome", after.statue_stands_ignored != before.statue_stands_ignored
                             ? "ignored: bus statements locked out"
                             : mon::stands_outcome_name(u.statue_stands));
    if (after.statue_stands_lockouts != before.statue_stands_lockouts) {
      line.flag("locks_out_the_bus", true);
      std::fprintf(stderr,
                   "plinth-monitor: can: %d statue-stands statements refused within %g s: the "
                   "bus's are ignored while the collapse is held (state it at the box, over MQTT "
                   "or Modbus)\n",
                   fw::kRefusedStatementsBeforeLockout,
                   static_cast<double>(fw::kRefusedStatementWindowNs) * 1e-9);
    }
    if (!cleared) line.count("not_shown", bus_refusals_.take_not_shown());
    print_line(line.close());
  }

  fw::RunTotals totals;
  fw::SampleTrace* trace = nullptr;  // --trace
  fw::Supervisor* supervisor = nullptr;  // STATUS= and the journal at each alarm change
  std::string identity;  // run_identity.h's members, in the first status line
  std::string status_extra;  // members every later status line carries ("" none)
  std::int64_t last_frame_ns = 0;  // receive time of the newest frame (the recorder's clock)

 private:
  void trigger(const fw::BoxStatus& s, const mon::AlarmEventRecord& e) {
    if (recorder_ == nullptr) return;
    fw::TriggerInfo info;
    info.t = static_cast<double>(e.time_ns) * 1e-9 - t_origin_;
    info.level = mon::alarm_level_name(e.level);
    info.cause = mon::alarm_cause_name(e.cause);
    char detail[96];
    std::snprintf(detail, sizeof detail, "\"risk\": %.4f, \"phase\": \"%s\"", s.risk,
                  plinth::phase_name(s.axes[0].mode.phase));
    info.detail = detail;
    info.alarm = e.level == mon::AlarmLevel::kAlarm;
    recorder_->trigger(info, last_frame_ns);
  }

  static fw::JsonObject command_line(const char* command, const std::string& source) {
    fw::JsonObject line;
    line.text("type", "command").text("command", command).text("source", source);
    return line;
  }

  // A failed write is said once, and again after a write succeeded; the box goes on (its
  // memory is the process's until the folder takes writes again).
  void save_state() {
    const bool saved = state_->save(monitor_.memory(), fw::wall_clock_ns());
    if (!saved && !state_failing_) {
      std::fprintf(stderr, "plinth-monitor: error: cannot save the box's state: %s\n",
                   state_->error().c_str());
    } else if (saved && state_failing_) {
      std::fprintf(stderr, "plinth-monitor: the box's state is saved again (%s)\n",
                   state_->path().c_str());
    }
    state_failing_ = !saved;
  }

  // Frames the update could not carry: said on stderr (the first, then at every power of two),
  // counted in the status (frames_not_encoded) and the summary.
  void note_frames_lost(const fw::BoxStatus& s, std::size_t lost) {
    const std::uint64_t before = frames_lost_;
    frames_lost_ += lost;
    if ((before & frames_lost_) != 0 && before != 0) return;  // not across a power of two
    std::fprintf(stderr,
                 "plinth-monitor: error: %zu frame(s) not sent at t = %.3f s (the codec refused "
                 "them; %llu in all, frames_not_encoded in the status)\n",
                 lost, static_cast<double>(s.time_ns) * 1e-9 - t_origin_,
                 static_cast<unsigned long long>(frames_lost_));
  }

  void post_alarm(const mon::AlarmEventRecord& e) {
    snapshot_.cause = e.cause;
    snapshot_.event_sequence = e.sequence;
    snapshot_.any_event = true;
    for (fw::StatusOutput* output : outputs_) output->mailbox().post_alarm({e, t_origin_});
  }

  void post_snapshot(const fw::BoxStatus& status) {
    if (outputs_.empty()) return;
    fw::copy_status(status, t_origin_, snapshot_);
    if (recorder_ != nullptr) snapshot_.recorder = recorder_->status();
    ++snapshot_.updates;
    snapshot_.wall_time_ns = fw::wall_clock_ns();
    snapshot_.uptime_ns = fw::monotonic_ns() - start_ns_;
    for (fw::StatusOutput* output : outputs_) output->mailbox().post_status(snapshot_);
  }

  const fw::Monitor& monitor_;
  double t_origin_;
  fw::EventRecorder* recorder_;
  plinth::hal::FrameSink* bus_;
  fw::RelayOutputs* relays_;
  std::vector<fw::StatusOutput*> outputs_;
  std::int64_t start_ns_;
  fw::StatusSnapshot snapshot_;
  fw::BoxStateStore* state_ = nullptr;
  bool state_failing_ = false;
  std::uint64_t frames_lost_ = 0;
  fw::BurstLimit bus_refusals_{5, 60.0};  // bus_acknowledgement's refused lines
};

// The monitor takes one input item.
void take(const fw::InputItem& item, fw::Monitor& monitor, fw::FrameDecoder& decoder,
          Outputs& outputs, fw::EventRecorder* recorder) {
  switch (item.kind) {
    case fw::InputItem::Kind::kSample:
      if (recorder != nullptr && item.has_frame) recorder->on_frame(item.frame);
      outputs.last_frame_ns = item.sample.receive_time_ns;
      outputs.handle(monitor.on_sample(item.sample));
      ++outputs.totals.samples;
      break;
    case fw::InputItem::Kind::kFrame: {
      if (recorder != nullptr) recorder->on_frame(item.frame, item.lost_before);
      outputs.last_frame_ns = item.frame.timestamp_ns;
      const fw::FrameCounters before = decoder.counters();
      const fw::MonitorUpdate u = fw::on_frame(monitor, decoder, item.frame);
      if (decoder.counters().acknowledgements != before.acknowledgements) {
        outputs.bus_acknowledgement(item.frame.frame, u, before, decoder.counters());
      }
      if (decoder.counters().statue_stands != before.statue_stands) {
        outputs.bus_statue_stands(item.frame.frame, u, before, decoder.counters());
      }
      outputs.handle(u);
      break;
    }
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
      {"node", "--node"},
      {"base.", "--scene"}};
  for (const auto& [key, option] : kOptions) {
    if (field.find(key) != std::string::npos) return option;
  }
  return "";
}

// Each axis's ensemble: the scene file's statue first, then the corners of its [uncertainty]
// (one member when it declares none). Monitor::start's error names the option or the file that
// gave the setting. The frames' decoder starts afresh with it.
void start_monitor(fw::Monitor& monitor, fw::FrameDecoder& decoder,
                   const fw::MonitorConfig& config, const plinth::host::UncertainScene& scene_x,
                   const std::optional<plinth::host::UncertainScene>& scene_y,
                   const CLI::App& app, const std::string& config_path) {
  const plinth::Error e = monitor.start(
      config, {std::span<const plinth::Scene>(scene_x.members),
               scene_y ? std::span<const plinth::Scene>(scene_y->members)
                       : std::span<const plinth::Scene>()});
  if (e.ok()) {
    decoder.start(config);
    return;
  }
  // Too few steps per sample where even the most the box takes (64) are too few: the scene's
  // base is the culprit, too stiff or light for the box (lib/core estimator.cpp).
  const bool steps_needed = std::string(e.field) == "estimator.steps_per_sample" && e.limit > 0.0;
  if (steps_needed && std::ceil(e.limit) > 64.0) {
    throw InputError("--scene " + app["--scene"]->as<std::string>() +
                     " (base.period): too short for the box: a stable estimate needs " +
                     plinth::host::number_text(std::ceil(e.limit)) +
                     " solver steps a sample at this rate, more than the 64 the box takes (a "
                     "longer base.period, a heavier base, or a lower sample rate)");
  }
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
  if (steps_needed) {
    message += " (limit " + plinth::host::number_text(std::ceil(e.limit)) + ")";
  } else if (e.limit != 0.0 && std::isfinite(e.limit) && message.find('[') == std::string::npos) {
    message += " (limit " + plinth::host::number_text(e.limit) + ")";
  }
  throw InputError(message);
}

std::unique_ptr<fw::EventRecorder> make_recorder(const Options& opt, const fw::MonitorFile& file,
                                                 const std::string& identity) {
  if (opt.record_dir.empty()) return nullptr;
  fw::EventRecorderSettings rs;
  rs.directory = opt.record_dir;
  rs.interface_name = opt.can_interface.empty() ? "can0" : opt.can_interface;
  rs.pre_trigger_s = opt.pre_trigger;
  rs.post_trigger_s = opt.post_trigger;
  rs.frame_rate_hz = fw::recorder_frame_rate_hz(file);
  rs.retention = file.recorder.retention;
  rs.test_pause_mid_write_s = file.recorder.test_pause_mid_write_s;
  rs.identity_json = identity;
  return std::make_unique<fw::EventRecorder>(rs);
}

// The relays' lines, requested released (contacts open) until the monitor says otherwise.
std::unique_ptr<fw::RelayOutputs> make_relays(const fw::RelaySettings& settings) {
  if (!settings.enabled()) return nullptr;
  return std::make_unique<fw::RelayOutputs>(settings, fw::open_gpiod_relays(settings));
}

// Takes the input until it ends or a signal; systemd's watchdog hears of every item taken.
// The loop: each input item taken, its latency noted (--latency), the network outputs' operator
// commands carried out, the watchdog told of the progress. True when the estimators ran at some
// point.
template <typename Restart, typename Poll>
bool run_loop(fw::MonitorInput& input, fw::Monitor& monitor, fw::FrameDecoder& decoder,
              Outputs& outputs, fw::EventRecorder* recorder, fw::Supervisor& supervisor,
              fw::LatencyLog* latency, fw::LatencyLog* due_latency, Restart restart, Poll poll) {
  supervisor.ready("monitoring " + input.source());
  fw::InputItem item;
  bool estimated = false;
  while (g_stop == 0 && input.next(item)) {
    const std::int64_t arrival_ns = latency != nullptr ? fw::monotonic_ns() : 0;
    take(item, monitor, decoder, outputs, recorder);
    estimated = estimated || monitor.status().estimating;
    if (latency != nullptr && item.kind != fw::InputItem::Kind::kTick &&
        item.kind != fw::InputItem::Kind::kBusFault) {
      const std::int64_t ready_ns = fw::monotonic_ns();
      latency->add(ready_ns - arrival_ns);
      if (item.due_ns > 0) due_latency->add(ready_ns - item.due_ns);
    }
    outputs.carry_out_commands(monitor, restart);
    const std::int64_t now_ns = plinth::hal::monotonic_now_ns();
    if (supervisor.stall_due(now_ns)) {  // test only: a hung loop pings no more, even at its end
      fw::Supervisor::stall(g_stop);
      continue;
    }
    supervisor.on_progress(now_ns);
    poll(now_ns);
  }
  supervisor.stopping();
  return estimated;
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
  if (!opt.log_time.empty()) {
    in.log_time = plinth::host::parse_name<plinth::hal::kLogPolicyNames>(
        opt.log_time, "--log-time", "policy");
  }
  if (!opt.log_drops.empty()) {
    in.log_drops = plinth::host::parse_name<plinth::hal::kLogPolicyNames>(
        opt.log_drops, "--log-drops", "policy");
  }
  return in;
}

// The summary's totals besides the monitor's own counters.
fw::RunTotals run_totals(const Outputs& outputs, fw::MonitorInput& input,
                         const fw::Monitor& monitor, const fw::FrameDecoder& decoder,
                         const fw::EventRecorder* recorder, const std::vector<AxisEvents>& sinks) {
  fw::RunTotals t = outputs.totals;
  t.source = input.source();
  t.frames = decoder.counters();
  t.samples += t.frames.sensor_samples;
  for (const AxisEvents& sink : sinks) t.phase_events += sink.count;
  const fw::InputTimeCounters time = input.time_counters();
  t.log_time_back = time.went_back;
  t.log_time_still = time.stood_still;
  t.log_time_gaps = time.gaps;
  const fw::InputDropCounters drops = input.drop_counters();
  t.log_drop_reports = drops.reports;
  t.log_drop_frames = drops.frames;
  const fw::BusCounters bus = input.bus_counters();
  t.bus_errors = bus.bus_errors;
  t.bus_dropped_frames = bus.dropped_frames;
  if (input.sink() != nullptr) t.bus_send_errors += monitor.frames_not_encoded();
  if (recorder != nullptr) {
    t.recorder = true;
    t.recorder_status = recorder->status();
    t.captures_dropped = recorder->captures_dropped();
    t.recorder_write_errors = recorder->write_errors();
    t.frames_lost = recorder->frames_lost();
    t.recorder_first_index = recorder->first_index();
    t.partial_files_removed = static_cast<std::uint64_t>(recorder->partial_files_removed());
  }
  return t;
}

// Samples whose latency --latency keeps (4 bytes each); later ones are counted only.
constexpr std::size_t kLatencyCapacity = std::size_t{1} << 22;

// The outputs off the loop that the configuration enables, each given the run's identity once.
std::vector<std::unique_ptr<fw::StatusOutput>> start_outputs(const fw::MonitorFile& file,
                                                             const fw::RunIdentity& identity) {
  std::vector<std::unique_ptr<fw::StatusOutput>> outputs;
  if (!file.modbus.listen.empty()) {
    outputs.push_back(std::make_unique<fw::ModbusServer>(file.modbus, identity));
  }
  if (!file.mqtt.broker.empty()) {
    fw::MqttSettings mqtt = file.mqtt;
    if (const auto* room = mon::built_part<mon::RegionalAlertSettings>(file.config.regional)) {
      mqtt.regional = *room;  // its fragility ranks a burst, its key authenticates
    }
    outputs.push_back(std::make_unique<fw::MqttPublisher>(mqtt, identity));
  }
  return outputs;
}

// A file replay that ends without the box vouching for it: no estimator ever ran (an empty
// log, no usable sensor frame), the log's time could not be monitor time, or the log lost
// frames. Says why on stderr; "" when the run is sound (a live bus is judged by its own fault
// levels).
std::string input_fault(fw::MonitorInput& input, bool estimated) {
  const fw::InputTimeCounters time = input.time_counters();
  const fw::InputDropCounters drops = input.drop_counters();
  if (time.total() > 0) {
    std::fprintf(stderr,
                 "plinth-monitor: fault: %s (%llu timestamps back, %llu standing still, %llu "
                 "gaps beyond %g s in all)\n",
                 time.first.c_str(), static_cast<unsigned long long>(time.went_back),
                 static_cast<unsigned long long>(time.stood_still),
                 static_cast<unsigned long long>(time.gaps), fw::kMaxLogGapS);
  }
  if (drops.reports > 0) {
    std::fprintf(stderr,
                 "plinth-monitor: fault: %s (%llu frames lost in %llu DROPCOUNT lines in all)\n",
                 drops.first.c_str(), static_cast<unsigned long long>(drops.frames),
                 static_cast<unsigned long long>(drops.reports));
  }
  if (time.total() > 0) return "log_time";
  if (drops.reports > 0) return "log_drops";
  if (!estimated && input.sink() == nullptr) {
    std::fprintf(stderr,
                 "plinth-monitor: fault: %s: no usable sensor data, the estimator never ran\n",
                 input.source().c_str());
    return "no_sensor_data";
  }
  return "";
}

// The statue's fragility for regional alerts and the P-wave stage: the scene's [fragility];
// with two scenes that both give one, the more fragile (the lower median) of the two.
void set_fragility(fw::MonitorConfig& config, const plinth::host::UncertainScene& x,
                   const std::optional<plinth::host::UncertainScene>& y) {
  std::optional<plinth::LognormalFragility> f = x.fragility;
  if (y && y->fragility && (!f || y->fragility->median_g < f->median_g)) f = y->fragility;
  const auto give = [&f](auto* part) {  // a part this build has not: nullptr
    if (part == nullptr) return;
    part->fragility_known = f.has_value();
    if (f) part->fragility = *f;
  };
  give(mon::built_part<mon::RegionalAlertSettings>(config.regional));
  give(mon::built_part<mon::PWaveSettings>(config.pwave));
}

// What the state directory held, into the monitor just started: a line saying what was restored
// (nothing said on a first start), and an error for a file that could not be trusted (the worst
// it may have said is restored: a latched alarm).
void restore_state(fw::Monitor& monitor, const fw::BoxStateStore& state) {
  if (!state.unreadable().empty()) {
    std::fprintf(stderr,
                 "plinth-monitor: error: the box's saved state cannot be read: %s; restored the "
                 "worst it may have said, a latched alarm (acknowledge it once the statue is "
                 "seen)\n",
                 state.unreadable().c_str());
  }
  if (!state.loaded()) return;
  const fw::SavedBoxState& saved = *state.loaded();
  const fw::BoxMemory& m = saved.memory;
  monitor.restore(m);
  if (m.alarm.latched_level == mon::AlarmLevel::kNormal && !m.alarm.collapse_held) return;
  fw::JsonObject line;
  line.text("type", "restored")
      .text("latched", mon::alarm_level_name(m.alarm.latched_level))
      .text("cause", mon::alarm_cause_name(m.alarm.latched_cause))
      .flag("collapse_held", m.alarm.collapse_held);
  if (m.alarm.collapse_held) {
    line.count("collapse_axis", static_cast<std::uint64_t>(m.collapse.axis))
        .text("collapse_phase", plinth::phase_name(m.collapse.mode.phase))
        .general("collapse_wall_s", static_cast<double>(saved.collapse_wall_ns) * 1e-9, 13);
  }
  line.general("saved_wall_s", static_cast<double>(saved.saved_wall_ns) * 1e-9, 13)
      .text("from", state.path());
  print_line(line.close());
}

int run(const Options& opt, const CLI::App& app) {
  const int sources = (opt.replay_path.empty() ? 0 : 1) + (opt.can_interface.empty() ? 0 : 1);
  if (sources != 1) throw InputError("give exactly one input: --replay FILE or --can INTERFACE");
  const fw::InputOptions input_settings = input_options(opt);
  // Paced input: each line goes out as it is written, for whoever reads them live. Set before
  // any output (the restored state's lines): glibc keeps a stream whose buffer already holds
  // data fully buffered, and under systemd those lines then reached the journal only when 4 KiB
  // had gathered or at exit, or never, at a kill (seen in the image's test, docs/image.md).
  if (input_settings.speed > 0.0 || !opt.can_interface.empty()) {
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
  }
  fw::MonitorFile file = fw::configure_monitor(opt.config);
  if (!opt.replay_y_path.empty() && file.second_scene_path.empty()) {
    throw InputError("--replay-y needs a second axis: --scene-y or monitor.second_scene");
  }
  const plinth::host::UncertainScene scene_x =
      plinth::host::load_uncertain_scene_file(opt.scene_path);
  std::optional<plinth::host::UncertainScene> scene_y;
  if (!file.second_scene_path.empty()) {
    scene_y = plinth::host::load_uncertain_scene_file(file.second_scene_path);
  }
  fw::MonitorConfig& config = file.config;
  config.axis_count = scene_y ? 2 : 1;
  set_fragility(config, scene_x, scene_y);
  // The commissioning of this mounting (docs/commissioning.md), before a record replay reduces
  // the sensors to its one.
  fw::CommissioningGate gate(file.commissioning, opt.record_dir, fw::mounting_sha256(config),
                             opt.commissioning_override);
  gate.check();
  gate.announce();
  const std::unique_ptr<fw::MonitorInput> input = fw::open_input(input_settings, config, g_stop);

  fw::Monitor monitor;
  fw::FrameDecoder decoder;
  start_monitor(monitor, decoder, config, scene_x, scene_y, app, opt.config.config_path);
  const auto hold_commissioning = [&] {
    monitor.hold_fault(gate.refuses() ? mon::AlarmCause::kCommissioningFailed
                                      : mon::AlarmCause::kNone);
  };
  hold_commissioning();
  std::optional<fw::BoxStateStore> state;
  if (!opt.state_dir.empty()) restore_state(monitor, state.emplace(opt.state_dir));
  std::vector<AxisEvents> sinks;
  sinks.reserve(static_cast<std::size_t>(config.axis_count));
  for (int i = 0; i < config.axis_count; ++i) {
    sinks.emplace_back(i, monitor, input->t_origin(), !opt.quiet_events);
    monitor.set_event_sink(i, &sinks.back());
  }
  const fw::RunIdentity run_identity =
      fw::run_identity(opt.scene_path, file.second_scene_path, opt.config.config_path);
  const std::string identity =
      fw::identity_members(run_identity) + ", " + gate.status_member();
  const std::unique_ptr<fw::EventRecorder> recorder = make_recorder(opt, file, identity);
  // --frames-out: the frames a replay sends, stamped with the receive time of the input that
  // caused them (what candump on the bus would show).
  const Outputs* frames_clock = nullptr;
  std::optional<plinth::hal::CandumpLogWriter> frames_log;
  if (!opt.frames_out.empty()) {
    plinth::hal::CandumpLogWriterOpenResult opened = plinth::hal::CandumpLogWriter::open(
        opt.frames_out, "can0", [&frames_clock] { return frames_clock->last_frame_ns; });
    if (!opened.ok()) throw InputError("--frames-out: " + opened.message);
    frames_log.emplace(std::move(*opened.writer));
  }
  plinth::hal::FrameSink* const bus = frames_log ? &*frames_log : input->sink();
  const std::unique_ptr<fw::RelayOutputs> relays = make_relays(file.relays);
  const std::vector<std::unique_ptr<fw::StatusOutput>> network = start_outputs(file, run_identity);
  std::vector<fw::StatusOutput*> output_list;
  for (const auto& o : network) output_list.push_back(o.get());
  Outputs outputs(monitor, input->t_origin(), recorder.get(), bus, relays.get(), output_list);
  if (state) outputs.keep_state_in(&*state);
  frames_clock = &outputs;
  std::optional<fw::SampleTrace> trace;
  if (!opt.trace_path.empty()) {
    outputs.trace = &trace.emplace(opt.trace_path, config.axis_count, input->t_origin());
  }
  std::optional<fw::LatencyLog> latency;
  std::optional<fw::LatencyLog> due_latency;  // a paced replay: from each sample's deadline
  if (opt.latency) {
    latency.emplace(kLatencyCapacity);
    due_latency.emplace(kLatencyCapacity);
  }
  fw::Supervisor supervisor(file.watchdog);
  outputs.supervisor = &supervisor;
  outputs.identity = identity;
  const auto commissioning_extra = [&] {
    outputs.status_extra = gate.verdict().state == fw::GateState::kRefused ||
                                   gate.verdict().state == fw::GateState::kOverridden
                               ? gate.status_member()
                               : "";
  };
  commissioning_extra();
  const auto restart = [&] {
    start_monitor(monitor, decoder, config, scene_x, scene_y, app, opt.config.config_path);
    hold_commissioning();
  };
  // A newer report (plinth-commission ran) changes what the box vouches for, within
  // kGateRescanS.
  const auto poll = [&](std::int64_t now_ns) {
    if (!gate.poll(now_ns)) return;
    gate.announce();
    hold_commissioning();
    commissioning_extra();
  };
  const bool estimated = run_loop(*input, monitor, decoder, outputs, recorder.get(), supervisor,
                                  latency ? &*latency : nullptr,
                                  due_latency ? &*due_latency : nullptr, restart, poll);
  if (trace) trace->close();
  if (recorder) recorder->close();  // every capture is on disk before the summary
  if (frames_log && !frames_log->flush()) throw InputError("--frames-out: " + frames_log->error());
  fw::RunTotals totals = run_totals(outputs, *input, monitor, decoder, recorder.get(), sinks);
  if (frames_log) totals.bus_send_errors += monitor.frames_not_encoded();
  for (const auto& o : network) {
    o->stop();  // the MQTT publisher delivers its queue first (bounded)
    totals.outputs.emplace_back(o->name(), o->summary_json());
  }
  if (latency) totals.outputs.emplace_back("latency", latency->summary_json());
  totals.outputs.emplace_back("commissioning", gate.json());
  if (due_latency && input_settings.speed > 0.0) {
    totals.outputs.emplace_back("latency_from_due", due_latency->summary_json());
  }
  totals.input_fault = input_fault(*input, estimated);
  print_line(fw::summary_json(monitor, totals, input->t_origin()));
  std::fflush(stdout);
  return totals.input_fault.empty() || g_stop != 0 ? 0 : kInputFaultExit;
}

// The options the input chosen has no use for (every option means something).
void refuse_without_effect(const CLI::App& app, const Options& opt) {
  using plinth::host::refuse_without_effect;
  const bool live = !opt.can_interface.empty();
  const bool log = !live && fw::is_candump_log(opt.replay_path);
  refuse_without_effect(app, {"--pga", "--scale", "--replay-y", "--vertical"}, !live && !log,
                        "scales or completes a record replay (.AT2, .csv); a candump log's and a "
                        "bus's frames are taken as they come");
  refuse_without_effect(app, {"--duration"}, live,
                        "stops a live run (--can); a replay ends with its input");
  refuse_without_effect(app, {"--speed"}, !live,
                        "paces a replay; a live bus (--can) comes at its own pace");
  refuse_without_effect(app, {"--log-time"}, log,
                        "applies to a candump log replay only (a record's samples are timed by "
                        "its sampling interval, a bus's frames by the receive clock)");
  refuse_without_effect(app, {"--log-drops"}, log,
                        "applies to a candump log replay only (a record has no DROPCOUNT lines; a "
                        "bus's drops are the kernel's, counted in bus_dropped_frames)");
  refuse_without_effect(app, {"--pre-trigger", "--post-trigger"}, !opt.record_dir.empty(),
                        "sets the event recorder's captures, which is off (--record-dir)");
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
  app.add_option("--log-time", opt.log_time,
                 "a candump log's timestamps that go back, stand still or jump: warn (default: "
                 "named, counted, the box's input fault raised) or refuse (stop at the first)");
  app.add_option("--log-drops", opt.log_drops,
                 "a candump log's DROPCOUNT lines (frames its logger lost): warn (default: named, "
                 "counted, the box's bus fault raised as for a live overflow) or refuse (stop at "
                 "the first)");
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
  app.add_option("--state-dir", opt.state_dir,
                 "keep the latched alarm and any collapse here (alarm-state.json), restored at "
                 "the next start (docs/safety.md)");
  app.add_option("--frames-out", opt.frames_out,
                 "replay: write the status and alarm frames sent to this candump log")
      ->excludes("--can");
  app.add_option("--pre-trigger", opt.pre_trigger, "s kept before an alarm (default 30)")
      ->check(plinth::host::kFinite);
  app.add_option("--post-trigger", opt.post_trigger, "s kept after an alarm (default 60)")
      ->check(plinth::host::kFinite);
  app.add_flag("--no-events", opt.quiet_events, "leave out the phase event lines");
  app.add_option("--trace", opt.trace_path,
                 "write a line per sample to this file (TSV: risk, levels, ground, rotation, "
                 "phase; for tools/plinth-event-plot)");
  app.add_option("--relay-chip", c.relay_chip,
                 "GPIO chip of the relays (relays.chip; the lines come from [relays])");
  app.add_flag("--no-relays", c.no_relays, "drive no relays, whatever [relays] says")
      ->excludes("--relay-chip");
  app.add_option("--modbus", c.modbus_listen,
                 "Modbus TCP server at HOST:PORT (modbus.listen; docs/integration.md)");
  app.add_flag("--modbus-writes", c.modbus_writes,
               "the acknowledge and reset coils may be written (modbus.writes) ...");
  app.add_option("--modbus-write-from", c.modbus_write_from,
                 "... by these addresses or prefixes only, comma-separated: 10.0.4.7,::1 "
                 "(modbus.write_from)")
      ->delimiter(',');
  app.add_flag_callback(
      "--modbus-map",
      [] {
        std::fputs(fw::modbus::map_csv().c_str(), stdout);
        throw CLI::Success();
      },
      "print the Modbus map this program serves (CSV, as share/plinth/modbus-map.csv) and exit");
  app.add_option("--mqtt", c.mqtt_broker, "publish to the MQTT broker at HOST:PORT (mqtt.broker)");
  app.add_option("--mqtt-box-id", c.mqtt_box_id, "the box's id in the topics (mqtt.box_id)");
  app.add_option("--mqtt-username", c.mqtt_username, "MQTT user name (mqtt.username)");
  app.add_option("--mqtt-password-file", c.mqtt_password_file,
                 "a file whose first line is the MQTT password (mqtt.password_file)");
  app.add_option("--mqtt-ca", c.mqtt_ca_file, "TLS: the CA that signed the broker's certificate");
  app.add_option("--mqtt-cert", c.mqtt_cert_file, "TLS: the box's client certificate");
  app.add_option("--mqtt-key", c.mqtt_key_file, "TLS: its private key");
  app.add_flag("--no-forecast", c.no_forecast,
               "the box without the forecast (forecast.enabled = false; docs/forecast.md)");
  app.add_option("--commissioning-override", opt.commissioning_override,
                 "monitor whatever the commissioning report says, for this reason (logged at "
                 "each start; commissioning.override; docs/commissioning.md)");
  app.add_flag("--latency", opt.latency,
               "the summary gives each sample's latency, arrival to status ready (median, p99)");
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
  if (const std::optional<int> exit_code =
          plinth::host::parse_command_line(app, argc, argv, [&] { refuse_without_effect(app, opt); })) {
    return *exit_code;
  }
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  return plinth::host::run_tool("plinth-monitor", [&] { return run(opt, app); });
}
