// plinth-monitor's MQTT client (libmosquitto), on its own thread (status_outputs.h):
//   PREFIX/BOX/state          retained JSON: level, latched, cause, risk, the forecast, phase per
//                             axis, sensor counters, version and the files' digests, times
//   PREFIX/BOX/events         every alarm line, QoS 1, in order
//   PREFIX/BOX/availability   retained "online"; the Last Will, and a clean stop, say "offline"
//   PREFIX/BOX/command        the operator's acknowledgement (subscribed; mqtt.commands)
//   PREFIX/BOX/command/reply  accepted or refused, and why
//   PREFIX/regional_alert     the site's regional early-warning alerts from the integrator's
//                             bridge (subscribed; mqtt.regional_alerts, mqtt.regional_topic)
//   DISCOVERY/.../config      retained Home Assistant discovery (mqtt.discovery)
// Alarm events wait in a bounded queue while the broker is away (the oldest dropped and
// counted when it is full) and go out one at a time, each once the broker acknowledged the one
// before, so a broker restart loses none and keeps their order. Reconnects with exponential
// back-off. Username/password and TLS (a CA, optionally a client certificate). MQTT 5: a
// retained command is never taken (the subscription asks for none, and one published retained
// is refused), the client id carries 64 random bits (no other client can take the session
// without reading it off the box or the broker's log), and a takeover is said and counted: the
// DISCONNECT's reason 0x8E where the broker sends one, else the box's own Last Will found
// retained when it connects again (mosquitto 2.0.11 sends no reason, but publishes the Will).
// Who may publish a command is the broker's ACL: MQTT does not tell a subscriber who published; a
// regional alert can carry its own HMAC (docs/regional.md). What comes in is read strictly
// (json_payload.h) and said escaped (log_text.h), a burst of alerts keeps the most dangerous.
// Topics and payloads: docs/integration.md. Host code: allocates and throws.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "log_text.h"
#include "plinth/monitor/regional_alert.h"
#include "run_identity.h"
#include "status_outputs.h"

struct mosquitto;

namespace plinth::firmware {

// The longest box id and topic prefix (mqtt.topic_prefix, discovery_prefix, regional_topic) a
// box file may give: every topic stays far below MQTT's 65535 bytes.
inline constexpr std::size_t kMaxBoxIdBytes = 64;
inline constexpr std::size_t kMaxTopicPrefixBytes = 256;

// The box's [mqtt] table (docs/integration.md). Off while `broker` is empty.
struct MqttSettings {
  std::string broker;                   // mqtt.broker, "HOST:PORT" (checked when read)
  std::string broker_where;             // "box.toml:20: mqtt.broker" or "--mqtt"
  std::string box_id;                   // mqtt.box_id: in the topics; default: the host name
  std::string topic_prefix = "plinth";  // mqtt.topic_prefix: topics are PREFIX/BOX/...
  std::string username;                 // mqtt.username
  std::string password;                 // mqtt.password (better: password_file)
  std::string password_file;            // mqtt.password_file: its first line is the password
  std::string ca_file;    // mqtt.tls_ca_file: TLS on, the broker's certificate checked with it
  std::string cert_file;  // mqtt.tls_cert_file, mqtt.tls_key_file: a client certificate
  std::string key_file;
  std::string files_where;        // "box.toml" or "--mqtt-*", for messages about the files
  int keepalive_s = 10;           // mqtt.keepalive_s, 5..3600
  int event_queue = 1000;         // mqtt.event_queue: alarm events held while away, 1..100000
  double state_interval_s = 1.0;  // mqtt.state_interval_s: state at most this often (and at
                                  // every level change), 0.001..3600
  double reconnect_min_s = 0.5;   // mqtt.reconnect_min_s: first back-off, doubled to ...
  double reconnect_max_s = 30.0;  // mqtt.reconnect_max_s
  bool commands = false;          // mqtt.commands: acknowledgements on PREFIX/BOX/command
  // mqtt.regional_alerts: take regional alerts (docs/regional.md) from mqtt.regional_topic
  // (default PREFIX/regional_alert: one bridge for the site's boxes, each with its statue's
  // fragility; PREFIX/BOX/regional_alert or any other topic for a box of its own).
  bool regional_alerts = false;
  std::string regional_topic;
  bool discovery = true;          // mqtt.discovery: Home Assistant discovery configs
  std::string discovery_prefix = "homeassistant";  // mqtt.discovery_prefix
  // The regional room's settings (plinth-monitor's configuration, not an [mqtt] key): its
  // fragility ranks the alerts of a burst, its authentication says whether each must carry
  // the bridge's HMAC.
  monitor::RegionalAlertSettings regional;
};

// The user property that carries a regional alert's HMAC-SHA256 over its payload, 64 hex
// digits (docs/regional.md, "Who may send an alert").
inline constexpr const char* kRegionalHmacProperty = "hmac-sha256";

class MqttPublisher final : public StatusOutput {
 public:
  // Checks the settings (the password and TLS files are read now: a missing one is an
  // host::InputError naming its key and flag), then connects on its own thread. The state
  // carries `identity`'s digests for the whole run.
  MqttPublisher(const MqttSettings& settings, const RunIdentity& identity);
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
  // `hmac`: the kRegionalHmacProperty user property, "" when the message has none.
  void on_message(const std::string& topic, const std::string& payload, bool retained,
                  const std::string& hmac);

