// SocketCanPort: a non-blocking CAN_RAW socket with kernel timestamps, drop counter and error
// frames; and the decoding of error frames.
#include "plinth/hal/socketcan.h"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/sock_diag.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <utility>

#include "plinth/core/name_table.h"
#include "plinth/hal/pacing.h"

namespace plinth::hal {

static_assert(kCanEffFlag == CAN_EFF_FLAG && kCanRtrFlag == CAN_RTR_FLAG &&
              kCanErrFlag == CAN_ERR_FLAG && kCanSffMask == CAN_SFF_MASK);
// set_filters() hands CanIdFilter arrays to the kernel as struct can_filter arrays.
static_assert(sizeof(CanIdFilter) == sizeof(can_filter) &&
              offsetof(CanIdFilter, id) == offsetof(can_filter, can_id) &&
              offsetof(CanIdFilter, mask) == offsetof(can_filter, can_mask));
static_assert(bus_error_class::kTxTimeout == CAN_ERR_TX_TIMEOUT &&
              bus_error_class::kLostArbitration == CAN_ERR_LOSTARB &&
              bus_error_class::kController == CAN_ERR_CRTL &&
              bus_error_class::kProtocolViolation == CAN_ERR_PROT &&
              bus_error_class::kTransceiver == CAN_ERR_TRX &&
              bus_error_class::kNoAck == CAN_ERR_ACK &&
              bus_error_class::kBusOff == CAN_ERR_BUSOFF &&
              bus_error_class::kBusError == CAN_ERR_BUSERROR &&
              bus_error_class::kRestarted == CAN_ERR_RESTARTED &&
              bus_error_class::kCounters == CAN_ERR_CNT);
static_assert(controller_status::kRxOverflow == CAN_ERR_CRTL_RX_OVERFLOW &&
              controller_status::kTxOverflow == CAN_ERR_CRTL_TX_OVERFLOW &&
              controller_status::kRxWarning == CAN_ERR_CRTL_RX_WARNING &&
              controller_status::kTxWarning == CAN_ERR_CRTL_TX_WARNING &&
              controller_status::kRxPassive == CAN_ERR_CRTL_RX_PASSIVE &&
              controller_status::kTxPassive == CAN_ERR_CRTL_TX_PASSIVE &&
              controller_status::kBackToActive == CAN_ERR_CRTL_ACTIVE);

namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;
constexpr std::int64_t kNsPerMs = 1'000'000;

// ---------------------------------------------------------------------------------------------
// Error frame text

// Appends to a fixed buffer without allocating; stops (still terminated) when it is full.
class TextBuffer {
 public:
  explicit TextBuffer(std::span<char> text) : text_(text) {
    if (!text_.empty()) text_[0] = '\0';
  }
  void add(const char* s) {
    while (*s != '\0' && length_ + 1 < text_.size()) text_[length_++] = *s++;
    if (!text_.empty()) text_[length_] = '\0';
  }
  void add_number(unsigned value) {
    std::array<char, 12> digits{};
    std::snprintf(digits.data(), digits.size(), "%u", value);
    add(digits.data());
  }
  // A new item: "; " between items, none before the first.
  void item(const char* s) {
    if (length_ > 0) add("; ");
    add(s);
  }
  [[nodiscard]] std::size_t length() const { return length_; }

