// The box on the board: the compiled-in record (replay_case.h) replayed through the box's loop
// exactly as plinth-monitor --replay replays it (record_replay.h); the status and alarm frames the
// monitor hands over go out through the CAN stand-in, a candump log on the semihosting console;
// phase events, the cost per sample and the stack's high-water mark follow as '#' comment lines
// (docs/microcontroller.md). Exit status 0 when the replay ran to its end and every frame went out.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <span>

#include "plinth/core/events.h"
#include "plinth/core/scene.h"
#include "plinth/firmware/monitor.h"
#include "plinth/firmware/record_replay.h"
#include "plinth/firmware/replay_case.h"
#include "plinth/hal/board.h"
#include "plinth/hal/semihosting.h"
#include "plinth/hal/semihosting_can.h"
#include "plinth/hal/text_line.h"

namespace {

using namespace plinth;
namespace fw = plinth::firmware;
namespace board = plinth::hal::board;

// One instruction per ns of virtual time under qemu -icount shift=0, 25 ticks per us.
constexpr std::uint64_t kInstructionsPerTick = 1'000'000'000 / board::kTickHz;
constexpr std::int64_t kNsPerS = 1'000'000'000;

void print(const hal::TextLine& line) {
  hal::semihosting::write(line.c_str(), line.length());
  hal::semihosting::write("\n", 1);
}

// Ticks spent printing inside a timed region, to be taken out of its cost.
std::uint32_t g_untimed_ticks = 0;

// Phase events of one axis as comment lines, with the record's time (plinth-monitor's "t").
class EventPrinter final : public EventSink {
 public:
  EventPrinter(const char* axis, const fw::Monitor& monitor, std::int64_t origin_ns)
      : axis_(axis), monitor_(monitor), origin_ns_(origin_ns) {}
  void on_event(const Event& e) override {
    const std::uint32_t start = board::ticks();
    const std::int64_t t_ns =
        std::llround(e.t * 1e9) + monitor_.status().estimator_start_ns - origin_ns_;
    char text[128];
    hal::TextLine line(text, sizeof text);
    line.put("# event axis=").put(axis_).put(" t=").fixed(t_ns, 9);
    line.put(" event=").put(event_name(e.kind));
    if (e.kind == EventKind::kRockingStart || e.kind == EventKind::kOverturned ||
        e.kind == EventKind::kImpact) {
      line.put(" corner=").put(corner_name(e.corner));
    }
    print(line);
    ++count;
    g_untimed_ticks += board::ticks() - start;
  }
  std::uint64_t count = 0;

 private:
  const char* axis_;
  const fw::Monitor& monitor_;
  std::int64_t origin_ns_;
};

// Instructions per sample of one kind of samples, and the costliest one's record time.
struct Cost {
  std::uint64_t samples = 0;
  std::uint64_t ticks = 0;
  std::uint32_t max_ticks = 0;
  std::int64_t max_at_ns = 0;
  void add(std::uint32_t t, std::int64_t record_ns) {
    ++samples;
    ticks += t;
    if (t > max_ticks) {
      max_ticks = t;
      max_at_ns = record_ns;
    }
  }
  void print_as(const char* what) const {
    char text[160];
    hal::TextLine line(text, sizeof text);
    line.put("# cost ").put(what).put(": samples=").decimal(samples);
    // Mean to a tenth of an instruction.
    const std::uint64_t tenths = samples == 0 ? 0 : ticks * kInstructionsPerTick * 10 / samples;
    line.put(" mean_instructions=").fixed(static_cast<std::int64_t>(tenths), 1);
    line.put(" max_instructions=").decimal(std::uint64_t{max_ticks} * kInstructionsPerTick);
    line.put(" max_at_t=").fixed(max_at_ns, 9);
    print(line);
  }
};

// Which cost a sample counts to: every axis in full contact, some axis moving on the base, or
// none moving and some overturned or fallen (the estimator no longer steps).
enum class SampleKind { kQuiet, kMoving, kOver };
SampleKind kind_of(const fw::BoxStatus& s) {
  bool moving = false;
  bool over = false;
  for (int i = 0; i < s.axis_count; ++i) {
    const Phase phase = s.axes[static_cast<std::size_t>(i)].mode.phase;
    moving = moving || phase == Phase::kSliding || phase == Phase::kRocking ||
             phase == Phase::kSlideRocking;
    over = over || phase == Phase::kOverturned || phase == Phase::kFell;
  }
  return moving ? SampleKind::kMoving : (over ? SampleKind::kOver : SampleKind::kQuiet);
}

int fail(const char* what, const Error& e) {
  char text[200];
  hal::TextLine line(text, sizeof text);
  line.put("# end: FAILED: ").put(what).put(": ").put(e.field).put(" ").put(e.reason);
  print(line);
  return 1;
}

// Each axis's statues, the ensemble's members (replay_case.h).
std::array<std::array<Scene, kMaxEnsembleMembers>, fw::kMaxAxes> g_scenes;
fw::Monitor g_monitor;

// Makes the scenes of one axis; an empty span for an axis the case does not have.
Error make_axis(std::span<const SceneParams> members, std::array<Scene, kMaxEnsembleMembers>& out,
                std::span<const Scene>& scenes) {
  if (members.size() > out.size()) {
    return {ErrorCode::kOutOfRange, "ensemble",
            "has more members than this build holds (PLINTH_MAX_ENSEMBLE_MEMBERS)",
            static_cast<double>(out.size())};
  }
  for (std::size_t i = 0; i < members.size(); ++i) PLINTH_TRY(make_scene(members[i], out[i]));
  scenes = std::span<const Scene>(out.data(), members.size());
  return ok_error();
}

}  // namespace

