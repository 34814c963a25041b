#include "capture_store.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>

namespace plinth::firmware {

namespace {

constexpr std::string_view kPrefix = "event-";
constexpr std::string_view kPartialSuffix = ".partial";
constexpr int kMaxIndexDigits = 9;  // kMaxCaptureIndex
constexpr int kStemDigits = 3;      // capture_stem's zero padding

std::string errno_text(const char* what, const std::string& path, int error) {
  return std::string(what) + " " + path + ": " + std::strerror(error);
}

std::string joined(const std::string& folder, std::string_view name) {
  return (std::filesystem::path(folder) / std::string(name)).string();
}

// True when the summary says the capture reached the alarm level: "level" (the trigger's) or
// "highest_level" is "alarm", spaces allowed around the colon.
bool says_alarm(std::string_view text) {
  for (const std::string_view key : {"\"level\"", "\"highest_level\""}) {
    for (std::size_t at = text.find(key); at != std::string_view::npos;
         at = text.find(key, at + 1)) {
      std::size_t i = at + key.size();
      while (i < text.size() && text[i] == ' ') ++i;
      if (i >= text.size() || text[i] != ':') continue;
      ++i;
      while (i < text.size() && text[i] == ' ') ++i;
      if (text.substr(i, 7) == "\"alarm\"") return true;
    }
  }
  return false;
}

// The number after "continues": in the summary, 0 when none (or not a capture's number).
std::uint64_t continued_index(std::string_view text) {
  constexpr std::string_view kKey = "\"continues\"";
  const std::size_t at = text.find(kKey);
  if (at == std::string_view::npos) return 0;
  std::size_t i = at + kKey.size();
  while (i < text.size() && text[i] == ' ') ++i;
  if (i >= text.size() || text[i] != ':') return 0;
  ++i;
  while (i < text.size() && text[i] == ' ') ++i;
  std::uint64_t value = 0;
  int digits = 0;
  for (; i < text.size() && text[i] >= '0' && text[i] <= '9'; ++i) {
    if (++digits > kMaxIndexDigits) return 0;
    value = value * 10 + static_cast<std::uint64_t>(text[i] - '0');
  }
  return value;
}

WriteOutcome outcome_of(int error) {
  return error == ENOSPC || error == EDQUOT ? WriteOutcome::kNoSpace : WriteOutcome::kFailed;
}

// The newest alarm capture and the pieces it continues: retention never deletes them.
std::set<std::uint64_t> kept_always(const std::vector<CaptureOnDisk>& captures) {
  std::map<std::uint64_t, const CaptureOnDisk*> by_index;
  const CaptureOnDisk* newest_alarm = nullptr;
  for (const CaptureOnDisk& c : captures) {
    by_index[c.index] = &c;
    if (c.alarm && (newest_alarm == nullptr || c.index > newest_alarm->index)) newest_alarm = &c;
  }
  std::set<std::uint64_t> kept;
  // Back along "continues", to lower numbers only: a planted loop ends.
  for (const CaptureOnDisk* c = newest_alarm; c != nullptr;) {
    kept.insert(c->index);
    const auto previous = by_index.find(c->continues);
    c = c->continues < c->index && previous != by_index.end() ? previous->second : nullptr;
  }
  return kept;
}

std::uint64_t rounded_up(std::uint64_t bytes, std::uint64_t block) {
  return block == 0 ? bytes : (bytes + block - 1) / block * block;
}

}  // namespace

std::uint64_t capture_index(std::string_view name, std::string* extension) {
  if (name.substr(0, kPrefix.size()) != kPrefix) return 0;
  const std::size_t dot = name.find('.', kPrefix.size());
  if (dot == std::string_view::npos) return 0;
  const std::string_view digits = name.substr(kPrefix.size(), dot - kPrefix.size());
  const std::string_view ext = name.substr(dot + 1);
  if (ext != "log" && ext != "json") return 0;
  // As capture_stem writes them: "007", "1234"; never "0007" nor "12": one capture one name.
  if (digits.size() < static_cast<std::size_t>(kStemDigits) ||
      digits.size() > static_cast<std::size_t>(kMaxIndexDigits) ||
      (digits.size() > static_cast<std::size_t>(kStemDigits) && digits.front() == '0')) {
    return 0;
  }
  std::uint64_t index = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return 0;
    index = index * 10 + static_cast<std::uint64_t>(c - '0');
  }
  if (index == 0) return 0;
  if (extension != nullptr) *extension = std::string(ext);
  return index;
}

