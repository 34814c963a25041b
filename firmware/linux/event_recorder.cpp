#include "event_recorder.h"

#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include "plinth/hal/candump_log.h"
#include "plinth/host/input_error.h"

namespace plinth::firmware {

namespace {

std::int64_t seconds_to_ns(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

std::size_t frames_in(double seconds, double rate_hz) {
  return static_cast<std::size_t>(std::ceil(seconds * rate_hz)) + 16;
}

}  // namespace

EventRecorder::EventRecorder(EventRecorderSettings settings) : settings_(std::move(settings)) {
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
      settings_.frame_rate_hz > 20000.0) {
    throw bad("the frame rate bound must lie in (0, 20000] Hz");
  }
  std::error_code ec;
  std::filesystem::create_directories(settings_.directory, ec);
  if (ec || !std::filesystem::is_directory(settings_.directory)) {
    throw host::InputError("event recorder: cannot create the directory '" + settings_.directory +
                           "': " + (ec ? ec.message() : std::string("not a directory")));
  }
  if (!std::isfinite(settings_.test_pause_mid_write_s) || settings_.test_pause_mid_write_s < 0.0) {
    throw bad("the test pause must be a finite number of seconds >= 0");
  }
  partial_files_removed_ = remove_partial_files(settings_.directory);
  next_index_ = first_index_ = next_capture_index(scan_captures(settings_.directory));
  pre_ns_ = seconds_to_ns(settings_.pre_trigger_s);
  post_ns_ = seconds_to_ns(settings_.post_trigger_s);
  ring_.resize(frames_in(settings_.pre_trigger_s, settings_.frame_rate_hz));
  const std::size_t capture_frames =
      frames_in(settings_.pre_trigger_s + settings_.post_trigger_s, settings_.frame_rate_hz);
  for (Capture& c : buffers_) {
    c.frames.reserve(capture_frames);
    free_[free_count_++] = &c;
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

void EventRecorder::on_frame(const hal::TimedFrame& frame, std::uint64_t lost_before) {
  const RecordedFrame recorded{frame, lost_before};
  ring_[ring_next_] = recorded;
  ring_next_ = (ring_next_ + 1) % ring_.size();
  if (ring_count_ < ring_.size()) ++ring_count_;
  if (active_ == nullptr) return;
  if (frame.timestamp_ns > active_->end_ns) {
    hand_over();
    return;
  }
  if (active_->frames.size() < active_->frames.capacity()) active_->frames.push_back(recorded);
}

void EventRecorder::trigger(const TriggerInfo& info, std::int64_t time_ns) {
  if (active_ != nullptr) {  // a later alarm within the capture: keep recording after it
    active_->end_ns = time_ns + post_ns_;
    active_->reached_alarm = active_->reached_alarm || info.alarm;
    return;
  }
  {
    const std::lock_guard lock(mutex_);
    if (free_count_ > 0) active_ = free_[--free_count_];
  }
  if (active_ == nullptr) {  // both buffers busy: the writer is behind
    dropped_.fetch_add(1);
    return;
  }
  active_->frames.clear();  // keeps the capacity: no allocation
  const std::size_t first = (ring_next_ + ring_.size() - ring_count_) % ring_.size();
  for (std::size_t i = 0; i < ring_count_; ++i) {
    const RecordedFrame& f = ring_[(first + i) % ring_.size()];
    if (f.timed.timestamp_ns >= time_ns - pre_ns_ &&
        active_->frames.size() < active_->frames.capacity()) {
      active_->frames.push_back(f);
    }
  }
  active_->info = info;
  active_->trigger_ns = time_ns;
  active_->end_ns = time_ns + post_ns_;
  active_->index = next_index_++;
  active_->reached_alarm = info.alarm;
}

void EventRecorder::flush() {
  if (active_ != nullptr) hand_over();
}

void EventRecorder::hand_over() {
  {
    const std::lock_guard lock(mutex_);
    waiting_[waiting_count_++] = active_;  // room: at most two buffers exist
  }
  active_ = nullptr;
  wake_.notify_one();
}

std::vector<std::string> EventRecorder::written_paths() {
  const std::lock_guard lock(mutex_);
  return paths_;
}

void EventRecorder::writer_loop() {
  for (;;) {
    Capture* capture = nullptr;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return waiting_count_ > 0 || stopping_; });
      if (waiting_count_ == 0) return;  // stopping, nothing left
      capture = waiting_[0];
      waiting_[0] = waiting_[1];
      --waiting_count_;
    }
    write(*capture);
    const std::lock_guard lock(mutex_);
    free_[free_count_++] = capture;
  }
}

