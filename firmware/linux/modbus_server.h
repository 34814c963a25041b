// plinth-monitor's Modbus TCP server (libmodbus): the box's status as registers (input and
// holding, the same), its level as discrete inputs, the operator's acknowledge and reset as
// coils (refused unless [modbus] writes = true). Its own thread serves several clients at once;
// the loop only posts snapshots (status_outputs.h). The map: modbus_map.h, modbus-map.csv,
// docs/integration.md. Host code: allocates and throws.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "modbus_map.h"
#include "run_identity.h"
#include "status_outputs.h"

struct _modbus;
struct _modbus_mapping_t;

namespace plinth::firmware {

// The box's [modbus] table (docs/integration.md). Off while `listen` is empty.
struct ModbusSettings {
  std::string listen;        // modbus.listen, "HOST:PORT" (checked when read)
  std::string listen_where;  // how messages name it: "box.toml:12: modbus.listen" or "--modbus"
  bool writes = false;       // modbus.writes: the acknowledge and reset coils may be written
  int max_clients = 8;       // modbus.max_clients: connections at once, 1..64
};

class ModbusServer final : public StatusOutput {
 public:
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
  void serve();
  void refresh();
  void publish_image();
  [[nodiscard]] bool answer(int socket);
  void act_on_coils();

  ModbusSettings settings_;
  _modbus* context_ = nullptr;
  _modbus_mapping_t* map_ = nullptr;
  int listen_socket_ = -1;
  OutputMailbox mailbox_;
  modbus::Image image_;      // the identity's registers written once, the rest at each refresh
  StatusSnapshot snapshot_;  // the serving thread's newest
  std::uint64_t alarm_events_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
  // Counters, read after the thread ended.
  std::uint64_t connections_ = 0;
  std::uint64_t connections_refused_ = 0;  // beyond max_clients
  std::uint64_t requests_ = 0;
  std::uint64_t writes_refused_ = 0;  // register writes; coil writes while modbus.writes is false
  std::uint64_t commands_posted_ = 0;
  std::uint64_t commands_lost_ = 0;  // the command ring was full
  int max_clients_seen_ = 0;
};

}  // namespace plinth::firmware
