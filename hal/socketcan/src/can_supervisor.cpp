// CanInterfaceSupervisor: link flags through SIOCGIFFLAGS, the link kind through rtnetlink, the
// controller through libsocketcan.
#include "plinth/hal/can_supervisor.h"

#include <libsocketcan.h>
#include <linux/if_link.h>
#include <linux/netlink.h>
#include <linux/rtnetlink.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <utility>

#include "plinth/core/name_table.h"

namespace plinth::hal {

namespace {

// The rtnetlink link kind of a real CAN controller (drivers/net/can/dev/netlink.c).
constexpr std::string_view kControllerLinkKind = "can";

SupervisionResult failure(int error_number, std::string message) {
  SupervisionResult r;
  r.status = SupervisionStatus::kFailed;
  r.error_number = error_number;
  r.message = std::move(message);
  if (error_number != 0) r.message += std::string(" (") + std::strerror(error_number) + ")";
  return r;
}

// A socket closed on scope exit.
class Socket {
 public:
  Socket(int domain, int type, int protocol) : fd_(socket(domain, type | SOCK_CLOEXEC, protocol)) {}
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  ~Socket() {
    if (fd_ >= 0) close(fd_);
  }
  [[nodiscard]] int fd() const { return fd_; }

 private:
  int fd_;
};

// Attributes of a netlink message, walked without the kernel's C-cast macros.
template <typename Visit>
void for_each_attribute(const unsigned char* data, std::size_t length, Visit visit) {
  while (length >= sizeof(rtattr)) {
    rtattr attribute{};
    std::memcpy(&attribute, data, sizeof(attribute));
    if (attribute.rta_len < sizeof(rtattr) || attribute.rta_len > length) return;
    visit(attribute.rta_type, data + RTA_LENGTH(0), attribute.rta_len - RTA_LENGTH(0));
    const std::size_t step = RTA_ALIGN(attribute.rta_len);
    if (step >= length) return;
    data += step;
    length -= step;
  }
}

// The IFLA_INFO_KIND of interface `index` ("" when it has none, like lo or eth0), or the errno.
int query_link_kind(unsigned index, std::string& kind) {
  Socket nl(AF_NETLINK, SOCK_RAW, NETLINK_ROUTE);
  if (nl.fd() < 0) return errno;

  struct {
    nlmsghdr header;
    ifinfomsg info;
  } request{};
  request.header.nlmsg_len = sizeof(request);
  request.header.nlmsg_type = RTM_GETLINK;
  request.header.nlmsg_flags = NLM_F_REQUEST;
  request.header.nlmsg_seq = 1;
  request.info.ifi_family = AF_UNSPEC;
  request.info.ifi_index = static_cast<int>(index);
  if (send(nl.fd(), &request, sizeof(request), 0) < 0) return errno;

  alignas(nlmsghdr) std::array<unsigned char, 32768> reply{};
  const ssize_t n = recv(nl.fd(), reply.data(), reply.size(), 0);
  if (n < 0) return errno;
  if (static_cast<std::size_t>(n) < sizeof(nlmsghdr)) return EIO;
  nlmsghdr header{};
  std::memcpy(&header, reply.data(), sizeof(header));
  if (header.nlmsg_type == NLMSG_ERROR) {
    nlmsgerr error{};
    std::memcpy(&error, reply.data() + NLMSG_HDRLEN, sizeof(error));
    return error.error < 0 ? -error.error : EIO;
  }
  if (header.nlmsg_type != RTM_NEWLINK || header.nlmsg_len > static_cast<std::size_t>(n)) {
    return EIO;
  }
  const std::size_t attributes_at = NLMSG_HDRLEN + NLMSG_ALIGN(sizeof(ifinfomsg));
  if (header.nlmsg_len < attributes_at) return EIO;

  kind.clear();
  for_each_attribute(reply.data() + attributes_at, header.nlmsg_len - attributes_at,
                     [&](unsigned type, const unsigned char* value, std::size_t size) {
                       if (type != IFLA_LINKINFO) return;
                       for_each_attribute(value, size, [&](unsigned inner, const unsigned char* v,
                                                           std::size_t s) {
                         if (inner != IFLA_INFO_KIND) return;
                         const auto* text = reinterpret_cast<const char*>(v);
                         kind.assign(text, strnlen(text, s));
                       });
                     });
  return 0;
}

ControllerState from_libsocketcan(int state) {
  switch (state) {
    case CAN_STATE_ERROR_ACTIVE: return ControllerState::kErrorActive;
    case CAN_STATE_ERROR_WARNING: return ControllerState::kErrorWarning;
    case CAN_STATE_ERROR_PASSIVE: return ControllerState::kErrorPassive;
    case CAN_STATE_BUS_OFF: return ControllerState::kBusOff;
    case CAN_STATE_STOPPED: return ControllerState::kStopped;
    case CAN_STATE_SLEEPING: return ControllerState::kSleeping;
    default: return ControllerState::kStopped;
  }
}

}  // namespace

constexpr NameTable<SupervisionStatus, 3> kSupervisionStatusNames{{{
    {SupervisionStatus::kOk, "ok"},
    {SupervisionStatus::kNotSupported, "not supported on this interface"},
    {SupervisionStatus::kFailed, "failed"},
}}};

const char* supervision_status_name(SupervisionStatus status) {
  return kSupervisionStatusNames.name(status);
}

CanInterfaceSupervisor::CanInterfaceSupervisor(std::string_view interface_name)
    : interface_name_(interface_name) {}

Supervised<std::string> CanInterfaceSupervisor::link_kind() const {
  Supervised<std::string> out;
  const unsigned index = if_nametoindex(interface_name_.c_str());
  if (index == 0) {
    out.result = failure(errno, "CAN interface " + interface_name_ + " does not exist");
    return out;
  }
  if (const int e = query_link_kind(index, out.value); e != 0) {
    out.result = failure(e, "cannot read the link kind of " + interface_name_);
  }
  return out;
}

Supervised<LinkState> CanInterfaceSupervisor::link_state() const {
  Supervised<LinkState> out;
  if (interface_name_.empty() || interface_name_.size() >= IFNAMSIZ) {
    out.result = failure(0, "\"" + interface_name_ + "\" is not a valid interface name");
    return out;
  }
  // Any socket serves for SIOCGIFFLAGS; AF_INET exists where AF_CAN may not.
  Socket s(AF_INET, SOCK_DGRAM, 0);
  if (s.fd() < 0) {
    out.result = failure(errno, "cannot read the flags of " + interface_name_);
    return out;
  }
  ifreq request{};
  std::memcpy(request.ifr_name, interface_name_.c_str(), interface_name_.size() + 1);
  if (ioctl(s.fd(), SIOCGIFFLAGS, &request) != 0) {
    const int e = errno;
    out.result = e == ENODEV ? failure(e, "CAN interface " + interface_name_ + " does not exist")
                             : failure(e, "cannot read the flags of " + interface_name_);
    return out;
  }
  out.value.up = (request.ifr_flags & IFF_UP) != 0;
  out.value.running = (request.ifr_flags & IFF_RUNNING) != 0;
  return out;
}

SupervisionResult CanInterfaceSupervisor::controller_support() const {
  Supervised<std::string> kind = link_kind();
  if (!kind.result.ok()) return kind.result;
  if (kind.value == kControllerLinkKind) return {};
  // libsocketcan would return -1 here (and print "no link data found"): the interface has no
  // controller, which is not a fault.
  SupervisionResult r;
  r.status = SupervisionStatus::kNotSupported;
  r.message = interface_name_ + " is a " + (kind.value.empty() ? "non-CAN" : kind.value) +
              " interface: it has no CAN controller state, restart or error counters";
  return r;
}

SupervisionResult CanInterfaceSupervisor::libsocketcan_failure(const char* call,
                                                               int saved_errno) const {
  return failure(saved_errno, std::string(call) + " on " + interface_name_ + " failed" +
                                  (saved_errno == 0 ? " (libsocketcan gave no reason)" : ""));
}

SupervisionResult CanInterfaceSupervisor::start() const {
  errno = 0;
  if (can_do_start(interface_name_.c_str()) != 0) {
    return libsocketcan_failure("can_do_start", errno);
  }
  return {};
}

SupervisionResult CanInterfaceSupervisor::stop() const {
  errno = 0;
  if (can_do_stop(interface_name_.c_str()) != 0) return libsocketcan_failure("can_do_stop", errno);
  return {};
}

Supervised<ControllerState> CanInterfaceSupervisor::state() const {
  Supervised<ControllerState> out;
  out.result = controller_support();
  if (!out.result.ok()) return out;
  int state = 0;
  errno = 0;
  if (can_get_state(interface_name_.c_str(), &state) != 0) {
    out.result = libsocketcan_failure("can_get_state", errno);
    return out;
  }
  out.value = from_libsocketcan(state);
  return out;
}

SupervisionResult CanInterfaceSupervisor::restart() const {
  const Supervised<ControllerState> current = state();
  if (!current.result.ok()) return current.result;
  // libsocketcan refuses these two cases with -1 and a line on stderr; say why instead.
  if (current.value != ControllerState::kBusOff) {
    return failure(0, interface_name_ + " is " + controller_state_name(current.value) +
                          ", not bus-off: there is nothing to restart");
  }
  __u32 restart_ms = 0;
  if (can_get_restart_ms(interface_name_.c_str(), &restart_ms) == 0 && restart_ms > 0) {
    return failure(0, interface_name_ + " restarts itself after bus-off every " +
                          std::to_string(restart_ms) + " ms (restart-ms)");
  }
  errno = 0;
  if (can_do_restart(interface_name_.c_str()) != 0) {
    return libsocketcan_failure("can_do_restart", errno);
  }
  return {};
}

Supervised<ErrorCounters> CanInterfaceSupervisor::error_counters() const {
  Supervised<ErrorCounters> out;
  out.result = controller_support();
  if (!out.result.ok()) return out;
  can_berr_counter counters{};
  errno = 0;
  if (can_get_berr_counter(interface_name_.c_str(), &counters) != 0) {
    out.result = libsocketcan_failure("can_get_berr_counter", errno);
    return out;
  }
  out.value.tx = counters.txerr;
  out.value.rx = counters.rxerr;
  return out;
}

}  // namespace plinth::hal
