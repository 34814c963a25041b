// The small interfaces between the plinth CAN protocol and whatever carries its frames: a
// SocketCAN socket on Linux, a candump log file, a microcontroller's CAN peripheral, a fake in
// tests. Header-only, freestanding (no heap, no exceptions): the firmware and the host tools use
// the same two interfaces, and each backend lives in its own module (hal/socketcan, ...).
#pragma once

#include <cstdint>

#include "plinth/core/name_table.h"
#include "plinth/hal/can_codec.h"

namespace plinth::hal {

// A frame with the time it was received (or is to be sent), ns. The clock is the backend's:
// SocketCAN gives the kernel's receive timestamp (CLOCK_REALTIME), a log file the logged time.
struct TimedFrame {
  can::CanFrame frame;
  std::int64_t timestamp_ns = 0;
};

enum class IoStatus : std::uint8_t {
  kOk = 0,
  kTimeout,      // nothing arrived within the time asked for (not an error)
  kEndOfInput,   // a file source is exhausted; a socket never says this
  kNotPlinth,    // a frame arrived but was not for plinth (extended id, RTR, CAN FD, ...)
  kBusError,     // the controller reported an error frame (bus-off, passive, lost arbitration)
  kOverflow,     // frames were dropped before we read them (the kernel's drop counter grew)
  kIoError,      // the backend failed (socket closed, read error, interface gone)
};

inline constexpr NameTable<IoStatus, 7> kIoStatusNames{{{
    {IoStatus::kOk, "ok"},
    {IoStatus::kTimeout, "timeout"},
    {IoStatus::kEndOfInput, "end of input"},
    {IoStatus::kNotPlinth, "not a plinth frame"},
    {IoStatus::kBusError, "bus error"},
    {IoStatus::kOverflow, "frames dropped"},
    {IoStatus::kIoError, "i/o error"},
}}};

[[nodiscard]] constexpr const char* io_status_name(IoStatus status) {
  return kIoStatusNames.name(status);
}

// Both interfaces are used, never owned: their destructors are protected and not virtual (a
// backend is never deleted through them), so a microcontroller's driver class needs no deleting
// destructor and pulls no operator delete into a heap-free image.

// Where frames come from. receive() waits at most `timeout_ms` (0: poll, -1: forever).
class FrameSource {
 public:
  [[nodiscard]] virtual IoStatus receive(TimedFrame& out, int timeout_ms) = 0;

 protected:
  FrameSource() = default;
  FrameSource(const FrameSource&) = default;
  FrameSource& operator=(const FrameSource&) = default;
  ~FrameSource() = default;
};

// Where frames go. send() never blocks for long: a full transmit queue is an error to report.
class FrameSink {
 public:
  [[nodiscard]] virtual IoStatus send(const can::CanFrame& frame) = 0;

 protected:
  FrameSink() = default;
  FrameSink(const FrameSink&) = default;
  FrameSink& operator=(const FrameSink&) = default;
  ~FrameSink() = default;
};

}  // namespace plinth::hal
