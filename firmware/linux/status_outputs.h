// The seam between plinth-monitor's real-time loop and its outputs off that loop (Modbus TCP,
// MQTT, ...; docs/integration.md). The loop copies a StatusSnapshot after each update and each
// alarm event into every output's mailbox: lock-free, no allocation, never a wait on an output's
// thread (a full event ring drops the event and counts it). Operator commands (acknowledge,
// reset) come back the same way, one ring per output, polled by the loop, and each command's
// result goes back to its output.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string>

#include "plinth/core/state.h"
#include "plinth/firmware/monitor.h"
#include "plinth/monitor/alarm_level.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/sensor_health.h"
#include "recorder_status.h"

namespace plinth::firmware {

// The regional room's status as the outputs show it (regional_alert.h): valid when received > 0.
struct RegionalSnapshot {
  std::uint64_t received = 0;
  std::uint64_t accepted = 0;
  std::uint64_t refused = 0;  // every reason
  int held = 0;
  std::uint32_t event_id = 0;  // the worst held alert's (held > 0)
  std::uint32_t version = 0;
  double magnitude = 0.0;
  double distance_km = 0.0;
  double pga_g = 0.0;
  double sigma_ln = 0.0;
  double probability = 0.0;       // of collapse under it
  double time_to_s_arrival_s = 0.0;
  double s_arrival_t = 0.0;       // the JSON lines' time of its S arrival
  monitor::RegionalRefusal last_refusal = monitor::RegionalRefusal::kNone;
  // Refusals of alerts more dangerous than the worst held (RegionalAlertStatus), the latest.
  std::uint64_t refused_dangerous = 0;
  monitor::RefusedRegionalAlert last_refused_dangerous;
  double last_refused_dangerous_t = 0.0;  // the JSON lines' time of its refusal
};

// What the box shows after one update of the loop.
struct StatusSnapshot {
  std::uint64_t updates = 0;   // updates of the loop so far
  std::uint64_t statuses = 0;  // status reports so far (the heartbeat counter)
  std::int64_t time_ns = 0;    // monitor time
  double t = 0.0;              // s: the JSON lines' time (monitor time less the record's lead-in)
  std::int64_t wall_time_ns = 0;  // CLOCK_REALTIME when the loop took it
  std::int64_t uptime_ns = 0;     // since plinth-monitor started (CLOCK_MONOTONIC)
  monitor::AlarmLevel level = monitor::AlarmLevel::kNormal;    // shown
  monitor::AlarmLevel latched = monitor::AlarmLevel::kNormal;  // kNormal: nothing latched
  monitor::AlarmCause cause = monitor::AlarmCause::kNone;      // of the latest alarm event
  monitor::AlarmCause trouble = monitor::AlarmCause::kNone;    // beside the level (safety.md)
  bool collapse_held = false;  // a collapse held until a person states the statue stands
  std::uint8_t event_sequence = 0;  // of the latest alarm event (an acknowledgement quotes it)
  bool any_event = false;
  double risk = 0.0;
  // The forecast (MonitorStatus): the highest probability over the axes, its axis (-1: no
  // forecast yet), that axis's member collapsing first (-1: none) and the JSON lines' time of
  // the first forecast collapse (collapse_forecast false: none forecast).
  double probability = 0.0;
  int forecast_axis = -1;
  int forecast_worst_member = -1;
  bool collapse_forecast = false;
  double collapse_forecast_t = 0.0;
  int axis_count = 1;
  std::array<Phase, kMaxAxes> phase{};
  bool estimating = false;
  monitor::HealthState sensor = monitor::HealthState::kFault;  // the primary's
  monitor::HealthState sensors_state = monitor::HealthState::kFault;
  monitor::SensorCounters sensor_counters;  // the primary's
  std::uint64_t estimator_restarts = 0;
  // The statue sensor (BoxStatus): its streams' health, its offset known, per axis what the
  // filter makes of the members (StatueAxisStatus).
  bool has_statue_sensor = false;
  monitor::HealthState statue_rate = monitor::HealthState::kFault;
  monitor::HealthState statue_acceleration = monitor::HealthState::kFault;
  bool statue_ready = false;
  bool statue_unexplained = false;
  std::array<StatueAxisStatus, kMaxAxes> statue_axes{};
  monitor::AckOutcome last_ack = monitor::AckOutcome::kNone;  // of the latest command
  std::uint64_t commands = 0;  // operator commands the loop carried out
  std::uint64_t resets = 0;
  RegionalSnapshot regional;
  RecorderStatus recorder;  // the event recorder's health (present: --record-dir)
};

// One alarm event as the JSON alarm line writes it.
struct AlarmNotice {
  monitor::AlarmEventRecord event;
  double t_origin = 0.0;  // s: alarm_json(event, t_origin)
};

enum class OperatorCommand : std::uint8_t {
  kAcknowledge,   // the latched level, quoting the latest event's sequence
  kReset,         // the monitor starts again, its latch and any collapse kept (refused while an
                  // alarm is latched and unacknowledged)
  kStatueStands,  // a person on site states that the statue stands again, quoting the sequence
};

// A regional alert an output received (MQTT), for the loop: the alert, or refused before it
// was read (malformed, unauthenticated; `field`, a string literal, names what).
struct RegionalRequest {
  monitor::RegionalAlert alert;
  monitor::RegionalRefusal refusal = monitor::RegionalRefusal::kNone;
  const char* field = "";
};

struct CommandRequest {
  OperatorCommand command = OperatorCommand::kAcknowledge;
  monitor::AlarmLevel level = monitor::AlarmLevel::kNormal;  // kAcknowledge: the latched level
  std::uint8_t event_sequence = 0;  // kAcknowledge: the latest event the operator saw
  std::uint32_t id = 0;             // the output's own, quoted by the result
};

// What the loop did with a command: the acknowledgement's outcome, the statement's, or for a
// reset whether it was refused (an alarm latched and unacknowledged).
struct CommandResult {
  std::uint32_t id = 0;
  monitor::AckOutcome outcome = monitor::AckOutcome::kNone;
  monitor::StandsOutcome stands = monitor::StandsOutcome::kNone;
  bool reset_refused = false;
};

// The newest of a stream of values, one writer and one reader, without locks (a triple buffer):
// publish() never waits, take() gives the newest value not taken yet.
template <typename T>
class LatestValue {
 public:
  void publish(const T& value) noexcept {
    slots_[back_] = value;
    back_ = middle_.exchange(back_ | kFresh, std::memory_order_acq_rel) & kIndex;
  }
  // False when nothing new was published since the last take.
  [[nodiscard]] bool take(T& out) noexcept {
    if ((middle_.load(std::memory_order_acquire) & kFresh) == 0) return false;
    front_ = middle_.exchange(front_, std::memory_order_acq_rel) & kIndex;
    out = slots_[front_];
    return true;
  }

