// The seam between plinth-monitor's loop and its outputs (firmware/linux/status_outputs.h):
// the lock-free mailbox between two threads, HOST:PORT, and the [modbus] / [mqtt] keys.
#include <gtest/gtest.h>

#include <cstdint>
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
            "'#', no empty level)");
  EXPECT_EQ(config_error("[mqtt]\nbrokers = \"h:1\"\n")
                .rfind("/etc/plinth/box.toml:2: mqtt.brokers: unknown key", 0),
            0U);
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
