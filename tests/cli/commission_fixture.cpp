// A commissioning session as a candump log (docs/commissioning.md), for plinth-commission's
// tests: the sensors a box file declares, installed as it says unless a --fault says otherwise,
// through the procedure's steps (rest; each ground and plate sensor on a wedge, +x then +y; the
// statue raised on its +x side, and its +y side with a second axis; rest). The statue's raise is
// the rigid block turning about its base edge (lib/core block_specific_force, as plinth-eval's
// statue sensor), its gyroscope the turn's rate; a wedge turns a sensor's gravity; each sample
// gets its sensor's bias and noise, then the codec's frames (hal/can_codec).
//
//   plinth-commission-fixture --config BOX.toml --out SESSION.log [--windows W.txt]
//       [--fault KIND]... [--half-width 0.3] [--lift-mm 6] [--wedge-deg 5] [--seed 1] [--short]
//
// Faults (NODE a node id, AXIS x, y or z of the sensor's own frame):
//   turned:NODE:DEG   mounted turned DEG about the statue's vertical from its declared mounting
//   gain:NODE:AXIS:K  that axis reads K times what it feels (K = -1: the axis reversed)
//   ms2:NODE          it sends m/s2 where g is due (clamped at the frame's full scale)
//   missing:NODE      never sends
//   extra:NODE        an accelerometer the box file does not name, on the floor
//   duplicate:NODE    a second device answering to NODE
//   statue-on-plinth  the statue sensor is fixed to the plinth: the statue's raises leave it still
//   gyro-gain:K       the statue sensor's gyroscope reads K times its turn (K = -1: reversed)
// --windows writes each step's true hold as a plinth-commission --window option, one a line.
// --can IF sends the session on a bus in real time instead (the live test,
// tests/integration/commission_live.sh): at each step's wait point it prints "hold STEP" and
// stays there until a line on stdin, as a site stands still while a custodian answers a prompt.
#include <poll.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "monitor_config.h"
#include "plinth/core/statue_filter.h"
#include "plinth/firmware/record_replay.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/candump_log.h"
#include "plinth/hal/pacing.h"
#include "plinth/hal/socketcan.h"
#include "plinth/host/cli.h"
#include "plinth/host/input_error.h"

