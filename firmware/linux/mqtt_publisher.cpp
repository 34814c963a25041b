#include "mqtt_publisher.h"

#include <mosquitto.h>
#include <mqtt_protocol.h>
#include <sys/random.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <mutex>
#include <nlohmann/json.hpp>

#include "json_payload.h"
#include "plinth/host/input_error.h"
#include "plinth/host/json_text.h"
#include "plinth/host/text_file.h"
#include "plinth/monitor/hmac_sha256.h"
#include "plinth/version/version.h"
#include "regional_json.h"
#include "status_json.h"

namespace plinth::firmware {

namespace {

constexpr int kQos = 1;
constexpr int kLoopTimeoutMs = 10;        // how soon the thread sees new events, states and stop()
constexpr double kRepublishAfterS = 5.0;  // an event not acknowledged this long goes out again
constexpr std::int64_t kNsPerS = 1'000'000'000;

std::int64_t ns_of(double seconds) { return static_cast<std::int64_t>(seconds * 1e9); }

void say(const std::string& message) {
  std::fprintf(stderr, "plinth-monitor: mqtt: %s\n", message.c_str());
}

// A file the settings name: it must be a readable regular file.
void check_file(const std::string& path, const char* key, const char* flag) {
  if (path.empty()) return;
  (void)host::read_text_file(path, std::size_t{1} << 20, std::string(key) + " / " + flag + " file");
}

std::string first_line(const std::string& text) {
  const std::size_t end = text.find_first_of("\r\n");
  return end == std::string::npos ? text : text.substr(0, end);
}

// ISO 8601 UTC with ms: "2026-11-25T19:50:47.123Z".
std::string utc_text(std::int64_t wall_ns) {
  const std::time_t seconds = static_cast<std::time_t>(wall_ns / kNsPerS);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char text[40];
  const std::size_t n = std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &utc);
  std::snprintf(text + n, sizeof text - n, ".%03dZ",
                static_cast<int>((wall_ns % kNsPerS) / 1'000'000));
  return text;
}

// libmosquitto's text of `rc` (errno's for MOSQ_ERR_ERRNO), without its final period.
std::string error_text(int rc) {
  std::string text = rc == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(rc);
  if (!text.empty() && text.back() == '.') text.pop_back();
  return text;
}

// The CONNACK's reason (MQTT 5 codes; the box speaks MQTT 5).
std::string connack_text(int rc) {
  switch (rc) {
    case MQTT_RC_UNSUPPORTED_PROTOCOL_VERSION:
      return "unsupported protocol version (the box speaks MQTT 5: mosquitto 1.6 or later, "
             "EMQX, HiveMQ, ...)";
    case MQTT_RC_CLIENTID_NOT_VALID:
      return "client identifier rejected";
    case MQTT_RC_SERVER_UNAVAILABLE:
      return "broker unavailable";
    case MQTT_RC_BAD_USERNAME_OR_PASSWORD:
      return "bad user name or password (mqtt.username, mqtt.password or password_file)";
    case MQTT_RC_NOT_AUTHORIZED:
      return "not authorised (mqtt.username, mqtt.password or password_file)";
    default:
      return std::string("code ") + std::to_string(rc) + ": " + mosquitto_reason_string(rc);
  }
}

// 64 random bits as 16 hex digits (getrandom: the kernel's CSPRNG).
std::string random_hex() {
  std::uint64_t bits = 0;
  if (getrandom(&bits, sizeof bits, 0) != static_cast<ssize_t>(sizeof bits)) {
    throw host::InputError(std::string("mqtt: no random bits for the client id: ") +
                           std::strerror(errno));
  }
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(bits));
  return text;
}

// The kRegionalHmacProperty of `properties`, "" without one (the first, if given twice).
std::string hmac_property(const mosquitto_property* properties) {
  std::string value;
  bool first = true;
  for (const mosquitto_property* p = properties; p != nullptr; first = false) {
    char* name = nullptr;
    char* text = nullptr;
    p = mosquitto_property_read_string_pair(p, MQTT_PROP_USER_PROPERTY, &name, &text, !first);
    if (p != nullptr && name != nullptr && value.empty() &&
        std::strcmp(name, kRegionalHmacProperty) == 0 && text != nullptr) {
      value = text;
    }
    std::free(name);
    std::free(text);
  }
  return value;
}

extern "C" void connect_callback(mosquitto*, void* self, int rc) {
  static_cast<MqttPublisher*>(self)->on_connect(rc);
}
extern "C" void disconnect_callback(mosquitto*, void* self, int rc, const mosquitto_property*) {
  static_cast<MqttPublisher*>(self)->on_disconnect(rc);
}
extern "C" void publish_callback(mosquitto*, void* self, int mid) {
  static_cast<MqttPublisher*>(self)->on_publish(mid);
}
extern "C" void message_callback(mosquitto*, void* self, const mosquitto_message* message,
                                 const mosquitto_property* properties) {
  if (message == nullptr || message->topic == nullptr) return;
  const std::size_t length =
      message->payload == nullptr ? 0U : static_cast<std::size_t>(message->payloadlen);
  const std::string payload(static_cast<const char*>(message->payload), length);
  static_cast<MqttPublisher*>(self)->on_message(message->topic, payload, message->retain,
                                                hmac_property(properties));
}
extern "C" void log_callback(mosquitto*, void* self, int level, const char* text) {
  if ((level & MOSQ_LOG_ERR) != 0) static_cast<MqttPublisher*>(self)->on_error_log(text);
}

