// The event recorder's folder (firmware/linux/capture_store.h): the retention choice, the
// numbering, whole-or-nothing writes that write over nothing and follow no symlink, the lock,
// a folder that disappears; and the run's identity (run_identity.h): SHA-256 against
// FIPS 180-4's examples. The recorder in a real process (restarts, SIGKILL while writing, the
// limit): tests/cli/test_event_recorder.sh.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "capture_store.h"
#include "run_identity.h"

namespace plinth::firmware {
namespace {

namespace fs = std::filesystem;

std::vector<CaptureOnDisk> captures(const std::string& levels, std::uint64_t bytes = 100) {
  std::vector<CaptureOnDisk> out;
  for (std::size_t i = 0; i < levels.size(); ++i) {
    out.push_back({i + 1, levels[i] == 'A', bytes, 0});
  }
  return out;
}

using Indices = std::vector<std::uint64_t>;

TEST(Retention, NoLimitDeletesNothing) {
  EXPECT_TRUE(captures_to_delete(captures("wwwAAA"), {}).empty());
}

TEST(Retention, OldestBelowAlarmFirst) {
  // 1 A, 2 w, 3 A, 4 w, 5 w; keep 3: 2 and 4 go, 5 (a warning, the newest) stays.
  EXPECT_EQ(captures_to_delete(captures("AwAww"), {3, 0}), (Indices{2, 4}));
}

TEST(Retention, ThenOldestAlarmButNeverTheNewestAlarm) {
  EXPECT_EQ(captures_to_delete(captures("AwAww"), {1, 0}), (Indices{2, 4, 5, 1}));
  // Nothing but the newest alarm capture left to delete: the folder stays over its limit.
  EXPECT_EQ(captures_to_delete(captures("A"), {0, 10}), Indices{});
  EXPECT_EQ(captures_to_delete(captures("AAA"), {0, 150}), (Indices{1, 2}));
}

TEST(Retention, WithoutAlarmCapturesTheOldestGo) {
  EXPECT_EQ(captures_to_delete(captures("wwww"), {2, 0}), (Indices{1, 2}));
}

TEST(Retention, BytesAndCountTogether) {
  // 4 captures of 100 bytes; at most 3 captures and 250 bytes: two go.
  EXPECT_EQ(captures_to_delete(captures("wwww"), {3, 250}), (Indices{1, 2}));
}

TEST(Retention, TheNewestAlarmCapturesPiecesAreKept) {
  // 1 w, 2 w, 3 A, 4 A: 3 continues 2, 4 continues 3 (one long capture in three pieces).
  std::vector<CaptureOnDisk> c = captures("wwAA");
  c[2].continues = 2;
  c[3].continues = 3;
  EXPECT_EQ(captures_to_delete(c, {1, 0}), (Indices{1}));
  // A loop planted in the summaries ends: 2 "continues" 4.
  c[1].continues = 4;
  EXPECT_EQ(captures_to_delete(c, {1, 0}), (Indices{1}));
}

TEST(MakeRoom, BelowAlarmFirstThenOlderAlarmsForAnAlarm) {
  // 100-byte captures in 4096-byte blocks: each frees a block.
  const std::vector<CaptureOnDisk> c = captures("AwAw");
  EXPECT_EQ(captures_to_make_room(c, 5000, false, 4096), (Indices{2, 4}));
  EXPECT_EQ(captures_to_make_room(c, 4096, false, 4096), (Indices{2}));
  // A warning never takes an alarm capture's room: not enough, nothing deleted.
  EXPECT_EQ(captures_to_make_room(c, 9000, false, 4096), Indices{});
  // An alarm capture takes the older alarm captures' too, never the newest (3).
  EXPECT_EQ(captures_to_make_room(c, 9000, true, 4096), (Indices{2, 4, 1}));
  EXPECT_EQ(captures_to_make_room(c, 13000, true, 4096), Indices{});
}

TEST(CaptureNames, OneNameACapture) {
  std::string extension;
  EXPECT_EQ(capture_index("event-007.log", &extension), 7U);
  EXPECT_EQ(extension, "log");
  EXPECT_EQ(capture_index("event-1234.json", &extension), 1234U);
  EXPECT_EQ(extension, "json");
  EXPECT_EQ(capture_index("event-999999999.json"), kMaxCaptureIndex);
  for (const char* foreign :
       {"event-07.log", "event-0007.log", "event-000.log", "event-1000000000.json", "event-007.txt",
        "event-007.log.partial", "event--07.log", "event-0x7.log", "notes.txt", "event-.log"}) {
    EXPECT_EQ(capture_index(foreign), 0U) << foreign;
  }
  EXPECT_EQ(capture_stem(7), "event-007");
  EXPECT_EQ(capture_stem(1234), "event-1234");
  EXPECT_EQ(capture_stem(kMaxCaptureIndex), "event-999999999");
  EXPECT_EQ(next_capture_index({}), 1U);
  EXPECT_EQ(next_capture_index(captures("ww")), 3U);
  EXPECT_EQ(next_capture_index({{kMaxCaptureIndex, false, 1, 0}}), kMaxCaptureIndex + 1);
}

class Folder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("plinth-capture-store-" + std::to_string(::getpid()) + "-" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name()))
               .string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void put(const std::string& name, const std::string& text) {
    std::ofstream(fs::path(dir_) / name) << text;
  }
  static std::string text_of(const std::string& path) {
    std::ifstream in(path);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static void open(CaptureFolder& folder) {
    std::string error;
    ASSERT_EQ(folder.open(error), RecorderProblem::kNone) << error;
  }
  std::string dir_;
};

TEST_F(Folder, ScanFindsCapturesAndTheirLevels) {
  put("event-001.log", "x\n");
  put("event-001.json", R"({"event":1,"level":"warning","highest_level":"alarm"})");
  put("event-002.log", "y\n");
  put("event-002.json", R"({"event":2,"level":"warning","highest_level":"warning"})");
  put("event-017.json", R"({"level": "alarm", "continues": 2})");  // spaces, as by hand
  put("notes.txt", "not a capture");
  put("event-0018.json", R"({"level": "alarm"})");  // not a name the recorder writes
  put(".event-018.log.partial", "half");
  CaptureFolder folder(dir_);
  open(folder);
  const std::vector<CaptureOnDisk> found = folder.scan();
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].index, 1U);
  EXPECT_TRUE(found[0].alarm);
  EXPECT_EQ(found[0].bytes, 2 + 53U);
  EXPECT_FALSE(found[1].alarm);
  EXPECT_EQ(found[2].index, 17U);
  EXPECT_TRUE(found[2].alarm);
  EXPECT_EQ(found[2].continues, 2U);
  EXPECT_EQ(next_capture_index(found), 18U);
  EXPECT_EQ(folder.remove_partial_files(), 1);
  EXPECT_FALSE(fs::exists(fs::path(dir_) / ".event-018.log.partial"));
  EXPECT_TRUE(fs::exists(fs::path(dir_) / "notes.txt"));
  EXPECT_TRUE(fs::exists(fs::path(dir_) / "event-0018.json"));
}

