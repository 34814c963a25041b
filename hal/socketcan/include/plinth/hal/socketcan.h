// The Linux SocketCAN backend: one CAN_RAW socket bound to one interface (can0, vcan0, ...),
// implementing FrameSource and FrameSink.
//
// receive() and send() never allocate and never block longer than asked: the socket is
// non-blocking and receive() waits with poll(). What the kernel reports besides data frames
// becomes an IoStatus with the details kept on the port until the next call:
//   kBusError   an error frame (CAN_RAW_ERR_FILTER): last_bus_error(), decoded
//   kOverflow   the kernel dropped frames for this socket (SO_RXQ_OVFL): dropped_frames()
//   kNotPlinth  an extended, RTR or CAN FD frame, or an identifier outside 0x300-0x37F, passed
//               by the caller's filters: last_rejected_can_id()
//   kIoError    the socket failed (interface went down, send queue full): last_error(), errno
// Frames of the right identifier but the wrong length are delivered (kOk): refusing them is the
// codec's job, which can say why.
//
// Timestamps are the kernel's receive time (SO_TIMESTAMPNS, CLOCK_REALTIME).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "plinth/hal/frame_io.h"

namespace plinth::hal {

// ---------------------------------------------------------------------------------------------
// Receive filters

// SocketCAN's identifier flag bits (linux/can.h; the implementation checks they match).
inline constexpr std::uint32_t kCanEffFlag = 0x80000000U;  // extended 29-bit identifier
inline constexpr std::uint32_t kCanRtrFlag = 0x40000000U;  // remote transmission request
inline constexpr std::uint32_t kCanErrFlag = 0x20000000U;  // error frame
inline constexpr std::uint32_t kCanSffMask = 0x000007FFU;  // the 11 bits of a standard id

// One kernel receive filter, laid out as struct can_filter: a frame passes when
// (frame can_id & mask) == (id & mask), flag bits included.
struct CanIdFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
};

// Standard data frames whose 11-bit id matches `id` under `mask`: extended and RTR frames fail
// because their flag bits are in the mask and not in the id.
[[nodiscard]] constexpr CanIdFilter standard_id_filter(std::uint32_t id, std::uint32_t mask) {
  return {id & kCanSffMask, (mask & kCanSffMask) | kCanEffFlag | kCanRtrFlag};
}

// 0x300-0x37F is exactly the ids whose top four bits are 0b0110.
inline constexpr std::array<CanIdFilter, 1> kPlinthFilters{standard_id_filter(0x300, 0x780)};
// Every frame, of any format (what candump shows by default).
inline constexpr std::array<CanIdFilter, 1> kAllFrames{CanIdFilter{0, 0}};

// ---------------------------------------------------------------------------------------------
// Error frames (linux/can/error.h)

// What a controller says about the bus; the first four are the ISO 11898 fault confinement
// states, the last two only the interface supervisor reports (libsocketcan).
enum class ControllerState : std::uint8_t {
  kErrorActive,
  kErrorWarning,  // an error counter reached 96
  kErrorPassive,  // an error counter reached 128: the node may no longer signal errors
  kBusOff,        // the transmit counter reached 256: the node is off the bus until restarted
  kStopped,
  kSleeping,
};
[[nodiscard]] const char* controller_state_name(ControllerState state);  // "error-passive", ...

// The error classes of an error frame's can_id (CAN_ERR_TX_TIMEOUT ... CAN_ERR_CNT).
namespace bus_error_class {
inline constexpr std::uint32_t kTxTimeout = 0x001;
inline constexpr std::uint32_t kLostArbitration = 0x002;   // bit in `arbitration_bit`
inline constexpr std::uint32_t kController = 0x004;        // details in `controller`
inline constexpr std::uint32_t kProtocolViolation = 0x008;  // `protocol_type`, `..._location`
inline constexpr std::uint32_t kTransceiver = 0x010;        // details in `transceiver`
inline constexpr std::uint32_t kNoAck = 0x020;
inline constexpr std::uint32_t kBusOff = 0x040;
inline constexpr std::uint32_t kBusError = 0x080;
inline constexpr std::uint32_t kRestarted = 0x100;
inline constexpr std::uint32_t kCounters = 0x200;  // `tx_error_count`, `rx_error_count` valid
}  // namespace bus_error_class

