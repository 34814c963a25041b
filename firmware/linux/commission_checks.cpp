#include "commission_checks.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "commission_text.h"
#include "plinth/core/scene.h"

namespace plinth::firmware {

namespace {

constexpr double kDeg = 180.0 / 3.14159265358979323846;
constexpr double kG0 = static_cast<double>(kStandardGravity);  // m/s2
// Finding still windows in the data: a block of samples is still when no axis spreads by more
// than kStillStdM_S2 (a hand on a sensor, a wedge pushed in, a statue lifted move it far more);
// consecutive still blocks within kDriftM_S2 of the first make one interval (a slow raise is a
// run of short ones), kept from kMinIntervalS on. A noisier sensor (or one whose unit is wrong)
// is still within kNoiseFloors times its own noise floor: the spread of its quietest blocks
// (kFloorQuantile of them spread less), so that its rest is found and its checks say what is
// wrong with it.
constexpr double kBlockS = 0.25;
constexpr double kStillStdM_S2 = 0.02;
constexpr double kDriftM_S2 = 0.015;
constexpr double kMinIntervalS = 2.0;
constexpr double kNoiseFloors = 3.0;
constexpr double kFloorQuantile = 0.2;
constexpr double kTrimS = 0.25;  // left out at each end of a window found in the data
// The statue standing before and after a raise: at most this much of it next to the raise (the
// gyroscope's noise adds up over the span it is integrated).
constexpr double kStandingUseS = 5.0;
// A node's rate may differ from estimator.sample_rate_hz by this fraction (its clock).
constexpr double kRateTolerance = 0.1;
// Sequence breaks beyond this fraction of the frames: two devices answer to one node.
constexpr double kInterleavedFraction = 0.2;
// Frames lost beyond this fraction: the bus or the node drops samples.
constexpr double kLostFraction = 0.01;
// The statue sensor's gyroscope at rest: the box's offset window takes rates spread by this.
constexpr double kRestRateSpreadRad_S = 0.05;
// A gyroscope sending deg/s where rad/s are due reads 180/pi times the turn.
constexpr double kDegPerRad = kDeg;
// The gyroscope's turn and the accelerometer's tilt about axes this far apart: not one IMU.
constexpr double kGyroAxisToleranceDeg = 30.0;

double wrap_deg(double a) {
  while (a > 180.0) a -= 360.0;
  while (a <= -180.0) a += 360.0;
  return a;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kDeg;
}

// The statue-frame direction nearest a heading in the horizontal plane: "+x", "-y", ...
const char* direction_name(double heading_deg) {
  const double h = wrap_deg(heading_deg);
  if (std::abs(h) <= 45.0) return "+x";
  if (h > 45.0 && h <= 135.0) return "+y";
  if (h < -45.0 && h >= -135.0) return "-y";
  return "-x";
}

// The sensor's own axis that carries statue axis `statue_axis` (0 x, 1 y, 2 z): "+y", "-x", ...
std::string sensor_axis(const CommissionedSensor& s, int statue_axis) {
  const Eigen::Vector3d e = s.to_statue.row(statue_axis).transpose();  // R^T e_i
  int i = 0;
  e.cwiseAbs().maxCoeff(&i);
  return std::string(e[i] < 0 ? "-" : "+") + "xyz"[i];
}

const char* axis_letter(int axis) { return axis == 0 ? "x" : "y"; }

struct Stats {
  int n = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d std = Eigen::Vector3d::Zero();
  Eigen::Vector3d low = Eigen::Vector3d::Zero();
  Eigen::Vector3d high = Eigen::Vector3d::Zero();
};

// One stream in the statue frame: an accelerometer's specific force (m/s2) or a gyroscope's
// rates (rad/s), sorted by time.
struct Stream {
  std::vector<double> t;
  std::vector<Eigen::Vector3d> v;
  bool saturated = false;            // a frame said so, or an axis stood at the frame's full scale
  double still_std = kStillStdM_S2;  // set by set_thresholds()
  double drift = kDriftM_S2;

