#include "status_json.h"

#include <cstdio>

#include "plinth/core/state.h"
#include "plinth/hal/can_codec.h"
#include "plinth/host/json_text.h"
#include "plinth/host/run_output.h"

namespace plinth::firmware {

// The CAN protocol (hal/can_codec).
namespace can = hal::can;
namespace {

constexpr const char* kAxisNames[] = {"x", "y"};

double seconds(std::int64_t time_ns, double t_origin) {
  return static_cast<double>(time_ns) * 1e-9 - t_origin;
}

std::string quoted(std::string_view text) { return plinth::host::json_quoted(text); }

// `digits` decimals ("%.*f"), or `digits` significant digits ("%.*g").
std::string formatted(double value, int digits, bool fixed) {
  char text[64];
  if (fixed) {
    std::snprintf(text, sizeof text, "%.*f", digits, value);
  } else {
    std::snprintf(text, sizeof text, "%.*g", digits, value);
  }
  return text;
}

// One axis's value, or {"x": .., "y": ..} with two axes.
template <typename ValueOf>
std::string per_axis(const BoxStatus& s, ValueOf value_of) {
  if (s.axis_count == 1) return value_of(s.axes[0]);
  JsonObject axes;
  for (int i = 0; i < s.axis_count; ++i) {
    axes.raw(kAxisNames[i], value_of(s.axes[static_cast<std::size_t>(i)]));
  }
  return axes.close();
}

std::string axis_state(const AxisStatus& a) {
  return JsonObject()
      .general("u", a.state[kU], 6)
      .general("x", a.state[kX], 6)
      .general("theta", a.state[kTheta], 6)
      .general("u_dot", a.state[kUDot], 6)
      .general("x_dot", a.state[kXDot], 6)
      .general("theta_dot", a.state[kThetaDot], 6)
      .raw("overhang", std::to_string(a.mode.overhang))
      .fixed("risk_overturning", a.risk.overturning, 4)
      .fixed("risk_falling", a.risk.falling, 4)
      .fixed("risk_base_stops", a.risk.base_stops, 4)
      .count("members", static_cast<std::uint64_t>(a.members))
      .count("worst_member", static_cast<std::uint64_t>(a.worst_member))
      .close();
}

// A cross-check's RMS, m/s2, or null while its window is not full (or for the primary).
std::string rms_value(const SensorStatus& sensor) {
  if (sensor.primary || !sensor.window_full) return "null";
  return formatted(sensor.rms_m_s2, 4, false);
}

// The sensors of a status line, each with its health and cross-check.
std::string status_sensors(const BoxStatus& s) {
  std::vector<std::string> sensors;
  for (int i = 0; i < s.sensor_count; ++i) {
    const SensorStatus& sensor = s.sensors[static_cast<std::size_t>(i)];
    sensors.push_back(JsonObject()
                          .count("node", sensor.node)
                          .text("role", sensor_role_name(sensor.role))
                          .flag("primary", sensor.primary)
                          .text("health", monitor::health_state_name(sensor.health.state))
                          .text("cause", monitor::health_cause_name(sensor.health.cause))
                          .flag("ready", sensor.ready)
                          .raw("rms_m_s2", rms_value(sensor))
                          .flag("disagreeing", sensor.disagreeing)
                          .close());
  }
  return json_array(sensors);
}

// The statue sensor of a status line: each stream's health, the offset known, and per axis
// what its filter makes of the members (AxisStatus::statue).
std::string status_statue_sensor(const BoxStatus& s) {
  const auto stream = [](const monitor::SensorHealth& h) {
    return JsonObject()
        .text("health", monitor::health_state_name(h.state))
        .text("cause", monitor::health_cause_name(h.cause))
        .close();
  };
  return JsonObject()
      .raw("rate", stream(s.statue_sensor.rate))
      .raw("acceleration", stream(s.statue_sensor.acceleration))
      .flag("ready", s.statue_sensor.ready)
      .flag("unexplained", s.statue_unexplained)
      .raw("weights",
           per_axis(s, [](const AxisStatus& a) { return statue_weights_json(a.statue); }))
      .close();
}

std::uint64_t rejected(const monitor::SensorCounters& c) {
  return c.non_finite + c.out_of_range + c.undefined_status;
}

// The samples a sensor's stream passed on, bridged, and lost.
JsonObject& stream_counts(JsonObject& object, const monitor::SensorCounters& c) {
  return object.count("fed", c.fed)
      .count("bridged", c.bridged)
      .count("missing", c.missing)
      .count("long_gaps", c.long_gaps);
}

// The frame decoder's counters and the frames the monitor could not encode.
std::string frame_counters(const FrameCounters& f, std::uint64_t not_encoded) {
  return JsonObject()
      .count("received", f.received)
      .count("sensor_samples", f.sensor_samples)
      .count("statue_rates", f.statue_rates)
      .count("statue_accelerations", f.statue_accelerations)
      .count("other_nodes", f.other_nodes)
      .count("heartbeats", f.heartbeats)
      .count("acknowledgements", f.acknowledgements)
      .count("acknowledgements_refused", f.acknowledgements_refused)
      .count("acknowledgements_ignored", f.acknowledgements_ignored)
      .count("acknowledgement_lockouts", f.acknowledgement_lockouts)
      .count("statue_stands", f.statue_stands)
      .count("statue_stands_refused", f.statue_stands_refused)
      .count("statue_stands_ignored", f.statue_stands_ignored)
      .count("statue_stands_lockouts", f.statue_stands_lockouts)
      .count("regional_tags", f.regional_tags)
      .count("regional_unauthenticated", f.regional_unauthenticated)
      .count("monitor_frames", f.monitor_frames)
      .count("rejected", f.rejected)
      .count("unknown_identifiers", f.unknown_identifiers)
      .text("last_error", can::codec_error_text(f.last_error))
      .count("not_encoded", not_encoded)
      .close();
}

// The primary sensor's health counters.
std::string sensor_counters(const monitor::SensorHealth& h) {
  const monitor::SensorCounters& c = h.counters;
  JsonObject object;
  object.text("state", monitor::health_state_name(h.state));
  return stream_counts(object, c)
      .count("duplicates", c.duplicates)
      .count("out_of_order", c.out_of_order)
      .count("rejected", rejected(c))
      .count("saturated", c.saturated)
      .count("timeouts", c.timeouts)
      .count("faults", c.faults)
      .close();
}

// Every sensor's totals.
std::string summary_sensors(const BoxStatus& s) {
  std::vector<std::string> sensors;
  for (int i = 0; i < s.sensor_count; ++i) {
    const SensorStatus& sensor = s.sensors[static_cast<std::size_t>(i)];
    const monitor::SensorCounters& k = sensor.health.counters;
    JsonObject object;
    object.count("node", sensor.node)
        .text("role", sensor_role_name(sensor.role))
        .flag("primary", sensor.primary)
        .text("state", monitor::health_state_name(sensor.health.state))
        .count("received", k.received);
    sensors.push_back(stream_counts(object, k)
                          .count("rejected", rejected(k))
                          .count("timeouts", k.timeouts)
                          .count("faults", k.faults)
                          .count("pairs", sensor.pairs)
                          .count("unpaired", sensor.unpaired)
                          .count("disagreements", sensor.disagreements)
                          .general("max_rms_m_s2", sensor.max_rms_m_s2, 4)
                          .close());
  }
  return json_array(sensors);
}

}  // namespace

JsonObject& JsonObject::member(std::string_view key) {
  if (!empty_) text_ += ", ";
  empty_ = false;
  text_ += quoted(key);
  text_ += ": ";
  return *this;
}

JsonObject& JsonObject::text(std::string_view key, std::string_view value) {
  member(key).text_ += quoted(value);
  return *this;
}

JsonObject& JsonObject::fixed(std::string_view key, double value, int decimals) {
  member(key).text_ += formatted(value, decimals, true);
  return *this;
}

JsonObject& JsonObject::general(std::string_view key, double value, int digits) {
  member(key).text_ += formatted(value, digits, false);
  return *this;
}

JsonObject& JsonObject::count(std::string_view key, std::uint64_t value) {
  member(key).text_ += std::to_string(value);
  return *this;
}

JsonObject& JsonObject::flag(std::string_view key, bool value) {
  member(key).text_ += value ? "true" : "false";
  return *this;
}

JsonObject& JsonObject::raw(std::string_view key, std::string_view json) {
  member(key).text_ += json;
  return *this;
}

std::string json_array(const std::vector<std::string>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ", ";
    out += values[i];
  }
  return out + "]";
}