// Whether `hmac` (64 hex digits, either case) is the HMAC-SHA256 of `payload` with `key`.
bool hmac_matches(const std::array<std::uint8_t, monitor::kRegionalKeyBytes>& key,
                  const std::string& payload, const std::string& hmac) {
  if (hmac.size() != 64) return false;
  monitor::Sha256Digest given{};
  for (std::size_t i = 0; i < given.size(); ++i) {
    unsigned value = 0;
    for (int k = 0; k < 2; ++k) {
      const char c = hmac[2 * i + static_cast<std::size_t>(k)];
      const int digit = c >= '0' && c <= '9'   ? c - '0'
                        : c >= 'a' && c <= 'f' ? c - 'a' + 10
                        : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                               : -1;
      if (digit < 0) return false;
      value = value << 4 | static_cast<unsigned>(digit);
    }
    given[i] = static_cast<std::uint8_t>(value);
  }
  const monitor::ByteSpan part{reinterpret_cast<const std::uint8_t*>(payload.data()),
                               payload.size()};
  const monitor::Sha256Digest expected = monitor::hmac_sha256(key, &part, 1);
  return monitor::same_bytes(given.data(), expected.data(), given.size());
}

// How dangerous an alert is, to keep the most dangerous in a burst: its probability of collapse
// under the statue's fragility (the room's own), its PGA without one.
double danger_of(const monitor::RegionalAlertSettings& room, const monitor::RegionalAlert& a) {
  if (!std::isfinite(a.pga_g) || !std::isfinite(a.sigma_ln) || a.pga_g < 0.0 ||
      a.sigma_ln < 0.0) {
    return 0.0;
  }
  return room.fragility_known
             ? static_cast<double>(room.fragility.probability(a.pga_g, a.sigma_ln))
             : static_cast<double>(a.pga_g);
}

// The state's statue sensor: null without one; its streams' health, its offset known, and per
// axis whether the weights tell the members apart (weighted: the risk is theirs).
std::string statue_sensor_state(const StatusSnapshot& s, const char* const* axes) {
  if (!s.has_statue_sensor) return "null";
  JsonObject weights;
  for (int i = 0; i < s.axis_count && i < kMaxAxes; ++i) {
    weights.raw(axes[i], statue_weights_json(s.statue_axes[static_cast<std::size_t>(i)]));
  }
  return JsonObject()
      .text("rate", monitor::health_state_name(s.statue_rate))
      .text("acceleration", monitor::health_state_name(s.statue_acceleration))
      .flag("ready", s.statue_ready)
      .flag("unexplained", s.statue_unexplained)
      .raw("weights", weights.close())
      .close();
}

}  // namespace

MqttPublisher::MqttPublisher(const MqttSettings& settings, const RunIdentity& identity)
    : settings_(settings) {
  for (const NamedDigest& d : named_digests(identity)) {
    digests_.push_back({d.member, d.file, d.digest->has_value() ? hex(**d.digest) : ""});
  }
  static std::once_flag library;
  std::call_once(library, [] { mosquitto_lib_init(); });
  const Endpoint endpoint = parse_endpoint(settings.broker, settings.broker_where);
  host_ = endpoint.host;
  port_ = endpoint.port;
  endpoint_text_ = endpoint.text() + " (" + settings.broker_where + ")";
  if (settings_.box_id.empty()) {
    char name[256] = {};
    gethostname(name, sizeof name - 1);
    settings_.box_id = name[0] != '\0' ? name : "box";
  }
  const std::string base = settings_.topic_prefix + "/" + settings_.box_id + "/";
  state_topic_ = base + "state";
  events_topic_ = base + "events";
  availability_topic_ = base + "availability";
  command_topic_ = base + "command";
  reply_topic_ = command_topic_ + "/reply";
  regional_topic_ = settings_.regional_topic.empty() ? settings_.topic_prefix + "/regional_alert"
                                                     : settings_.regional_topic;

  std::string password = settings_.password;
  if (!settings_.password_file.empty()) {
    password = first_line(host::read_text_file(settings_.password_file, 4096,
                                               "mqtt.password_file / --mqtt-password-file"));
  }
  check_file(settings_.ca_file, "mqtt.tls_ca_file", "--mqtt-ca");
  check_file(settings_.cert_file, "mqtt.tls_cert_file", "--mqtt-cert");
  check_file(settings_.key_file, "mqtt.tls_key_file", "--mqtt-key");
  if (settings_.cert_file.empty() != settings_.key_file.empty()) {
    throw host::InputError(
        "mqtt.tls_cert_file and mqtt.tls_key_file (--mqtt-cert, --mqtt-key): give both or neither");
  }
  if (!settings_.cert_file.empty() && settings_.ca_file.empty()) {
    throw host::InputError("mqtt.tls_cert_file (--mqtt-cert): needs mqtt.tls_ca_file (--mqtt-ca)");
  }

  check_topics();

  // 64 random bits: a client that would take the box's session (a broker closes the older of
  // two with one id) must first read the id off the box or the broker's log.
  client_id_ = "plinth-" + settings_.box_id + "-" + random_hex();
  client_ = mosquitto_new(client_id_.c_str(), true, this);
  if (client_ == nullptr) {
    throw host::InputError("mqtt: cannot create the client: " + std::string(std::strerror(errno)));
  }
  const auto fail = [&](const std::string& what, int rc) {
    mosquitto_destroy(client_);
    client_ = nullptr;
    throw host::InputError(what + ": " + mosquitto_strerror(rc));
  };
  int rc = mosquitto_int_option(client_, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V5);
  if (rc != MOSQ_ERR_SUCCESS) fail("mqtt: MQTT 5", rc);
  rc = mosquitto_will_set(client_, availability_topic_.c_str(), 7, "offline", kQos, true);
  if (rc != MOSQ_ERR_SUCCESS) fail("mqtt: the Last Will on " + availability_topic_, rc);
  if (!settings_.username.empty()) {
    rc = mosquitto_username_pw_set(client_, settings_.username.c_str(),
                                   password.empty() ? nullptr : password.c_str());
    if (rc != MOSQ_ERR_SUCCESS) fail("mqtt.username", rc);
  } else if (!password.empty()) {
    fail("mqtt.password without mqtt.username (--mqtt-username)", MOSQ_ERR_INVAL);
  }
  if (!settings_.ca_file.empty()) {
    rc = mosquitto_tls_set(client_, settings_.ca_file.c_str(), nullptr,
                           settings_.cert_file.empty() ? nullptr : settings_.cert_file.c_str(),
                           settings_.key_file.empty() ? nullptr : settings_.key_file.c_str(),
                           nullptr);
    if (rc != MOSQ_ERR_SUCCESS) fail("mqtt.tls_ca_file " + settings_.ca_file + " (--mqtt-ca)", rc);
  }
  mosquitto_connect_callback_set(client_, connect_callback);
  mosquitto_disconnect_v5_callback_set(client_, disconnect_callback);
  mosquitto_publish_callback_set(client_, publish_callback);
  mosquitto_message_v5_callback_set(client_, message_callback);
  mosquitto_log_callback_set(client_, log_callback);
  backoff_s_ = settings_.reconnect_min_s;
  thread_ = std::thread([this] { run(); });
}

