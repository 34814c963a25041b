#include "plinth/firmware/monitor.h"

#include <cmath>

namespace plinth::firmware {

Error validate(const MonitorConfig& c) {
  if (c.axis_count < 1 || c.axis_count > kMaxAxes) {
    return {ErrorCode::kOutOfRange, "monitor.axis_count", "must be 1 or 2"};
  }
  if (c.ground_node < can::kFirstSensorNode || c.ground_node > can::kLastSensorNode) {
    return {ErrorCode::kOutOfRange, "monitor.ground_node", "must lie in [1, 15]"};
  }
  if (!std::isfinite(c.quiet_risk) || c.quiet_risk < 0.0 || c.quiet_risk > 1.0) {
    return {ErrorCode::kOutOfRange, "monitor.quiet_risk", "must lie in [0, 1]"};
  }
  if (Error e = validate(c.risk); !e.ok()) return e;
  if (Error e = monitor::validate(c.alarm); !e.ok()) return e;
  // The sensor's period is the estimator's sample period: checked with the values start() uses.
  if (!std::isfinite(c.estimator.sample_rate_hz) || c.estimator.sample_rate_hz < 100.0 ||
      c.estimator.sample_rate_hz > 1000.0) {
    return {ErrorCode::kOutOfRange, "estimator.sample_rate_hz", "must lie in [100, 1000] Hz"};
  }
  monitor::ConditioningSettings conditioning = c.conditioning;
  conditioning.sample_period_s = c.estimator.sample_period();
  if (Error e = monitor::validate(conditioning); !e.ok()) return e;
  monitor::SensorHealthSettings health = c.sensor_health;
  health.sample_period_s = c.estimator.sample_period();
  return monitor::validate(health);
}

Error Monitor::start(const MonitorConfig& config,
                     const std::array<const Scene*, kMaxAxes>& scenes) {
  if (Error e = validate(config); !e.ok()) return e;
  for (int i = 0; i < config.axis_count; ++i) {
    const Scene* scene = scenes[static_cast<std::size_t>(i)];
    if (scene == nullptr) {
      return {ErrorCode::kInconsistent, "monitor.axis_count", "names an axis without a scene"};
    }
    if (Error e = validate(config.estimator, *scene); !e.ok()) return e;
  }
  config_ = config;
  config_.conditioning.sample_period_s = config.estimator.sample_period();
  config_.sensor_health.sample_period_s = config.estimator.sample_period();
  if (Error e = monitor::SensorHealthTracker::create(config_.sensor_health, health_); !e.ok()) {
    return e;
  }
  if (Error e = monitor::Conditioner::create(config_.conditioning, conditioner_); !e.ok()) {
    return e;
  }
  if (Error e = monitor::AlarmPolicy::create(config_.alarm, alarm_); !e.ok()) return e;
  scenes_ = scenes;
  status_ = MonitorStatus{};
  status_.axis_count = config.axis_count;
  status_.sensor = health_.health();
  frames_ = FrameCounters{};
  have_epoch_ = false;
  bus_fault_ = false;
  pending_ack_ = false;
  return ok_error();
}

void Monitor::set_event_sink(int axis, EventSink* sink) {
  if (axis < 0 || axis >= kMaxAxes) return;
  const auto i = static_cast<std::size_t>(axis);
  sinks_[i] = sink;
  estimators_[i].set_event_sink(sink);
}

std::int64_t Monitor::monitor_time(std::int64_t receive_time_ns) {
  if (!have_epoch_) {
    have_epoch_ = true;
    epoch_ns_ = receive_time_ns;
  }
  const std::int64_t t = receive_time_ns - epoch_ns_;
  return t > status_.time_ns ? t : status_.time_ns;  // never backwards
}

MonitorUpdate Monitor::on_sample(const monitor::SensorSample& sample) {
  MonitorUpdate update;
  status_.time_ns = monitor_time(sample.receive_time_ns);
  const monitor::SensorUpdate fed = health_.on_sample(sample);
  for (std::size_t i = 0; i < fed.fed_count; ++i) feed(fed.fed[i]);
  evaluate(update);
  return update;
}

void Monitor::feed(const monitor::FedSample& sample) {
  bool quiet = status_.estimating && status_.risk < config_.quiet_risk;
  for (int i = 0; i < status_.axis_count; ++i) {
    quiet = quiet && status_.axes[static_cast<std::size_t>(i)].mode.phase == Phase::kFullContact;
  }
  const monitor::ConditionedSample c = conditioner_.condition(sample.acceleration_g, quiet);
  if (!c.ready) return;  // start-up window, or refused input (counted by the conditioner)
  const bool restart = !status_.estimating || sample.restart;
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const GroundAcceleration ground{c.ground_m_s2[i], c.ground_m_s2.z()};
    if (restart) {
      // validate() in start() checked what start() can refuse but a non-finite sample, which
      // conditioning does not pass on.
      (void)estimators_[k].start(*scenes_[k], config_.estimator, ground);
      estimators_[k].set_event_sink(sinks_[k]);
    } else {
      estimators_[k].push(ground);
    }
  }
  if (restart) {
    ++status_.estimator_restarts;
    status_.estimator_start_ns = sample.time_ns - epoch_ns_;
  }
  status_.estimating = true;
  status_.newest_sample_time_ns = sample.time_ns - epoch_ns_;
}