  [[nodiscard]] bool empty() const { return t.empty(); }
  [[nodiscard]] Stats stats(const Window& w) const {
    Stats s;
    const auto first = std::lower_bound(t.begin(), t.end(), w.t0);
    const auto last = std::upper_bound(t.begin(), t.end(), w.t1);
    Eigen::Vector3d m2 = Eigen::Vector3d::Zero();
    for (auto it = first; it != last; ++it) {
      const Eigen::Vector3d& x = v[static_cast<std::size_t>(it - t.begin())];
      if (s.n == 0) s.low = s.high = x;
      s.low = s.low.cwiseMin(x);
      s.high = s.high.cwiseMax(x);
      ++s.n;
      const Eigen::Vector3d d = x - s.mean;
      s.mean += d / s.n;
      m2 += d.cwiseProduct(x - s.mean);
    }
    if (s.n > 1) s.std = (m2 / (s.n - 1)).cwiseSqrt();
    return s;
  }
};

// The block grid's blocks of a stream: [b0, b0 + kBlockS) with samples, in time order.
template <typename Visit>
void for_each_block(const Stream& s, Visit visit) {
  std::size_t i = 0;
  while (i < s.t.size()) {
    const double b0 = std::floor(s.t[i] / kBlockS) * kBlockS;
    std::size_t j = i;
    while (j < s.t.size() && s.t[j] < b0 + kBlockS) ++j;
    visit(b0, s.stats(Window{b0, b0 + kBlockS - 1e-9, WindowSource::kData}));
    i = j;
  }
}

// The stream's stillness thresholds from its noise floor.
void set_thresholds(Stream& s) {
  std::vector<double> spreads;
  for_each_block(s, [&](double, const Stats& st) {
    if (st.n > 2) spreads.push_back(st.std.maxCoeff());
  });
  if (spreads.empty()) return;
  const auto at = spreads.begin() +
                  static_cast<std::ptrdiff_t>(kFloorQuantile * static_cast<double>(spreads.size()));
  std::nth_element(spreads.begin(), at, spreads.end());
  s.still_std = std::max(kStillStdM_S2, kNoiseFloors * *at);
  s.drift = std::max(kDriftM_S2, 2.0 * *at);
}

struct Interval {
  double t0 = 0.0;
  double t1 = 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
};

// The still intervals of a stream (constants above).
std::vector<Interval> still_intervals(const Stream& s, double sample_rate_hz) {
  std::vector<Interval> out;
  if (s.empty()) return out;
  const int min_block_samples = std::max(2, static_cast<int>(0.5 * kBlockS * sample_rate_hz));
  bool open = false;
  Interval current;
  Eigen::Vector3d first_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int summed = 0;
  const auto close = [&] {
    if (open && current.t1 - current.t0 >= kMinIntervalS) {
      current.mean = sum / summed;
      out.push_back(current);
    }
    open = false;
  };
  for_each_block(s, [&](double b0, const Stats& st) {
    const bool still = st.n >= min_block_samples && st.std.maxCoeff() <= s.still_std;
    const bool adjacent = open && b0 - current.t1 < 1.5 * kBlockS;
    if (still && adjacent && (st.mean - first_mean).cwiseAbs().maxCoeff() <= s.drift) {
      current.t1 = b0 + kBlockS;
      sum += st.mean * st.n;
      summed += st.n;
    } else {
      close();
      if (still) {
        open = true;
        current = Interval{b0, b0 + kBlockS, Eigen::Vector3d::Zero()};
        first_mean = st.mean;
        sum = st.mean * st.n;
        summed = st.n;
      }
    }
  });
  close();
  return out;
}

Window trimmed(double t0, double t1) { return {t0 + kTrimS, t1 - kTrimS, WindowSource::kData}; }

// The checks, over the streams of every sensor.
class Checker {
 public:
  explicit Checker(const CommissionInput& in) : in_(in), s_(in.settings) {
    for (const CommissionedSensor& sensor : in.sensors) {
      const NodeRecording& node = in.session->node(sensor.node);
      Stream acc;
      for (const NodeSample& x : node.accelerations) {
        acc.t.push_back(x.t);
        acc.v.push_back(sensor.to_statue * (sensor.unit_scale * x.value));
        const bool full_scale = x.value.cwiseAbs().maxCoeff() >= 8.0;  // the frame's +-8.192
        if ((x.status & monitor::sensor_flags::kSaturated) != 0 || full_scale) acc.saturated = true;
      }
      Stream rate;
      if (sensor.statue) {
        for (const NodeSample& x : node.rates) {
          rate.t.push_back(x.t);
          rate.v.push_back(sensor.to_statue * x.value);
        }
      }
      // Two devices on one node: their samples interleaved are no sensor's (the census says
      // so); the steps leave the node out.
      if (interleaved(node.acceleration_traffic)) acc = Stream{};
      if (interleaved(node.rate_traffic)) rate = Stream{};
      set_thresholds(acc);
      acc_.push_back(std::move(acc));
      rate_.push_back(std::move(rate));
    }
  }

  static bool interleaved(const NodeTraffic& t) {
    return t.frames > 0 && static_cast<double>(t.sequence_breaks) / static_cast<double>(t.frames) >
                               kInterleavedFraction;
  }

  // --- The bus -------------------------------------------------------------------------------

  void census(std::vector<CheckResult>& out) const {
    std::array<int, kNodeSlots> configured{};
    configured.fill(-1);
    for (std::size_t i = 0; i < in_.sensors.size(); ++i) {
      configured[in_.sensors[i].node] = static_cast<int>(i);
    }
    const double rate = in_.sample_rate_hz;
    for (const CommissionedSensor& sensor : in_.sensors) {
      const NodeRecording& node = in_.session->node(sensor.node);
      traffic_checks(sensor.label, "SensorAcceleration", node.acceleration_traffic, rate, out);
      if (sensor.statue) {
        traffic_checks(sensor.label, "StatueRotation", node.rate_traffic, rate, out);
      } else if (node.rate_traffic.frames > 0) {
        out.push_back({sensor.label, "kind", false,
                       format_text("%llu StatueRotation frames",
                                   static_cast<unsigned long long>(node.rate_traffic.frames)),
                       "none (an accelerometer)",
                       "sends StatueRotation frames: an IMU on this node; the box file's statue "
                       "sensor ([statue_sensor] node) on the wrong node?"});
      }
      const std::uint8_t bad =
          (node.heartbeat_traffic.status_flags | node.acceleration_traffic.status_flags |
           node.rate_traffic.status_flags) &
          static_cast<std::uint8_t>(monitor::sensor_flags::kSelfTestFailed |
                                    monitor::sensor_flags::kOverTemperature |
                                    monitor::sensor_flags::kCalibrationInvalid);
      if (bad != 0) {
        std::string what;
        if ((bad & monitor::sensor_flags::kSelfTestFailed) != 0) what += "self-test failed, ";
        if ((bad & monitor::sensor_flags::kOverTemperature) != 0) what += "over temperature, ";
        if ((bad & monitor::sensor_flags::kCalibrationInvalid) != 0) {
          what += "calibration invalid, ";
        }
        what.resize(what.size() - 2);
        out.push_back({sensor.label, "status", false, what, "no flag",
                       "reports " + what + " in its frames' status: replace or recalibrate it"});
      }
    }
    for (int id = hal::can::kFirstSensorNode; id <= hal::can::kLastSensorNode; ++id) {
      if (configured[static_cast<std::size_t>(id)] >= 0) continue;
      const NodeRecording& node = in_.session->node(id);
      const std::pair<const char*, const NodeTraffic*> kinds[] = {
          {"SensorAcceleration", &node.acceleration_traffic},
          {"StatueRotation", &node.rate_traffic},
          {"SensorHeartbeat", &node.heartbeat_traffic}};
      for (const auto& [kind, traffic] : kinds) {
        if (traffic->frames + traffic->rejected == 0) continue;
        out.push_back(
            {format_text("node %d", id), "expected", false,
             format_text("%llu %s frames",
                         static_cast<unsigned long long>(traffic->frames + traffic->rejected),
                         kind),
             "no frame: the box file names no sensor on this node",
             format_text("sends %s frames, but the box file names no sensor on node %d: a "
                         "sensor the box file leaves out, or a node id set wrong",
                         kind, id)});
        break;
      }
    }
  }

  // --- Windows --------------------------------------------------------------------------------