namespace {

// The regional alerts' object (regional_status_json), once an alert came: a box without any
// says nothing of them.
void regional_once_received(JsonObject& line, const BoxStatus& s, double t_origin) {
  if (const auto* regional = monitor::built_part<monitor::RegionalAlertStatus>(s.regional);
      regional != nullptr && regional->received > 0) {
    line.raw("regional", regional_status_json(*regional, t_origin));
  }
}

}  // namespace

std::string status_json(const BoxStatus& s, double t_origin) {
  JsonObject line;
  line.text("type", "status").fixed("t", seconds(s.time_ns, t_origin), 6);
  line.raw("phase",
           per_axis(s, [](const AxisStatus& a) { return quoted(phase_name(a.mode.phase)); }));
  line.raw("corner", per_axis(s, [](const AxisStatus& a) {
             return quoted(a.mode.rocking() ? corner_name(a.mode.corner) : "none");
           }));
  line.fixed("risk", s.risk, 4)
      .fixed("probability", s.probability, 4)
      .raw("collapse_forecast_t", s.collapse_forecast_s < 0.0
                                      ? std::string("null")
                                      : formatted(s.collapse_forecast_s - t_origin, 3, true))
      .text("alarm", monitor::alarm_level_name(s.alarm))
      .text("latched", monitor::alarm_level_name(s.latched))
      .text("trouble", monitor::alarm_cause_name(s.trouble));
  if (s.collapse.held) line.raw("collapse", collapse_json(s.collapse));
  if (s.frames_not_encoded > 0) line.count("frames_not_encoded", s.frames_not_encoded);
  line.flag("estimating", s.estimating)
      .flag("calibrated", s.calibrated)
      .text("sensor", monitor::health_state_name(s.sensor.state))
      .text("sensor_cause", monitor::health_cause_name(s.sensor.cause))
      .text("sensors_state", monitor::health_state_name(s.sensors_state))
      .flag("disagreement", s.disagreement)
      .count("failovers", s.failovers);
  if (s.plate >= 0) {
    line.raw("plate_residual_m_s2", rms_value(s.sensors[static_cast<std::size_t>(s.plate)]))
        .flag("plate_mismatch", s.plate_mismatch);
  }
  line.raw("sensors", status_sensors(s));
  if (s.has_statue_sensor) line.raw("statue_sensor", status_statue_sensor(s));
  line.raw("state", per_axis(s, axis_state));
  regional_once_received(line, s, t_origin);
  const auto* pwave = monitor::built_part<monitor::PWaveStatus>(s.pwave);
  if (pwave != nullptr && s.has_pwave) {
    line.raw("pwave", pwave_status_json(*pwave, s.estimator_start_ns, t_origin));
  }
  return line.close();
}

