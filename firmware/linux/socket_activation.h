// Sockets that systemd opened for the service and passed to it (socket activation,
// sd_listen_fds(3)): plinth-monitor@.socket binds Modbus TCP's port 502, which an unprivileged
// process cannot, and passes the listening socket named "modbus" (FileDescriptorName=). Host
// code: may throw.
#pragma once

#include <string>

namespace plinth::firmware {

// The listening TCP socket passed under `name`, or -1 when none was (not socket-activated: the
// caller binds its own). The passed sockets are taken once (LISTEN_FDS is unset), and the ones
// not asked for are closed. Throws host::InputError naming `where` when the socket passed is not
// a listening stream socket or listens on another port than `port`.
[[nodiscard]] int inherited_listening_socket(const std::string& name, int port,
                                             const std::string& where);

}  // namespace plinth::firmware
