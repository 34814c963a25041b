// The commissioning's parts (docs/commissioning.md): the box file's [commissioning] table, the
// mounting's digest, plinth-monitor's reading of the reports (commission_gate.h), the fault it
// holds while refusing (Monitor::hold_fault), and the checks on a session built here sample by
// sample (commission_checks.h). The programs on sessions made
// from the solver, and plinth-monitor's refusal: tests/cli/test_commission.sh; live on a bus:
// tests/integration/commission_live.sh.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "box_file_error.h"
#include "commission_checks.h"
#include "commission_gate.h"
#include "commission_report.h"
#include "monitor_config.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/firmware/monitor.h"
#include "test_support.h"

namespace plinth::firmware {
namespace {

namespace fs = std::filesystem;
using testing::box_file_error;
constexpr double kPi = 3.14159265358979323846;

TEST(CommissioningKeys, AreReadWithTheirUnitsAndPaths) {
  const MonitorFile f = load_monitor_text(
      "[commissioning]\nrequired = true\nreport = \"reports/commission-004.json\"\n"
      "override = \"node 2 replaced, check booked\"\nwedge_deg = 8.5\nhold_s = 6\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_TRUE(f.commissioning.required);
  EXPECT_EQ(f.commissioning.report, "/etc/plinth/reports/commission-004.json");
  EXPECT_EQ(f.commissioning.override_reason, "node 2 replaced, check booked");
  EXPECT_DOUBLE_EQ(f.commissioning.wedge_deg, 8.5);
  EXPECT_DOUBLE_EQ(f.commissioning.hold_s, 6.0);
}

TEST(CommissioningKeys, OutsideTheirRangeAreRefusedNamingTheKeyAndTheLimits) {
  EXPECT_EQ(box_file_error("[commissioning]\nwedge_deg = 0.5\n"),
            "/etc/plinth/box.toml:2: commissioning.wedge_deg: must lie in [1, 30]");
  EXPECT_EQ(box_file_error("[commissioning]\nwedge_deg = 4\nwedge_tolerance_deg = 3\n"),
            "/etc/plinth/box.toml:3: commissioning.wedge_tolerance_deg: must lie in [0.05, 2]");
  EXPECT_EQ(box_file_error("[commissioning]\ngyro_tolerance = 1\n"),
            "/etc/plinth/box.toml:2: commissioning.gyro_tolerance: must lie in [0.01, 0.5]");
  EXPECT_EQ(box_file_error("[commissioning]\nrequired = 1\n"),
            "/etc/plinth/box.toml:2: commissioning.required: expected true or false");
  EXPECT_NE(box_file_error("[commissioning]\noverride = \"\"\n").find("give the reason"),
            std::string::npos);
  EXPECT_NE(box_file_error("[commissioning]\nforce = true\n").find("unknown key"),
            std::string::npos);
}

MonitorConfig two_sensors() {
  return load_monitor_text(
             "[[sensor]]\nnode = 1\n[[sensor]]\nnode = 2\nunit = \"m/s2\"\n"
             "[statue_sensor]\nnode = 4\n",
             "box.toml", MonitorConfig{})
      .config;
}

TEST(MountingDigest, FollowsTheMountingAndNothingElse) {
  const MonitorConfig base = two_sensors();
  const std::string digest = mounting_sha256(base);
  EXPECT_EQ(digest.size(), 64U);
  MonitorConfig other = base;
  other.alarm.warning.on = 0.4;  // not the mounting
  other.forecast.horizon_s = 3.0;
  EXPECT_EQ(mounting_sha256(other), digest);
  other = base;
  other.sensors[1].conditioning.sensor_to_statue =
      Eigen::AngleAxis<Real>(Real(0.5 * kPi), Vector3r::UnitZ()).toRotationMatrix();
  EXPECT_NE(mounting_sha256(other), digest);
  other = base;
  other.sensors[1].conditioning.unit = monitor::AccelerationUnit::kStandardGravity;
  EXPECT_NE(mounting_sha256(other), digest);
  other = base;
  other.sensors[0].node = 3;
  EXPECT_NE(mounting_sha256(other), digest);
  other = base;
  other.estimator.sample_rate_hz = 100.0;
  EXPECT_NE(mounting_sha256(other), digest);
  other = base;
  auto* statue = monitor::built_part<StatueSensorSettings>(other.statue_sensor);
  ASSERT_NE(statue, nullptr);
  statue->node = 5;
  EXPECT_NE(mounting_sha256(other), digest);
}

class Gate : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (fs::temp_directory_path() /
            ("plinth-commission-gate-" +
             std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "-" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name()))
               .string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  void report(int index, const std::string& result, const std::string& mounting,
              const std::string& first_failure = "node 2 (ground, sensor[1]): never heard") {
    std::ofstream(fs::path(dir_) / (report_stem(index) + ".json"))
        << "{\"type\": \"commissioning\", \"result\": \"" << result
        << "\", \"time\": \"2026-05-12T09:41:07Z\", \"mounting_sha256\": \"" << mounting
        << "\", \"failures\": [" << (result == "pass" ? "" : "\"" + first_failure + "\"") << "]}\n";
  }
  GateVerdict verdict(const CommissioningSettings& settings, const std::string& option = "") {
    CommissioningGate gate(settings, dir_, kMounting, option);
    return gate.check();
  }

  static constexpr const char* kMounting = "0123456789abcdef";
  std::string dir_;
};

TEST_F(Gate, WithoutAReportTheBoxMonitorsUnlessOneIsRequired) {
  CommissioningSettings s;
  EXPECT_EQ(verdict(s).state, GateState::kNone);
  s.required = true;
  const GateVerdict v = verdict(s);
  EXPECT_EQ(v.state, GateState::kRefused);
  EXPECT_NE(v.why.find("commissioning.required, and no report (none in " + dir_),
            std::string::npos);
}

TEST_F(Gate, TheNewestReportDecides) {
  report(9, "pass", kMounting);
  report(10, "fail", kMounting);  // newer by number, not by name's order
  GateVerdict v = verdict({});
  EXPECT_EQ(v.state, GateState::kRefused);
  EXPECT_NE(v.report.find("commission-010.json"), std::string::npos);
  EXPECT_NE(v.why.find("failed (1 checks; the first: node 2 (ground, sensor[1]): never heard)"),
            std::string::npos);
  report(11, "pass", kMounting);
  v = verdict({});
  EXPECT_EQ(v.state, GateState::kPassed);
  EXPECT_EQ(v.report_time, "2026-05-12T09:41:07Z");
}

TEST_F(Gate, APassingReportOfAnotherMountingRefuses) {
  report(1, "pass", "fedcba9876543210");
  const GateVerdict v = verdict({});
  EXPECT_EQ(v.state, GateState::kRefused);
  EXPECT_NE(v.why.find("passed for another mounting"), std::string::npos);
}

TEST_F(Gate, AReportThatCannotBeReadRefusesNamingIt) {
  std::ofstream(fs::path(dir_) / "commission-001.json") << "{\"type\": \"commissioning\", ";
  GateVerdict v = verdict({});
  EXPECT_EQ(v.state, GateState::kRefused);
  EXPECT_NE(v.why.find("cannot read the commissioning report"), std::string::npos);
  std::ofstream(fs::path(dir_) / "commission-002.json") << "{\"type\": \"capture\"}";
  v = verdict({});
  EXPECT_NE(v.why.find("not a commissioning report"), std::string::npos);
  CommissioningSettings named;
  named.report = (fs::path(dir_) / "elsewhere.json").string();  // the box file's, missing
  EXPECT_EQ(verdict(named).state, GateState::kRefused);
}

TEST_F(Gate, AnOverrideMonitorsTheOptionBeforeTheBoxFile) {
  report(1, "fail", kMounting);
  CommissioningSettings s;
  s.override_reason = "from the box file";
  CommissioningGate by_file(s, dir_, kMounting, "");
  EXPECT_EQ(by_file.check().state, GateState::kOverridden);
  EXPECT_NE(by_file.message().find("overridden by commissioning.override (\"from the box file\")"),
            std::string::npos);
  CommissioningGate by_option(s, dir_, kMounting, "from the option");
  EXPECT_EQ(by_option.check().state, GateState::kOverridden);
  EXPECT_NE(by_option.message().find("--commissioning-override (\"from the option\")"),
            std::string::npos);
  EXPECT_NE(by_option.json().find("\"override\": \"from the option\""), std::string::npos);
  // An override does not hide a passing report.
  report(2, "pass", kMounting);
  EXPECT_EQ(by_option.check().state, GateState::kPassed);
}

TEST_F(Gate, PollLooksAgainOnlyAfterItsIntervalAndWhenTheFolderChanged) {
  report(1, "fail", kMounting);
  CommissioningGate gate({}, dir_, kMounting, "");
  ASSERT_EQ(gate.check().state, GateState::kRefused);
  EXPECT_FALSE(gate.poll(1'000'000'000));  // the first look: nothing changed
  report(2, "pass", kMounting);
  // The folder's time moves on at the next look: at least kGateRescanS later.
  EXPECT_FALSE(gate.poll(1'500'000'000));
  EXPECT_TRUE(gate.poll(3'100'000'000));
  EXPECT_EQ(gate.verdict().state, GateState::kPassed);
  EXPECT_FALSE(gate.poll(5'200'000'000));  // nothing new
}

// The box's refusal (Monitor::hold_fault, as plinth-monitor holds it while the gate refuses):
// fault with the cause commissioning_failed from the first evaluation, through a quiet start-up
// that would otherwise earn normal; never hiding the alarm of a collapse (the non-isolated block
// pushed over, as test_monitor's AcknowledgeFrameReleasesTheLatch); and normal again once
// released.
TEST(HeldFault, ShowsCommissioningFailedNeverHidesTheAlarmAndLifts) {
  const Scene scene = testing::make(testing::paper_block(0.0));
  MonitorConfig config;
  config.estimator.sample_rate_hz = 200.0;
  config.conditioning.startup_window_s = 0.5;
  config.sensor_health.stuck_samples = 0;
  const auto run = [&](Monitor& monitor, bool push, int samples, bool release_at_half) {
    FrameDecoder decoder;
    decoder.start(config);
    std::vector<monitor::AlarmEventRecord> events;
    for (int n = 0; n < samples && !monitor.status().axes[0].mode.terminal(); ++n) {
      if (release_at_half && n == samples / 2) monitor.hold_fault(monitor::AlarmCause::kNone);
      hal::can::SensorAcceleration m;
      m.node = 1;
      m.ax_g = push && n >= 400 && n < 600 ? 0.6 : 0.0;
      m.az_g = 1.0;
      m.sequence = static_cast<std::uint8_t>(n);
      hal::TimedFrame frame;
      frame.timestamp_ns = static_cast<std::int64_t>(n) * 5'000'000;
      EXPECT_TRUE(hal::can::encode(m, frame.frame).ok());
      const MonitorUpdate u = on_frame(monitor, decoder, frame);
      events.insert(events.end(), u.events.begin(),
                    u.events.begin() + static_cast<std::ptrdiff_t>(u.event_count));
      if (n > 0 && n < 400 && !(release_at_half && n >= samples / 2)) {
        EXPECT_EQ(u.status->alarm, monitor::AlarmLevel::kFault) << n;
      }
    }
    return events;
  };
  Monitor pushed;
  ASSERT_TRUE(pushed.start(config, {&scene, nullptr}).ok());
  pushed.hold_fault(monitor::AlarmCause::kCommissioningFailed);
  std::vector<monitor::AlarmEventRecord> events = run(pushed, true, 1400, false);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events.front().level, monitor::AlarmLevel::kFault);
  EXPECT_EQ(events.front().cause, monitor::AlarmCause::kCommissioningFailed);
  EXPECT_EQ(pushed.status().axes[0].mode.phase, Phase::kOverturned);
  EXPECT_EQ(pushed.status().alarm, monitor::AlarmLevel::kAlarm);
  Monitor released;
  ASSERT_TRUE(released.start(config, {&scene, nullptr}).ok());
  released.hold_fault(monitor::AlarmCause::kCommissioningFailed);
  events = run(released, false, 2000, true);  // 10 s, released after 5 s
  ASSERT_GE(events.size(), 2U);
  EXPECT_EQ(events.front().cause, monitor::AlarmCause::kCommissioningFailed);
  EXPECT_EQ(events.back().level, monitor::AlarmLevel::kNormal);
  EXPECT_EQ(released.status().alarm, monitor::AlarmLevel::kNormal);
  // A restart forgets it: plinth-monitor holds it again after each start.
  ASSERT_TRUE(pushed.start(config, {&scene, nullptr}).ok());
  EXPECT_NE(run(pushed, false, 600, false).front().cause,
            monitor::AlarmCause::kCommissioningFailed);
}

// A session made here: one ground sensor at rest, on the wedge on its +x side, then its +y side,
// at rest again, mounted as `installed` while the box file says the identity.
SessionRecording wedge_session(const Eigen::Matrix3d& installed, double wedge_deg = 5.0) {
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 0.0005);  // g
  SessionRecording session;
  const double rate = 200.0;
  std::uint8_t sequence = 0;
  for (int n = 0; n < static_cast<int>(60 * rate); ++n) {
    const double t = n / rate;
    Eigen::Matrix3d body = Eigen::Matrix3d::Identity();  // statue frame <- the sensor's body
    const double a = wedge_deg * kPi / 180.0;
    if (t >= 14.0 && t < 22.0) body = Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitY()).matrix();
    if (t >= 28.0 && t < 36.0) body = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix();
    const bool moving =
        (t >= 12.0 && t < 14.0) || (t >= 22.0 && t < 28.0) || (t >= 36.0 && t < 38.0);
    const Eigen::Vector3d g = installed.transpose() * body.transpose() * Eigen::Vector3d::UnitZ();
    hal::can::SensorAcceleration m;
    m.node = 1;
    const double hand = moving ? 0.05 : 0.0;
    m.ax_g = g.x() + noise(random) + hand * std::sin(40.0 * t);
    m.ay_g = g.y() + noise(random);
    m.az_g = g.z() + noise(random);
    m.sequence = sequence++;
    hal::TimedFrame frame;
    frame.timestamp_ns = 1'700'000'000'000'000'000 + static_cast<std::int64_t>(n) * 5'000'000;
    EXPECT_TRUE(hal::can::encode(m, frame.frame).ok());
    session.take(frame);
  }
  return session;
}

std::vector<std::string> commission_failures(const SessionRecording& session) {
  CommissionInput input;
  input.session = &session;
  input.sensors = commissioned_sensors(
      load_monitor_text("[[sensor]]\nnode = 1\n", "box.toml", MonitorConfig{}).config);
  input.steps = plan_steps(input.sensors, 1);
  return commission(input).failures();
}

TEST(CommissionChecks, TheStepsOfABoxFile) {
  const std::vector<CommissionedSensor> sensors = commissioned_sensors(two_sensors());
  ASSERT_EQ(sensors.size(), 3U);
  EXPECT_EQ(sensors[1].label, "node 2 (ground, sensor[1])");
  EXPECT_EQ(sensors[2].label, "statue sensor (node 4)");
  EXPECT_DOUBLE_EQ(sensors[1].unit_scale, 1.0);  // m/s2
  std::string names;
  for (const Step& step : plan_steps(sensors, 2)) names += step.name + " ";
  EXPECT_EQ(names, "rest tilt-x:1 tilt-y:1 tilt-x:2 tilt-y:2 statue-x statue-y final-rest ");
}

TEST(CommissionChecks, ASensorMountedAsDeclaredPasses) {
  EXPECT_EQ(commission_failures(wedge_session(Eigen::Matrix3d::Identity())),
            std::vector<std::string>{});
}

TEST(CommissionChecks, ASensorTurnedAboutTheVerticalIsNamedWithItsTurn) {
  const std::vector<std::string> failures = commission_failures(
      wedge_session(Eigen::AngleAxisd(kPi / 2.0, Eigen::Vector3d::UnitZ()).matrix()));
  ASSERT_EQ(failures.size(), 3U);  // both raises, and the heading that explains them
  EXPECT_NE(failures[2].find("node 1 (ground, sensor[0]): turned 90 deg counter-clockwise"),
            std::string::npos)
      << failures[2];
}

TEST(CommissionChecks, AWedgeOfAnotherAngleIsAGain) {
  // The sensor read 3 deg where the box file's wedge gives 5: as if its gains were 0.6.
  const std::vector<std::string> failures =
      commission_failures(wedge_session(Eigen::Matrix3d::Identity(), 3.0));
  ASSERT_EQ(failures.size(), 2U);
  EXPECT_NE(failures[0].find("read 3.00 deg where the wedge gives 5.0 +- 1.0: a gain of 0.60"),
            std::string::npos)
      << failures[0];
}

}  // namespace
}  // namespace plinth::firmware