// The box's topics against each other: each distinct, the regional alerts' topic none of a
// box's own (any box's: PREFIX/+/state, ...) nor under the discovery prefix, each a valid topic.
void MqttPublisher::check_topics() const {
  struct Named {
    const char* key;  // how the message names it
    std::string topic;
  };
  std::vector<Named> own = {{"state", state_topic_},
                            {"events", events_topic_},
                            {"availability", availability_topic_},
                            {"command", command_topic_},
                            {"command reply", reply_topic_}};
  for (const Named& t : own) {
    if (mosquitto_pub_topic_check2(t.topic.data(), t.topic.size()) != MOSQ_ERR_SUCCESS ||
        mosquitto_validate_utf8(t.topic.data(), static_cast<int>(t.topic.size())) !=
            MOSQ_ERR_SUCCESS) {
      throw host::InputError("mqtt.topic_prefix, mqtt.box_id: the " + std::string(t.key) +
                             " topic \"" + printable(t.topic) + "\" is not a valid topic");
    }
  }
  if (!settings_.regional_alerts) return;
  const std::string& regional = regional_topic_;
  if (mosquitto_pub_topic_check2(regional.data(), regional.size()) != MOSQ_ERR_SUCCESS) {
    throw host::InputError("mqtt.regional_topic: \"" + printable(regional) +
                           "\" is not one topic (no wildcard, no empty level)");
  }
  const std::string prefix = settings_.topic_prefix;
  const std::pair<std::string, const char*> patterns[] = {
      {prefix + "/+/state", "a box's state"},
      {prefix + "/+/events", "a box's events"},
      {prefix + "/+/availability", "a box's availability"},
      {prefix + "/+/command", "a box's command topic"},
      {prefix + "/+/command/reply", "a box's command replies"},
      {settings_.discovery_prefix + "/#", "the discovery prefix"},
  };
  for (const auto& [pattern, what] : patterns) {
    bool matches = false;
    if (mosquitto_topic_matches_sub(pattern.c_str(), regional.c_str(), &matches) ==
            MOSQ_ERR_SUCCESS &&
        matches) {
      throw host::InputError("mqtt.regional_topic: \"" + printable(regional) + "\" is " + what +
                             " (" + pattern + "): alerts would be mixed with the box's own "
                             "messages; give the bridge a topic of its own");
    }
  }
}

MqttPublisher::~MqttPublisher() {
  stop();
  if (client_ != nullptr) mosquitto_destroy(client_);
}

void MqttPublisher::stop() {
  stopping_.store(true);
  if (thread_.joinable()) thread_.join();
}

void MqttPublisher::on_connect(int rc) {
  answered_ = true;
  if (rc != 0) {
    ++refusals_;
    const std::string problem =
        "the broker at " + endpoint_text_ + " refused the connection: " + connack_text(rc);
    if (problem != last_problem_) say(problem);
    last_problem_ = problem;
    return;
  }
  connected_ = true;
  ++connects_;
  backoff_s_ = settings_.reconnect_min_s;
  const std::string problem = "connected to " + endpoint_text_;
  if (problem != last_problem_ && !last_problem_.empty()) say(problem);
  last_problem_ = problem;
  // The box's own availability, its retained value first: after a session of this run that
  // ended without the box's DISCONNECT, "offline" there is the box's Last Will, which the broker
  // published while the box still ran (another client took its session, or the broker dropped
  // it). Then "online".
  checking_will_ = ended_uncleanly_;
  ended_uncleanly_ = false;
  if (mosquitto_subscribe_v5(client_, nullptr, availability_topic_.c_str(), kQos, 0, nullptr) !=
      MOSQ_ERR_SUCCESS) {
    checking_will_ = false;
  }
  (void)publish(availability_topic_, "online", true, nullptr);
  // Also while commands are off: the reply says so. No retained command is sent (a retained
  // acknowledgement would be carried out at every connection), and one published retained
  // shows as retained, to be refused; none of the box's own messages come back.
  constexpr int kCommandOptions =
      MQTT_SUB_OPT_SEND_RETAIN_NEVER | MQTT_SUB_OPT_RETAIN_AS_PUBLISHED | MQTT_SUB_OPT_NO_LOCAL;
  if (mosquitto_subscribe_v5(client_, nullptr, command_topic_.c_str(), kQos, kCommandOptions,
                             nullptr) != MOSQ_ERR_SUCCESS) {
    say("cannot subscribe to " + command_topic_);
  }
  // Regional alerts may be retained (the bridge's latest, taken again at a connection: its
  // origin time and the duplicate rule decide).
  if (settings_.regional_alerts &&
      mosquitto_subscribe_v5(client_, nullptr, regional_topic_.c_str(), kQos,
                             MQTT_SUB_OPT_NO_LOCAL, nullptr) != MOSQ_ERR_SUCCESS) {
    say("cannot subscribe to " + regional_topic_);
  }
  publish_discovery();
  state_due_ = have_state_;
  head_sent_ns_ = 0;  // the head event goes out again if the broker never acknowledged it
}

