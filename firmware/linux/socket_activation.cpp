#include "socket_activation.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>

#include "plinth/host/input_error.h"

namespace plinth::firmware {

namespace {

// The port a bound IPv4 or IPv6 socket listens on, or -1.
int bound_port(int fd) {
  sockaddr_storage address{};
  socklen_t length = sizeof address;
  if (getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) return -1;
  if (address.ss_family == AF_INET) {
    return ntohs(reinterpret_cast<const sockaddr_in*>(&address)->sin_port);
  }
  if (address.ss_family == AF_INET6) {
    return ntohs(reinterpret_cast<const sockaddr_in6*>(&address)->sin6_port);
  }
  return -1;
}

}  // namespace

int inherited_listening_socket(const std::string& name, int port, const std::string& where) {
  char** names = nullptr;
  const int count = sd_listen_fds_with_names(1, &names);
  if (count <= 0) return -1;
  int found = -1;
  for (int i = 0; i < count; ++i) {
    const int fd = SD_LISTEN_FDS_START + i;
    if (found < 0 && names != nullptr && names[i] != nullptr && name == names[i]) {
      found = fd;
    } else {
      close(fd);  // not ours: no descriptor leaks into the loop
    }
    if (names != nullptr) std::free(names[i]);
  }
  std::free(static_cast<void*>(names));
  if (found < 0) return -1;
  if (sd_is_socket(found, AF_UNSPEC, SOCK_STREAM, 1) <= 0) {
    close(found);
    throw host::InputError(where + ": the socket systemd passed as '" + name +
                           "' is not a listening TCP socket");
  }
  const int passed_port = bound_port(found);
  if (passed_port != port) {
    close(found);
    throw host::InputError(where + ": the socket systemd passed as '" + name + "' listens on port " +
                           std::to_string(passed_port) + ", the configuration says " +
                           std::to_string(port) + " (make them agree: ListenStream= of the "
                           "socket unit)");
  }
  return found;
}

}  // namespace plinth::firmware
