// plinth-monitor's inputs behind one interface: a record replayed as an ideal ground sensor's
// samples, a candump log of frames, a live SocketCAN bus. Each paces itself (a replay at
// --speed) and says what the monitor is to take next. Host code: allocates and throws.
#pragma once

#include <csignal>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "plinth/firmware/monitor.h"
#include "plinth/hal/candump_log.h"
#include "plinth/hal/frame_io.h"
#include "plinth/monitor/sensor_health.h"

namespace plinth::firmware {

// What the monitor takes next.
struct InputItem {
  enum class Kind : std::uint8_t {
    kSample,    // `sample`: the first sensor's, decoded (record replay)
    kFrame,     // `frame`: from a log or the bus
    kTick,      // `time_ns` on the receive clock: timeouts, heartbeats
    kBusFault,  // `bus_fault`: the bus reported trouble (true) or has been quiet long enough
  };
  Kind kind = Kind::kTick;
  monitor::SensorSample sample;
  // kFrame: the frame. kSample: the sample as its sensor's frame would carry it, for the event
  // recorder, when `has_frame` (asked for, and within the frame's +-8 g).
  hal::TimedFrame frame;
  bool has_frame = false;
  std::int64_t time_ns = 0;
  bool bus_fault = false;
  // kFrame: frames lost just before this one (the kernel's drops on a live bus, a log's
  // DROPCOUNT lines), for the event recorder; 0 otherwise.
  std::uint64_t lost_before = 0;
  // A paced replay's item: the CLOCK_MONOTONIC time it was due at (--latency measures from it
  // too, the wake-up's lateness included); 0 otherwise.
  std::int64_t due_ns = 0;
};

// Live bus trouble, for the summary.
struct BusCounters {
  std::uint64_t bus_errors = 0;      // error frames reported by the controller
  std::uint64_t overflows = 0;       // times the kernel reported dropped frames
  std::uint64_t dropped_frames = 0;  // frames the kernel dropped before we read them
};

// A log's timestamps that cannot be monitor time (docs/monitor.md, "Time in logs";
// hal::LogTimeCheck): with --log-time warn (the default) a frame stamped before the previous
// one, or at the same microsecond, is not given to the monitor; a jump forward beyond
// kMaxLogGapS is given, but not ticked through beyond that gap. Each is named on stderr (the
// first kLogTimeWarnings of them, with the line and the size) and raises the input fault (as a
// bus fault) until kInputFaultHoldS of well-stamped frames have passed. With --log-time refuse
// the first one ends the run (host::InputError, the same text).
inline constexpr double kMaxLogGapS = hal::kMaxLogGapS;
inline constexpr std::uint64_t kLogTimeWarnings = 10;
inline constexpr double kInputFaultHoldS = 2.0;
struct InputTimeCounters {
  std::uint64_t went_back = 0;
  std::uint64_t stood_still = 0;
  std::uint64_t gaps = 0;  // jumps forward beyond kMaxLogGapS
  std::string first;       // "file:line: what" of the first
  [[nodiscard]] std::uint64_t total() const { return went_back + stood_still + gaps; }
};

// The frames a log lost (docs/monitor.md, "Frames a log lost"; its DROPCOUNT lines, each the
// logger's socket overflowing): with --log-drops warn (the default) each is named on stderr (the
// first kLogDropWarnings, with the line and the count) and raises the bus fault, as a live
// overflow does, held until kInputFaultHoldS after the next frame. With --log-drops refuse the
// first one ends the run (host::InputError, the same text).
inline constexpr std::uint64_t kLogDropWarnings = 10;
struct InputDropCounters {
  std::uint64_t reports = 0;  // DROPCOUNT lines
  std::uint64_t frames = 0;   // the frames they say were lost
  std::string first;          // "file:line: what" of the first
};

class MonitorInput {
 public:
  virtual ~MonitorInput() = default;
  // The next item; false at the end of the input, or once the stop flag is set.
  [[nodiscard]] virtual bool next(InputItem& item) = 0;
  // The record, the log or the interface (the summary's "source").
  [[nodiscard]] virtual const std::string& source() const = 0;
  // Monitor time of the record's t = 0, s (a record replay's quiet lead-in); 0 otherwise.
  [[nodiscard]] virtual double t_origin() const { return 0.0; }
  [[nodiscard]] virtual BusCounters bus_counters() const { return {}; }
  [[nodiscard]] virtual InputTimeCounters time_counters() const { return {}; }
  [[nodiscard]] virtual InputDropCounters drop_counters() const { return {}; }
  // Where the monitor's status and alarm frames go; nullptr: nowhere (a replay).
  [[nodiscard]] virtual hal::FrameSink* sink() { return nullptr; }
};

struct InputOptions {
  std::string replay_path;    // a record (.AT2, .csv) or a candump log (.log)
  std::string replay_y_path;  // record: the second horizontal component
  std::string vertical_path;  // record: the vertical component
  std::string can_interface;  // live: the SocketCAN interface
  std::string pga;            // record: scale to this PGA ("0.3g")
  std::optional<double> scale;
  std::optional<double> rate_hz;  // record: the sensor rate (default: the record's, or 200)
  double speed = 0.0;             // replay: a factor of real time; 0: as fast as possible
  double duration_s = 0.0;        // live: stop after this long; 0: at the stop flag only
  bool recorder_frames = false;   // record: also give each sample as its frame
  // candump log: the policies for its time and for the frames it lost (above); not given:
  // warn. Refused for other inputs.
  std::optional<hal::LogPolicy> log_time;
  std::optional<hal::LogPolicy> log_drops;
};

// A replay file that is a candump log (.log), not a record.
[[nodiscard]] bool is_candump_log(const std::string& path);

// Opens the input `options` name (exactly one of replay_path, can_interface) and fits `config`
// to it: a record replay feeds one ideal ground sensor at the record's rate. `stop` (a signal
// handler's flag) ends the input. Throws host::InputError naming what is wrong.
[[nodiscard]] std::unique_ptr<MonitorInput> open_input(const InputOptions& options,
                                                       MonitorConfig& config,
                                                       const volatile std::sig_atomic_t& stop);

}  // namespace plinth::firmware
