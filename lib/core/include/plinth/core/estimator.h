// The real-time estimator of one planar model: ground acceleration samples in at the sensor
// rate, the solver stepping a whole number of times per sample period (the input interpolated
// linearly between samples, as plinth-sim interpolates a record), the block's phase and state
// out. No heap, no exceptions: sized at compile time, set up once at start-up.
#pragma once

#include <cstdint>

#include "plinth/core/error.h"
#include "plinth/core/excitation.h"
#include "plinth/core/real.h"
#include "plinth/core/scene.h"
#include "plinth/core/simulator.h"

namespace plinth {

struct EstimatorSettings {
  double sample_rate_hz = 200.0;  // Hz, the sensor rate: 100 to 1000 (the time base: Time's type)
  int steps_per_sample = 4;       // solver steps per sample period: 1 to 64
  // The solver's other settings; its step is 1 / (sample_rate_hz * steps_per_sample). Full
  // contact propagated exactly, as docs/accuracy.md recommends for the box: a quiet step costs
  // a fraction of an RK4 one and the base's motion is exact between samples.
  SolverSettings solver{.exact_full_contact = true};

  [[nodiscard]] Time sample_period() const { return 1.0 / sample_rate_hz; }
  [[nodiscard]] Time step() const { return sample_period() / static_cast<Time>(steps_per_sample); }
};

// Checks the settings and that the resulting step is stable for `scene`; the Error names the
// field ("estimator.sample_rate_hz", "estimator.steps_per_sample", "solver.step", ...).
[[nodiscard]] Error validate(const EstimatorSettings& settings, const Scene& scene);

class PlanarEstimator {
 public:
  PlanarEstimator() = default;
  // The solver refers to this object's input stream: it stays where it was started.
  PlanarEstimator(const PlanarEstimator&) = delete;
  PlanarEstimator& operator=(const PlanarEstimator&) = delete;

  // At rest in full contact at t = 0, where the ground acceleration is `first` (sample 0).
  // `scene` must outlive the estimator.
  [[nodiscard]] Error start(const Scene& scene, const EstimatorSettings& settings,
                            GroundAcceleration first);
  // Sample n + 1 arrived (t = (n + 1) / rate): the model advances to it.
  void push(GroundAcceleration sample);

  void set_event_sink(EventSink* sink) { simulator_.set_event_sink(sink); }

  [[nodiscard]] bool started() const { return started_; }
  [[nodiscard]] Time time() const { return simulator_.time(); }
  [[nodiscard]] std::int64_t samples() const { return stream_.latest_index; }
  [[nodiscard]] const Mode& mode() const { return simulator_.mode(); }
  [[nodiscard]] const State& state() const { return simulator_.state(); }
  [[nodiscard]] const Scene& scene() const { return simulator_.scene(); }
  [[nodiscard]] const Simulator& simulator() const { return simulator_; }
  // The ground acceleration the model sees now.
  [[nodiscard]] GroundAcceleration ground() const { return stream_.latest; }

 private:
  GroundStream stream_;
  Simulator simulator_;
  int steps_per_sample_ = 1;
  bool started_ = false;
};

}  // namespace plinth