// A process killed between a capture's two renames: its log under its final name, its summary
// still partial (whole: both are flushed before either rename). The next start completes it;
// other partial files go.
TEST_F(Folder, ACaptureKilledBetweenItsRenamesIsCompleted) {
  put("event-020.log", "x\n");
  put(".event-020.json.partial", R"({"event":20,"highest_level":"alarm"})");
  put(".event-021.json.partial", R"({"event":21})");  // its log never renamed
  put(".event-022.log.partial", "half");
  put("event-023.log", "y\n");
  put("event-023.json", R"({"event":23})");
  put(".event-023.json.partial", R"({"planted":true})");  // never over the summary there
  CaptureFolder folder(dir_);
  open(folder);
  int completed = 0;
  EXPECT_EQ(folder.remove_partial_files(&completed), 3);
  EXPECT_EQ(completed, 1);
  EXPECT_EQ(text_of(dir_ + "/event-020.json"), R"({"event":20,"highest_level":"alarm"})");
  EXPECT_EQ(text_of(dir_ + "/event-023.json"), R"({"event":23})");
  EXPECT_FALSE(fs::exists(fs::path(dir_) / "event-021.json"));
  for (const char* partial : {".event-020.json.partial", ".event-021.json.partial",
                              ".event-022.log.partial", ".event-023.json.partial"}) {
    EXPECT_FALSE(fs::exists(fs::path(dir_) / partial)) << partial;
  }
}

