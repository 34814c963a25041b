// plinth-monitor's Modbus TCP server (libmodbus): the box's status as input registers, the
// operator's acknowledge and reset as coils (refused unless [modbus] writes = true). Its own
// thread serves several clients at once; the loop only posts snapshots (status_outputs.h).
// The register map: docs/integration.md. Host code: allocates and throws.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "monitor_config.h"
#include "status_outputs.h"

struct _modbus;
struct _modbus_mapping_t;

namespace plinth::firmware {

// Input registers (function 04), 0-based addresses. 32-bit values: two registers, the high
// word first.
namespace modbus_register {
inline constexpr int kAlarmLevel = 0;     // the DBC's AlarmLevel: 0 normal .. 3 alarm, 4 fault
inline constexpr int kHeartbeat = 1;      // status reports, modulo 65536
inline constexpr int kRisk = 2;           // risk x 10000 (0 .. 10000)
inline constexpr int kLatchedLevel = 3;   // AlarmLevel latched, 0: none
inline constexpr int kCause = 4;          // the DBC's AlarmCause of the latest alarm event
inline constexpr int kEventSequence = 5;  // the latest alarm event's sequence; 65535: none yet
inline constexpr int kAxisCount = 6;      // 1 or 2
inline constexpr int kPhaseX = 7;         // the DBC's Phase of axis x
inline constexpr int kPhaseY = 8;         // of axis y; 65535 when the box models one axis
inline constexpr int kEstimating = 9;     // 1: the estimators run
inline constexpr int kSensorHealth = 10;  // the primary sensor: 0 ok, 1 degraded, 2 fault
inline constexpr int kSensorsState = 11;  // all sensors: 0 ok, 1 degraded, 2 fault
inline constexpr int kUptime = 12;        // s since plinth-monitor started (32 bits)
inline constexpr int kSamplesFed = 14;    // the primary's counters (32 bits each) ...
inline constexpr int kSamplesBridged = 16;
inline constexpr int kSamplesMissing = 18;
inline constexpr int kSensorTimeouts = 20;
inline constexpr int kSensorFaults = 22;
inline constexpr int kSamplesRejected = 24;
inline constexpr int kEstimatorRestarts = 26;    // (32 bits)
inline constexpr int kLastAcknowledgement = 28;  // AckOutcome of the latest acknowledge
inline constexpr int kCommands = 29;             // operator commands carried out, modulo 65536
inline constexpr int kAlarmEvents = 30;          // alarm events so far, modulo 65536
inline constexpr int kMapVersion = 31;           // 1: this map
inline constexpr int kCount = 32;
}  // namespace modbus_register

// Coils (functions 01, 05, 15): write 1 to act; they read 0.
namespace modbus_coil {
inline constexpr int kAcknowledge = 0;  // acknowledge the latched level (registers 3 and 5)
inline constexpr int kReset = 1;        // start the monitor again as at power-up
inline constexpr int kCount = 2;
}  // namespace modbus_coil

class ModbusServer final : public StatusOutput {
 public:
  // Listens at settings.listen now and serves on its own thread. Throws host::InputError
  // naming settings.listen_where: an address that does not resolve, a port in use, ...
  explicit ModbusServer(const ModbusSettings& settings);
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
  [[nodiscard]] bool answer(int socket);
  void act_on_coils();

  ModbusSettings settings_;
  _modbus* context_ = nullptr;
  _modbus_mapping_t* map_ = nullptr;
  int listen_socket_ = -1;
  OutputMailbox mailbox_;
  StatusSnapshot snapshot_;  // the serving thread's newest
  std::uint64_t alarm_events_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
  // Counters, read after the thread ended.
  std::uint64_t connections_ = 0;
  std::uint64_t connections_refused_ = 0;  // beyond max_clients
  std::uint64_t requests_ = 0;
  std::uint64_t writes_refused_ = 0;  // writes while modbus.writes is false
  std::uint64_t commands_posted_ = 0;
  std::uint64_t commands_lost_ = 0;  // the command ring was full
  int max_clients_seen_ = 0;
};

}  // namespace plinth::firmware