  // Every step's windows: the given ones, the others found in the data.
  std::vector<StepWindows> resolve_windows() {
    std::vector<StepWindows> out;
    for (const Step& step : in_.steps) {
      StepWindows w;
      w.step = step;
      w.hold = given(step.name);
      w.before = given(window_name(step, "before"));
      w.after = given(window_name(step, "after"));
      out.push_back(w);
    }
    // The rest first: the others are found against it.
    for (StepWindows& w : out) {
      if (w.step.kind == StepKind::kRest && !w.hold.found()) w.hold = find_rest(0.0, false);
    }
    rest_ = rest_window(out);
    double after_rest = rest_.found() ? rest_.t1 : 0.0;
    double last_hold_end = after_rest;
    for (StepWindows& w : out) {
      const Step& step = w.step;
      if (step.kind == StepKind::kWedge && !w.hold.found() && rest_.found()) {
        w.hold = find_hold(step.sensor, step.axis, wedge_detect_deg());  // x first, then y
      }
      if (step.kind == StepKind::kStatueRaise && rest_.found()) {
        if (!w.hold.found()) {
          w.hold = find_hold(step.sensor, step.axis, 0.5 * s_.statue_min_tilt_deg);
        }
        if (w.hold.found()) {
          if (!w.before.found()) w.before = find_standing(step.sensor, w.hold.t0, true);
          if (!w.after.found()) w.after = find_standing(step.sensor, w.hold.t1, false);
        }
      }
      if (w.hold.found() && step.kind != StepKind::kFinalRest) {
        last_hold_end = std::max(last_hold_end, w.hold.t1);
      }
    }
    for (StepWindows& w : out) {
      if (w.step.kind == StepKind::kFinalRest && !w.hold.found() && rest_.found()) {
        w.hold = find_rest(last_hold_end, true);
      }
    }
    return out;
  }

  void set_rest(const Window& rest) { rest_ = rest; }

  // --- Checks ---------------------------------------------------------------------------------

  void step_checks(const StepWindows& w, std::vector<CheckResult>& out) const {
    switch (w.step.kind) {
      case StepKind::kRest:
        if (!w.hold.found()) {
          out.push_back(
              {"bus", "rest", false, "none", format_text("%.0f s still", 0.5 * s_.rest_s),
               format_text("found no %.0f s in which every sensor stood still: the session "
                           "must begin with everything at rest",
                           0.5 * s_.rest_s)});
          return;
        }
        for (std::size_t i = 0; i < in_.sensors.size(); ++i) rest_checks(i, w.hold, "", out);
        return;
      case StepKind::kFinalRest:
        if (!w.hold.found()) {
          out.push_back({"bus", "final-rest", false, "none",
                         format_text("%.0f s still after the last step", 0.5 * s_.rest_s),
                         "found no rest after the last step: the session must end with every "
                         "sensor back on its marks and the statue on its seat, still"});
          return;
        }
        for (std::size_t i = 0; i < in_.sensors.size(); ++i) {
          rest_checks(i, w.hold, "final-", out);
          seat_check(i, w.hold, out);
        }
        return;
      case StepKind::kWedge:
        wedge_check(w, out);
        return;
      case StepKind::kStatueRaise:
        raise_check(w, out);
        return;
    }
  }

  // Heading and signs from both wedge steps of each sensor (the gains are each step's).
  void axes_checks(const std::vector<StepWindows>& windows, std::vector<CheckResult>& out) const {
    for (std::size_t i = 0; i < in_.sensors.size(); ++i) {
      const CommissionedSensor& sensor = in_.sensors[i];
      if (sensor.statue || acc_[i].empty() || !rest_.found()) continue;
      std::array<std::optional<Tilt>, 2> tilt;
      for (const StepWindows& w : windows) {
        if (w.step.kind == StepKind::kWedge && w.step.sensor == static_cast<int>(i) &&
            w.hold.found()) {
          tilt[static_cast<std::size_t>(w.step.axis)] = measure_tilt(i, rest_, w.hold, w.step.axis);
        }
      }
      if (!tilt[0] || !tilt[1]) continue;
      const double tolerance = s_.heading_tolerance_deg;
      const double ex = tilt[0]->heading_error_deg;
      const double ey = tilt[1]->heading_error_deg;
      std::string message;
      if (std::abs(ex) > tolerance && std::abs(ey) > tolerance &&
          std::abs(wrap_deg(ex - ey)) <= 2.0 * tolerance) {
        // The readings turned by `turn` about the vertical: the sensor by -turn from what its
        // sensor_to_statue says (counter-clockwise seen from above when positive).
        const double turn = wrap_deg(ex + 0.5 * wrap_deg(ey - ex));
        message = format_text(
            "turned %.0f deg %s (seen from above) from what its sensor_to_statue "
            "says: the +x raise read toward %s and the +y raise toward %s; turn it "
            "back on its marks, or correct sensor_to_statue",
            std::abs(turn), turn < 0 ? "counter-clockwise" : "clockwise",
            direction_name(tilt[0]->heading_deg), direction_name(tilt[1]->heading_deg));
      } else {
        for (int a = 0; a < 2; ++a) {
          const double e = tilt[static_cast<std::size_t>(a)]->heading_error_deg;
          const double other = tilt[static_cast<std::size_t>(1 - a)]->heading_error_deg;
          if (std::abs(wrap_deg(e - 180.0)) <= tolerance && std::abs(other) <= tolerance) {
            message = format_text(
                "its statue %s axis (sensor axis %s) reads backwards: that axis's "
                "sign is reversed (the sensor's setting or wiring), or "
                "sensor_to_statue's",
                axis_letter(a), sensor_axis(sensor, a).c_str());
          }
        }
        if (message.empty() && (std::abs(ex) > tolerance || std::abs(ey) > tolerance)) {
          message = format_text(
              "its axes do not match sensor_to_statue: the +x raise read toward "
              "%.0f deg, the +y raise toward %.0f deg (expected 0 and 90)",
              tilt[0]->heading_deg, tilt[1]->heading_deg);
        }
      }
      out.push_back({sensor.label, "heading", message.empty(),
                     format_text("raises read %.2f deg toward %.1f deg, %.2f deg toward %.1f deg",
                                 tilt[0]->angle_deg, tilt[0]->heading_deg, tilt[1]->angle_deg,
                                 tilt[1]->heading_deg),
                     format_text("%.1f +- %.1f deg toward 0 and 90 +- %.0f deg", s_.wedge_deg,
                                 s_.wedge_tolerance_deg, tolerance),
                     message.empty() ? "heading and the horizontal axes' signs as the box "
                                       "file says (the gains: each wedge step)"
                                     : message});
    }
  }