 private:
  static constexpr unsigned kIndex = 3U;
  static constexpr unsigned kFresh = 4U;
  std::array<T, 3> slots_{};
  std::atomic<unsigned> middle_{1U};
  unsigned back_ = 0U;   // the writer's slot
  unsigned front_ = 2U;  // the reader's slot
};

// A bounded FIFO, one writer and one reader, without locks.
template <typename T, std::size_t N>
class SpscRing {
  static_assert(N > 0 && (N & (N - 1)) == 0, "a power of two");

 public:
  [[nodiscard]] bool push(const T& value) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_.load(std::memory_order_acquire) >= N) return false;
    slots_[head % N] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }
  [[nodiscard]] bool pop(T& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return false;
    out = slots_[tail % N];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

 private:
  std::array<T, N> slots_{};
  alignas(64) std::atomic<std::uint64_t> head_{0};
  alignas(64) std::atomic<std::uint64_t> tail_{0};
};

// What the loop hands one output: the newest snapshot, the alarm events in order, and the
// output's commands back.
class OutputMailbox {
 public:
  static constexpr std::size_t kEventSlots = 256;
  static constexpr std::size_t kCommandSlots = 16;
  static constexpr std::size_t kRegionalSlots = 16;

  // Loop side.
  void post_status(const StatusSnapshot& snapshot) noexcept { status_.publish(snapshot); }
  void post_alarm(const AlarmNotice& notice) noexcept {
    if (!events_.push(notice)) events_dropped_.fetch_add(1, std::memory_order_relaxed);
  }
  [[nodiscard]] bool take_command(CommandRequest& out) noexcept { return commands_.pop(out); }
  // Dropped when the ring is full: an output that reads the results (MqttPublisher) keeps at
  // most kCommandSlots commands under way; one that does not (ModbusServer) loses nothing.
  void post_result(const CommandResult& result) noexcept { (void)results_.push(result); }
  [[nodiscard]] bool take_regional(RegionalRequest& out) noexcept { return regional_.pop(out); }

