// The event recorder: the last pre_trigger_s of raw frames in a ring; on a trigger (an alarm)
// it keeps that window and the following post_trigger_s, then hands the capture to a writer
// thread that writes a candump log and a JSON summary. The real-time side (on_frame, trigger)
// never allocates, blocks or does I/O: the ring and two capture buffers are allocated once at
// start-up, and captures are handed over through a mutex held only for a pointer swap. When the
// writer is still busy with an earlier capture, a new trigger extends the capture in progress;
// a trigger while both buffers are full is counted (captures_dropped), never silently lost.
// Frames the input lost (a live socket's overflow, a log's DROPCOUNT lines) go into the capture
// as candump writes them: a DROPCOUNT line before the next frame, and a count in its JSON.
// The folder (capture_store.h): numbers continue after the highest capture present, each file
// appears under its final name only when complete, and the retention limit is kept after each
// capture.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "capture_store.h"
#include "plinth/hal/frame_io.h"

namespace plinth::firmware {

struct EventRecorderSettings {
  std::string directory;       // where captures go (created if missing)
  std::string interface_name = "can0";  // written in the candump log's lines
  double pre_trigger_s = 30.0;   // s of frames kept before the trigger
  double post_trigger_s = 60.0;  // s of frames kept after the (latest) trigger
  double frame_rate_hz = 1000.0;  // upper bound of the frame rate, sizes the buffers
  RetentionLimits retention;      // [recorder] max_captures, max_bytes
  // Members written already, added to each capture's JSON: what was running (the version, the
  // scene and box files' hashes; run_identity.h).
  std::string identity_json;
  // recorder.test_pause_mid_write_s, TEST ONLY: the writer stops this long halfway through each
  // capture's log, so a test can kill the process while a file is being written; 0: never.
  double test_pause_mid_write_s = 0.0;
};

// What a capture's JSON summary says about its trigger; filled by the caller.
struct TriggerInfo {
  double t = 0.0;  // s, monitor time
  std::string level;
  std::string cause;
  std::string detail;  // a JSON object's members, e.g. "\"risk\":0.82,\"phase\":\"rocking\""
  bool alarm = false;  // the trigger is the alarm level (retention keeps the newest such capture)
};

class EventRecorder {
 public:
  // Throws plinth::host::InputError when the directory cannot be created or a setting is bad.
  // Removes partial files a killed process left (partial_files_removed) and numbers the
  // captures after the highest present.
  explicit EventRecorder(EventRecorderSettings settings);
  ~EventRecorder();  // finishes any capture in progress and joins the writer
  EventRecorder(const EventRecorder&) = delete;
  EventRecorder& operator=(const EventRecorder&) = delete;

  // Real-time side. `lost_before`: frames the input lost just before this one.
  void on_frame(const hal::TimedFrame& frame, std::uint64_t lost_before = 0);
  void trigger(const TriggerInfo& info, std::int64_t time_ns);
  // The input ended: the capture in progress is written with what it has.
  void flush();
  // flush(), then waits until the writer has written everything and stops it (idempotent).
  void close();

  [[nodiscard]] std::uint64_t captures_written() const { return written_.load(); }
  [[nodiscard]] std::uint64_t captures_dropped() const { return dropped_.load(); }
  [[nodiscard]] std::uint64_t write_errors() const { return write_errors_.load(); }
  // Captures deleted to keep the retention limit.
  [[nodiscard]] std::uint64_t captures_deleted() const { return deleted_.load(); }
  [[nodiscard]] int partial_files_removed() const { return partial_files_removed_; }
  [[nodiscard]] int first_index() const { return first_index_; }
  // Paths of the files written so far (candump logs), for the summary.
  [[nodiscard]] std::vector<std::string> written_paths();

 private:
  struct RecordedFrame {
    hal::TimedFrame timed;
    std::uint64_t lost_before = 0;  // frames lost just before it
  };
  struct Capture {
    std::vector<RecordedFrame> frames;  // capacity reserved once
    TriggerInfo info;
    std::int64_t trigger_ns = 0;
    std::int64_t end_ns = 0;  // frames up to this receive time belong to the capture
    int index = 0;
    bool reached_alarm = false;  // its trigger or a later one within it was the alarm level
  };

  void hand_over();  // the active capture is complete
  void writer_loop();
  void write(const Capture& capture);
  void keep_retention();

  EventRecorderSettings settings_;
  std::int64_t pre_ns_ = 0;
  std::int64_t post_ns_ = 0;
  std::vector<RecordedFrame> ring_;
  std::size_t ring_next_ = 0;
  std::size_t ring_count_ = 0;
  Capture buffers_[2];
  Capture* active_ = nullptr;  // the capture being filled (real-time side only), or none
  int next_index_ = 1;
  int first_index_ = 1;
  int partial_files_removed_ = 0;

  // Under mutex_: buffers free for a new capture, and captures waiting for the writer (in
  // order). Each buffer is in exactly one place: free, active, waiting or being written.
  std::mutex mutex_;
  std::condition_variable wake_;
  Capture* free_[2] = {};
  int free_count_ = 0;
  Capture* waiting_[2] = {};
  int waiting_count_ = 0;
  bool stopping_ = false;
  std::thread writer_;
  std::vector<std::string> paths_;
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> write_errors_{0};
  std::atomic<std::uint64_t> deleted_{0};
};

}  // namespace plinth::firmware
