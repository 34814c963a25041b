#include "plinth/monitor/regional_alert.h"

#include <cmath>

#include "settings_checks.h"

namespace plinth::monitor {

namespace {

// The ranges an alert's numbers must lie in.
constexpr Real kMaxMagnitude = 10;
constexpr Real kMaxDistanceKm = 20040;  // half the Earth's circumference
constexpr Real kMaxPgaG = 10;
constexpr Real kMaxSigmaLn = 3;

// Seconds to ns (the alert's times are checked finite and bounded first).
std::int64_t seconds_to_ns(Real s) {
  return static_cast<std::int64_t>(std::llround(static_cast<double>(s) * 1e9));
}

}  // namespace

Error validate(const RegionalAlertSettings& s) {
  PLINTH_TRY(detail::first_error({
      detail::check_duration(s.max_origin_age_s, "regional_alert.max_origin_age_s", false),
      detail::check_duration(s.future_tolerance_s, "regional_alert.future_tolerance_s", true),
      detail::check_duration(s.expiry_margin_s, "regional_alert.expiry_margin_s", true),
      check_positive(s.stress_drop_bar, "regional_alert.stress_drop_bar"),
      check_positive(s.shear_wave_speed_km_s, "regional_alert.shear_wave_speed_km_s"),
  }));
  if (!std::isfinite(s.path_duration_s_per_km)) {
    return {ErrorCode::kNotFinite, "regional_alert.path_duration_s_per_km", "must be finite"};
  }
  if (s.path_duration_s_per_km < Real(0)) {
    return {ErrorCode::kOutOfRange, "regional_alert.path_duration_s_per_km",
            "must not be negative", 0.0};
  }
  return s.fragility_known ? detail::check_fragility(s.fragility) : ok_error();
}

// Boore (2003), the stochastic method: M0 = 10^(1.5 M + 16.05) dyne cm, the Brune corner
// frequency f0 = 4.906e6 beta (delta_sigma / M0)^(1/3) (beta in km/s, delta_sigma in bar), the
// duration 1 / f0 plus the path's part. M 7 at 100 bar: 8.9 s. 1 / f0 is taken through its
// logarithm, ln(M0^(1/3)) = ln(10) (0.5 M + 5.35), in Real: a Cortex-M4F links expf and logf
// already (the fragility's), where double pow and cbrt pull about 4 KB of libm (e_pow 2,960 B).
Time shaking_duration_s(const RegionalAlertSettings& s, Real magnitude, Real distance_km) {
  constexpr Real kLn10 = Real(2.302585092994045684);
  const Real ln_source_s = kLn10 * (Real(0.5) * magnitude + Real(5.35)) -
                           std::log(s.stress_drop_bar) / Real(3) -
                           std::log(Real(4.906e6) * s.shear_wave_speed_km_s);
  return static_cast<double>(std::exp(ln_source_s) + s.path_duration_s_per_km * distance_km);
}

Error RegionalAlertState::create(const RegionalAlertSettings& settings, RegionalAlertState& out) {
  PLINTH_TRY(validate(settings));
  out = RegionalAlertState{};
  out.settings_ = settings;
  return ok_error();
}

const RegionalAlertState::SeenEvent* RegionalAlertState::seen(std::uint32_t event_id) const {
  for (std::size_t i = 0; i < seen_count_; ++i) {
    if (seen_[i].event_id == event_id) return &seen_[i];
  }
  return nullptr;
}

void RegionalAlertState::remember(std::uint32_t event_id, std::uint32_t version) {
  for (std::size_t i = 0; i < seen_count_; ++i) {
    if (seen_[i].event_id == event_id) {
      // The highest version seen: an older one taken for its danger leaves it.
      seen_[i].version = version > seen_[i].version ? version : seen_[i].version;
      return;
    }
  }
  if (seen_count_ < seen_.size()) {
    seen_[seen_count_++] = {event_id, version};
    return;
  }
  seen_[seen_next_] = {event_id, version};  // the oldest event forgotten
  seen_next_ = (seen_next_ + 1) % seen_.size();
}

int RegionalAlertState::slot_of(std::uint32_t event_id) const {
  for (int i = 0; i < held_count_; ++i) {
    if (held_[static_cast<std::size_t>(i)].alert.event_id == event_id) return i;
  }
  return -1;
}

void RegionalAlertState::drop(int slot) {
  for (int i = slot; i + 1 < held_count_; ++i) {
    held_[static_cast<std::size_t>(i)] = held_[static_cast<std::size_t>(i + 1)];
  }
  --held_count_;
}

Real RegionalAlertState::probability_of(const RegionalAlert& a) const {
  return settings_.fragility_known ? settings_.fragility.probability(a.pga_g, a.sigma_ln)
                                   : Real(0);
}

RegionalOutcome RegionalAlertState::check(const RegionalAlert& a, Real& probability) const {
  using R = RegionalRefusal;
  struct Number {
    Real value;
    Real low;
    Real high;
    const char* field;
  };
  const Number numbers[] = {
      {a.magnitude, 0, kMaxMagnitude, "magnitude"},
      {a.distance_km, 0, kMaxDistanceKm, "distance_km"},
      {a.origin_age_s, -Real(detail::kMaxDurationS), Real(detail::kMaxDurationS), "origin_age_s"},
      {a.pga_g, 0, kMaxPgaG, "pga_g"},
      {a.sigma_ln, 0, kMaxSigmaLn, "sigma_ln"},
      {a.s_arrival_in_s, -Real(detail::kMaxDurationS), Real(detail::kMaxDurationS),
       "s_arrival_in_s"},
  };
  for (const Number& n : numbers) {
    if (!std::isfinite(n.value)) return {R::kNotFinite, n.field};
  }
  if (a.version > kMaxRegionalVersion) return {R::kOutOfRange, "version"};
  for (const Number& n : numbers) {
    if (n.value < n.low || n.value > n.high) return {R::kOutOfRange, n.field};
  }
  // The S waves leave with the origin: their arrival comes after it.
  if (a.s_arrival_in_s < -a.origin_age_s) return {R::kInconsistent, "s_arrival_in_s"};
  probability = probability_of(a);
  if (a.origin_age_s < -Real(settings_.future_tolerance_s)) {
    return {R::kFutureDated, "origin_age_s"};
  }
  if (a.origin_age_s > Real(settings_.max_origin_age_s)) return {R::kStale, "origin_age_s"};
  const Time expires_in_s = static_cast<double>(a.s_arrival_in_s) +
                            shaking_duration_s(settings_, a.magnitude, a.distance_km) +
                            settings_.expiry_margin_s;
  if (!a.cancelled && expires_in_s <= 0.0) return {R::kStale, "s_arrival_in_s"};
  if (const SeenEvent* e = seen(a.event_id); e != nullptr && a.version <= e->version) {
    // Unauthenticated: what the room holds of the event (nothing once cancelled or expired)
    // is no more dangerous than this version, or it is refused.
    const int slot = slot_of(a.event_id);
    const Real held = slot >= 0 ? held_[static_cast<std::size_t>(slot)].probability : Real(0);
    const bool more_dangerous = !a.cancelled && probability > held;
    if (settings_.authentication.required || !more_dangerous) {
      return {a.version == e->version ? R::kDuplicate : R::kOutOfOrder, "version"};
    }
  }
  return {};
}

void RegionalAlertState::refuse(RegionalOutcome outcome) {
  ++status_.refused[static_cast<std::size_t>(outcome.refusal)];
  status_.last_refusal = outcome.refusal;
  status_.last_refusal_field = outcome.field;
}

void RegionalAlertState::refuse_malformed(const char* field) {
  refuse_unread(RegionalRefusal::kMalformed, field);
}

void RegionalAlertState::refuse_unread(RegionalRefusal refusal, const char* field) {
  ++status_.received;
  refuse({refusal, field});
}

// A refusal of a valid alert more dangerous than the worst one held (what the box shows).
bool RegionalAlertState::note_if_dangerous(const RegionalAlert& a, Real probability,
                                           RegionalRefusal refusal) {
  if (a.cancelled || !(probability > status_.probability) || !(probability > Real(0))) {
    return false;
  }
  ++status_.refused_dangerous;
  status_.last_refused_dangerous = {a.event_id, a.version, probability, refusal, now_ns_};
  return true;
}

RegionalOutcome RegionalAlertState::receive(const RegionalAlert& a, std::int64_t now_ns) {
  now_ns_ = now_ns > now_ns_ ? now_ns : now_ns_;
  ++status_.received;
  Real probability = -1;  // known once the numbers passed their checks
  RegionalOutcome outcome = check(a, probability);
  if (!outcome.accepted()) {
    refuse(outcome);
    update_status(now_ns_);
    outcome.dangerous = note_if_dangerous(a, probability, outcome.refusal);
    return outcome;
  }
  HeldRegionalAlert h;
  h.alert = a;
  h.received_ns = now_ns_;
  h.origin_ns = now_ns_ - seconds_to_ns(a.origin_age_s);
  h.s_arrival_ns = now_ns_ + seconds_to_ns(a.s_arrival_in_s);
  h.expires_ns = h.s_arrival_ns +
                 detail::to_ns(shaking_duration_s(settings_, a.magnitude, a.distance_km) +
                               settings_.expiry_margin_s);
  h.probability = probability;
  int slot = slot_of(a.event_id);
  outcome.replaced = slot >= 0;
  if (a.cancelled) {
    if (slot >= 0) drop(slot);
    outcome.cancelled = true;
  } else if (slot < 0) {
    if (held_count_ < static_cast<int>(held_.size())) {
      slot = held_count_++;
    } else {
      // Full: the new alert takes the place of the least dangerous, if it is more so.
      int least = 0;
      for (int i = 1; i < held_count_; ++i) {
        if (held_[static_cast<std::size_t>(i)].probability <
            held_[static_cast<std::size_t>(least)].probability) {
          least = i;
        }
      }
      if (!(h.probability > held_[static_cast<std::size_t>(least)].probability)) {
        outcome = {RegionalRefusal::kNoRoom, "event_id"};
        refuse(outcome);
        update_status(now_ns_);
        return outcome;
      }
      slot = least;
    }
  }
  if (!a.cancelled) held_[static_cast<std::size_t>(slot)] = h;
  remember(a.event_id, a.version);
  ++status_.accepted;
  if (outcome.replaced) ++status_.replaced;
  if (outcome.cancelled) ++status_.cancelled;
  update_status(now_ns_);
  return outcome;
}

void RegionalAlertState::tick(std::int64_t now_ns) {
  now_ns_ = now_ns > now_ns_ ? now_ns : now_ns_;
  update_status(now_ns_);
}

void RegionalAlertState::update_status(std::int64_t now_ns) {
  for (int i = held_count_ - 1; i >= 0; --i) {
    if (held_[static_cast<std::size_t>(i)].expires_ns <= now_ns) {
      drop(i);
      ++status_.expired;
    }
  }
  status_.held = held_count_;
  status_.probability = 0;
  status_.time_to_s_arrival_s = 0;
  if (held_count_ == 0) {
    status_.worst = HeldRegionalAlert{};
    return;
  }
  int worst = 0;
  for (int i = 1; i < held_count_; ++i) {
    const HeldRegionalAlert& h = held_[static_cast<std::size_t>(i)];
    const HeldRegionalAlert& w = held_[static_cast<std::size_t>(worst)];
    if (h.probability > w.probability ||
        (h.probability == w.probability && h.s_arrival_ns < w.s_arrival_ns)) {
      worst = i;
    }
  }
  status_.worst = held_[static_cast<std::size_t>(worst)];
  status_.probability = status_.worst.probability;
  status_.time_to_s_arrival_s =
      static_cast<Real>(static_cast<double>(status_.worst.s_arrival_ns - now_ns) * 1e-9);
}

}  // namespace plinth::monitor