void MqttPublisher::on_disconnect(int rc) {
  if (connected_ && rc != 0 && !stopping_.load()) ++connections_lost_;
  if (connected_ && rc != 0) ended_uncleanly_ = true;
  if (rc == MQTT_RC_SESSION_TAKEN_OVER) {
    ++takeovers_;
    session_log_.say("the broker at " + endpoint_text_ + " closed the box's session: another "
                         "client connected with its client id (" + client_id_ + ", " +
                         std::to_string(takeovers_) + " times so far); the box connects again. "
                         "Give the box credentials of its own and let the broker bind the id "
                         "to them (docs/integration.md, \"What each surface trusts\")",
                     monotonic_ns());
  }
  connected_ = false;
}

void MqttPublisher::on_error_log(const char* text) {
  if (text != nullptr) error_log_ = text;
}

void MqttPublisher::on_publish(int mid) {
  if (mid == offline_mid_) offline_acknowledged_ = true;
  if (queue_.empty()) return;
  const std::vector<int>& mids = queue_.front().mids;
  if (std::find(mids.begin(), mids.end(), mid) == mids.end()) return;
  queue_.pop_front();
  ++events_published_;
  head_sent_ns_ = 0;
}

bool MqttPublisher::publish(const std::string& topic, const std::string& payload, bool retain,
                            int* mid) {
  return mosquitto_publish(client_, mid, topic.c_str(), static_cast<int>(payload.size()),
                           payload.data(), kQos, retain) == MOSQ_ERR_SUCCESS;
}

// The loop's alarm events into the queue (bounded), its newest snapshot into the state.
void MqttPublisher::take_mailbox(std::int64_t now_ns) {
  take_results();
  if (mailbox_.events_dropped() != mailbox_dropped_seen_) {  // the loop's ring was full
    mailbox_dropped_seen_ = mailbox_.events_dropped();
    say_dropped();
  }
  AlarmNotice notice;
  while (mailbox_.take_alarm(notice)) {
    // The oldest waiting event makes room; never the one the broker may be acknowledging.
    if (static_cast<int>(queue_.size()) >= settings_.event_queue) {
      const bool head_in_flight = !queue_.front().mids.empty();
      if (head_in_flight && queue_.size() > 1) {
        queue_.erase(queue_.begin() + 1);
      } else {
        queue_.pop_front();
      }
      ++events_dropped_;
      say_dropped();
    }
    queue_.push_back({alarm_json(notice.event, notice.t_origin), {}});
    most_queued_ = std::max(most_queued_, queue_.size());
  }
  StatusSnapshot s;
  if (!mailbox_.take_status(s)) return;
  const bool changed = !have_state_ || s.level != state_sent_.level ||
                       s.latched != state_sent_.latched || s.cause != state_sent_.cause ||
                       s.phase != state_sent_.phase || s.resets != state_sent_.resets ||
                       s.recorder.health != state_sent_.recorder.health ||
                       s.recorder.problem != state_sent_.recorder.problem;
  state_ = s;
  have_state_ = true;
  if (changed || now_ns - state_sent_ns_ >= ns_of(settings_.state_interval_s)) state_due_ = true;
}

// An overflow is said at once, then again each time the count doubles (1, 2, 4, ...): a long
// outage does not flood the journal, and the count is also in the state (events_dropped).
void MqttPublisher::say_dropped() {
  const std::uint64_t dropped = events_dropped_ + mailbox_.events_dropped();
  if (dropped < next_drop_report_) return;
  next_drop_report_ = 2 * dropped;
  say("alarm event queue full (mqtt.event_queue = " + std::to_string(settings_.event_queue) +
      ", the broker at " + endpoint_text_ + " away): the oldest waiting event dropped, " +
      std::to_string(dropped) + " so far");
}

void MqttPublisher::try_connect(std::int64_t now_ns) {
  if (now_ns < next_attempt_ns_) return;
  if (socket_open_ && !answered_) {  // the attempt before never reached the broker
    ++connect_failures_;  // said once while it lasts, whatever the back-off has grown to
    say_problem("cannot reach the broker at " + endpoint_text_ +
                ": the connection attempt was not answered");
  }
  // A new session each time: libmosquitto keeps the unacknowledged publishes and sends them
  // again once the broker accepted it. Asynchronous: a broker that never answers the TCP
  // handshake (a host gone behind a firewall, a stalled broker's full accept queue) held a
  // blocking connect ~130 s, the events undrained and stop() waiting that long past its flush
  // bound; mosquitto_loop completes the connection.
  answered_ = false;
  const int rc = mosquitto_connect_async(client_, host_.c_str(), port_, settings_.keepalive_s);
  if (rc == MOSQ_ERR_SUCCESS) {
    socket_open_ = true;
    next_attempt_ns_ = now_ns + ns_of(backoff_s_);  // if the session never starts
    backoff_s_ = std::min(2.0 * backoff_s_, settings_.reconnect_max_s);
    return;
  }
  ++connect_failures_;
  lost("cannot reach the broker at " + endpoint_text_ + ": " + error_text(rc), now_ns);
}

