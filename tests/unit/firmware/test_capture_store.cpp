// The event recorder's folder (firmware/linux/capture_store.h): the retention choice, the
// numbering, whole-or-nothing writes; and the run's identity (run_identity.h): SHA-256 against
// FIPS 180-4's examples. The recorder in a real process (restarts, SIGKILL while writing, the
// limit): tests/cli/test_event_recorder.sh.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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
    out.push_back({static_cast<int>(i) + 1, levels[i] == 'A', bytes});
  }
  return out;
}

TEST(Retention, NoLimitDeletesNothing) {
  EXPECT_TRUE(captures_to_delete(captures("wwwAAA"), {}).empty());
}

TEST(Retention, OldestBelowAlarmFirst) {
  // 1 A, 2 w, 3 A, 4 w, 5 w; keep 3: 2 and 4 go, 5 (a warning, the newest) stays.
  EXPECT_EQ(captures_to_delete(captures("AwAww"), {3, 0}), (std::vector<int>{2, 4}));
}

TEST(Retention, ThenOldestAlarmButNeverTheNewestAlarm) {
  EXPECT_EQ(captures_to_delete(captures("AwAww"), {1, 0}), (std::vector<int>{2, 4, 5, 1}));
  // Nothing but the newest alarm capture left to delete: the folder stays over its limit.
  EXPECT_EQ(captures_to_delete(captures("A"), {0, 10}), std::vector<int>{});
  EXPECT_EQ(captures_to_delete(captures("AAA"), {0, 150}), (std::vector<int>{1, 2}));
}

TEST(Retention, WithoutAlarmCapturesTheOldestGo) {
  EXPECT_EQ(captures_to_delete(captures("wwww"), {2, 0}), (std::vector<int>{1, 2}));
}

TEST(Retention, BytesAndCountTogether) {
  // 4 captures of 100 bytes; at most 3 captures and 250 bytes: two go.
  EXPECT_EQ(captures_to_delete(captures("wwww"), {3, 250}), (std::vector<int>{1, 2}));
}

class Folder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("plinth-capture-store-" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
             "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name()))
               .string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  void put(const std::string& name, const std::string& text) {
    std::ofstream(fs::path(dir_) / name) << text;
  }
  std::string dir_;
};

TEST_F(Folder, ScanFindsCapturesAndTheirLevels) {
  put("event-001.log", "x\n");
  put("event-001.json", R"({"event":1,"level":"warning","highest_level":"alarm"})");
  put("event-002.log", "y\n");
  put("event-002.json", R"({"event":2,"level":"warning","highest_level":"warning"})");
  put("event-017.json", R"({"level": "alarm"})");  // spaces, as a hand-made file may have
  put("notes.txt", "not a capture");
  put(".event-018.log.partial", "half");
  const std::vector<CaptureOnDisk> found = scan_captures(dir_);
  ASSERT_EQ(found.size(), 3u);
  EXPECT_EQ(found[0].index, 1);
  EXPECT_TRUE(found[0].alarm);
  EXPECT_FALSE(found[1].alarm);
  EXPECT_EQ(found[2].index, 17);
  EXPECT_TRUE(found[2].alarm);
  EXPECT_EQ(next_capture_index(found), 18);
  EXPECT_EQ(next_capture_index({}), 1);
  EXPECT_EQ(remove_partial_files(dir_), 1);
  EXPECT_FALSE(fs::exists(fs::path(dir_) / ".event-018.log.partial"));
  EXPECT_TRUE(fs::exists(fs::path(dir_) / "notes.txt"));
}

TEST_F(Folder, WholeWriteLeavesOnlyTheFinalFile) {
  std::string error;
  bool halfway_seen = false;
  ASSERT_TRUE(write_file_whole(dir_, "event-003.log", "abcdef", error, [&] {
    halfway_seen = true;
    // Halfway: the final name does not exist yet, the partial file holds half.
    EXPECT_FALSE(fs::exists(fs::path(dir_) / "event-003.log"));
    EXPECT_EQ(fs::file_size(fs::path(dir_) / ".event-003.log.partial"), 3u);
  })) << error;
  EXPECT_TRUE(halfway_seen);
  EXPECT_TRUE(commit_folder(dir_, error)) << error;
  std::ifstream in(fs::path(dir_) / "event-003.log");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text, "abcdef");
  EXPECT_FALSE(fs::exists(fs::path(dir_) / ".event-003.log.partial"));
}

TEST_F(Folder, AFailedWriteSaysWhy) {
  std::string error;
  EXPECT_FALSE(write_file_whole(dir_ + "/missing", "event-001.log", "x", error));
  EXPECT_NE(error.find("cannot create"), std::string::npos) << error;
  EXPECT_FALSE(commit_folder(dir_ + "/missing", error));
}

TEST(CaptureStem, AtLeastThreeDigits) {
  EXPECT_EQ(capture_stem(7), "event-007");
  EXPECT_EQ(capture_stem(1234), "event-1234");
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