  [[nodiscard]] std::vector<SensorTrace> traces(const std::vector<StepWindows>& windows) const {
    std::vector<SensorTrace> out;
    for (std::size_t i = 0; i < in_.sensors.size(); ++i) {
      const Stream& acc = acc_[i];
      if (acc.empty()) continue;
      SensorTrace trace;
      trace.label = in_.sensors[i].label;
      trace.sensor = static_cast<int>(i);
      trace.statue = in_.sensors[i].statue;
      // The rest's raise angles, so that each curve starts at 0.
      const Eigen::Vector3d rest =
          rest_.found() ? acc.stats(rest_).mean : Eigen::Vector3d(0.0, 0.0, kG0);
      const double x0 = std::atan2(rest.x(), rest.z());
      const double y0 = std::atan2(rest.y(), rest.z());
      // At most about 20 points a second: a picture, not the data.
      const std::size_t stride =
          std::max<std::size_t>(1, static_cast<std::size_t>(in_.sample_rate_hz / 20.0));
      for (std::size_t k = 0; k < acc.t.size(); k += stride) {
        const Eigen::Vector3d& f = acc.v[k];
        trace.t.push_back(acc.t[k]);
        trace.raise_x_deg.push_back((std::atan2(f.x(), f.z()) - x0) * kDeg);
        trace.raise_y_deg.push_back((std::atan2(f.y(), f.z()) - y0) * kDeg);
      }
      if (trace.statue) {
        for (const StepWindows& w : windows) {
          if (w.step.kind != StepKind::kStatueRaise || !w.before.found() || !w.hold.found()) {
            continue;
          }
          const double end = w.after.found() ? w.after.t1 : w.hold.t1;
          const Eigen::Vector3d bias = gyro_offset(i, w);
          const std::vector<Eigen::Vector3d> turn = gyro_turn(i, bias, w.before.t0, end);
          // The statue stands before and after: the turn is 0 in both windows, the offset's
          // error (a line) taken out, as the check's up-and-down mean does.
          const Eigen::Vector3d at_before = mean_turn(i, bias, w.before.t0, w.before);
          const Eigen::Vector3d at_after =
              w.after.found() ? mean_turn(i, bias, w.before.t0, w.after) : at_before;
          const double c_before = 0.5 * (w.before.t0 + w.before.t1);
          const double c_after = w.after.found() ? 0.5 * (w.after.t0 + w.after.t1) : c_before;
          const Stream& rate = rate_[i];
          const auto first = std::lower_bound(rate.t.begin(), rate.t.end(), w.before.t0);
          for (std::size_t k = 0; k < turn.size(); k += stride) {
            const double t = *(first + static_cast<std::ptrdiff_t>(k));
            const double along = c_after > c_before ? (t - c_before) / (c_after - c_before) : 0.0;
            const Eigen::Vector3d r = turn[k] - at_before - along * (at_after - at_before);
            trace.gyro_t.push_back(t);
            // Raising +x turns the block about -y; raising +y about +x.
            trace.gyro_raise_x_deg.push_back(-r.y() * kDeg);
            trace.gyro_raise_y_deg.push_back(r.x() * kDeg);
          }
          trace.gyro_t.push_back(std::numeric_limits<double>::quiet_NaN());  // a break
          trace.gyro_raise_x_deg.push_back(std::numeric_limits<double>::quiet_NaN());
          trace.gyro_raise_y_deg.push_back(std::numeric_limits<double>::quiet_NaN());
        }
      }
      out.push_back(std::move(trace));
    }
    return out;
  }

 private:
  struct Tilt {
    double angle_deg = 0.0;    // between the gravity read before and during the hold
    double heading_deg = 0.0;  // where the raise pushed the reading, statue frame
    double heading_error_deg = 0.0;
    double gain = 1.0;  // tan(angle) / tan(wedge)
    Stats hold;
  };

  Window given(const std::string& name) const {
    const auto it = in_.given.find(name);
    return it == in_.given.end() ? Window{} : it->second;
  }

  static Window rest_window(const std::vector<StepWindows>& windows) {
    for (const StepWindows& w : windows) {
      if (w.step.kind == StepKind::kRest) return w.hold;
    }
    return {};
  }

  double wedge_detect_deg() const { return std::max(0.5, 0.25 * s_.wedge_deg); }

  // The first (or, `last`, the last) span from `from` on in which every heard accelerometer
  // stands still for half the rest's time at least.
  Window find_rest(double from, bool last) const {
    std::vector<std::vector<Interval>> intervals;
    for (std::size_t i = 0; i < acc_.size(); ++i) {
      if (!acc_[i].empty()) intervals.push_back(still_intervals(acc_[i], in_.sample_rate_hz));
    }
    if (intervals.empty()) return {};
    const double need = 0.5 * s_.rest_s;
    Window found;
    // Candidate starts: every interval's start; the common span from there.
    std::vector<double> starts;
    for (const auto& list : intervals) {
      for (const Interval& iv : list) starts.push_back(std::max(iv.t0, from));
    }
    std::sort(starts.begin(), starts.end());
    for (const double t0 : starts) {
      double t1 = std::numeric_limits<double>::infinity();
      for (const auto& list : intervals) {
        double end = -1.0;
        for (const Interval& iv : list) {
          if (iv.t0 <= t0 + 1e-9 && iv.t1 > t0) end = iv.t1;
        }
        t1 = std::min(t1, end);
      }
      if (t1 - t0 >= need) {
        found = trimmed(t0, t1);
        if (!last) return found;
      }
    }
    return found;
  }

  // The `ordinal`-th hold of sensor i after the rest (0: its first): still intervals whose
  // gravity leans more than `detect_deg` from the rest's; consecutive ones leaning alike, with no
  // standing interval between them, are one hold (a bump broke it), measured on its longest.
  Window find_hold(int sensor, int ordinal, double detect_deg) const {
    const Stream& acc = acc_[static_cast<std::size_t>(sensor)];
    if (acc.empty()) return {};
    const Eigen::Vector3d rest = acc.stats(rest_).mean;
    std::vector<Interval> holds;
    bool standing_since = true;  // no leaning interval since the last standing one
    for (const Interval& iv : still_intervals(acc, in_.sample_rate_hz)) {
      if (iv.t0 < rest_.t1) continue;
      if (angle_deg(iv.mean, rest) <= detect_deg) {
        standing_since = true;
        continue;
      }
      if (!standing_since && angle_deg(holds.back().mean, iv.mean) < 0.5 * detect_deg) {
        if (iv.t1 - iv.t0 > holds.back().t1 - holds.back().t0) holds.back() = iv;
        continue;
      }
      holds.push_back(iv);
      standing_since = false;
    }
    if (ordinal >= static_cast<int>(holds.size())) return {};
    const Interval& h = holds[static_cast<std::size_t>(ordinal)];
    return trimmed(h.t0, h.t1);
  }

