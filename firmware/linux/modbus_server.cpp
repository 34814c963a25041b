#include "modbus_server.h"

#include <modbus/modbus.h>
#include <netdb.h>
#include <sys/select.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <vector>

#include "modbus_map.h"
#include "plinth/host/input_error.h"
#include "socket_activation.h"
#include "status_json.h"

namespace plinth::firmware {

namespace {

constexpr int kSelectTimeoutUs = 20'000;  // how soon the thread sees stop() and new snapshots

bool is_coil_write(int function) {
  return function == MODBUS_FC_WRITE_SINGLE_COIL || function == MODBUS_FC_WRITE_MULTIPLE_COILS;
}

// The registers are read-only (the holding registers mirror the input registers).
bool is_register_write(int function) {
  switch (function) {
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS:
    case MODBUS_FC_MASK_WRITE_REGISTER:
    case MODBUS_FC_WRITE_AND_READ_REGISTERS:
      return true;
    default:
      return false;
  }
}

// Resolves `endpoint` as the server will bind it, for a clear message before libmodbus's.
void check_resolves(const Endpoint& endpoint, const std::string& where) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* list = nullptr;
  const int rc =
      getaddrinfo(endpoint.host.c_str(), std::to_string(endpoint.port).c_str(), &hints, &list);
  if (rc != 0) {
    throw host::InputError(where + ": cannot listen at " + endpoint.text() + ": " +
                           gai_strerror(rc));
  }
  freeaddrinfo(list);
}

}  // namespace

ModbusServer::ModbusServer(const ModbusSettings& settings, const RunIdentity& identity)
    : settings_(settings) {
  modbus::fill_identity(identity, image_);
  const Endpoint endpoint = parse_endpoint(settings.listen, settings.listen_where);
  check_resolves(endpoint, settings.listen_where);
  const std::string port = std::to_string(endpoint.port);
  context_ = modbus_new_tcp_pi(endpoint.host.c_str(), port.c_str());
  if (context_ == nullptr) {
    throw host::InputError(settings.listen_where + ": cannot listen at " + endpoint.text() + ": " +
                           modbus_strerror(errno));
  }
  // Under systemd, the socket unit's listening socket (port 502 without privileges); else ours.
  listen_socket_ = inherited_listening_socket("modbus", endpoint.port, settings.listen_where);
  if (listen_socket_ < 0) listen_socket_ = modbus_tcp_pi_listen(context_, settings.max_clients);
  if (listen_socket_ < 0) {
    const int error = errno;
    modbus_free(context_);
    context_ = nullptr;
    throw host::InputError(settings.listen_where + ": cannot listen at " + endpoint.text() + ": " +
                           std::strerror(error) +
                           (error == EADDRINUSE ? " (another program has the port)" : ""));
  }
  // A client that stops in the middle of a request holds the thread for at most this long.
  modbus_set_indication_timeout(context_, 1, 0);
  map_ = modbus_mapping_new_start_address(0, modbus::coil::kCount, 0, modbus::discrete::kCount, 0,
                                          modbus::reg::kCount, 0, modbus::reg::kCount);
  if (map_ == nullptr) {
    close(listen_socket_);
    modbus_free(context_);
    throw host::InputError(settings.listen_where + ": no memory for the register map");
  }
  publish_image();
  thread_ = std::thread([this] { serve(); });
}

ModbusServer::~ModbusServer() {
  stop();
  if (map_ != nullptr) modbus_mapping_free(map_);
  if (listen_socket_ >= 0) close(listen_socket_);
  if (context_ != nullptr) modbus_free(context_);
}

void ModbusServer::stop() {
  stopping_.store(true);
  if (thread_.joinable()) thread_.join();
}

// The newest snapshot into the registers; alarm events counted.
void ModbusServer::refresh() {
  AlarmNotice notice;
  while (mailbox_.take_alarm(notice)) ++alarm_events_;
  (void)mailbox_.take_status(snapshot_);
  publish_image();
}

