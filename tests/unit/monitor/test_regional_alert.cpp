// Regional alerts (regional_alert.h): accepted or refused with a counted reason, replaced by
// later versions, expired after the S arrival and the shaking, and the statue's probability of
// collapse under the worst one.
#include "plinth/monitor/regional_alert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "settings_support.h"

namespace plinth::monitor {
namespace {

constexpr std::int64_t kS = 1'000'000'000;  // ns

RegionalAlertSettings with_fragility() {
  RegionalAlertSettings s;
  s.fragility_known = true;
  s.fragility = {0.6, 0.5};
  return s;
}

// An M 7 at 60 km: origin 8 s ago, S arrival in 9 s, 0.4 g expected with sigma 0.6.
RegionalAlert alert(std::uint32_t id = 7, std::uint32_t version = 1) {
  RegionalAlert a;
  a.event_id = id;
  a.version = version;
  a.magnitude = 7.0;
  a.distance_km = 60.0;
  a.origin_age_s = 8.0;
  a.pga_g = 0.4;
  a.sigma_ln = 0.6;
  a.s_arrival_in_s = 9.0;
  return a;
}

class Room {
 public:
  explicit Room(const RegionalAlertSettings& s = with_fragility()) {
    const Error e = RegionalAlertState::create(s, state);
    EXPECT_TRUE(e.ok()) << e.field << ": " << e.reason;
  }
  RegionalAlertState state;
};

TEST(RegionalAlertSettings, DefaultsAreValidAndEachFieldIsChecked) {
  EXPECT_TRUE(validate(RegionalAlertSettings{}).ok());
  EXPECT_TRUE(validate(with_fragility()).ok());
  using testing::expect_create_refused;
  RegionalAlertSettings s;
  s.max_origin_age_s = 0.0;
  expect_create_refused<RegionalAlertState>(s, "regional_alert.max_origin_age_s",
                                            ErrorCode::kOutOfRange);
  s = {};
  s.future_tolerance_s = -1.0;
  expect_create_refused<RegionalAlertState>(s, "regional_alert.future_tolerance_s",
                                            ErrorCode::kOutOfRange);
  s = {};
  s.expiry_margin_s = std::numeric_limits<double>::quiet_NaN();
  expect_create_refused<RegionalAlertState>(s, "regional_alert.expiry_margin_s",
                                            ErrorCode::kNotFinite);
  s = {};
  s.stress_drop_bar = 0.0;
  expect_create_refused<RegionalAlertState>(s, "regional_alert.stress_drop_bar",
                                            ErrorCode::kOutOfRange);
  s = {};
  s.shear_wave_speed_km_s = -3.5;
  expect_create_refused<RegionalAlertState>(s, "regional_alert.shear_wave_speed_km_s",
                                            ErrorCode::kOutOfRange);
  s = {};
  s.path_duration_s_per_km = -0.01;
  expect_create_refused<RegionalAlertState>(s, "regional_alert.path_duration_s_per_km",
                                            ErrorCode::kOutOfRange);
  s = with_fragility();
  s.fragility.median_g = 0.0;
  expect_create_refused<RegionalAlertState>(s, "fragility.median_g", ErrorCode::kOutOfRange);
  s = with_fragility();
  s.fragility.beta = -0.1;
  expect_create_refused<RegionalAlertState>(s, "fragility.beta", ErrorCode::kOutOfRange);
  s.fragility_known = false;  // not checked when not given
  EXPECT_TRUE(validate(s).ok());
}

// Boore (2003)'s source duration 1 / f0 plus 0.05 s/km: M 7 at 100 bar and 3.5 km/s, 8.88 s;
// one magnitude more multiplies it by 10^0.5.
TEST(RegionalAlert, ShakingDurationIsTheStochasticMethods) {
  const RegionalAlertSettings s;
  const double m0 = std::pow(10.0, 1.5 * 7.0 + 16.05);
  const double f0 = 4.906e6 * 3.5 * std::cbrt(100.0 / m0);
  EXPECT_NEAR(shaking_duration_s(s, 7.0, 0.0), 1.0 / f0, 1e-9);
  EXPECT_NEAR(shaking_duration_s(s, 7.0, 0.0), 8.88, 0.01);
  EXPECT_NEAR(shaking_duration_s(s, 8.0, 0.0) / shaking_duration_s(s, 7.0, 0.0),
              std::sqrt(10.0), 1e-9);
  EXPECT_NEAR(shaking_duration_s(s, 7.0, 100.0) - shaking_duration_s(s, 7.0, 0.0), 5.0, 1e-9);
}

TEST(RegionalAlert, AnAcceptedAlertShowsItsProbabilityAndTimeToArrival) {
  Room r;
  EXPECT_EQ(r.state.status().held, 0);
  EXPECT_EQ(r.state.status().probability, 0.0);
  const RegionalOutcome o = r.state.receive(alert(), 100 * kS);
  EXPECT_TRUE(o.accepted());
  EXPECT_FALSE(o.replaced);
  const RegionalAlertStatus& st = r.state.status();
  EXPECT_EQ(st.held, 1);
  EXPECT_EQ(st.accepted, 1U);
  EXPECT_EQ(st.received, 1U);
  EXPECT_EQ(st.worst.alert.event_id, 7U);
  EXPECT_EQ(st.worst.origin_ns, 92 * kS);
  EXPECT_EQ(st.worst.s_arrival_ns, 109 * kS);
  // Phi(ln(0.4 / 0.6) / sqrt(0.5^2 + 0.6^2))
  const double expected = 0.5 * std::erfc(-std::log(0.4 / 0.6) / std::sqrt(0.61) / std::sqrt(2.0));
  EXPECT_NEAR(st.probability, expected, 1e-12);
  EXPECT_NEAR(st.time_to_s_arrival_s, 9.0, 1e-9);
  r.state.tick(104 * kS);
  EXPECT_NEAR(r.state.status().time_to_s_arrival_s, 5.0, 1e-9);
  r.state.tick(111 * kS);  // the S waves passing: negative, still held
  EXPECT_NEAR(r.state.status().time_to_s_arrival_s, -2.0, 1e-9);
  EXPECT_EQ(r.state.status().held, 1);
}

TEST(RegionalAlert, WithoutAFragilityTheAlertIsShownAndRaisesNothing) {
  Room r(RegionalAlertSettings{});
  EXPECT_TRUE(r.state.receive(alert(), 0).accepted());
  EXPECT_EQ(r.state.status().held, 1);
  EXPECT_EQ(r.state.status().probability, 0.0);
}

// Expiry: the S arrival, plus the shaking's duration, plus the margin.
TEST(RegionalAlert, AnAlertExpiresAfterItsArrivalTheShakingAndTheMargin) {
  Room r;
  ASSERT_TRUE(r.state.receive(alert(), 100 * kS).accepted());
  const RegionalAlertSettings s = with_fragility();
  const std::int64_t expires =
      109 * kS + std::llround((shaking_duration_s(s, 7.0, 60.0) + s.expiry_margin_s) * 1e9);
  EXPECT_EQ(r.state.status().worst.expires_ns, expires);
  r.state.tick(expires - 1);
  EXPECT_EQ(r.state.status().held, 1);
  r.state.tick(expires);
  EXPECT_EQ(r.state.status().held, 0);
  EXPECT_EQ(r.state.status().expired, 1U);
  EXPECT_EQ(r.state.status().probability, 0.0);
  EXPECT_EQ(r.state.status().time_to_s_arrival_s, 0.0);
}

TEST(RegionalAlert, ALaterVersionReplacesTheEarlierAndOlderOnesAreRefused) {
  Room r;
  ASSERT_TRUE(r.state.receive(alert(7, 1), 0).accepted());
  RegionalAlert v2 = alert(7, 2);
  v2.pga_g = 1.2;  // the magnitude grew
  v2.magnitude = 7.6;
  v2.s_arrival_in_s = 6.0;
  const RegionalOutcome o = r.state.receive(v2, 2 * kS);
  EXPECT_TRUE(o.accepted());
  EXPECT_TRUE(o.replaced);
  EXPECT_EQ(r.state.status().held, 1);
  EXPECT_EQ(r.state.status().replaced, 1U);
  EXPECT_EQ(r.state.status().worst.alert.version, 2U);
  EXPECT_NEAR(r.state.status().worst.alert.pga_g, 1.2, 1e-12);
  EXPECT_EQ(r.state.status().worst.s_arrival_ns, 8 * kS);
  // The same version again, and an older one, arriving late.
  RegionalOutcome dup = r.state.receive(v2, 3 * kS);
  EXPECT_EQ(dup.refusal, RegionalRefusal::kDuplicate);
  EXPECT_STREQ(dup.field, "version");
  EXPECT_EQ(r.state.receive(alert(7, 1), 3 * kS).refusal, RegionalRefusal::kOutOfOrder);
  const RegionalAlertStatus& st = r.state.status();
  EXPECT_EQ(st.refused[static_cast<std::size_t>(RegionalRefusal::kDuplicate)], 1U);
  EXPECT_EQ(st.refused[static_cast<std::size_t>(RegionalRefusal::kOutOfOrder)], 1U);
  EXPECT_EQ(st.last_refusal, RegionalRefusal::kOutOfOrder);
  EXPECT_EQ(st.received, 4U);
  EXPECT_EQ(st.accepted, 2U);
  EXPECT_NEAR(st.worst.alert.pga_g, 1.2, 1e-12);  // untouched by the refused
}

// Settings whose alerts' source is authenticated: the versions' order is trusted.
RegionalAlertSettings authenticated() {
  RegionalAlertSettings s = with_fragility();
  s.authentication.required = true;
  return s;
}

// A duplicate of an expired event is still a duplicate: the versions seen outlive the alert.
TEST(RegionalAlert, TheVersionsSeenOutliveTheirAlerts) {
  RegionalAlertSettings s = authenticated();
  s.expiry_margin_s = 0.0;
  Room r(s);
  RegionalAlert a = alert(9, 3);
  a.origin_age_s = 1.0;
  a.s_arrival_in_s = 0.5;
  ASSERT_TRUE(r.state.receive(a, 0).accepted());
  r.state.tick(60 * kS);
  EXPECT_EQ(r.state.status().held, 0);
  a.s_arrival_in_s = 200.0;  // as if it were new: still version 3 of event 9
  EXPECT_EQ(r.state.receive(a, 60 * kS).refusal, RegionalRefusal::kDuplicate);
}

TEST(RegionalAlert, ACancellationDropsTheEvent) {
  Room r(authenticated());
  ASSERT_TRUE(r.state.receive(alert(7, 1), 0).accepted());
  RegionalAlert cancel = alert(7, 2);
  cancel.cancelled = true;
  const RegionalOutcome o = r.state.receive(cancel, kS);
  EXPECT_TRUE(o.accepted());
  EXPECT_TRUE(o.cancelled);
  EXPECT_EQ(r.state.status().held, 0);
  EXPECT_EQ(r.state.status().cancelled, 1U);
  // Version 1 arriving after the cancellation stays out.
  EXPECT_EQ(r.state.receive(alert(7, 1), 2 * kS).refusal, RegionalRefusal::kOutOfOrder);
  EXPECT_EQ(r.state.status().held, 0);
}

// Unauthenticated, anyone may have sent an event's higher version: four spoofed events at
// version 255 (the ids the bridge numbers next), harmless, fill the room; the bridge's real
// alerts of those events, more dangerous, are still taken, never refused as out of order. A
// version no more dangerous than what is held stays refused, and a spoof sent again after the
// real alert is a duplicate: the highest version seen is kept.
TEST(RegionalAlert, ASpoofedHigherVersionCannotLockTheBridgeOut) {
  Room r;  // no authentication
  for (std::uint32_t id = 20; id < 24; ++id) {
    RegionalAlert spoof = alert(id, 255);
    spoof.pga_g = 0.01;
    ASSERT_TRUE(r.state.receive(spoof, 0).accepted()) << id;
  }
  EXPECT_EQ(r.state.status().held, 4);
  RegionalAlert real = alert(21, 1);
  real.pga_g = 1.5;
  const RegionalOutcome taken = r.state.receive(real, kS);
  EXPECT_TRUE(taken.accepted()) << regional_refusal_name(taken.refusal);
  EXPECT_TRUE(taken.replaced);
  EXPECT_EQ(r.state.status().worst.alert.event_id, 21U);
  EXPECT_EQ(r.state.status().worst.alert.version, 1U);
  EXPECT_GT(r.state.status().probability, 0.8);
  RegionalAlert spoof_again = alert(21, 255);
  spoof_again.pga_g = 0.01;
  EXPECT_EQ(r.state.receive(spoof_again, 2 * kS).refusal, RegionalRefusal::kDuplicate);
  RegionalAlert lower = alert(21, 2);
  lower.pga_g = 0.3;
  EXPECT_EQ(r.state.receive(lower, 3 * kS).refusal, RegionalRefusal::kOutOfOrder)
      << "an update no more dangerous than what is held of the event";
  EXPECT_EQ(r.state.status().worst.alert.version, 1U);
  // A spoofed cancellation at 255 does not keep the bridge's alert of the event out either.
  RegionalAlert cancel = alert(30, 255);
  cancel.cancelled = true;
  ASSERT_TRUE(r.state.receive(cancel, 4 * kS).accepted());
  RegionalAlert after = alert(30, 1);
  after.pga_g = 1.0;
  EXPECT_TRUE(r.state.receive(after, 5 * kS).accepted());
  RegionalAlert cancel_again = cancel;
  EXPECT_EQ(r.state.receive(cancel_again, 6 * kS).refusal, RegionalRefusal::kDuplicate)
      << "a cancellation is never more dangerous";
}

// With authenticated sources the same sequence keeps the version order: an older version is
// out of order, whatever it says.
TEST(RegionalAlert, AuthenticatedVersionsKeepTheirOrder) {
  Room r(authenticated());
  RegionalAlert high = alert(21, 255);
  high.pga_g = 0.01;
  ASSERT_TRUE(r.state.receive(high, 0).accepted());
  RegionalAlert older = alert(21, 1);
  older.pga_g = 1.5;
  EXPECT_EQ(r.state.receive(older, kS).refusal, RegionalRefusal::kOutOfOrder);
}

// A refused alert more dangerous than every held one is counted and kept for the status; a
// refusal that hides nothing is not.
TEST(RegionalAlert, ARefusedDangerousAlertShows) {
  Room r(authenticated());
  ASSERT_TRUE(r.state.receive(alert(7, 2), 0).accepted());  // 0.4 g
  const Real held = r.state.status().probability;
  RegionalAlert stale = alert(8, 1);
  stale.pga_g = 2.0;
  stale.origin_age_s = 700.0;
  stale.s_arrival_in_s = -600.0;
  const RegionalOutcome refused = r.state.receive(stale, kS);
  EXPECT_EQ(refused.refusal, RegionalRefusal::kStale);
  EXPECT_TRUE(refused.dangerous);
  RegionalAlert older = alert(7, 1);
  older.pga_g = 3.0;
  EXPECT_TRUE(r.state.receive(older, 2 * kS).dangerous) << "out of order, more dangerous";
  const RegionalAlertStatus& st = r.state.status();
  EXPECT_EQ(st.refused_dangerous, 2U);
  EXPECT_EQ(st.last_refused_dangerous.event_id, 7U);
  EXPECT_EQ(st.last_refused_dangerous.version, 1U);
  EXPECT_EQ(st.last_refused_dangerous.refusal, RegionalRefusal::kOutOfOrder);
  EXPECT_GT(st.last_refused_dangerous.probability, held);
  EXPECT_EQ(st.last_refused_dangerous.refused_ns, 2 * kS);
  RegionalAlert harmless = alert(7, 1);
  harmless.pga_g = 0.05;
  EXPECT_FALSE(r.state.receive(harmless, 3 * kS).dangerous);
  RegionalAlert out_of_range = alert(9, 1);
  out_of_range.pga_g = 12.0;
  EXPECT_FALSE(r.state.receive(out_of_range, 3 * kS).dangerous) << "no probability: no danger";
  EXPECT_EQ(r.state.status().refused_dangerous, 2U);
  r.state.refuse_unread(RegionalRefusal::kUnauthenticated, "RegionalAlertTag");
  EXPECT_EQ(r.state.status().refused[static_cast<std::size_t>(RegionalRefusal::kUnauthenticated)],
            1U);
  EXPECT_STREQ(r.state.status().last_refusal_field, "RegionalAlertTag");
}

TEST(RegionalAlert, EachBadFieldIsRefusedWithItsReasonAndCounted) {
  Room r;
  struct Case {
    void (*change)(RegionalAlert&);
    RegionalRefusal refusal;
    const char* field;
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const Case cases[] = {
      {[](RegionalAlert& a) { a.magnitude = kNaN; }, RegionalRefusal::kNotFinite, "magnitude"},
      {[](RegionalAlert& a) { a.pga_g = kInf; }, RegionalRefusal::kNotFinite, "pga_g"},
      {[](RegionalAlert& a) { a.sigma_ln = kNaN; }, RegionalRefusal::kNotFinite, "sigma_ln"},
      {[](RegionalAlert& a) { a.s_arrival_in_s = -kInf; }, RegionalRefusal::kNotFinite,
       "s_arrival_in_s"},
      {[](RegionalAlert& a) { a.origin_age_s = kNaN; }, RegionalRefusal::kNotFinite,
       "origin_age_s"},
      {[](RegionalAlert& a) { a.distance_km = kNaN; }, RegionalRefusal::kNotFinite,
       "distance_km"},
      {[](RegionalAlert& a) { a.magnitude = 10.5; }, RegionalRefusal::kOutOfRange, "magnitude"},
      {[](RegionalAlert& a) { a.magnitude = -1.0; }, RegionalRefusal::kOutOfRange, "magnitude"},
      {[](RegionalAlert& a) { a.distance_km = -0.1; }, RegionalRefusal::kOutOfRange,
       "distance_km"},
      {[](RegionalAlert& a) { a.pga_g = -0.1; }, RegionalRefusal::kOutOfRange, "pga_g"},
      {[](RegionalAlert& a) { a.pga_g = 12.0; }, RegionalRefusal::kOutOfRange, "pga_g"},
      {[](RegionalAlert& a) { a.sigma_ln = 3.5; }, RegionalRefusal::kOutOfRange, "sigma_ln"},
      {[](RegionalAlert& a) { a.version = 256; }, RegionalRefusal::kOutOfRange, "version"},
      {[](RegionalAlert& a) { a.s_arrival_in_s = -9.0; }, RegionalRefusal::kInconsistent,
       "s_arrival_in_s"},
      {[](RegionalAlert& a) {
         a.origin_age_s = -5.0;  // the earthquake 5 s from now: a clock is wrong
         a.s_arrival_in_s = 10.0;
       },
       RegionalRefusal::kFutureDated, "origin_age_s"},
      {[](RegionalAlert& a) { a.origin_age_s = 700.0; }, RegionalRefusal::kStale,
       "origin_age_s"},
      {[](RegionalAlert& a) {
         a.origin_age_s = 200.0;  // its S waves and shaking long past
         a.s_arrival_in_s = -180.0;
       },
       RegionalRefusal::kStale, "s_arrival_in_s"},
  };
  std::uint64_t n = 0;
  for (const Case& c : cases) {
    RegionalAlert a = alert(100 + static_cast<std::uint32_t>(n));
    c.change(a);
    const RegionalOutcome o = r.state.receive(a, 1000 * kS);
    EXPECT_EQ(o.refusal, c.refusal) << c.field;
    EXPECT_STREQ(o.field, c.field);
    EXPECT_STREQ(r.state.status().last_refusal_field, c.field);
    ++n;
  }
  const RegionalAlertStatus& st = r.state.status();
  EXPECT_EQ(st.held, 0);
  EXPECT_EQ(st.accepted, 0U);
  EXPECT_EQ(st.received, n);
  EXPECT_EQ(st.refused[static_cast<std::size_t>(RegionalRefusal::kNotFinite)], 6U);
  EXPECT_EQ(st.refused[static_cast<std::size_t>(RegionalRefusal::kOutOfRange)], 7U);
  EXPECT_EQ(st.refused[static_cast<std::size_t>(RegionalRefusal::kInconsistent)], 1U);
  EXPECT_EQ(st.refused[static_cast<std::size_t>(RegionalRefusal::kFutureDated)], 1U);
  EXPECT_EQ(st.refused[static_cast<std::size_t>(RegionalRefusal::kStale)], 2U);
  // A small skew is tolerated: the origin 1 s after the receipt.
  RegionalAlert skewed = alert(200);
  skewed.origin_age_s = -1.0;
  EXPECT_TRUE(r.state.receive(skewed, 1000 * kS).accepted());
  r.state.refuse_malformed("pga_g");
  EXPECT_EQ(r.state.status().refused[static_cast<std::size_t>(RegionalRefusal::kMalformed)], 1U);
  EXPECT_EQ(r.state.status().received, n + 2);
  EXPECT_STREQ(regional_refusal_name(RegionalRefusal::kFutureDated), "future-dated");
}

// Several events: the worst is shown; when the room is full, a new event takes the least
// dangerous one's place only if it is more dangerous.
TEST(RegionalAlert, TheWorstEventIsShownAndAFullRoomKeepsTheMostDangerous) {
  Room r;
  const double pgas[] = {0.2, 0.8, 0.1, 0.5};
  for (std::uint32_t i = 0; i < kMaxRegionalEvents; ++i) {
    RegionalAlert a = alert(i + 1);
    a.pga_g = pgas[i];
    ASSERT_TRUE(r.state.receive(a, 0).accepted());
  }
  EXPECT_EQ(r.state.status().held, 4);
  EXPECT_EQ(r.state.status().worst.alert.event_id, 2U);
  RegionalAlert weak = alert(10);
  weak.pga_g = 0.05;
  const RegionalOutcome refused = r.state.receive(weak, 0);
  EXPECT_EQ(refused.refusal, RegionalRefusal::kNoRoom);
  RegionalAlert strong = alert(11);
  strong.pga_g = 2.0;
  EXPECT_TRUE(r.state.receive(strong, 0).accepted());
  EXPECT_EQ(r.state.status().held, 4);
  EXPECT_EQ(r.state.status().worst.alert.event_id, 11U);
  // Event 3 (0.1 g) made room; event 10 was never taken and may still come.
  RegionalAlert again = alert(3, 2);
  again.pga_g = 0.05;
  EXPECT_EQ(r.state.receive(again, 0).refusal, RegionalRefusal::kNoRoom);
  // Equal probabilities: the earlier S arrival is shown.
  Room t;
  RegionalAlert later = alert(1);
  later.s_arrival_in_s = 20.0;
  RegionalAlert sooner = alert(2);
  sooner.s_arrival_in_s = 4.0;
  ASSERT_TRUE(t.state.receive(later, 0).accepted());
  ASSERT_TRUE(t.state.receive(sooner, 0).accepted());
  EXPECT_EQ(t.state.status().worst.alert.event_id, 2U);
}

TEST(RegionalAlert, TimeNeverGoesBack) {
  Room r;
  ASSERT_TRUE(r.state.receive(alert(), 100 * kS).accepted());
  r.state.tick(50 * kS);  // earlier: counts as the latest
  EXPECT_NEAR(r.state.status().time_to_s_arrival_s, 9.0, 1e-9);
}

}  // namespace
}  // namespace plinth::monitor
