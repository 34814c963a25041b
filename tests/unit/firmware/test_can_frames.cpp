// The firmware's one map between domain types and CAN messages (firmware/monitor/can_frames.h),
// against plinth.dbc's VAL_ tables, and the frames a Monitor hands over with each update.
#include "plinth/firmware/can_frames.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "bundled_records.h"
#include "dbc_file.h"
#include "monitor_input.h"
#include "plinth/firmware/frame_decoder.h"
#include "plinth/firmware/monitor.h"
#include "plinth/host/record_io.h"
#include "test_support.h"

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;
namespace {

using monitor::AlarmCause;
using monitor::AlarmLevel;

constexpr std::int64_t kMs = 1'000'000;
constexpr std::array<Phase, 7> kPhases = {Phase::kFullContact,  Phase::kSliding,
                                          Phase::kRocking,      Phase::kSlideRocking,
                                          Phase::kOverturned,   Phase::kFell,
                                          Phase::kLiftedOff};

Mode rocking_about(Corner corner) {
  Mode m;
  m.phase = Phase::kRocking;
  m.corner = corner;
  return m;
}

// The domain name that the wire value `raw` of DBC signal `signal` stands for ("?": none).
std::string domain_name(const std::string& signal, unsigned raw) {
  if (signal == "Phase") {
    for (const Phase p : kPhases) {
      if (static_cast<unsigned>(to_wire(p)) == raw) return phase_name(p);
    }
  } else if (signal == "Corner") {
    if (static_cast<unsigned>(wire_corner(Mode{})) == raw) return "none";  // not rocking
    for (const Corner c : {Corner::kLeft, Corner::kRight}) {
      if (static_cast<unsigned>(wire_corner(rocking_about(c))) == raw) return corner_name(c);
    }
  } else if (signal == "AlarmLevel" || signal == "Level" || signal == "PreviousLevel") {
    for (const auto& [level, name] : monitor::kAlarmLevelNames) {
      if (static_cast<unsigned>(to_wire(level)) == raw) {
        EXPECT_EQ(from_wire(to_wire(level)), level) << name;
        return name;
      }
    }
  } else if (signal == "Cause") {
    for (const auto& [cause, name] : monitor::kAlarmCauseNames) {
      if (static_cast<unsigned>(to_wire(cause)) == raw) return name;
    }
  } else if (signal == "Latched") {
    return raw == 0 ? "not_latched" : "latched";  // a flag: the DBC names its two values
  } else if (signal == "Cancelled") {
    can::RegionalAlertOrigin origin;
    origin.cancelled = raw != 0;
    return regional_alert_of(origin, can::RegionalAlert{}, 0.0).cancelled ? "cancelled" : "alert";
  } else if (signal == "WorstMember" || signal == "CollapseIn") {
    BoxStatus s;  // a forecast in which no member collapses
    s.axes[0].forecast.valid = true;
    s.axes[0].forecast.members = 5;
    const can::CollapseForecast m = forecast_message(s, 0, 4.0, 0);
    if (raw == (signal == "WorstMember" ? m.worst_member : m.collapse_in_ms)) return "none";
  }
  return "?";
}

// Every wire value the DBC names stands for the domain value of that name, and no domain
// value is missing from the wire (the tables have as many entries as the domain has values).
TEST(CanFrames, TheDbcsValueNamesAreTheDomainNames) {
  const testing::Dbc& dbc = testing::plinth_dbc();
  int tables = 0;
  for (const auto& [key, table] : dbc.values) {
    const std::string& signal = key.second;
    SCOPED_TRACE(signal);
    ++tables;
    for (const auto& [raw, name] : table) EXPECT_EQ(name, domain_name(signal, raw)) << raw;
    std::size_t values = 2;  // Latched
    if (signal == "Phase") values = kPhases.size();
    if (signal == "Corner") values = 3;  // none, left, right
    if (signal == "Cause") values = monitor::kAlarmCauseNames.size();
    if (signal == "AlarmLevel" || signal == "Level" || signal == "PreviousLevel") {
      values = monitor::kAlarmLevelNames.size();
    }
    if (signal == "WorstMember" || signal == "CollapseIn") values = 1;  // none
    EXPECT_EQ(table.size(), values);
  }
  EXPECT_GT(tables, 5);  // MonitorStatus x2 (Phase, Corner, AlarmLevel), AlarmEvent, Acknowledge
}

// A regional alert's two frames: every field, the origin's age counted from the alert frame.
TEST(CanFrames, ARegionalAlertsFramesMakeOneAlert) {
  can::RegionalAlertOrigin o;
  o.event_id = 300;
  o.version = 4;
  o.magnitude = 6.85;
  o.origin_age_s = 7.5;
  o.distance_km = 95;
  can::RegionalAlert a;
  a.event_id = 300;
  a.version = 4;
  a.pga_g = 0.25;
  a.sigma_ln = 0.7;
  a.s_arrival_in_s = 12.3;
  const monitor::RegionalAlert r = regional_alert_of(o, a, 0.02);
  EXPECT_EQ(r.event_id, 300U);
  EXPECT_EQ(r.version, 4U);
  EXPECT_FALSE(r.cancelled);
  EXPECT_DOUBLE_EQ(r.magnitude, 6.85);
  EXPECT_DOUBLE_EQ(r.distance_km, 95.0);
  EXPECT_DOUBLE_EQ(r.origin_age_s, 7.52);
  EXPECT_DOUBLE_EQ(r.pga_g, 0.25);
  EXPECT_DOUBLE_EQ(r.sigma_ln, 0.7);
  EXPECT_DOUBLE_EQ(r.s_arrival_in_s, 12.3);
}

TEST(CanFrames, AlarmEventsKeepTheirFieldsAndWrapTheirMilliseconds) {
  monitor::AlarmEventRecord r;
  r.level = AlarmLevel::kAlarm;
  r.previous_level = AlarmLevel::kWarning;
  r.cause = AlarmCause::kOverturnDetected;
  r.latched = true;
  r.time_ns = 5'000'123'456;
  r.sequence = 200;
  const can::AlarmEvent e = alarm_event_message(r);
  EXPECT_EQ(e.time_since_start_ms, 5000U);
  EXPECT_EQ(e.level, can::AlarmLevel::kAlarm);
  EXPECT_EQ(e.previous_level, can::AlarmLevel::kWarning);
  EXPECT_EQ(e.cause, can::AlarmCause::kOverturnDetected);
  EXPECT_TRUE(e.latched);
  EXPECT_EQ(e.sequence, 200);
  can::CanFrame frame;
  EXPECT_TRUE(can::encode(e, frame).ok());
  r.time_ns = ((std::int64_t{1} << 32) + 7) * kMs;  // the frame's millisecond counter wraps
  EXPECT_EQ(alarm_event_message(r).time_since_start_ms, 7U);
}

TEST(CanFrames, StatusCarriesPhaseCornerLevelRiskAndSampleAge) {
  BoxStatus s;
  s.axis_count = 2;
  s.axes[1].mode = rocking_about(Corner::kRight);
  s.axes[1].risk.total = 0.4321;
  s.alarm = AlarmLevel::kWarning;
  s.estimating = true;
  s.time_ns = 10'000 * kMs;
  s.newest_sample_time_ns = 9'993 * kMs + 500'000;
  const can::MonitorStatus m = status_message(s, 1, 17);
  EXPECT_EQ(m.axis, 1);
  EXPECT_EQ(m.phase, can::Phase::kRocking);
  EXPECT_EQ(m.corner, can::Corner::kRight);
  EXPECT_EQ(m.alarm_level, can::AlarmLevel::kWarning);
  EXPECT_EQ(m.risk, 0.4321);
  EXPECT_EQ(m.sequence, 17);
  EXPECT_EQ(m.sample_age_ms, 6);  // whole ms
  // Not rocking: no corner, whatever the mode's corner field holds.
  s.axes[1].mode.phase = Phase::kSliding;
  EXPECT_EQ(status_message(s, 1, 0).corner, can::Corner::kNone);
  // Not estimating: the largest age the frame says; an age beyond it is clamped to it.
  s.estimating = false;
  EXPECT_EQ(status_message(s, 1, 0).sample_age_ms, 65535);
  s.estimating = true;
  s.newest_sample_time_ns = 0;
  s.time_ns = 100'000 * kMs;
  EXPECT_EQ(status_message(s, 0, 0).sample_age_ms, 65535);
}

TEST(CanFrames, ForecastCarriesProbabilityWorstMemberAndTimeToCollapse) {
  BoxStatus s;
  s.axis_count = 2;
  s.time_ns = 12'000 * kMs;
  ForecastOutcome& f = s.axes[1].forecast;
  f.valid = true;
  f.members = 17;
  f.collapsing = 6;
  f.probability = 6.0 / 17.0;
  f.worst_member = 16;
  s.axes[1].collapse_forecast_s = 13.2345;  // monitor time
  const can::CollapseForecast m = forecast_message(s, 1, 4.0, 99);
  EXPECT_EQ(m.axis, 1);
  EXPECT_EQ(m.probability, 6.0 / 17.0);
  EXPECT_EQ(m.worst_member, 16);
  EXPECT_EQ(m.members, 17);
  EXPECT_EQ(m.collapse_in_ms, 1235);  // 1.2345 s from the status's time, to the nearest ms
  EXPECT_EQ(m.horizon_s, 4.0);
  EXPECT_EQ(m.sequence, 99);
  can::CanFrame frame;
  ASSERT_TRUE(can::encode(m, frame).ok());
  EXPECT_EQ(frame.id, can::kCollapseForecastBaseId + 1);
  // A collapse forecast for a time now past is due now.
  s.time_ns = 13'500 * kMs;
  EXPECT_EQ(forecast_message(s, 1, 4.0, 0).collapse_in_ms, 0);
  // No member collapses: none, probability 0.
  f.collapsing = 0;
  f.probability = 0.0;
  f.worst_member = -1;
  s.axes[1].collapse_forecast_s = -1.0;
  const can::CollapseForecast none = forecast_message(s, 1, 4.0, 0);
  EXPECT_EQ(none.worst_member, can::kNoWorstMember);
  EXPECT_EQ(none.collapse_in_ms, can::kNoCollapseForecast);
  EXPECT_EQ(none.members, 17);
  EXPECT_TRUE(can::encode(none, frame).ok());
}

TEST(CanFrames, SamplesAndAcknowledgementsFromTheWire) {
  monitor::SensorSample in;
  in.receive_time_ns = 123;
  in.sequence = 9;
  in.status = monitor::sensor_flags::kOverTemperature;
  in.acceleration_g = Eigen::Vector3d(0.5, -0.25, 1.0);
  can::CanFrame frame;
  ASSERT_TRUE(can::encode(sensor_message(3, in), frame).ok());
  EXPECT_EQ(frame.id, can::kSensorAccelerationBaseId + 3);
  can::SensorAcceleration decoded;
  ASSERT_TRUE(can::decode(frame, decoded).ok());
  const monitor::SensorSample out = sample_of(decoded, 456);
  EXPECT_EQ(out.receive_time_ns, 456);
  EXPECT_EQ(out.sequence, 9);
  EXPECT_EQ(out.status, monitor::sensor_flags::kOverTemperature);
  EXPECT_EQ(out.acceleration_g, in.acceleration_g);  // multiples of the 0.25 mg step

  const monitor::Acknowledgement ack = acknowledgement_of({can::AlarmLevel::kWarning, 4, 77});
  EXPECT_EQ(ack.level, AlarmLevel::kWarning);
  EXPECT_EQ(ack.event_sequence, 77);
}

// A monitor's updates carry the frames to send: an AlarmEvent per event, then a MonitorStatus
// per axis when a status is due (at the interval, at an alarm change, at the heartbeat), each
// decoding to what the status says, their sequence one up per status.
TEST(CanFrames, UpdatesCarryTheFramesToSend) {
  const Scene scene = plinth::testing::make(plinth::testing::paper_isolated(0.0));
  MonitorConfig config;
  config.axis_count = 2;
  config.estimator.sample_rate_hz = 200.0;
  config.conditioning.startup_window_s = 0.5;
  config.status_interval_s = 0.25;
  Monitor monitor;
  ASSERT_TRUE(monitor.start(config, {&scene, &scene}).ok());
  int statuses = 0;
  int alarm_frames = 0;
  std::uint8_t next_sequence = 0;
  std::int64_t last_status_ns = -1;
  for (int n = 0; n < 1200; ++n) {
    monitor::SensorSample s;
    s.receive_time_ns = n * 5 * kMs;
    s.sequence = static_cast<std::uint8_t>(n);
    s.acceleration_g = Eigen::Vector3d(1e-4 * std::sin(n), 0.0, 1.0);
    const MonitorUpdate u = monitor.on_sample(s);
    // A MonitorStatus per axis, and a CollapseForecast per axis once a forecast completed.
    const bool forecast = monitor.status().axes[0].forecast.valid;
    ASSERT_EQ(u.frame_count, u.event_count + (u.status_due ? (forecast ? 4U : 2U) : 0U)) << n;
    for (std::size_t i = 0; i < u.event_count; ++i, ++alarm_frames) {
      can::AlarmEvent e;
      ASSERT_TRUE(can::decode(u.frames[i], e).ok());
      EXPECT_EQ(from_wire(e.level), u.events[i].level);
      EXPECT_EQ(e.sequence, u.events[i].sequence);
    }
    if (!u.status_due) continue;
    const std::int64_t t = monitor.status().time_ns;
    EXPECT_TRUE(u.event_count > 0 || last_status_ns < 0 || t - last_status_ns >= 250 * kMs ||
                t / (250 * kMs) > last_status_ns / (250 * kMs))
        << "a status " << t - last_status_ns << " ns after the last without a reason";
    last_status_ns = t;
    ++statuses;
    for (std::size_t axis = 0; axis < 2; ++axis) {
      can::MonitorStatus m;
      ASSERT_TRUE(can::decode(u.frames[u.event_count + axis], m).ok());
      EXPECT_EQ(m.axis, axis);
      EXPECT_EQ(m.sequence, next_sequence);
      EXPECT_EQ(from_wire(m.alarm_level), monitor.status().alarm);
      EXPECT_EQ(m.phase, to_wire(monitor.status().axes[axis].mode.phase));
      if (!forecast) continue;
      can::CollapseForecast c;  // at rest: none collapses
      ASSERT_TRUE(can::decode(u.frames[u.event_count + 2 + axis], c).ok());
      EXPECT_EQ(c.axis, axis);
      EXPECT_EQ(c.sequence, next_sequence);
      EXPECT_EQ(c.worst_member, can::kNoWorstMember);
      EXPECT_EQ(c.members, 1);
      EXPECT_NEAR(c.horizon_s, config.forecast.horizon_s, 0.05);
    }
    ++next_sequence;
  }
  // 6 s of samples at a 0.25 s interval: 24 intervals, the first sample's status and the alarm
  // changes (fault at the start, no data yet; its trouble not calibrated once the sensor sends;
  // normal 2 s, lower_hold_s, after the sensor is ready).
  EXPECT_GE(statuses, 26);
  EXPECT_LE(statuses, 28);
  EXPECT_EQ(alarm_frames, 3);
  EXPECT_EQ(monitor.frames_not_encoded(), 0U);
}

TEST(CanFrames, AStatusIsDueBeforeTheFirstSample) {
  const Scene scene = plinth::testing::make(plinth::testing::paper_isolated(0.0));
  Monitor monitor;
  ASSERT_TRUE(monitor.start(MonitorConfig{}, {&scene, nullptr}).ok());
  FrameDecoder decoder;
  decoder.start(MonitorConfig{});
  can::CanFrame heartbeat;
  ASSERT_TRUE(can::encode(can::SensorHeartbeat{1, 1, 0, 1, 0, 0, 0}, heartbeat).ok());
  const MonitorUpdate first = on_frame(monitor, decoder, {heartbeat, 1000});
  EXPECT_TRUE(first.status_due);
  // The first evaluation's AlarmEvent (fault: no data yet), then the status: never the alarm
  // policy's initial normal (found by fuzz_monitor).
  ASSERT_EQ(first.event_count, 1U);
  EXPECT_EQ(first.events[0].level, monitor::AlarmLevel::kFault);
  EXPECT_EQ(first.frame_count, 2U);
  EXPECT_EQ(monitor.status().alarm, monitor::AlarmLevel::kFault);
  EXPECT_FALSE(on_frame(monitor, decoder, {heartbeat, 2000}).status_due);  // the time did not move
}

// An ensemble in an earthquake that overturns it: with each status a CollapseForecast (one axis)
// once a forecast completed, saying what the status says (probability, worst member, the time
// to its collapse from the status's time), a collapse forecast before the overturn; none with the
// forecast disabled.
struct ForecastFrames {
  int statuses = 0;
  int forecasts = 0;
  int collapsing = 0;                       // forecasts with a worst member
  double first_collapse_forecast_t = -1.0;  // monitor time, s, of the first such frame
  double overturn_t = -1.0;
};

ForecastFrames run_forecast_frames(bool enabled) {
  std::vector<Scene> statues;
  for (const double height_factor : {1.0, 0.9, 1.1}) {
    SceneParams p = plinth::testing::paper_isolated(0.0);
    p.block.com_height *= height_factor;
    statues.push_back(plinth::testing::make(p));
  }
  MonitorConfig config;
  config.estimator.sample_rate_hz = 200.0;
  config.forecast.enabled = enabled;
  Monitor monitor;
  EXPECT_TRUE(monitor.start(config, {std::span<const Scene>(statues), {}}).ok());
  const host::Record record = plinth::testing::brienza();
  plinth::testing::QuietThenQuake input(200.0, 12.0, record, 20.0);  // after the 10 s start-up
  ForecastFrames out;
  for (long n = 0; n < input.size() && out.overturn_t < 0.0; ++n) {
    const MonitorUpdate u = monitor.on_sample(input.sample(n));
    const BoxStatus& st = monitor.status();
    if (st.axes[0].mode.terminal()) out.overturn_t = static_cast<double>(st.time_ns) * 1e-9;
    if (!u.status_due) continue;
    ++out.statuses;
    const std::size_t at = u.event_count + 1;  // after the events and the MonitorStatus
    can::MonitorStatus status;
    EXPECT_TRUE(can::decode(u.frames[at - 1], status).ok());
    const bool expected = enabled && st.axes[0].forecast.valid;
    EXPECT_EQ(u.frame_count, at + (expected ? 1U : 0U)) << n;
    if (!expected || u.frame_count != at + 1) continue;
    can::CollapseForecast c;
    EXPECT_TRUE(can::decode(u.frames[at], c).ok()) << n;
    ++out.forecasts;
    const AxisStatus& axis = st.axes[0];
    EXPECT_EQ(c.sequence, status.sequence);
    EXPECT_EQ(c.members, 3);
    EXPECT_NEAR(c.probability, st.probability, 0.5e-4);
    EXPECT_NEAR(c.probability, axis.forecast.probability, 0.5e-4);
    if (axis.forecast.worst_member < 0) {
      EXPECT_EQ(c.worst_member, can::kNoWorstMember);
      EXPECT_EQ(c.collapse_in_ms, can::kNoCollapseForecast);
      continue;
    }
    ++out.collapsing;
    EXPECT_EQ(c.worst_member, axis.forecast.worst_member);
    const double in_s = st.collapse_forecast_s - static_cast<double>(st.time_ns) * 1e-9;
    EXPECT_NEAR(c.collapse_in_ms * 1e-3, in_s < 0.0 ? 0.0 : in_s, 0.5e-3 + 1e-9) << n;
    if (out.first_collapse_forecast_t < 0.0) {
      out.first_collapse_forecast_t = static_cast<double>(st.time_ns) * 1e-9;
    }
  }
  EXPECT_EQ(monitor.frames_not_encoded(), 0U);
  return out;
}

TEST(CanFrames, ForecastFramesGoWithTheStatusWhileForecasting) {
  const ForecastFrames on = run_forecast_frames(true);
  ASSERT_GT(on.overturn_t, 0.0);  // the quake overturns the nominal statue
  EXPECT_GT(on.forecasts, 50);    // about 10 statuses a second from the estimator's start
  EXPECT_GT(on.collapsing, 0);
  EXPECT_LT(on.collapsing, on.forecasts);  // quiet at first: none collapses
  EXPECT_GT(on.first_collapse_forecast_t, 0.0);
  EXPECT_LT(on.first_collapse_forecast_t, on.overturn_t);
  const ForecastFrames off = run_forecast_frames(false);
  EXPECT_GT(off.statuses, 0);
  EXPECT_EQ(off.forecasts, 0);
}

}  // namespace
}  // namespace plinth::firmware