void EventRecorder::write(const Capture& c) {
  const std::string stem = capture_stem(c.index);
  const std::string log_path = (std::filesystem::path(settings_.directory) / (stem + ".log")).string();
  std::string log;
  log.reserve(c.frames.size() * 48);
  // Frames lost within the capture: DROPCOUNT lines as candump writes them, before the frame
  // that came next, their total counted from the capture's start (candump's counters are 32-bit:
  // a larger loss takes several lines).
  std::uint64_t lost = 0;
  std::uint64_t loss_lines = 0;
  std::uint32_t lost_total = 0;
  for (const RecordedFrame& f : c.frames) {
    for (std::uint64_t left = f.lost_before; left > 0;) {
      const auto count = static_cast<std::uint32_t>(std::min<std::uint64_t>(left, UINT32_MAX));
      lost_total += count;  // wraps as candump's does
      log += hal::format_candump_drop_line(count, settings_.interface_name, lost_total);
      log += '\n';
      left -= count;
      ++loss_lines;
    }
    lost += f.lost_before;
    log += hal::format_candump_line(f.timed.timestamp_ns, settings_.interface_name, f.timed.frame);
    log += '\n';
  }
  const double first =
      c.frames.empty() ? 0.0 : static_cast<double>(c.frames.front().timed.timestamp_ns) * 1e-9;
  const double last =
      c.frames.empty() ? 0.0 : static_cast<double>(c.frames.back().timed.timestamp_ns) * 1e-9;
  char numbers[320];
  std::snprintf(numbers, sizeof numbers,
                "\"t\":%.6f,\"frames\":%zu,\"first_frame_time\":%.6f,\"last_frame_time\":%.6f,"
                "\"pre_trigger_s\":%g,\"post_trigger_s\":%g,\"frames_lost\":%llu,"
                "\"loss_reports\":%llu",
                c.info.t, c.frames.size(), first, last, settings_.pre_trigger_s,
                settings_.post_trigger_s, static_cast<unsigned long long>(lost),
                static_cast<unsigned long long>(loss_lines));
  std::string json = "{\"event\":" + std::to_string(c.index) + ",\"level\":\"" + c.info.level +
                     "\",\"highest_level\":\"" + (c.reached_alarm ? "alarm" : c.info.level) +
                     "\",\"cause\":\"" + c.info.cause + "\"," + numbers + ",\"log\":\"" + log_path +
                     '"';
  if (!c.info.detail.empty()) json += ',' + c.info.detail;
  if (!settings_.identity_json.empty()) json += ',' + settings_.identity_json;
  json += "}\n";
  // The log, then its summary, each whole under its final name or not at all; the folder last.
  std::string error;
  const auto pause = [this] {
    std::this_thread::sleep_for(std::chrono::duration<double>(settings_.test_pause_mid_write_s));
  };
  const bool ok =
      write_file_whole(settings_.directory, stem + ".log", log, error,
                       settings_.test_pause_mid_write_s > 0.0 ? pause : std::function<void()>()) &&
      write_file_whole(settings_.directory, stem + ".json", json, error) &&
      commit_folder(settings_.directory, error);
  if (!ok) {
    if (write_errors_.fetch_add(1) == 0) {  // once: a full disk must not flood stderr
      std::fprintf(stderr, "plinth-monitor: event recorder: %s\n", error.c_str());
    }
    return;
  }
  written_.fetch_add(1);
  {
    const std::lock_guard lock(mutex_);
    paths_.push_back(log_path);
  }
  keep_retention();
}

void EventRecorder::keep_retention() {
  const RetentionLimits& limits = settings_.retention;
  if (limits.max_captures == 0 && limits.max_bytes == 0) return;
  const std::filesystem::path dir(settings_.directory);
  for (const int index : captures_to_delete(scan_captures(settings_.directory), limits)) {
    std::error_code ec;
    const std::string stem = capture_stem(index);
    std::filesystem::remove(dir / (stem + ".log"), ec);
    std::filesystem::remove(dir / (stem + ".json"), ec);
    deleted_.fetch_add(1);
  }
}

}  // namespace plinth::firmware