// The snapshot into the input registers, the holding registers (the same) and the discrete
// inputs.
void ModbusServer::publish_image() {
  modbus::fill(snapshot_, alarm_events_, image_);
  std::copy(image_.registers.begin(), image_.registers.end(), map_->tab_input_registers);
  std::copy(image_.registers.begin(), image_.registers.end(), map_->tab_registers);
  std::copy(image_.discrete_inputs.begin(), image_.discrete_inputs.end(), map_->tab_input_bits);
}

void ModbusServer::serve() {
  std::vector<int> clients;
  while (!stopping_.load(std::memory_order_relaxed)) {
    refresh();
    fd_set readable;
    FD_ZERO(&readable);
    FD_SET(listen_socket_, &readable);
    int highest = listen_socket_;
    for (const int c : clients) {
      FD_SET(c, &readable);
      highest = std::max(highest, c);
    }
    timeval timeout{0, kSelectTimeoutUs};
    if (select(highest + 1, &readable, nullptr, nullptr, &timeout) <= 0) continue;
    if (FD_ISSET(listen_socket_, &readable)) {
      int listener = listen_socket_;
      const int client = modbus_tcp_pi_accept(context_, &listener);
      if (client >= 0 && static_cast<int>(clients.size()) >= settings_.max_clients) {
        close(client);
        ++connections_refused_;
      } else if (client >= 0) {
        clients.push_back(client);
        ++connections_;
        max_clients_seen_ = std::max(max_clients_seen_, static_cast<int>(clients.size()));
      }
    }
    for (auto it = clients.begin(); it != clients.end();) {
      if (FD_ISSET(*it, &readable) && !answer(*it)) {
        close(*it);
        it = clients.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const int c : clients) close(c);
}

// One request of the client on `socket`; false when the connection ended.
bool ModbusServer::answer(int socket) {
  std::array<std::uint8_t, MODBUS_TCP_MAX_ADU_LENGTH> query{};
  modbus_set_socket(context_, socket);
  const int length = modbus_receive(context_, query.data());
  if (length < 0) return false;
  if (length == 0) return true;  // not for this unit
  ++requests_;
  const int function = query[static_cast<std::size_t>(modbus_get_header_length(context_))];
  if (is_register_write(function) || (is_coil_write(function) && !settings_.writes)) {
    ++writes_refused_;
    return modbus_reply_exception(context_, query.data(), MODBUS_EXCEPTION_ILLEGAL_FUNCTION) >= 0;
  }
  refresh();
  if (modbus_reply(context_, query.data(), length, map_) < 0) return false;
  if (is_coil_write(function)) act_on_coils();
  return true;
}

// A coil written 1 becomes the loop's command; the coils read 0 again.
void ModbusServer::act_on_coils() {
  std::uint8_t* coils = map_->tab_bits;
  for (const int coil : {modbus::coil::kAcknowledge, modbus::coil::kReset}) {
    if (coils[coil] == 0) continue;
    coils[coil] = 0;
    CommandRequest request;
    request.command =
        coil == modbus::coil::kReset ? OperatorCommand::kReset : OperatorCommand::kAcknowledge;
    request.level = snapshot_.latched;
    request.event_sequence = snapshot_.event_sequence;
    if (mailbox_.post_command(request)) {
      ++commands_posted_;
    } else {
      ++commands_lost_;
    }
  }
}

std::string ModbusServer::summary_json() const {
  return JsonObject()
      .text("listen", settings_.listen)
      .flag("writes", settings_.writes)
      .count("connections", connections_)
      .count("connections_refused", connections_refused_)
      .count("most_clients_at_once", static_cast<std::uint64_t>(max_clients_seen_))
      .count("requests", requests_)
      .count("writes_refused", writes_refused_)
      .count("commands", commands_posted_)
      .count("commands_lost", commands_lost_)
      .close();
}

}  // namespace plinth::firmware