// The connection is gone: say why (once), and try again after the back-off.
void MqttPublisher::lost(const std::string& reason, std::int64_t now_ns) {
  say_problem(reason);
  back_off(now_ns);
}

void MqttPublisher::say_problem(const std::string& reason) {
  // libmosquitto's own error (a TLS certificate refused, ...) says more.
  const std::string why = error_log_.empty() ? reason : reason + " (" + error_log_ + ")";
  if (why != last_problem_) {
    char retry[48];
    std::snprintf(retry, sizeof retry, "; retrying (back-off up to %g s)",
                  settings_.reconnect_max_s);
    say(why + retry);
  }
  last_problem_ = why;
}

void MqttPublisher::back_off(std::int64_t now_ns) {
  connected_ = false;
  socket_open_ = false;
  error_log_.clear();
  next_attempt_ns_ = now_ns + ns_of(backoff_s_);
  backoff_s_ = std::min(2.0 * backoff_s_, settings_.reconnect_max_s);
}

// The head event goes out when the one before was acknowledged (or again after a silence).
void MqttPublisher::publish_head(std::int64_t now_ns) {
  if (queue_.empty()) return;
  QueuedEvent& head = queue_.front();
  if (!head.mids.empty() && head_sent_ns_ != 0 &&
      now_ns - head_sent_ns_ < ns_of(kRepublishAfterS)) {
    return;
  }
  int mid = 0;
  if (!publish(events_topic_, head.payload, false, &mid)) return;
  if (!head.mids.empty()) ++events_republished_;
  head.mids.push_back(mid);
  head_sent_ns_ = now_ns;
}

// An operator's command (docs/integration.md, "Commands"): {"command": "acknowledge",
// "level": .., "sequence": .., "id": ..}, or {"command": "statue_stands", "sequence": ..,
// "id": ..} (docs/safety.md); level and sequence default to what the box shows. A well-formed
// command goes to the loop; the reply waits for its outcome.
void MqttPublisher::on_message(const std::string& topic, const std::string& payload,
                               bool retained, const std::string& hmac) {
  if (topic == availability_topic_) {
    // The first message after a connection is the retained value, if any; later ones are the
    // box's own.
    if (checking_will_ && retained && payload == "offline") {
      ++wills_seen_;
      session_log_.say("the broker published the box's Last Will (\"offline\" on " +
                           availability_topic_ + ") while the box ran: another client " +
                           "connected with its client id (" + client_id_ + "), or the broker " +
                           "dropped the box's connection (" + std::to_string(wills_seen_) +
                           " times so far)",
                       monotonic_ns());
    }
    checking_will_ = false;
    return;
  }
  if (settings_.regional_alerts && topic == regional_topic_) {
    return on_regional_alert(payload, hmac);
  }
  if (topic != command_topic_) return;
  ++commands_received_;
  std::string id_json = "null";
  std::string name = "acknowledge";  // the reply's "command"
  const auto refuse = [&](const std::string& why) {
    reply(id_json, name, "refused", why, "");
    incoming_log_.say("command refused: " + why + ": " + printable(payload), monotonic_ns());
  };
  // Published retained, a command would be carried out again at every connection of the box.
  if (retained) {
    ++commands_retained_;
    return refuse("retained (a command is carried out once, when published: publish it "
                  "without the retain flag; an empty retained message clears it)");
  }
  const JsonPayload parsed = parse_json_payload(payload);
  if (!parsed.problem.empty()) return refuse(parsed.problem);
  const nlohmann::json& command = parsed.value;
  if (!command.is_object()) return refuse("expected a JSON object");
  if (command.contains("id")) {
    const nlohmann::json& id = command["id"];
    if (!id.is_string() && !id.is_number_integer()) {
      return refuse("id: expected a string or an integer");
    }
    id_json = id.dump(-1, ' ', true);  // ASCII: \uXXXX for the rest
  }
  for (const auto& [key, value] : command.items()) {
    if (key != "command" && key != "level" && key != "sequence" && key != "id") {
      return refuse("unknown member \"" + printable(key, 64) +
                    "\" (expected command, level, sequence, id)");
    }
  }
  if (!command.contains("command") || !command["command"].is_string()) {
    return refuse("command: expected \"acknowledge\" or \"statue_stands\"");
  }
  CommandRequest request;
  if (command["command"].get<std::string>() == "statue_stands") {
    name = "statue_stands";
    request.command = OperatorCommand::kStatueStands;
    if (command.contains("level")) return refuse("level: statue_stands takes a sequence only");
  } else if (command["command"].get<std::string>() != "acknowledge") {
    return refuse("command: unknown command " +
                  printable(command["command"].dump(-1, ' ', true), 64) +
                  " (expected \"acknowledge\" or \"statue_stands\")");
  }
  if (!settings_.commands) return refuse("commands are off (mqtt.commands = false)");
  request.level = state_.latched;
  request.event_sequence = state_.event_sequence;
  if (command.contains("level")) {
    const nlohmann::json& level = command["level"];
    if (!level.is_string() ||
        !monitor::kAlarmLevelNames.parse(level.get<std::string>(), request.level)) {
      return refuse(std::string("level: expected ") +
                    joined_names<monitor::kAlarmLevelNames>("one of ").data());
    }
  }
  if (command.contains("sequence")) {
    const nlohmann::json& sequence = command["sequence"];
    if (!sequence.is_number_integer() || sequence.get<std::int64_t>() < 0 ||
        sequence.get<std::int64_t>() > 255) {
      return refuse("sequence: expected an integer from 0 to 255");
    }
    request.event_sequence = static_cast<std::uint8_t>(sequence.get<int>());
  }
  if (pending_.size() >= OutputMailbox::kCommandSlots) {
    return refuse("busy: " + std::to_string(pending_.size()) + " commands under way");
  }
  request.id = next_command_id_++;
  if (!mailbox_.post_command(request)) return refuse("busy: the loop has not taken commands");
  JsonObject details;
  if (request.command == OperatorCommand::kAcknowledge) {
    details.text("level", monitor::alarm_level_name(request.level));
  }
  pending_[request.id] = {id_json, request.command,
                          details.count("sequence", request.event_sequence).close()};
}

