// The event recorder's folder (docs/monitor.md, "Event recorder"): what captures it holds, their
// numbers, files written whole or not at all and never over another file, the lock that keeps
// one box a folder, and retention. Every file in the folder is taken as written by an attacker:
// names are read strictly, no symlink is followed, summaries are read bounded, and only the
// recorder's own names are ever removed. Host code: allocates; used off the real-time loop (at
// start-up and by the recorder's writer thread).
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "recorder_status.h"

namespace plinth::firmware {

// Capture numbers run from 1 to this (event-999999999: nine digits); a capture with this number
// in the folder leaves none after it (RecorderProblem::kNumberingExhausted).
inline constexpr std::uint64_t kMaxCaptureIndex = 999'999'999;
// The lock file in the folder (flock): the plinth-monitor holding it writes its pid in it.
inline constexpr const char* kFolderLockName = ".plinth-monitor.lock";
// A capture's JSON summary is read up to this many bytes (a real one is under 2 KiB).
inline constexpr std::size_t kMaxSummaryBytes = 64 * 1024;

// [recorder] of the box's file: how much the folder keeps; 0: no limit.
struct RetentionLimits {
  std::uint64_t max_captures = 0;  // recorder.max_captures: captures (a .log with its .json)
  std::uint64_t max_bytes = 0;     // recorder.max_bytes: bytes of all captures together
};

// One capture in the folder: event-<index>.log and its summary event-<index>.json.
struct CaptureOnDisk {
  std::uint64_t index = 0;
  bool alarm = false;           // it reached the alarm level (its JSON says so)
  std::uint64_t bytes = 0;      // both files
  std::uint64_t continues = 0;  // the capture it continues (a long one in pieces), 0: none
};

// The number of a capture's file name, "event-<digits>.log" or ".json" with its digits as
// capture_stem() writes them (at least three, no other leading zero, at most kMaxCaptureIndex);
// 0 for any other name. `extension`, when given, receives "log" or "json".
[[nodiscard]] std::uint64_t capture_index(std::string_view name, std::string* extension = nullptr);

// "event-007": the stem of a capture's files (at least three digits).
[[nodiscard]] std::string capture_stem(std::uint64_t index);

// The index after the highest of `captures` (1 for none); kMaxCaptureIndex + 1 when exhausted.
[[nodiscard]] std::uint64_t next_capture_index(const std::vector<CaptureOnDisk>& captures);

// The indices to delete so that `captures` (sorted by index, the newest last) keep within
// `limits`: the oldest captures below alarm first, then the oldest alarm captures, never the
// newest alarm capture nor the pieces it continues (the folder may stay over its limit for
// them alone).
[[nodiscard]] std::vector<std::uint64_t> captures_to_delete(
    const std::vector<CaptureOnDisk>& captures, const RetentionLimits& limits);

// The indices to delete, in the same order, to free `bytes` (each capture frees its bytes
// rounded up to `block_bytes`) for a new capture: below alarm only for a capture below alarm;
// for an alarm capture (`for_alarm`) the older alarm captures too, but never the newest alarm
// capture nor its pieces. Empty when even all of those would not free `bytes`: nothing is
// deleted for a capture that would not fit anyway.
[[nodiscard]] std::vector<std::uint64_t> captures_to_make_room(
    const std::vector<CaptureOnDisk>& captures, std::uint64_t bytes, bool for_alarm,
    std::uint64_t block_bytes);

enum class WriteOutcome : std::uint8_t {
  kWritten,
  kNameTaken,  // a file of that name exists: nothing was written over it
  kNoSpace,    // ENOSPC or EDQUOT: the disk (or the quota) is full
  kFailed,     // any other error
};

// The folder held by one recorder: a descriptor of it (its files are reached through it, so a
// symlink planted in the folder is never followed), and its lock.
class CaptureFolder {
 public:
  explicit CaptureFolder(std::string path) : path_(std::move(path)) {}
  ~CaptureFolder() { release(); }
  CaptureFolder(const CaptureFolder&) = delete;
  CaptureFolder& operator=(const CaptureFolder&) = delete;

  // Opens the folder at the path (created when missing; the path itself may be a symlink, the
  // administrator's), locks it against another plinth-monitor (flock on kFolderLockName) and
  // checks that files can be created in it. kNone when it can be used; otherwise the problem,
  // with `error` saying it, and nothing is held.
  [[nodiscard]] RecorderProblem open(std::string& error);
  // Whether the folder held is still the one at the path, and writable; a folder that
  // disappeared (deleted, renamed) is opened again, recreated (`recreated` set). Not held: as
  // open().
  [[nodiscard]] RecorderProblem check(std::string& error, bool& recreated);
  [[nodiscard]] bool held() const { return dir_fd_ >= 0; }
  [[nodiscard]] const std::string& path() const { return path_; }

  // The captures in the folder, by index: regular files with a capture's name (a .json
  // without its .log, or the reverse, is one capture all the same; a summary that cannot be
  // read counts as below alarm). Symlinks, folders, devices and other names are left alone.
  [[nodiscard]] std::vector<CaptureOnDisk> scan() const;
  // The partial files (".event-*.partial") a process killed while writing left: a capture's
  // summary whose log is already under its final name is renamed into place too (both files
  // are flushed before either is renamed: it is whole; `completed` counts them); every other
  // partial file is removed. Returns how many were removed.
  int remove_partial_files(int* completed = nullptr);
  // Whether anything (a file, a symlink, a folder) has this name.
  [[nodiscard]] bool taken(std::string_view name) const;
  // Writes `text` into ".name.partial", created afresh (whatever had that name, a symlink
  // included, is removed first, never opened), and flushes it to disk (fsync): nothing is under
  // `name` yet. On failure the partial file is removed and `error` says what failed. `halfway`,
  // when set, runs with half the text written (a test's pause: the recorder's
  // test_pause_mid_write_s).
  [[nodiscard]] WriteOutcome write_partial(std::string_view name, std::string_view text,
                                           std::string& error,
                                           const std::function<void()>& halfway = {});
  // Renames ".name.partial" to `name` unless a file has that name (kNameTaken: nothing is
  // written over it); the partial file is removed on any failure.
  [[nodiscard]] WriteOutcome publish(std::string_view name, std::string& error);
  // Removes ".name.partial".
  void discard_partial(std::string_view name);
  // write_partial(), then publish(): `name` whole or not at all.
  [[nodiscard]] WriteOutcome write_whole(std::string_view name, std::string_view text,
                                         std::string& error,
                                         const std::function<void()>& halfway = {});
  // Removes both files of capture `index` (a symlink of such a name is removed, not followed).
  void remove_capture(std::uint64_t index);
  // Removes `name` (a file this recorder wrote).
  void remove(std::string_view name);
  // fsync of the folder: the renames and removals survive a power cut.
  [[nodiscard]] bool commit(std::string& error);
  // Bytes free for this process (statvfs f_bavail), and the file system's block size.
  [[nodiscard]] std::uint64_t free_bytes() const;
  [[nodiscard]] std::uint64_t block_bytes() const;

 private:
  void release();
  std::string path_;
  int dir_fd_ = -1;
  int lock_fd_ = -1;
  dev_t device_ = 0;
  ino_t inode_ = 0;
};

}  // namespace plinth::firmware
