// libFuzzer target: the box's loop, firmware/monitor's Monitor, fed frame sequences decoded from
// the input. Byte 0 chooses the box (bits 0-1: 1 to 3 sensors, bit 2: the third on the plate,
// bit 3: stuck check off, bit 4: the forecast on); then operations, each an opcode byte and its
// operands (missing operands read as 0):
//   0 sample    node, sequence step (0 duplicate, 1 next, 2-127 a gap, 128-255 behind), flags,
//               ax, ay, az (int8 each, 1/64 g; az about 1 g), dt (0.25 ms units)
//   1 run       count, node, ax, amplitude (1/64 g): `count` samples of ax (+- amplitude
//               dither, so not stuck) at 200 Hz, sequence counting up and wrapping
//   2 raw       identifier (2 bytes, little endian), length, 8 data bytes, dt: any frame
//   3 tick      dt (1 ms units): on_tick
//   4 bus       set_bus_fault(operand & 1)
//   5 ack       level, sequence: an Acknowledge frame
//   6 late      dt (0.25 ms units): the receive clock steps back (a late frame's timestamp)
//   7 restart   Monitor::start again (a watchdog reset)
// At most kMaxFramesPerInput frames are sent. After every call the check function below: the
// estimator's invariants (finite state, phase and mode consistent, risk and probability in [0, 1]),
// never normal while not estimating or not calibrated, the heartbeat (a status at least every
// heartbeat period of monitor time), and that a fault reports what was rejected (its cause is the
// one the monitor's inputs give).
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fuzz_check.h"
#include "plinth/core/scene.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/firmware/monitor.h"
#include "plinth/hal/can_codec.h"

