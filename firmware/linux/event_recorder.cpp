#include "event_recorder.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>

#include "plinth/hal/candump_log.h"
#include "plinth/host/input_error.h"

namespace plinth::firmware {

namespace {

// Frames a buffer holds beyond its window at the bound rate (timestamps rounded, a late frame).
constexpr std::size_t kSpareFrames = 16;
// A new name tried this many times when the one chosen is taken meanwhile (planted files).
constexpr int kNameAttempts = 16;
// Bytes of a candump log line (the longest classic one) and its newline, for the room needed.
constexpr std::size_t kLogLineBytes = 48;

std::int64_t seconds_to_ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

std::size_t frames_in(double seconds, double rate_hz) {
  return static_cast<std::size_t>(std::ceil(seconds * rate_hz)) + kSpareFrames;
}

// One line on stderr, "plinth-monitor: event recorder: ...": every loss and every change of the
// folder is said (captures are rare: one a trigger window).
[[gnu::format(printf, 1, 2)]] void say(const char* format, ...) {
  char text[1024];
  va_list args;
  va_start(args, format);
  std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  std::fprintf(stderr, "plinth-monitor: event recorder: %s\n", text);
}

unsigned long long ull(std::uint64_t value) { return static_cast<unsigned long long>(value); }

}  // namespace

EventRecorder::EventRecorder(EventRecorderSettings settings)
    : settings_(std::move(settings)), folder_(settings_.directory) {
  const auto bad = [](const char* what) {
    return host::InputError(std::string("event recorder: ") + what);
  };
  if (!std::isfinite(settings_.pre_trigger_s) || settings_.pre_trigger_s < 0.0 ||
      settings_.pre_trigger_s > 3600.0) {
    throw bad("the pre-trigger window must lie in [0, 3600] s");
  }
  if (!std::isfinite(settings_.post_trigger_s) || settings_.post_trigger_s < 0.0 ||
      settings_.post_trigger_s > 3600.0) {
    throw bad("the post-trigger window must lie in [0, 3600] s");
  }
  if (!std::isfinite(settings_.frame_rate_hz) || settings_.frame_rate_hz <= 0.0 ||
      settings_.frame_rate_hz > 50000.0) {
    throw bad("the frame rate bound must lie in (0, 50000] Hz");
  }
  if (!std::isfinite(settings_.test_pause_mid_write_s) || settings_.test_pause_mid_write_s < 0.0) {
    throw bad("the test pause must be a finite number of seconds >= 0");
  }
  if (!std::isfinite(settings_.folder_check_period_s) || settings_.folder_check_period_s <= 0.0) {
    throw bad("the folder check period must be a positive number of seconds");
  }
  pre_ns_ = seconds_to_ns(settings_.pre_trigger_s);
  post_ns_ = seconds_to_ns(settings_.post_trigger_s);
  ring_.resize(frames_in(settings_.pre_trigger_s, settings_.frame_rate_hz));
  const std::size_t capture_frames =
      frames_in(settings_.pre_trigger_s + settings_.post_trigger_s, settings_.frame_rate_hz);
  for (Capture& c : buffers_) {
    c.frames.reserve(capture_frames);
    free_[free_count_++] = &c;
  }
  std::string error;
  const RecorderProblem problem = folder_.open(error);
  folder_problem_.store(problem);
  if (problem == RecorderProblem::kNone) {
    folder_opened();
  } else {
    say("%s (%s); the box runs, but its captures are lost until the folder can be used (tried "
        "every %g s)",
        error.c_str(), kRecorderProblemNames.name(problem), settings_.folder_check_period_s);
  }
  writer_ = std::thread([this] { writer_loop(); });
}

EventRecorder::~EventRecorder() { close(); }

void EventRecorder::close() {
  flush();
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_one();
  if (writer_.joinable()) writer_.join();
}

RecorderStatus EventRecorder::status() const {
  RecorderStatus s;
  s.present = true;
  s.captures_written = written_.load();
  s.captures_lost = dropped_.load() + write_errors_.load();
  s.captures_truncated = truncated_.load();
  s.captures_deleted = deleted_.load();
  const RecorderProblem folder = folder_problem_.load();
  const RecorderProblem write = write_problem_.load();
  if (folder != RecorderProblem::kNone || write != RecorderProblem::kNone) {
    s.health = RecorderHealth::kFailed;
    s.problem = folder != RecorderProblem::kNone ? folder : write;
  } else if (s.captures_lost > 0 || s.captures_truncated > 0) {
    s.health = RecorderHealth::kDegraded;
    s.problem = latest_loss_.load();
  }
  return s;
}

// ---- Real-time side ----------------------------------------------------------------------------

bool EventRecorder::take_buffer(bool may_wait) {
  // The writer holds the mutex only to move a pointer; while frames find no buffer, they do not
  // even wait for that.
  std::unique_lock lock(mutex_, std::defer_lock);
  if (may_wait) {
    lock.lock();
  } else if (!lock.try_lock()) {
    return false;
  }
  if (free_count_ == 0) return false;
  active_ = free_[--free_count_];
  return true;
}

void EventRecorder::start_piece(bool continuation) {
  Capture& c = *active_;
  c.frames.clear();  // keeps the capacity: no allocation
  c.info = window_info_;
  c.trigger_ns = window_trigger_ns_;
  c.reached_alarm = window_alarm_;
  c.continuation = continuation;
  c.continued = false;
  c.frames_dropped = window_dropped_;
  c.pre_trigger_cut_ns = 0;
  window_dropped_ = 0;
}

void EventRecorder::on_frame(const hal::TimedFrame& frame, std::uint64_t lost_before) {
  const RecordedFrame recorded{frame, lost_before};
  ring_[ring_next_] = recorded;
  ring_next_ = (ring_next_ + 1) % ring_.size();
  if (ring_count_ < ring_.size()) ++ring_count_;
  if (!window_open_) return;
  if (frame.timestamp_ns > window_end_ns_) {
    close_window();
    return;
  }
  // Full: the window goes on in the other buffer. Without a buffer (the writer has both), frames
  // are counted until one is free, without waiting for the writer's mutex.
  const bool full = active_ != nullptr && active_->frames.size() == active_->frames.capacity();
  if (full) hand_over(true);
  if (active_ == nullptr) {
    if (!take_buffer(full)) {
      ++window_dropped_;
      frames_lost_.fetch_add(1);
      wake_.notify_one();
      return;
    }
    start_piece(true);
  }
  active_->frames.push_back(recorded);
}

void EventRecorder::trigger(const TriggerInfo& info, std::int64_t time_ns) {
  if (window_open_) {  // a later trigger within the window: keep recording after it
    window_end_ns_ = time_ns + post_ns_;
    window_alarm_ = window_alarm_ || info.alarm;
    if (active_ != nullptr) active_->reached_alarm = window_alarm_;
    return;
  }
  if (!take_buffer(true)) {  // both buffers busy: the writer is behind
    dropped_.fetch_add(1);
    latest_loss_.store(RecorderProblem::kWriterBehind);
    wake_.notify_one();
    return;
  }
  window_open_ = true;
  window_info_ = info;
  window_trigger_ns_ = time_ns;
  window_end_ns_ = time_ns + post_ns_;
  window_alarm_ = info.alarm;
  window_dropped_ = 0;
  start_piece(false);
  const std::size_t first = (ring_next_ + ring_.size() - ring_count_) % ring_.size();
  const std::int64_t window_start_ns = time_ns - pre_ns_;
  for (std::size_t i = 0; i < ring_count_; ++i) {
    const RecordedFrame& f = ring_[(first + i) % ring_.size()];
    if (f.timed.timestamp_ns >= window_start_ns &&
        active_->frames.size() < active_->frames.capacity()) {
      active_->frames.push_back(f);
    }
  }
  // A full ring whose oldest frame is inside the window has written over the window's start.
  const std::int64_t oldest_ns = ring_[first].timed.timestamp_ns;
  if (ring_count_ == ring_.size() && oldest_ns > window_start_ns) {
    active_->pre_trigger_cut_ns = oldest_ns - window_start_ns;
  }
}

void EventRecorder::flush() {
  if (window_open_) close_window();
}

void EventRecorder::close_window() {
  if (active_ != nullptr) {
    hand_over(false);
  } else if (window_dropped_ > 0) {  // its end found no buffer: the pieces written miss it
    truncated_.fetch_add(1);
    latest_loss_.store(RecorderProblem::kTruncated);
    wake_.notify_one();
  }
  window_open_ = false;
  window_dropped_ = 0;
}

void EventRecorder::hand_over(bool continued) {
  active_->continued = continued;
  active_->reached_alarm = window_alarm_;
  {
    const std::lock_guard lock(mutex_);
    waiting_[waiting_count_++] = active_;  // room: at most two buffers exist
  }
  active_ = nullptr;
  wake_.notify_one();
}

// ---- Writer side -------------------------------------------------------------------------------

std::vector<std::string> EventRecorder::written_paths() {
  const std::lock_guard lock(mutex_);
  return paths_;
}

bool EventRecorder::real_time_losses_unsaid() const {
  return dropped_.load() != said_dropped_ || frames_lost_.load() != said_frames_lost_;
}

void EventRecorder::say_real_time_losses() {
  const std::uint64_t dropped = dropped_.load();
  if (dropped != said_dropped_) {
    say("%llu trigger(s) found both capture buffers busy (the writer is behind): their "
        "captures are lost; %llu lost so far",
        ull(dropped - said_dropped_), ull(dropped + write_errors_.load()));
    said_dropped_ = dropped;
  }
  const std::uint64_t frames = frames_lost_.load();
  if (frames != said_frames_lost_) {
    say("%llu frame(s) of a capture window found no buffer (the writer is behind): the "
        "captures miss them; %llu frames lost so far",
        ull(frames - said_frames_lost_), ull(frames));
    said_frames_lost_ = frames;
  }
}

void EventRecorder::writer_loop() {
  const auto period = std::chrono::duration<double>(settings_.folder_check_period_s);
  auto next_check = std::chrono::steady_clock::now() + period;
  for (;;) {
    Capture* capture = nullptr;
    bool stop = false;
    {
      std::unique_lock lock(mutex_);
      wake_.wait_until(lock, next_check, [this] {
        return waiting_count_ > 0 || stopping_ || real_time_losses_unsaid();
      });
      if (waiting_count_ > 0) {
        capture = waiting_[0];
        waiting_[0] = waiting_[1];
        --waiting_count_;
      } else {
        stop = stopping_;
      }
    }
    say_real_time_losses();
    if (stop) return;
    if (capture != nullptr) {
      write(*capture);  // checks the folder first
      const std::lock_guard lock(mutex_);
      free_[free_count_++] = capture;
    } else if (std::chrono::steady_clock::now() >= next_check) {
      check_folder();
    }
    if (std::chrono::steady_clock::now() >= next_check) {
      next_check = std::chrono::steady_clock::now() + period;
    }
  }
}

void EventRecorder::folder_opened() {
  int completed = 0;
  partial_files_removed_.fetch_add(folder_.remove_partial_files(&completed));
  if (completed > 0) {
    say("%d capture(s) killed between their log's and their summary's final names: completed",
        completed);
  }
  next_index_ = std::max(next_index_, next_capture_index(folder_.scan()));
  if (!wrote_any_) first_index_.store(next_index_ <= kMaxCaptureIndex ? next_index_ : 0);
  if (next_index_ > kMaxCaptureIndex) {
    write_problem_.store(RecorderProblem::kNumberingExhausted);
    say("%s holds %s (a .log or .json), the highest number a capture can have: no capture "
        "can be numbered after it (move it away)",
        folder_.path().c_str(), capture_stem(kMaxCaptureIndex).c_str());
  }
  keep_retention();
}

void EventRecorder::check_folder() {
  std::string error;
  bool recreated = false;
  const bool held = folder_.held();
  const RecorderProblem before = folder_problem_.load();
  const RecorderProblem problem = folder_.check(error, recreated);
  folder_problem_.store(problem);
  if (problem != RecorderProblem::kNone) {
    if (problem != before) {
      say("%s (%s); captures are lost until the folder can be used", error.c_str(),
          kRecorderProblemNames.name(problem));
    }
    return;
  }
  if (recreated || !held) {
    if (recreated) say("%s disappeared: recreated", folder_.path().c_str());
    folder_opened();
  }
  if (before != RecorderProblem::kNone) {
    say("%s can be used again (captures from %s)", folder_.path().c_str(),
        capture_stem(next_index_).c_str());
  }
  // A capture lost to a full disk, or to the numbering: cleared once there is room again.
  const RecorderProblem write = write_problem_.load();
  if (write == RecorderProblem::kDiskFull && folder_.free_bytes() >= room_needed_) {
    write_problem_.store(RecorderProblem::kNone);
    say("%s has room for a capture again", folder_.path().c_str());
  } else if (write == RecorderProblem::kNumberingExhausted) {
    next_index_ = next_capture_index(folder_.scan());
    if (next_index_ <= kMaxCaptureIndex) {
      write_problem_.store(RecorderProblem::kNone);
      say("%s: captures numbered again, from %s", folder_.path().c_str(),
          capture_stem(next_index_).c_str());
    }
  }
}

void EventRecorder::lose(const Capture& c, RecorderProblem problem, const std::string& error) {
  const std::uint64_t lost = write_errors_.fetch_add(1) + 1 + dropped_.load();
  latest_loss_.store(problem);
  if (problem == RecorderProblem::kDiskFull || problem == RecorderProblem::kWriteError ||
      problem == RecorderProblem::kNumberingExhausted) {
    write_problem_.store(problem);
  }
  say("the %s capture at t = %.3f s (%zu frames%s) is lost: %s (%s); %llu lost so far",
      c.reached_alarm ? "alarm" : c.info.level.c_str(), c.info.t, c.frames.size(),
      c.continuation ? ", a continuation" : "", error.c_str(), kRecorderProblemNames.name(problem),
      ull(lost));
}

bool EventRecorder::make_room(std::uint64_t bytes, bool for_alarm) {
  const std::vector<std::uint64_t> doomed =
      captures_to_make_room(folder_.scan(), bytes, for_alarm, folder_.block_bytes());
  for (const std::uint64_t index : doomed) {
    folder_.remove_capture(index);
    deleted_.fetch_add(1);
  }
  if (doomed.empty()) return false;
  std::string error;
  (void)folder_.commit(error);
  const std::string range = doomed.size() == 1 ? capture_stem(doomed.front())
                                                : capture_stem(doomed.front()) + " to " +
                                                      capture_stem(doomed.back());
  say("the disk is full: %zu older capture(s) deleted to make room (%s; %s)", doomed.size(),
      range.c_str(), for_alarm ? "the newest alarm capture kept" : "alarm captures kept");
  return true;
}

WriteOutcome EventRecorder::write_files(const std::string& stem, const std::string& log,
                                        const std::string& json, bool alarm, std::string& error) {
  // Room first: what both files take in whole blocks (and a block for the folder's entries).
  const std::uint64_t block = folder_.block_bytes();
  const auto blocks = [block](std::size_t bytes) { return (bytes + block - 1) / block * block; };
  room_needed_ = blocks(log.size()) + blocks(json.size()) + block;
  const std::uint64_t free = folder_.free_bytes();
  if (free < room_needed_) (void)make_room(room_needed_ - free, alarm);
  const auto pause = [this] {
    std::this_thread::sleep_for(std::chrono::duration<double>(settings_.test_pause_mid_write_s));
  };
  const auto write_partial = [&](const std::string& name, const std::string& text, bool paused) {
    WriteOutcome outcome =
        folder_.write_partial(name, text, error, paused ? pause : std::function<void()>());
    // A full disk (statvfs is an estimate): room made, then once more.
    if (outcome == WriteOutcome::kNoSpace &&
        make_room(room_needed_ - std::min(room_needed_, folder_.free_bytes()) + block, alarm)) {
      outcome = folder_.write_partial(name, text, error);
    }
    return outcome;
  };
  // Both files whole on disk first, the log then its summary; then their final names, the log's
  // first: a process killed between the two renames leaves a summary the next start completes.
  const std::string log_name = stem + ".log";
  const std::string json_name = stem + ".json";
  WriteOutcome outcome = write_partial(log_name, log, settings_.test_pause_mid_write_s > 0.0);
  if (outcome != WriteOutcome::kWritten) return outcome;
  outcome = write_partial(json_name, json, false);
  if (outcome == WriteOutcome::kWritten) outcome = folder_.publish(log_name, error);
  if (outcome != WriteOutcome::kWritten) {
    folder_.discard_partial(log_name);
    folder_.discard_partial(json_name);
    return outcome;  // kNameTaken: the capture takes another number
  }
  outcome = folder_.publish(json_name, error);
  if (outcome == WriteOutcome::kNameTaken) {
    folder_.remove(log_name);  // ours, renamed just now: the capture takes another number
  } else if (outcome != WriteOutcome::kWritten) {
    error += " (" + log_name + " is kept without its summary)";
  }
  return outcome;
}

void EventRecorder::write(Capture& c) {
  // The folder first (still there, locked, writable): the capture may come long after the last
  // check.
  check_folder();
  const RecorderProblem folder = folder_problem_.load();
  if (folder != RecorderProblem::kNone) {
    lose(c, folder, "the folder " + settings_.directory + " cannot be used");
    previous_piece_ = 0;
    return;
  }
  std::string log;
  log.reserve(c.frames.size() * kLogLineBytes);
  // Frames the input lost: DROPCOUNT lines as candump writes them, before the frame that came
  // next, their total counted from the capture's start (candump's counters are 32-bit: a larger
  // loss takes several lines).
  std::uint64_t input_lost = 0;
  std::uint64_t input_loss_lines = 0;
  std::uint32_t input_lost_total = 0;
  for (const RecordedFrame& f : c.frames) {
    for (std::uint64_t left = f.lost_before; left > 0;) {
      const auto count = static_cast<std::uint32_t>(
          std::min<std::uint64_t>(left, std::numeric_limits<std::uint32_t>::max()));
      input_lost_total += count;  // wraps as candump's does
      log += hal::format_candump_drop_line(count, settings_.interface_name, input_lost_total);
      log += '\n';
      left -= count;
      ++input_loss_lines;
    }
    input_lost += f.lost_before;
    log += hal::format_candump_line(f.timed.timestamp_ns, settings_.interface_name, f.timed.frame);
    log += '\n';
  }
  const auto seconds = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-9; };
  const double first = c.frames.empty() ? 0.0 : seconds(c.frames.front().timed.timestamp_ns);
  const double last = c.frames.empty() ? 0.0 : seconds(c.frames.back().timed.timestamp_ns);
  const bool truncated = c.frames_dropped > 0 || c.pre_trigger_cut_ns > 0;
  char numbers[640];
  std::snprintf(numbers, sizeof numbers,
                "\"t\":%.6f,\"frames\":%zu,\"first_frame_time\":%.6f,\"last_frame_time\":%.6f,"
                "\"pre_trigger_s\":%g,\"post_trigger_s\":%g,\"truncated\":%s,"
                "\"frames_dropped\":%llu,\"pre_trigger_cut_s\":%.6f,\"input_frames_lost\":%llu,"
                "\"input_loss_reports\":%llu",
                c.info.t, c.frames.size(), first, last, settings_.pre_trigger_s,
                settings_.post_trigger_s, truncated ? "true" : "false", ull(c.frames_dropped),
                static_cast<double>(c.pre_trigger_cut_ns) * 1e-9, ull(input_lost),
                ull(input_loss_lines));
  std::string error = "no free capture number";
  WriteOutcome outcome = WriteOutcome::kNameTaken;
  std::uint64_t index = 0;
  std::string log_path;
  for (int attempt = 0; attempt < kNameAttempts && outcome == WriteOutcome::kNameTaken; ++attempt) {
    index = next_index_;
    if (index > kMaxCaptureIndex) {
      lose(c, RecorderProblem::kNumberingExhausted,
           "no capture number after " + capture_stem(kMaxCaptureIndex));
      previous_piece_ = 0;
      return;
    }
    const std::string stem = capture_stem(index);
    if (folder_.taken(stem + ".log") || folder_.taken(stem + ".json")) {  // never written over
      ++next_index_;
      continue;
    }
    log_path = (std::filesystem::path(settings_.directory) / (stem + ".log")).string();
    std::string json = "{\"event\":" + std::to_string(index) + ",\"level\":\"" + c.info.level +
                       "\",\"highest_level\":\"" + (c.reached_alarm ? "alarm" : c.info.level) +
                       "\",\"cause\":\"" + c.info.cause + "\"," + numbers + ",\"log\":\"" +
                       log_path + '"';
    if (c.continuation && previous_piece_ != 0) {
      json += ",\"continues\":" + std::to_string(previous_piece_);
    }
    if (c.continued) json += ",\"continued\":true";
    if (!c.info.detail.empty()) json += ',' + c.info.detail;
    if (!settings_.identity_json.empty()) json += ',' + settings_.identity_json;
    json += "}\n";
    outcome = write_files(stem, log, json, c.reached_alarm, error);
    if (outcome == WriteOutcome::kNameTaken) ++next_index_;
  }
  if (outcome == WriteOutcome::kWritten && !folder_.commit(error)) outcome = WriteOutcome::kFailed;
  if (outcome != WriteOutcome::kWritten) {
    lose(c,
         outcome == WriteOutcome::kNoSpace ? RecorderProblem::kDiskFull
                                           : RecorderProblem::kWriteError,
         error);
    previous_piece_ = 0;
    return;
  }
  ++next_index_;
  previous_piece_ = c.continued ? index : 0;
  if (!wrote_any_) first_index_.store(index);
  wrote_any_ = true;
  written_.fetch_add(1);
  write_problem_.store(RecorderProblem::kNone);
  {
    const std::lock_guard lock(mutex_);
    paths_.push_back(log_path);
  }
  if (truncated) {
    truncated_.fetch_add(1);
    latest_loss_.store(RecorderProblem::kTruncated);
    say("%s misses frames of its window: %llu dropped before it, %.3f s of its pre-trigger "
        "window no longer held (the buffers hold %g frames/s)",
        capture_stem(index).c_str(), ull(c.frames_dropped),
        static_cast<double>(c.pre_trigger_cut_ns) * 1e-9, settings_.frame_rate_hz);
  }
  keep_retention();
}

void EventRecorder::keep_retention() {
  const RetentionLimits& limits = settings_.retention;
  if (limits.max_captures == 0 && limits.max_bytes == 0) return;
  const std::vector<std::uint64_t> doomed = captures_to_delete(folder_.scan(), limits);
  for (const std::uint64_t index : doomed) {
    folder_.remove_capture(index);
    deleted_.fetch_add(1);
  }
  std::string error;
  if (!doomed.empty()) (void)folder_.commit(error);
}

}  // namespace plinth::firmware
