// The box's memory across restarts (firmware/linux/box_state_store.h): the state's JSON read back
// exactly, anything else refused with the member named; the folder's file written atomically,
// an unreadable one kept aside and taken for the worst it may have said. The store in a real
// process (a restart, a reset, SIGKILL): tests/cli/test_monitor_state.sh.
#include <gtest/gtest.h>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "box_state_store.h"
#include "plinth/host/input_error.h"

namespace plinth::firmware {
namespace {

namespace fs = std::filesystem;
namespace mon = monitor;

// A fresh folder under the test's temporary directory.
fs::path fresh_folder(const std::string& name) {
  const fs::path p = fs::path(::testing::TempDir()) / ("box-state-" + name);
  fs::remove_all(p);
  return p;
}

std::string read_file(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

SavedBoxState collapsed_state() {
  SavedBoxState s;
  s.memory.alarm.latched_level = mon::AlarmLevel::kAlarm;
  s.memory.alarm.latched_cause = mon::AlarmCause::kOverturnDetected;
  s.memory.alarm.collapse_held = true;
  s.memory.alarm.next_sequence = 7;
  s.memory.collapse.held = true;
  s.memory.collapse.axis = 1;
  s.memory.collapse.mode.phase = Phase::kFell;
  s.memory.collapse.mode.corner = Corner::kRight;
  s.saved_wall_ns = 1'765'000'000'000'000'000;
  s.collapse_wall_ns = 1'764'999'999'000'000'000;
  return s;
}

TEST(BoxState, TheJsonReadsBackExactly) {
  const SavedBoxState s = collapsed_state();
  const BoxStateParse p = parse_box_state(box_state_json(s));
  ASSERT_TRUE(p.state) << p.error;
  const BoxMemory& m = p.state->memory;
  EXPECT_EQ(m.alarm.latched_level, mon::AlarmLevel::kAlarm);
  EXPECT_EQ(m.alarm.latched_cause, mon::AlarmCause::kOverturnDetected);
  EXPECT_TRUE(m.alarm.collapse_held);
  EXPECT_EQ(m.alarm.next_sequence, 7);
  EXPECT_EQ(m.collapse.axis, 1);
  EXPECT_EQ(m.collapse.mode.phase, Phase::kFell);
  EXPECT_EQ(m.collapse.mode.corner, Corner::kRight);
  EXPECT_EQ(p.state->saved_wall_ns, s.saved_wall_ns);
  EXPECT_EQ(p.state->collapse_wall_ns, s.collapse_wall_ns);
}

// Every way a file can lie is refused, the member named: a reader that guessed would restore
// another state than the one saved.
TEST(BoxState, AnythingElseIsRefusedNamingTheMember) {
  const std::string good = box_state_json(collapsed_state());
  const auto with = [&good](const std::string& from, const std::string& to) {
    std::string s = good;
    const std::size_t at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
  };
  const struct {
    std::string text;
    const char* says;
  } cases[] = {
      {"", "not JSON"},
      {"[1, 2]", "expected a JSON object"},
      {with("\"latched_level\": \"alarm\"", "\"latched_level\": \"fault\""), "latched_level"},
      {with("\"latched_level\": \"alarm\"", "\"latched_level\": 3"), "latched_level"},
      {with("\"latched_cause\": \"overturn_detected\"", "\"latched_cause\": \"boom\""),
       "latched_cause"},
      {with("\"next_sequence\": 7", "\"next_sequence\": 256"), "next_sequence"},
      {with("\"next_sequence\": 7", "\"next_sequence\": 7, \"next_sequence\": 8"),
       "\"next_sequence\" twice"},
      {with("\"next_sequence\": 7", "\"next_sequence\": 7, \"extra\": 1"),
       "unknown member \"extra\""},
      {with("\"held\": true", "\"held\": 1"), "collapse.held"},
      {with("\"axis\": 1", "\"axis\": 2"), "collapse.axis"},
      {with("\"phase\": \"fell\"", "\"phase\": \"full_contact\""), "collapse.phase"},
      {with("\"corner\": \"right\"", "\"corner\": \"none\""), "collapse.corner"},
      {with("\"format\": \"plinth-alarm-state 1\"", "\"format\": \"plinth-alarm-state 2\""),
       "format"},
      {with("\"saved_wall_ns\": 1765000000000000000", "\"saved_wall_ns\": -1"),
       "saved_wall_ns"},
  };
  for (const auto& c : cases) {
    const BoxStateParse p = parse_box_state(c.text);
    EXPECT_FALSE(p.state) << c.text;
    EXPECT_NE(p.error.find(c.says), std::string::npos) << p.error << " / " << c.says;
  }
}

TEST(BoxState, AFirstStartFindsNothingAndWritesTheFile) {
  const fs::path dir = fresh_folder("first");
  BoxStateStore store(dir.string());
  EXPECT_FALSE(store.loaded());
  EXPECT_TRUE(store.unreadable().empty());
  ASSERT_TRUE(fs::exists(dir / BoxStateStore::kFileName));
  EXPECT_TRUE(parse_box_state(read_file(dir / BoxStateStore::kFileName)).state);
}

// Saved when the memory changes (not else), read back by the next start, the collapse's wall
// time kept from when it was first saved.
TEST(BoxState, WhatIsSavedComesBackAtTheNextStart) {
  const fs::path dir = fresh_folder("saved");
  {
    BoxStateStore store(dir.string());
    const std::uint64_t writes = store.writes();
    BoxMemory m = collapsed_state().memory;
    ASSERT_TRUE(store.save(m, 100));
    ASSERT_TRUE(store.save(m, 200));  // unchanged: not written again
    EXPECT_EQ(store.writes(), writes + 1);
    m.alarm.latched_level = mon::AlarmLevel::kNormal;  // acknowledged; the collapse held
    m.alarm.latched_cause = mon::AlarmCause::kNone;
    ASSERT_TRUE(store.save(m, 300));
    EXPECT_EQ(store.writes(), writes + 2);
  }
  BoxStateStore again(dir.string());
  ASSERT_TRUE(again.loaded());
  const SavedBoxState& s = *again.loaded();
  EXPECT_EQ(s.memory.alarm.latched_level, mon::AlarmLevel::kNormal);
  EXPECT_TRUE(s.memory.alarm.collapse_held);
  EXPECT_EQ(s.memory.collapse.mode.phase, Phase::kFell);
  EXPECT_EQ(s.saved_wall_ns, 300);
  EXPECT_EQ(s.collapse_wall_ns, 100);
  EXPECT_FALSE(fs::exists(dir / ".alarm-state.json.tmp"));  // renamed over, nothing left
}

// A file that cannot be trusted: kept aside, the worst it may have said restored (a latched
// alarm), and the folder's file rewritten so that the next start reads it.
TEST(BoxState, AnUnreadableFileIsKeptAsideAndTakenForTheWorst) {
  const fs::path dir = fresh_folder("unreadable");
  fs::create_directories(dir);
  std::ofstream(dir / BoxStateStore::kFileName) << "{\"format\": \"plinth-alarm-state 1\"";
  BoxStateStore store(dir.string());
  ASSERT_TRUE(store.loaded());
  EXPECT_EQ(store.loaded()->memory.alarm.latched_level, mon::AlarmLevel::kAlarm);
  EXPECT_EQ(store.loaded()->memory.alarm.latched_cause, mon::AlarmCause::kRestored);
  EXPECT_NE(store.unreadable().find("not JSON"), std::string::npos) << store.unreadable();
  EXPECT_TRUE(fs::exists(dir / "alarm-state.json.unreadable"));
  EXPECT_TRUE(parse_box_state(read_file(dir / BoxStateStore::kFileName)).state);
}

// The temporary file's name planted as a link to another file: never followed, the target
// untouched.
TEST(BoxState, APlantedLinkIsNeverFollowed) {
  const fs::path dir = fresh_folder("link");
  fs::create_directories(dir);
  const fs::path target = dir / "victim";
  std::ofstream(target) << "keep me";
  fs::create_symlink(target, dir / ".alarm-state.json.tmp");
  BoxStateStore store(dir.string());
  ASSERT_TRUE(store.save(collapsed_state().memory, 1));
  EXPECT_EQ(read_file(target), "keep me");
  EXPECT_FALSE(fs::is_symlink(dir / BoxStateStore::kFileName));
}

// A folder that cannot be made (its parent a file; root writes any folder, so this is how a
// test refuses one as root too): refused at start, the folder named.
TEST(BoxState, AFolderThatCannotBeMadeIsRefusedAtStart) {
  const fs::path parent = fresh_folder("parent-file");
  fs::create_directories(parent.parent_path());
  std::ofstream(parent) << "a file";
  const fs::path dir = parent / "state";
  try {
    BoxStateStore store(dir.string());
    FAIL() << "accepted " << dir;
  } catch (const host::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.string() + ": cannot create"), std::string::npos)
        << e.what();
  }
  fs::remove(parent);
}

TEST(BoxState, APathThatIsNoFolderIsRefused) {
  const fs::path dir = fresh_folder("file");
  fs::create_directories(dir.parent_path());
  std::ofstream(dir) << "a file";
  try {
    BoxStateStore store(dir.string());
    FAIL() << "accepted a file as the state directory";
  } catch (const host::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a directory"), std::string::npos) << e.what();
  }
  fs::remove(dir);
}

}  // namespace
}  // namespace plinth::firmware
