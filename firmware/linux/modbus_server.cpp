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

#include "plinth/firmware/can_frames.h"
#include "plinth/host/input_error.h"
#include "socket_activation.h"
#include "status_json.h"

namespace plinth::firmware {

namespace {

namespace reg = modbus_register;

constexpr std::uint16_t kNone = 0xFFFF;
constexpr int kSelectTimeoutUs = 20'000;  // how soon the thread sees stop() and new snapshots

bool is_write(int function) {
  switch (function) {
    case MODBUS_FC_WRITE_SINGLE_COIL:
    case MODBUS_FC_WRITE_MULTIPLE_COILS:
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS:
    case MODBUS_FC_MASK_WRITE_REGISTER:
    case MODBUS_FC_WRITE_AND_READ_REGISTERS:
      return true;
    default:
      return false;
  }
}

void put16(std::uint16_t* registers, int address, std::uint64_t value) {
  registers[address] = static_cast<std::uint16_t>(value & 0xFFFFU);
}

// A 32-bit value, high word first; saturates at 2^32 - 1.
void put32(std::uint16_t* registers, int address, std::uint64_t value) {
  const std::uint64_t v = std::min<std::uint64_t>(value, 0xFFFFFFFFULL);
  registers[address] = static_cast<std::uint16_t>(v >> 16);
  registers[address + 1] = static_cast<std::uint16_t>(v & 0xFFFFU);
}

void write_registers(const StatusSnapshot& s, std::uint64_t alarm_events, std::uint16_t* r) {
  put16(r, reg::kAlarmLevel, static_cast<std::uint8_t>(to_wire(s.level)));
  put16(r, reg::kHeartbeat, s.statuses);
  put16(r, reg::kRisk, static_cast<std::uint64_t>(std::lround(std::clamp(s.risk, 0.0, 1.0) * 1e4)));
  put16(r, reg::kLatchedLevel, static_cast<std::uint8_t>(to_wire(s.latched)));
  put16(r, reg::kCause, static_cast<std::uint8_t>(to_wire(s.cause)));
  put16(r, reg::kEventSequence, s.any_event ? s.event_sequence : kNone);
  put16(r, reg::kAxisCount, static_cast<std::uint64_t>(s.axis_count));
  put16(r, reg::kPhaseX, static_cast<std::uint8_t>(to_wire(s.phase[0])));
  put16(r, reg::kPhaseY, s.axis_count > 1 ? static_cast<std::uint8_t>(to_wire(s.phase[1])) : kNone);
  put16(r, reg::kEstimating, s.estimating ? 1 : 0);
  put16(r, reg::kSensorHealth, static_cast<std::uint8_t>(s.sensor));
  put16(r, reg::kSensorsState, static_cast<std::uint8_t>(s.sensors_state));
  put32(r, reg::kUptime,
        static_cast<std::uint64_t>(std::max<std::int64_t>(s.uptime_ns, 0)) / 1'000'000'000ULL);
  const monitor::SensorCounters& c = s.sensor_counters;
  put32(r, reg::kSamplesFed, c.fed);
  put32(r, reg::kSamplesBridged, c.bridged);
  put32(r, reg::kSamplesMissing, c.missing);
  put32(r, reg::kSensorTimeouts, c.timeouts);
  put32(r, reg::kSensorFaults, c.faults);
  put32(r, reg::kSamplesRejected, c.non_finite + c.out_of_range + c.undefined_status);
  put32(r, reg::kEstimatorRestarts, s.estimator_restarts);
  put16(r, reg::kLastAcknowledgement, static_cast<std::uint8_t>(s.last_ack));
  put16(r, reg::kCommands, s.commands);
  put16(r, reg::kAlarmEvents, alarm_events);
  put16(r, reg::kMapVersion, 1);
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

ModbusServer::ModbusServer(const ModbusSettings& settings) : settings_(settings) {
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
  map_ = modbus_mapping_new_start_address(0, modbus_coil::kCount, 0, 0, 0, 0, 0, reg::kCount);
  if (map_ == nullptr) {
    close(listen_socket_);
    modbus_free(context_);
    throw host::InputError(settings.listen_where + ": no memory for the register map");
  }
  write_registers(snapshot_, 0, map_->tab_input_registers);
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
  write_registers(snapshot_, alarm_events_, map_->tab_input_registers);
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
  if (is_write(function) && !settings_.writes) {
    ++writes_refused_;
    return modbus_reply_exception(context_, query.data(), MODBUS_EXCEPTION_ILLEGAL_FUNCTION) >= 0;
  }
  refresh();
  if (modbus_reply(context_, query.data(), length, map_) < 0) return false;
  if (is_write(function)) act_on_coils();
  return true;
}

// A coil written 1 becomes the loop's command; the coils read 0 again.
void ModbusServer::act_on_coils() {
  std::uint8_t* coils = map_->tab_bits;
  for (const int coil : {modbus_coil::kAcknowledge, modbus_coil::kReset}) {
    if (coils[coil] == 0) continue;
    coils[coil] = 0;
    CommandRequest request;
    request.command =
        coil == modbus_coil::kReset ? OperatorCommand::kReset : OperatorCommand::kAcknowledge;
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
