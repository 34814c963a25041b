// plinth-sim's output formats: the CSV time history and the JSON Lines event log
// (documented in docs/output-formats.md; integrators parse them, keep them stable).
#pragma once

#include <ostream>
#include <string>

#include "plinth/core/events.h"
#include "plinth/core/name_table.h"
#include "plinth/core/state.h"

namespace plinth::host {

inline constexpr const char* kTimeHistoryHeader = "t,ag,u,u_dot,x,x_dot,theta,theta_dot,phase";

// Writes one CSV row per call: SI units, ag the horizontal ground acceleration in m/s2.
class TimeHistoryCsv {
 public:
  explicit TimeHistoryCsv(std::ostream& out);
  void write_row(double t, double ag, const State& y, Phase phase);

 private:
  std::ostream& out_;
};

// kLiftedOff: the block lost contact with its support at the end time; the model has no free
// flight, so nothing after it is known (neither survival nor collapse).
enum class Outcome { kSurvived, kOverturned, kFell, kLiftedOff };

inline constexpr NameTable<Outcome, 4> kOutcomeNames{{{
    {Outcome::kSurvived, "survived"},
    {Outcome::kOverturned, "overturned"},
    {Outcome::kFell, "fell"},
    {Outcome::kLiftedOff, "lifted_off"},
}}};
[[nodiscard]] constexpr const char* outcome_name(Outcome outcome) {
  return kOutcomeNames.name(outcome);
}
[[nodiscard]] Outcome outcome_of(Phase final_phase);

// One JSON object per line: {"t": s, "event": name, ...details}.
[[nodiscard]] std::string event_json(const Event& event);
// The last line: {"t": s, "event": "end", "outcome": "survived" | "overturned" | "fell" |
// "lifted_off"}; with lifted_off also "model_valid_until": s, the lift-off event's time.
[[nodiscard]] std::string end_json(double t, Outcome outcome, double lift_off_t = 0.0);

}  // namespace plinth::host