// The controller status byte (data[1]) with kController (CAN_ERR_CRTL_*).
namespace controller_status {
inline constexpr std::uint8_t kRxOverflow = 0x01;
inline constexpr std::uint8_t kTxOverflow = 0x02;
inline constexpr std::uint8_t kRxWarning = 0x04;
inline constexpr std::uint8_t kTxWarning = 0x08;
inline constexpr std::uint8_t kRxPassive = 0x10;
inline constexpr std::uint8_t kTxPassive = 0x20;
inline constexpr std::uint8_t kBackToActive = 0x40;
}  // namespace controller_status

// One error frame, decoded. The bytes keep the kernel's encoding (see linux/can/error.h for the
// protocol and transceiver codes); describe_bus_error() turns them into words.
struct CanBusError {
  std::uint32_t classes = 0;           // bus_error_class bits
  std::uint8_t arbitration_bit = 0;    // data[0]: bit where arbitration was lost (0: unknown)
  std::uint8_t controller = 0;         // data[1]: controller_status bits
  std::uint8_t protocol_type = 0;      // data[2]: CAN_ERR_PROT_* bits
  std::uint8_t protocol_location = 0;  // data[3]: CAN_ERR_PROT_LOC_* code
  std::uint8_t transceiver = 0;        // data[4]: CAN_ERR_TRX_* code
  std::uint8_t tx_error_count = 0;     // data[6], with kCounters
  std::uint8_t rx_error_count = 0;     // data[7], with kCounters

  [[nodiscard]] constexpr bool has(std::uint32_t error_class) const {
    return (classes & error_class) != 0;
  }
};

// Decodes an error frame's can_id (CAN_ERR_FLAG set) and data; the flag bits are ignored.
[[nodiscard]] CanBusError decode_error_frame(std::uint32_t can_id,
                                             const std::array<std::uint8_t, 8>& data);
// The worst fault confinement state the frame reports (bus-off, then passive, then warning);
// kErrorActive when it reports none (a protocol error, a lost arbitration, a restart).
[[nodiscard]] ControllerState error_state(const CanBusError& error);
// Writes e.g. "bus-off; controller: tx error-passive; counters tx 128 rx 0" into `text`
// (always terminated, truncated if short); returns the length written.
std::size_t describe_bus_error(const CanBusError& error, std::span<char> text);

// ---------------------------------------------------------------------------------------------
// The port

struct SocketCanOptions {
  // Copied into the kernel at open(); the span need not outlive the call.
  std::span<const CanIdFilter> filters = kPlinthFilters;
  bool error_frames = true;        // report every class of error frame (kBusError)
  bool receive_own_frames = false;  // CAN_RAW_RECV_OWN_MSGS (the kernel's default is off)
  int receive_buffer_bytes = 0;    // SO_RCVBUF; 0 keeps the kernel's default
};

enum class OpenError : std::uint8_t {
  kOk = 0,
  kBadName,           // empty, or longer than IFNAMSIZ - 1 (15) characters
  kNoCanSupport,      // the kernel has no CAN (EAFNOSUPPORT) or no raw CAN (EPROTONOSUPPORT)
  kNoSuchInterface,   // ENODEV
  kNotCanInterface,   // the interface exists but is not CAN (lo, eth0)
  kInterfaceDown,     // not IFF_UP: `ip link set <name> up` first
  kPermissionDenied,  // EPERM / EACCES
  kSystemError,       // any other failure, with its errno
};

struct SocketCanOpenResult;

class SocketCanPort final : public FrameSource, public FrameSink {
 public:
  // Opens and binds a socket on `interface_name`. On failure the result's `message` names the
  // interface and the cause, e.g. "cannot open CAN interface vcan0: this kernel has no CAN
  // support (...)". May allocate; receive() and send() do not.
  [[nodiscard]] static SocketCanOpenResult open(std::string_view interface_name,
                                                const SocketCanOptions& options = {});

