// The frames the box sends on the bus after each input (docs/monitor.md): an AlarmEvent for every
// alarm change, and MonitorStatus frames (one per modelled axis) at the status interval, on every
// alarm change and when the alarm policy's heartbeat is due. plinth-monitor sends them on
// SocketCAN (or writes them to a log with --frames-out), the microcontroller image through its
// CAN stand-in; both through a hal::FrameSink.
#pragma once

#include <cstdint>

#include "plinth/firmware/monitor.h"
#include "plinth/hal/frame_io.h"

namespace plinth::firmware {

// s between status frames (and plinth-monitor's status lines) unless configured otherwise.
inline constexpr double kDefaultStatusIntervalS = 0.1;

class MonitorFrames {
 public:
  // `bus` may be null (nothing is sent; the schedule still runs). Both must outlive this.
  MonitorFrames(Monitor& monitor, std::int64_t status_interval_ns, hal::FrameSink* bus)
      : monitor_(monitor), interval_ns_(status_interval_ns), bus_(bus) {}

  // The AlarmEvent frame of one alarm change.
  void send_alarm(const monitor::AlarmEventRecord& event);
  // Whether a status goes out after `update`: an alarm change, the heartbeat, or the interval.
  [[nodiscard]] bool status_due(const MonitorUpdate& update) const;
  // The MonitorStatus frames of the current status (one per axis); records the heartbeat and
  // moves the schedule past the status's time.
  void send_status();

  // Frames the codec refused or the bus did not take.
  [[nodiscard]] std::uint64_t send_errors() const { return send_errors_; }

 private:
  void send(const can::CanFrame& frame, bool encoded);

  Monitor& monitor_;
  std::int64_t interval_ns_;
  hal::FrameSink* bus_;
  std::int64_t next_status_ns_ = 0;
  std::uint8_t status_sequence_ = 0;
  std::uint64_t send_errors_ = 0;
};

}  // namespace plinth::firmware
