// Single against double precision on the M4F (ctest precision_bench; docs/microcontroller.md),
// before the core has a scalar type: the rocking phase's arithmetic, Eq 8 with the base coupled
// and RK4 on Eigen's fixed-size vectors as lib/core does it, written once as a template and run
// in float (the FPU) and in double (libgcc's software routines) on the compiled-in case's first
// scene, from theta = 0.05 rad about corner 1 under the record's first seconds, for
// kSteps steps of 0.25 ms (1000 Hz x 4) or until the block lands; and the exact full-contact
// propagation's 4x4 matrix-vector product. Prints instructions per step of each and how far the
// float trajectory drifts from the double one (rad, and in steps of theta' at the end).
// Counts are instructions under qemu -icount shift=0 (40 per tick of the board's counter).
#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "plinth/core/scene.h"
#include "plinth/firmware/replay_case.h"
#include "plinth/hal/board.h"
#include "plinth/hal/semihosting.h"
#include "plinth/hal/text_line.h"

namespace {

using namespace plinth;
namespace board = plinth::hal::board;

constexpr std::uint64_t kInstructionsPerTick = 1'000'000'000 / board::kTickHz;
constexpr double kStepS = 0.00025;  // the estimator's step at 1000 Hz x 4
constexpr int kSteps = 8000;        // 2 s
constexpr int kPropagations = 2000;
constexpr double kStartAngleRad = 0.05;

// The scene's numbers Eq 8 needs, in T.
template <typename T>
struct RockingScene {
  T m, total_mass, damping, stiffness, g, inertia, offset, h;
};

template <typename T>
RockingScene<T> rocking_scene(const Scene& s) {
  const CornerGeometry& c = s.corner1;
  return {T(s.m), T(s.total_mass), T(s.damping), T(s.stiffness),
          T(s.g), T(c.inertia),    T(c.offset),  T(s.h)};
}

using std::cos;
using std::sin;

// (u, theta, u', theta') -> their derivatives, Eq 8 about corner 1 with the base coupled.
template <typename T>
Eigen::Matrix<T, 4, 1> rocking_derivative(const RockingScene<T>& s, const Eigen::Matrix<T, 4, 1>& y,
                                          T ground) {
  const T sin_t = sin(y[1]);
  const T cos_t = cos(y[1]);
  const T arm_h = s.offset * cos_t + s.h * sin_t;  // b'_i
  const T arm_v = s.h * cos_t - s.offset * sin_t;  // h'_i
  const T coupling = s.m * arm_v;
  const T force_u =
      -s.total_mass * ground - s.damping * y[2] - s.stiffness * y[0] + s.m * y[3] * y[3] * arm_h;
  const T force_theta = coupling * ground - s.m * s.g * arm_h;
  const T inverse_det = T(1) / (s.total_mass * s.inertia - coupling * coupling);
  Eigen::Matrix<T, 4, 1> d;
  d << y[2], y[3], (s.inertia * force_u + coupling * force_theta) * inverse_det,
      (coupling * force_u + s.total_mass * force_theta) * inverse_det;
  return d;
}

template <typename T>
Eigen::Matrix<T, 4, 1> rk4_step(const RockingScene<T>& s, const Eigen::Matrix<T, 4, 1>& y,
                                T ground0, T ground_mid, T ground1, T h) {
  const Eigen::Matrix<T, 4, 1> k1 = rocking_derivative(s, y, ground0);
  const Eigen::Matrix<T, 4, 1> k2 = rocking_derivative(s, (y + T(0.5) * h * k1).eval(), ground_mid);
  const Eigen::Matrix<T, 4, 1> k3 = rocking_derivative(s, (y + T(0.5) * h * k2).eval(), ground_mid);
  const Eigen::Matrix<T, 4, 1> k4 = rocking_derivative(s, (y + h * k3).eval(), ground1);
  return y + (h / T(6)) * (k1 + T(2) * k2 + T(2) * k3 + k4);
}

struct Run {
  std::uint32_t ticks = 0;
  int steps = 0;
  double theta = 0.0;
  double theta_dot = 0.0;
};

// Rocks from kStartAngleRad until theta returns to 0 (the impact) or kSteps.
template <typename T>
Run rock(const Scene& scene, const hal::CompiledRecord& record) {
  const RockingScene<T> s = rocking_scene<T>(scene);
  Eigen::Matrix<T, 4, 1> y(T(0), T(kStartAngleRad), T(0), T(0));
  const T h = T(kStepS);
  const double record_dt = 1.0 / record.sample_rate_hz;
  const auto ground_at = [&](double t) {
    const auto k = static_cast<std::int64_t>(t / record_dt);
    return T(k < record.count ? record.x[k] : 0.0);
  };
  Run run;
  const std::uint32_t start = board::ticks();
  for (; run.steps < kSteps && y[1] > T(0); ++run.steps) {
    const double t = run.steps * kStepS;
    y = rk4_step(s, y, ground_at(t), ground_at(t + 0.5 * kStepS), ground_at(t + kStepS), h);
  }
  run.ticks = board::ticks() - start;
  run.theta = static_cast<double>(y[1]);
  run.theta_dot = static_cast<double>(y[3]);
  return run;
}

// kPropagations products of a 4x4 transition matrix (full contact's exact propagation) with
// the state; returns the ticks and a result so the work is kept.
template <typename T>
std::uint32_t propagate(T& result) {
  Eigen::Matrix<T, 4, 4> phi;
  phi << T(0.99), T(0.0002), T(0.001), T(0.0),  //
      T(-0.1), T(0.99), T(0.0), T(0.001),       //
      T(0.0), T(0.0), T(1.0), T(0.0),           //
      T(0.0), T(0.0), T(0.0), T(1.0);
  Eigen::Matrix<T, 4, 1> y(T(0.01), T(0.0), T(0.0), T(0.0));
  const std::uint32_t start = board::ticks();
  for (int i = 0; i < kPropagations; ++i) y = (phi * y).eval();
  const std::uint32_t ticks = board::ticks() - start;
  result = y[0];
  return ticks;
}

void print_cost(const char* what, const char* precision, std::uint32_t ticks, int count) {
  char text[160];
  hal::TextLine line(text, sizeof text);
  const std::uint64_t tenths =
      count > 0 ? std::uint64_t{ticks} * kInstructionsPerTick * 10 / static_cast<unsigned>(count)
                : 0;
  line.put("# precision ").put(what).put(" ").put(precision).put(": count=");
  line.decimal(static_cast<std::int64_t>(count));
  line.put(" mean_instructions=").fixed(static_cast<std::int64_t>(tenths), 1);
  hal::semihosting::write(line.c_str(), line.length());
  hal::semihosting::write("\n", 1);
}

Scene g_scene;

}  // namespace

