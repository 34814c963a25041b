#include "plinth/core/forecast.h"

#include <cmath>

namespace plinth {

namespace {

bool within(double value, double low, double high) {
  return std::isfinite(value) && value >= low && value <= high;
}

// Input samples averaged into one continuation sample: the nearest whole ratio, at least 1.
int decimation_for(double rate_hz, double input_rate_hz) {
  const long ratio = std::lround(input_rate_hz / rate_hz);
  return ratio < 1 ? 1 : static_cast<int>(ratio);
}

}  // namespace

Error validate(const ForecastSettings& s, double input_rate_hz) {
  if (!s.enabled) return ok_error();  // nothing of it runs
  if (!kForecastBuiltIn) {
    return {ErrorCode::kInconsistent, "forecast.enabled",
            "this build has no forecast (PLINTH_FORECAST=OFF): set it false"};
  }
  if (!within(s.horizon_s, 1e-3, 10.0)) {
    return {ErrorCode::kOutOfRange, "forecast.horizon_s", "must lie in (0, 10] s", 10.0};
  }
  if (!within(s.rate_hz, 50.0, 1000.0)) {
    return {ErrorCode::kOutOfRange, "forecast.rate_hz", "must lie in [50, 1000] Hz"};
  }
  if (!within(input_rate_hz, 1.0, 1e6)) {
    return {ErrorCode::kOutOfRange, "estimator.sample_rate_hz", "must be a positive rate"};
  }
  const double rate = input_rate_hz / decimation_for(s.rate_hz, input_rate_hz);
  if (!within(s.window_s, 0.5, 1e9) || s.window_s * rate > kMaxWindowSamples) {
    return {ErrorCode::kOutOfRange, "forecast.window_s",
            "must be at least 0.5 s and hold at most 1024 samples at forecast.rate_hz",
            kMaxWindowSamples / rate};
  }
  if (s.horizon_s * rate + 1.0 > kMaxContinuationSamples) {
    return {ErrorCode::kOutOfRange, "forecast.horizon_s",
            "holds more than 2048 samples at forecast.rate_hz: shorten it or lower the rate",
            (kMaxContinuationSamples - 1) / rate};
  }
  if (!within(s.growth, 0.5, 4.0)) {
    return {ErrorCode::kOutOfRange, "forecast.growth", "must lie in [0.5, 4]"};
  }
  if (!within(s.memory_s, 1e-3, 1e6)) {
    return {ErrorCode::kOutOfRange, "forecast.memory_s", "must be a positive time, s"};
  }
  if (!within(s.interval_s, 1e-3, 3600.0)) {
    return {ErrorCode::kOutOfRange, "forecast.interval_s", "must lie in (0, 3600] s"};
  }
  if (s.steps_per_period < 1 || s.steps_per_period > 16) {
    return {ErrorCode::kOutOfRange, "forecast.steps_per_period", "must lie in [1, 16]"};
  }
  if (!within(s.work_steps_per_s, 1000.0, 1e9)) {
    return {ErrorCode::kOutOfRange, "forecast.work_steps_per_s", "must lie in [1000, 1e9]"};
  }
  if (s.continuation != Continuation::kRecentWindow &&
      s.continuation != Continuation::kStrongestWindow) {
    return {ErrorCode::kOutOfRange, "forecast.continuation",
            "must be recent_window or strongest_window"};
  }
  return ok_error();
}

Error Forecaster::start(const ForecastSettings& settings, double input_rate_hz) {
  PLINTH_TRY(validate(settings, input_rate_hz));
  settings_ = settings;
  if constexpr (!kForecastBuiltIn) {
    // validate() let only a disabled forecast through: nothing of it is built or linked.
    started_ = true;
    reset();
    return ok_error();
  }
  decimation_ = decimation_for(settings.rate_hz, input_rate_hz);
  rate_hz_ = input_rate_hz / decimation_;
  window_length_ = static_cast<int>(std::lround(settings.window_s * rate_hz_));
  continuation_length_ = static_cast<int>(std::ceil(settings.horizon_s * rate_hz_)) + 1;
  step_s_ = 1.0 / (rate_hz_ * settings.steps_per_period);
  horizon_steps_ = std::llround(settings.horizon_s / step_s_);
  budget_per_sample_ = settings.work_steps_per_s / input_rate_hz;
  started_ = true;
  steps_taken_ = 0;
  reset();
  return ok_error();
}

void Forecaster::reset() {
  sum_ = {};
  summed_ = 0;
  window_next_ = 0;
  window_count_ = 0;
  have_strongest_ = false;
  strongest_energy_ = 0.0;
  members_ = 0;
  member_ = 0;
  ever_begun_ = false;
  carry_ = 0.0;
  latest_ = ForecastOutcome{};
}

void Forecaster::push_window(GroundAcceleration averaged) {
  window_[static_cast<std::size_t>(window_next_)] = averaged;
  window_next_ = window_next_ + 1 >= window_length_ ? 0 : window_next_ + 1;
  if (window_count_ < window_length_) ++window_count_;
}

double Forecaster::window_energy() const {
  double sum = 0.0;
  for (int i = 0; i < window_count_; ++i) {
    const double a = window_[static_cast<std::size_t>(i)].horizontal;
    sum += a * a;
  }
  return sum;
}

void Forecaster::on_sample(GroundAcceleration sample, double time_s,
                           std::span<const PlanarEstimator> members) {
  if (!kForecastBuiltIn || !started_ || !settings_.enabled) return;
  sum_.horizontal += sample.horizontal;
  sum_.vertical += sample.vertical;
  if (++summed_ >= decimation_) {
    push_window(
        {sum_.horizontal / static_cast<Real>(summed_), sum_.vertical / static_cast<Real>(summed_)});
    sum_ = {};
    summed_ = 0;
  }
  const bool due = !ever_begun_ || time_s - last_begin_s_ >= settings_.interval_s - 1e-9;
  if (!running() && due && window_count_ >= window_length_) begin(time_s, members);
  if (running()) work(budget_per_sample_);
}

void Forecaster::begin(double time_s, std::span<const PlanarEstimator> members) {
  members_ = static_cast<int>(members.size() < kMaxEnsembleMembers ? members.size()
                                                                    : kMaxEnsembleMembers);
  for (int m = 0; m < members_; ++m) {
    const PlanarEstimator& e = members[static_cast<std::size_t>(m)];
    snapshots_[static_cast<std::size_t>(m)] = {e.mode(), e.state(), &e.scene()};
  }
  ever_begun_ = true;
  last_begin_s_ = time_s;
  begin_time_s_ = time_s;
  building_ = ForecastOutcome{};
  building_.start_time_s = time_s;
  building_.members = members_;
  fill_continuation();
  member_ = 0;
  carry_ = 0.0;
  start_member();
}

// The window (oldest sample first), or the strongest one, repeated to the horizon, times
// growth. The strongest window is replaced when the recent one carries more energy than what
// is left of it.
void Forecaster::fill_continuation() {
  const std::array<GroundAcceleration, kMaxWindowSamples>* source = &window_;
  int first = window_next_;  // the ring's oldest sample
  if (settings_.continuation == Continuation::kStrongestWindow) {
    const double decay = have_strongest_
                             ? std::exp(-(begin_time_s_ - strongest_time_s_) / settings_.memory_s)
                             : 0.0;
    const double recent = window_energy();
    if (!have_strongest_ || recent >= strongest_energy_ * decay) {
      for (int i = 0; i < window_length_; ++i) {
        strongest_[static_cast<std::size_t>(i)] =
            window_[static_cast<std::size_t>((first + i) % window_length_)];
      }
      strongest_energy_ = recent;
      strongest_time_s_ = begin_time_s_;
      have_strongest_ = true;
    }
    source = &strongest_;
    first = 0;
  }
  double scale = settings_.growth;
  if (settings_.continuation == Continuation::kStrongestWindow) {
    scale *= std::sqrt(std::exp(-(begin_time_s_ - strongest_time_s_) / settings_.memory_s));
  }
  for (int i = 0; i < continuation_length_; ++i) {
    const GroundAcceleration& a = (*source)[static_cast<std::size_t>((first + i) % window_length_)];
    horizontal_[static_cast<std::size_t>(i)] = scale * static_cast<double>(a.horizontal);
    vertical_[static_cast<std::size_t>(i)] = scale * static_cast<double>(a.vertical);
  }
}

void Forecaster::start_member() {
  while (member_ < members_) {
    const Snapshot& s = snapshots_[static_cast<std::size_t>(member_)];
    if (s.mode.terminal()) {  // collapsed (or lifted off) already: at the snapshot's time
      finish_member(true, 0.0);
      continue;
    }
    SolverSettings solver;
    solver.step = step_s_;
    solver.exact_full_contact = true;
    const auto count = static_cast<std::size_t>(continuation_length_);
    const Excitation continuation =
        Excitation::record(SampledSignal{horizontal_.data(), count, 1.0 / rate_hz_},
                           SampledSignal{vertical_.data(), count, 1.0 / rate_hz_});
    if (!Simulator::create(*s.scene, continuation, solver, simulator_).ok()) {
      // The members' scenes integrate stably at the estimator's step; a forecast step the
      // scene cannot take makes no statement about this member.
      finish_member(false, 0.0);
      continue;
    }
    simulator_.start_from(s.mode, s.state);
    member_steps_ = 0;
    return;
  }
}

void Forecaster::finish_member(bool collapsed, double time_s) {
  if (collapsed) {
    ++building_.collapsing;
    building_.collapsing_members |= std::uint32_t{1} << static_cast<unsigned>(member_);
    building_.member_collapse_in_s[static_cast<std::size_t>(member_)] =
        static_cast<float>(time_s);
    if (building_.worst_member < 0 || time_s < building_.collapse_in_s) {
      building_.worst_member = member_;
      building_.collapse_in_s = time_s;
    }
  }
  ++member_;
  if (member_ >= members_) {
    building_.valid = true;
    building_.probability =
        members_ > 0 ? static_cast<double>(building_.collapsing) / members_ : 0.0;
    latest_ = building_;
  }
}

void Forecaster::work(double step_budget) {
  double budget = step_budget + carry_;
  while (running() && budget >= 1.0) {
    simulator_.step();
    ++member_steps_;
    ++steps_taken_;
    budget -= 1.0;
    if (simulator_.mode().terminal()) {
      finish_member(true, simulator_.time());
      start_member();
    } else if (member_steps_ >= horizon_steps_) {
      finish_member(false, 0.0);
      start_member();
    }
  }
  carry_ = running() ? budget : 0.0;
}

}  // namespace plinth
