#include "inputs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <utility>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/firmware/can_frames.h"
#include "plinth/firmware/record_replay.h"
#include "plinth/hal/candump_log.h"
#include "plinth/hal/pacing.h"
#include "plinth/hal/socketcan.h"
#include "plinth/host/input_error.h"
#include "record_input.h"

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;
namespace {

using host::InputError;

constexpr std::int64_t kLogTickNs = 10'000'000;          // ticks inside a log's gaps: timeouts
constexpr int kBusReceiveTimeoutMs = 10;                 // the live loop ticks at least this often
constexpr std::int64_t kBusFaultHoldNs = 2'000'000'000;  // after the latest report
constexpr auto kInputFaultHoldNs = static_cast<std::int64_t>(kInputFaultHoldS * 1e9);

// A record replayed sample by sample after the quiet lead-in (record_replay.h), so that the
// estimator starts at the record's first sample and replay equals plinth-sim.
class RecordInput final : public MonitorInput {
 public:
  RecordInput(std::string path, RecordSamples record, const MonitorConfig& config, double speed,
              bool frames, const volatile std::sig_atomic_t& stop)
      : path_(std::move(path)),
        record_(std::move(record)),
        config_(config),
        lead_in_(static_cast<std::size_t>(record_replay_lead_in(config))),
        frames_(frames),
        pacer_(speed),
        stop_(stop) {}

  bool next(InputItem& item) override {
    if (n_ == 0) pacer_.start();
    if (n_ >= lead_in_ + record_.samples.size()) return false;
    item.sample = record_replay_sample(
        config_, static_cast<std::int64_t>(n_),
        n_ < lead_in_ ? Eigen::Vector3d::Zero() : record_.samples[n_ - lead_in_], kStandardGravity);
    if (!pacer_.wait_until(item.sample.receive_time_ns, stop_)) return false;
    item.due_ns = pacer_.paced() ? pacer_.deadline_ns(item.sample.receive_time_ns) : 0;
    item.kind = InputItem::Kind::kSample;
    item.has_frame = frames_ && encode_frame(item.sample, item.frame);
    ++n_;
    return true;
  }

  [[nodiscard]] const std::string& source() const override { return path_; }
  [[nodiscard]] double t_origin() const override { return record_replay_origin_s(config_); }

 private:
  // The sample (m/s2) as its sensor's frame (g); false beyond the frame's +-8 g.
  bool encode_frame(const monitor::SensorSample& sample, hal::TimedFrame& out) const {
    monitor::SensorSample sample_g = sample;
    sample_g.acceleration_g = sample.acceleration_g / kStandardGravity;
    out.timestamp_ns = sample.receive_time_ns;
    return can::encode(sensor_message(config_.ground_node, sample_g), out.frame).ok();
  }

  std::string path_;
  RecordSamples record_;
  MonitorConfig config_;
  std::size_t lead_in_;
  bool frames_;
  hal::Pacer pacer_;
  const volatile std::sig_atomic_t& stop_;
  std::size_t n_ = 0;
};

// A candump log's frames at their logged times, with ticks inside its gaps (timeouts), and the
// policies of inputs.h: frames stamped back or still are counted and dropped, gaps beyond
// kMaxLogGapS counted and not ticked through, frames the log lost (DROPCOUNT) counted; each
// raises the input fault.
class LogInput final : public MonitorInput {
 public:
  LogInput(hal::CandumpLogReader reader, double speed, hal::LogPolicy time_policy,
           hal::LogPolicy drop_policy, const volatile std::sig_atomic_t& stop)
      : reader_(std::move(reader)),
        pacer_(speed),
        time_policy_(time_policy),
        drop_policy_(drop_policy),
        stop_(stop) {}

  bool next(InputItem& item) override {
    if (!pending_ && !read_frame()) return false;
    if (fault_told_ != (fault_until_ns_ != 0)) {
      fault_told_ = fault_until_ns_ != 0;
      item.kind = InputItem::Kind::kBusFault;
      item.bus_fault = fault_told_;
      return true;
    }
    if (next_tick_ns_ < frame_.timestamp_ns) {
      item.kind = InputItem::Kind::kTick;
      item.time_ns = next_tick_ns_;
      next_tick_ns_ += kLogTickNs;
      return true;
    }
    item.kind = InputItem::Kind::kFrame;
    item.frame = frame_;
    item.lost_before = lost_before_;
    lost_before_ = 0;
    pending_ = false;
    return true;
  }