// What an attacker plants under a capture's name is no capture: a symlink (to a file that says
// alarm), a folder, a FIFO (opening it would hang), a huge summary (read 64 KiB at most).
TEST_F(Folder, ScanFollowsNoSymlinkAndReadsSummariesBounded) {
  const std::string outside = dir_ + "-outside.json";
  std::ofstream(outside) << R"({"highest_level":"alarm"})";
  fs::create_symlink(outside, fs::path(dir_) / "event-003.json");
  fs::create_directory(fs::path(dir_) / "event-004.log");
  ASSERT_EQ(::mkfifo((fs::path(dir_) / "event-005.json").c_str(), 0644), 0);
  put("event-006.json", std::string(kMaxSummaryBytes, ' ') + R"("highest_level":"alarm")");
  CaptureFolder folder(dir_);
  open(folder);
  const std::vector<CaptureOnDisk> found = folder.scan();
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].index, 6U);
  EXPECT_FALSE(found[0].alarm) << "beyond the bytes read";
  fs::remove(outside);
}

TEST_F(Folder, WholeWriteLeavesOnlyTheFinalFile) {
  CaptureFolder folder(dir_);
  open(folder);
  std::string error;
  bool halfway_seen = false;
  const auto halfway = [&] {
    halfway_seen = true;
    // Halfway: no final name yet, the partial file holds half.
    EXPECT_FALSE(fs::exists(fs::path(dir_) / "event-003.log"));
    EXPECT_EQ(fs::file_size(fs::path(dir_) / ".event-003.log.partial"), 3u);
  };
  ASSERT_EQ(folder.write_whole("event-003.log", "abcdef", error, halfway), WriteOutcome::kWritten)
      << error;
  EXPECT_TRUE(halfway_seen);
  EXPECT_TRUE(folder.commit(error)) << error;
  EXPECT_EQ(text_of(dir_ + "/event-003.log"), "abcdef");
  EXPECT_FALSE(fs::exists(fs::path(dir_) / ".event-003.log.partial"));
}

