#include "eval_fault.h"

#include <charconv>
#include <cmath>
#include <numbers>
#include <string_view>
#include <system_error>

#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"

namespace plinth::sim {
namespace {

using host::InputError;

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kMaxStatueGain = 1000.0;     // above deg/s read as rad/s (57.3)
constexpr double kMaxStatueBiasDegS = 2000.0;  // deg/s: a BMI088's widest range
constexpr double kMaxStatueDelayS = 10.0;
constexpr double kMaxDurationS = 3600.0;  // a drop-out's, a restart's downtime
constexpr double kMaxGroundGain = 1000.0;
constexpr double kMaxHeadingDeg = 360.0;
constexpr double kMaxOnsetS = 1e6;

// `text` as a finite number (a leading '+' allowed); false otherwise.
bool number(std::string_view text, double& out) {
  if (text.size() > 1 && text.front() == '+' && text[1] != '-') text.remove_prefix(1);
  const char* end = text.data() + text.size();
  const auto r = std::from_chars(text.data(), end, out);
  return r.ec == std::errc{} && r.ptr == end && std::isfinite(out);
}

double number_in(std::string_view text, double low, double high, const std::string& what) {
  double v = 0.0;
  if (!number(text, v)) {
    throw InputError("--fault: " + what + ": expected a number, got " + host::shown(text));
  }
  if (v < low || v > high) {
    throw InputError("--fault: " + what + ": expected " + host::number_text(low) + " to " +
                     host::number_text(high) + ", got " + host::shown(text));
  }
  return v;
}

int axis_index(std::string_view text, const std::string& what) {
  if (text == "x") return 0;
  if (text == "y") return 1;
  if (text == "z") return 2;
  throw InputError("--fault: " + what + ": expected the axis x, y or z, got " + host::shown(text));
}

// A ground sensor's error: "gain:G" (x), "gain:AXIS=G" or "heading:DEG"; `kind` names the
// fault in messages.
GroundSensorError ground_error(std::string_view text, const std::string& kind) {
  GroundSensorError e;
  const std::size_t colon = text.find(':');
  const std::string_view what = text.substr(0, colon);
  if (colon == std::string_view::npos || colon + 1 == text.size()) {
    throw InputError("--fault: " + kind + ": expected gain:G, gain:AXIS=G or heading:DEG, got " +
                     host::shown(text));
  }
  const std::string_view value = text.substr(colon + 1);
  if (what == "gain") {
    const std::size_t equals = value.find('=');
    const int axis = equals == std::string_view::npos
                         ? 0
                         : axis_index(value.substr(0, equals), kind + " gain");
    const std::string_view g = equals == std::string_view::npos ? value : value.substr(equals + 1);
    e.gain[axis] = number_in(g, 0.0, kMaxGroundGain, kind + " gain");
  } else if (what == "heading") {
    e.heading_rad = number_in(value, -kMaxHeadingDeg, kMaxHeadingDeg, kind + " heading (deg)") *
                    kDegree;
  } else {
    throw InputError("--fault: " + kind + ": expected gain:... or heading:..., got " +
                     host::shown(text));
  }
  return e;
}

}  // namespace

FaultedInput faulted_input(FaultKind kind) {
  switch (kind) {
    case FaultKind::kNone: return FaultedInput::kNone;
    case FaultKind::kGroundGain:
    case FaultKind::kGroundHeading:
    case FaultKind::kGroundPairPrimary:
    case FaultKind::kGroundPairSecond: return FaultedInput::kGroundSensor;
    case FaultKind::kReset:
    case FaultKind::kRestart: return FaultedInput::kBox;
    default: return FaultedInput::kStatueSensor;
  }
}

bool names_faulted_input(FaultedInput input, monitor::AlarmCause cause) {
  using monitor::AlarmCause;
  switch (input) {
    case FaultedInput::kNone: return false;
    case FaultedInput::kStatueSensor:
      return cause == AlarmCause::kStatueSensorFault || cause == AlarmCause::kStatueUnexplained;
    case FaultedInput::kGroundSensor:
      return cause == AlarmCause::kSensorFault || cause == AlarmCause::kSensorTimeout ||
             cause == AlarmCause::kSensorDisagreement;
    case FaultedInput::kBox:
      return cause == AlarmCause::kNotCalibrated || cause == AlarmCause::kRestored;
  }
  return false;
}

Eigen::Vector3d GroundSensorError::read(const Eigen::Vector3d& a) const {
  const double c = std::cos(heading_rad);
  const double s = std::sin(heading_rad);
  const Eigen::Vector3d turned(c * a.x() + s * a.y(), -s * a.x() + c * a.y(), a.z());
  return gain.cwiseProduct(turned);
}

Fault parse_fault(const std::string& text) {
  Fault f;
  const std::size_t colon = text.find(':');
  const std::string kind = text.substr(0, colon);
  if (!kFaultKindNames.parse(kind, f.kind)) {
    throw InputError("--fault: unknown kind " + host::shown(kind) +
                     " (plinth-eval run --help lists the kinds; docs/safety.md says what each "
                     "does)");
  }
  const bool has_param = colon != std::string::npos;
  f.param = has_param ? text.substr(colon + 1) : "";
  if (has_param && f.param.empty()) {
    throw InputError("--fault: " + kind + ": an empty parameter after ':'");
  }
  const auto refuse_param = [&] {
    if (has_param) {
      throw InputError("--fault: " + kind + " takes no parameter, got " + host::shown(f.param));
    }
  };
  const auto need_param = [&](const char* what) {
    if (!has_param) throw InputError("--fault: " + kind + " needs its parameter: " + what);
  };
  switch (f.kind) {
    case FaultKind::kNone:
    case FaultKind::kStatueAtRest:
    case FaultKind::kStatueStuck:
    case FaultKind::kStatueAxesSwapped:
    case FaultKind::kStatueNeighbour:
    case FaultKind::kStatueOnPlinth:
    case FaultKind::kReset: refuse_param(); break;
    case FaultKind::kStatueGain:
      need_param("the gyroscope's gain, e.g. statue_gain:0.5");
      f.value = number_in(f.param, 0.0, kMaxStatueGain, kind);
      if (!(f.value > 0.0)) throw InputError("--fault: " + kind + ": a gain above 0, got 0");
      break;
    case FaultKind::kStatueBias:
      need_param("deg/s, e.g. statue_bias:5");
      f.value = number_in(f.param, -kMaxStatueBiasDegS, kMaxStatueBiasDegS, kind + " (deg/s)") *
                kDegree;
      break;
    case FaultKind::kStatueSign:
      need_param("the axis x, y or z, e.g. statue_sign:y");
      f.axis = axis_index(f.param, kind);
      break;
    case FaultKind::kStatueDelay:
      need_param("s, e.g. statue_delay:0.1");
      f.value = number_in(f.param, 0.0, kMaxStatueDelayS, kind + " (s)");
      break;
    case FaultKind::kStatueDropout:
      need_param("s, e.g. statue_dropout:2");
      f.value = number_in(f.param, 0.0, kMaxDurationS, kind + " (s)");
      break;
    case FaultKind::kGroundGain:
      need_param("G (on x) or AXIS=G, e.g. ground_gain:0.5 or ground_gain:z=0.5");
      f.ground = ground_error("gain:" + f.param, kind);
      break;
    case FaultKind::kGroundHeading:
      need_param("degrees about the vertical, e.g. ground_heading:90");
      f.ground = ground_error("heading:" + f.param, kind);
      break;
    case FaultKind::kGroundPairPrimary:
    case FaultKind::kGroundPairSecond:
      need_param("the wrong sensor's fault, gain:G, gain:AXIS=G or heading:DEG");
      f.ground = ground_error(f.param, kind);
      break;
    case FaultKind::kRestart:
      f.value = has_param ? number_in(f.param, 0.0, kMaxDurationS, kind + " downtime (s)") : 0.0;
      break;
  }
  return f;
}

FaultOnset parse_fault_onset(const std::string& text) {
  FaultOnset onset;
  onset.text = text;
  if (text == "start") return onset;
  double t = 0.0;
  if (number(text, t)) {
    if (t < 0.0 || t > kMaxOnsetS) {
      throw InputError("--fault-at: a time from the record's start, s, expected 0 to 1e6, got " +
                       host::shown(text));
    }
    onset.anchor = FaultAnchor::kRecord;
    onset.offset_s = t;
    return onset;
  }
  const std::size_t sign = text.find_first_of("+-");
  const std::string anchor = text.substr(0, sign);
  if (anchor == "strong") {
    onset.anchor = FaultAnchor::kStrongMotion;
  } else if (anchor == "motion") {
    onset.anchor = FaultAnchor::kMotion;
  } else if (anchor == "alarm") {
    onset.anchor = FaultAnchor::kAlarm;
  } else {
    throw InputError("--fault-at: expected start, a time in s, or strong, motion or alarm with "
                     "an optional +S or -S, got " + host::shown(text));
  }
  if (sign == std::string::npos) return onset;
  if (!number(std::string_view(text).substr(sign), onset.offset_s) ||
      std::fabs(onset.offset_s) > kMaxOnsetS) {
    throw InputError("--fault-at: " + anchor + ": expected +S or -S seconds after it, got " +
                     host::shown(text));
  }
  if (onset.anchor == FaultAnchor::kAlarm && onset.offset_s < 0.0) {
    throw InputError("--fault-at: alarm" + text.substr(sign) +
                     ": a fault cannot begin before the alarm that times it (alarm+S)");
  }
  return onset;
}

bool needs_statue_sensor(FaultKind kind) {
  return faulted_input(kind) == FaultedInput::kStatueSensor;
}

bool happens_at_an_instant(FaultKind kind) {
  return kind == FaultKind::kReset || kind == FaultKind::kRestart;
}

}  // namespace plinth::sim
