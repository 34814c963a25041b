#include "modbus_server.h"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "plinth/host/input_error.h"
#include "socket_activation.h"
#include "status_json.h"

namespace plinth::firmware {

namespace {

constexpr int kPollTimeoutMs = 20;    // how soon the thread sees stop() and new snapshots
constexpr int kFramesPerTurn = 4;     // a client's frames answered before the next client's
// Connections taken each turn: every client's bytes are read between two such, so a client
// that connects and asks at once is answered (and kept) before newer connections can push it
// out as the idlest.
constexpr int kAcceptsPerTurn = 2;
constexpr int kListenBacklog = 64;

std::int64_t ns_of(double seconds) { return static_cast<std::int64_t>(seconds * 1e9); }

void set_nonblocking(int socket) {
  const int flags = fcntl(socket, F_GETFL, 0);
  if (flags >= 0) (void)fcntl(socket, F_SETFL, flags | O_NONBLOCK);
}

}  // namespace

ModbusServer::ModbusServer(const ModbusSettings& settings, const RunIdentity& identity)
    : settings_(settings) {
  modbus::fill_identity(identity, image_);
  const Endpoint endpoint = parse_endpoint(settings.listen, settings.listen_where);
  for (const std::string& text : settings.write_from) {
    std::optional<AddressPrefix> prefix = parse_address_prefix(text);
    if (!prefix) {
      throw host::InputError("modbus.write_from: \"" + text +
                             "\" is not an address or ADDRESS/BITS prefix");
    }
    writers_.push_back(*prefix);
  }
  // Under systemd, the socket unit's listening socket (port 502 without privileges); else ours.
  listen_socket_ = inherited_listening_socket("modbus", endpoint.port, settings.listen_where);
  if (listen_socket_ < 0) listen_at(endpoint.host, endpoint.port);
  set_nonblocking(listen_socket_);
  publish_image();
  thread_ = std::thread([this] { serve(); });
}

ModbusServer::~ModbusServer() {
  stop();
  for (const Client& c : clients_) close(c.socket);
  if (listen_socket_ >= 0) close(listen_socket_);
}

// Binds the first of `host`'s addresses that takes the port (as a server does for "localhost",
// which resolves to ::1 and 127.0.0.1).
void ModbusServer::listen_at(const std::string& host, int port) {
  const std::string text = Endpoint{host, port}.text();
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* list = nullptr;
  const int rc = getaddrinfo(host.empty() ? nullptr : host.c_str(), std::to_string(port).c_str(),
                             &hints, &list);
  if (rc != 0) {
    throw host::InputError(settings_.listen_where + ": cannot listen at " + text + ": " +
                           gai_strerror(rc));
  }
  int error = 0;
  for (const addrinfo* a = list; a != nullptr && listen_socket_ < 0; a = a->ai_next) {
    const int s = socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (s < 0) {
      error = errno;
      continue;
    }
    const int on = 1;
    (void)setsockopt(s, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    if (bind(s, a->ai_addr, a->ai_addrlen) == 0 && listen(s, kListenBacklog) == 0) {
      listen_socket_ = s;
    } else {
      error = errno;
      close(s);
    }
  }
  freeaddrinfo(list);
  if (listen_socket_ < 0) {
    throw host::InputError(settings_.listen_where + ": cannot listen at " + text + ": " +
                           std::strerror(error) +
                           (error == EADDRINUSE ? " (another program has the port)" : ""));
  }
}

void ModbusServer::stop() {
  stopping_.store(true);
  if (thread_.joinable()) thread_.join();
}

// The newest snapshot into the registers; alarm events counted.
void ModbusServer::refresh() {
  AlarmNotice notice;
  bool changed = false;
  while (mailbox_.take_alarm(notice)) {
    ++alarm_events_;
    changed = true;
  }
  if (mailbox_.take_status(snapshot_)) changed = true;
  if (changed) publish_image();
}

void ModbusServer::publish_image() { modbus::fill(snapshot_, alarm_events_, image_); }

void ModbusServer::serve() {
  std::vector<pollfd> polled;
  bool more = false;  // a client holds whole frames not answered yet: look again at once
  while (!stopping_.load(std::memory_order_relaxed)) {
    refresh();
    polled.assign(1, pollfd{listen_socket_, POLLIN, 0});
    for (const Client& c : clients_) polled.push_back({c.socket, POLLIN, 0});
    if (poll(polled.data(), polled.size(), more ? 0 : kPollTimeoutMs) < 0 && errno != EINTR) {
      break;
    }
    const std::int64_t now = monotonic_ns();
    more = false;
    // Clients first (the indexes of `polled` are theirs), then new connections.
    for (std::size_t i = clients_.size(); i-- > 0;) {
      Client& c = clients_[i];
      Closed closed = Closed::kNo;
      if ((polled[i + 1].revents & (POLLIN | POLLHUP | POLLERR)) != 0) closed = read_from(c, now);
      if (closed == Closed::kNo) {
        refresh();
        bool client_more = false;
        closed = answer_frames(c, now, client_more);
        more = more || client_more;
      }
      if (closed != Closed::kNo) close_client(i);
    }
    if ((polled[0].revents & POLLIN) != 0) accept_clients(now);
    close_expired(now);
  }
}

// Pending connections (kAcceptsPerTurn): a slot made for each (make_room), never a refusal.
void ModbusServer::accept_clients(std::int64_t now_ns) {
  for (int taken = 0; taken < kAcceptsPerTurn; ++taken) {
    Client c;
    socklen_t length = sizeof c.peer;
    c.socket = accept4(listen_socket_, reinterpret_cast<sockaddr*>(&c.peer), &length,
                       SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (c.socket < 0) return;  // EAGAIN: none left (or a transient error: next turn)
    const int on = 1;
    (void)setsockopt(c.socket, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
    c.may_write = settings_.writes && std::any_of(writers_.begin(), writers_.end(),
                                                  [&](const AddressPrefix& p) {
                                                    return p.contains(c.peer);
                                                  });
    c.connected_ns = now_ns;
    if (static_cast<int>(clients_.size()) >= settings_.max_clients) make_room();
    clients_.push_back(c);
    ++connections_;
    max_clients_seen_ = std::max(max_clients_seen_, static_cast<int>(clients_.size()));
  }
}

// Closes one client to take a new one: from the address that holds the most connections (one
// host cannot starve the others), the one never answered that connected first, else the one
// idle longest: a client that only connects, or only sends what is refused, gives its slot up
// before one the box has served.
void ModbusServer::make_room() {
  const auto same_host = [](const Client& a, const Client& b) {
    return AddressPrefix::same_address(a.peer, b.peer);
  };
  const auto rank = [](const Client& c) {
    return std::pair<bool, std::int64_t>(c.answered, std::max(c.connected_ns, c.last_request_ns));
  };
  std::size_t chosen = 0;
  std::size_t chosen_count = 0;
  for (std::size_t i = 0; i < clients_.size(); ++i) {
    const std::size_t count = static_cast<std::size_t>(
        std::count_if(clients_.begin(), clients_.end(),
                      [&](const Client& c) { return same_host(c, clients_[i]); }));
    if (count > chosen_count ||
        (count == chosen_count && rank(clients_[i]) < rank(clients_[chosen]))) {
      chosen = i;
      chosen_count = count;
    }
  }
  ++closed_for_room_;
  close_client(chosen);
}

ModbusServer::Closed ModbusServer::read_from(Client& c, std::int64_t now_ns) {
  if (c.used == c.received.size()) return Closed::kNo;  // whole frames wait: answer them first
  const ssize_t n = recv(c.socket, c.received.data() + c.used, c.received.size() - c.used, 0);
  if (n == 0) return Closed::kByPeer;
  if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? Closed::kNo
                                                                                : Closed::kByPeer;
  if (c.used == 0) c.frame_started_ns = now_ns;
  c.used += static_cast<std::size_t>(n);
  return Closed::kNo;
}

// Up to kFramesPerTurn of the client's whole frames answered; `more` when whole frames (or a
// fault) remain.
ModbusServer::Closed ModbusServer::answer_frames(Client& c, std::int64_t now_ns, bool& more) {
  std::array<std::uint8_t, modbus::kMaxFrameBytes> out{};
  for (int turn = 0; turn < kFramesPerTurn; ++turn) {
    const std::span<const std::uint8_t> bytes(c.received.data(), c.used);
    const modbus::FrameSpan frame = modbus::frame_at(bytes);
    modbus::Answer a;
    if (frame.fault != modbus::FrameFault::kNoFault) {
      a.fault = frame.fault;
    } else if (frame.bytes == 0) {
      return Closed::kNo;  // the rest of the frame has not come yet
    } else {
      ++requests_;
      c.last_request_ns = now_ns;
      a = modbus::answer(bytes.first(frame.bytes), image_, c.may_write, out);
    }
    if (a.fault != modbus::FrameFault::kNoFault) {
      ++malformed_;
      refused_log_.say(peer_text(c.peer) + ": not a Modbus frame (" +
                           modbus::kFrameFaultNames.name(a.fault) + "): connection closed",
                       now_ns);
      return Closed::kMalformed;
    }
    if (a.exception != modbus::Exception::kNoException) ++exceptions_;
    if (a.write_refused) {
      ++writes_refused_;
      if (settings_.writes && !c.may_write) {
        refused_log_.say(peer_text(c.peer) + ": coil write refused: not in modbus.write_from",
                         now_ns);
      }
    }
    if (a.exception == modbus::Exception::kNoException) c.answered = true;
    const ssize_t sent = send(c.socket, out.data(), a.bytes, MSG_NOSIGNAL | MSG_DONTWAIT);
    if (sent != static_cast<ssize_t>(a.bytes)) {
      ++closed_unread_;  // the client does not read its answers (or is gone)
      return Closed::kSlowReader;
    }
    if (a.acknowledge) post_command(OperatorCommand::kAcknowledge);
    if (a.reset) post_command(OperatorCommand::kReset);
    if (a.statue_stands) post_command(OperatorCommand::kStatueStands);
    std::memmove(c.received.data(), c.received.data() + frame.bytes, c.used - frame.bytes);
    c.used -= frame.bytes;
    if (c.used > 0) c.frame_started_ns = now_ns;
  }
  const modbus::FrameSpan next = modbus::frame_at({c.received.data(), c.used});
  more = next.bytes > 0 || next.fault != modbus::FrameFault::kNoFault;
  return Closed::kNo;
}

// Clients silent for idle_timeout_s, or whose frame stays unfinished for kFrameTimeoutS.
void ModbusServer::close_expired(std::int64_t now_ns) {
  for (std::size_t i = clients_.size(); i-- > 0;) {
    const Client& c = clients_[i];
    if (c.used > 0 && now_ns - c.frame_started_ns > ns_of(kFrameTimeoutS)) {
      ++closed_slow_;
      close_client(i);
    } else if (now_ns - std::max(c.connected_ns, c.last_request_ns) >
               ns_of(settings_.idle_timeout_s)) {
      ++closed_idle_;
      close_client(i);
    }
  }
}

void ModbusServer::close_client(std::size_t index) {
  close(clients_[index].socket);
  clients_.erase(clients_.begin() + static_cast<std::ptrdiff_t>(index));
}

// A coil written 1 becomes the loop's command, quoting what the box shows.
void ModbusServer::post_command(OperatorCommand command) {
  CommandRequest request;
  request.command = command;
  request.level = snapshot_.latched;
  request.event_sequence = snapshot_.event_sequence;
  if (mailbox_.post_command(request)) {
    ++commands_posted_;
  } else {
    ++commands_lost_;
  }
}

std::string ModbusServer::summary_json() const {
  return JsonObject()
      .text("listen", settings_.listen)
      .flag("writes", settings_.writes)
      .count("connections", connections_)
      .count("most_clients_at_once", static_cast<std::uint64_t>(max_clients_seen_))
      .count("closed_idle", closed_idle_)
      .count("closed_slow", closed_slow_)
      .count("closed_for_room", closed_for_room_)
      .count("closed_unread", closed_unread_)
      .count("requests", requests_)
      .count("exceptions", exceptions_)
      .count("malformed", malformed_)
      .count("writes_refused", writes_refused_)
      .count("commands", commands_posted_)
      .count("commands_lost", commands_lost_)
      .close();
}

}  // namespace plinth::firmware
