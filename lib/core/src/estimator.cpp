#include "plinth/core/estimator.h"

#include <cmath>

#include "plinth/core/stability.h"

namespace plinth {

Error validate(const EstimatorSettings& st, const Scene& scene) {
  if (!std::isfinite(st.sample_rate_hz) || st.sample_rate_hz < 100.0 ||
      st.sample_rate_hz > 1000.0) {
    return {ErrorCode::kOutOfRange, "estimator.sample_rate_hz", "must lie in [100, 1000] Hz"};
  }
  if (st.steps_per_sample < 1 || st.steps_per_sample > 64) {
    return {ErrorCode::kOutOfRange, "estimator.steps_per_sample", "must lie in [1, 64]"};
  }
  SolverSettings solver = st.solver;
  solver.step = st.step();
  PLINTH_TRY(validate(solver));
  PLINTH_TRY(validate_feature_set(scene));
  if (const auto limit = static_cast<Time>(largest_stable_step(scene, solver.stepper));
      solver.step > limit) {
    // The limit: the steps per sample a stable integration needs at this rate (the tools round
    // it up). Above 64, the most the box takes, the base is the culprit: the tools say so.
    return {ErrorCode::kOutOfRange, "estimator.steps_per_sample",
            "too few for this base at this rate (limit: the steps needed)",
            static_cast<double>(Time(1) / (st.sample_rate_hz * limit))};
  }
  return ok_error();
}

Error PlanarEstimator::start(const Scene& scene, const EstimatorSettings& settings,
                             GroundAcceleration first) {
  PLINTH_TRY(validate(settings, scene));
  if (!std::isfinite(first.horizontal) || !std::isfinite(first.vertical)) {
    return {ErrorCode::kNotFinite, "sample", "the first ground acceleration is not finite"};
  }
  SolverSettings solver = settings.solver;
  solver.step = settings.step();
  stream_.reset(settings.sample_period(), first);
  PLINTH_TRY(Simulator::create(scene, Excitation::streamed(stream_), solver, simulator_));
  steps_per_sample_ = settings.steps_per_sample;
  simulator_.start_at_rest();
  started_ = true;
  return ok_error();
}

void PlanarEstimator::push(GroundAcceleration sample) {
  stream_.push(sample);
  for (int i = 0; i < steps_per_sample_; ++i) simulator_.step();
}

}  // namespace plinth
