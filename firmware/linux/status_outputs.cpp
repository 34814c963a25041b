#include "status_outputs.h"

#include <time.h>

#include <cerrno>
#include <cstdlib>

#include "plinth/host/input_error.h"

namespace plinth::firmware {

namespace {

std::int64_t clock_ns(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

std::int64_t monotonic_ns() { return clock_ns(CLOCK_MONOTONIC); }
std::int64_t wall_clock_ns() { return clock_ns(CLOCK_REALTIME); }

void copy_status(const BoxStatus& s, double t_origin, StatusSnapshot& snapshot) {
  snapshot.time_ns = s.time_ns;
  snapshot.t = static_cast<double>(s.time_ns) * 1e-9 - t_origin;
  snapshot.level = s.alarm;
  snapshot.latched = s.latched;
  snapshot.trouble = s.trouble;
  snapshot.collapse_held = s.collapse.held;
  snapshot.risk = s.risk;
  snapshot.probability = s.probability;
  snapshot.forecast_axis = s.forecast_axis;
  snapshot.forecast_worst_member =
      s.forecast_axis >= 0 ? s.axes[static_cast<std::size_t>(s.forecast_axis)].forecast.worst_member
                           : -1;
  snapshot.collapse_forecast = s.collapse_forecast_s >= 0.0;
  snapshot.collapse_forecast_t = s.collapse_forecast_s - t_origin;
  snapshot.axis_count = s.axis_count;
  for (std::size_t i = 0; i < snapshot.phase.size(); ++i) snapshot.phase[i] = s.axes[i].mode.phase;
  snapshot.estimating = s.estimating;
  snapshot.sensor = s.sensor.state;
  snapshot.sensors_state = s.sensors_state;
  snapshot.sensor_counters = s.sensor.counters;
  snapshot.estimator_restarts = s.estimator_restarts;
  snapshot.has_statue_sensor = s.has_statue_sensor;
  snapshot.statue_rate = s.statue_sensor.rate.state;
  snapshot.statue_acceleration = s.statue_sensor.acceleration.state;
  snapshot.statue_ready = s.statue_sensor.ready;
  snapshot.statue_unexplained = s.statue_unexplained;
  for (std::size_t i = 0; i < snapshot.statue_axes.size(); ++i) {
    snapshot.statue_axes[i] = s.axes[i].statue;
  }
  const auto* regional = monitor::built_part<monitor::RegionalAlertStatus>(s.regional);
  if (regional == nullptr) return;  // a build without regional alerts: none
  const monitor::RegionalAlertStatus& r = *regional;
  RegionalSnapshot& out = snapshot.regional;
  out.received = r.received;
  out.accepted = r.accepted;
  out.refused = 0;
  for (const std::uint64_t n : r.refused) out.refused += n;
  out.held = r.held;
  out.event_id = r.worst.alert.event_id;
  out.version = r.worst.alert.version;
  out.magnitude = static_cast<double>(r.worst.alert.magnitude);
  out.distance_km = static_cast<double>(r.worst.alert.distance_km);
  out.pga_g = static_cast<double>(r.worst.alert.pga_g);
  out.sigma_ln = static_cast<double>(r.worst.alert.sigma_ln);
  out.probability = static_cast<double>(r.probability);
  out.time_to_s_arrival_s = static_cast<double>(r.time_to_s_arrival_s);
  out.s_arrival_t = static_cast<double>(r.worst.s_arrival_ns) * 1e-9 - t_origin;
  out.last_refusal = r.last_refusal;
  out.refused_dangerous = r.refused_dangerous;
  out.last_refused_dangerous = r.last_refused_dangerous;
  out.last_refused_dangerous_t =
      static_cast<double>(r.last_refused_dangerous.refused_ns) * 1e-9 - t_origin;
}

std::string Endpoint::text() const {
  const bool v6 = host.find(':') != std::string::npos;
  return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

Endpoint parse_endpoint(const std::string& text, const std::string& what) {
  const auto bad = [&](const std::string& why) {
    return host::InputError(what +
                            ": expected HOST:PORT (e.g. 127.0.0.1:1502 or [::1]:1502), got \"" +
                            text + "\": " + why);
  };
  Endpoint e;
  std::string port;
  if (!text.empty() && text.front() == '[') {
    const std::size_t close = text.find(']');
    if (close == std::string::npos) throw bad("no closing ']'");
    e.host = text.substr(1, close - 1);
    if (close + 1 >= text.size() || text[close + 1] != ':') throw bad("no ':PORT' after ']'");
    port = text.substr(close + 2);
  } else {
    const std::size_t colon = text.rfind(':');
    if (colon == std::string::npos) throw bad("no ':PORT'");
    e.host = text.substr(0, colon);
    if (e.host.find(':') != std::string::npos) throw bad("an IPv6 address goes in brackets");
    port = text.substr(colon + 1);
  }
  if (e.host.empty()) throw bad("no host");
  for (const char c : e.host) {
    if (c == ' ' || c == '\t' || c == '/' || c == '[' || c == ']') throw bad("not a host name");
  }
  if (port.empty() || port.size() > 5 ||
      port.find_first_not_of("0123456789") != std::string::npos) {
    throw bad("the port is not a number");
  }
  e.port = std::atoi(port.c_str());
  if (e.port < 1 || e.port > 65535) throw bad("the port must lie in [1, 65535]");
  return e;
}

}  // namespace plinth::firmware
