// The P-wave stage in the box's loop (MonitorConfig::pwave, docs/pwave.md): fed the primary's
// conditioned samples, it raises `warning` with cause p_wave ahead of the statue's physics on a
// bundled three-component record, never `alarm`, and nothing on the synthesised nuisance
// signals (nuisance_signals.h) the stage's own tests use.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "nuisance_signals.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/pwave_records.h"
#include "plinth/host/record_io.h"
#include "plinth/host/record_sampling.h"
#include "test_paths.h"
#include "test_support.h"

namespace plinth::monitor_pwave_test {
namespace {

namespace fw = firmware;
using ::plinth::testing::ns;

constexpr double kRateHz = 200.0;
constexpr double kQuietS = 20.0;  // before the motion: the start-up window, the fault's hold

fw::MonitorConfig pwave_config(bool stage) {
  fw::MonitorConfig config;
  config.estimator.sample_rate_hz = kRateHz;
  config.conditioning.startup_window_s = 1.0;
  config.sensor_health.stuck_samples = 0;  // the quiet lead-in repeats itself
  if (auto* p = monitor::built_part<monitor::PWaveSettings>(config.pwave); p != nullptr && stage) {
    p->enabled = true;
    p->fragility_known = true;
    p->fragility = {0.6, 0.3};  // median 0.6 g, beta 0.3
  }
  return config;
}

// What a run shows: the first time (s after the motion's start) each level is first shown and
// the cause of its event; the stage's counters.
struct Shown {
  double warning_s = -1.0;
  monitor::AlarmCause warning_cause = monitor::AlarmCause::kNone;
  double alarm_s = -1.0;
  monitor::AlarmCause alarm_cause = monitor::AlarmCause::kNone;
  bool p_wave_alarm = false;  // an alarm event with cause p_wave (never)
  bool any_p_wave = false;    // any event with cause p_wave
  monitor::PWaveStatus pwave;
};

// `quiet_s` of sensor noise (1 mg), then `motion` (m/s2, statue frame, z up), as a ground
// sensor's samples in g at kRateHz.
Shown run(const fw::MonitorConfig& config, const std::vector<Eigen::Vector3d>& motion) {
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  fw::Monitor monitor;
  EXPECT_TRUE(monitor.start(config, {&scene, nullptr}).ok());
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1e-3);
  const auto quiet = static_cast<long>(kQuietS * kRateHz);
  const long total = quiet + static_cast<long>(motion.size());
  Shown out;
  for (long n = 0; n < total; ++n) {
    const Eigen::Vector3d a =
        n < quiet ? Eigen::Vector3d::Zero() : motion[static_cast<std::size_t>(n - quiet)];
    monitor::SensorSample s;
    s.receive_time_ns = ns(static_cast<double>(n) / kRateHz);
    s.sequence = static_cast<std::uint8_t>(n & 0xFF);
    s.acceleration_g = a / kStandardGravity + Eigen::Vector3d(noise(rng), noise(rng), 1.0 + noise(rng));
    const fw::MonitorUpdate u = monitor.on_sample(s);
    const double t = static_cast<double>(n - quiet) / kRateHz;
    for (std::size_t i = 0; i < u.event_count; ++i) {
      const monitor::AlarmEventRecord& e = u.events[i];
      out.any_p_wave = out.any_p_wave || e.cause == monitor::AlarmCause::kPWave;
      if (e.level == monitor::AlarmLevel::kAlarm) {
        out.p_wave_alarm = out.p_wave_alarm || e.cause == monitor::AlarmCause::kPWave;
        if (out.alarm_s < 0.0) {
          out.alarm_s = t;
          out.alarm_cause = e.cause;
        }
      }
      if (n >= quiet && out.warning_s < 0.0 && e.level >= monitor::AlarmLevel::kWarning &&
          e.level != monitor::AlarmLevel::kFault) {
        out.warning_s = t;
        out.warning_cause = e.cause;
      }
    }
    if (monitor.status().axes[0].mode.terminal()) break;
  }
  EXPECT_EQ(monitor.status().has_pwave, config.pwave.enabled);
  if (const auto* p = monitor::built_part<monitor::PWaveStatus>(monitor.status().pwave)) {
    out.pwave = *p;
  }
  return out;
}

// Northridge-01 at Orr (RSN963), horizontal 090 and vertical, scaled to 2 g (3.3 times the
// statue's median): its P wave comes more than 3 s before its strong motion.
TEST(MonitorPWave, WarnsWithCausePWaveAheadOfThePhysicsAndNeverAlarms) {
  if (!monitor::kPWaveStageBuiltIn) GTEST_SKIP() << "PLINTH_PWAVE_STAGE=OFF";
  const std::string dir = testing::kSource + "/sim/data/records/pwave/";
  host::Record record = host::read_at2(dir + "RSN963_NORTHR_ORR090.AT2", kStandardGravity);
  host::attach_vertical(record, host::read_at2(dir + "RSN963_NORTHR_ORR-UP.AT2", kStandardGravity),
                        "RSN963_NORTHR_ORR-UP.AT2");
  const host::RecordPhases phases = host::record_phases(record);
  ASSERT_GE(phases.p_lead_s(), 3.0);
  const double gamma = 2.0 * kStandardGravity / record.peak_horizontal();
  const std::size_t count = host::sample_count(record.duration(), kRateHz);
  const std::vector<double> h = host::resample(record.horizontal_signal(), kRateHz, count);
  const std::vector<double> v = host::resample(record.vertical_signal(), kRateHz, count);
  std::vector<Eigen::Vector3d> motion;
  for (std::size_t k = 0; k < count; ++k) motion.emplace_back(gamma * h[k], 0.0, gamma * v[k]);

  const Shown without = run(pwave_config(false), motion);
  const Shown with = run(pwave_config(true), motion);
  ASSERT_GE(without.warning_s, 0.0);  // the physics warns...
  ASSERT_GE(without.alarm_s, 0.0);    // ...and alarms: the statue falls
  EXPECT_FALSE(without.any_p_wave);
  EXPECT_EQ(with.pwave.triggers, 1U);
  ASSERT_GE(with.warning_s, 0.0);
  EXPECT_EQ(with.warning_cause, monitor::AlarmCause::kPWave);
  EXPECT_LT(with.warning_s, phases.strong_motion_s);
  EXPECT_LT(with.warning_s + 1.0, without.warning_s);  // at least a second ahead of the physics
  // The alarm stays the physics': the same time and cause with the stage as without it.
  EXPECT_FALSE(with.p_wave_alarm);
  EXPECT_EQ(with.alarm_s, without.alarm_s);
  EXPECT_EQ(with.alarm_cause, without.alarm_cause);
  EXPECT_GE(with.pwave.probability, 0.8);
  RecordProperty("warning_s", std::to_string(with.warning_s) + " with the stage, " +
                                  std::to_string(without.warning_s) + " without; strong motion " +
                                  std::to_string(phases.strong_motion_s) + " s");
}

void expect_nothing(const testing::Motion& m, const std::string& what) {
  const Shown shown = run(pwave_config(true), m.acceleration_m_s2());
  EXPECT_EQ(shown.pwave.triggers, 0U) << what;
  EXPECT_EQ(shown.pwave.probability, 0.0) << what;
  EXPECT_FALSE(shown.any_p_wave) << what;
}

// The nuisance signals of test_p_wave.cpp's PWaveNuisance (their strongest and weakest
// settings), through the box: no trigger, no p_wave event.
TEST(MonitorPWave, NuisanceSignalsDoNotTriggerThroughTheBox) {
  if (!monitor::kPWaveStageBuiltIn) GTEST_SKIP() << "PLINTH_PWAVE_STAGE=OFF";
  for (const double floor_hz : {5.0, 12.0}) {
    for (const double peak_g : {0.005, 0.015}) {
      testing::FootstepModel m;
      m.floor_hz = floor_hz;
      m.peak_g = peak_g;
      expect_nothing(testing::footsteps(m, kRateHz),
                     "footsteps " + std::to_string(floor_hz) + " Hz " + std::to_string(peak_g));
    }
  }
  for (const double mode_hz : {15.0, 40.0}) {
    testing::BurstModel m;
    m.mode_hz = mode_hz;
    m.peak_g = 0.2;
    expect_nothing(testing::door(m, kRateHz), "door " + std::to_string(mode_hz) + " Hz");
  }
  for (const auto& [low, high] : {std::pair{3.0, 10.0}, {10.0, 30.0}}) {
    testing::TrafficModel m;
    m.low_hz = low;
    m.high_hz = high;
    m.peak_g = 0.02;
    expect_nothing(testing::traffic(m, kRateHz), "traffic from " + std::to_string(low) + " Hz");
  }
  for (const double mode_hz : {10.0, 40.0}) {
    for (const double peak_g : {0.1, 1.0}) {
      testing::BurstModel m;
      m.mode_hz = mode_hz;
      m.zeta = 0.08;
      m.peak_g = peak_g;
      expect_nothing(testing::bump(m, kRateHz),
                     "bump " + std::to_string(mode_hz) + " Hz " + std::to_string(peak_g) + " g");
    }
  }
}

// Without the scene's fragility the stage would never give a probability: start() refuses it.
TEST(MonitorPWave, RefusesTheStageWithoutAFragility) {
  if (!monitor::kPWaveStageBuiltIn) GTEST_SKIP() << "PLINTH_PWAVE_STAGE=OFF";
  fw::MonitorConfig config = pwave_config(true);
  monitor::built_part<monitor::PWaveSettings>(config.pwave)->fragility_known = false;
  const Scene scene = testing::make(testing::paper_isolated(0.0));
  fw::Monitor monitor;
  const Error e = monitor.start(config, {&scene, nullptr});
  EXPECT_EQ(e.code, ErrorCode::kInconsistent);
  EXPECT_STREQ(e.field, "pwave");
  // A bad setting is named by its key.
  config = pwave_config(true);
  monitor::built_part<monitor::PWaveSettings>(config.pwave)->lowpass_hz = 150.0;  // > 100 Hz
  EXPECT_STREQ(fw::validate(config).field, "pwave.lowpass_hz");
}

}  // namespace
}  // namespace plinth::monitor_pwave_test