  [[nodiscard]] const std::string& source() const override { return reader_.path(); }
  [[nodiscard]] InputTimeCounters time_counters() const override { return time_; }
  [[nodiscard]] InputDropCounters drop_counters() const override { return drops_; }

 private:
  // The next classic standard frame (others are not ours) with a usable time, paced to it.
  bool read_frame() {
    for (;;) {
      const hal::IoStatus status = reader_.receive(frame_, 0);
      if (status == hal::IoStatus::kEndOfInput) return false;
      if (status == hal::IoStatus::kIoError) throw InputError(reader_.error());  // file:line
      if (status == hal::IoStatus::kOverflow) take_drop_count();
      if (status != hal::IoStatus::kOk) continue;  // extended, RTR, FD, error frames: not ours
      if (usable_time()) break;
    }
    if (!first_ns_) {
      first_ns_ = frame_.timestamp_ns;
      next_tick_ns_ = frame_.timestamp_ns + kLogTickNs;
      pacer_.start();
    }
    if (fault_until_ns_ != 0 && frame_.timestamp_ns > fault_until_ns_) fault_until_ns_ = 0;
    // A loss, as a live box sees its socket's overflow: reported with the first frame after
    // it, the fault raised before that frame and the ticks up to it (BusInput ticks at the
    // newest frame's time), held kInputFaultHoldS from that frame.
    if (lost_before_ > 0) {
      fault_until_ns_ = std::max(fault_until_ns_, frame_.timestamp_ns + kInputFaultHoldNs);
    }
    time_check_.take(frame_.timestamp_ns, frame_.frame.id);
    pending_ = true;
    return pacer_.wait_until(frame_.timestamp_ns - *first_ns_, stop_);
  }

  // Whether frame_'s time can be monitor time; counts and raises the fault when it cannot, or
  // when it jumps beyond kMaxLogGapS (then the ticks skip the rest of the gap).
  bool usable_time() {
    const std::int64_t t = frame_.timestamp_ns;
    const hal::LogTimeStep step = time_check_.check(t, frame_.frame.id);
    if (step.problem == hal::LogTimeProblem::kNone) return true;
    const std::string what = reader_.path() + ":" + std::to_string(reader_.line_number()) + ": " +
                             time_check_.describe(step, t);
    if (time_policy_ == hal::LogPolicy::kRefuse) throw InputError(what + " (--log-time refuse)");
    const std::int64_t max_gap_ns = std::llround(kMaxLogGapS * 1e9);
    switch (step.problem) {
      case hal::LogTimeProblem::kWentBack: ++time_.went_back; break;
      case hal::LogTimeProblem::kStoodStill: ++time_.stood_still; break;
      default:
        ++time_.gaps;
        next_tick_ns_ = std::max(next_tick_ns_, t - max_gap_ns);
        break;
    }
    if (time_.total() <= kLogTimeWarnings) {
      std::fprintf(stderr, "plinth-monitor: warning: %s%s\n", what.c_str(),
                   time_.total() == kLogTimeWarnings ? " (further ones are counted in the summary)"
                                                      : "");
    }
    if (time_.first.empty()) time_.first = what;
    fault_until_ns_ = std::max(t, time_check_.previous_ns()) + kInputFaultHoldNs;
    return step.problem == hal::LogTimeProblem::kJumped;  // given; one back or still is not
  }

  // A DROPCOUNT line: counted and named (the first kLogDropWarnings), its frames lost before
  // the next frame; or, refused, the end of the run.
  void take_drop_count() {
    const std::string what = reader_.path() + ":" + std::to_string(reader_.line_number()) + ": " +
                             hal::describe_candump_drop(reader_.last_line());
    if (drop_policy_ == hal::LogPolicy::kRefuse) throw InputError(what + " (--log-drops refuse)");
    ++drops_.reports;
    drops_.frames += reader_.dropped_frames();
    lost_before_ += reader_.dropped_frames();
    if (drops_.reports <= kLogDropWarnings) {
      std::fprintf(stderr, "plinth-monitor: warning: %s%s\n", what.c_str(),
                   drops_.reports == kLogDropWarnings
                       ? " (further ones are counted in the summary)"
                       : "");
    }
    if (drops_.first.empty()) drops_.first = what;
  }

