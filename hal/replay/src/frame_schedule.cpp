#include "frame_schedule.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "plinth/core/scene.h"
#include "plinth/hal/candump_log.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/record_sampling.h"

namespace plinth::hal::replay {
namespace {

constexpr double kNsPerSecond = 1e9;
// The frame's full scale (DBC: signed 16 bit at 0.25 mg).
constexpr double kFullScaleMin_g = -8.192;
constexpr double kFullScaleMax_g = 8.19175;
// plinth-replay speaks as firmware 0.1 (the project's version).
constexpr std::uint8_t kFirmwareMajor = 0;
constexpr std::uint8_t kFirmwareMinor = 1;
// Heartbeats: a sample time within this fraction of a sample of a whole second is at it.
constexpr double kSampleCountTolerance = 1e-6;

std::int64_t sample_time_ns(std::int64_t sample, double rate_hz) {
  return std::llround(static_cast<double>(sample) * kNsPerSecond / rate_hz);
}

double clamp_to_full_scale(double value_g, std::uint8_t& status) {
  if (value_g < kFullScaleMin_g || value_g > kFullScaleMax_g) {
    status = static_cast<std::uint8_t>(status | can::sensor_status::kSaturated);
    return std::clamp(value_g, kFullScaleMin_g, kFullScaleMax_g);
  }
  return value_g;
}

void encode_or_throw(const can::CodecResult& result, const char* what) {
  // The values are clamped and the nodes checked before: a refusal is a bug here.
  if (!result.ok()) {
    throw std::logic_error(std::string("cannot encode ") + what + ": " +
                           can::codec_error_text(result.error) + " " + result.signal);
  }
}

}  // namespace

SensorNodeSamples resample(const SensorNodeInput& input, double scale, double rate_hz,
                           double duration_s) {
  SensorNodeSamples out;
  out.node = input.node;
  const std::size_t count = host::sample_count(duration_s, rate_hz);
  const std::vector<double> x = host::resample(input.x, rate_hz, count);
  const std::vector<double> y = host::resample(input.y, rate_hz, count);
  const std::vector<double> z = host::resample(input.z, rate_hz, count);
  out.acceleration_g.reserve(count);
  out.status.reserve(count);
  for (std::size_t k = 0; k < count; ++k) {
    std::uint8_t status = 0;
    // An accelerometer reads specific force: at rest, +1 g along z (up); ground motion adds.
    const std::array<double, 3> reading_g{
        scale * x[k] / kStandardGravity,
        scale * y[k] / kStandardGravity,
        1.0 + scale * z[k] / kStandardGravity,
    };
    std::array<double, 3> clamped_g{};
    for (std::size_t axis = 0; axis < 3; ++axis) {
      clamped_g[axis] = clamp_to_full_scale(reading_g[axis], status);
    }
    out.acceleration_g.push_back(clamped_g);
    out.status.push_back(status);
    if (status != 0) ++out.clipped;
  }
  return out;
}

RecordSchedule::RecordSchedule(std::vector<SensorNodeSamples> nodes, double rate_hz,
                               std::int64_t loops)
    : nodes_(std::move(nodes)),
      rate_hz_(rate_hz),
      samples_per_loop_(nodes_.empty() ? 0
                                       : static_cast<std::int64_t>(nodes_.front().status.size())),
      total_samples_(samples_per_loop_ * loops),
      sequence_(nodes_.size(), 0),
      status_since_(nodes_.size(), 0) {
  for (const SensorNodeSamples& node : nodes_) {
    if (static_cast<std::int64_t>(node.status.size()) != samples_per_loop_) {
      throw std::logic_error("RecordSchedule: nodes with different sample counts");
    }
  }
}

bool RecordSchedule::next(ScheduledFrame& out) {
  if (sample_ >= total_samples_ || nodes_.empty()) return false;
  out.virtual_ns = sample_time_ns(sample_, rate_hz_);
  if (heartbeat_due_) {
    can::SensorHeartbeat heartbeat;
    heartbeat.node = nodes_[slot_].node;
    heartbeat.uptime_s = static_cast<std::uint32_t>(next_heartbeat_s_);
    heartbeat.firmware_major = kFirmwareMajor;
    heartbeat.firmware_minor = kFirmwareMinor;
    heartbeat.status = status_since_[slot_];
    status_since_[slot_] = 0;
    encode_or_throw(can::encode(heartbeat, out.frame), "a SensorHeartbeat");
    out.kind = FrameKind::kHeartbeat;
    if (++slot_ == nodes_.size()) {
      slot_ = 0;
      heartbeat_due_ = false;
      ++next_heartbeat_s_;
    }
    return true;
  }
  const SensorNodeSamples& node = nodes_[slot_];
  const auto k = static_cast<std::size_t>(sample_ % samples_per_loop_);
  can::SensorAcceleration sample;
  sample.node = node.node;
  sample.ax_g = node.acceleration_g[k][0];
  sample.ay_g = node.acceleration_g[k][1];
  sample.az_g = node.acceleration_g[k][2];
  sample.sequence = sequence_[slot_]++;  // uint8_t: wraps 255 -> 0
  sample.status = node.status[k];
  status_since_[slot_] = static_cast<std::uint8_t>(status_since_[slot_] | sample.status);
  encode_or_throw(can::encode(sample, out.frame), "a SensorAcceleration");
  out.kind = FrameKind::kAcceleration;
  if (++slot_ == nodes_.size()) {
    slot_ = 0;
    ++sample_;
    // A heartbeat at each whole second, with the first sample at or after it.
    heartbeat_due_ = static_cast<double>(sample_) + kSampleCountTolerance >=
                     static_cast<double>(next_heartbeat_s_) * rate_hz_;
  }
  return true;
}

LoggedFrames read_logged_sensor_frames(const std::string& path, double t_end_s,
                                       hal::LogPolicy time_policy, hal::LogPolicy drop_policy) {
  hal::CandumpLogReaderOpenResult opened = hal::CandumpLogReader::open(path);
  if (!opened.ok()) throw host::InputError(opened.message);
  hal::CandumpLogReader& reader = *opened.reader;
  LoggedFrames out;
  std::int64_t first_ns = 0;
  std::int64_t previous_ns = 0;
  std::int64_t cut_ns = 0;  // of the jumps shortened so far
  const auto max_gap_ns = static_cast<std::int64_t>(hal::kMaxLogGapS * kNsPerSecond);
  hal::LogTimeCheck time_check;
  hal::TimedFrame timed;
  for (;;) {
    const hal::IoStatus status = reader.receive(timed, 0);
    if (status == hal::IoStatus::kEndOfInput) break;
    if (status == hal::IoStatus::kIoError) throw host::InputError(reader.error());
    if (static_cast<double>(reader.line_number()) > host::kMaxReplayLogLines ||
        static_cast<double>(out.frames.size()) >= host::kMaxReplayLogFrames) {
      throw host::InputError(path + ":" + std::to_string(reader.line_number()) +
                             ": the log is longer than plinth-replay holds (" +
                             host::number_text(host::kMaxReplayLogFrames, 3) +
                             " sensor frames or " + host::number_text(host::kMaxReplayLogLines, 3) +
                             " lines); use --t-end, or split it");
    }
    if (status == hal::IoStatus::kOverflow) {  // a DROPCOUNT line
      const std::string what = path + ":" + std::to_string(reader.line_number()) + ": " +
                               hal::describe_candump_drop(reader.last_line());
      if (drop_policy == hal::LogPolicy::kRefuse) {
        throw host::InputError(what + " (--log-drops refuse)");
      }
      ++out.drop_reports;
      out.dropped_frames += reader.dropped_frames();
      if (out.drop_warnings.size() < kLogTimeWarnings) {
        out.drop_warnings.push_back(what + ": not in the log, not sent");
      }
      continue;
    }
    const can::MessageKind kind =
        status == hal::IoStatus::kOk ? can::classify(timed.frame.id) : can::MessageKind::kUnknown;
    if (kind != can::MessageKind::kSensorAcceleration &&
        kind != can::MessageKind::kSensorHeartbeat && kind != can::MessageKind::kStatueRotation) {
      ++out.skipped;
      continue;
    }
    if (out.frames.empty()) first_ns = timed.timestamp_ns;
    const hal::LogTimeStep step = time_check.check(timed.timestamp_ns, timed.frame.id);
    if (step.problem == hal::LogTimeProblem::kWentBack ||
        step.problem == hal::LogTimeProblem::kJumped) {
      const bool back = step.problem == hal::LogTimeProblem::kWentBack;
      std::string what = path + ":" + std::to_string(reader.line_number()) + ": " +
                         time_check.describe(step, timed.timestamp_ns);
      if (time_policy == hal::LogPolicy::kRefuse) {
        throw host::InputError(what + " (--log-time refuse)");
      }
      ++(back ? out.went_back : out.jumps);
      if (!back) cut_ns += step.step_ns - max_gap_ns;
      if (out.time_warnings.size() < kLogTimeWarnings) {
        char gap[48];
        std::snprintf(gap, sizeof gap, ": replayed as a %g s gap", hal::kMaxLogGapS);
        out.time_warnings.push_back(what + (back ? ": sent at the previous frame's time" : gap));
      }
    }
    time_check.take(std::max(timed.timestamp_ns, time_check.previous_ns()), timed.frame.id);
    const std::int64_t relative_ns =
        std::max(previous_ns, timed.timestamp_ns - first_ns - cut_ns);
    if (t_end_s >= 0.0 && static_cast<double>(relative_ns) > t_end_s * kNsPerSecond) break;
    previous_ns = relative_ns;
    ScheduledFrame frame;
    frame.virtual_ns = relative_ns;
    frame.kind = kind == can::MessageKind::kSensorHeartbeat  ? FrameKind::kHeartbeat
                 : kind == can::MessageKind::kStatueRotation ? FrameKind::kRotation
                                                             : FrameKind::kAcceleration;
    frame.frame = timed.frame;
    out.frames.push_back(frame);
  }
  if (out.frames.empty()) {
    throw host::InputError(path +
                           ": no sensor frames (SensorAcceleration 0x301-0x30F, "
                           "SensorHeartbeat 0x311-0x31F or StatueRotation 0x371-0x37F) in the "
                           "log");
  }
  return out;
}

LogSchedule::LogSchedule(std::vector<ScheduledFrame> frames, std::int64_t loops)
    : frames_(std::move(frames)), loops_(loops), loop_period_ns_(0) {
  const std::int64_t span_ns = frames_.empty() ? 0 : frames_.back().virtual_ns;
  const auto intervals = static_cast<std::int64_t>(frames_.size()) - 1;
  const std::int64_t mean_interval_ns =
      intervals > 0 && span_ns > 0 ? span_ns / intervals : static_cast<std::int64_t>(kNsPerSecond);
  loop_period_ns_ = span_ns + mean_interval_ns;
}

bool LogSchedule::next(ScheduledFrame& out) {
  if (frames_.empty() || loop_ >= loops_) return false;
  out = frames_[index_];
  out.virtual_ns += loop_ * loop_period_ns_;
  if (++index_ == frames_.size()) {
    index_ = 0;
    ++loop_;
  }
  return true;
}

}  // namespace plinth::hal::replay