  // The statue sensor standing (leaning less than half the minimum raise from the rest) just
  // before `t` (`before`) or just after it.
  Window find_standing(int sensor, double t, bool before) const {
    const Stream& acc = acc_[static_cast<std::size_t>(sensor)];
    const Eigen::Vector3d rest = acc.stats(rest_).mean;
    const double detect = 0.5 * s_.statue_min_tilt_deg;
    std::optional<Interval> found;
    for (const Interval& iv : still_intervals(acc, in_.sample_rate_hz)) {
      if (angle_deg(iv.mean, rest) > detect) continue;
      if (before && iv.t1 <= t + kTrimS + 1e-9) found = iv;
      if (!before && iv.t0 >= t - kTrimS - 1e-9) {
        found = iv;
        break;
      }
    }
    if (!found) return {};
    const Window w = trimmed(found->t0, found->t1);
    return before ? Window{std::max(w.t0, w.t1 - kStandingUseS), w.t1, w.source}
                  : Window{w.t0, std::min(w.t1, w.t0 + kStandingUseS), w.source};
  }

  Tilt measure_tilt(std::size_t i, const Window& reference, const Window& hold, int axis) const {
    Tilt tilt;
    const Eigen::Vector3d u0 = acc_[i].stats(reference).mean.normalized();
    tilt.hold = acc_[i].stats(hold);
    const Eigen::Vector3d u1 = tilt.hold.mean.normalized();
    tilt.angle_deg = angle_deg(u0, u1);
    const Eigen::Vector3d d = u1 - u0;
    tilt.heading_deg = std::atan2(d.y(), d.x()) * kDeg;
    tilt.heading_error_deg = wrap_deg(tilt.heading_deg - (axis == 0 ? 0.0 : 90.0));
    tilt.gain = std::tan(tilt.angle_deg / kDeg) / std::tan(s_.wedge_deg / kDeg);
    return tilt;
  }

  void rest_checks(std::size_t i, const Window& w, const std::string& prefix,
                   std::vector<CheckResult>& out) const {
    const CommissionedSensor& sensor = in_.sensors[i];
    const Stream& acc = acc_[i];
    if (acc.empty()) return;  // the census said so
    const Stats st = acc.stats(w);
    if (st.n < 2) {
      out.push_back({sensor.label, prefix + "rest", false, format_text("%d samples", st.n),
                     "its samples through the rest", "sent nothing during the rest"});
      return;
    }
    // Gravity: the unit and the vertical axis's gain (once, at the first rest).
    const double g = st.mean.norm();
    const double ratio = g / kG0;
    const bool gravity_ok = std::abs(ratio - 1.0) <= s_.gravity_tolerance && !acc.saturated;
    std::string why = format_text("reads 1 g as %.4f m/s2", g);
    if (!gravity_ok) {
      if (acc.saturated) {
        why = format_text(
            "reads gravity at the frame's full scale (8.19 on an axis): its numbers "
            "are not %s as the box file's unit says (m/s2 sent where g is due?)",
            sensor.unit_name.c_str());
      } else if (std::abs(ratio * kG0 - 1.0) <= 0.1) {
        why = format_text(
            "reads gravity as %.3f m/s2, 1/9.81 of 1 g: it sends g, the box file says "
            "unit = \"%s\" (a unit error)",
            g, sensor.unit_name.c_str());
      } else if (std::abs(ratio / kG0 - 1.0) <= 0.1) {
        why = format_text(
            "reads gravity as %.1f m/s2, 9.81 times 1 g: it sends m/s2, the box file "
            "says unit = \"%s\" (a unit error)",
            g, sensor.unit_name.c_str());
      } else {
        why = format_text(
            "reads gravity as %.3f m/s2, %.3f of 1 g: a gain error on its vertical "
            "axis (sensor axis %s), or a wrong unit",
            g, ratio, sensor_axis(sensor, 2).c_str());
      }
    }
    if (prefix.empty()) {
      out.push_back({sensor.label, "gravity", gravity_ok, format_text("%.4f m/s2", g),
                     format_text("%.4f +- %.4f m/s2", kG0, s_.gravity_tolerance * kG0), why});
    }
    // Level: gravity along the statue's +z.
    const double lean = angle_deg(st.mean, Eigen::Vector3d::UnitZ());
    const bool level_ok = lean <= s_.level_tolerance_deg;
    std::string level_why = format_text("gravity %.2f deg from the statue's vertical", lean);
    if (!level_ok) {
      if (lean > 150.0) {
        level_why = format_text(
            "reads gravity downwards in the statue frame (%.0f deg from up): its "
            "vertical axis (sensor axis %s) reversed, or sensor_to_statue's",
            lean, sensor_axis(sensor, 2).c_str());
      } else if (lean > 30.0) {
        const double heading = std::atan2(st.mean.y(), st.mean.x()) * kDeg;
        level_why = format_text(
            "reads gravity along the statue's %s (%.0f deg from up): "
            "sensor_to_statue maps the wrong sensor axis to the vertical",
            direction_name(heading), lean);
      } else {
        level_why = format_text("leans %.2f deg from level (at most %.1f): level it on its marks",
                                lean, s_.level_tolerance_deg);
      }
    }
    out.push_back({sensor.label, prefix + "level", level_ok, format_text("%.2f deg", lean),
                   format_text("<= %.1f deg", s_.level_tolerance_deg), level_why});
    if (!prefix.empty()) return;  // noise and the gyroscope once, at the first rest
    const double noise = st.std.maxCoeff();
    const bool quiet = noise <= sensor.max_rest_std_m_s2;
    out.push_back({sensor.label, "noise", quiet, format_text("%.4f m/s2", noise),
                   format_text("<= %.4f m/s2", sensor.max_rest_std_m_s2),
                   quiet
                       ? format_text("std %.4f m/s2 at rest", noise)
                       : format_text("too noisy at rest (std %.4f m/s2; the box's start-up window "
                                     "takes at most %.4f): loose, or vibration nearby",
                                     noise, sensor.max_rest_std_m_s2)});
    if (!sensor.statue || rate_[i].empty()) return;
    const Stats rates = rate_[i].stats(w);
    const double spread = (rates.high - rates.low).maxCoeff();
    const bool steady = rates.n > 1 && spread <= kRestRateSpreadRad_S;
    out.push_back({sensor.label, "gyroscope-rest", steady, format_text("%.4f rad/s spread", spread),
                   format_text("<= %.2f rad/s", kRestRateSpreadRad_S),
                   steady
                       ? format_text("offset %.4f rad/s, spread %.4f rad/s at rest",
                                     rates.mean.norm(), spread)
                       : format_text("its rates spread by %.3f rad/s while the statue stands (the "
                                     "box's offset window takes %.2f): loose, or a noisy gyroscope",
                                     spread, kRestRateSpreadRad_S)});
  }

