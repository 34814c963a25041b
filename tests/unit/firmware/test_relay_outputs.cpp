// The relays' logic (firmware/linux/relay_outputs.h) on the fake backend, and the [relays] and
// [watchdog] tables of the box's configuration file. The libgpiod backend is tested on the
// kernel's gpio-sim (tests/integration/relays_guest.sh).
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "box_file_error.h"
#include "monitor_config.h"
#include "plinth/host/input_error.h"
#include "relay_fake.h"
#include "relay_gpiod.h"
#include "relay_outputs.h"

namespace plinth::firmware {
namespace {

using monitor::AlarmLevel;

constexpr AlarmLevel kNormal = AlarmLevel::kNormal;
constexpr AlarmLevel kAdvisory = AlarmLevel::kAdvisory;
constexpr AlarmLevel kWarning = AlarmLevel::kWarning;
constexpr AlarmLevel kAlarm = AlarmLevel::kAlarm;
constexpr AlarmLevel kFault = AlarmLevel::kFault;

// Energised relays as a string in the order advisory, warning, alarm, fault: "1110".
std::string pattern(AlarmLevel shown, AlarmLevel latched, bool fault = false) {
  std::string out;
  for (std::size_t i = 0; i < kRelayCount; ++i) {
    out += relay_energised(static_cast<Relay>(i), shown, latched, fault) ? '1' : '0';
  }
  return out;
}

TEST(RelayLogic, EachLevelOpensItsRelayAndTheOnesBelow) {
  EXPECT_EQ(pattern(kNormal, kNormal), "1111");
  EXPECT_EQ(pattern(kAdvisory, kNormal), "0111");
  EXPECT_EQ(pattern(kWarning, kNormal), "0011");
  EXPECT_EQ(pattern(kAlarm, kNormal), "0001");
}

TEST(RelayLogic, ALatchedLevelKeepsItsRelaysOpenUntilAcknowledged) {
  EXPECT_EQ(pattern(kNormal, kWarning), "0011");
  EXPECT_EQ(pattern(kAdvisory, kAlarm), "0001");
  EXPECT_EQ(pattern(kWarning, kAlarm), "0001");
}

TEST(RelayLogic, TheFaultLevelOpensEveryRelay) {
  EXPECT_EQ(pattern(kFault, kNormal), "0000");
  EXPECT_EQ(pattern(kFault, kAlarm), "0000");
  // A fault latched (not a level the policy latches) does not open the level relays.
  EXPECT_EQ(pattern(kNormal, kFault), "1111");
}

TEST(RelayLogic, AFaultUnderAnAlarmStillOpensTheFaultRelay) {
  EXPECT_EQ(pattern(kAlarm, kAlarm, true), "0000");  // the policy shows the alarm
  EXPECT_EQ(pattern(kFault, kNormal, true), "0000");
  EXPECT_EQ(pattern(kNormal, kNormal, true), "1110");
}

struct Bench {
  explicit Bench(const RelaySettings& settings, std::size_t wired) {
    auto fake = std::make_unique<FakeRelayBackend>(wired);
    backend = fake.get();
    relays = std::make_unique<RelayOutputs>(settings, std::move(fake));
  }
  FakeRelayBackend* backend;
  std::unique_ptr<RelayOutputs> relays;
};

RelaySettings all_four() {
  RelaySettings s;
  s.chip = "gpiochip0";
  for (std::size_t i = 0; i < kRelayCount; ++i) s.lines[i].offset = static_cast<int>(10 + i);
  return s;
}

TEST(RelayOutputs, ReleasedUntilTheMonitorIsHealthyThenWritesOnlyChanges) {
  Bench b(all_four(), 4);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_FALSE(b.backend->level(i));
  b.relays->update(kFault, kNormal, false);  // the box starts in fault: nothing to write
  EXPECT_TRUE(b.backend->writes().empty());
  b.relays->update(kNormal, kNormal, false);
  ASSERT_EQ(b.backend->writes().size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_TRUE(b.backend->level(i));
  b.relays->update(kNormal, kNormal, false);
  EXPECT_EQ(b.backend->writes().size(), 4u);
  b.relays->update(kWarning, kWarning, false);
  EXPECT_EQ(b.backend->writes().size(), 6u);
  EXPECT_FALSE(b.backend->level(0));
  EXPECT_FALSE(b.backend->level(1));
  EXPECT_TRUE(b.backend->level(2));
  EXPECT_TRUE(b.backend->level(3));
  b.relays->update(kNormal, kWarning, false);  // the risk fell, the warning is latched: no change
  EXPECT_EQ(b.backend->writes().size(), 6u);
  b.relays->update(kNormal, kNormal, false);  // acknowledged
  EXPECT_TRUE(b.backend->level(0));
  EXPECT_TRUE(b.backend->level(1));
  b.relays->update(kFault, kNormal, false);
  for (std::size_t i = 0; i < 4; ++i) EXPECT_FALSE(b.backend->level(i));
  EXPECT_EQ(b.relays->write_errors(), 0u);
}

TEST(RelayOutputs, OnlyTheWiredRelaysInTheBackendsOrder) {
  RelaySettings s;
  s.chip = "gpiochip0";
  s.lines[static_cast<std::size_t>(Relay::kAlarm)].offset = 3;
  s.lines[static_cast<std::size_t>(Relay::kFault)].offset = 1;
  Bench b(s, 2);
  b.relays->update(kAdvisory, kNormal, false);
  EXPECT_TRUE(b.backend->level(0));  // alarm
  EXPECT_TRUE(b.backend->level(1));  // fault
  b.relays->update(kAlarm, kAlarm, false);
  EXPECT_FALSE(b.backend->level(0));
  EXPECT_TRUE(b.backend->level(1));
  ASSERT_EQ(b.backend->writes().size(), 3u);
  EXPECT_EQ(b.backend->writes().back().index, 0u);
}

TEST(RelayOutputs, AFailedWriteIsCountedAndTriedAgain) {
  Bench b(all_four(), 4);
  b.backend->fail_writes = true;
  b.relays->update(kNormal, kNormal, false);
  EXPECT_EQ(b.relays->write_errors(), 4u);
  EXPECT_FALSE(b.relays->energised(Relay::kAlarm));
  b.backend->fail_writes = false;
  b.relays->update(kNormal, kNormal, false);
  EXPECT_TRUE(b.relays->energised(Relay::kAlarm));
  EXPECT_TRUE(b.backend->level(2));
}

// Messages name the file box.toml.
std::string relay_file_error(const std::string& text) {
  return testing::box_file_error(text, "box.toml");
}

TEST(RelayConfig, OffsetsPolarityAndTheChip) {
  const MonitorFile f = load_monitor_text(
      "[relays]\nchip = \"gpiochip2\"\nactive_low = true\nadvisory = 4\n"
      "warning = { line = 5, active_low = false }\nalarm.line = 6\n",
      "box.toml", MonitorConfig{});
  EXPECT_EQ(f.relays.chip, "gpiochip2");
  EXPECT_EQ(f.relays.lines[0].offset, 4);
  EXPECT_TRUE(f.relays.lines[0].active_low);
  EXPECT_EQ(f.relays.lines[1].offset, 5);
  EXPECT_FALSE(f.relays.lines[1].active_low);
  EXPECT_EQ(f.relays.lines[2].offset, 6);
  EXPECT_TRUE(f.relays.lines[2].active_low);
  EXPECT_EQ(f.relays.lines[3].offset, -1);
  EXPECT_FALSE(load_monitor_text("", "box.toml", MonitorConfig{}).relays.enabled());
}

TEST(RelayConfig, BadTablesNameTheKeyAndTheLine) {
  EXPECT_EQ(relay_file_error("[relays]\nchip = \"gpiochip0\"\nadvisory = 1\nalarm = 1\n"),
            "box.toml:4: relays.alarm: line 1 is already relays.advisory's");
  EXPECT_EQ(relay_file_error("[relays]\nalarm = 3\n"),
            "box.toml: relays: lines without relays.chip");
  EXPECT_EQ(relay_file_error("[relays]\nchip = \"gpiochip0\"\n"),
            "box.toml:2: relays.chip: no relay lines (advisory, warning, alarm, fault)");
  EXPECT_EQ(relay_file_error("[relays]\nchip = \"gpiochip0\"\nalarm = -2\n"),
            "box.toml:3: relays.alarm: line offset must lie in [0, 1023]");
  EXPECT_EQ(relay_file_error("[relays]\nchip = \"gpiochip0\"\nalarm = \"GPIO17\"\n"),
            "box.toml:3: relays.alarm: expected an integer (a line offset)");
  EXPECT_EQ(relay_file_error("[relays]\nchip = \"gpiochip0\"\nsiren = 3\n"),
            "box.toml:3: relays.siren: unknown key (docs/monitor.md lists them)");
  EXPECT_EQ(
      relay_file_error("[relays]\nchip = \"gpiochip0\"\nalarm = 2\nwarning.active_low = true\n"),
      "box.toml:4: relays.warning: no line");
}

TEST(RelayConfig, TheCommandLineReplacesTheChipOrTurnsTheRelaysOff) {
  MonitorFile f =
      load_monitor_text("[relays]\nchip = \"gpiochip0\"\nalarm = 2\n", "box.toml", MonitorConfig{});
  MonitorOverrides o;
  o.relay_chip = "/dev/gpiochip3";
  apply_overrides(f, o);
  EXPECT_EQ(f.relays.chip, "/dev/gpiochip3");
  MonitorOverrides off;
  off.no_relays = true;
  apply_overrides(f, off);
  EXPECT_FALSE(f.relays.enabled());
  MonitorFile none;
  EXPECT_THROW(apply_overrides(none, o), host::InputError);
}

TEST(RelayConfig, TheExamplesCommentedTableParsesOnceUncommented) {
  std::ifstream in(std::string(PLINTH_SOURCE_DIR) + "/firmware/monitor.example.toml");
  std::stringstream text;
  bool inside = false;
  for (std::string line; std::getline(in, line);) {
    if (line == "#[relays]") inside = true;
    if (inside && line.empty()) inside = false;
    text << (inside ? line.substr(1) : line) << '\n';
  }
  const MonitorFile f = load_monitor_text(text.str(), "example.toml", MonitorConfig{});
  EXPECT_EQ(f.relays.chip, "gpiochip0");
  EXPECT_EQ(f.relays.lines[0].offset, 17);
  EXPECT_TRUE(f.relays.lines[0].active_low);
  EXPECT_EQ(f.relays.lines[3].offset, 23);
  EXPECT_TRUE(load_monitor_file(std::string(PLINTH_SOURCE_DIR) + "/firmware/monitor.example.toml",
                                MonitorConfig{})
                  .watchdog.notify);
}

TEST(RelayGpiod, AChipThatDoesNotExistIsNamed) {
  RelaySettings s;
  s.chip = "/dev/plinth-no-such-gpiochip";
  s.lines[0].offset = 0;
  try {
    (void)open_gpiod_relays(s);
    FAIL() << "opened a chip that does not exist";
  } catch (const host::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "relays.chip: cannot open GPIO chip '/dev/plinth-no-such-gpiochip': No such file or "
              "directory");
  }
}

TEST(WatchdogConfig, NotifyAndTheTestOnlyStall) {
  const MonitorFile defaults = load_monitor_text("", "box.toml", MonitorConfig{});
  EXPECT_TRUE(defaults.watchdog.notify);
  EXPECT_EQ(defaults.watchdog.test_stall_after_s, 0.0);
  const MonitorFile f = load_monitor_text("[watchdog]\nnotify = false\ntest_stall_after_s = 2.5\n",
                                          "box.toml", MonitorConfig{});
  EXPECT_FALSE(f.watchdog.notify);
  EXPECT_EQ(f.watchdog.test_stall_after_s, 2.5);
  EXPECT_EQ(relay_file_error("[watchdog]\ntest_stall_after_s = -1\n"),
            "box.toml:2: watchdog.test_stall_after_s: must be a finite number of seconds >= 0");
  EXPECT_EQ(relay_file_error("[watchdog]\nnotify = 1\n"),
            "box.toml:2: watchdog.notify: expected true or false");
}

}  // namespace
}  // namespace plinth::firmware
