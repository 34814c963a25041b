// What plinth-replay sends and when: sensor frames made from records, or the sensor frames of a
// candump log, each with its virtual send time (time since the replay started, at speed 1).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "plinth/core/excitation.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/candump_log.h"

namespace plinth::hal::replay {

enum class FrameKind : std::uint8_t { kAcceleration, kHeartbeat, kRotation };

struct ScheduledFrame {
  std::int64_t virtual_ns = 0;  // since the replay started, at speed 1
  FrameKind kind = FrameKind::kAcceleration;
  can::CanFrame frame;
};

class FrameSchedule {
 public:
  virtual ~FrameSchedule() = default;
  // The next frame in send order; false after the last one.
  [[nodiscard]] virtual bool next(ScheduledFrame& out) = 0;
};

// The ground motion one sensor node measures, m/s2: x and y horizontal, z vertical (positive
// up). An empty signal is a still axis; signals end (read zero) after their last sample.
struct SensorNodeInput {
  std::uint8_t node = can::kFirstSensorNode;
  SampledSignal x;
  SampledSignal y;
  SampledSignal z;
};

// A node's samples at the sensor rate, in g, as the accelerometer reads them (specific force:
// the ground's acceleration, plus +1 g on z from gravity), clamped to the frame's full scale
// with sensor_status::kSaturated set where a value had to be clamped.
struct SensorNodeSamples {
  std::uint8_t node = can::kFirstSensorNode;
  std::vector<std::array<double, 3>> acceleration_g;  // per sample: ax, ay, az
  std::vector<std::uint8_t> status;                   // per sample
  std::size_t clipped = 0;  // samples with an axis clamped to the full scale
};

// Samples at t = k / rate_hz, k = 0 .. floor(duration_s * rate_hz) (host::resample: the
// record's own samples at its rate, else the solver's linear interpolation), each signal
// multiplied by `scale`; 1 g is plinth::kStandardGravity, the DBC's.
[[nodiscard]] SensorNodeSamples resample(const SensorNodeInput& input, double scale, double rate_hz,
                                         double duration_s);

// SensorAcceleration frames of every node at each sample time (nodes in the given order),
// preceded at each whole second of virtual time by a SensorHeartbeat of every node; `loops`
// times over, each loop starting one sample period after the previous one's last sample. The
// sequence counters run on across loops (wrapping 255 -> 0), and so does the heartbeats'
// uptime.
class RecordSchedule final : public FrameSchedule {
 public:
  RecordSchedule(std::vector<SensorNodeSamples> nodes, double rate_hz, std::int64_t loops);
  [[nodiscard]] bool next(ScheduledFrame& out) override;

  [[nodiscard]] std::int64_t samples_per_loop() const { return samples_per_loop_; }

 private:
  std::vector<SensorNodeSamples> nodes_;
  double rate_hz_;
  std::int64_t samples_per_loop_;
  std::int64_t total_samples_;
  std::int64_t sample_ = 0;    // global sample index, across loops
  std::size_t slot_ = 0;       // position within the current sample time's frames
  bool heartbeat_due_ = true;  // heartbeats lead the frames of this sample time
  std::int64_t next_heartbeat_s_ = 0;
  std::vector<std::uint8_t> sequence_;      // per node
  std::vector<std::uint8_t> status_since_;  // per node: flags since its last heartbeat
};

// The sensor frames (SensorAcceleration, SensorHeartbeat and StatueRotation of any node: the
// ground sensors' and the statue sensor's) of a candump log, sent again as logged, at their
// logged times relative to the first of them. Other lines are skipped and counted. Their time is
// checked (hal::LogTimeCheck): with LogPolicy::kWarn a frame stamped before the previous one
// is sent at the previous one's time, and a jump forward beyond hal::kMaxLogGapS is shortened to
// that gap (the replay does not sit through a logger's pause or a clock step), each one named in
// `time_warnings` (the first kLogTimeWarnings) and counted; with kRefuse the first one throws.
// Frames of an identifier at the same microsecond are sent as logged. The frames the log lost
// (its DROPCOUNT lines: the logger's socket overflowed) cannot be sent: with `drop_policy`
// kWarn each line is named in `drop_warnings` (the first kLogTimeWarnings) and counted, the
// frames after it sent at their times; with kRefuse the first one throws.
inline constexpr std::size_t kLogTimeWarnings = 10;
struct LoggedFrames {
  std::vector<ScheduledFrame> frames;  // virtual_ns relative to the first
  std::int64_t skipped = 0;            // non-sensor, non-plinth, error-frame lines
  std::int64_t went_back = 0;          // frames stamped before the previous one
  std::int64_t jumps = 0;              // jumps forward beyond hal::kMaxLogGapS
  std::int64_t drop_reports = 0;       // DROPCOUNT lines
  std::int64_t dropped_frames = 0;     // the frames they say the log lost
  std::vector<std::string> time_warnings;  // "file:line: what, by how much: what was done"
  std::vector<std::string> drop_warnings;  // "file:line: what was lost"
};

// Reads the log; throws host::InputError "file:line: what" for a malformed line, for a time or
// a loss the policies refuse, and when the log holds no sensor frame. Frames later than
// `t_end_s` (relative, s; <0: no limit) are left out.
[[nodiscard]] LoggedFrames read_logged_sensor_frames(const std::string& path, double t_end_s,
                                                     hal::LogPolicy time_policy,
                                                     hal::LogPolicy drop_policy);

// `loops` times over the logged frames; each loop starts one mean frame interval after the
// previous loop's last frame (1 s when the log holds a single frame).
class LogSchedule final : public FrameSchedule {
 public:
  LogSchedule(std::vector<ScheduledFrame> frames, std::int64_t loops);
  [[nodiscard]] bool next(ScheduledFrame& out) override;

 private:
  std::vector<ScheduledFrame> frames_;
  std::int64_t loops_;
  std::int64_t loop_period_ns_;
  std::int64_t loop_ = 0;
  std::size_t index_ = 0;
};

}  // namespace plinth::hal::replay