// A regional alert (docs/regional.md, "MQTT"), its UTC times made relative to now, its HMAC
// checked when the box file asks for one: waits for the loop, which checks its values (or
// counts it malformed or unauthenticated). In a burst the least dangerous waiting alert goes.
void MqttPublisher::on_regional_alert(const std::string& payload, const std::string& hmac) {
  const std::int64_t now = monotonic_ns();
  ++regional_received_;
  WaitingAlert waiting;
  waiting.received_ns = now;
  RegionalRequest& request = waiting.request;
  const monitor::RegionalAuthentication& auth = settings_.regional.authentication;
  if (auth.required && !hmac_matches(auth.key, payload, hmac)) {
    ++regional_unauthenticated_;
    request.refusal = monitor::RegionalRefusal::kUnauthenticated;
    request.field = kRegionalHmacProperty;
    incoming_log_.say(std::string("regional alert unauthenticated: ") +
                          (hmac.empty() ? "no " : "a wrong ") + kRegionalHmacProperty +
                          " user property: " + printable(payload),
                      now);
  } else {
    const RegionalJson parsed = parse_regional_json(payload, wall_clock_ns());
    request.alert = parsed.alert;
    if (!parsed.ok) {
      ++regional_malformed_;
      request.refusal = monitor::RegionalRefusal::kMalformed;
      request.field = parsed.field;
      incoming_log_.say("regional alert malformed: " + parsed.problem + ": " + printable(payload),
                        now);
    } else {
      waiting.danger = danger_of(settings_.regional, parsed.alert);
    }
  }
  if (regional_waiting_.size() >= kRegionalHeldForLoop) {
    // The least dangerous goes, the latest of equals (a burst's refusals before its alerts).
    auto least = regional_waiting_.begin();
    for (auto it = regional_waiting_.begin(); it != regional_waiting_.end(); ++it) {
      if (it->danger <= least->danger) least = it;
    }
    ++regional_lost_;
    incoming_log_.say("regional alerts arrive faster than the loop takes them: the least "
                      "dangerous of " + std::to_string(kRegionalHeldForLoop + 1) +
                          " waiting dropped (" + std::to_string(regional_lost_) + " so far)",
                      now);
    if (waiting.danger <= least->danger) return;
    regional_waiting_.erase(least);
  }
  regional_waiting_.push_back(waiting);
}

// The waiting alerts into the loop's ring, in arrival order, as far as it has room; their
// times made relative to now (they waited).
void MqttPublisher::pass_regional_alerts(std::int64_t now_ns) {
  std::size_t passed = 0;
  for (WaitingAlert& w : regional_waiting_) {
    const double waited_s = static_cast<double>(now_ns - w.received_ns) * 1e-9;
    RegionalRequest request = w.request;
    request.alert.origin_age_s += waited_s;
    request.alert.s_arrival_in_s -= waited_s;
    if (!mailbox_.post_regional(request)) break;
    ++passed;
  }
  regional_waiting_.erase(regional_waiting_.begin(),
                          regional_waiting_.begin() + static_cast<std::ptrdiff_t>(passed));
}

// {"id": .., "command": "acknowledge" | "statue_stands", "result": "accepted" | "refused",
// "reason": .., "level": .., "sequence": .., "outcome": ..}: `details` are the members after
// "reason".
void MqttPublisher::reply(const std::string& id_json, const std::string& command,
                          const std::string& result, const std::string& why,
                          const std::string& details) {
  (result == "accepted" ? commands_accepted_ : commands_refused_) += 1;
  JsonObject line;
  line.raw("id", id_json).text("command", command).text("result", result);
  if (!why.empty()) line.text("reason", why);
  std::string text = line.close();
  if (!details.empty()) text.replace(text.size() - 1, 1, ", " + details.substr(1));
  (void)publish(reply_topic_, text, false, nullptr);
}

// The loop's outcomes of the commands under way.
void MqttPublisher::take_results() {
  CommandResult result;
  while (mailbox_.take_result(result)) {
    const auto it = pending_.find(result.id);
    if (it == pending_.end()) continue;
    const bool stands = it->second.command == OperatorCommand::kStatueStands;
    const bool accepted =
        stands ? result.stands == monitor::StandsOutcome::kCleared
               : result.outcome == monitor::AckOutcome::kReleased ||
                     result.outcome == monitor::AckOutcome::kReleasedConditionHolds;
    const std::string outcome = stands ? monitor::stands_outcome_name(result.stands)
                                       : monitor::ack_outcome_name(result.outcome);
    std::string details = it->second.details;
    details.replace(details.size() - 1, 1, ", \"outcome\": " + host::json_quoted(outcome) + "}");
    reply(it->second.id_json, stands ? "statue_stands" : "acknowledge",
          accepted ? "accepted" : "refused", accepted ? "" : outcome, details);
    pending_.erase(it);
  }
}