std::string statue_weights_json(const StatueAxisStatus& a) {
  return JsonObject()
      .flag("measured", a.measured)
      .flag("informative", a.informative)
      .flag("explained", !a.unexplained)
      .flag("weighted", a.weighted)
      .general("effective_members", a.effective_members, 4)
      .count("best_member", static_cast<std::uint64_t>(a.best_member))
      .general("best_score", a.best_score, 4)
      .count("ruled_out", static_cast<std::uint64_t>(a.ruled_out))
      .flag("acceleration_used", a.acceleration_used)
      .flag("corroborated", a.corroborated)
      .text("refutation", statue_refutation_name(a.refutation))
      .flag("lowering_refused", a.lowering_refused)
      .fixed("risk_without", static_cast<double>(a.risk_without), 4)
      .close();
}

std::string collapse_json(const CollapseRecord& c) {
  return JsonObject()
      .count("axis", static_cast<std::uint64_t>(c.axis))
      .text("phase", phase_name(c.mode.phase))
      .text("corner", corner_name(c.mode.corner))
      .flag("restored", c.restored)
      .close();
}

std::string recorder_status_json(const RecorderStatus& r) {
  return JsonObject()
      .text("health", kRecorderHealthNames.name(r.health))
      .text("problem", kRecorderProblemNames.name(r.problem))
      .count("captures_written", r.captures_written)
      .count("captures_lost", r.captures_lost)
      .count("captures_truncated", r.captures_truncated)
      .count("captures_deleted", r.captures_deleted)
      .close();
}

