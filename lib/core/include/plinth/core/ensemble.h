// The statues of one axis as the box models them: member 0 the scene file's statue (the
// nominal one), the others points of the two-level design over its declared uncertainty
// (ensemble_design.h), each a PlanarEstimator fed the same measured ground motion, and one
// Forecaster that integrates them ahead (forecast.h). The ensemble's risk is its worst member's:
// the box warns for the most fragile statue it cannot rule out (docs/forecast.md). Freestanding:
// no heap; at most kMaxEnsembleMembers members. An Ensemble refers to its members' scenes and
// its estimators to their own input streams: it stays where it was started.
#pragma once

#include <array>
#include <span>

#include "plinth/core/error.h"
#include "plinth/core/estimator.h"
#include "plinth/core/events.h"
#include "plinth/core/excitation.h"
#include "plinth/core/forecast.h"
#include "plinth/core/real.h"
#include "plinth/core/risk.h"
#include "plinth/core/scene.h"

namespace plinth {

// The members' risks combined.
struct EnsembleRisk {
  Risk risk;             // the worst member's: the highest total (the first of equals)
  Risk nominal_risk;     // member 0's: the scene file's statue alone
  int worst_member = 0;  // whose `risk` that is
  // A member's estimate ended outside the model (Phase::kLiftedOff): the box cannot vouch for
  // this axis until its estimators start again (the alarm policy's outside_model).
  bool outside_model = false;
};

class Ensemble {
 public:
  Ensemble() = default;
  Ensemble(const Ensemble&) = delete;
  Ensemble& operator=(const Ensemble&) = delete;

  // `members`: the statues, the nominal one first; they must outlive the ensemble. Refuses
  // more than kMaxEnsembleMembers (field "uncertainty"), a member the estimator's settings do
  // not suit (validate(EstimatorSettings, Scene)) and the forecast's settings
  // (validate(ForecastSettings, rate)), in that order. The members start with restart().
  [[nodiscard]] Error start(std::span<const Scene> members, const EstimatorSettings& estimator,
                            const ForecastSettings& forecast, const RiskSettings& risk);

  // Every member at rest in full contact on `first` (its sample 0); the forecast forgets the
  // motion. The nominal statue's phase changes and impacts go to the event sink.
  void restart(GroundAcceleration first);
  // The next sample: every member advances to it, then the forecaster does its share.
  void push(GroundAcceleration sample);
  // Phase changes and impacts of the nominal statue go to `sink` (nullptr: nowhere).
  void set_event_sink(EventSink* sink);

  // Every member in full contact.
  [[nodiscard]] bool in_full_contact() const;
  // The members' risks (the status keeps them in place: AxisStatus is an EnsembleRisk).
  void risk(EnsembleRisk& out) const;
  // Member `member`'s absolute base acceleration u'' + u_G'' (Simulator::accelerations() of its
  // mode, plus the ground's), m/s2; by default the nominal statue's.
  [[nodiscard]] Real base_acceleration(int member = 0) const;

  [[nodiscard]] int size() const { return static_cast<int>(scenes_.size()); }
  [[nodiscard]] const PlanarEstimator& member(int m) const {
    return members_[static_cast<std::size_t>(m)];
  }
  [[nodiscard]] const PlanarEstimator& nominal() const { return members_[0]; }
  [[nodiscard]] const Forecaster& forecaster() const { return forecaster_; }

 private:
  [[nodiscard]] std::span<PlanarEstimator> running() {
    return {members_.data(), scenes_.size()};
  }

  std::span<const Scene> scenes_;
  std::array<PlanarEstimator, kMaxEnsembleMembers> members_{};
  Forecaster forecaster_;
  EstimatorSettings estimator_;
  RiskSettings risk_;
  EventSink* sink_ = nullptr;
};

}  // namespace plinth
