// plinth-monitor's Modbus TCP server: the box's status as registers (input and holding, the
// same), its level as discrete inputs, the operator's acknowledge and reset as coils (refused
// unless [modbus] writes = true, and then only from modbus.write_from's addresses). One thread
// serves up to max_clients connections with poll(), never blocking and never sleeping on a
// client: each client's bytes are framed (modbus_protocol.h) as they come; a frame that is not
// Modbus closes its connection, a frame begun and not finished within kFrameTimeoutS and a
// client silent for idle_timeout_s are closed too, and a new connection while every slot is
// taken closes one of the host holding the most (the one never answered first, else the one
// idle longest) rather than being refused. The loop only posts snapshots (status_outputs.h).
// The map: modbus_map.h, modbus-map.csv, docs/integration.md. Host code: allocates and throws.
#pragma once

#include <sys/socket.h>

#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include "address_prefix.h"
#include "log_text.h"
#include "modbus_map.h"
#include "modbus_protocol.h"
#include "run_identity.h"
#include "status_outputs.h"

namespace plinth::firmware {

// The box's [modbus] table (docs/integration.md). Off while `listen` is empty.
struct ModbusSettings {
  std::string listen;        // modbus.listen, "HOST:PORT" (checked when read)
  std::string listen_where;  // how messages name it: "box.toml:12: modbus.listen" or "--modbus"
  bool writes = false;       // modbus.writes: the acknowledge and reset coils may be written ...
  // ... by these addresses only (modbus.write_from, "10.0.4.7", "10.0.4.0/24", "::1"; checked
  // when read): Modbus has no authentication, the peer's address is all a server knows.
  std::vector<std::string> write_from;
  int max_clients = 8;          // modbus.max_clients: connections at once, 1..64
  double idle_timeout_s = 60.0;  // modbus.idle_timeout_s: a client silent this long is closed
};

class ModbusServer final : public StatusOutput {
 public:
  // A request begun must be whole within this (a client that trickles bytes holds no slot).
  static constexpr double kFrameTimeoutS = 1.0;

  // Listens at settings.listen now and serves on its own thread, `identity`'s version and
  // digests in their registers for the whole run. Throws host::InputError naming
  // settings.listen_where: an address that does not resolve, a port in use, ...
  ModbusServer(const ModbusSettings& settings, const RunIdentity& identity);
  ~ModbusServer() override;
  ModbusServer(const ModbusServer&) = delete;
  ModbusServer& operator=(const ModbusServer&) = delete;

  [[nodiscard]] OutputMailbox& mailbox() override { return mailbox_; }
  void stop() override;
  [[nodiscard]] std::string summary_json() const override;
  [[nodiscard]] const char* name() const override { return "modbus"; }

 private:
  struct Client {
    int socket = -1;
    sockaddr_storage peer{};
    bool may_write = false;  // the peer is in write_from (and writes are on)
    std::array<std::uint8_t, modbus::kMaxFrameBytes> received{};
    std::size_t used = 0;                // bytes of `received` not yet answered
    std::int64_t connected_ns = 0;
    std::int64_t last_request_ns = 0;    // of the latest complete request; 0: none yet
    std::int64_t frame_started_ns = 0;   // when the bytes of an unfinished frame began
    bool answered = false;               // a request of it was answered with data
  };
  enum class Closed : std::uint8_t { kNo, kByPeer, kMalformed, kSlowReader };

  void listen_at(const std::string& host, int port);
  void serve();
  void refresh();
  void publish_image();
  void accept_clients(std::int64_t now_ns);
  void make_room();
  [[nodiscard]] Closed read_from(Client& client, std::int64_t now_ns);
  [[nodiscard]] Closed answer_frames(Client& client, std::int64_t now_ns, bool& more);
  void close_expired(std::int64_t now_ns);
  void close_client(std::size_t index);
  void post_command(OperatorCommand command);

  ModbusSettings settings_;
  std::vector<AddressPrefix> writers_;
  int listen_socket_ = -1;
  OutputMailbox mailbox_;
  modbus::Image image_;      // the identity's registers written once, the rest at each refresh
  StatusSnapshot snapshot_;  // the serving thread's newest
  std::uint64_t alarm_events_ = 0;
  std::atomic<bool> stopping_{false};
  std::vector<Client> clients_;
  LogLimiter refused_log_{"modbus", 5, 10.0};  // malformed frames, refused writes
  std::thread thread_;
  // Counters, read after the thread ended.
  std::uint64_t connections_ = 0;
  std::uint64_t requests_ = 0;        // complete frames taken (answered or not)
  std::uint64_t exceptions_ = 0;      // requests answered with an exception
  std::uint64_t malformed_ = 0;       // frames that are not Modbus: the connection closed
  std::uint64_t writes_refused_ = 0;  // register writes; coil writes not allowed
  std::uint64_t commands_posted_ = 0;
  std::uint64_t commands_lost_ = 0;  // the command ring was full
  std::uint64_t closed_idle_ = 0;    // silent idle_timeout_s
  std::uint64_t closed_slow_ = 0;    // a frame unfinished after kFrameTimeoutS
  std::uint64_t closed_for_room_ = 0;  // the idlest, to take a new connection
  std::uint64_t closed_unread_ = 0;  // an answer the client's socket would not take whole
  int max_clients_seen_ = 0;
};

}  // namespace plinth::firmware
