// Regional earthquake early-warning alerts as an input: the alerts a bridge relays from the
// regional operator's feed (ShakeAlert, JMA, SASMEX, PRESTo) to the box, each an event's
// magnitude, origin time, epicentral distance, the PGA expected at the site with its lognormal
// scatter and the expected S arrival. This room accepts or refuses each (a counted reason),
// replaces an event's earlier versions, lets alerts expire, and gives the statue's probability
// of collapse under the worst held alert: the alarm policy raises `warning` (never `alarm`) on
// it, cause regional_alert. Times are int64 ns of one clock (the monitor's); an alert's own
// times are relative to its receipt, so no clock is shared with the bridge (docs/regional.md).
// Freestanding: no heap, no exceptions.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/fragility.h"
#include "plinth/core/name_table.h"
#include "plinth/core/real.h"
#include "plinth/monitor/optional_part.h"  // kRegionalAlertBuiltIn

namespace plinth::monitor {

// The message of a build without.
inline constexpr const char* kRegionalAlertNotBuilt =
    "this build has no regional alerts (PLINTH_REGIONAL_ALERT=OFF)";

// Alerts held at once (distinct events); the versions seen of recent events, remembered past
// their expiry so that a late duplicate is still told from a new event.
inline constexpr std::size_t kMaxRegionalEvents = 4;
inline constexpr std::size_t kRecentRegionalEvents = 16;
inline constexpr std::uint32_t kMaxRegionalVersion = 255;  // the CAN frame's 8 bits

// An alert as received, its times relative to the receipt (the bridge computes them from the
// operator's message; on the bus they are relative to the frame's receive time).
struct RegionalAlert {
  std::uint32_t event_id = 0;  // the bridge's number for the operator's event
  std::uint32_t version = 0;   // 0..kMaxRegionalVersion; a higher one replaces the earlier
  bool cancelled = false;      // the operator withdrew the event: it is dropped
  Real magnitude = 0;          // moment magnitude, [0, 10]
  Real distance_km = 0;        // epicentral distance of the site, km, [0, 20040]
  Real origin_age_s = 0;       // s from the origin time to the receipt (> 0: in the past)
  Real pga_g = 0;              // expected PGA at the site (the median), g, [0, 10]
  Real sigma_ln = 0;           // its scatter: the standard deviation of ln PGA, [0, 3]
  Real s_arrival_in_s = 0;     // s from the receipt to the expected S arrival (< 0: arrived)
};

// Why an alert was refused; each counted (RegionalAlertStatus::refused).
enum class RegionalRefusal : std::uint8_t {
  kNone = 0,
  kMalformed,     // the host could not read it (JSON, a missing field; a frame the codec refused)
  kNotFinite,     // a number is NaN or infinite
  kOutOfRange,    // a number outside its range (RegionalOutcome::field names it)
  kInconsistent,  // the S arrival before the origin
  kFutureDated,   // the origin lies after the receipt beyond future_tolerance_s
  kStale,         // the origin older than max_origin_age_s, or the alert already expired
  kDuplicate,     // this event's version was taken already
  kOutOfOrder,    // an older version of an event than the one taken
  kNoRoom,        // kMaxRegionalEvents held, each with a higher probability of collapse
  // The box file requires authenticated alerts (RegionalAuthentication) and this one's tag is
  // missing or wrong, or its counter is not above the last one taken (a replay).
  kUnauthenticated,
};
inline constexpr std::size_t kRegionalRefusalCount = 11;

inline constexpr NameTable<RegionalRefusal, kRegionalRefusalCount> kRegionalRefusalNames{{{
    {RegionalRefusal::kNone, "none"},
    {RegionalRefusal::kMalformed, "malformed"},
    {RegionalRefusal::kNotFinite, "not finite"},
    {RegionalRefusal::kOutOfRange, "out of range"},
    {RegionalRefusal::kInconsistent, "S arrival before origin"},
    {RegionalRefusal::kFutureDated, "future-dated"},
    {RegionalRefusal::kStale, "stale"},
    {RegionalRefusal::kDuplicate, "duplicate"},
    {RegionalRefusal::kOutOfOrder, "out of order"},
    {RegionalRefusal::kNoRoom, "no room"},
    {RegionalRefusal::kUnauthenticated, "unauthenticated"},
}}};
[[nodiscard]] constexpr const char* regional_refusal_name(RegionalRefusal refusal) {
  return kRegionalRefusalNames.name(refusal);
}

// What came of one alert.
struct RegionalOutcome {
  RegionalRefusal refusal = RegionalRefusal::kNone;
  const char* field = "";  // the field at fault ("pga_g", ...), "" when none is
  bool replaced = false;   // taken, replacing an earlier version of the event
  bool cancelled = false;  // taken: a cancellation, the event dropped
  bool dangerous = false;  // refused, and more dangerous than every alert held (counted)
  [[nodiscard]] constexpr bool accepted() const { return refusal == RegionalRefusal::kNone; }
};

// The alerts' source authenticated (docs/regional.md, "Who may send an alert"): with a key,
// every alert must carry an HMAC-SHA256 tag of it made with that key (MQTT: a user property over
// the payload; CAN: a RegionalAlertTag frame over both frames and a counter), and an alert
// without, or with a wrong one, is refused (kUnauthenticated) before the room sees it. The
// hosts check the tags (frame_decoder.h, the MQTT client); the room trusts the versions' order
// only then.
inline constexpr std::size_t kRegionalKeyBytes = 32;
struct RegionalAuthentication {
  bool required = false;
  std::array<std::uint8_t, kRegionalKeyBytes> key{};  // regional_alert.key_file's
};

struct RegionalAlertSettings {
  // s, > 0: an alert whose origin lies further back is stale (S waves cross 2000 km in 570 s).
  Time max_origin_age_s = 600.0;
  // s, >= 0: an origin up to this far after the receipt is clock skew; beyond: future-dated.
  Time future_tolerance_s = 2.0;
  // s, >= 0: an alert is held this long after its S arrival plus the shaking's duration.
  Time expiry_margin_s = 30.0;
  // The shaking's duration, the stochastic method's (Boore 2003): the source's 1 / f0, f0 the
  // Brune corner frequency at this stress drop and shear-wave speed, plus the path's part.
  Real stress_drop_bar = 100.0;           // bar, > 0
  Real shear_wave_speed_km_s = 3.5;       // km/s, > 0
  Real path_duration_s_per_km = Real(0.05);  // s/km, >= 0
  // The statue's collapse fragility (the scene file's [fragility]); without it alerts are
  // taken and shown, and the probability of collapse stays 0.
  bool fragility_known = false;
  LognormalFragility fragility;  // PGA in g: median_g > 0, beta >= 0
  RegionalAuthentication authentication;
};

// Checks the settings; the Error names the field ("regional_alert.expiry_margin_s", ...).
[[nodiscard]] Error validate(const RegionalAlertSettings& settings);

// The strong shaking's duration for an event of `magnitude` at `distance_km`, s (the settings'
// stochastic-method estimate; it bounds an alert's life).
[[nodiscard]] Time shaking_duration_s(const RegionalAlertSettings& settings, Real magnitude,
                                      Real distance_km);

// One held alert, its times on the monitor's clock.
struct HeldRegionalAlert {
  RegionalAlert alert;           // as received
  std::int64_t received_ns = 0;  // when
  std::int64_t origin_ns = 0;
  std::int64_t s_arrival_ns = 0;
  std::int64_t expires_ns = 0;   // s_arrival + shaking duration + expiry_margin_s
  Real probability = 0;          // the statue's probability of collapse under it
};

// A refused alert that was more dangerous than every alert held (a higher probability of
// collapse than the worst held one's): the refusal hid a danger, so the status shows it.
struct RefusedRegionalAlert {
  std::uint32_t event_id = 0;
  std::uint32_t version = 0;
  Real probability = 0;  // of collapse under it
  RegionalRefusal refusal = RegionalRefusal::kNone;
  std::int64_t refused_ns = 0;  // when
};

// The room's status after each update.
struct RegionalAlertStatus {
  int held = 0;                // alerts held (not expired)
  // The held alert with the highest probability of collapse (the earliest S arrival among
  // equals); valid when held > 0.
  HeldRegionalAlert worst;
  Real probability = 0;        // its probability of collapse; 0 when none is held
  // s from now to its S arrival (< 0: the S waves are due or passing); 0 when none is held.
  Real time_to_s_arrival_s = 0;
  std::uint64_t received = 0;  // alerts offered (accepted or refused, malformed ones too)
  std::uint64_t accepted = 0;
  std::uint64_t replaced = 0;  // accepted versions that replaced an earlier one
  std::uint64_t cancelled = 0;  // accepted cancellations
  std::uint64_t expired = 0;
  std::array<std::uint64_t, kRegionalRefusalCount> refused{};  // by RegionalRefusal; [0] unused
  RegionalRefusal last_refusal = RegionalRefusal::kNone;
  const char* last_refusal_field = "";
  // Refusals of alerts more dangerous than the worst held one (a stale, future-dated, duplicate
  // or older version's): counted, the latest kept.
  std::uint64_t refused_dangerous = 0;
  RefusedRegionalAlert last_refused_dangerous;  // valid when refused_dangerous > 0
};

// Accept or refuse (in this order: finite, ranges, consistency, future-dated, stale, duplicate
// or out of order, room), replace, expire, and the worst held alert's probability of collapse:
// Versions: with authenticated sources an event's version at or below the one taken is refused
// (duplicate, out of order). Without, anyone may have sent the higher one (a spoofed version
// 255 would lock the bridge's own out), so such a version is still taken when it is more
// dangerous than what the room holds of its event (nothing, after a cancellation): a spoofed
// version can then add a warning, never hide one.
//
//   P = Phi(ln(PGA / median) / sqrt(beta^2 + sigma_ln^2))
// (the fragility under the prediction's lognormal scatter: LognormalFragility::probability).
// A cancellation is checked like an alert; taken, it drops the event. Times never go back: an
// earlier `now_ns` counts as the latest.
class RegionalAlertState {
 public:
  RegionalAlertState() = default;
  // Fails on invalid settings (the Error names the field); `out` is then left untouched.
  [[nodiscard]] static Error create(const RegionalAlertSettings& settings,
                                    RegionalAlertState& out);