namespace {

namespace fw = plinth::firmware;
namespace mon = plinth::monitor;
namespace can = plinth::hal::can;
using plinth::fuzz::check;

constexpr double kRateHz = 200.0;
constexpr std::int64_t kPeriodNs = 5'000'000;
// Frames per input at most (10 s at 200 Hz: start-up and verification windows, timeouts and
// heartbeats all fit); keeps an execution short so the suite's short run stays short.
constexpr int kMaxFramesPerInput = 2000;

// The paper's isolated block with base stops (every kind of phase is reachable).
const plinth::Scene& scene() {
  static const plinth::Scene s = [] {
    plinth::SceneParams p;
    p.block.half_width = 0.3;
    p.block.com_height = 0.9;
    p.block.mass = 2000.0 * 0.6 * 1.8;
    p.block.inertia = plinth::homogeneous_rectangle_inertia(p.block.mass, 0.3, 0.9);
    p.has_base = true;
    p.base.mass = p.block.mass;
    p.base.period = 2.0;
    p.base.damping_ratio = 0.2;
    plinth::Scene out;
    check(plinth::make_scene(p, out).ok(), "the fuzz scene is valid");
    return out;
  }();
  return s;
}

fw::MonitorConfig box_config(std::uint8_t choice) {
  fw::MonitorConfig c;
  c.estimator.sample_rate_hz = kRateHz;
  c.estimator.steps_per_sample = 1;
  c.conditioning.startup_window_s = 0.05;  // 10 samples: the fuzzer reaches estimating soon
  c.sensor_health.recovery_samples = 3;
  c.sensor_health.stuck_samples = (choice & 0x08) != 0 ? 0 : 20;
  c.forecast.enabled = (choice & 0x10) != 0;  // the ensemble's look ahead costs: on request
  const int sensors = 1 + (choice & 0x03) % 3;
  if (sensors > 1) {
    c.sensor_count = sensors;
    for (int i = 0; i < sensors; ++i) {
      fw::SensorConfig& s = c.sensors[static_cast<std::size_t>(i)];
      s.node = static_cast<std::uint8_t>(i + 1);
      s.role = i == 2 && (choice & 0x04) != 0 ? fw::SensorRole::kPlate : fw::SensorRole::kGround;
      s.conditioning = c.conditioning;
      s.sensor_health = c.sensor_health;
    }
  }
  return c;
}

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  [[nodiscard]] bool done() const { return at_ >= size_; }
  std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  double g64() { return static_cast<double>(static_cast<std::int8_t>(byte())) / 64.0; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

class Harness {
 public:
  explicit Harness(std::uint8_t choice) : config_(box_config(choice)) { restart(); }

  void restart() {
    check(box_->start(config_, {&scene(), nullptr}).ok(), "the fuzz configuration starts");
    decoder_.start(config_);
    last_status_ns_ = 0;
    have_status_ = false;
    last_time_ns_ = 0;
    rejected_ = 0;
  }

  [[nodiscard]] bool spent() const { return frames_sent_ >= kMaxFramesPerInput; }

  void step(Reader& in) {
    switch (in.byte() % 8) {
      case 0:
        sample(in);
        break;
      case 1:
        run(in);
        break;
      case 2:
        raw(in);
        break;
      case 3:
        clock_ns_ += static_cast<std::int64_t>(in.byte()) * 1'000'000;
        after(box_->on_tick(clock_ns_));
        break;
      case 4:
        box_->set_bus_fault((in.byte() & 1) != 0);
        break;
      case 5:
        acknowledge(in);
        break;
      case 6:
        clock_ns_ -= static_cast<std::int64_t>(in.byte()) * 250'000;
        break;
      case 7:
        restart();
        break;
    }
  }

 private:
  void send(const can::CanFrame& frame) {
    if (frames_sent_ >= kMaxFramesPerInput) return;
    ++frames_sent_;
    after(fw::on_frame(*box_, decoder_, {frame, clock_ns_}));
  }

  void sensor_frame(std::uint8_t node, double ax, double ay, double az, std::uint8_t flags) {
    can::SensorAcceleration m;
    m.node = static_cast<std::uint8_t>(1 + node % 15);
    m.ax_g = ax;
    m.ay_g = ay;
    m.az_g = az;
    m.sequence = sequences_[m.node];
    m.status = flags;
    can::CanFrame f;
    if (can::encode(m, f).ok()) send(f);
  }

  void sample(Reader& in) {
    const std::uint8_t node = in.byte();
    const std::uint8_t step = in.byte();
    const std::uint8_t flags = in.byte();
    const double ax = in.g64();
    const double ay = in.g64();
    const double az = 1.0 + in.g64();
    clock_ns_ += static_cast<std::int64_t>(in.byte()) * 250'000;
    const auto n = static_cast<std::uint8_t>(1 + node % 15);
    sequences_[n] = static_cast<std::uint8_t>(sequences_[n] + step);
    sensor_frame(node, ax, ay, az, flags);
  }

  void run(Reader& in) {
    const int count = in.byte();
    const std::uint8_t node = in.byte();
    const double ax = in.g64();
    const double amplitude = in.g64() / 64.0;
    const auto n = static_cast<std::uint8_t>(1 + node % 15);
    for (int k = 0; k < count; ++k) {
      clock_ns_ += kPeriodNs;
      ++sequences_[n];
      sensor_frame(node, ax + (k % 2 == 0 ? amplitude : -amplitude), 0.0, 1.0, 0);
    }
  }

  void raw(Reader& in) {
    can::CanFrame f;
    f.id = static_cast<std::uint32_t>(in.byte() | (in.byte() << 8)) & 0x7FF;
    f.length = in.byte();
    for (std::uint8_t& b : f.data) b = in.byte();
    clock_ns_ += static_cast<std::int64_t>(in.byte()) * 250'000;
    send(f);
  }

  void acknowledge(Reader& in) {
    can::Acknowledge a;
    a.level = static_cast<can::AlarmLevel>(in.byte() % 5);
    a.event_sequence = in.byte();
    can::CanFrame f;
    if (can::encode(a, f).ok()) send(f);
  }

  // The check function, after every call.
  void after(const fw::MonitorUpdate& u) {
    const fw::BoxStatus& s = box_->status();
    check(u.status == &s, "an update carries the monitor's status");
    check(s.time_ns >= last_time_ns_, "monitor time never goes back");
    last_time_ns_ = s.time_ns;
    check_estimator(s);
    check(s.alarm != mon::AlarmLevel::kNormal || (s.estimating && s.calibrated),
          "never normal while not estimating or not calibrated");
    if (u.status_due) {
      check(u.frame_count >= static_cast<std::size_t>(s.axis_count) + u.event_count ||
                box_->frames_not_encoded() > 0,
            "a due status carries its frames");
      last_status_ns_ = s.time_ns;
      have_status_ = true;
    }
    check(have_status_, "the first update reports a status");
    check(s.time_ns - last_status_ns_ <
              static_cast<std::int64_t>(config_.alarm.heartbeat_period_s * 1e9),
          "a status at least every heartbeat period");
    for (std::size_t i = 0; i < u.event_count; ++i) check_event(s, u.events[i]);
    const fw::FrameCounters& c = decoder_.counters();
    if (c.rejected > rejected_) {
      check(c.last_error != can::CodecError::kOk, "a rejected frame names its error");
    }
    rejected_ = c.rejected;
  }

  void check_estimator(const fw::BoxStatus& s) {
    check(std::isfinite(s.risk) && s.risk >= 0.0 && s.risk <= 1.0, "risk in [0, 1]");
    check(std::isfinite(s.probability) && s.probability >= 0.0 && s.probability <= 1.0,
          "probability in [0, 1]");
    for (int i = 0; i < s.axis_count; ++i) {
      const fw::AxisStatus& a = s.axes[static_cast<std::size_t>(i)];
      check(a.state.allFinite(), "finite state");
      const auto phase = static_cast<int>(a.mode.phase);
      check(phase >= 0 && phase <= static_cast<int>(plinth::Phase::kFell), "a known phase");
      check(a.mode.rocking() || a.mode.phase == plinth::Phase::kFullContact ||
                a.mode.phase == plinth::Phase::kSliding || a.mode.terminal(),
            "phase is one of the model's");
      check(a.mode.phase != plinth::Phase::kFullContact || a.mode.slide_direction == 0,
            "no slide direction in full contact");
      check(std::abs(a.mode.overhang) <= 1 && std::abs(a.mode.held_stop) <= 1,
            "overhang and held stop are -1, 0 or +1");
      check(a.risk.total >= 0.0 && a.risk.total <= 1.0, "axis risk in [0, 1]");
      check(!s.estimating || box_->ensemble(i).nominal().time() >= 0.0, "estimator time >= 0");
    }
  }

  // A fault event reports what was rejected: the cause the monitor's inputs give now.
  void check_event(const fw::BoxStatus& s, const mon::AlarmEventRecord& e) {
    if (e.level != mon::AlarmLevel::kFault || e.cause == mon::AlarmCause::kAcknowledged) return;
    // From alarm the fault may be one held beneath it; fault to fault is a latch change.
    if (e.previous_level != mon::AlarmLevel::kAlarm &&
        e.previous_level != mon::AlarmLevel::kFault) {
      // Entered at once from a lower risk level: a fault input is active now.
      if (s.sensor.state == mon::HealthState::kFault) {
        check(e.cause == mon::to_alarm_cause(s.sensor.cause), "a sensor fault names its cause");
      } else if (s.disagreement) {
        check(e.cause == mon::AlarmCause::kSensorDisagreement, "a disagreement is named");
      } else if (!s.estimating || !s.calibrated) {
        check(e.cause == mon::AlarmCause::kNotCalibrated || e.cause == mon::AlarmCause::kBusError,
              "an uncalibrated box says not_calibrated (or the bus fault beneath)");
      } else {
        check(e.cause == mon::AlarmCause::kBusError ||
                  e.cause == mon::AlarmCause::kSensorDisagreement,
              "a fault with no sensor cause is the bus's or the plate's");
      }
    }
  }

  fw::MonitorConfig config_;
  std::unique_ptr<fw::Monitor> box_ = std::make_unique<fw::Monitor>();
  fw::FrameDecoder decoder_;
  std::int64_t clock_ns_ = 0;
  std::array<std::uint8_t, 16> sequences_{};
  std::int64_t last_status_ns_ = 0;
  bool have_status_ = false;
  std::int64_t last_time_ns_ = 0;
  std::uint64_t rejected_ = 0;
  int frames_sent_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in(data, size);
  Harness box(in.byte());
  for (int ops = 0; !in.done() && !box.spent() && ops < 4096; ++ops) box.step(in);
  return 0;
}
