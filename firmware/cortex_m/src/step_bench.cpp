// Instructions per solver step on the board (ctest step_bench; docs/microcontroller.md), with the
// estimator's settings at a 1000 Hz sensor rate and 4 steps per sample (rk4_located, full contact
// propagated exactly) on the compiled-in case's first scene:
//  - quiet full contact: from rest under the record's first second (no phase change);
//  - rocking: from theta = 0.05 rad about the left corner, no ground motion, until the block
//    stops rocking or 10 s (impacts included), as tests/bench's BM_PhaseStep/rocking_base;
//  - the exact full-contact propagator made for a partial step (what locating an event out of
//    full contact does at every iteration).
// Counts are instructions under qemu -icount shift=0 (40 per tick of the board's counter).
#include <cstdint>

#include "plinth/core/estimator.h"
#include "plinth/core/internal/full_contact_propagator.h"
#include "plinth/core/simulator.h"
#include "plinth/firmware/replay_case.h"
#include "plinth/hal/board.h"
#include "plinth/hal/semihosting.h"
#include "plinth/hal/text_line.h"

namespace {

using namespace plinth;
namespace board = plinth::hal::board;

constexpr std::uint64_t kInstructionsPerTick = 1'000'000'000 / board::kTickHz;
constexpr double kSampleRateHz = 1000.0;
constexpr int kStepsPerSample = 4;
constexpr std::int64_t kQuietSteps = 4000;        // 1 s
constexpr std::int64_t kMaxRockingSteps = 40000;  // 10 s
constexpr int kPropagatorRuns = 20;

bool report(const char* what, std::uint64_t ticks, std::int64_t count, const char* unit) {
  char text[160];
  hal::TextLine line(text, sizeof text);
  const std::uint64_t tenths =
      count > 0 ? ticks * kInstructionsPerTick * 10 / static_cast<std::uint64_t>(count) : 0;
  line.put("# step ").put(what).put(": ").put(unit).put("=").decimal(
      static_cast<std::int64_t>(count));
  line.put(" mean_instructions=").fixed(static_cast<std::int64_t>(tenths), 1);
  hal::semihosting::write(line.c_str(), line.length());
  hal::semihosting::write("\n", 1);
  return count > 0;
}

Scene g_scene;
Simulator g_simulator;

}  // namespace

extern "C" int plinth_board_main() {
  const firmware::ReplayCase& replay = firmware::kReplayCase;
  EstimatorSettings estimator;
  estimator.sample_rate_hz = kSampleRateHz;
  estimator.steps_per_sample = kStepsPerSample;
  SolverSettings settings = estimator.solver;
  settings.step = estimator.step();
  const hal::CompiledRecord& record = replay.record;
  const Excitation ground = Excitation::record(
      SampledSignal{record.x, static_cast<std::size_t>(record.count), 1.0 / record.sample_rate_hz});
  if (!make_scene(replay.x[0], g_scene).ok() ||
      !Simulator::create(g_scene, ground, settings, g_simulator).ok()) {
    hal::semihosting::write("# end: FAILED: scene or solver settings\n");
    return 1;
  }
  bool ok = true;

  g_simulator.start_at_rest();
  std::uint32_t start = board::ticks();
  while (g_simulator.step_count() < kQuietSteps &&
         g_simulator.mode().phase == Phase::kFullContact) {
    g_simulator.step();
  }
  const std::uint32_t quiet_ticks = board::ticks() - start;
  ok = report("full_contact_quiet", quiet_ticks, g_simulator.step_count(), "steps") && ok;
  ok = ok && g_simulator.mode().phase == Phase::kFullContact;

  Simulator rocking;
  if (!Simulator::create(g_scene, Excitation::none(), settings, rocking).ok()) ok = false;
  State y = State::Zero();
  y[kTheta] = Real(0.05);
  rocking.start_from({Phase::kRocking, Corner::kLeft}, y);
  start = board::ticks();
  while (rocking.step_count() < kMaxRockingSteps && rocking.mode().phase == Phase::kRocking) {
    rocking.step();
  }
  const std::uint32_t rocking_ticks = board::ticks() - start;
  ok = report("rocking", rocking_ticks, rocking.step_count(), "steps") && ok;

  Real sink = 0;
  start = board::ticks();
  for (int i = 0; i < kPropagatorRuns; ++i) {
    const auto partial_step = static_cast<Real>(settings.step * (0.5 + 0.01 * i));
    sink += internal::FullContactPropagator::make(g_scene, partial_step).phi[0][0];
  }
  const std::uint32_t propagator_ticks = board::ticks() - start;
  ok =
      report("propagator_make", propagator_ticks, kPropagatorRuns, "calls") && ok && sink > Real(0);

  hal::semihosting::write(ok ? "# end: ok\n" : "# end: FAILED\n");
  return ok ? 0 : 1;
}