  SocketCanPort(SocketCanPort&& other) noexcept;
  SocketCanPort& operator=(SocketCanPort&& other) noexcept;
  SocketCanPort(const SocketCanPort&) = delete;
  SocketCanPort& operator=(const SocketCanPort&) = delete;
  ~SocketCanPort();

  // kOk with a standard data frame in 0x300-0x37F (any length 0..8), or another status (see the
  // top of this file). `out` is written only on kOk.
  [[nodiscard]] IoStatus receive(TimedFrame& out, int timeout_ms) override;
  // Queues a classic data frame (standard id, length 0..8; any id, not only plinth's). kIoError
  // with last_error() ENOBUFS or EAGAIN when the transmit queue is full (transmit_queue_full()),
  // ENETDOWN when the interface is down, EINVAL for an id above 0x7FF or a length above 8.
  [[nodiscard]] IoStatus send(const can::CanFrame& frame) override;

  // Replaces the receive filters (an empty span receives no data frames; error frames still
  // arrive when enabled). Returns 0 or the errno.
  int set_filters(std::span<const CanIdFilter> filters);

  // After kBusError: the error frame.
  [[nodiscard]] const CanBusError& last_bus_error() const { return last_bus_error_; }
  // After kOverflow: frames the kernel dropped since the previous kOverflow. The frame that
  // revealed the drop is not lost: the next receive() returns it.
  [[nodiscard]] std::uint32_t dropped_frames() const { return dropped_frames_; }
  [[nodiscard]] std::uint64_t total_dropped_frames() const { return total_dropped_frames_; }
  // After kNotPlinth: the frame's can_id with SocketCAN's flag bits (EFF, RTR), and whether it
  // was a CAN FD frame.
  [[nodiscard]] std::uint32_t last_rejected_can_id() const { return last_rejected_can_id_; }
  [[nodiscard]] bool last_rejected_was_fd() const { return last_rejected_was_fd_; }
  // After kIoError: the errno. ENETDOWN: the interface went down (reported once; frames flow
  // again when it is up); ENODEV: it was removed (open again); ENOBUFS / EAGAIN: the transmit
  // queue is full. strerror() tells it in words.
  [[nodiscard]] int last_error() const { return last_error_; }
  [[nodiscard]] bool transmit_queue_full() const;

  [[nodiscard]] int native_handle() const { return fd_; }
  [[nodiscard]] const char* interface_name() const { return interface_name_.data(); }

 private:
  // A frame as read from the socket, before it is classified.
  struct RawFrame {
    std::uint32_t can_id = 0;
    std::uint8_t length = 0;
    bool fd = false;
    std::array<std::uint8_t, 8> data{};
    std::int64_t timestamp_ns = 0;
  };
  enum class ReadResult : std::uint8_t { kFrame, kEmpty, kError };

  SocketCanPort(int fd, std::string_view interface_name);
  void close_fd();
  ReadResult read_frame(RawFrame& raw, std::uint32_t& drop_count);
  IoStatus classify(const RawFrame& raw, TimedFrame& out);
  bool drops_grew(std::uint32_t drop_count);
  bool kernel_drop_counter(std::uint32_t& drop_count) const;

  int fd_ = -1;
  std::array<char, 16> interface_name_{};  // IFNAMSIZ
  std::optional<RawFrame> pending_;         // held back while kOverflow is reported
  std::uint32_t last_drop_count_ = 0;      // the kernel's cumulative counter, as last seen
  std::uint32_t dropped_frames_ = 0;
  std::uint64_t total_dropped_frames_ = 0;
  CanBusError last_bus_error_{};
  std::uint32_t last_rejected_can_id_ = 0;
  bool last_rejected_was_fd_ = false;
  int last_error_ = 0;
};

struct SocketCanOpenResult {
  std::optional<SocketCanPort> port;  // set on success
  OpenError error = OpenError::kOk;
  int error_number = 0;  // the errno behind the failure, 0 when there is none
  std::string message;   // names the interface and the cause; empty on success

  [[nodiscard]] bool ok() const { return error == OpenError::kOk; }
};

}  // namespace plinth::hal
