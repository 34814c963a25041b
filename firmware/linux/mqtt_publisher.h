// plinth-monitor's MQTT publisher (libmosquitto), on its own thread (status_outputs.h):
//   PREFIX/BOX/state         retained JSON: level, latched, cause, risk, phase per axis, times
//   PREFIX/BOX/events        every alarm line, QoS 1, in order
//   PREFIX/BOX/availability  retained "online"; the Last Will, and a clean stop, say "offline"
// Alarm events wait in a bounded queue while the broker is away (the oldest dropped and
// counted when it is full) and go out one at a time, each once the broker acknowledged the one
// before, so a broker restart loses none and keeps their order. Reconnects with exponential
// back-off. Username/password and TLS (a CA, optionally a client certificate). Topics and
// payloads: docs/integration.md. Host code: allocates and throws.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <string>
#include <thread>
#include <vector>

#include "monitor_config.h"
#include "status_outputs.h"

struct mosquitto;

namespace plinth::firmware {

class MqttPublisher final : public StatusOutput {
 public:
  // Checks the settings (the password and TLS files are read now: a missing one is an
  // host::InputError naming its key and flag), then connects on its own thread.
  explicit MqttPublisher(const MqttSettings& settings);
  ~MqttPublisher() override;
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  [[nodiscard]] OutputMailbox& mailbox() override { return mailbox_; }
  // Delivers the queued events (at most kFlushTimeoutS while the broker is away), says
  // "offline" and disconnects.
  void stop() override;
  [[nodiscard]] std::string summary_json() const override;
  [[nodiscard]] const char* name() const override { return "mqtt"; }

  static constexpr double kFlushTimeoutS = 10.0;

  // Called by libmosquitto on this publisher's thread.
  void on_connect(int rc);
  void on_disconnect(int rc);
  void on_publish(int mid);
  void on_error_log(const char* text);

 private:
  struct QueuedEvent {
    std::string payload;
    std::vector<int> mids;  // the publishes of this event not acknowledged yet
  };

  void run();
  void take_mailbox(std::int64_t now_ns);
  void try_connect(std::int64_t now_ns);
  void publish_head(std::int64_t now_ns);
  void publish_state(std::int64_t now_ns);
  void lost(const std::string& reason, std::int64_t now_ns);
  void back_off(std::int64_t now_ns);
  void say_offline();
  [[nodiscard]] bool publish(const std::string& topic, const std::string& payload, bool retain,
                             int* mid);
  [[nodiscard]] std::string state_json() const;

  MqttSettings settings_;
  std::string endpoint_text_;  // "HOST:PORT (where)"
  std::string host_;
  int port_ = 0;
  std::string state_topic_, events_topic_, availability_topic_;
  mosquitto* client_ = nullptr;
  OutputMailbox mailbox_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;

  // The thread's state.
  bool socket_open_ = false;  // a connection attempt or session is under way
  bool connected_ = false;    // the broker accepted the session
  std::int64_t next_attempt_ns_ = 0;
  double backoff_s_ = 0.0;
  std::string last_problem_;  // the latest message printed (printed again only when it changes)
  std::string error_log_;     // libmosquitto's latest error log line since the last message
  std::deque<QueuedEvent> queue_;
  std::int64_t head_sent_ns_ = 0;  // when the head event was last published
  StatusSnapshot state_;
  bool have_state_ = false;
  bool state_due_ = false;
  std::int64_t state_sent_ns_ = 0;
  StatusSnapshot state_sent_;
  int offline_mid_ = -1;
  bool offline_acknowledged_ = false;

  // Counters, read after the thread ended.
  std::uint64_t connects_ = 0;
  std::uint64_t connect_failures_ = 0;  // attempts that did not reach the broker
  std::uint64_t refusals_ = 0;          // the broker refused the session (CONNACK)
  std::uint64_t connections_lost_ = 0;
  std::uint64_t events_published_ = 0;  // acknowledged by the broker
  std::uint64_t events_dropped_ = 0;    // the queue was full: the oldest went
  std::uint64_t events_republished_ = 0;
  std::uint64_t states_published_ = 0;
  std::size_t most_queued_ = 0;
};

}  // namespace plinth::firmware