  // Alerts of a burst held for the loop at most; beyond, the least dangerous goes.
  static constexpr std::size_t kRegionalHeldForLoop = 64;

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
  void say_dropped();
  void say_problem(const std::string& reason);
  void back_off(std::int64_t now_ns);
  void say_offline();
  void publish_discovery();
  void reply(const std::string& id_json, const std::string& command, const std::string& result,
             const std::string& why, const std::string& details);
  void take_results();
  void on_regional_alert(const std::string& payload, const std::string& hmac);
  void pass_regional_alerts(std::int64_t now_ns);
  void check_topics() const;
  [[nodiscard]] bool publish(const std::string& topic, const std::string& payload, bool retain,
                             int* mid);
  [[nodiscard]] std::string state_json() const;

  MqttSettings settings_;
  struct DigestMember {
    std::string member;  // "scene_sha256", ...
    std::string file;    // "Scene", ...
    std::string hex;     // "" when the file was not given
  };
  std::vector<DigestMember> digests_;  // the run's identity, written once
  std::string endpoint_text_;  // "HOST:PORT (where)"
  std::string host_;
  int port_ = 0;
  std::string state_topic_, events_topic_, availability_topic_, command_topic_, reply_topic_;
  std::string regional_topic_;
  std::string client_id_;  // "plinth-BOX-" and 16 random hex digits
  mosquitto* client_ = nullptr;
  OutputMailbox mailbox_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;

  // The thread's state.
  bool socket_open_ = false;  // a connection attempt or session is under way
  bool connected_ = false;    // the broker accepted the session
  bool answered_ = false;     // the broker answered this attempt (CONNACK, accepted or not)
  bool ended_uncleanly_ = false;  // the last session ended without the box's DISCONNECT
  bool checking_will_ = false;    // the availability topic's retained value is still to come
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
  // Commands handed to the loop, by CommandRequest::id: the reply's id (JSON) and what the
  // operator quoted.
  struct PendingCommand {
    std::string id_json;
    OperatorCommand command = OperatorCommand::kAcknowledge;
    std::string details;  // "level" and "sequence" members of the reply
  };
  std::map<std::uint32_t, PendingCommand> pending_;
  std::uint32_t next_command_id_ = 1;
  // Regional alerts waiting for room in the loop's ring, in arrival order, each with when it
  // came (its times are made relative to the handover) and how dangerous it is.
  struct WaitingAlert {
    RegionalRequest request;
    std::int64_t received_ns = 0;
    double danger = -1.0;  // its probability of collapse (its PGA without a fragility); -1: not
                           // an alert
  };
  std::vector<WaitingAlert> regional_waiting_;
  LogLimiter incoming_log_{"mqtt", 5, 10.0};  // refused commands and alerts, lost alerts
  LogLimiter session_log_{"mqtt", 3, 60.0};   // takeovers

  // Counters, read after the thread ended.
  std::uint64_t connects_ = 0;
  std::uint64_t connect_failures_ = 0;  // attempts that did not reach the broker
  std::uint64_t refusals_ = 0;          // the broker refused the session (CONNACK)
  std::uint64_t connections_lost_ = 0;
  std::uint64_t takeovers_ = 0;  // the broker closed the session: another client took the id
  // At a reconnection, the box's Last Will retained on its availability topic: published while
  // the box ran (a takeover by a broker that does not say so, as mosquitto 2.0.11, or a drop).
  std::uint64_t wills_seen_ = 0;
  std::uint64_t events_published_ = 0;  // acknowledged by the broker
  std::uint64_t events_dropped_ = 0;    // the queue was full: the oldest went
  std::uint64_t next_drop_report_ = 1;     // say_dropped() speaks at this count
  std::uint64_t mailbox_dropped_seen_ = 0;
  std::uint64_t events_republished_ = 0;
  std::uint64_t states_published_ = 0;
  std::size_t most_queued_ = 0;
  std::uint64_t commands_received_ = 0;
  std::uint64_t commands_accepted_ = 0;  // acknowledgements the monitor released a latch with
  std::uint64_t commands_refused_ = 0;
  std::uint64_t commands_retained_ = 0;  // of which published retained
  std::uint64_t discovery_configs_ = 0;  // config messages published
  std::uint64_t regional_received_ = 0;   // messages on the regional topic
  std::uint64_t regional_malformed_ = 0;  // of which not an alert (handed on as malformed)
  std::uint64_t regional_unauthenticated_ = 0;  // no HMAC or a wrong one (handed on as such)
  std::uint64_t regional_lost_ = 0;  // not handed on: kRegionalHeldForLoop more dangerous waited
};

}  // namespace plinth::firmware
