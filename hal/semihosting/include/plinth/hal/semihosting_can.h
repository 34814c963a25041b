// The CAN controller's stand-in on a board without a bus: every frame the box sends is printed on
// the semihosting console as a candump log line, "(0000000002.450000) can0 330#...", so a host
// can decode it exactly as it would decode a capture of the real bus (candump_log.h). Frames are
// stamped with the time `now_ns` points at (the box's clock). Nothing is received: the sensor
// samples come from the board's record (plinth/hal/compiled_record.h).
//
// A bxCAN or FDCAN driver is a FrameSink of the same shape (plinth/hal/frame_io.h), and a
// FrameSource for the sensors' frames: send() queues the frame in a transmit mailbox (kIoError
// when all are full), receive() takes one from the receive FIFO, stamped by the controller.
#pragma once

#include <cstdint>

#include "plinth/hal/frame_io.h"

namespace plinth::hal {

class SemihostingCanPort final : public FrameSink {
 public:
  // `interface_name`: 1 to 15 characters, as in the log line; `now_ns` must outlive the port.
  SemihostingCanPort(const char* interface_name, const std::int64_t* now_ns)
      : interface_name_(interface_name), now_ns_(now_ns) {}

  // Prints the frame's log line; kIoError when the line cannot be formatted (a negative time,
  // a bad interface name) or the host did not take it.
  [[nodiscard]] IoStatus send(const can::CanFrame& frame) override;

  [[nodiscard]] std::uint64_t frames_sent() const { return frames_sent_; }

 private:
  const char* interface_name_;
  const std::int64_t* now_ns_;
  std::uint64_t frames_sent_ = 0;
};

}  // namespace plinth::hal