  void wedge_check(const StepWindows& w, std::vector<CheckResult>& out) const {
    const auto i = static_cast<std::size_t>(w.step.sensor);
    const CommissionedSensor& sensor = in_.sensors[i];
    if (acc_[i].empty() || !rest_.found()) return;
    const char* a = axis_letter(w.step.axis);
    const std::string expected =
        format_text("%.1f +- %.1f deg toward +%s", s_.wedge_deg, s_.wedge_tolerance_deg, a);
    if (!w.hold.found()) {
      out.push_back(
          {sensor.label, w.step.name, false, "no raise found", expected,
           format_text("found no raise of its +%s side: no still reading leaning more than "
                       "%.1f deg from its rest after the rest (%s)",
                       a, wedge_detect_deg(), w.step.axis == 0 ? "its first" : "its second")});
      return;
    }
    const Tilt t = measure_tilt(i, rest_, w.hold, w.step.axis);
    const bool angle_ok = std::abs(t.angle_deg - s_.wedge_deg) <= s_.wedge_tolerance_deg;
    const bool heading_ok = std::abs(t.heading_error_deg) <= s_.heading_tolerance_deg;
    const bool still = t.hold.std.maxCoeff() <= 2.0 * acc_[i].still_std;
    std::string why =
        format_text("the +%s raise read %.2f deg toward %.1f deg", a, t.angle_deg, t.heading_deg);
    if (!still) {
      why =
          format_text("moved while its +%s side stood on the wedge (std %.3f m/s2): hold it still",
                      a, t.hold.std.maxCoeff());
    } else if (t.angle_deg < wedge_detect_deg()) {
      why = format_text(
          "did not tilt (%.2f deg) while its +%s side was to be on the wedge: the "
          "wedge under another sensor, or this one fixed down",
          t.angle_deg, a);
    } else if (!heading_ok) {
      why = format_text("the raise of its +%s side read toward the statue's %s (%.0f deg off)", a,
                        direction_name(t.heading_deg), t.heading_error_deg);
    } else if (!angle_ok) {
      why = format_text(
          "the raise of its +%s side read %.2f deg where the wedge gives %.1f +- %.1f: "
          "a gain of %.2f on its statue %s axis (sensor axis %s)",
          a, t.angle_deg, s_.wedge_deg, s_.wedge_tolerance_deg, t.gain, a,
          sensor_axis(sensor, w.step.axis).c_str());
    }
    out.push_back({sensor.label, w.step.name, still && angle_ok && heading_ok,
                   format_text("%.2f deg toward %.1f deg", t.angle_deg, t.heading_deg), expected,
                   why});
  }

  // The gyroscope's offset while the statue stands around a raise: its mean rate over the
  // standing windows before and after it.
  Eigen::Vector3d gyro_offset(std::size_t i, const StepWindows& w) const {
    const Stats b = rate_[i].stats(w.before);
    const Stats a = w.after.found() ? rate_[i].stats(w.after) : Stats{};
    return b.n + a.n > 0 ? Eigen::Vector3d((b.mean * b.n + a.mean * a.n) / (b.n + a.n))
                         : Eigen::Vector3d::Zero();
  }

  // The gyroscope's turn (statue frame, rad) at each of its samples from `from` to `to`,
  // integrated from `from` (trapezoids), less `bias`.
  std::vector<Eigen::Vector3d> gyro_turn(std::size_t i, const Eigen::Vector3d& bias, double from,
                                         double to) const {
    const Stream& rate = rate_[i];
    std::vector<Eigen::Vector3d> out;
    const auto first = std::lower_bound(rate.t.begin(), rate.t.end(), from);
    Eigen::Vector3d turn = Eigen::Vector3d::Zero();
    for (auto it = first; it != rate.t.end() && *it <= to; ++it) {
      const auto k = static_cast<std::size_t>(it - rate.t.begin());
      if (it != first) turn += 0.5 * (rate.v[k] + rate.v[k - 1] - 2.0 * bias) * (*it - *(it - 1));
      out.push_back(turn);
    }
    return out;
  }

  // The mean turn over window `w` of a turn integrated from `from`.
  Eigen::Vector3d mean_turn(std::size_t i, const Eigen::Vector3d& bias, double from,
                            const Window& w) const {
    const Stream& rate = rate_[i];
    const std::vector<Eigen::Vector3d> turn = gyro_turn(i, bias, from, w.t1);
    const auto first = std::lower_bound(rate.t.begin(), rate.t.end(), from);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    for (std::size_t k = 0; k < turn.size(); ++k) {
      if (*(first + static_cast<std::ptrdiff_t>(k)) >= w.t0) {
        sum += turn[k];
        ++n;
      }
    }
    return n > 0 ? Eigen::Vector3d(sum / n) : Eigen::Vector3d::Zero();
  }

