// can-utils' candump log files: read as a FrameSource, written as a FrameSink.
//
// One frame per line, exactly as `candump -l` writes and `canplayer -I` reads:
//
//     (1700000000.123456) vcan0 301#0011223344556677
//
// the timestamp in seconds with exactly six decimals (microseconds; canplayer reads the
// decimals as an integer count of microseconds, so "1.5" would mean 1 s + 5 us: refused), the
// interface name, then the frame: the identifier in hex (3 digits: standard, 8 digits:
// extended or, with 0x20000000 set, an error frame), '#', the data bytes in hex (0 to 8
// bytes, either case, optionally separated by '.'). Also recognised, as canplayer does:
// `123#R` / `123#R5` (remote request, optional DLC), `123##1<data>` (CAN FD: flags nibble,
// up to 64 bytes), `...#<8 bytes>_9` (classic frame with a raw DLC of 9-15) and a trailing
// direction token `R` or `T` (asc2log writes one). Blank lines and lines starting with '#' are
// comments. candump -d writes, before the next frame it receives after its socket overflowed,
//
//     DROPCOUNT: dropped 410 CAN frames on 'vcan0' socket (total drops 410)
//
// (the frames the kernel dropped since the previous report; the quoted socket is the interface,
// or before can-utils 2020.12 the command-line argument with its filters): read as frames lost
// at that point of the log (docs/record-formats.md, "Frames a log lost"). Anything else is
// malformed and reported with its file and line; canplayer would silently skip a line not
// starting with '(', this reader refuses it so a wrong file is noticed.
//
// Host code: allocates (never throws for a bad file: open() and receive() say what is wrong).
#pragma once

#include <array>
#include <cstdint>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "plinth/core/name_table.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/candump_format.h"
#include "plinth/hal/frame_io.h"