namespace {

namespace fw = plinth::firmware;
namespace can = plinth::hal::can;
using plinth::host::InputError;

constexpr double kG0 = 9.80665;
constexpr double kPi = 3.14159265358979323846;
constexpr std::int64_t kEpochNs = 1'700'000'000'000'000'000;
constexpr double kNoiseG = 0.0005;    // g rms per axis (statue_frames.py's)
constexpr double kRateNoise = 0.003;  // rad/s rms (a BMI088 at 200 Hz)
constexpr double kRateBias = 0.01;    // rad/s about the sensor's y
constexpr double kHandNoiseG = 0.03;  // g rms while a hand places or takes the wedge
constexpr double kFullScaleG = 8.19175;

// One accelerometer as installed.
struct Device {
  int node = 1;
  bool statue = false;
  bool ground = true;  // a ground or plate sensor (wedge steps)
  bool silent = false;
  bool on_plinth = false;  // statue sensor fixed to the plinth
  bool sends_ms2 = false;
  Eigen::Matrix3d to_statue = Eigen::Matrix3d::Identity();  // as installed
  Eigen::Vector3d gain = Eigen::Vector3d::Ones();
  Eigen::Vector3d bias_g = Eigen::Vector3d::Zero();
  double gyro_gain = 1.0;
  double phase_s = 0.0;  // its clock's offset from the others
  int sequence = 0;
  int index = -1;         // in the box file's ground and plate sensors (wedge steps)
  double height_m = 1.0;  // statue sensor: above the block's base
  double offset_x_m = 0.0;
  double offset_y_m = 0.0;
};

// What happens at a time: which device is on the wedge (and which side), how far the statue's
// side is raised (rad), whose hand shakes.
struct Motion {
  int wedge_device = -1;
  int wedge_axis = 0;
  double wedge_rad = 0.0;
  bool hand = false;
  int statue_axis = 0;
  double theta = 0.0;
  double theta_dot = 0.0;
  double theta_ddot = 0.0;
};

// A smooth ramp 0 -> 1 over [0, 1] (cosine), and its first two derivatives.
void ramp(double u, double& s, double& ds, double& dds) {
  if (u <= 0.0 || u >= 1.0) {
    s = u <= 0.0 ? 0.0 : 1.0;
    ds = dds = 0.0;
    return;
  }
  s = 0.5 - 0.5 * std::cos(kPi * u);
  ds = 0.5 * kPi * std::sin(kPi * u);
  dds = 0.5 * kPi * kPi * std::cos(kPi * u);
}

// How long each part of the session lasts, s.
struct Timeline {
  double rest = 12.0;         // the first rest
  double place = 2.0;         // a wedge put under a sensor (a hand on it)
  double hold = 7.0;          // the sensor on the wedge
  double remove = 2.0;        // the wedge taken away
  double stand = 3.0;         // the sensor back on its marks
  double statue_stand = 5.0;  // the statue standing before a raise
  double raise = 2.5;         // the statue's side raised, or lowered
  double statue_hold = 7.0;   // the statue's side held up
  double final_rest = 17.0;   // everything back, at the end
};
// --short: a live test's session (tests/integration/commission_live.sh, windows of 3 s).
constexpr Timeline kShortTimeline{6.0, 1.0, 4.5, 1.0, 1.0, 3.5, 2.0, 4.5, 8.0};

struct Options {
  std::string config;
  std::string out;
  std::string can_interface;  // live: send the session on this bus
  std::string windows;
  std::vector<std::string> faults;
  double half_width = 0.3;  // m
  double lift_mm = 6.0;
  double wedge_deg = 5.0;
  unsigned seed = 1;
  bool short_session = false;
};

struct Segment {
  double t0 = 0.0;
  double t1 = 0.0;
  // kind: 0 rest, 1 wedge place, 2 wedge hold, 3 wedge remove, 4 statue raise, 5 statue hold,
  // 6 statue lower
  int kind = 0;
  int device = -1;
  int axis = 0;
  // Live (--can): the step a custodian is prompted for while the site stands in this segment;
  // the session stays in its middle until told to go on ("" none).
  std::string step;
};

class Session {
 public:
  Session(std::vector<Device> devices, int axes, double wedge_rad, double lift_rad, double rate,
          const Timeline& time)
      : devices_(std::move(devices)), wedge_rad_(wedge_rad), lift_rad_(lift_rad), rate_(rate) {
    double t = 0.0;
    const auto add = [&](double length, int kind, int device, int axis, std::string step = "") {
      segments_.push_back({t, t + length, kind, device, axis, std::move(step)});
      t += length;
    };
    add(time.rest, 0, -1, 0, "rest");
    for (std::size_t d = 0; d < devices_.size(); ++d) {
      if (!devices_[d].ground || devices_[d].index < 0) continue;
      for (int axis = 0; axis < 2; ++axis) {
        add(time.place, 1, static_cast<int>(d), axis);
        const std::string name = name_wedge(devices_[d].node, axis);
        holds_.push_back({name, t + 0.5, t + time.hold - 0.5});
        add(time.hold, 2, static_cast<int>(d), axis, name);
        add(time.remove, 3, static_cast<int>(d), axis);
        add(time.stand, 0, -1, 0);
      }
    }
    for (std::size_t d = 0; d < devices_.size(); ++d) {
      if (!devices_[d].statue) continue;
      for (int axis = 0; axis < axes; ++axis) {
        const std::string name = axis == 0 ? "statue-x" : "statue-y";
        add(time.statue_stand, 0, -1, 0, name + "-before");
        add(time.raise, 4, static_cast<int>(d), axis);
        holds_.push_back({name, t + 0.5, t + time.statue_hold - 0.5});
        add(time.statue_hold, 5, static_cast<int>(d), axis, name);
        add(time.raise, 6, static_cast<int>(d), axis);
        add(time.statue_stand, 0, -1, 0, name + "-after");
      }
    }
    add(time.final_rest, 0, -1, 0, "final-rest");
    end_ = t;
  }