  void raise_check(const StepWindows& w, std::vector<CheckResult>& out) const {
    const auto i = static_cast<std::size_t>(w.step.sensor);
    const CommissionedSensor& sensor = in_.sensors[i];
    if (acc_[i].empty() || !rest_.found()) return;
    const char* a = axis_letter(w.step.axis);
    const std::string expected = format_text(">= %.2f deg toward +%s", s_.statue_min_tilt_deg, a);
    if (!w.hold.found()) {
      out.push_back({sensor.label, w.step.name, false, "no tilt found", expected,
                     format_text("never tilted by %.2f deg after the rest: it is not fixed to the "
                                 "statue (on the plinth?), or the statue's +%s side was not raised",
                                 0.5 * s_.statue_min_tilt_deg, a)});
      return;
    }
    const Window before = w.before.found() ? w.before : rest_;
    const Tilt t = measure_tilt(i, before, w.hold, w.step.axis);
    const bool tilted = t.angle_deg >= s_.statue_min_tilt_deg;
    const bool heading_ok = std::abs(t.heading_error_deg) <= s_.heading_tolerance_deg;
    std::string why =
        format_text("the statue's +%s raise tilted its sensor %.3f deg toward %.1f deg", a,
                    t.angle_deg, t.heading_deg);
    if (!tilted) {
      why = format_text(
          "tilted %.3f deg while the statue's +%s side was raised (at least %.2f): it "
          "does not move with the statue (fixed to the plinth?), or the statue was not "
          "raised",
          t.angle_deg, a, s_.statue_min_tilt_deg);
    } else if (!heading_ok) {
      why = format_text(
          "read the statue's +%s raise toward the statue's %s (%.0f deg off): its "
          "sensor_to_statue, or its mounting, is turned",
          a, direction_name(t.heading_deg), t.heading_error_deg);
    }
    out.push_back({sensor.label, w.step.name, tilted && heading_ok,
                   format_text("%.3f deg toward %.1f deg", t.angle_deg, t.heading_deg), expected,
                   why});
    if (!tilted) return;  // nothing for the gyroscope to be compared with
    // The gyroscope against the accelerometer: the turn over the raise (before -> hold) and the
    // tilt's rotation vector, (u1 x u0) / |u1 x u0| * angle (a reading turns against the body).
    if (rate_[i].empty()) return;  // the census said so
    const Eigen::Vector3d u0 = acc_[i].stats(before).mean.normalized();
    const Eigen::Vector3d u1 = t.hold.mean.normalized();
    const Eigen::Vector3d tilt_axis = u1.cross(u0).normalized();
    const Eigen::Vector3d tilt = tilt_axis * (t.angle_deg / kDeg);
    // Up (before -> hold) and back down (hold -> after): an offset left over cancels.
    StepWindows standing = w;
    standing.before = before;
    const Eigen::Vector3d bias = gyro_offset(i, standing);
    const Eigen::Vector3d at_hold = mean_turn(i, bias, before.t0, w.hold);
    const Eigen::Vector3d up = at_hold - mean_turn(i, bias, before.t0, before);
    const Eigen::Vector3d turn =
        w.after.found()
            ? Eigen::Vector3d(0.5 * (up + at_hold - mean_turn(i, bias, before.t0, w.after)))
            : up;
    const double ratio = turn.dot(tilt) / tilt.squaredNorm();
    const double apart = angle_deg(turn, ratio < 0 ? Eigen::Vector3d(-tilt) : tilt);
    const bool ratio_ok = std::abs(ratio - 1.0) <= s_.gyro_tolerance;
    const bool axis_ok = apart <= kGyroAxisToleranceDeg;
    std::string gyro_why = format_text(
        "its gyroscope turned %.2f times the tilt its accelerometer "
        "read",
        ratio);
    if (!axis_ok) {
      gyro_why = format_text(
          "its gyroscope turned about an axis %.0f deg from the one its "
          "accelerometer tilted about: the gyroscope's axes are not the "
          "accelerometer's",
          apart);
    } else if (std::abs(ratio + 1.0) <= s_.gyro_tolerance) {
      gyro_why = format_text(
          "its gyroscope turned the other way (%.2f times the tilt its "
          "accelerometer read): the gyroscope's sign is reversed",
          ratio);
    } else if (std::abs(ratio / kDegPerRad - 1.0) <= 0.1) {
      gyro_why = format_text(
          "its gyroscope read %.1f times the tilt: it sends deg/s where rad/s are "
          "due",
          ratio);
    } else if (!ratio_ok) {
      gyro_why = format_text(
          "its gyroscope turned %.2f times the tilt its accelerometer read: a "
          "gyroscope gain of %.2f (or a gain error of the accelerometer's "
          "horizontal axes)",
          ratio, ratio);
    }
    out.push_back({sensor.label, w.step.name + "-gyroscope", ratio_ok && axis_ok,
                   format_text("%.4f rad turned for %.4f rad tilted (x %.3f)", turn.norm(),
                               tilt.norm(), ratio),
                   format_text("x 1 +- %.2f", s_.gyro_tolerance), gyro_why});
  }

  // The statue back on its seat at the end: its sensor reads as at the first rest.
  void seat_check(std::size_t i, const Window& w, std::vector<CheckResult>& out) const {
    const CommissionedSensor& sensor = in_.sensors[i];
    if (!sensor.statue || acc_[i].empty() || !rest_.found()) return;
    const double moved = angle_deg(acc_[i].stats(w).mean, acc_[i].stats(rest_).mean);
    const bool seated = moved <= s_.seat_tolerance_deg;
    out.push_back({sensor.label, "seat", seated, format_text("%.3f deg", moved),
                   format_text("<= %.2f deg", s_.seat_tolerance_deg),
                   seated
                       ? format_text("back on its seat (%.3f deg from the first rest)", moved)
                       : format_text("the statue stands %.3f deg from where it stood at the first "
                                     "rest: not back on its seat (a shim left under it?)",
                                     moved)});
  }

