#include "box_state_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>
#include <vector>

#include "plinth/host/input_error.h"
#include "plinth/version/version.h"

namespace plinth::firmware {

namespace {

using nlohmann::json;
namespace mon = monitor;

constexpr const char* kFormat = "plinth-alarm-state 1";

bool same(const BoxMemory& a, const BoxMemory& b) {
  return a.alarm.latched_level == b.alarm.latched_level &&
         a.alarm.latched_cause == b.alarm.latched_cause &&
         a.alarm.collapse_held == b.alarm.collapse_held &&
         a.alarm.next_sequence == b.alarm.next_sequence && a.collapse.held == b.collapse.held &&
         a.collapse.axis == b.collapse.axis && a.collapse.mode.phase == b.collapse.mode.phase &&
         a.collapse.mode.corner == b.collapse.mode.corner;
}

// The worst a state that cannot be read may have said: a latched alarm (acknowledged by a
// person, as any other).
SavedBoxState worst_state() {
  SavedBoxState s;
  s.memory.alarm.latched_level = mon::AlarmLevel::kAlarm;
  s.memory.alarm.latched_cause = mon::AlarmCause::kRestored;
  return s;
}

std::string errno_text(int error) { return std::strerror(error); }

// Parses `text` as JSON, refusing an object with a member twice (a reader that takes the first
// and one that takes the last would see two states).
json parse_unique(const std::string& text, std::string& error) {
  std::vector<std::set<std::string>> keys;
  const json::parser_callback_t unique = [&](int, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    if (event == json::parse_event_t::key && !keys.empty() &&
        !keys.back().insert(parsed.get<std::string>()).second && error.empty()) {
      error = "member \"" + parsed.get<std::string>() + "\" twice";
    }
    return true;
  };
  return json::parse(text, unique, false);
}

template <typename Table>
bool name_of(const json& value, const Table& table, typename Table::value_type& out) {
  return value.is_string() && table.parse(value.get<std::string>(), out);
}

bool integer_in(const json& value, std::int64_t low, std::int64_t high, std::int64_t& out) {
  if (!value.is_number_integer()) return false;
  out = value.get<std::int64_t>();
  return out >= low && out <= high;
}

}  // namespace

std::string box_state_json(const SavedBoxState& state) {
  const BoxMemory& m = state.memory;
  json j;
  j["format"] = kFormat;
  j["version"] = std::string(plinth::version::kVersionText);
  j["saved_wall_ns"] = state.saved_wall_ns;
  j["latched_level"] = mon::alarm_level_name(m.alarm.latched_level);
  j["latched_cause"] = mon::alarm_cause_name(m.alarm.latched_cause);
  j["next_sequence"] = m.alarm.next_sequence;
  json collapse;
  collapse["held"] = m.alarm.collapse_held;
  collapse["axis"] = m.collapse.axis;
  collapse["phase"] = phase_name(m.collapse.mode.phase);
  collapse["corner"] = corner_name(m.collapse.mode.corner);
  collapse["seen_wall_ns"] = state.collapse_wall_ns;
  j["collapse"] = collapse;
  return j.dump(2) + "\n";
}

BoxStateParse parse_box_state(const std::string& text) {
  BoxStateParse r;
  std::string duplicate;
  const json j = parse_unique(text, duplicate);
  const auto refuse = [&r](const std::string& why) {
    r.error = why;
    return r;
  };
  if (j.is_discarded()) return refuse("not JSON");
  if (!duplicate.empty()) return refuse(duplicate);
  if (!j.is_object()) return refuse("expected a JSON object");
  static const std::set<std::string> kMembers{"format",        "version",       "saved_wall_ns",
                                              "latched_level", "latched_cause", "next_sequence",
                                              "collapse"};
  static const std::set<std::string> kCollapseMembers{"held", "axis", "phase", "corner",
                                                      "seen_wall_ns"};
  for (const auto& [key, value] : j.items()) {
    if (kMembers.count(key) == 0) return refuse("unknown member \"" + key + "\"");
  }
  for (const char* key : {"format", "latched_level", "latched_cause", "next_sequence",
                          "collapse", "saved_wall_ns"}) {
    if (!j.contains(key)) return refuse(std::string("no member \"") + key + "\"");
  }
  if (j["format"] != kFormat) return refuse(std::string("format: expected \"") + kFormat + "\"");
  SavedBoxState s;
  BoxMemory& m = s.memory;
  if (!name_of(j["latched_level"], mon::kAlarmLevelNames, m.alarm.latched_level) ||
      m.alarm.latched_level == mon::AlarmLevel::kAdvisory ||
      m.alarm.latched_level == mon::AlarmLevel::kFault) {
    return refuse("latched_level: expected \"normal\", \"warning\" or \"alarm\"");
  }
  if (!name_of(j["latched_cause"], mon::kAlarmCauseNames, m.alarm.latched_cause)) {
    return refuse("latched_cause: not a cause's name (docs/monitor.md)");
  }
  std::int64_t n = 0;
  if (!integer_in(j["next_sequence"], 0, 255, n)) return refuse("next_sequence: expected 0..255");
  m.alarm.next_sequence = static_cast<std::uint8_t>(n);
  if (!integer_in(j["saved_wall_ns"], 0, INT64_MAX, s.saved_wall_ns)) {
    return refuse("saved_wall_ns: expected an integer >= 0");
  }
  const json& c = j["collapse"];
  if (!c.is_object()) return refuse("collapse: expected an object");
  for (const auto& [key, value] : c.items()) {
    if (kCollapseMembers.count(key) == 0) return refuse("collapse: unknown member \"" + key + "\"");
  }
  for (const char* key : {"held", "axis", "phase", "corner", "seen_wall_ns"}) {
    if (!c.contains(key)) return refuse(std::string("collapse: no member \"") + key + "\"");
  }
  if (!c["held"].is_boolean()) return refuse("collapse.held: expected true or false");
  m.alarm.collapse_held = c["held"].get<bool>();
  m.collapse.held = m.alarm.collapse_held;
  if (!integer_in(c["axis"], 0, kMaxAxes - 1, n)) return refuse("collapse.axis: expected 0 or 1");
  m.collapse.axis = static_cast<int>(n);
  if (!name_of(c["phase"], kPhaseNames, m.collapse.mode.phase)) {
    return refuse("collapse.phase: not a phase's name");
  }
  if (m.collapse.held && !m.collapse.mode.collapsed()) {
    return refuse("collapse.phase: a held collapse must be \"overturned\" or \"fell\"");
  }
  if (!name_of(c["corner"], kCornerNames, m.collapse.mode.corner)) {
    return refuse("collapse.corner: expected \"left\" or \"right\"");
  }
  if (!integer_in(c["seen_wall_ns"], 0, INT64_MAX, s.collapse_wall_ns)) {
    return refuse("collapse.seen_wall_ns: expected an integer >= 0");
  }
  r.state = s;
  return r;
}

BoxStateStore::BoxStateStore(std::string directory)
    : directory_(std::move(directory)), path_(directory_ + "/" + kFileName) {
  if (directory_.empty()) throw host::InputError("--state-dir: empty path");
  if (::mkdir(directory_.c_str(), 0750) != 0 && errno != EEXIST) {
    throw host::InputError("--state-dir " + directory_ + ": cannot create: " + errno_text(errno));
  }
  struct stat st {};
  if (::lstat(directory_.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    throw host::InputError("--state-dir " + directory_ + ": not a directory");
  }
  const int fd = ::open(path_.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0 && errno != ENOENT) {
    unreadable_ = path_ + ": cannot open: " + errno_text(errno);
  } else if (fd >= 0) {
    std::string text;
    char buffer[4096];
    ssize_t got = 0;
    while ((got = ::read(fd, buffer, sizeof buffer)) > 0 && text.size() < 65536) {
      text.append(buffer, static_cast<std::size_t>(got));
    }
    const int read_error = got < 0 ? errno : 0;
    ::close(fd);
    if (read_error != 0) {
      unreadable_ = path_ + ": cannot read: " + errno_text(read_error);
    } else if (text.size() >= 65536) {
      unreadable_ = path_ + ": larger than 64 KiB";
    } else {
      BoxStateParse parsed = parse_box_state(text);
      if (parsed.state) {
        loaded_ = parsed.state;
      } else {
        unreadable_ = path_ + ": " + parsed.error;
      }
    }
  }
  if (!unreadable_.empty()) {
    loaded_ = worst_state();
    const std::string aside = path_ + ".unreadable";
    if (::rename(path_.c_str(), aside.c_str()) == 0) unreadable_ += " (kept as " + aside + ")";
  }
  // Writable, checked by writing what holds now.
  const SavedBoxState now = loaded_.value_or(SavedBoxState{});
  if (!write(now)) throw host::InputError("--state-dir " + directory_ + ": " + error_);
}

bool BoxStateStore::save(const BoxMemory& memory, std::int64_t wall_ns) {
  if (written_ && same(written_->memory, memory)) return true;
  SavedBoxState s;
  s.memory = memory;
  s.saved_wall_ns = wall_ns;
  // The collapse's wall time: kept from when it was first written held.
  const bool held_before = written_ && written_->memory.alarm.collapse_held;
  s.collapse_wall_ns = !memory.alarm.collapse_held ? 0
                       : held_before               ? written_->collapse_wall_ns
                                                   : wall_ns;
  return write(s);
}

bool BoxStateStore::write(const SavedBoxState& state) {
  const std::string text = box_state_json(state);
  const std::string temporary = directory_ + "/." + kFileName + ".tmp";
  const auto fail = [this](const std::string& what) {
    error_ = what + ": " + errno_text(errno);
    ++write_errors_;
    return false;
  };
  ::unlink(temporary.c_str());  // a leftover, or a planted link: never followed (O_EXCL)
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                        0640);
  if (fd < 0) return fail(temporary + ": cannot create");
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ::close(fd);
      ::unlink(temporary.c_str());
      return fail(temporary + ": cannot write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    ::unlink(temporary.c_str());
    return fail(temporary + ": cannot sync");
  }
  ::close(fd);
  if (::rename(temporary.c_str(), path_.c_str()) != 0) {
    ::unlink(temporary.c_str());
    return fail(path_ + ": cannot replace");
  }
  const int dir = ::open(directory_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    (void)::fsync(dir);  // the rename itself on disk
    ::close(dir);
  }
  written_ = state;
  error_.clear();
  ++writes_;
  return true;
}

}  // namespace plinth::firmware