namespace plinth::hal {

enum class CandumpFrameKind : std::uint8_t {
  kComment,     // blank line or '#' comment: no frame
  kClassic,     // classic data frame, standard (11-bit) identifier
  kExtended,    // classic data frame, extended (29-bit) identifier
  kRemote,      // remote transmission request (standard or extended)
  kFd,          // CAN FD frame ("##")
  kErrorFrame,  // error frame (8-digit identifier with CAN_ERR_FLAG 0x20000000)
  kDropCount,   // candump's "DROPCOUNT: dropped N CAN frames ...": no frame, N frames lost here
};

inline constexpr NameTable<CandumpFrameKind, 7> kCandumpFrameKindNames{{{
    {CandumpFrameKind::kComment, "comment"},
    {CandumpFrameKind::kClassic, "classic"},
    {CandumpFrameKind::kExtended, "extended"},
    {CandumpFrameKind::kRemote, "remote request"},
    {CandumpFrameKind::kFd, "CAN FD"},
    {CandumpFrameKind::kErrorFrame, "error frame"},
    {CandumpFrameKind::kDropCount, "drop count"},
}}};

[[nodiscard]] constexpr const char* candump_frame_kind_name(CandumpFrameKind kind) {
  return kCandumpFrameKindNames.name(kind);
}

inline constexpr std::size_t kCandumpMaxFdLength = 64;         // bytes
// A line of a CAN FD frame with 64 bytes separated by dots is about 260 bytes; a longer line is
// not a candump line, and reading it whole could take any amount of memory.
inline constexpr std::size_t kCandumpMaxLineBytes = 512;
inline constexpr std::uint32_t kStandardIdMask = 0x7FF;
inline constexpr std::uint32_t kExtendedIdMask = 0x1FFFFFFF;
inline constexpr std::uint32_t kCanErrorFlag = 0x20000000;  // SocketCAN's CAN_ERR_FLAG

// One parsed log line.
struct CandumpLine {
  CandumpFrameKind kind = CandumpFrameKind::kComment;
  std::int64_t timestamp_ns = 0;  // since the epoch, a whole number of microseconds
  // A frame's interface; a DROPCOUNT line's socket as candump names it (see above).
  std::string interface_name;
  std::uint32_t id = 0;      // without flag bits (for error frames: the error class bits)
  bool extended = false;     // 8-digit identifier
  std::uint8_t length = 0;   // data bytes (remote request: the requested DLC)
  std::uint8_t raw_dlc = 0;  // classic frames with 8 bytes and a "_<dlc>" suffix: 9..15, else 0
  std::uint8_t fd_flags = 0;
  std::array<std::uint8_t, kCandumpMaxFdLength> data{};
  // kDropCount: the frames lost since the socket's previous report (1 or more), and the
  // socket's total so far (both candump's 32-bit counters).
  std::uint32_t dropped_frames = 0;
  std::uint32_t total_dropped_frames = 0;
};

// Parses one line (without its newline; a trailing '\r' is allowed). Returns "" on success,
// otherwise what is wrong, e.g. "odd number of hex digits in the data (a truncated byte)".
[[nodiscard]] std::string parse_candump_line(std::string_view line, CandumpLine& out);

// A DROPCOUNT line as candump -d writes it (no newline): "DROPCOUNT: dropped 1 CAN frame on
// 'vcan0' socket (total drops 7)". "" when the count is 0 or the socket name is empty or holds
// a quote or a line break.
[[nodiscard]] std::string format_candump_drop_line(std::uint32_t dropped_frames,
                                                   std::string_view socket_name,
                                                   std::uint32_t total_dropped_frames);
// What a parsed DROPCOUNT line says, for messages: "candump lost 410 CAN frames on 'vcan0'
// before this line (its socket overflowed; 410 in all so far)".
[[nodiscard]] std::string describe_candump_drop(const CandumpLine& line);

// The log line of a classic frame with a standard identifier, as candump -l writes it
// (uppercase hex, no newline): "(1700000000.123456) vcan0 301#0011223344556677".
// The timestamp is truncated to whole microseconds; it must not be negative, and the interface
// name must be 1 to 15 characters (otherwise: ""). The freestanding form: candump_format.h.
[[nodiscard]] std::string format_candump_line(std::int64_t timestamp_ns,
                                              std::string_view interface_name,
                                              const can::CanFrame& frame);

// Reads a candump log file frame by frame. receive() never waits (timeout_ms is ignored) and
// returns, per non-comment line:
//   kOk          a classic data frame with a standard identifier (any identifier and length
//                0..8: whether it is a plinth frame is the codec's business);
//   kNotPlinth   an extended, remote, CAN FD or raw-DLC frame (only the timestamp is set);
//   kBusError    a logged error frame (only the timestamp is set);
//   kOverflow    a DROPCOUNT line: dropped_frames() frames were lost before the next frame
//                (last_line() has the socket and candump's total; the timestamp is not set);
//   kIoError     a malformed line or a read error: error() says "file:line: what"; the next
//                call goes on with the following line (after a line longer than
//                kCandumpMaxLineBytes, or a read error, the input ends there);
//   kEndOfInput  at the end of the file (and on every later call).
struct CandumpLogReaderOpenResult;
class CandumpLogReader final : public FrameSource {
 public:
  // Opens `path` for reading; on failure the result's message is "<path>: cannot open file"
  // with the reason: missing, a directory, or not a regular file (a FIFO or device such as
  // /dev/zero, which would never end).
  [[nodiscard]] static CandumpLogReaderOpenResult open(std::string path);

  [[nodiscard]] IoStatus receive(TimedFrame& out, int timeout_ms) override;

  [[nodiscard]] const std::string& error() const { return error_; }
  // The last line read, as parsed (interface, kind, full identifier and data of any frame).
  [[nodiscard]] const CandumpLine& last_line() const { return line_; }
  [[nodiscard]] std::size_t line_number() const { return line_number_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  // After kOverflow: the frames the DROPCOUNT line says were lost; and all so far, every
  // DROPCOUNT line read (as hal::SocketCanPort's dropped_frames() and total_dropped_frames()).
  [[nodiscard]] std::uint32_t dropped_frames() const { return line_.dropped_frames; }
  [[nodiscard]] std::uint64_t total_dropped_frames() const { return total_dropped_frames_; }

 private:
  CandumpLogReader(std::string path, std::ifstream in);
  bool read_line();

  std::string path_;
  std::ifstream in_;
  std::string text_;
  CandumpLine line_;
  std::size_t line_number_ = 0;
  std::uint64_t total_dropped_frames_ = 0;
  std::string error_;
  bool ended_ = false;  // after a line too long or a read error
};

// Writes a candump log file. Each sent frame becomes one line stamped with `clock()` (ns since
// the epoch: the caller decides what time a frame carries, e.g. its virtual send time).
// send() returns kIoError, with error() set, for a frame that is not a classic standard frame
// of 0..8 bytes, a negative timestamp or a failed write.
struct CandumpLogWriterOpenResult;
class CandumpLogWriter final : public FrameSink {
 public:
  using Clock = std::function<std::int64_t()>;

