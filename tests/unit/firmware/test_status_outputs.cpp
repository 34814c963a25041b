// The seam between plinth-monitor's loop and its outputs (firmware/linux/status_outputs.h):
// the lock-free mailbox between two threads, HOST:PORT, and the [modbus] / [mqtt] keys.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "monitor_config.h"
#include "plinth/host/input_error.h"
#include "status_outputs.h"

namespace plinth::firmware {
namespace {

// A value whose parts must always agree: a torn copy shows.
struct Pair {
  std::uint64_t a = 0;
  std::uint64_t b = 0;
};

TEST(LatestValue, TheReaderSeesOnlyWholeValuesInOrder) {
  LatestValue<Pair> value;
  constexpr std::uint64_t kCount = 200000;
  std::thread writer([&] {
    for (std::uint64_t i = 1; i <= kCount; ++i) value.publish({i, ~i});
  });
  std::uint64_t last = 0;
  std::uint64_t taken = 0;
  while (last < kCount) {
    Pair p;
    if (!value.take(p)) continue;
    ASSERT_EQ(p.b, ~p.a) << "a torn value";
    ASSERT_GT(p.a, last) << "an older value after a newer one";
    last = p.a;
    ++taken;
  }
  writer.join();
  EXPECT_GE(taken, 1U);
  Pair p;
  EXPECT_FALSE(value.take(p)) << "nothing new after the last value was taken";
}

TEST(SpscRing, KeepsOrderAndRefusesWhenFull) {
  SpscRing<int, 4> ring;
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(ring.push(i));
  EXPECT_FALSE(ring.push(4));
  int v = -1;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(ring.pop(v));
}

TEST(SpscRing, TwoThreadsLoseNothing) {
  SpscRing<std::uint64_t, 64> ring;
  constexpr std::uint64_t kCount = 200000;
  std::thread writer([&] {
    for (std::uint64_t i = 0; i < kCount; ++i) {
      while (!ring.push(i)) std::this_thread::yield();
    }
  });
  std::uint64_t expected = 0;
  while (expected < kCount) {
    std::uint64_t v = 0;
    if (ring.pop(v)) {
      ASSERT_EQ(v, expected++);
    }
  }
  writer.join();
}

TEST(OutputMailbox, AFullEventRingCountsTheDropped) {
  OutputMailbox mailbox;
  AlarmNotice notice;
  for (std::size_t i = 0; i < OutputMailbox::kEventSlots + 3; ++i) {
    notice.event.sequence = static_cast<std::uint8_t>(i);
    mailbox.post_alarm(notice);
  }
  EXPECT_EQ(mailbox.events_dropped(), 3U);
  ASSERT_TRUE(mailbox.take_alarm(notice));
  EXPECT_EQ(notice.event.sequence, 0);
}

std::string endpoint_error(const std::string& text) {
  try {
    (void)parse_endpoint(text, "--modbus");
  } catch (const host::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Endpoint, HostAndPort) {
  EXPECT_EQ(parse_endpoint("127.0.0.1:1502", "k").host, "127.0.0.1");
  EXPECT_EQ(parse_endpoint("127.0.0.1:1502", "k").port, 1502);
  EXPECT_EQ(parse_endpoint("[::1]:8883", "k").host, "::1");
  EXPECT_EQ(parse_endpoint("[::1]:8883", "k").text(), "[::1]:8883");
  EXPECT_EQ(parse_endpoint("broker.local:1883", "k").text(), "broker.local:1883");
  for (const char* bad : {"", "1502", "host:", ":1502", "host:0", "host:65536", "host:15x",
                          "::1:1502", "[::1]1502", "[::1", "a b:1"}) {
    const std::string e = endpoint_error(bad);
    EXPECT_EQ(e.rfind("--modbus: expected HOST:PORT", 0), 0U) << bad << ": " << e;
  }
}

std::string config_error(const std::string& text) {
  try {
    (void)load_monitor_text(text, "/etc/plinth/box.toml", MonitorConfig{});
  } catch (const host::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(OutputKeys, ReadWithTheirLinesAndPathsResolved) {
  const MonitorFile f = load_monitor_text(
      "[modbus]\nlisten = \"0.0.0.0:1502\"\nwrites = true\n"
      "[mqtt]\nbroker = \"site.local:8883\"\nbox_id = \"hall-3\"\npassword_file = \"mqtt.pw\"\n"
      "tls_ca_file = \"/etc/ssl/site-ca.crt\"\nevent_queue = 50\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_EQ(f.modbus.listen, "0.0.0.0:1502");
  EXPECT_EQ(f.modbus.listen_where, "/etc/plinth/box.toml:2: modbus.listen");
  EXPECT_TRUE(f.modbus.writes);
  EXPECT_EQ(f.mqtt.broker_where, "/etc/plinth/box.toml:5: mqtt.broker");
  EXPECT_EQ(f.mqtt.box_id, "hall-3");
  EXPECT_EQ(f.mqtt.password_file, "/etc/plinth/mqtt.pw");
  EXPECT_EQ(f.mqtt.ca_file, "/etc/ssl/site-ca.crt");
  EXPECT_EQ(f.mqtt.event_queue, 50);
  EXPECT_FALSE(f.mqtt.commands) << "commands are off unless the file turns them on";
  EXPECT_TRUE(f.mqtt.discovery);
  EXPECT_EQ(f.mqtt.discovery_prefix, "homeassistant");
  const MonitorFile g = load_monitor_text(
      "[mqtt]\ncommands = true\ndiscovery = false\ndiscovery_prefix = \"site/ha\"\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_TRUE(g.mqtt.commands);
  EXPECT_FALSE(g.mqtt.discovery);
  EXPECT_EQ(g.mqtt.discovery_prefix, "site/ha");
}

TEST(OutputKeys, BadValuesNameTheLineAndKey) {
  EXPECT_EQ(config_error("[modbus]\nlisten = 1502\n"),
            "/etc/plinth/box.toml:2: modbus.listen: expected a string, \"HOST:PORT\"");
  EXPECT_EQ(config_error("[mqtt]\nbroker = \"h:1\"\nbox_id = \"a/b\"\n")
                .rfind("/etc/plinth/box.toml:3: mqtt.box_id: expected one topic level", 0),
            0U);
  EXPECT_EQ(config_error("[mqtt]\ntopic_prefix = \"site/#\"\n")
                .rfind("/etc/plinth/box.toml:2: mqtt.topic_prefix", 0),
            0U);
  EXPECT_EQ(config_error("[mqtt]\nreconnect_min_s = 5\nreconnect_max_s = 1\n"),
            "/etc/plinth/box.toml:3: mqtt.reconnect_max_s: must lie in [5, 3600]");
  EXPECT_EQ(config_error("[mqtt]\npassword = \"x\"\npassword_file = \"y\"\n")
                .rfind("/etc/plinth/box.toml:2: mqtt.password: give", 0),
            0U);
  EXPECT_EQ(config_error("[mqtt]\ndiscovery_prefix = \"ha/+\"\n"),
            "/etc/plinth/box.toml:2: mqtt.discovery_prefix: expected topic levels (no '+' or "
            "'#', no empty level): a wildcard ('+' or '#')");
  EXPECT_EQ(config_error("[mqtt]\nbrokers = \"h:1\"\n")
                .rfind("/etc/plinth/box.toml:2: mqtt.brokers: unknown key", 0),
            0U);
}

// A topic part the file gives is one the broker sees whole: a NUL would end it early (in
// another box's topics), a control character forge a log line; the length is bounded.
TEST(OutputKeys, TopicPartsArePrintableUtf8OfBoundedLength) {
  const std::string nul = config_error(std::string("[mqtt]\nbox_id = \"hall-3\\u0000x\"\n"));
  EXPECT_EQ(nul.rfind("/etc/plinth/box.toml:2: mqtt.box_id: expected one topic level", 0), 0U)
      << nul;
  EXPECT_NE(nul.find("a control character"), std::string::npos) << nul;
  const std::string long_id =
      config_error("[mqtt]\nbox_id = \"" + std::string(70000, 'a') + "\"\n");
  EXPECT_NE(long_id.find("mqtt.box_id: expected one topic level"), std::string::npos);
  EXPECT_NE(long_id.find("longer than 64 bytes (70000)"), std::string::npos) << long_id.size();
  EXPECT_NE(config_error("[mqtt]\ntopic_prefix = \"site\\nx\"\n").find("a control character"),
            std::string::npos);
  EXPECT_EQ(config_error("[mqtt]\nbox_id = \"hall-\\u00e9\"\n"), "") << "UTF-8 is a topic";
}

// regional_topic: one topic, and only with regional_alerts on.
TEST(OutputKeys, TheRegionalTopicNeedsItsAlerts) {
  EXPECT_EQ(config_error("[mqtt]\nregional_topic = \"site/eew\"\n"),
            "/etc/plinth/box.toml:2: mqtt.regional_topic: names the regional alerts' topic, and "
            "mqtt.regional_alerts is false (set it to true to take them)");
  EXPECT_EQ(config_error("[mqtt]\nregional_alerts = true\nregional_topic = \"site/+/eew\"\n"),
            "/etc/plinth/box.toml:3: mqtt.regional_topic: expected one topic, without wildcards "
            "(the box takes alerts from one bridge's topic): a wildcard ('+' or '#')");
  EXPECT_EQ(config_error("[mqtt]\nregional_alerts = true\nregional_topic = \"site/eew\"\n"), "");
}

std::string override_error(const std::string& text, const MonitorOverrides& o) {
  try {
    MonitorFile f = load_monitor_text(text, "/etc/plinth/box.toml", MonitorConfig{});
    apply_overrides(f, o);
  } catch (const host::InputError& e) {
    return e.what();
  }
  return "";
}

// A key that turns something on while what it turns on is off is refused with its line; coil
// writes need the addresses that may make them.
TEST(OutputKeys, KeysThatTurnOnWhatIsOffAreRefused) {
  const MonitorOverrides none;
  EXPECT_EQ(override_error("[modbus]\nwrites = true\n", none),
            "/etc/plinth/box.toml:2: modbus.writes: lets the Modbus server's coils be written; "
            "the server is off (--modbus, or modbus.listen)");
  EXPECT_EQ(override_error("[modbus]\nwrites = false\nmax_clients = 8\n", none), "")
      << "the shipped box file's template: defaults, no effect, accepted";
  const std::string no_writers =
      override_error("[modbus]\nlisten = \"127.0.0.1:1502\"\nwrites = true\n", none);
  EXPECT_EQ(no_writers.rfind("/etc/plinth/box.toml:3: modbus.writes: needs modbus.write_from", 0),
            0U)
      << no_writers;
  EXPECT_EQ(override_error("[modbus]\nlisten = \"127.0.0.1:1502\"\nwrite_from = [\"::1\"]\n",
                           none)
                .rfind("/etc/plinth/box.toml:3: modbus.write_from: names who may write", 0),
            0U);
  EXPECT_EQ(override_error("[modbus]\nlisten = \"127.0.0.1:1502\"\nwrites = true\n"
                           "write_from = [\"127.0.0.1\", \"10.0.4.0/24\"]\n",
                           none),
            "");
  EXPECT_EQ(config_error("[modbus]\nwrite_from = [\"10.0.4.7/24\"]\n")
                .rfind("/etc/plinth/box.toml:2: modbus.write_from: \"10.0.4.7/24\" is not", 0),
            0U);
  EXPECT_EQ(config_error("[modbus]\nwrite_from = \"10.0.4.7\"\n"),
            "/etc/plinth/box.toml:2: modbus.write_from: expected an array of strings (addresses, "
            "\"10.0.4.7\" or \"10.0.4.0/24\")");
  EXPECT_EQ(config_error("[modbus]\nidle_timeout_s = 0.5\n"),
            "/etc/plinth/box.toml:2: modbus.idle_timeout_s: must lie in [1, 86400]");
  MonitorOverrides writes;
  writes.modbus_listen = "127.0.0.1:1502";
  writes.modbus_writes = true;
  EXPECT_EQ(override_error("", writes).rfind("--modbus-writes: needs modbus.write_from", 0), 0U);
  writes.modbus_write_from = {"127.0.0.1"};
  EXPECT_EQ(override_error("", writes), "");
  writes.modbus_write_from = {"localhost"};
  EXPECT_EQ(override_error("", writes).rfind("--modbus-write-from: \"localhost\" is not", 0), 0U);
  EXPECT_EQ(override_error("[mqtt]\ncommands = true\n", none),
            "/etc/plinth/box.toml:2: mqtt.commands: turns on a part of the MQTT client, which is "
            "off (--mqtt, or mqtt.broker)");
  MonitorOverrides broker;
  broker.mqtt_broker = "127.0.0.1:1883";
  EXPECT_EQ(override_error("[mqtt]\ncommands = true\n", broker), "");
  MonitorOverrides nul_id = broker;
  nul_id.mqtt_box_id = std::string("a\0b", 3);
  EXPECT_NE(override_error("", nul_id).find("--mqtt-box-id: expected one topic level"),
            std::string::npos);
}

// regional_alert.key_file: 64 hex digits on the first line; the room then requires tags.
TEST(OutputKeys, TheRegionalKeyFile) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("plinth-key-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const char* name, const std::string& text) {
    std::ofstream(dir / name) << text;
  };
  write("good.key", "000102030405060708090a0b0c0d0e0f101112131415161718191A1B1C1D1E1F\n");
  write("short.key", "0001\n");
  write("bad.key", std::string(63, '0') + "g\n");
  const std::string box = (dir / "box.toml").string();
  const MonitorFile f =
      load_monitor_text("[regional_alert]\nkey_file = \"good.key\"\n", box, MonitorConfig{});
  const auto* room = monitor::built_part<monitor::RegionalAlertSettings>(f.config.regional);
  ASSERT_NE(room, nullptr);
  EXPECT_TRUE(room->authentication.required);
  for (std::size_t i = 0; i < room->authentication.key.size(); ++i) {
    EXPECT_EQ(room->authentication.key[i], i) << i;
  }
  MonitorFile plain = load_monitor_text("", box, MonitorConfig{});
  EXPECT_FALSE(monitor::built_part<monitor::RegionalAlertSettings>(plain.config.regional)
                   ->authentication.required);
  for (const char* bad : {"short.key", "bad.key", "missing.key"}) {
    std::string error;
    try {
      (void)load_monitor_text(std::string("[regional_alert]\nkey_file = \"") + bad + "\"\n", box,
                              MonitorConfig{});
    } catch (const host::InputError& e) {
      error = e.what();
    }
    EXPECT_NE(error.find("regional_alert.key_file"), std::string::npos) << bad << ": " << error;
  }
  std::filesystem::remove_all(dir);
}

TEST(OutputKeys, TheCommandLineOverTheFile) {
  MonitorFile f =
      load_monitor_text("[modbus]\nlisten = \"127.0.0.1:1502\"\n", "box.toml", MonitorConfig{});
  MonitorOverrides o;
  o.modbus_listen = "127.0.0.1:1503";
  o.mqtt_broker = "127.0.0.1:1883";
  o.mqtt_password_file = "pw";
  apply_overrides(f, o);
  EXPECT_EQ(f.modbus.listen, "127.0.0.1:1503");
  EXPECT_EQ(f.modbus.listen_where, "--modbus");
  EXPECT_EQ(f.mqtt.broker_where, "--mqtt");
  EXPECT_EQ(f.mqtt.password_file, "pw");
  o.mqtt_broker = "nonsense";
  EXPECT_THROW(apply_overrides(f, o), host::InputError);
}

}  // namespace
}  // namespace plinth::firmware
