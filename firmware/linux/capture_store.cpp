#include "capture_store.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

namespace plinth::firmware {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPartialSuffix = ".partial";

// The index of a capture's file name ("event-012.log" -> 12), or -1.
int capture_index(const std::string& name, std::string& extension) {
  static const std::regex kName(R"(event-([0-9]{1,9})\.(log|json))");
  std::smatch m;
  if (!std::regex_match(name, m, kName)) return -1;
  extension = m[2].str();
  return std::stoi(m[1].str());
}

// True when the capture's JSON says it reached the alarm level: "level" (the trigger's) or
// "highest_level" is "alarm".
bool json_says_alarm(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  static const std::regex kAlarm(R"re("(level|highest_level)"\s*:\s*"alarm")re");
  return std::regex_search(text.str(), kAlarm);
}

std::string errno_text(const char* what, const std::string& path) {
  return std::string(what) + " " + path + ": " + std::strerror(errno);
}

}  // namespace

std::vector<CaptureOnDisk> scan_captures(const std::string& directory) {
  std::map<int, CaptureOnDisk> found;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
    std::string extension;
    const int index = capture_index(entry.path().filename().string(), extension);
    if (index < 0 || !entry.is_regular_file(ec)) continue;
    CaptureOnDisk& c = found[index];
    c.index = index;
    const std::uintmax_t size = entry.file_size(ec);
    if (!ec) c.bytes += size;
    if (extension == "json") c.alarm = json_says_alarm(entry.path());
  }
  std::vector<CaptureOnDisk> out;
  out.reserve(found.size());
  for (const auto& [index, c] : found) out.push_back(c);
  return out;
}

int next_capture_index(const std::vector<CaptureOnDisk>& captures) {
  int highest = 0;
  for (const CaptureOnDisk& c : captures) highest = std::max(highest, c.index);
  return highest + 1;
}

std::vector<int> captures_to_delete(const std::vector<CaptureOnDisk>& captures,
                                    const RetentionLimits& limits) {
  std::uint64_t count = captures.size();
  std::uint64_t bytes = 0;
  int newest_alarm = -1;
  for (const CaptureOnDisk& c : captures) {
    bytes += c.bytes;
    if (c.alarm) newest_alarm = std::max(newest_alarm, c.index);
  }
  const auto over = [&] {
    return (limits.max_captures > 0 && count > limits.max_captures) ||
           (limits.max_bytes > 0 && bytes > limits.max_bytes);
  };
  std::vector<int> doomed;
  // Two passes, oldest first: below alarm, then alarm captures but the newest.
  for (const bool alarm_pass : {false, true}) {
    for (const CaptureOnDisk& c : captures) {
      if (!over()) return doomed;
      if (c.alarm != alarm_pass || c.index == newest_alarm) continue;
      doomed.push_back(c.index);
      --count;
      bytes -= c.bytes;
    }
  }
  return doomed;
}

std::string capture_stem(int index) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "event-%03d", index);
  return stem;
}

bool write_file_whole(const std::string& directory, std::string_view name, std::string_view text,
                      std::string& error, const std::function<void()>& halfway) {
  const std::string final_path = (fs::path(directory) / std::string(name)).string();
  std::string partial_name(".");  // appended: GCC 12 warns falsely on "." + std::string
  partial_name.append(name).append(kPartialSuffix);
  const std::string partial_path = (fs::path(directory) / partial_name).string();
  const int fd = ::open(partial_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) {
    error = errno_text("cannot create", partial_path);
    return false;
  }
  std::size_t done = 0;
  bool ok = true;
  while (ok && done < text.size()) {
    std::size_t end = text.size();
    if (halfway && done < text.size() / 2) end = text.size() / 2;
    const ssize_t n = ::write(fd, text.data() + done, end - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      error = errno_text("cannot write", partial_path);
      ok = false;
    } else {
      done += static_cast<std::size_t>(n);
      if (halfway && done == text.size() / 2) halfway();
    }
  }
  if (ok && ::fsync(fd) != 0) {
    error = errno_text("cannot flush", partial_path);
    ok = false;
  }
  if (::close(fd) != 0 && ok) {
    error = errno_text("cannot close", partial_path);
    ok = false;
  }
  if (ok && std::rename(partial_path.c_str(), final_path.c_str()) != 0) {
    error = errno_text("cannot rename to", final_path);
    ok = false;
  }
  if (!ok) ::unlink(partial_path.c_str());
  return ok;
}

bool commit_folder(const std::string& directory, std::string& error) {
  const int fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    error = errno_text("cannot open", directory);
    return false;
  }
  const bool ok = ::fsync(fd) == 0;
  if (!ok) error = errno_text("cannot flush", directory);
  ::close(fd);
  return ok;
}

int remove_partial_files(const std::string& directory) {
  static const std::regex kPartial(R"(\.event-[0-9]+\.(log|json)\.partial)");
  int removed = 0;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
    if (std::regex_match(entry.path().filename().string(), kPartial) &&
        fs::remove(entry.path(), ec)) {
      ++removed;
    }
  }
  return removed;
}

}  // namespace plinth::firmware