extern "C" int plinth_board_main() {
  const fw::ReplayCase& replay = fw::kReplayCase;
  const hal::CompiledRecord& record = replay.record;
  {
    char text[400];
    hal::TextLine line(text, sizeof text);
    line.put("# plinth box on mps2-an386: ").put(replay.name).put(": plinth-monitor ");
    print(line.put(replay.command));
    // The scalar of the model's arithmetic (plinth/core/real.h): the host comparison's rule
    // (tests/cli/mcu_replay_check.py) follows it.
    hal::semihosting::write(sizeof(Real) == sizeof(double) ? "# real=double\n" : "# real=float\n");
  }
  const bool two_axes = !replay.y.empty();
  std::array<std::span<const Scene>, fw::kMaxAxes> scenes{};
  if (Error e = make_axis(replay.x, g_scenes[0], scenes[0]); !e.ok()) return fail("scene x", e);
  if (Error e = make_axis(replay.y, g_scenes[1], scenes[1]); !e.ok()) return fail("scene y", e);
  fw::MonitorConfig config = fw::box_defaults();
  config.axis_count = two_axes ? 2 : 1;
  if (replay.steps_per_sample > 0) config.estimator.steps_per_sample = replay.steps_per_sample;
  if (!replay.forecast) config.forecast.enabled = false;
  fw::configure_record_replay(config, record.sample_rate_hz);
  if constexpr (fw::kMaxSensors == 1) {
    // This build holds one sensor: no cross-check runs, and their windows, never filled, are
    // set within the build's window capacity.
    const double longest_s = fw::kMaxCheckWindowSamples / record.sample_rate_hz;
    config.redundancy.window_s = std::min(config.redundancy.window_s, longest_s);
    config.plate.window_s = std::min(config.plate.window_s, longest_s);
  }
  if (Error e = g_monitor.start(config, scenes); !e.ok()) {
    return fail("monitor settings", e);
  }
  const std::int64_t lead_in = fw::record_replay_lead_in(config);
  const std::int64_t origin_ns = std::llround(fw::record_replay_origin_s(config) * 1e9);
  EventPrinter events_x("x", g_monitor, origin_ns);
  EventPrinter events_y("y", g_monitor, origin_ns);
  g_monitor.set_event_sink(0, &events_x);
  if (two_axes) g_monitor.set_event_sink(1, &events_y);

  std::int64_t now_ns = 0;  // the CAN stand-in's clock: the receive time of the latest sample
  hal::SemihostingCanPort can("can0", &now_ns);
  std::uint64_t send_errors = 0;  // frames the CAN stand-in did not take
  std::array<Cost, 3> costs{};
  Cost all;
  const double gravity = kStandardGravity;
  for (std::int64_t n = 0; n < lead_in + record.count; ++n) {
    const monitor::SensorSample sample = fw::record_replay_sample(
        config, n, n < lead_in ? Eigen::Vector3d::Zero() : record.ground(n - lead_in, gravity),
        gravity);
    now_ns = sample.receive_time_ns;
    g_untimed_ticks = 0;
    const std::uint32_t start = board::ticks();
    const fw::MonitorUpdate update = g_monitor.on_sample(sample);
    const std::uint32_t ticks = board::ticks() - start - g_untimed_ticks;
    if (n >= lead_in) {
      const std::int64_t record_ns = sample.receive_time_ns - origin_ns;
      all.add(ticks, record_ns);
      costs[static_cast<std::size_t>(kind_of(*update.status))].add(ticks, record_ns);
    }
    for (std::size_t i = 0; i < update.frame_count; ++i) {
      if (can.send(update.frames[i]) != hal::IoStatus::kOk) ++send_errors;
    }
  }

  const fw::BoxStatus& s = g_monitor.status();
  char text[200];
  hal::TextLine line(text, sizeof text);
  line.put("# summary samples=").decimal(static_cast<std::uint64_t>(lead_in + record.count));
  line.put(" record_samples=").decimal(static_cast<std::uint64_t>(record.count));
  line.put(" final_phase=").put(phase_name(s.axes[0].mode.phase));
  line.put(" alarm=").put(monitor::alarm_level_name(s.alarm));
  line.put(" phase_events=").decimal(events_x.count + events_y.count);
  line.put(" sample_period_ns=")
      .decimal(static_cast<std::uint64_t>(std::llround(config.estimator.sample_period() * 1e9)));
  line.put(" frames=")
      .decimal(can.frames_sent())
      .put(" send_errors=")
      .decimal(send_errors + g_monitor.frames_not_encoded());
  print(line);
  all.print_as("per_sample");
  costs[0].print_as("per_sample_quiet");
  costs[1].print_as("per_sample_moving");
  costs[2].print_as("per_sample_over");
  hal::TextLine stack(text, sizeof text);
  stack.put("# stack used_bytes=").decimal(static_cast<std::uint64_t>(board::stack_used_bytes()));
  print(stack.put(" size_bytes=").decimal(static_cast<std::uint64_t>(board::stack_size_bytes())));
  const bool ok = send_errors + g_monitor.frames_not_encoded() == 0;
  hal::semihosting::write(ok ? "# end: ok\n" : "# end: FAILED: frames not sent\n");
  return ok ? 0 : 1;
}
