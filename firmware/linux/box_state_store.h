// The box's memory across restarts (docs/safety.md, "Memory across restarts"): the latched
// level, its cause and a collapse seen, kept in the state directory's alarm-state.json and
// written atomically (a temporary file, fsync, rename, fsync of the folder), so that a reset, a
// crash or a power cut leaves either the old state or the new, never a torn one.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "plinth/firmware/monitor.h"

namespace plinth::firmware {

// What the file holds: the monitor's memory, when it was saved and when the collapse was seen
// (wall clock, ns since 1970; 0: unknown).
struct SavedBoxState {
  BoxMemory memory;
  std::int64_t saved_wall_ns = 0;
  std::int64_t collapse_wall_ns = 0;
};

// The state's JSON (one object, every member named in docs/safety.md) and its reading, which
// refuses anything else with a message naming the member at fault.
[[nodiscard]] std::string box_state_json(const SavedBoxState& state);
struct BoxStateParse {
  std::optional<SavedBoxState> state;  // empty: refused
  std::string error;
};
[[nodiscard]] BoxStateParse parse_box_state(const std::string& text);

class BoxStateStore {
 public:
  inline static const char* const kFileName = "alarm-state.json";

  // The state directory: created if missing (mode 0750), checked writable by a write of the
  // state itself. Throws host::InputError naming the directory and the reason.
  explicit BoxStateStore(std::string directory);

  // What the folder held at start: nothing (a first start), the state, or, for a file that
  // cannot be read or trusted, the worst it may have said: a latched alarm (`unreadable` says
  // why; the file is kept beside as alarm-state.json.unreadable for a person to read).
  [[nodiscard]] const std::optional<SavedBoxState>& loaded() const { return loaded_; }
  [[nodiscard]] const std::string& unreadable() const { return unreadable_; }

  // Writes the monitor's memory when it differs from the last one written. False when the write
  // failed (error() says why; the next call tries again).
  bool save(const BoxMemory& memory, std::int64_t wall_ns);
  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] std::uint64_t writes() const { return writes_; }
  [[nodiscard]] std::uint64_t write_errors() const { return write_errors_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  bool write(const SavedBoxState& state);

  std::string directory_;
  std::string path_;
  std::optional<SavedBoxState> loaded_;
  std::string unreadable_;
  std::optional<SavedBoxState> written_;
  std::string error_;
  std::uint64_t writes_ = 0;
  std::uint64_t write_errors_ = 0;
};

}  // namespace plinth::firmware
