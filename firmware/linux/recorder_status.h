// The event recorder's health as the status line, the summary, Modbus and MQTT show it
// (docs/monitor.md, "Event recorder"; event_recorder.h keeps it).
#pragma once

#include <cstdint>

#include "plinth/core/name_table.h"

namespace plinth::firmware {

enum class RecorderHealth : std::uint8_t {
  kOk,        // every capture so far is on disk whole, and the folder can take the next one
  kDegraded,  // the folder can take the next capture, but a capture was lost or cut short
  kFailed,    // the folder cannot take a capture now (the problem says why)
};
inline constexpr NameTable<RecorderHealth, 3> kRecorderHealthNames{{{
    {RecorderHealth::kOk, "ok"},
    {RecorderHealth::kDegraded, "degraded"},
    {RecorderHealth::kFailed, "failed"},
}}};

// Why the recorder is failed; when degraded, what its latest loss was.
enum class RecorderProblem : std::uint8_t {
  kNone,
  kFolderMissing,       // the folder cannot be created or opened
  kNotWritable,         // no file can be created in it (a read-only mount, permissions)
  kFolderInUse,         // another plinth-monitor holds its lock: one box a folder
  kLockFile,            // its lock file is not a regular file (something planted there)
  kDiskFull,            // a capture did not fit and retention could not make room
  kWriteError,          // another error while writing a capture
  kNumberingExhausted,  // a capture numbered kMaxCaptureIndex is in the folder
  kWriterBehind,        // a trigger found both capture buffers busy: its capture is lost
  kTruncated,           // a capture misses frames of its window (the buffers were full)
};
inline constexpr NameTable<RecorderProblem, 10> kRecorderProblemNames{{{
    {RecorderProblem::kNone, "none"},
    {RecorderProblem::kFolderMissing, "folder_missing"},
    {RecorderProblem::kNotWritable, "not_writable"},
    {RecorderProblem::kFolderInUse, "folder_in_use"},
    {RecorderProblem::kLockFile, "lock_file"},
    {RecorderProblem::kDiskFull, "disk_full"},
    {RecorderProblem::kWriteError, "write_error"},
    {RecorderProblem::kNumberingExhausted, "numbering_exhausted"},
    {RecorderProblem::kWriterBehind, "writer_behind"},
    {RecorderProblem::kTruncated, "truncated"},
}}};

// What the outputs show of the recorder; `present` false without --record-dir.
struct RecorderStatus {
  bool present = false;
  RecorderHealth health = RecorderHealth::kOk;
  RecorderProblem problem = RecorderProblem::kNone;
  std::uint64_t captures_written = 0;    // capture files written whole (a long one in pieces)
  std::uint64_t captures_lost = 0;       // captures, or pieces of one, that never reached disk
  std::uint64_t captures_truncated = 0;  // captures on disk that miss frames of their window
  std::uint64_t captures_deleted = 0;    // by retention (limits, or room for a new capture)
};

}  // namespace plinth::firmware