std::string pwave_status_json(const monitor::PWaveStatus& p, std::int64_t start_ns,
                              double t_origin) {
  JsonObject out;
  out.text("state", monitor::kPWaveStateNames.name(p.state))
      .fixed("probability", static_cast<double>(p.probability), 4)
      .fixed("sta_lta", static_cast<double>(p.sta_lta), 2)
      .count("candidates", p.candidates)
      .count("triggers", p.triggers)
      .raw("rejected", JsonObject()
                           .count("period_short", p.rejected_short)
                           .count("period_long", p.rejected_long)
                           .count("horizontal", p.rejected_horizontal)
                           .count("not_after_quiet", p.rejected_not_after_quiet)
                           .close());
  if (p.triggers > 0) {  // the latest trigger's window
    out.fixed("onset_t", seconds(start_ns, t_origin) + static_cast<double>(p.onset_s), 3)
        .fixed("window_s", static_cast<double>(p.window_s), 3)
        .text("window_end", monitor::kPWaveWindowEndNames.name(p.window_end))
        .general("pa_m_s2", static_cast<double>(p.pa_m_s2), 4)
        .general("pd_m", static_cast<double>(p.pd_m), 4)
        .fixed("tau_c_s", static_cast<double>(p.tau_c_s), 3)
        .fixed("tau_p_s", static_cast<double>(p.tau_p_s), 3)
        .general("predicted_pga_g", static_cast<double>(p.predicted_pga_g), 4)
        .fixed("sigma_ln", static_cast<double>(p.sigma_ln), 3);
  }
  return out.close();
}

std::string refused_dangerous_json(std::uint64_t count, const monitor::RefusedRegionalAlert& d,
                                   double t) {
  return JsonObject()
      .count("count", count)
      .raw("latest", count == 0 ? "null"
                                : JsonObject()
                                      .count("event_id", d.event_id)
                                      .count("version", d.version)
                                      .fixed("probability", static_cast<double>(d.probability), 4)
                                      .text("reason", monitor::regional_refusal_name(d.refusal))
                                      .fixed("t", t, 3)
                                      .close())
      .close();
}

std::string regional_status_json(const monitor::RegionalAlertStatus& r, double t_origin) {
  JsonObject refused;
  for (const NamedValue<monitor::RegionalRefusal>& named : monitor::kRegionalRefusalNames) {
    if (named.value == monitor::RegionalRefusal::kNone) continue;
    refused.count(named.name, r.refused[static_cast<std::size_t>(named.value)]);
  }
  JsonObject out;
  out.count("held", static_cast<std::uint64_t>(r.held));
  if (r.held > 0) {
    const monitor::RegionalAlert& a = r.worst.alert;
    out.count("event_id", a.event_id)
        .count("version", a.version)
        .fixed("magnitude", static_cast<double>(a.magnitude), 2)
        .fixed("distance_km", static_cast<double>(a.distance_km), 1)
        .fixed("pga_g", static_cast<double>(a.pga_g), 4)
        .fixed("sigma_ln", static_cast<double>(a.sigma_ln), 2)
        .fixed("probability", static_cast<double>(r.probability), 4)
        .fixed("time_to_s_arrival_s", static_cast<double>(r.time_to_s_arrival_s), 3)
        .fixed("s_arrival_t", seconds(r.worst.s_arrival_ns, t_origin), 3)
        .fixed("expires_t", seconds(r.worst.expires_ns, t_origin), 3);
  }
  return out.count("received", r.received)
      .count("accepted", r.accepted)
      .count("replaced", r.replaced)
      .count("cancelled", r.cancelled)
      .count("expired", r.expired)
      .raw("refused", refused.close())
      .text("last_refusal", monitor::regional_refusal_name(r.last_refusal))
      .text("last_refusal_field", r.last_refusal_field)
      .raw("refused_dangerous",
           refused_dangerous_json(r.refused_dangerous, r.last_refused_dangerous,
                                  seconds(r.last_refused_dangerous.refused_ns, t_origin)))
      .close();
}

std::string regional_json(const monitor::RegionalOutcome& o, const BoxStatus& s) {
  JsonObject line;
  line.text("type", "regional").text("result", o.accepted() ? "accepted" : "refused");
  if (!o.accepted()) {
    line.text("reason", monitor::regional_refusal_name(o.refusal)).text("field", o.field);
    if (o.dangerous) line.flag("more_dangerous_than_held", true);
  } else {
    line.flag("replaced", o.replaced).flag("cancelled", o.cancelled);
  }
  const auto* regional = monitor::built_part<monitor::RegionalAlertStatus>(s.regional);
  return line.count("held", regional != nullptr ? static_cast<std::uint64_t>(regional->held) : 0)
      .fixed("probability", regional != nullptr ? static_cast<double>(regional->probability) : 0.0,
             4)
      .close();
}

