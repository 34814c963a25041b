#include "plinth/host/run_output.h"

#include <cstdio>

namespace plinth::host {
namespace {

// Shortest round-trip representation is not needed; 10 significant digits keeps the event
// times exact to far below the solver step.
std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

std::string field(const char* key, const std::string& json_value) {
  return std::string(", \"") + key + "\": " + json_value;
}

std::string quoted(const char* text) { return std::string("\"") + text + "\""; }

}  // namespace

TimeHistoryCsv::TimeHistoryCsv(std::ostream& out) : out_(out) {
  out_ << kTimeHistoryHeader << '\n';
}

void TimeHistoryCsv::write_row(double t, double ag, const State& y, Phase phase) {
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%.6f,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%s\n", t, ag,
                y[kU], y[kUDot], y[kX], y[kXDot], y[kTheta], y[kThetaDot], phase_name(phase));
  out_ << buffer;
}

Outcome outcome_of(Phase final_phase) {
  if (final_phase == Phase::kOverturned) return Outcome::kOverturned;
  if (final_phase == Phase::kFell) return Outcome::kFell;  // fell off the base
  if (final_phase == Phase::kLiftedOff) return Outcome::kLiftedOff;
  return Outcome::kSurvived;
}

std::string event_json(const Event& e) {
  std::string line = "{\"t\": " + number(e.t) + ", \"event\": " + quoted(event_name(e.kind));
  switch (e.kind) {
    case EventKind::kRockingStart:
    case EventKind::kOverturned:
      line += field("corner", quoted(corner_name(e.corner)));
      line += field("pivot", quoted(pivots_on_support(e.corner, e.overhang) ? "support" : "body"));
      break;
    case EventKind::kImpact:
      line += field("corner", quoted(corner_name(e.corner)));
      line += field("pivot", quoted(pivots_on_support(e.corner, e.overhang) ? "support" : "body"));
      line += field("theta_dot_before", number(e.before));
      line += field("theta_dot_after", number(e.after));
      break;
    case EventKind::kRockingStop:
      line += field("theta_dot_before", number(e.before));
      break;
    case EventKind::kBaseStopHit:
      line += field("side", quoted(e.side > 0 ? "right" : "left"));
      line += field("u_dot_before", number(e.before));
      line += field("u_dot_after", number(e.after));
      break;
    case EventKind::kBaseStopHeld:
    case EventKind::kBaseStopReleased:
    case EventKind::kOutOfBase:
    case EventKind::kBackOnBase:
    case EventKind::kFell:
      line += field("side", quoted(e.side > 0 ? "right" : "left"));
      break;
    case EventKind::kSlidingStart:
      line += field("direction", quoted(e.side > 0 ? "right" : "left"));
      break;
    case EventKind::kSlidingStop:
      break;
    case EventKind::kSlideStopHit:
      line += field("side", quoted(e.side > 0 ? "right" : "left"));
      line += field("x_dot_before", number(e.before));
      line += field("u_dot_after", number(e.after));
      break;
    case EventKind::kLiftOff:
      line += field("from", quoted(phase_name(e.left)));
      if (e.left == Phase::kRocking || e.left == Phase::kSlideRocking) {
        line += field("corner", quoted(corner_name(e.corner)));
        line += field("pivot", quoted(pivots_on_support(e.corner, e.overhang) ? "support" : "body"));
        line += field("theta_dot", number(e.state[kThetaDot]));
      }
      line += field("g_plus_vertical", number(e.before));
      break;
  }
  line += field("u", number(e.state[kU]));
  line += field("x", number(e.state[kX]));
  line += field("theta", number(e.state[kTheta]));
  line += "}";
  return line;
}

std::string end_json(double t, Outcome outcome, double lift_off_t) {
  std::string line = "{\"t\": " + number(t) + ", \"event\": \"end\", \"outcome\": " +
                     quoted(outcome_name(outcome));
  if (outcome == Outcome::kLiftedOff) line += field("model_valid_until", number(lift_off_t));
  return line + "}";
}

}  // namespace plinth::host