  hal::CandumpLogReader reader_;
  hal::Pacer pacer_;
  hal::LogPolicy time_policy_;
  hal::LogPolicy drop_policy_;
  const volatile std::sig_atomic_t& stop_;
  hal::TimedFrame frame_;
  bool pending_ = false;  // frame_ is read, not yet given
  std::optional<std::int64_t> first_ns_;
  std::int64_t next_tick_ns_ = 0;
  hal::LogTimeCheck time_check_;  // the latest usable frame's time, and each identifier's
  std::int64_t fault_until_ns_ = 0;                                     // 0: no input fault held
  bool fault_told_ = false;  // the fault as the monitor has it (a change goes before the frame)
  InputTimeCounters time_;
  InputDropCounters drops_;
  std::uint64_t lost_before_ = 0;  // frames lost (DROPCOUNT) before frame_
};

// A live SocketCAN bus. After each receive (at most kBusReceiveTimeoutMs): the frame, or the
// bus trouble reported (held kBusFaultHoldNs after the latest report, then cleared), then a
// tick at the newest frame's receive time: frames still queued in the socket are newer, and a
// monitor that fell behind must not count its own delay as a sensor timeout. Only with nothing
// to read is the wall clock the right time.
class BusInput final : public MonitorInput {
 public:
  BusInput(hal::SocketCanPort port, std::string interface_name, double duration_s,
           const volatile std::sig_atomic_t& stop)
      : port_(std::move(port)),
        interface_name_(std::move(interface_name)),
        duration_ns_(duration_s > 0.0 ? std::llround(duration_s * 1e9) : 0),
        stop_(stop) {}

  bool next(InputItem& item) override {
    switch (step_) {
      case Step::kReceive:
        if (!receive()) return false;
        step_ = Step::kFaultCleared;
        if (give_received(item)) return true;
        [[fallthrough]];
      case Step::kFaultCleared:
        step_ = Step::kTick;
        if (fault_until_ns_ != 0 && now_ns_ > fault_until_ns_) {
          fault_until_ns_ = 0;
          item.kind = InputItem::Kind::kBusFault;
          item.bus_fault = false;
          return true;
        }
        [[fallthrough]];
      case Step::kTick:
        step_ = Step::kReceive;
        item.kind = InputItem::Kind::kTick;
        item.time_ns = status_ == hal::IoStatus::kTimeout ? now_ns_ : last_frame_ns_;
        return true;
    }
    return false;
  }

  [[nodiscard]] const std::string& source() const override { return interface_name_; }
  [[nodiscard]] BusCounters bus_counters() const override {
    BusCounters c = counters_;
    c.dropped_frames = port_.total_dropped_frames();
    return c;
  }
  [[nodiscard]] hal::FrameSink* sink() override { return &port_; }

 private:
  enum class Step : std::uint8_t { kReceive, kFaultCleared, kTick };

  // Waits for the bus; false at the stop flag or after the duration.
  bool receive() {
    if (!started_) {
      started_ = true;
      end_ns_ = duration_ns_ > 0 ? hal::monotonic_now_ns() + duration_ns_ : INT64_MAX;
    }
    if (stop_ != 0 || hal::monotonic_now_ns() >= end_ns_) return false;
    status_ = port_.receive(frame_, kBusReceiveTimeoutMs);
    now_ns_ = hal::realtime_now_ns();
    if (status_ == hal::IoStatus::kTimeout) {
      // A last look after the clock is read: frames that came while this process waited to
      // run after its wait ended are older than now_ns_ and must be given before the tick at
      // now_ns_ (a starved guest counted sensor timeouts with no 50 ms silence on the bus).
      status_ = port_.receive(frame_, 0);
      if (status_ != hal::IoStatus::kTimeout) now_ns_ = hal::realtime_now_ns();
    }
    return true;
  }

