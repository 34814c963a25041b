#include "plinth/core/ensemble.h"

namespace plinth {

Error Ensemble::start(std::span<const Scene> members, const EstimatorSettings& estimator,
                      const ForecastSettings& forecast, const RiskSettings& risk) {
  PLINTH_TRY(validate(risk));
  if (members.size() > static_cast<std::size_t>(kMaxEnsembleMembers)) {
    return {ErrorCode::kOutOfRange, "uncertainty",
            "gives more ensemble members than this build holds (kMaxEnsembleMembers)",
            static_cast<double>(kMaxEnsembleMembers)};
  }
  for (const Scene& scene : members) PLINTH_TRY(validate(estimator, scene));
  PLINTH_TRY(forecaster_.start(forecast, estimator.sample_rate_hz));
  scenes_ = members;
  estimator_ = estimator;
  risk_ = risk;
  return ok_error();
}

void Ensemble::restart(GroundAcceleration first) {
  // start() checked what PlanarEstimator::start can refuse but a non-finite sample, which the
  // box's conditioning does not pass on.
  for (std::size_t m = 0; m < scenes_.size(); ++m) {
    (void)members_[m].start(scenes_[m], estimator_, first);
  }
  members_[0].set_event_sink(sink_);
  forecaster_.reset();
}

void Ensemble::push(GroundAcceleration sample) {
  const std::span<PlanarEstimator> members = running();
  for (PlanarEstimator& e : members) e.push(sample);
  forecaster_.on_sample(sample, members[0].time(), members);
}

void Ensemble::set_event_sink(EventSink* sink) {
  sink_ = sink;
  members_[0].set_event_sink(sink);
}

bool Ensemble::in_full_contact() const {
  bool contact = true;
  for (std::size_t m = 0; m < scenes_.size(); ++m) {
    contact = contact && members_[m].mode().phase == Phase::kFullContact;
  }
  return contact;
}

void Ensemble::risk(EnsembleRisk& out) const {
  out.risk = Risk{};
  out.worst_member = 0;
  out.outside_model = false;
  for (std::size_t m = 0; m < scenes_.size(); ++m) {
    const PlanarEstimator& e = members_[m];
    out.outside_model = out.outside_model || e.mode().phase == Phase::kLiftedOff;
    const Risk member = overturning_risk(scenes_[m], e.mode(), e.state(), risk_);
    if (m == 0) out.nominal_risk = member;
    if (m == 0 || member.total > out.risk.total) {
      out.risk = member;
      out.worst_member = static_cast<int>(m);
    }
  }
}

Real Ensemble::base_acceleration(int member) const {
  const PlanarEstimator& m = members_[static_cast<std::size_t>(member)];
  return m.simulator().accelerations().u + m.ground().horizontal;
}

}  // namespace plinth
