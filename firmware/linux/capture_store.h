// The event recorder's folder (docs/monitor.md, "Event recorder"): what captures it holds, the
// next capture's number (after the highest present, so a restarted box never writes over an
// earlier capture), files written whole or not at all (a temporary name, fsync, rename, fsync of
// the folder), and the retention limit (oldest captures below the alarm level deleted first,
// the newest alarm capture never). Host code: allocates and throws; used off the real-time loop
// (at start-up and by the recorder's writer thread).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace plinth::firmware {

// [recorder] of the box's file: how much the folder keeps; 0: no limit.
struct RetentionLimits {
  std::uint64_t max_captures = 0;  // recorder.max_captures: captures (a .log with its .json)
  std::uint64_t max_bytes = 0;     // recorder.max_bytes: bytes of all captures together
};

// One capture in the folder: event-<index>.log and its summary event-<index>.json.
struct CaptureOnDisk {
  int index = 0;
  bool alarm = false;       // it reached the alarm level (its JSON says so)
  std::uint64_t bytes = 0;  // both files
};

// The captures in `directory`, by index. A .json without its .log, or the reverse, is one
// capture all the same (a capture written by an older plinth, or half removed by hand); a JSON
// that cannot be read counts as below alarm. Files that are not captures are left alone.
[[nodiscard]] std::vector<CaptureOnDisk> scan_captures(const std::string& directory);

// The index after the highest of `captures` (1 for none).
[[nodiscard]] int next_capture_index(const std::vector<CaptureOnDisk>& captures);

// The indices to delete so that `captures` (sorted by index, the newest last) keep within
// `limits`: the oldest captures below alarm first, then the oldest alarm captures, never the
// newest alarm capture (the folder may stay over its limit for that one alone).
[[nodiscard]] std::vector<int> captures_to_delete(const std::vector<CaptureOnDisk>& captures,
                                                  const RetentionLimits& limits);

// "event-007": the stem of a capture's files (at least three digits).
[[nodiscard]] std::string capture_stem(int index);

// Writes `text` to `directory`/`name` whole or not at all: into ".name.partial" first, flushed
// to disk (fsync), then renamed; the folder is fsynced by commit_folder(). False, with `error`
// set, when any step failed (the partial file is removed). `halfway`, when set, runs with half
// the text written (a test's pause: the recorder's test_pause_mid_write_s).
[[nodiscard]] bool write_file_whole(const std::string& directory, std::string_view name,
                                    std::string_view text, std::string& error,
                                    const std::function<void()>& halfway = {});
// fsync of the folder: the renames above survive a power cut.
[[nodiscard]] bool commit_folder(const std::string& directory, std::string& error);

// Removes partial files (".event-*.partial") left by a process killed while writing; returns
// how many.
int remove_partial_files(const std::string& directory);

}  // namespace plinth::firmware