  // Creates (truncates) `path`. On failure the result's message says why: the file cannot be
  // created, or the interface name is empty, longer than 15 characters or contains white space.
  [[nodiscard]] static CandumpLogWriterOpenResult open(std::string path, std::string interface_name,
                                                       Clock clock);

  [[nodiscard]] IoStatus send(const can::CanFrame& frame) override;
  // Flushes to the file; false (error() set) when a write failed.
  [[nodiscard]] bool flush();

  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] const std::string& path() const { return path_; }

 private:
  CandumpLogWriter(std::string path, std::string interface_name, Clock clock, std::ofstream out);

  std::string path_;
  std::string interface_name_;
  Clock clock_;
  std::ofstream out_;
  std::string error_;
};

// ---------------------------------------------------------------------------------------------
// Time in a log (docs/record-formats.md, "Time in candump logs")
//
// A log's frames are meant to follow one another in time: a frame stamped before the previous
// one (the log was merged, or the logging clock was stepped back), at the same microsecond as
// the previous frame of its identifier (a duplicate), or long after the previous one (the
// logger paused, or the clock was stepped forward) cannot be replayed as logged.
// plinth-replay and plinth-monitor check every frame with LogTimeCheck and apply the policy
// --log-time chooses: warn (the default: name each, go on) or refuse (stop at the first).
// The frames a log lost (its DROPCOUNT lines) have a policy of their own, --log-drops.

enum class LogTimeProblem : std::uint8_t {
  kNone,
  kWentBack,    // stamped before the previous frame
  kStoodStill,  // stamped at the previous time of its identifier
  kJumped,      // stamped more than the gap limit after the previous frame
};

// What a reader does with a flaw of a log (--log-time, --log-drops): warn (name it, go on) or
// refuse (stop at the first).
enum class LogPolicy : std::uint8_t { kWarn, kRefuse };
inline constexpr NameTable<LogPolicy, 2> kLogPolicyNames{{{
    {LogPolicy::kWarn, "warn"},
    {LogPolicy::kRefuse, "refuse"},
}}};

// A log's frames longer apart than this are a jump: s.
inline constexpr double kMaxLogGapS = 10.0;

struct LogTimeStep {
  LogTimeProblem problem = LogTimeProblem::kNone;
  std::int64_t step_ns = 0;  // the frame's time minus the previous frame's (< 0: back)
};

class LogTimeCheck {
 public:
  LogTimeCheck();
  // The frame stamped t_ns (standard identifier `id`) against the latest frame taken; kNone for
  // the first one.
  [[nodiscard]] LogTimeStep check(std::int64_t t_ns, std::uint32_t id) const;
  // Takes the frame as the latest (its time then becomes the previous frame's).
  void take(std::int64_t t_ns, std::uint32_t id);
  [[nodiscard]] bool started() const { return started_; }
  [[nodiscard]] std::int64_t previous_ns() const { return previous_ns_; }
  // What is wrong, with the size: "timestamp goes back by 0.250000 s (1700000000.250000 after
  // 1700000000.500000)", "timestamp jumps forward by 3600.000000 s (more than the 10 s a log's
  // frames may be apart)", "timestamp stands still (...)". "" for kNone.
  [[nodiscard]] std::string describe(const LogTimeStep& step, std::int64_t t_ns) const;

 private:
  bool started_ = false;
  std::int64_t previous_ns_ = 0;
  std::array<std::int64_t, kStandardIdMask + 1> last_ns_by_id_{};  // -1: none yet
};

struct CandumpLogReaderOpenResult {
  std::optional<CandumpLogReader> reader;  // set on success
  std::string message;                     // names the file and the cause; empty on success

  [[nodiscard]] bool ok() const { return reader.has_value(); }
};

struct CandumpLogWriterOpenResult {
  std::optional<CandumpLogWriter> writer;  // set on success
  std::string message;                     // names the file or the interface name and the cause

  [[nodiscard]] bool ok() const { return writer.has_value(); }
};

}  // namespace plinth::hal