// Home Assistant MQTT discovery: retained configs under DISCOVERY/<component>/<node>/<object>/
// for the level, the latched level, the risk, the forecast's probability, the connection, the
// digest of each file given (diagnostic: a device block has no key for them) and, with commands
// on, an acknowledge button; one device per box.
void MqttPublisher::publish_discovery() {
  if (!settings_.discovery) return;
  std::string node = "plinth_" + settings_.box_id;  // [A-Za-z0-9_-] only in discovery topics
  for (char& c : node) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
  }
  const std::string device = JsonObject()
                                 .raw("identifiers", json_array({host::json_quoted(node)}))
                                 .text("name", "plinth " + settings_.box_id)
                                 .text("manufacturer", "plinth")
                                 .text("model", "plinth-monitor")
                                 .text("sw_version", version::kVersionText)
                                 .close();
  std::vector<std::string> levels;
  for (const auto& level : monitor::kAlarmLevelNames) {
    levels.push_back(host::json_quoted(level.name));
  }
  const auto config = [&](const char* component, const char* object, JsonObject entity) {
    const std::string topic =
        settings_.discovery_prefix + "/" + component + "/" + node + "/" + object + "/config";
    entity.text("unique_id", node + "_" + object).raw("device", device);
    if (publish(topic, entity.close(), true, nullptr)) ++discovery_configs_;
  };
  const auto state_sensor = [&](const char* name, const char* template_text) {
    JsonObject e;
    e.text("name", name)
        .text("state_topic", state_topic_)
        .text("value_template", template_text)
        .text("availability_topic", availability_topic_);
    return e;
  };
  config("sensor", "level",
         state_sensor("Alarm level", "{{ value_json.level }}")
             .text("device_class", "enum")
             .raw("options", json_array(levels)));
  config("sensor", "latched",
         state_sensor("Latched level", "{{ value_json.latched }}")
             .text("device_class", "enum")
             .raw("options", json_array(levels)));
  config("sensor", "risk",
         state_sensor("Overturning risk", "{{ value_json.risk }}")
             .text("state_class", "measurement")
             .count("suggested_display_precision", 4));
  config("sensor", "probability",
         state_sensor("Collapse probability", "{{ value_json.forecast.probability }}")
             .text("state_class", "measurement")
             .count("suggested_display_precision", 4));
  for (const DigestMember& d : digests_) {
    if (d.hex.empty()) continue;
    const std::string value_template = "{{ value_json." + d.member + " }}";
    config("sensor", d.member.c_str(),
           state_sensor((d.file + " SHA-256").c_str(), value_template.c_str())
               .text("entity_category", "diagnostic"));
  }
  config("binary_sensor", "availability",
         JsonObject()
             .text("name", "Online")
             .text("state_topic", availability_topic_)
             .text("payload_on", "online")
             .text("payload_off", "offline")
             .text("device_class", "connectivity")
             .text("entity_category", "diagnostic"));
  if (settings_.commands) {
    config("button", "acknowledge",
           JsonObject()
               .text("name", "Acknowledge")
               .text("command_topic", command_topic_)
               .text("payload_press", "{\"command\": \"acknowledge\", \"id\": \"home-assistant\"}")
               .text("availability_topic", availability_topic_));
  }
}

namespace {

// The state's "regional": null before any alert; the worst held alert (null: none held) with
// its time to the S arrival, and the counters.
std::string regional_state_json(const RegionalSnapshot& r) {
  if (r.received == 0) return "null";
  std::string alert = "null";
  if (r.held > 0) {
    alert = JsonObject()
                .count("event_id", r.event_id)
                .count("version", r.version)
                .fixed("magnitude", r.magnitude, 2)
                .fixed("distance_km", r.distance_km, 1)
                .fixed("pga_g", r.pga_g, 4)
                .fixed("sigma_ln", r.sigma_ln, 2)
                .fixed("probability", r.probability, 4)
                .fixed("time_to_s_arrival_s", r.time_to_s_arrival_s, 1)
                .fixed("s_arrival_t", r.s_arrival_t, 3)
                .close();
  }
  return JsonObject()
      .count("held", static_cast<std::uint64_t>(r.held))
      .raw("alert", alert)
      .count("received", r.received)
      .count("accepted", r.accepted)
      .count("refused", r.refused)
      .text("last_refusal", monitor::regional_refusal_name(r.last_refusal))
      .raw("refused_dangerous", refused_dangerous_json(r.refused_dangerous,
                                                       r.last_refused_dangerous,
                                                       r.last_refused_dangerous_t))
      .close();
}

}  // namespace