TEST_F(Folder, NothingIsWrittenOverNorThroughASymlink) {
  CaptureFolder folder(dir_);
  open(folder);
  std::string error;
  // A file under the final name stays as it was.
  put("event-001.log", "earlier");
  EXPECT_EQ(folder.write_whole("event-001.log", "later", error), WriteOutcome::kNameTaken);
  EXPECT_EQ(text_of(dir_ + "/event-001.log"), "earlier");
  EXPECT_NE(error.find("not written over"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(fs::path(dir_) / ".event-001.log.partial"));
  // A symlink planted at the partial name: removed, its target untouched.
  const std::string target = dir_ + "-target";
  std::ofstream(target) << "precious";
  fs::create_symlink(target, fs::path(dir_) / ".event-002.log.partial");
  EXPECT_EQ(folder.write_whole("event-002.log", "capture", error), WriteOutcome::kWritten) << error;
  EXPECT_EQ(text_of(target), "precious");
  EXPECT_EQ(text_of(dir_ + "/event-002.log"), "capture");
  EXPECT_FALSE(fs::is_symlink(fs::path(dir_) / "event-002.log"));
  // A symlink under the final name is a name taken: not followed, not replaced.
  fs::create_symlink(target, fs::path(dir_) / "event-003.log");
  EXPECT_EQ(folder.write_whole("event-003.log", "capture", error), WriteOutcome::kNameTaken);
  EXPECT_EQ(text_of(target), "precious");
  EXPECT_TRUE(folder.taken("event-003.log"));
  EXPECT_FALSE(folder.taken("event-004.log"));
  fs::remove(target);
}

TEST_F(Folder, OneBoxAFolder) {
  std::optional<CaptureFolder> first(std::in_place, dir_);
  open(*first);
  EXPECT_EQ(text_of(dir_ + "/" + kFolderLockName), std::to_string(::getpid()) + "\n");
  CaptureFolder second(dir_);
  std::string error;
  EXPECT_EQ(second.open(error), RecorderProblem::kFolderInUse);
  EXPECT_NE(error.find("in use by another plinth-monitor (pid " + std::to_string(::getpid())),
            std::string::npos)
      << error;
  EXPECT_FALSE(second.held());
  first.reset();  // the lock goes with the descriptor
  EXPECT_EQ(second.open(error), RecorderProblem::kNone) << error;
}

TEST_F(Folder, APlantedLockFileIsRefusedNotFollowed) {
  const std::string target = dir_ + "-target";
  std::ofstream(target) << "precious";
  fs::create_symlink(target, fs::path(dir_) / kFolderLockName);
  CaptureFolder folder(dir_);
  std::string error;
  EXPECT_EQ(folder.open(error), RecorderProblem::kLockFile);
  EXPECT_NE(error.find("a symlink, not followed"), std::string::npos) << error;
  EXPECT_EQ(text_of(target), "precious");
  fs::remove(fs::path(dir_) / kFolderLockName);
  fs::create_directory(fs::path(dir_) / kFolderLockName);
  EXPECT_EQ(folder.open(error), RecorderProblem::kLockFile);
  fs::remove(target);
}

TEST_F(Folder, AFolderThatDisappearsIsRecreated) {
  CaptureFolder folder(dir_);
  open(folder);
  std::string error;
  bool recreated = true;
  EXPECT_EQ(folder.check(error, recreated), RecorderProblem::kNone) << error;
  EXPECT_FALSE(recreated);
  fs::remove_all(dir_);
  EXPECT_EQ(folder.check(error, recreated), RecorderProblem::kNone) << error;
  EXPECT_TRUE(recreated);
  EXPECT_TRUE(fs::is_directory(dir_));
  EXPECT_EQ(folder.write_whole("event-001.log", "x", error), WriteOutcome::kWritten) << error;
  EXPECT_TRUE(fs::exists(fs::path(dir_) / "event-001.log"));
  // Renamed away: the path is a new folder again.
  fs::rename(dir_, dir_ + "-old");
  EXPECT_EQ(folder.check(error, recreated), RecorderProblem::kNone) << error;
  EXPECT_TRUE(recreated);
  EXPECT_FALSE(fs::exists(fs::path(dir_) / "event-001.log"));
  fs::remove_all(dir_ + "-old");
  EXPECT_GT(folder.free_bytes(), 0U);
  EXPECT_GE(folder.block_bytes(), 512U);
}

TEST_F(Folder, AFolderThatCannotBeMadeSaysWhy) {
  put("file", "x");
  CaptureFolder folder(dir_ + "/file/sub");
  std::string error;
  EXPECT_EQ(folder.open(error), RecorderProblem::kFolderMissing);
  EXPECT_NE(error.find("cannot create the folder " + dir_ + "/file/sub"), std::string::npos)
      << error;
  EXPECT_EQ(folder.write_whole("event-001.log", "x", error), WriteOutcome::kFailed);
}

// FIPS 180-4's examples (NIST CSRC, "SHA256.pdf", "SHA2_Additional.pdf").
TEST(Sha256, FipsExamples) {
  EXPECT_EQ(hex(sha256("")), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(hex(sha256("abc")),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(hex(sha256("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(hex(sha256(std::string(1000000, 'a'))),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  // 55, 56 and 64 bytes: the padding's boundaries (one block, two blocks, a whole block).
  EXPECT_EQ(hex(sha256(std::string(55, 'a'))),
            "9f4390f8d30c2dd92ec9f095b65e2b9ae9b0a925a5258e241c9f1e910f734318");
  EXPECT_EQ(hex(sha256(std::string(56, 'a'))),
            "b35439a4ac6f0948b6d6f9e3c6af0f5f590ce20f1bde7090ef7970686ec6738a");
  EXPECT_EQ(hex(sha256(std::string(64, 'a'))),
            "ffe054fe7ae0cb6dc65c3af9b61d5209f439851db43d0ba5997337df154668eb");
  EXPECT_EQ(leading_64_bits(sha256("abc")), 0xba7816bf8f01cfeaULL);
}

TEST(RunIdentity, MembersAndInsertion) {
  RunIdentity id;
  id.version = "0.1.0 (abc)";
  id.scene = sha256("");
  id.config = sha256("abc");
  EXPECT_EQ(identity_members(id),
            "\"version\": \"0.1.0 (abc)\", "
            "\"scene_sha256\": "
            "\"e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855\", "
            "\"config_sha256\": "
            "\"ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad\"")
      << "no scene_y_sha256: that file was not given";
  EXPECT_EQ(with_members("{\"a\": 1}", "\"b\": 2"), "{\"a\": 1, \"b\": 2}");
  EXPECT_EQ(with_members("{}", "\"b\": 2"), "{\"b\": 2}");
}

}  // namespace
}  // namespace plinth::firmware