  void traffic_checks(const std::string& label, const char* kind, const NodeTraffic& t, double rate,
                      std::vector<CheckResult>& out) const {
    if (t.frames == 0) {
      out.push_back(
          {label, "heard", false, format_text("no %s frame", kind), "its frames",
           format_text("never heard (no %s frame%s): not connected, not powered, or on "
                       "another node id",
                       kind,
                       t.rejected > 0 ? format_text(", %llu refused by the codec",
                                                    static_cast<unsigned long long>(t.rejected))
                                            .c_str()
                                      : "")});
      return;
    }
    const double measured = t.rate_hz();
    if (interleaved(t)) {
      const double broken = static_cast<double>(t.sequence_breaks) / static_cast<double>(t.frames);
      out.push_back(
          {label, "unique", false,
           format_text("%.0f %s frames/s, %.0f %% out of sequence", measured, kind, 100.0 * broken),
           format_text("%.0f frames/s in sequence", rate),
           format_text("two devices answer to this node: %.0f %% of its %s frames break "
                       "the sequence, at %.0f frames/s where one sensor sends %.0f",
                       100.0 * broken, kind, measured, rate)});
      return;
    }
    const bool rate_ok = std::abs(measured / rate - 1.0) <= kRateTolerance;
    out.push_back({label, std::string("rate-") + kind, rate_ok, format_text("%.1f Hz", measured),
                   format_text("%.0f Hz +- %.0f %%", rate, 100.0 * kRateTolerance),
                   rate_ok ? format_text("%llu %s frames at %.1f Hz",
                                         static_cast<unsigned long long>(t.frames), kind, measured)
                           : format_text("sends %s at %.1f Hz; the box file's "
                                         "estimator.sample_rate_hz is %.0f",
                                         kind, measured, rate)});
    const double lost = static_cast<double>(t.lost) / static_cast<double>(t.frames + t.lost);
    const bool whole = lost <= kLostFraction && t.rejected == 0;
    out.push_back(
        {label, std::string("loss-") + kind, whole,
         format_text("%llu lost, %llu refused", static_cast<unsigned long long>(t.lost),
                     static_cast<unsigned long long>(t.rejected)),
         format_text("<= %.0f %% lost, none refused", 100.0 * kLostFraction),
         whole ? "no sample lost beyond 1 %"
               : format_text("%.1f %% of its %s samples lost, %llu frames refused by the "
                             "codec: the bus or the node drops frames",
                             100.0 * lost, kind, static_cast<unsigned long long>(t.rejected))});
  }

  const CommissionInput& in_;
  const CommissioningSettings& s_;
  std::vector<Stream> acc_;   // per sensor, statue frame, m/s2
  std::vector<Stream> rate_;  // per sensor (the statue sensor's), statue frame, rad/s
  Window rest_;
};

}  // namespace

const char* window_source_name(WindowSource source) {
  switch (source) {
    case WindowSource::kData:
      return "data";
    case WindowSource::kOption:
      return "option";
    case WindowSource::kPrompt:
      return "prompt";
    case WindowSource::kNone:
      break;
  }
  return "none";
}

std::vector<CommissionedSensor> commissioned_sensors(const MonitorConfig& config) {
  std::array<SensorConfig, kMaxSensors> resolved{};
  const int count = resolved_sensors(config, resolved);
  std::vector<CommissionedSensor> out;
  for (int i = 0; i < count; ++i) {
    const SensorConfig& s = resolved[static_cast<std::size_t>(i)];
    CommissionedSensor c;
    c.index = i;
    c.node = s.node;
    c.role = s.role;
    c.label = format_text("node %u (%s, sensor[%d])", static_cast<unsigned>(s.node),
                          sensor_role_name(s.role), i);
    c.to_statue = s.conditioning.sensor_to_statue.cast<double>();
    c.unit_scale = s.conditioning.unit == monitor::AccelerationUnit::kStandardGravity ? kG0 : 1.0;
    c.unit_name = monitor::kAccelerationUnitNames.name(s.conditioning.unit);
    c.max_rest_std_m_s2 = static_cast<double>(s.conditioning.startup_max_std_m_s2);
    out.push_back(c);
  }
  if (const auto* statue = monitor::built_part<StatueSensorSettings>(config.statue_sensor);
      statue != nullptr && statue->present) {
    CommissionedSensor c;
    c.node = statue->node;
    c.statue = true;
    c.label = format_text("statue sensor (node %u)", static_cast<unsigned>(statue->node));
    c.to_statue = statue->sensor_to_statue.cast<double>();
    c.unit_scale = kG0;  // its SensorAcceleration frames carry g
    c.max_rest_std_m_s2 = static_cast<double>(config.conditioning.startup_max_std_m_s2);
    out.push_back(c);
  }
  return out;
}

std::vector<Step> plan_steps(const std::vector<CommissionedSensor>& sensors, int axis_count) {
  std::vector<Step> steps{{"rest", StepKind::kRest, -1, 0}};
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    if (sensors[i].statue) continue;
    for (int axis = 0; axis < 2; ++axis) {
      steps.push_back(
          {format_text("tilt-%s:%u", axis_letter(axis), static_cast<unsigned>(sensors[i].node)),
           StepKind::kWedge, static_cast<int>(i), axis});
    }
  }
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    if (!sensors[i].statue) continue;
    for (int axis = 0; axis < axis_count; ++axis) {
      steps.push_back({format_text("statue-%s", axis_letter(axis)), StepKind::kStatueRaise,
                       static_cast<int>(i), axis});
    }
  }
  steps.push_back({"final-rest", StepKind::kFinalRest, -1, 0});
  return steps;
}

std::string window_name(const Step& step, const char* part) { return step.name + "-" + part; }

std::vector<std::string> CommissionResult::failures() const {
  std::vector<std::string> out;
  for (const CheckResult& c : checks) {
    if (!c.passed) out.push_back(c.subject + ": " + c.message);
  }
  return out;
}

CommissionResult commission(const CommissionInput& input) {
  CommissionResult result;
  Checker checker(input);
  checker.census(result.checks);
  result.windows = checker.resolve_windows();
  for (const StepWindows& w : result.windows) checker.step_checks(w, result.checks);
  checker.axes_checks(result.windows, result.checks);
  result.traces = checker.traces(result.windows);
  result.passed = std::all_of(result.checks.begin(), result.checks.end(),
                              [](const CheckResult& c) { return c.passed; });
  if (input.session->monitor_frames() > 0) {
    result.notes.push_back(
        format_text("%llu frames of a monitor box heard: plinth-monitor runs on "
                    "this bus; a tilt it hears is shaking to it (stop it while "
                    "commissioning: docs/commissioning.md)",
                    static_cast<unsigned long long>(input.session->monitor_frames())));
  }
  return result;
}

std::vector<CheckResult> check_step(const CommissionInput& input, const Step& step) {
  Checker checker(input);
  const std::vector<StepWindows> windows = checker.resolve_windows();
  std::vector<CheckResult> out;
  for (const StepWindows& w : windows) {
    if (w.step.name == step.name) checker.step_checks(w, out);
  }
  return out;
}

}  // namespace plinth::firmware