std::string capture_stem(std::uint64_t index) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "event-%03llu", static_cast<unsigned long long>(index));
  return stem;
}

std::uint64_t next_capture_index(const std::vector<CaptureOnDisk>& captures) {
  std::uint64_t highest = 0;
  for (const CaptureOnDisk& c : captures) highest = std::max(highest, c.index);
  return highest + 1;
}

std::vector<std::uint64_t> captures_to_delete(const std::vector<CaptureOnDisk>& captures,
                                              const RetentionLimits& limits) {
  std::uint64_t count = captures.size();
  std::uint64_t bytes = 0;
  for (const CaptureOnDisk& c : captures) bytes += c.bytes;
  const std::set<std::uint64_t> kept = kept_always(captures);
  const auto over = [&] {
    return (limits.max_captures > 0 && count > limits.max_captures) ||
           (limits.max_bytes > 0 && bytes > limits.max_bytes);
  };
  std::vector<std::uint64_t> doomed;
  // Two passes, oldest first: below alarm, then alarm captures but the newest.
  for (const bool alarm_pass : {false, true}) {
    for (const CaptureOnDisk& c : captures) {
      if (!over()) return doomed;
      if (c.alarm != alarm_pass || kept.count(c.index) > 0) continue;
      doomed.push_back(c.index);
      --count;
      bytes -= c.bytes;
    }
  }
  return doomed;
}

std::vector<std::uint64_t> captures_to_make_room(const std::vector<CaptureOnDisk>& captures,
                                                 std::uint64_t bytes, bool for_alarm,
                                                 std::uint64_t block_bytes) {
  const std::set<std::uint64_t> kept = kept_always(captures);
  std::vector<std::uint64_t> doomed;
  std::uint64_t freed = 0;
  for (const bool alarm_pass : {false, true}) {
    if (alarm_pass && !for_alarm) break;
    for (const CaptureOnDisk& c : captures) {
      if (freed >= bytes) return doomed;
      if (c.alarm != alarm_pass || kept.count(c.index) > 0) continue;
      doomed.push_back(c.index);
      freed += rounded_up(c.bytes, block_bytes);
    }
  }
  if (freed < bytes) doomed.clear();
  return doomed;
}

void CaptureFolder::release() {
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock
  if (dir_fd_ >= 0) ::close(dir_fd_);
  lock_fd_ = dir_fd_ = -1;
}

