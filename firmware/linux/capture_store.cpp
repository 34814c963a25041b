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
#include <sstream>
#include <string_view>

namespace plinth::firmware {

namespace fs = std::filesystem;

namespace {

constexpr std::string_view kPartialSuffix = ".partial";

// The index of "event-<digits>.<extension>" (extension "log" or "json"), or -1. (No std::regex:
// GCC 12 warns falsely inside it under the sanitize preset.)
int capture_index(std::string_view name, std::string& extension) {
  constexpr std::string_view kPrefix = "event-";
  if (name.substr(0, kPrefix.size()) != kPrefix) return -1;
  const std::size_t dot = name.find('.', kPrefix.size());
  if (dot == std::string_view::npos) return -1;
  const std::string_view digits = name.substr(kPrefix.size(), dot - kPrefix.size());
  const std::string_view ext = name.substr(dot + 1);
  if (digits.empty() || digits.size() > 9 || (ext != "log" && ext != "json")) return -1;
  int index = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return -1;
    index = index * 10 + (c - '0');
  }
  extension = std::string(ext);
  return index;
}

// True when the capture's JSON says it reached the alarm level: "level" (the trigger's) or
// "highest_level" is "alarm", spaces allowed around the colon.
bool json_says_alarm(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  for (const std::string_view key : {"\"level\"", "\"highest_level\""}) {
    for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + 1)) {
      std::size_t i = at + key.size();
      while (i < text.size() && text[i] == ' ') ++i;
      if (i >= text.size() || text[i] != ':') continue;
      ++i;
      while (i < text.size() && text[i] == ' ') ++i;
      if (text.compare(i, 7, "\"alarm\"") == 0) return true;
    }
  }
  return false;
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
  constexpr std::string_view kSuffix = kPartialSuffix;
  int removed = 0;
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(directory, ec)) {
    // ".event-NNN.log.partial": a capture's name between the dot and the suffix.
    const std::string name = entry.path().filename().string();
    std::string extension;
    if (name.size() > 1 + kSuffix.size() && name[0] == '.' &&
        std::string_view(name).substr(name.size() - kSuffix.size()) == kSuffix &&
        capture_index(std::string_view(name).substr(1, name.size() - 1 - kSuffix.size()),
                      extension) >= 0 &&
        fs::remove(entry.path(), ec)) {
      ++removed;
    }
  }
  return removed;
}

}  // namespace plinth::firmware