  // Output side.
  [[nodiscard]] bool take_status(StatusSnapshot& out) noexcept { return status_.take(out); }
  [[nodiscard]] bool take_alarm(AlarmNotice& out) noexcept { return events_.pop(out); }
  // False when the ring is full (the loop has not polled): the command is refused.
  [[nodiscard]] bool post_command(const CommandRequest& c) noexcept { return commands_.push(c); }
  [[nodiscard]] bool take_result(CommandResult& out) noexcept { return results_.pop(out); }
  // False when the ring is full (the loop has not polled): the output counts the alert lost.
  [[nodiscard]] bool post_regional(const RegionalRequest& r) noexcept { return regional_.push(r); }
  // Alarm events the loop could not hand over (the ring was full).
  [[nodiscard]] std::uint64_t events_dropped() const noexcept {
    return events_dropped_.load(std::memory_order_relaxed);
  }

 private:
  LatestValue<StatusSnapshot> status_;
  SpscRing<AlarmNotice, kEventSlots> events_;
  SpscRing<CommandRequest, kCommandSlots> commands_;
  SpscRing<CommandResult, 2 * kCommandSlots> results_;
  SpscRing<RegionalRequest, kRegionalSlots> regional_;
  std::atomic<std::uint64_t> events_dropped_{0};
};

// An output with its own thread. The loop only touches mailbox(); summary_json() and stop()
// run on the main thread at the end.
class StatusOutput {
 public:
  virtual ~StatusOutput() = default;
  [[nodiscard]] virtual OutputMailbox& mailbox() = 0;
  // Delivers what is queued (bounded by the output's own limit) and ends the thread.
  virtual void stop() = 0;
  // The output's counters for the summary line: a JSON object.
  [[nodiscard]] virtual std::string summary_json() const = 0;
  [[nodiscard]] virtual const char* name() const = 0;  // the summary's key: "modbus", "mqtt"
};

// Copies the monitor's `status` into `snapshot` (time, level, risk, phases, sensors); the fields
// the loop keeps itself (updates, statuses, the latest event, commands) are left as they are.
void copy_status(const BoxStatus& status, double t_origin, StatusSnapshot& snapshot);

// CLOCK_MONOTONIC and CLOCK_REALTIME, ns.
[[nodiscard]] std::int64_t monotonic_ns();
[[nodiscard]] std::int64_t wall_clock_ns();

// "HOST:PORT" or "[IPv6]:PORT" split; `what` names the key or flag in the message
// (host::InputError: "--modbus: expected HOST:PORT, got ...").
struct Endpoint {
  std::string host;
  int port = 0;
  [[nodiscard]] std::string text() const;
};
[[nodiscard]] Endpoint parse_endpoint(const std::string& text, const std::string& what);

}  // namespace plinth::firmware