RecorderProblem CaptureFolder::open(std::string& error) {
  release();
  std::error_code ec;
  std::filesystem::create_directories(path_, ec);
  const int dir = ::open(path_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir < 0) {
    error = ec ? "cannot create the folder " + path_ + ": " + ec.message()
               : errno_text("cannot open the folder", path_, errno);
    return RecorderProblem::kFolderMissing;
  }
  struct stat st {};
  (void)::fstat(dir, &st);
  const std::string lock_path = joined(path_, kFolderLockName);
  // O_NOFOLLOW: a symlink planted as the lock file is refused, never followed; O_NONBLOCK: a
  // FIFO planted there does not hang the open. Held read-only (flock needs no more): the box
  // keeps no file open for writing between captures, so the file system can be remounted
  // read-only under it.
  const int lock = ::openat(dir, kFolderLockName,
                            O_RDONLY | O_CREAT | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC, 0644);
  const int open_error = errno;
  const auto fail = [&](RecorderProblem problem, std::string text) {
    if (lock >= 0) ::close(lock);
    ::close(dir);
    error = std::move(text);
    return problem;
  };
  if (lock < 0) {
    if (open_error == EROFS || open_error == EACCES || open_error == EPERM) {
      return fail(RecorderProblem::kNotWritable,
                  errno_text("cannot create files in", path_, open_error));
    }
    if (open_error == ENOSPC || open_error == EDQUOT) {
      return fail(RecorderProblem::kDiskFull, errno_text("cannot create", lock_path, open_error));
    }
    return fail(RecorderProblem::kLockFile,
                errno_text("cannot open the lock file", lock_path, open_error) +
                    (open_error == ELOOP ? " (a symlink, not followed)" : ""));
  }
  struct stat lock_stat {};
  if (::fstat(lock, &lock_stat) != 0 || !S_ISREG(lock_stat.st_mode)) {
    return fail(RecorderProblem::kLockFile,
                "the lock file " + lock_path + " is not a regular file (remove it)");
  }
  if (::flock(lock, LOCK_EX | LOCK_NB) != 0) {
    if (errno != EWOULDBLOCK) {
      return fail(RecorderProblem::kLockFile, errno_text("cannot lock", lock_path, errno));
    }
    // The holder's pid, digits only (the file is anyone's to write).
    char text[24] = {};
    const ssize_t n = ::pread(lock, text, sizeof text - 1, 0);
    std::string pid;
    for (ssize_t i = 0; i < n && text[i] >= '0' && text[i] <= '9'; ++i) pid += text[i];
    return fail(RecorderProblem::kFolderInUse,
                path_ + " is in use by another plinth-monitor (" +
                    (pid.empty() ? std::string("its pid unknown") : "pid " + pid) + ", holding " +
                    lock_path + "): give each box its own --record-dir");
  }
  if (::faccessat(dir, ".", W_OK | X_OK, AT_EACCESS) != 0) {
    return fail(RecorderProblem::kNotWritable, errno_text("cannot create files in", path_, errno));
  }
  // Its pid, for a second box's message (best effort: a full disk may refuse even that).
  const std::string pid = std::to_string(::getpid()) + "\n";
  const int note =
      ::openat(dir, kFolderLockName, O_WRONLY | O_TRUNC | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (note >= 0) {
    (void)!::write(note, pid.data(), pid.size());
    ::close(note);
  }
  dir_fd_ = dir;
  lock_fd_ = lock;
  device_ = st.st_dev;
  inode_ = st.st_ino;
  return RecorderProblem::kNone;
}

RecorderProblem CaptureFolder::check(std::string& error, bool& recreated) {
  recreated = false;
  if (dir_fd_ < 0) return open(error);
  struct stat held {};
  struct stat now {};
  const bool gone = ::fstat(dir_fd_, &held) != 0 || held.st_nlink == 0 ||
                    ::stat(path_.c_str(), &now) != 0 || now.st_dev != device_ ||
                    now.st_ino != inode_;
  if (gone) {
    const RecorderProblem problem = open(error);
    recreated = problem == RecorderProblem::kNone;
    return problem;
  }
  if (::faccessat(dir_fd_, ".", W_OK | X_OK, AT_EACCESS) != 0) {
    error = errno_text("cannot create files in", path_, errno);
    return RecorderProblem::kNotWritable;
  }
  return RecorderProblem::kNone;
}

std::vector<CaptureOnDisk> CaptureFolder::scan() const {
  std::map<std::uint64_t, CaptureOnDisk> found;
  const int fd = dir_fd_ < 0 ? -1 : ::openat(dir_fd_, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  DIR* dir = fd < 0 ? nullptr : ::fdopendir(fd);
  if (dir == nullptr) {
    if (fd >= 0) ::close(fd);
    return {};
  }
  std::string summary;
  while (const dirent* entry = ::readdir(dir)) {
    std::string extension;
    const std::uint64_t index = capture_index(entry->d_name, &extension);
    struct stat st {};
    if (index == 0 || ::fstatat(dir_fd_, entry->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 ||
        !S_ISREG(st.st_mode)) {
      continue;
    }
    CaptureOnDisk& c = found[index];
    c.index = index;
    c.bytes += static_cast<std::uint64_t>(st.st_size);
    if (extension != "json") continue;
    const int file =
        ::openat(dir_fd_, entry->d_name, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (file < 0) continue;
    struct stat opened {};
    summary.assign(kMaxSummaryBytes, '\0');
    ssize_t n = 0;
    if (::fstat(file, &opened) == 0 && S_ISREG(opened.st_mode)) {
      n = ::read(file, summary.data(), summary.size());
    }
    ::close(file);
    summary.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
    c.alarm = says_alarm(summary);
    c.continues = continued_index(summary);
  }
  ::closedir(dir);
  std::vector<CaptureOnDisk> out;
  out.reserve(found.size());
  for (const auto& [index, c] : found) out.push_back(c);
  return out;
}

int CaptureFolder::remove_partial_files(int* completed) {
  const int fd = dir_fd_ < 0 ? -1 : ::openat(dir_fd_, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  DIR* dir = fd < 0 ? nullptr : ::fdopendir(fd);
  if (dir == nullptr) {
    if (fd >= 0) ::close(fd);
    return 0;
  }
  std::vector<std::string> partial;  // the final names
  while (const dirent* entry = ::readdir(dir)) {
    // ".event-NNN.log.partial": a capture's name between the dot and the suffix.
    const std::string_view name = entry->d_name;
    if (name.size() > 1 + kPartialSuffix.size() && name[0] == '.' &&
        name.substr(name.size() - kPartialSuffix.size()) == kPartialSuffix &&
        capture_index(name.substr(1, name.size() - 1 - kPartialSuffix.size())) != 0) {
      partial.emplace_back(name.substr(1, name.size() - 1 - kPartialSuffix.size()));
    }
  }
  ::closedir(dir);
  int removed = 0;
  for (const std::string& name : partial) {
    std::string extension;
    const std::string stem = capture_stem(capture_index(name, &extension));
    struct stat log {};
    const bool log_published = ::fstatat(dir_fd_, (stem + ".log").c_str(), &log,
                                         AT_SYMLINK_NOFOLLOW) == 0 &&
                               S_ISREG(log.st_mode);
    std::string error;
    if (extension == "json" && log_published && !taken(name) &&
        publish(name, error) == WriteOutcome::kWritten) {
      if (completed != nullptr) ++*completed;
      continue;
    }
    discard_partial(name);
    ++removed;
  }
  return removed;
}

bool CaptureFolder::taken(std::string_view name) const {
  struct stat st {};
  const std::string n(name);
  return ::fstatat(dir_fd_, n.c_str(), &st, AT_SYMLINK_NOFOLLOW) == 0 || errno != ENOENT;
}

namespace {

std::string partial_name_of(std::string_view name) {
  std::string partial(".");  // appended: GCC 12 warns falsely on "." + std::string
  partial.append(name).append(kPartialSuffix);
  return partial;
}

}  // namespace

WriteOutcome CaptureFolder::write_partial(std::string_view name, std::string_view text,
                                          std::string& error,
                                          const std::function<void()>& halfway) {
  const std::string partial_name = partial_name_of(name);
  const std::string partial_path = joined(path_, partial_name);
  if (dir_fd_ < 0) {
    error = "the folder " + path_ + " is not open";
    return WriteOutcome::kFailed;
  }
  constexpr int kCreate = O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC;
  int fd = ::openat(dir_fd_, partial_name.c_str(), kCreate, 0644);
  if (fd < 0 && errno == EEXIST) {
    // A stale partial file, or anything planted under its name: removed (a symlink itself,
    // never its target), then created afresh.
    (void)::unlinkat(dir_fd_, partial_name.c_str(), 0);
    fd = ::openat(dir_fd_, partial_name.c_str(), kCreate, 0644);
  }
  if (fd < 0) {
    const int e = errno;
    error = errno_text("cannot create", partial_path, e);
    return outcome_of(e);
  }
  WriteOutcome outcome = WriteOutcome::kWritten;
  const auto failed = [&](const char* what, int e) {
    error = errno_text(what, partial_path, e);
    outcome = outcome_of(e);
  };
  std::size_t done = 0;
  while (outcome == WriteOutcome::kWritten && done < text.size()) {
    std::size_t end = text.size();
    if (halfway && done < text.size() / 2) end = text.size() / 2;
    const ssize_t n = ::write(fd, text.data() + done, end - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      failed("cannot write", n < 0 ? errno : EIO);
    } else {
      done += static_cast<std::size_t>(n);
      if (halfway && done == text.size() / 2) halfway();
    }
  }
  if (outcome == WriteOutcome::kWritten && ::fsync(fd) != 0) failed("cannot flush", errno);
  if (::close(fd) != 0 && outcome == WriteOutcome::kWritten) failed("cannot close", errno);
  if (outcome != WriteOutcome::kWritten) (void)::unlinkat(dir_fd_, partial_name.c_str(), 0);
  return outcome;
}

WriteOutcome CaptureFolder::publish(std::string_view name, std::string& error) {
  const std::string final_name(name);
  const std::string partial_name = partial_name_of(name);
  if (dir_fd_ < 0) {
    error = "the folder " + path_ + " is not open";
    return WriteOutcome::kFailed;
  }
  int e = ::renameat2(dir_fd_, partial_name.c_str(), dir_fd_, final_name.c_str(),
                      RENAME_NOREPLACE) == 0
              ? 0
              : errno;
  const bool renamed = e == 0;
  if (e == EINVAL || e == ENOSYS) {  // a file system without RENAME_NOREPLACE: link, unlink
    e = ::linkat(dir_fd_, partial_name.c_str(), dir_fd_, final_name.c_str(), 0) == 0 ? 0 : errno;
  }
  // Gone on failure; after a link (not a rename), the second name.
  if (!renamed) (void)::unlinkat(dir_fd_, partial_name.c_str(), 0);
  if (e == EEXIST) {
    error = joined(path_, final_name) + " exists: not written over";
    return WriteOutcome::kNameTaken;
  }
  if (e != 0) {
    error = errno_text("cannot rename to", joined(path_, final_name), e);
    return outcome_of(e);
  }
  return WriteOutcome::kWritten;
}

void CaptureFolder::discard_partial(std::string_view name) { remove(partial_name_of(name)); }

WriteOutcome CaptureFolder::write_whole(std::string_view name, std::string_view text,
                                        std::string& error, const std::function<void()>& halfway) {
  const WriteOutcome written = write_partial(name, text, error, halfway);
  return written == WriteOutcome::kWritten ? publish(name, error) : written;
}

void CaptureFolder::remove_capture(std::uint64_t index) {
  const std::string stem = capture_stem(index);
  remove(stem + ".log");
  remove(stem + ".json");
}

void CaptureFolder::remove(std::string_view name) {
  if (dir_fd_ < 0) return;
  (void)::unlinkat(dir_fd_, std::string(name).c_str(), 0);
}

bool CaptureFolder::commit(std::string& error) {
  if (dir_fd_ >= 0 && ::fsync(dir_fd_) == 0) return true;
  error = errno_text("cannot flush", path_, dir_fd_ < 0 ? EBADF : errno);
  return false;
}

std::uint64_t CaptureFolder::free_bytes() const {
  struct statvfs vfs {};
  if (dir_fd_ < 0 || ::fstatvfs(dir_fd_, &vfs) != 0) return 0;
  return static_cast<std::uint64_t>(vfs.f_bavail) * static_cast<std::uint64_t>(vfs.f_frsize);
}

std::uint64_t CaptureFolder::block_bytes() const {
  struct statvfs vfs {};
  if (dir_fd_ < 0 || ::fstatvfs(dir_fd_, &vfs) != 0 || vfs.f_bsize == 0) return 4096;
  return static_cast<std::uint64_t>(vfs.f_bsize);
}

}  // namespace plinth::firmware
