#include "plinth/firmware/monitor_frames.h"

namespace plinth::firmware {

namespace {
constexpr std::int64_t kNsPerMs = 1'000'000;
constexpr std::int64_t kUnknownSampleAgeMs = 65535;  // the frame's largest age
}  // namespace

void MonitorFrames::send(const can::CanFrame& frame, bool encoded) {
  if (bus_ == nullptr) return;
  if (!encoded || bus_->send(frame) != hal::IoStatus::kOk) ++send_errors_;
}

void MonitorFrames::send_alarm(const monitor::AlarmEventRecord& event) {
  if (bus_ == nullptr) return;
  can::CanFrame frame;
  const bool encoded = can::encode(monitor::to_can_event(event), frame).ok();
  send(frame, encoded);
}

bool MonitorFrames::status_due(const MonitorUpdate& update) const {
  return update.event_count > 0 || update.status_due ||
         monitor_.status().time_ns >= next_status_ns_;
}

void MonitorFrames::send_status() {
  const MonitorStatus& s = monitor_.status();
  for (int i = 0; i < s.axis_count && bus_ != nullptr; ++i) {
    const AxisStatus& a = s.axes[static_cast<std::size_t>(i)];
    can::MonitorStatus m;
    m.axis = static_cast<std::uint8_t>(i);
    m.phase = static_cast<can::Phase>(a.mode.phase);
    m.corner = a.mode.rocking() ? static_cast<can::Corner>(a.mode.corner) : can::Corner::kNone;
    m.alarm_level = s.alarm;
    m.risk = a.risk.total;
    m.sequence = status_sequence_;
    // Not estimating yet: no sample was used, the age is the largest the frame can say.
    const std::int64_t age_ms =
        s.estimating ? (s.time_ns - s.newest_sample_time_ns) / kNsPerMs : kUnknownSampleAgeMs;
    m.sample_age_ms = static_cast<std::uint16_t>(
        age_ms < 0 ? 0 : (age_ms > kUnknownSampleAgeMs ? kUnknownSampleAgeMs : age_ms));
    can::CanFrame frame;
    const bool encoded = can::encode(m, frame).ok();
    send(frame, encoded);
  }
  ++status_sequence_;
  monitor_.status_sent();
  while (next_status_ns_ <= s.time_ns) next_status_ns_ += interval_ns_;
}

}  // namespace plinth::firmware