  struct Hold {
    std::string name;
    double t0;
    double t1;
  };
  static std::string name_wedge(int node, int axis) {
    return std::string(axis == 0 ? "tilt-x:" : "tilt-y:") + std::to_string(node);
  }

  [[nodiscard]] Motion motion(double t) const {
    Motion m;
    for (const Segment& s : segments_) {
      if (t < s.t0 || t >= s.t1) continue;
      const double u = (t - s.t0) / (s.t1 - s.t0);
      double r = 0.0, dr = 0.0, ddr = 0.0;
      switch (s.kind) {
        case 1:
        case 3:
          ramp(s.kind == 1 ? u : 1.0 - u, r, dr, ddr);
          m.wedge_device = s.device;
          m.wedge_axis = s.axis;
          m.wedge_rad = wedge_rad_ * r;
          m.hand = true;
          break;
        case 2:
          m.wedge_device = s.device;
          m.wedge_axis = s.axis;
          m.wedge_rad = wedge_rad_;
          break;
        case 4:
        case 6: {
          const double sign = s.kind == 4 ? 1.0 : -1.0;
          ramp(s.kind == 4 ? u : 1.0 - u, r, dr, ddr);
          const double rate = 1.0 / (s.t1 - s.t0);
          m.statue_axis = s.axis;
          m.theta = lift_rad_ * r;
          m.theta_dot = sign * lift_rad_ * dr * rate;
          m.theta_ddot = lift_rad_ * ddr * rate * rate;
          break;
        }
        case 5:
          m.statue_axis = s.axis;
          m.theta = lift_rad_;
          break;
        default:
          break;
      }
    }
    return m;
  }

  // Live: the next wait point from session time `t` on (its step and the middle of its segment),
  // or none.
  [[nodiscard]] const Segment* next_wait(double t) const {
    for (const Segment& s : segments_) {
      if (!s.step.empty() && 0.5 * (s.t0 + s.t1) >= t) return &s;
    }
    return nullptr;
  }

  std::vector<Device>& devices() { return devices_; }
  [[nodiscard]] double end() const { return end_; }
  [[nodiscard]] const std::vector<Hold>& holds() const { return holds_; }
  [[nodiscard]] double rate() const { return rate_; }