void Monitor::evaluate(MonitorUpdate& update) {
  status_.sensor = health_.health();
  double risk = 0.0;
  bool moving = false;
  bool collapse = false;
  for (int i = 0; i < status_.axis_count; ++i) {
    const auto k = static_cast<std::size_t>(i);
    AxisStatus& axis = status_.axes[k];
    if (status_.estimating) {
      axis.mode = estimators_[k].mode();
      axis.state = estimators_[k].state();
      axis.risk = overturning_risk(*scenes_[k], axis.mode, axis.state, config_.risk);
    }
    risk = axis.risk.total > risk ? axis.risk.total : risk;
    moving = moving || axis.mode.phase != Phase::kFullContact;
    collapse = collapse || axis.mode.terminal();
  }
  status_.risk = risk;

  monitor::AlarmInput input;
  input.time_ns = status_.time_ns;
  input.risk = risk;
  input.out_of_full_contact = moving;
  input.collapse_detected = collapse;
  const bool sensor_fault = status_.sensor.state == monitor::HealthState::kFault;
  input.fault_active = sensor_fault || bus_fault_;
  input.fault_cause = sensor_fault ? monitor::to_alarm_cause(status_.sensor.cause)
                                   : can::AlarmCause::kBusError;
  input.acknowledged = pending_ack_;
  input.acknowledgement = ack_;
  pending_ack_ = false;
  const monitor::AlarmOutput out = alarm_.update(input);
  for (std::size_t i = 0; i < out.event_count && update.event_count < update.events.size(); ++i) {
    update.events[update.event_count++] = out.events[i];
  }
  if (out.acknowledgement != monitor::AckOutcome::kNone) update.acknowledgement = out.acknowledgement;
  status_.alarm = out.level;
  status_.latched = out.latched_level;
  update.status_due = update.status_due || out.event_count > 0 || alarm_.heartbeat_due(status_.time_ns);
}

MonitorUpdate Monitor::on_tick(std::int64_t receive_time_ns) {
  MonitorUpdate update;
  if (have_epoch_) {
    (void)health_.tick(receive_time_ns);
    status_.time_ns = monitor_time(receive_time_ns);
  }
  evaluate(update);
  return update;
}

MonitorUpdate Monitor::on_frame(const hal::TimedFrame& timed) {
  ++frames_.received;
  const can::CanFrame& frame = timed.frame;
  const auto reject = [&](const can::DecodeResult& r) {
    ++frames_.rejected;
    frames_.last_error = r.error;
    frames_.last_error_signal = r.signal;
  };
  switch (can::classify(frame.id)) {
    case can::MessageKind::kSensorAcceleration: {
      can::SensorAcceleration message;
      if (const can::DecodeResult r = can::decode(frame, message); !r.ok()) {
        reject(r);
        return {};
      }
      if (message.node != config_.ground_node) {
        ++frames_.other_nodes;
        return {};
      }
      ++frames_.sensor_samples;
      monitor::SensorSample sample;
      sample.receive_time_ns = timed.timestamp_ns;
      sample.sequence = message.sequence;
      sample.status = message.status;
      sample.acceleration_g = Eigen::Vector3d(message.ax_g, message.ay_g, message.az_g);
      return on_sample(sample);
    }
    case can::MessageKind::kSensorHeartbeat: {
      can::SensorHeartbeat message;
      if (const can::DecodeResult r = can::decode(frame, message); !r.ok()) {
        reject(r);
      } else {
        ++frames_.heartbeats;
      }
      return {};
    }
    case can::MessageKind::kAcknowledge: {
      can::Acknowledge message;
      if (const can::DecodeResult r = can::decode(frame, message); !r.ok()) {
        reject(r);
        return {};
      }
      ++frames_.acknowledgements;
      pending_ack_ = true;
      ack_ = {message.level, message.event_sequence};
      MonitorUpdate update;
      evaluate(update);  // at once, at the current monitor time
      return update;
    }
    case can::MessageKind::kMonitorStatus: {
      can::MonitorStatus message;
      if (const can::DecodeResult r = can::decode(frame, message); !r.ok()) {
        reject(r);
      } else {
        ++frames_.monitor_frames;
      }
      return {};
    }
    case can::MessageKind::kAlarmEvent: {
      can::AlarmEvent message;
      if (const can::DecodeResult r = can::decode(frame, message); !r.ok()) {
        reject(r);
      } else {
        ++frames_.monitor_frames;
      }
      return {};
    }
    case can::MessageKind::kUnknown:
      ++frames_.unknown_identifiers;
      return {};
  }
  return {};
}

}  // namespace plinth::firmware