std::string alarm_json(const monitor::AlarmEventRecord& e, double t_origin) {
  return JsonObject()
      .text("type", "alarm")
      .fixed("t", seconds(e.time_ns, t_origin), 6)
      .text("level", monitor::alarm_level_name(e.level))
      .text("previous", monitor::alarm_level_name(e.previous_level))
      .text("cause", monitor::alarm_cause_name(e.cause))
      .flag("latched", e.latched)
      .text("trouble", monitor::alarm_cause_name(e.trouble))
      .count("sequence", e.sequence)
      .close();
}

std::string event_json(int axis, const Event& event) {
  std::string line = host::event_json(event);  // {"t": .., "event": .., ...}
  line.insert(1, std::string("\"type\": \"event\", \"axis\": \"") + kAxisNames[axis] + "\", ");
  return line;
}

std::string summary_json(const Monitor& monitor, const RunTotals& totals, double t_origin) {
  const BoxStatus& s = monitor.status();
  JsonObject line;
  line.text("type", "summary")
      .text("source", totals.source)
      .fixed("t", seconds(s.time_ns, t_origin), 6)
      .count("samples", totals.samples)
      .text("final_phase", phase_name(s.axes[0].mode.phase))
      .fixed("max_risk", totals.max_risk, 4)
      .text("max_alarm", monitor::alarm_level_name(totals.max_level))
      .text("alarm", totals.input_fault.empty()
                         ? monitor::alarm_level_name(s.alarm)
                         : monitor::alarm_level_name(monitor::AlarmLevel::kFault));
  if (!totals.input_fault.empty()) line.text("input_fault", totals.input_fault);
  line.count("alarm_events", totals.alarm_events)
      .count("fault_events", totals.fault_events)
      .count("phase_events", totals.phase_events)
      .raw("frames", frame_counters(totals.frames, monitor.frames_not_encoded()))
      .raw("sensor", sensor_counters(s.sensor))
      .count("estimator_restarts", s.estimator_restarts)
      .count("bus_send_errors", totals.bus_send_errors)
      .count("bus_errors", totals.bus_errors)
      .count("bus_dropped_frames", totals.bus_dropped_frames)
      .raw("log_time", JsonObject()
                           .count("went_back", totals.log_time_back)
                           .count("stood_still", totals.log_time_still)
                           .count("gaps", totals.log_time_gaps)
                           .close())
      .raw("log_drops", JsonObject()
                            .count("reports", totals.log_drop_reports)
                            .count("frames", totals.log_drop_frames)
                            .close())
      .text("sensors_state", monitor::health_state_name(s.sensors_state))
      .count("failovers", s.failovers)
      .count("failovers_continued", s.failovers_continued)
      .raw("sensors", summary_sensors(s));
  regional_once_received(line, s, t_origin);  // the refusals by reason (docs/regional.md)
  if (s.has_statue_sensor) {
    const StatueSensorStatus& statue = s.statue_sensor;
    line.raw("statue_sensor", JsonObject()
                                  .raw("rate", sensor_counters(statue.rate))
                                  .raw("acceleration", sensor_counters(statue.acceleration))
                                  .flag("ready", statue.ready)
                                  .close());
  }
  if (totals.recorder) {
    const RecorderStatus& r = totals.recorder_status;
    line.raw("recorder", JsonObject()
                             .count("captures_written", r.captures_written)
                             .count("captures_dropped", totals.captures_dropped)
                             .count("write_errors", totals.recorder_write_errors)
                             .count("captures_deleted", r.captures_deleted)
                             .count("first_index", totals.recorder_first_index)
                             .count("partial_files_removed", totals.partial_files_removed)
                             .text("health", kRecorderHealthNames.name(r.health))
                             .text("problem", kRecorderProblemNames.name(r.problem))
                             .count("captures_lost", r.captures_lost)
                             .count("captures_truncated", r.captures_truncated)
                             .count("frames_lost", totals.frames_lost)
                             .close());
  }
  for (const auto& [key, json] : totals.outputs) line.raw(key, json);
  return line.close();
}

}  // namespace plinth::firmware