  // An alert received at `now_ns`.
  RegionalOutcome receive(const RegionalAlert& alert, std::int64_t now_ns);
  // An alert the host could not read (counted as malformed).
  void refuse_malformed(const char* field);
  // An alert the host refused before reading it: malformed, or unauthenticated (`field` names
  // what: "payload", "RegionalAlertTag", ...).
  void refuse_unread(RegionalRefusal refusal, const char* field);
  // Drops the alerts expired by `now_ns` and updates the status's time to arrival.
  void tick(std::int64_t now_ns);

  [[nodiscard]] const RegionalAlertStatus& status() const { return status_; }
  [[nodiscard]] const RegionalAlertSettings& settings() const { return settings_; }

 private:
  struct SeenEvent {
    std::uint32_t event_id = 0;
    std::uint32_t version = 0;
  };
  // `probability`: the alert's probability of collapse once its numbers passed their checks.
  [[nodiscard]] RegionalOutcome check(const RegionalAlert& alert, Real& probability) const;
  [[nodiscard]] Real probability_of(const RegionalAlert& alert) const;
  [[nodiscard]] const SeenEvent* seen(std::uint32_t event_id) const;
  void remember(std::uint32_t event_id, std::uint32_t version);
  [[nodiscard]] int slot_of(std::uint32_t event_id) const;
  void drop(int slot);
  void refuse(RegionalOutcome outcome);
  [[nodiscard]] bool note_if_dangerous(const RegionalAlert& alert, Real probability,
                                       RegionalRefusal refusal);
  void update_status(std::int64_t now_ns);

  RegionalAlertSettings settings_;
  std::array<HeldRegionalAlert, kMaxRegionalEvents> held_{};
  int held_count_ = 0;
  std::array<SeenEvent, kRecentRegionalEvents> seen_{};
  std::size_t seen_count_ = 0;
  std::size_t seen_next_ = 0;  // the oldest entry once full
  std::int64_t now_ns_ = 0;
  RegionalAlertStatus status_;
};

// What a Monitor holds for the room: the room, or nothing in a build without it.
using RegionalAlertRoom = OptionalPart<RegionalAlertState, kRegionalAlertBuiltIn>;
// The room's settings (MonitorConfig) and status (BoxStatus): nothing in a build without.
using RegionalAlertConfig = OptionalPart<RegionalAlertSettings, kRegionalAlertBuiltIn>;
using RegionalAlertStatusField = OptionalPart<RegionalAlertStatus, kRegionalAlertBuiltIn>;

}  // namespace plinth::monitor