std::string MqttPublisher::state_json() const {
  const StatusSnapshot& s = state_;
  JsonObject phase;
  const char* axes[] = {"x", "y"};
  for (int i = 0; i < s.axis_count && i < kMaxAxes; ++i) {
    phase.text(axes[i], phase_name(s.phase[static_cast<std::size_t>(i)]));
  }
  const bool forecast = s.forecast_axis >= 0 && s.forecast_axis < kMaxAxes;
  const bool worst = forecast && s.forecast_worst_member >= 0;
  JsonObject forecast_json;
  forecast_json.fixed("probability", s.probability, 4)
      .raw("axis", forecast ? host::json_quoted(axes[s.forecast_axis]) : "null")
      .raw("worst_member", worst ? std::to_string(s.forecast_worst_member) : "null");
  if (s.collapse_forecast) {
    forecast_json.fixed("collapse_t", s.collapse_forecast_t, 3)
        .fixed("collapse_in_s", std::max(s.collapse_forecast_t - s.t, 0.0), 3);
  } else {
    forecast_json.raw("collapse_t", "null").raw("collapse_in_s", "null");
  }
  const monitor::SensorCounters& c = s.sensor_counters;
  const std::string counters = JsonObject()
                                   .count("fed", c.fed)
                                   .count("bridged", c.bridged)
                                   .count("missing", c.missing)
                                   .count("timeouts", c.timeouts)
                                   .count("faults", c.faults)
                                   .count("rejected", c.non_finite + c.out_of_range +
                                                          c.undefined_status)
                                   .close();
  JsonObject state;
  state.text("box", settings_.box_id)
      .fixed("t", s.t, 6)
      .text("time", utc_text(s.wall_time_ns))
      .text("level", monitor::alarm_level_name(s.level))
      .text("latched", monitor::alarm_level_name(s.latched))
      .text("cause", monitor::alarm_cause_name(s.cause))
      .text("trouble", monitor::alarm_cause_name(s.trouble))
      .flag("collapse_held", s.collapse_held)
      .fixed("risk", s.risk, 4)
      .raw("forecast", forecast_json.close())
      .raw("phase", phase.close())
      .flag("estimating", s.estimating)
      .text("sensor", monitor::health_state_name(s.sensor))
      .text("sensors_state", monitor::health_state_name(s.sensors_state))
      .raw("sensor_counters", counters)
      .raw("statue_sensor", statue_sensor_state(s, axes))
      .count("estimator_restarts", s.estimator_restarts)
      .raw("regional", regional_state_json(s.regional))
      .raw("recorder", s.recorder.present ? recorder_status_json(s.recorder) : "null")
      .count("heartbeat", s.statuses)
      .count("events_dropped", events_dropped_ + mailbox_.events_dropped())
      .count("session_takeovers", takeovers_)
      .count("wills_while_running", wills_seen_)
      .raw("version", JsonObject()
                          .text("project", version::kProjectVersion)
                          .text("git", version::kGitDescription)
                          .close());
  for (const DigestMember& d : digests_) {
    state.raw(d.member, d.hex.empty() ? "null" : host::json_quoted(d.hex));
  }
  return state.close();
}

void MqttPublisher::publish_state(std::int64_t now_ns) {
  if (!state_due_) return;
  if (!publish(state_topic_, state_json(), true, nullptr)) return;
  state_due_ = false;
  state_sent_ = state_;
  state_sent_ns_ = now_ns;
  ++states_published_;
}

void MqttPublisher::run() {
  std::int64_t flush_deadline_ns = 0;
  while (true) {
    const std::int64_t now = monotonic_ns();
    take_mailbox(now);
    if (stopping_.load()) {
      if (flush_deadline_ns == 0) {
        flush_deadline_ns = now + ns_of(kFlushTimeoutS);
        state_due_ = have_state_ && state_.updates != state_sent_.updates;  // the final state
      }
      if ((queue_.empty() && (!state_due_ || !connected_)) || now > flush_deadline_ns) break;
    }
    pass_regional_alerts(now);
    if (!connected_) try_connect(now);
    if (connected_) {
      publish_state(now);
      publish_head(now);
    }
    if (!socket_open_) {
      usleep(kLoopTimeoutMs * 1000);
      continue;
    }
    const int rc = mosquitto_loop(client_, kLoopTimeoutMs, 1);
    if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_CONN_REFUSED && !answered_) {
      ++connect_failures_;  // the asynchronous connection failed (refused, unreachable, ...)
      lost("cannot reach the broker at " + endpoint_text_ + ": " + error_text(rc), now);
    } else if (rc != MOSQ_ERR_SUCCESS && rc != MOSQ_ERR_CONN_REFUSED) {
      // on_disconnect counted it.
      lost("connection to " + endpoint_text_ + " lost: " + error_text(rc), now);
    } else if (rc == MOSQ_ERR_CONN_REFUSED) {
      back_off(now);  // on_connect said why
    }
  }
  say_offline();
}

// A clean stop: "offline" on the availability topic (the Will goes only on a lost connection).
void MqttPublisher::say_offline() {
  if (!connected_) return;
  if (publish(availability_topic_, "offline", true, &offline_mid_)) {
    const std::int64_t deadline = monotonic_ns() + kNsPerS;
    while (!offline_acknowledged_ && monotonic_ns() < deadline &&
           mosquitto_loop(client_, kLoopTimeoutMs, 1) == MOSQ_ERR_SUCCESS) {
    }
  }
  mosquitto_disconnect(client_);
  (void)mosquitto_loop(client_, kLoopTimeoutMs, 1);
}

std::string MqttPublisher::summary_json() const {
  return JsonObject()
      .text("broker", endpoint_text_.substr(0, endpoint_text_.find(' ')))
      .text("box", settings_.box_id)
      .count("connects", connects_)
      .count("connect_failures", connect_failures_)
      .count("refusals", refusals_)
      .count("connections_lost", connections_lost_)
      .count("session_takeovers", takeovers_)
      .count("wills_while_running", wills_seen_)
      .count("events_published", events_published_)
      .count("events_republished", events_republished_)
      .count("events_dropped", events_dropped_ + mailbox_.events_dropped())
      .count("events_undelivered", queue_.size())
      .count("most_queued", most_queued_)
      .count("states_published", states_published_)
      .count("discovery_configs", discovery_configs_)
      .count("commands_received", commands_received_)
      .count("commands_accepted", commands_accepted_)
      .count("commands_refused", commands_refused_)
      .count("commands_retained", commands_retained_)
      .count("regional_received", regional_received_)
      .count("regional_malformed", regional_malformed_)
      .count("regional_unauthenticated", regional_unauthenticated_)
      .count("regional_lost", regional_lost_)
      .count("regional_waiting", regional_waiting_.size())
      .close();
}

}  // namespace plinth::firmware
