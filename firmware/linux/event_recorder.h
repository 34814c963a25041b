// The event recorder: the last pre_trigger_s of raw frames in a ring; on a trigger (a warning or
// an alarm) it keeps that window and the following post_trigger_s (a later trigger extends it),
// then hands the capture to a writer thread that writes a candump log and a JSON summary. The
// real-time side (on_frame, trigger) never blocks or does I/O: the ring and two capture buffers
// are allocated once at start-up, and captures are handed over through a mutex held only for a
// pointer swap. A window longer than a buffer goes on in the other buffer (the next capture
// "continues" it); frames that find no buffer, a pre-trigger window the ring no longer holds,
// and a trigger while both buffers are busy are counted and said, never silently lost. The
// folder (capture_store.h) is locked against another box, checked and recreated, and kept to
// its retention limit at start, after each capture and when a capture does not fit. status()
// gives its health to the outputs (docs/monitor.md, "Event recorder"). Frames the input lost (a
// live socket's overflow, a replayed log's DROPCOUNT lines) go into the capture as candump writes
// them: a DROPCOUNT line before the next frame, and a count in its JSON.
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
#include "recorder_status.h"

namespace plinth::firmware {

struct EventRecorderSettings {
  std::string directory;       // where captures go (created if missing)
  std::string interface_name = "can0";  // written in the candump log's lines
  double pre_trigger_s = 30.0;   // s of frames kept before the trigger
  double post_trigger_s = 60.0;  // s of frames kept after the (latest) trigger
  // Frames/s the buffers are sized for: every sensor's frames and the bus's other traffic
  // (plinth-monitor: recorder_frame_rate_hz, monitor_config.h).
  double frame_rate_hz = 1000.0;
  RetentionLimits retention;      // [recorder] max_captures, max_bytes
  // Members written already, added to each capture's JSON: what was running (the version, the
  // scene and box files' hashes; run_identity.h).
  std::string identity_json;
  // s between checks of the folder off the loop (still there, locked, writable; recreated when
  // gone); a capture checks it again before it is written.
  double folder_check_period_s = 2.0;
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
  // Throws plinth::host::InputError when a setting is bad. A folder it cannot use (not
  // creatable, read-only, another box's) does not stop the box: it is said on stderr, status()
  // is failed, and the folder is tried again at every check. With the folder: removes partial
  // files a killed process left (partial_files_removed), numbers the captures after the highest
  // present and applies the retention limit.
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

  // Any thread, without a lock: health, its problem and the counters.
  [[nodiscard]] RecorderStatus status() const;
  [[nodiscard]] std::uint64_t captures_written() const { return written_.load(); }
  // Triggers that found both buffers busy (part of status().captures_lost).
  [[nodiscard]] std::uint64_t captures_dropped() const { return dropped_.load(); }
  // Captures (or pieces) the writer could not write (part of status().captures_lost).
  [[nodiscard]] std::uint64_t write_errors() const { return write_errors_.load(); }
  // Frames of capture windows that no capture holds.
  [[nodiscard]] std::uint64_t frames_lost() const { return frames_lost_.load(); }
  // Captures deleted by retention (the limits, or room for a new capture).
  [[nodiscard]] std::uint64_t captures_deleted() const { return deleted_.load(); }
  [[nodiscard]] int partial_files_removed() const { return partial_files_removed_.load(); }
  // The number of this run's first capture (before any: the number the next one takes; 0: the
  // folder was never usable).
  [[nodiscard]] std::uint64_t first_index() const { return first_index_.load(); }
  // Paths of the files written so far (candump logs), for the summary.
  [[nodiscard]] std::vector<std::string> written_paths();

 private:
  struct RecordedFrame {
    hal::TimedFrame timed;
    std::uint64_t lost_before = 0;  // frames the input lost just before it
  };
  // One capture: a window, or a piece of a window longer than a buffer.
  struct Capture {
    std::vector<RecordedFrame> frames;    // capacity reserved once
    TriggerInfo info;                     // the window's first trigger
    std::int64_t trigger_ns = 0;
    bool reached_alarm = false;           // the window reached the alarm level by this piece's end
    bool continuation = false;            // it continues the window's previous piece
    bool continued = false;               // it was full: the next piece continues it
    std::uint64_t frames_dropped = 0;     // frames of the window before it that no piece holds
    std::int64_t pre_trigger_cut_ns = 0;  // of the pre-trigger window, what the ring had lost
  };

  // Real-time side.
  [[nodiscard]] bool take_buffer(bool may_wait);
  void start_piece(bool continuation);
  void hand_over(bool continued);  // the piece being filled is complete
  void close_window();

  // Writer side.
  void writer_loop();
  void write(Capture& capture);
  [[nodiscard]] WriteOutcome write_files(const std::string& stem, const std::string& log,
                                         const std::string& json, bool alarm, std::string& error);
  [[nodiscard]] bool make_room(std::uint64_t bytes, bool for_alarm);
  void check_folder();
  void folder_opened();
  void keep_retention();
  void lose(const Capture& capture, RecorderProblem problem, const std::string& error);
  void say_real_time_losses();
  [[nodiscard]] bool real_time_losses_unsaid() const;

  EventRecorderSettings settings_;
  std::int64_t pre_ns_ = 0;
  std::int64_t post_ns_ = 0;
  std::vector<RecordedFrame> ring_;
  std::size_t ring_next_ = 0;
  std::size_t ring_count_ = 0;
  Capture buffers_[2];
  // The window in progress (real-time side only).
  bool window_open_ = false;
  TriggerInfo window_info_;
  std::int64_t window_trigger_ns_ = 0;
  std::int64_t window_end_ns_ = 0;  // frames up to this receive time belong to it
  bool window_alarm_ = false;
  std::uint64_t window_dropped_ = 0;  // frames since the last piece that found no buffer
  Capture* active_ = nullptr;         // the piece being filled, or none

  // Under mutex_: buffers free for a new piece, and pieces waiting for the writer (in order).
  // Each buffer is in exactly one place: free, active, waiting or being written.
  std::mutex mutex_;
  std::condition_variable wake_;
  Capture* free_[2] = {};
  int free_count_ = 0;
  Capture* waiting_[2] = {};
  int waiting_count_ = 0;
  bool stopping_ = false;
  std::vector<std::string> paths_;

  // Writer side only (and the constructor, before the writer starts).
  CaptureFolder folder_;
  std::uint64_t next_index_ = 1;
  std::uint64_t previous_piece_ = 0;  // the number of the window's previous piece written
  std::uint64_t room_needed_ = 0;     // bytes of the latest capture lost to a full disk
  bool wrote_any_ = false;
  std::uint64_t said_dropped_ = 0;
  std::uint64_t said_frames_lost_ = 0;
  std::thread writer_;

  // Health, read by status() from any thread.
  std::atomic<RecorderProblem> folder_problem_{RecorderProblem::kNone};  // the folder's now
  std::atomic<RecorderProblem> write_problem_{RecorderProblem::kNone};   // until a capture fits
  std::atomic<RecorderProblem> latest_loss_{RecorderProblem::kNone};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> write_errors_{0};
  std::atomic<std::uint64_t> truncated_{0};
  std::atomic<std::uint64_t> frames_lost_{0};
  std::atomic<std::uint64_t> deleted_{0};
  std::atomic<std::uint64_t> first_index_{0};
  std::atomic<int> partial_files_removed_{0};
};

}  // namespace plinth::firmware