  // What the receive brought: a frame, or bus trouble; false for nothing to give.
  bool give_received(InputItem& item) {
    switch (status_) {
      case hal::IoStatus::kOk:
        last_frame_ns_ = frame_.timestamp_ns;
        item.kind = InputItem::Kind::kFrame;
        item.frame = frame_;
        item.lost_before = lost_before_;
        lost_before_ = 0;
        return true;
      case hal::IoStatus::kBusError:
      case hal::IoStatus::kOverflow:
        ++(status_ == hal::IoStatus::kBusError ? counters_.bus_errors : counters_.overflows);
        if (status_ == hal::IoStatus::kOverflow) lost_before_ += port_.dropped_frames();
        fault_until_ns_ = now_ns_ + kBusFaultHoldNs;
        item.kind = InputItem::Kind::kBusFault;
        item.bus_fault = true;
        return true;
      case hal::IoStatus::kIoError:
        throw InputError("CAN interface " + interface_name_ +
                         ": receive failed: " + std::strerror(port_.last_error()));
      default:
        return false;
    }
  }

  hal::SocketCanPort port_;
  std::string interface_name_;
  std::int64_t duration_ns_;
  const volatile std::sig_atomic_t& stop_;
  bool started_ = false;
  std::int64_t end_ns_ = 0;
  Step step_ = Step::kReceive;
  hal::TimedFrame frame_;
  hal::IoStatus status_ = hal::IoStatus::kTimeout;
  std::int64_t now_ns_ = 0;
  std::int64_t last_frame_ns_ = 0;   // receive time of the newest frame
  std::int64_t fault_until_ns_ = 0;  // 0: no bus fault held
  std::uint64_t lost_before_ = 0;    // the kernel's drops before the next frame
  BusCounters counters_;
};

}  // namespace

bool is_candump_log(const std::string& path) {
  const std::string extension = std::filesystem::path(path).extension().string();
  return extension == ".log" || extension == ".LOG";
}

std::unique_ptr<MonitorInput> open_input(const InputOptions& opt, MonitorConfig& config,
                                         const volatile std::sig_atomic_t& stop) {
  const bool log = !opt.replay_path.empty() && is_candump_log(opt.replay_path);
  const bool record = !opt.replay_path.empty() && !log;
  if (!record &&
      (!opt.pga.empty() || opt.scale || !opt.replay_y_path.empty() || !opt.vertical_path.empty())) {
    throw InputError("--pga, --scale, --replay-y and --vertical apply to an AT2 or CSV record");
  }
  if (record) {
    RecordSamples samples = record_samples(
        {opt.replay_path, opt.replay_y_path, opt.vertical_path, opt.pga, opt.scale, opt.rate_hz},
        kStandardGravity);
    configure_record_replay(config, samples.rate_hz);
    const auto* pwave = monitor::built_part<monitor::PWaveSettings>(config.pwave);
    if (pwave != nullptr && pwave->enabled && pwave->channel == monitor::PWaveChannel::kVertical &&
        !samples.vertical) {
      // The stage would watch a vertical channel that never moves.
      throw InputError(opt.replay_path +
                       ": no vertical record for the P-wave stage's vertical channel: give "
                       "--vertical V.AT2, or pwave.channel = \"horizontal\" in the box file");
    }
    return std::make_unique<RecordInput>(opt.replay_path, std::move(samples), config, opt.speed,
                                         opt.recorder_frames, stop);
  }
  if (log) {
    hal::CandumpLogReaderOpenResult opened = hal::CandumpLogReader::open(opt.replay_path);
    if (!opened.ok()) throw InputError(opened.message);
    return std::make_unique<LogInput>(std::move(*opened.reader), opt.speed,
                                      opt.log_time.value_or(hal::LogPolicy::kWarn),
                                      opt.log_drops.value_or(hal::LogPolicy::kWarn), stop);
  }
  hal::SocketCanOpenResult opened = hal::SocketCanPort::open(opt.can_interface);
  if (!opened.ok()) throw InputError(opened.message);
  return std::make_unique<BusInput>(std::move(*opened.port), opt.can_interface, opt.duration_s,
                                    stop);
}

}  // namespace plinth::firmware