extern "C" int plinth_board_main() {
  const firmware::ReplayCase& replay = firmware::kReplayCase;
  if (!make_scene(replay.x[0], g_scene).ok() || !g_scene.has_base()) {
    hal::semihosting::write("# end: FAILED: the case's first scene has no base\n");
    return 1;
  }
  const Run single = rock<float>(g_scene, replay.record);
  const Run dual = rock<double>(g_scene, replay.record);
  print_cost("rocking_rk4_step", "float", single.ticks, single.steps);
  print_cost("rocking_rk4_step", "double", dual.ticks, dual.steps);
  float float_sink = 0.0F;
  double double_sink = 0.0;
  print_cost("propagation_4x4", "float", propagate(float_sink), kPropagations);
  print_cost("propagation_4x4", "double", propagate(double_sink), kPropagations);
  // The drift: nano-radians of theta at the end, the end's step count.
  char text[200];
  hal::TextLine line(text, sizeof text);
  line.put("# precision drift: steps_float=").decimal(static_cast<std::int64_t>(single.steps));
  line.put(" steps_double=").decimal(static_cast<std::int64_t>(dual.steps));
  line.put(" theta_difference_nrad=")
      .decimal(static_cast<std::int64_t>(std::llround((single.theta - dual.theta) * 1e9)));
  line.put(" theta_dot_difference_urad_s=")
      .decimal(static_cast<std::int64_t>(std::llround((single.theta_dot - dual.theta_dot) * 1e6)));
  hal::semihosting::write(line.c_str(), line.length());
  hal::semihosting::write("\n", 1);
  const bool ok = single.steps > 0 && dual.steps > 0 && float_sink != 0.0F && double_sink != 0.0;
  hal::semihosting::write(ok ? "# end: ok\n" : "# end: FAILED\n");
  return ok ? 0 : 1;
}