 private:
  std::vector<Device> devices_;
  std::vector<Segment> segments_;
  std::vector<Hold> holds_;
  double wedge_rad_;
  double lift_rad_;
  double rate_;
  double end_ = 0.0;
};

// The statue frame's rotation of a sensor body turned about the statue's x or y axis.
Eigen::Matrix3d tilt(int axis, double angle) {
  // Raising +x turns the body about -y; raising +y about +x.
  return axis == 0 ? Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitY()).toRotationMatrix()
                   : Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

std::string frame_line(std::int64_t t_ns, const can::CanFrame& frame) {
  return plinth::hal::format_candump_line(t_ns, "can0", frame) + "\n";
}

void parse_fault(const std::string& fault, std::vector<Device>& devices, int& extra,
                 int& duplicate) {
  std::vector<std::string> parts;
  std::size_t from = 0;
  for (;;) {
    const std::size_t colon = fault.find(':', from);
    parts.push_back(fault.substr(from, colon - from));
    if (colon == std::string::npos) break;
    from = colon + 1;
  }
  const auto device = [&](const std::string& node) -> Device& {
    for (Device& d : devices) {
      if (d.node == std::stoi(node)) return d;
    }
    throw InputError("--fault " + fault + ": no sensor on node " + node + " in the box file");
  };
  const auto axis = [&](const std::string& a) {
    if (a == "x") return 0;
    if (a == "y") return 1;
    if (a == "z") return 2;
    throw InputError("--fault " + fault + ": axis x, y or z");
  };
  const std::string& kind = parts[0];
  if (kind == "turned" && parts.size() == 3) {
    Device& d = device(parts[1]);
    d.to_statue = Eigen::AngleAxisd(std::stod(parts[2]) * kPi / 180.0, Eigen::Vector3d::UnitZ())
                      .toRotationMatrix() *
                  d.to_statue;
  } else if (kind == "gain" && parts.size() == 4) {
    device(parts[1]).gain[axis(parts[2])] = std::stod(parts[3]);
  } else if (kind == "ms2" && parts.size() == 2) {
    device(parts[1]).sends_ms2 = true;
  } else if (kind == "missing" && parts.size() == 2) {
    device(parts[1]).silent = true;
  } else if (kind == "extra" && parts.size() == 2) {
    extra = std::stoi(parts[1]);
  } else if (kind == "duplicate" && parts.size() == 2) {
    duplicate = device(parts[1]).node;
  } else if (kind == "statue-on-plinth" && parts.size() == 1) {
    for (Device& d : devices) d.on_plinth = d.on_plinth || d.statue;
  } else if (kind == "gyro-gain" && parts.size() == 2) {
    for (Device& d : devices) {
      if (d.statue) d.gyro_gain = std::stod(parts[1]);
    }
  } else {
    throw InputError("--fault " + fault + ": unknown (see the file's head)");
  }
}

// Live (--can): the session sent on a bus in real time; at each step's wait point it stays
// there ("hold STEP" on stdout) until a line on stdin, then goes on to the next; it ends after
// the last one.
template <typename Sample>
int run_live(const Options& opt, const Session& session, Sample& sample) {
  plinth::hal::SocketCanOpenResult opened = plinth::hal::SocketCanPort::open(opt.can_interface);
  if (!opened.ok()) throw InputError(opened.message);
  plinth::hal::SocketCanPort& port = *opened.port;
  const double rate = session.rate();
  const auto start = std::chrono::steady_clock::now();
  double tau = 0.0;
  const Segment* wait = session.next_wait(0.0);
  bool said = false;
  std::string line;
  for (std::int64_t n = 0; wait != nullptr; ++n) {
    std::this_thread::sleep_until(
        start + std::chrono::nanoseconds(std::llround(1e9 * static_cast<double>(n) / rate)));
    const double middle = 0.5 * (wait->t0 + wait->t1);
    if (tau >= middle && !said) {
      std::printf("hold %s\n", wait->step.c_str());
      std::fflush(stdout);
      said = true;
    }
    pollfd in{STDIN_FILENO, POLLIN, 0};
    if (said && n % 10 == 0 && ::poll(&in, 1, 0) > 0) {  // a look every 10 samples is enough
      char c = 0;
      if (::read(STDIN_FILENO, &c, 1) <= 0) break;  // stdin closed: the session ends
      if (c == '\n') {
        wait = session.next_wait(middle + 1e-6);
        said = false;
      }
    }
    sample(n, tau, plinth::hal::realtime_now_ns(), [&port](std::int64_t, const can::CanFrame& f) {
      if (port.send(f) != plinth::hal::IoStatus::kOk) throw InputError("cannot send on the bus");
    });
    if (!said) tau += 1.0 / rate;  // a wait point holds the site still
  }
  return 0;
}

int run(const Options& opt) {
  const fw::MonitorFile file = fw::load_monitor_file(opt.config, fw::box_defaults());
  std::array<fw::SensorConfig, fw::kMaxSensors> sensors{};
  const int count = fw::resolved_sensors(file.config, sensors);
  std::mt19937 random(opt.seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<Device> devices;
  for (int i = 0; i < count; ++i) {
    Device d;
    d.node = sensors[static_cast<std::size_t>(i)].node;
    d.index = i;
    d.to_statue = sensors[static_cast<std::size_t>(i)].conditioning.sensor_to_statue.cast<double>();
    d.bias_g = Eigen::Vector3d(normal(random), normal(random), normal(random)) * 0.002;
    d.phase_s = 0.1 * i / file.config.estimator.sample_rate_hz;  // its clock's phase
    devices.push_back(d);
  }
  if (const auto* statue =
          plinth::monitor::built_part<fw::StatueSensorSettings>(file.config.statue_sensor);
      statue != nullptr && statue->present) {
    Device d;
    d.node = statue->node;
    d.statue = true;
    d.ground = false;
    d.to_statue = statue->sensor_to_statue.cast<double>();
    d.bias_g = Eigen::Vector3d(normal(random), normal(random), normal(random)) * 0.002;
    d.phase_s = 0.5 / file.config.estimator.sample_rate_hz;
    d.height_m = static_cast<double>(statue->height_m);
    d.offset_x_m = static_cast<double>(statue->offset_x_m);
    d.offset_y_m = static_cast<double>(statue->offset_y_m);
    devices.push_back(d);
  }
  const double rate_hz = file.config.estimator.sample_rate_hz;
  int extra = -1;
  int duplicate = -1;
  for (const std::string& f : opt.faults) parse_fault(f, devices, extra, duplicate);
  if (extra > 0) {
    Device d;
    d.node = extra;
    d.phase_s = 0.6 / rate_hz;
    devices.push_back(d);  // index -1: never on the wedge
  }
  if (duplicate > 0) {
    Device d;
    d.node = duplicate;
    d.phase_s = 0.7 / rate_hz;
    d.sequence = 97;
    devices.push_back(d);
  }
  const int axes = file.second_scene_path.empty() ? 1 : 2;
  const double rate = file.config.estimator.sample_rate_hz;
  Session session(devices, axes, opt.wedge_deg * kPi / 180.0,
                  opt.lift_mm * 1e-3 / (2.0 * opt.half_width), rate,
                  opt.short_session ? kShortTimeline : Timeline{});

  // One sample of each device at session time `tau` (+ its phase), stamped `stamp_ns` (+ its
  // phase): its frames to `emit`.
  const auto sample = [&](std::int64_t n, double tau, std::int64_t stamp_ns, auto emit) {
    for (Device& d : session.devices()) {
      if (d.silent) continue;
      const double t = tau + d.phase_s;
      const std::int64_t t_ns = stamp_ns + std::llround(d.phase_s * 1e9);
      const Motion m = session.motion(t);
      Eigen::Vector3d f(0.0, 0.0, kG0);  // statue frame, the body's own specific force, m/s2
      Eigen::Vector3d omega = Eigen::Vector3d::Zero();  // statue frame, rad/s
      if (d.ground && &d - session.devices().data() == m.wedge_device) {
        f = tilt(m.wedge_axis, m.wedge_rad).transpose() * f;
      }
      if (d.statue && !d.on_plinth && m.theta != 0.0) {
        // The block turning about its -x (-y) base edge, the sensor at its place on the block.
        const double from_edge =
            opt.half_width + (m.statue_axis == 0 ? d.offset_x_m : d.offset_y_m);
        const plinth::Vector2r plane = plinth::block_specific_force(
            plinth::Vector2r::Zero(), plinth::Vector2r(from_edge, d.height_m), m.theta, m.theta_dot,
            m.theta_ddot, kG0);
        f = m.statue_axis == 0 ? Eigen::Vector3d(plane.x(), 0.0, plane.y())
                               : Eigen::Vector3d(0.0, plane.x(), plane.y());
        omega = m.statue_axis == 0 ? Eigen::Vector3d(0.0, -m.theta_dot, 0.0)
                                   : Eigen::Vector3d(m.theta_dot, 0.0, 0.0);
      }
      const double hand =
          m.hand && &d - session.devices().data() == m.wedge_device ? kHandNoiseG : 0.0;
      Eigen::Vector3d reading = d.to_statue.transpose() * f / kG0;
      for (int a = 0; a < 3; ++a) {
        reading[a] = d.gain[a] * reading[a] + d.bias_g[a] + (kNoiseG + hand) * normal(random);
      }
      can::SensorAcceleration acc;
      acc.node = static_cast<std::uint8_t>(d.node);
      if (d.sends_ms2) reading *= kG0;
      for (int a = 0; a < 3; ++a) {
        if (std::abs(reading[a]) > kFullScaleG) {
          reading[a] = std::copysign(kFullScaleG, reading[a]);
          acc.status |= can::sensor_status::kSaturated;
        }
      }
      acc.ax_g = reading.x();
      acc.ay_g = reading.y();
      acc.az_g = reading.z();
      acc.sequence = static_cast<std::uint8_t>(d.sequence);
      can::CanFrame frame;
      if (!can::encode(acc, frame).ok()) throw InputError("a sample beyond the frame's range");
      emit(t_ns, frame);
      if (d.statue) {
        const Eigen::Vector3d w = d.gyro_gain * (d.to_statue.transpose() * omega);
        can::StatueRotation rot;
        rot.node = acc.node;
        rot.wx_rad_s = w.x() + kRateNoise * normal(random);
        rot.wy_rad_s = w.y() + kRateBias + kRateNoise * normal(random);
        rot.wz_rad_s = w.z() + kRateNoise * normal(random);
        rot.sequence = acc.sequence;
        if (!can::encode(rot, frame).ok()) throw InputError("a rate beyond the frame's range");
        emit(t_ns + 1000, frame);  // its own microsecond (the log's time check)
      }
      d.sequence = (d.sequence + 1) % 256;
      if (n % static_cast<std::int64_t>(rate) == 0) {  // heartbeats, once a second
        can::SensorHeartbeat beat;
        beat.node = acc.node;
        beat.uptime_s = static_cast<std::uint32_t>(n / static_cast<std::int64_t>(rate));
        if (can::encode(beat, frame).ok()) emit(t_ns + 2000, frame);
      }
    }
  };
  if (!opt.can_interface.empty()) return run_live(opt, session, sample);

  std::ofstream out(opt.out);
  if (!out) throw InputError(opt.out + ": cannot write");
  const auto samples = static_cast<std::int64_t>(session.end() * rate);
  for (std::int64_t n = 0; n < samples; ++n) {
    const double tau = static_cast<double>(n) / rate;
    sample(
        n, tau, kEpochNs + std::llround(tau * 1e9),
        [&out](std::int64_t t_ns, const can::CanFrame& frame) { out << frame_line(t_ns, frame); });
  }
  if (!out.flush()) throw InputError(opt.out + ": write failed");
  if (!opt.windows.empty()) {
    std::ofstream w(opt.windows);
    for (const Session::Hold& h : session.holds()) {
      char line[96];
      std::snprintf(line, sizeof line, "%s=%.3f:%.3f\n", h.name.c_str(), h.t0, h.t1);
      w << line;
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plinth-commission-fixture: a commissioning session as a candump log (tests)"};
  Options opt;
  app.add_option("--config", opt.config, "the box file (the installation as declared)")->required();
  app.add_option("--out", opt.out, "the candump log to write");
  app.add_option("--can", opt.can_interface,
                 "send the session on this bus in real time, waiting at each step (stdin)")
      ->excludes("--out");
  app.add_option("--windows", opt.windows, "write each step's true hold as --window options here");
  app.add_option("--fault", opt.faults, "a fault of the installation (see the source's head)");
  app.add_option("--half-width", opt.half_width, "the statue's half base width, m");
  app.add_option("--lift-mm", opt.lift_mm, "how far the statue's side is raised, mm");
  app.add_option("--wedge-deg", opt.wedge_deg, "the wedge's angle, deg");
  app.add_option("--seed", opt.seed, "the noise's seed");
  app.add_flag("--short", opt.short_session,
               "a short session (rests of 6 s, holds of 4.5 s), for the live test");
  if (const auto code = plinth::host::parse_command_line(app, argc, argv)) return *code;
  return plinth::host::run_tool("plinth-commission-fixture", [&] { return run(opt); });
}