 private:
  std::span<char> text_;
  std::size_t length_ = 0;
};

const char* protocol_location_name(std::uint8_t location) {
  switch (location) {
    case CAN_ERR_PROT_LOC_SOF: return "start of frame";
    case CAN_ERR_PROT_LOC_ID28_21: return "id bits 28-21";
    case CAN_ERR_PROT_LOC_ID20_18: return "id bits 20-18";
    case CAN_ERR_PROT_LOC_SRTR: return "substitute RTR";
    case CAN_ERR_PROT_LOC_IDE: return "id extension";
    case CAN_ERR_PROT_LOC_ID17_13: return "id bits 17-13";
    case CAN_ERR_PROT_LOC_ID12_05: return "id bits 12-5";
    case CAN_ERR_PROT_LOC_ID04_00: return "id bits 4-0";
    case CAN_ERR_PROT_LOC_RTR: return "RTR";
    case CAN_ERR_PROT_LOC_RES1: return "reserved bit 1";
    case CAN_ERR_PROT_LOC_RES0: return "reserved bit 0";
    case CAN_ERR_PROT_LOC_DLC: return "data length code";
    case CAN_ERR_PROT_LOC_DATA: return "data";
    case CAN_ERR_PROT_LOC_CRC_SEQ: return "CRC sequence";
    case CAN_ERR_PROT_LOC_CRC_DEL: return "CRC delimiter";
    case CAN_ERR_PROT_LOC_ACK: return "ACK slot";
    case CAN_ERR_PROT_LOC_ACK_DEL: return "ACK delimiter";
    case CAN_ERR_PROT_LOC_EOF: return "end of frame";
    case CAN_ERR_PROT_LOC_INTERM: return "intermission";
    default: return "unspecified location";
  }
}

struct BitName {
  std::uint32_t bit;
  const char* name;
};

constexpr std::array<BitName, 7> kControllerBits{{
    {CAN_ERR_CRTL_RX_OVERFLOW, "rx overflow"},
    {CAN_ERR_CRTL_TX_OVERFLOW, "tx overflow"},
    {CAN_ERR_CRTL_RX_WARNING, "rx error-warning"},
    {CAN_ERR_CRTL_TX_WARNING, "tx error-warning"},
    {CAN_ERR_CRTL_RX_PASSIVE, "rx error-passive"},
    {CAN_ERR_CRTL_TX_PASSIVE, "tx error-passive"},
    {CAN_ERR_CRTL_ACTIVE, "back to error-active"},
}};

constexpr std::array<BitName, 8> kProtocolBits{{
    {CAN_ERR_PROT_BIT, "bit error"},
    {CAN_ERR_PROT_FORM, "form error"},
    {CAN_ERR_PROT_STUFF, "stuff error"},
    {CAN_ERR_PROT_BIT0, "cannot send dominant bit"},
    {CAN_ERR_PROT_BIT1, "cannot send recessive bit"},
    {CAN_ERR_PROT_OVERLOAD, "bus overload"},
    {CAN_ERR_PROT_ACTIVE, "active error announcement"},
    {CAN_ERR_PROT_TX, "on transmission"},
}};

// Error classes that carry no detail bytes, in the order describe_bus_error() names them.
constexpr std::array<BitName, 4> kPlainClasses{{
    {CAN_ERR_ACK, "no ACK on transmission"},
    {CAN_ERR_TX_TIMEOUT, "transmit timeout"},
    {CAN_ERR_BUSERROR, "bus error"},
    {CAN_ERR_RESTARTED, "controller restarted"},
}};

void add_bits(TextBuffer& text, std::uint32_t value, std::span<const BitName> names) {
  bool first = true;
  for (const BitName& b : names) {
    if ((value & b.bit) == 0) continue;
    text.add(first ? " " : ", ");
    text.add(b.name);
    first = false;
  }
  if (first) text.add(" unspecified");
}

// ---------------------------------------------------------------------------------------------
// Opening

SocketCanOpenResult open_failure(OpenError error, int error_number, std::string_view name,
                                 const std::string& cause) {
  SocketCanOpenResult result;
  result.error = error;
  result.error_number = error_number;
  result.message = "cannot open CAN interface " + std::string(name) + ": " + cause;
  if (error_number != 0) result.message += " (" + std::string(std::strerror(error_number)) + ")";
  return result;
}

// Closes an fd on every early return of open().
class FdGuard {
 public:
  explicit FdGuard(int fd) : fd_(fd) {}
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  ~FdGuard() {
    if (fd_ >= 0) ::close(fd_);
  }
  [[nodiscard]] int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

int set_int_option(int fd, int level, int option, int value) {
  return setsockopt(fd, level, option, &value, sizeof(value)) == 0 ? 0 : errno;
}

int set_filter_option(int fd, std::span<const CanIdFilter> filters) {
  // The kernel copies the array (layout checked above): no allocation here.
  const auto bytes = static_cast<socklen_t>(filters.size_bytes());
  return setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.empty() ? nullptr : filters.data(),
                    bytes) == 0
             ? 0
             : errno;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Error frames

constexpr NameTable<ControllerState, 6> kControllerStateNames{{{
    {ControllerState::kErrorActive, "error-active"},
    {ControllerState::kErrorWarning, "error-warning"},
    {ControllerState::kErrorPassive, "error-passive"},
    {ControllerState::kBusOff, "bus-off"},
    {ControllerState::kStopped, "stopped"},
    {ControllerState::kSleeping, "sleeping"},
}}};

const char* controller_state_name(ControllerState state) {
  return kControllerStateNames.name(state);
}

CanBusError decode_error_frame(std::uint32_t can_id, const std::array<std::uint8_t, 8>& data) {
  CanBusError e;
  e.classes = can_id & CAN_ERR_MASK;
  e.arbitration_bit = data[0];
  e.controller = data[1];
  e.protocol_type = data[2];
  e.protocol_location = data[3];
  e.transceiver = data[4];
  e.tx_error_count = data[6];
  e.rx_error_count = data[7];
  return e;
}

ControllerState error_state(const CanBusError& error) {
  if (error.has(bus_error_class::kBusOff)) return ControllerState::kBusOff;
  if (!error.has(bus_error_class::kController)) return ControllerState::kErrorActive;
  if ((error.controller & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
    return ControllerState::kErrorPassive;
  }
  if ((error.controller & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
    return ControllerState::kErrorWarning;
  }
  return ControllerState::kErrorActive;
}

std::size_t describe_bus_error(const CanBusError& error, std::span<char> text_out) {
  TextBuffer text(text_out);
  using namespace bus_error_class;
  if (error.has(kBusOff)) text.item("bus-off");
  if (error.has(kController)) {
    text.item("controller:");
    add_bits(text, error.controller, kControllerBits);
  }
  if (error.has(kProtocolViolation)) {
    text.item("protocol violation:");
    add_bits(text, error.protocol_type, kProtocolBits);
    text.add(" at ");
    text.add(protocol_location_name(error.protocol_location));
  }
  if (error.has(kLostArbitration)) {
    text.item("lost arbitration");
    if (error.arbitration_bit != 0) {
      text.add(" at bit ");
      text.add_number(error.arbitration_bit);
    }
  }
  if (error.has(kTransceiver)) {
    std::array<char, 32> status{};
    std::snprintf(status.data(), status.size(), "transceiver status 0x%02x", error.transceiver);
    text.item(status.data());
  }
  for (const BitName& c : kPlainClasses) {
    if (error.has(c.bit)) text.item(c.name);
  }
  if (error.has(kCounters)) {
    text.item("counters tx ");
    text.add_number(error.tx_error_count);
    text.add(" rx ");
    text.add_number(error.rx_error_count);
  }
  if (text.length() == 0) text.add("error frame without class");
  return text.length();
}

// ---------------------------------------------------------------------------------------------
// SocketCanPort

SocketCanOpenResult SocketCanPort::open(std::string_view interface_name,
                                        const SocketCanOptions& options) {
  if (interface_name.empty()) {
    return open_failure(OpenError::kBadName, 0, "\"\"", "the interface name is empty");
  }
  if (interface_name.size() >= IFNAMSIZ) {
    return open_failure(OpenError::kBadName, 0, interface_name,
                        "the name has " + std::to_string(interface_name.size()) +
                            " characters, Linux allows at most " + std::to_string(IFNAMSIZ - 1));
  }
  const std::string name(interface_name);

  FdGuard fd(socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
  const int socket_error = fd.get() < 0 ? errno : 0;
  // A missing interface is said first, whatever else is wrong (a mistyped name on a machine
  // without CAN is still a mistyped name); the kernel's lack of CAN follows it.
  const unsigned index = if_nametoindex(name.c_str());
  if (index == 0) {
    const int e = errno;
    return open_failure(OpenError::kNoSuchInterface, e == 0 ? ENODEV : e, name,
                        "the interface does not exist (ip link add dev " + name +
                            " type vcan, for a virtual bus" +
                            (socket_error == EAFNOSUPPORT
                                 ? std::string("; and this kernel has no CAN support: a kernel "
                                               "built with CONFIG_CAN, or a guest kernel: "
                                               "tools/vcan-bus.sh")
                                 : std::string()) +
                            ")");
  }
  if (fd.get() < 0) {
    const int e = socket_error;
    if (e == EAFNOSUPPORT) {
      return open_failure(OpenError::kNoCanSupport, e, name,
                          "this kernel has no CAN support (socket(AF_CAN) refused; a kernel "
                          "built with CONFIG_CAN, or a guest kernel: tools/vcan-bus.sh)");
    }
    if (e == EPROTONOSUPPORT) {
      return open_failure(OpenError::kNoCanSupport, e, name,
                          "this kernel has CAN but no raw CAN sockets (load module can-raw)");
    }
    if (e == EPERM || e == EACCES) {
      return open_failure(OpenError::kPermissionDenied, e, name, "socket(AF_CAN) not permitted");
    }
    return open_failure(OpenError::kSystemError, e, name, "socket(AF_CAN) failed");
  }

  ifreq request{};
  std::memcpy(request.ifr_name, name.c_str(), name.size() + 1);
  if (ioctl(fd.get(), SIOCGIFFLAGS, &request) != 0) {
    return open_failure(OpenError::kSystemError, errno, name, "reading its flags failed");
  }
  // Binding to a down interface succeeds, but nothing would ever arrive: say so now.
  if ((request.ifr_flags & IFF_UP) == 0) {
    return open_failure(OpenError::kInterfaceDown, 0, name,
                        "the interface is down (ip link set " + name + " up)");
  }

  const std::span<const CanIdFilter> filters = options.filters;
  if (const int e = set_filter_option(fd.get(), filters); e != 0) {
    return open_failure(OpenError::kSystemError, e, name, "setting the receive filters failed");
  }
  if (options.error_frames) {
    if (const int e = set_int_option(fd.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER,
                                     static_cast<int>(CAN_ERR_MASK));
        e != 0) {
      return open_failure(OpenError::kSystemError, e, name, "enabling error frames failed");
    }
  }
  if (options.receive_own_frames) {
    if (const int e = set_int_option(fd.get(), SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, 1); e != 0) {
      return open_failure(OpenError::kSystemError, e, name, "CAN_RAW_RECV_OWN_MSGS failed");
    }
  }
  if (options.receive_buffer_bytes > 0) {
    if (const int e = set_int_option(fd.get(), SOL_SOCKET, SO_RCVBUF, options.receive_buffer_bytes);
        e != 0) {
      return open_failure(OpenError::kSystemError, e, name, "SO_RCVBUF failed");
    }
  }
  if (const int e = set_int_option(fd.get(), SOL_SOCKET, SO_TIMESTAMPNS, 1); e != 0) {
    return open_failure(OpenError::kSystemError, e, name, "enabling receive timestamps failed");
  }
  if (const int e = set_int_option(fd.get(), SOL_SOCKET, SO_RXQ_OVFL, 1); e != 0) {
    return open_failure(OpenError::kSystemError, e, name, "enabling the drop counter failed");
  }

  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  if (bind(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof(address)) != 0) {
    const int e = errno;
    if (e == ENODEV) {
      // The name exists (if_nametoindex found it): the kernel refuses non-CAN devices so.
      return open_failure(OpenError::kNotCanInterface, e, name, "the interface is not CAN");
    }
    return open_failure(OpenError::kSystemError, e, name, "bind failed");
  }

  SocketCanOpenResult result;
  result.port = SocketCanPort(fd.release(), interface_name);
  return result;
}

SocketCanPort::SocketCanPort(int fd, std::string_view interface_name) : fd_(fd) {
  std::memcpy(interface_name_.data(), interface_name.data(), interface_name.size());
}

SocketCanPort::SocketCanPort(SocketCanPort&& other) noexcept { *this = std::move(other); }

SocketCanPort& SocketCanPort::operator=(SocketCanPort&& other) noexcept {
  if (this == &other) return *this;
  close_fd();
  fd_ = std::exchange(other.fd_, -1);
  interface_name_ = other.interface_name_;
  pending_ = std::exchange(other.pending_, std::nullopt);
  last_drop_count_ = other.last_drop_count_;
  dropped_frames_ = other.dropped_frames_;
  total_dropped_frames_ = other.total_dropped_frames_;
  last_bus_error_ = other.last_bus_error_;
  last_rejected_can_id_ = other.last_rejected_can_id_;
  last_rejected_was_fd_ = other.last_rejected_was_fd_;
  last_error_ = other.last_error_;
  return *this;
}

SocketCanPort::~SocketCanPort() { close_fd(); }

void SocketCanPort::close_fd() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

int SocketCanPort::set_filters(std::span<const CanIdFilter> filters) {
  if (fd_ < 0) return EBADF;
  return set_filter_option(fd_, filters);
}

bool SocketCanPort::transmit_queue_full() const {
  return last_error_ == ENOBUFS || last_error_ == EAGAIN || last_error_ == EWOULDBLOCK;
}

IoStatus SocketCanPort::send(const can::CanFrame& frame) {
  if (fd_ < 0) {
    last_error_ = EBADF;
    return IoStatus::kIoError;
  }
  if (frame.id > CAN_SFF_MASK || frame.length > CAN_MAX_DLEN) {
    last_error_ = EINVAL;
    return IoStatus::kIoError;
  }
  can_frame out{};
  out.can_id = frame.id;
  out.len = frame.length;
  std::memcpy(out.data, frame.data.data(), frame.length);
  const ssize_t written = ::send(fd_, &out, sizeof(out), MSG_DONTWAIT);
  if (written == static_cast<ssize_t>(sizeof(out))) return IoStatus::kOk;
  last_error_ = written < 0 ? errno : EIO;
  return IoStatus::kIoError;
}

// The kernel counts, per socket, the frames it dropped because the receive queue was full. It
// tells the count with each frame queued after a drop (SO_RXQ_OVFL) and, on request, at any time
// (SO_MEMINFO): receive() asks before reporting a timeout, so drops at the end of a burst are
// not left unsaid until the next frame.
bool SocketCanPort::kernel_drop_counter(std::uint32_t& drop_count) const {
  std::array<std::uint32_t, SK_MEMINFO_VARS> meminfo{};
  socklen_t size = sizeof(meminfo);
  if (getsockopt(fd_, SOL_SOCKET, SO_MEMINFO, meminfo.data(), &size) != 0) return false;
  if (size < (SK_MEMINFO_DROPS + 1) * sizeof(std::uint32_t)) return false;
  drop_count = meminfo[SK_MEMINFO_DROPS];
  return true;
}

bool SocketCanPort::drops_grew(std::uint32_t drop_count) {
  // Unsigned difference: right across the counter's wrap.
  const std::uint32_t grown = drop_count - last_drop_count_;
  if (grown == 0) return false;
  last_drop_count_ = drop_count;
  dropped_frames_ = grown;
  total_dropped_frames_ += grown;
  return true;
}

SocketCanPort::ReadResult SocketCanPort::read_frame(RawFrame& raw, std::uint32_t& drop_count) {
  canfd_frame frame{};  // large enough for either kind; the read length tells which
  iovec iov{&frame, sizeof(frame)};
  // Room for the timestamp and the drop counter; aligned for cmsghdr.
  alignas(cmsghdr) std::array<unsigned char, CMSG_SPACE(sizeof(timespec)) +
                                                 CMSG_SPACE(sizeof(std::uint32_t))>
      control{};
  msghdr message{};
  message.msg_iov = &iov;
  message.msg_iovlen = 1;
  message.msg_control = control.data();
  message.msg_controllen = control.size();

  const ssize_t n = recvmsg(fd_, &message, MSG_DONTWAIT);
  if (n < 0) {
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return ReadResult::kEmpty;
    last_error_ = errno;
    return ReadResult::kError;
  }

  raw = RawFrame{};
  raw.can_id = frame.can_id;
  raw.fd = n == static_cast<ssize_t>(CANFD_MTU);
  if (!raw.fd && n != static_cast<ssize_t>(CAN_MTU)) {
    last_error_ = EIO;  // neither a classic nor an FD frame: nothing we can interpret
    return ReadResult::kError;
  }
  raw.length = frame.len > CAN_MAX_DLEN ? static_cast<std::uint8_t>(CAN_MAX_DLEN) : frame.len;
  std::memcpy(raw.data.data(), frame.data, raw.length);

  bool stamped = false;
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof(ts));
      raw.timestamp_ns = static_cast<std::int64_t>(ts.tv_sec) * kNsPerSecond + ts.tv_nsec;
      stamped = true;
    } else if (c->cmsg_type == SO_RXQ_OVFL) {
      std::memcpy(&drop_count, CMSG_DATA(c), sizeof(drop_count));
    }
  }
  // The kernel stamps every frame once SO_TIMESTAMPNS is on; this only guards the contract.
  if (!stamped) raw.timestamp_ns = realtime_now_ns();
  return ReadResult::kFrame;
}

IoStatus SocketCanPort::classify(const RawFrame& raw, TimedFrame& out) {
  if ((raw.can_id & CAN_ERR_FLAG) != 0) {
    last_bus_error_ = decode_error_frame(raw.can_id, raw.data);
    return IoStatus::kBusError;
  }
  const std::uint32_t id = raw.can_id & CAN_SFF_MASK;
  if (raw.fd || (raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG)) != 0 || id < can::kFirstPlinthId ||
      id > can::kLastPlinthId) {
    last_rejected_can_id_ = raw.can_id;
    last_rejected_was_fd_ = raw.fd;
    return IoStatus::kNotPlinth;
  }
  out.frame.id = id;
  out.frame.length = raw.length;
  out.frame.data = raw.data;
  out.timestamp_ns = raw.timestamp_ns;
  return IoStatus::kOk;
}

IoStatus SocketCanPort::receive(TimedFrame& out, int timeout_ms) {
  if (fd_ < 0) {
    last_error_ = EBADF;
    return IoStatus::kIoError;
  }
  if (pending_) {
    const RawFrame raw = *pending_;
    pending_.reset();
    return classify(raw, out);
  }
  const std::int64_t deadline_ns = monotonic_now_ns() + std::int64_t{timeout_ms} * kNsPerMs;
  for (;;) {
    RawFrame raw;
    std::uint32_t drop_count = last_drop_count_;  // no cmsg: the counter did not move
    switch (read_frame(raw, drop_count)) {
      case ReadResult::kFrame:
        if (drops_grew(drop_count)) {
          pending_ = raw;  // dropped frames came before this one: report them first
          return IoStatus::kOverflow;
        }
        return classify(raw, out);
      case ReadResult::kError:
        return IoStatus::kIoError;
      case ReadResult::kEmpty:
        break;
    }

    int wait_ms = -1;
    if (timeout_ms >= 0) {
      const std::int64_t left_ns = deadline_ns - monotonic_now_ns();
      // Round up: poll() waiting 0 ms short of the deadline would spin.
      wait_ms = left_ns <= 0 ? 0 : static_cast<int>((left_ns + kNsPerMs - 1) / kNsPerMs);
    }
    if (wait_ms == 0) {
      std::uint32_t counter = 0;
      if (kernel_drop_counter(counter) && drops_grew(counter)) return IoStatus::kOverflow;
      return IoStatus::kTimeout;
    }
    pollfd p{fd_, POLLIN, 0};
    const int ready = poll(&p, 1, wait_ms);
    if (ready < 0 && errno != EINTR) {
      last_error_ = errno;
      return IoStatus::kIoError;
    }
    // Readable, an error pending (POLLERR: recvmsg returns it), EINTR or the time is up: the
    // loop reads again, then checks the deadline.
  }
}

}  // namespace plinth::hal
