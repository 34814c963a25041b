#include "plinth/hal/candump_log.h"

#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <system_error>
#include <utility>

namespace plinth::hal {
namespace {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;
constexpr std::int64_t kNsPerMicrosecond = 1'000;
// The largest whole second whose nanoseconds (plus a fraction) still fit an int64.
constexpr std::int64_t kMaxTimestampSeconds =
    std::numeric_limits<std::int64_t>::max() / kNsPerSecond - 1;
constexpr std::size_t kMaxClassicLength = 8;
constexpr std::size_t kQuoteLength = 40;  // characters of a bad token quoted in a message

bool is_blank(char c) { return c == ' ' || c == '\t'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

// 0..15 for a hex digit (either case), -1 otherwise.
int hex_value(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Message parts joined (GCC 12 warns falsely on `"literal" + std::string` at -O3).
std::string join(std::initializer_list<std::string_view> parts) {
  std::string out;
  for (const std::string_view part : parts) out += part;
  return out;
}

std::string quoted(std::string_view text) {
  if (text.size() <= kQuoteLength) return join({"'", text, "'"});
  return join({"'", text.substr(0, kQuoteLength), "...'"});
}

std::string_view next_token(std::string_view& rest) {
  std::size_t begin = 0;
  while (begin < rest.size() && is_blank(rest[begin])) ++begin;
  std::size_t end = begin;
  while (end < rest.size() && !is_blank(rest[end])) ++end;
  const std::string_view token = rest.substr(begin, end - begin);
  rest.remove_prefix(end);
  return token;
}

// "(seconds.micro)" with exactly six decimals -> ns; "" or the reason.
std::string parse_timestamp(std::string_view token, std::int64_t& timestamp_ns) {
  const std::string bad = join({"bad timestamp ", quoted(token),
                                ": expected (seconds.microseconds) with six decimals, as "
                                "candump -l writes"});
  if (token.size() < 4 || token.front() != '(' || token.back() != ')') return bad;
  const std::string_view inner = token.substr(1, token.size() - 2);
  const std::size_t point = inner.find('.');
  if (point == std::string_view::npos || point == 0) return bad;
  const std::string_view seconds_text = inner.substr(0, point);
  const std::string_view micros_text = inner.substr(point + 1);
  if (micros_text.size() != 6) return bad;
  std::int64_t seconds = 0;
  for (const char c : seconds_text) {
    if (!is_digit(c)) return bad;
    seconds = seconds * 10 + (c - '0');
    if (seconds > kMaxTimestampSeconds) {
      return join({"timestamp ", quoted(token), " is too large (beyond the year 2262)"});
    }
  }
  std::int64_t micros = 0;
  for (const char c : micros_text) {
    if (!is_digit(c)) return bad;
    micros = micros * 10 + (c - '0');
  }
  timestamp_ns = seconds * kNsPerSecond + micros * kNsPerMicrosecond;
  return {};
}

// Hex bytes, optionally '.'-separated, from `text` into `data` (at most `max_length`); stops at
// '_' (a raw DLC suffix follows) or the end. "" or the reason.
std::string parse_data(std::string_view text, std::size_t max_length, std::uint8_t* data,
                       std::size_t& length, std::size_t& consumed) {
  length = 0;
  std::size_t digits = 0;
  std::size_t i = 0;
  while (i < text.size() && text[i] != '_') {
    const char c = text[i];
    if (c == '.' && digits % 2 == 0) {
      ++i;
      continue;
    }
    const int nibble = hex_value(c);
    if (nibble < 0) {
      if (c == '.') return "separator '.' inside a byte of the data";
      return join({"'", std::string_view(&c, 1), "' in the data is not a hex digit"});
    }
    if (digits % 2 == 0) {
      if (length < max_length) data[length] = static_cast<std::uint8_t>(nibble << 4);
    } else {
      if (length < max_length) data[length] = static_cast<std::uint8_t>(data[length] | nibble);
      ++length;
    }
    ++digits;
    ++i;
  }
  consumed = i;
  if (digits % 2 != 0) return "odd number of hex digits in the data (a truncated byte)";
  if (length > max_length) {
    return join(
        {std::to_string(length), " data bytes, at most ", std::to_string(max_length),
         max_length == kMaxClassicLength ? " fit a classic CAN frame" : " fit a CAN FD frame"});
  }
  return {};
}

// The identifier before '#': 3 hex digits (standard) or 8 (extended, or an error frame with
// CAN_ERR_FLAG). Sets out.id, out.extended and `error_frame`; "" or the reason.
std::string parse_identifier(std::string_view id_text, CandumpLine& out, bool& error_frame) {
  if (id_text.size() != 3 && id_text.size() != 8) {
    return join(
        {"identifier ", quoted(id_text), " must have 3 (standard) or 8 (extended) hex digits"});
  }
  std::uint32_t id = 0;
  for (const char c : id_text) {
    const int nibble = hex_value(c);
    if (nibble < 0) return join({"identifier ", quoted(id_text), " is not hexadecimal"});
    id = (id << 4) | static_cast<std::uint32_t>(nibble);
  }
  out.extended = id_text.size() == 8;
  if (!out.extended && id > kStandardIdMask) {
    return join({"standard identifier ", quoted(id_text), " is above 7FF"});
  }
  error_frame = false;
  if (out.extended && id > kExtendedIdMask) {
    if ((id & ~(kCanErrorFlag | kExtendedIdMask)) != 0) {
      return join({"extended identifier ", quoted(id_text), " is above 1FFFFFFF"});
    }
    error_frame = true;  // candump logs error frames with CAN_ERR_FLAG in the identifier
    id &= kExtendedIdMask;
  }
  out.id = id;
  return {};
}

// A remote request after "R": an optional DLC; "" or the reason.
std::string parse_remote(std::string_view rest, const std::string& in_frame, CandumpLine& out) {
  out.kind = CandumpFrameKind::kRemote;
  if (!rest.empty()) {
    const int dlc = hex_value(rest.front());
    if (dlc < 0 || static_cast<std::size_t>(dlc) > kMaxClassicLength) {
      return join({"remote request length ", quoted(rest), " is not 0-8", in_frame});
    }
    out.length = static_cast<std::uint8_t>(dlc);
    rest.remove_prefix(1);
  }
  if (!rest.empty()) {
    return join({"unexpected ", quoted(rest), " after the remote request", in_frame});
  }
  return {};
}

// The frame after the interface name: "<id>#<data>", "<id>#R[dlc]", "<id>##<flags><data>".
std::string parse_frame(std::string_view token, CandumpLine& out) {
  const std::size_t hash = token.find('#');
  if (hash == std::string_view::npos) {
    return join({"frame ", quoted(token), " has no '#' between identifier and data"});
  }
  bool error_frame = false;
  std::string problem = parse_identifier(token.substr(0, hash), out, error_frame);
  if (!problem.empty()) return problem;
  std::string_view rest = token.substr(hash + 1);
  const std::string in_frame = join({" in frame ", quoted(token)});
  if (!rest.empty() && (rest.front() == 'R' || rest.front() == 'r')) {
    return parse_remote(rest.substr(1), in_frame, out);
  }

  std::size_t max_length = kMaxClassicLength;
  if (!rest.empty() && rest.front() == '#') {
    out.kind = CandumpFrameKind::kFd;
    max_length = kCandumpMaxFdLength;
    if (rest.size() < 2 || hex_value(rest[1]) < 0) {
      return join({"CAN FD frame needs a flags hex digit after '##'", in_frame});
    }
    out.fd_flags = static_cast<std::uint8_t>(hex_value(rest[1]));
    rest.remove_prefix(2);
  } else if (error_frame) {
    out.kind = CandumpFrameKind::kErrorFrame;
  } else {
    out.kind = out.extended ? CandumpFrameKind::kExtended : CandumpFrameKind::kClassic;
  }
  std::size_t length = 0;
  std::size_t consumed = 0;
  problem = parse_data(rest, max_length, out.data.data(), length, consumed);
  if (!problem.empty()) return join({problem, in_frame});
  out.length = static_cast<std::uint8_t>(length);
  rest.remove_prefix(consumed);
  if (!rest.empty()) {
    // "_<dlc>": a classic 8-byte frame whose DLC on the wire is 9..15.
    const int dlc = rest.size() == 2 ? hex_value(rest[1]) : -1;
    if (out.kind == CandumpFrameKind::kFd || length != kMaxClassicLength || dlc <= 8) {
      return join({"unexpected ", quoted(rest),
                   " after the data (a raw DLC suffix is _9.._F after 8 bytes)", in_frame});
    }
    out.raw_dlc = static_cast<std::uint8_t>(dlc);
  }
  return {};
}

// candump -d's report of frames its socket lost (candump.c, "check for (unlikely) dropped
// frames"): "DROPCOUNT: dropped %u CAN frame%s on '%s' socket (total drops %u)".
constexpr std::string_view kDropTag = "DROPCOUNT:";
constexpr std::string_view kDropCountHead = "DROPCOUNT: dropped ";
constexpr std::string_view kDropFrames = " CAN frame";
constexpr std::string_view kDropSocket = " on '";
constexpr std::string_view kDropTotal = "' socket (total drops ";
constexpr std::uint64_t kMaxDropCounter = 0xFFFFFFFF;  // candump's counters are 32-bit

bool take_prefix(std::string_view& rest, std::string_view prefix) {
  if (rest.substr(0, prefix.size()) != prefix) return false;
  rest.remove_prefix(prefix.size());
  return true;
}

// A decimal number from `least` to 2^32 - 1 (candump prints its counters with %u; before
// can-utils 2023.03 with %d, so a count past 2^31 came out negative). "" or the reason.
std::string parse_drop_counter(std::string_view text, std::string_view what, std::uint64_t least,
                               std::uint32_t& out) {
  std::uint64_t value = 0;
  bool digits = !text.empty() && text.size() <= 10;
  for (const char c : text) {
    digits = digits && is_digit(c);
    if (digits) value = value * 10 + static_cast<std::uint64_t>(c - '0');
  }
  if (!digits || value < least || value > kMaxDropCounter) {
    return join({"DROPCOUNT line: ", what, " ", quoted(text), " is not a number of frames from ",
                 std::to_string(least), " to ", std::to_string(kMaxDropCounter)});
  }
  out = static_cast<std::uint32_t>(value);
  return {};
}

// "DROPCOUNT: dropped N CAN frame[s] on 'SOCKET' socket (total drops T)"; "" or the reason.
std::string parse_drop_count(std::string_view line, CandumpLine& out) {
  const std::string shape =
      join({"expected a DROPCOUNT line as candump -d writes it, 'DROPCOUNT: dropped N CAN frames "
            "on 'vcan0' socket (total drops T)', got ",
            quoted(line)});
  std::string_view rest = line;
  if (!take_prefix(rest, kDropCountHead)) return shape;
  const std::size_t count_end = rest.find(' ');
  if (count_end == std::string_view::npos) return shape;
  const std::string_view count = rest.substr(0, count_end);
  rest.remove_prefix(count_end);
  if (!take_prefix(rest, kDropFrames)) return shape;
  take_prefix(rest, "s");  // "frame" for 1, else "frames"
  if (!take_prefix(rest, kDropSocket)) return shape;
  const std::size_t name_end = rest.find(kDropTotal);
  if (name_end == std::string_view::npos || name_end == 0) return shape;
  const std::string_view socket_name = rest.substr(0, name_end);
  // A quote in the name leaves the line two readings (the fuzzer's "on 'a' socket (t' socket
  // (total drops 1)"); format_candump_drop_line writes none either.
  if (socket_name.find('\'') != std::string_view::npos) {
    return join({"DROPCOUNT line: the socket name ", quoted(socket_name),
                 " holds a quote: it cannot be read back unambiguously"});
  }
  rest.remove_prefix(name_end + kDropTotal.size());
  if (rest.empty() || rest.back() != ')') return shape;
  const std::string_view total = rest.substr(0, rest.size() - 1);
  std::string problem = parse_drop_counter(count, "the count", 1, out.dropped_frames);
  if (!problem.empty()) return problem;
  problem = parse_drop_counter(total, "the total", 0, out.total_dropped_frames);
  if (!problem.empty()) return problem;
  out.interface_name = std::string(socket_name);
  out.kind = CandumpFrameKind::kDropCount;
  return {};
}

std::string frames_text(std::uint64_t count) {
  return std::to_string(count) + (count == 1 ? " CAN frame" : " CAN frames");
}

}  // namespace

std::string format_candump_drop_line(std::uint32_t dropped_frames, std::string_view socket_name,
                                     std::uint32_t total_dropped_frames) {
  if (dropped_frames == 0 || socket_name.empty() ||
      socket_name.find_first_of("'\r\n") != std::string_view::npos) {
    return {};
  }
  return join({kDropCountHead, frames_text(dropped_frames), kDropSocket, socket_name,
               kDropTotal, std::to_string(total_dropped_frames), ")"});
}

std::string describe_candump_drop(const CandumpLine& line) {
  return join({"candump lost ", frames_text(line.dropped_frames), " on '", line.interface_name,
               "' before this line (its socket overflowed; ",
               std::to_string(line.total_dropped_frames), " in all so far)"});
}

std::string parse_candump_line(std::string_view line, CandumpLine& out) {
  out = CandumpLine{};
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  std::string_view rest = line;
  const std::string_view timestamp = next_token(rest);
  if (timestamp.empty() || timestamp.front() == '#') return {};  // blank or comment
  if (timestamp == kDropTag) {
    while (!line.empty() && is_blank(line.front())) line.remove_prefix(1);
    return parse_drop_count(line, out);
  }
  if (timestamp.front() != '(') {
    return join({"expected a line '(seconds.microseconds) interface id#data', got ", quoted(line)});
  }
  const std::size_t close = timestamp.find(')');
  if (close != std::string_view::npos && close + 1 < timestamp.size()) {
    return join({"no space after the timestamp ", quoted(timestamp.substr(0, close + 1)),
                 " in ", quoted(line)});
  }
  std::string problem = parse_timestamp(timestamp, out.timestamp_ns);
  if (!problem.empty()) return problem;
  const std::string_view interface_name = next_token(rest);
  if (interface_name.empty()) return "missing the interface name after the timestamp";
  // "(t) 301#00": the frame where the interface name belongs (a '#' in the next token, if any,
  // says that one is the frame and this an odd interface name).
  if (interface_name.find('#') != std::string_view::npos &&
      std::string_view(rest).find('#') == std::string_view::npos) {
    return join({"no interface name between the timestamp and the frame ",
                 quoted(interface_name), " (candump -l writes '(seconds) interface id#data')"});
  }
  if (interface_name.size() > kCandumpMaxInterfaceLength) {
    return join({"interface name ", quoted(interface_name), " is longer than 15 characters"});
  }
  out.interface_name = std::string(interface_name);
  const std::string_view frame = next_token(rest);
  if (frame.empty()) return "missing the frame (id#data) after the interface name";
  problem = parse_frame(frame, out);
  if (!problem.empty()) {
    out.kind = CandumpFrameKind::kComment;
    return problem;
  }
  // Newer candump (-x) and asc2log add the direction: R (received) or T (transmitted).
  const std::string_view direction = next_token(rest);
  if (!direction.empty() && direction != "R" && direction != "T") {
    out.kind = CandumpFrameKind::kComment;
    return join({"unexpected ", quoted(direction), " after the frame (only R or T may follow)"});
  }
  if (!next_token(rest).empty()) {
    out.kind = CandumpFrameKind::kComment;
    return "unexpected text after the frame";
  }
  return {};
}

std::string format_candump_line(std::int64_t timestamp_ns, std::string_view interface_name,
                                const can::CanFrame& frame) {
  if (interface_name.size() > kCandumpMaxInterfaceLength) return {};
  char name[kCandumpMaxInterfaceLength + 1] = {};
  interface_name.copy(name, interface_name.size());
  char line[kCandumpLineCapacity];
  const std::size_t length = format_candump_line(line, sizeof line, timestamp_ns, name, frame);
  return std::string(line, length);
}

CandumpLogReaderOpenResult CandumpLogReader::open(std::string path) {
  CandumpLogReaderOpenResult result;
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  const char* why = !std::filesystem::exists(status)        ? " (no such file)"
                    : std::filesystem::is_directory(status) ? " (it is a directory)"
                    : !std::filesystem::is_regular_file(status)
                        ? " (not a regular file: a FIFO, socket or device)"
                        : "";
  std::ifstream in;
  if (*why == '\0') in.open(path);
  if (*why != '\0' || !in) {
    result.message = path + ": cannot open file" + why;
    return result;
  }
  result.reader.emplace(CandumpLogReader(std::move(path), std::move(in)));
  return result;
}

CandumpLogReader::CandumpLogReader(std::string path, std::ifstream in)
    : path_(std::move(path)), in_(std::move(in)) {}

// The next line into text_, at most kCandumpMaxLineBytes + 1 of it (more means too long).
bool CandumpLogReader::read_line() {
  text_.clear();
  std::streambuf* buffer = in_.rdbuf();
  for (;;) {
    const int c = buffer->sbumpc();
    if (c == std::char_traits<char>::eof()) {
      if (text_.empty()) {
        in_.setstate(std::ios::eofbit);
        return false;
      }
      return true;
    }
    if (c == '\n') return true;
    text_.push_back(static_cast<char>(c));
    if (text_.size() > kCandumpMaxLineBytes) return true;
  }
}

IoStatus CandumpLogReader::receive(TimedFrame& out, int /*timeout_ms*/) {
  error_.clear();
  if (ended_) return IoStatus::kEndOfInput;
  while (read_line()) {
    ++line_number_;
    if (text_.size() > kCandumpMaxLineBytes) {
      ended_ = true;
      error_ = join({path_, ":", std::to_string(line_number_), ": line longer than ",
                     std::to_string(kCandumpMaxLineBytes), " bytes: not a candump log"});
      return IoStatus::kIoError;
    }
    const std::string problem = parse_candump_line(text_, line_);
    if (!problem.empty()) {
      error_ = join({path_, ":", std::to_string(line_number_), ": ", problem});
      return IoStatus::kIoError;
    }
    if (line_.kind == CandumpFrameKind::kComment) continue;
    out = TimedFrame{};
    out.timestamp_ns = line_.timestamp_ns;
    switch (line_.kind) {
      case CandumpFrameKind::kClassic:
        if (line_.raw_dlc != 0) return IoStatus::kNotPlinth;  // plinth frames have DLC 8
        out.frame.id = line_.id;
        out.frame.length = line_.length;
        for (std::size_t i = 0; i < line_.length; ++i) out.frame.data[i] = line_.data[i];
        return IoStatus::kOk;
      case CandumpFrameKind::kErrorFrame: return IoStatus::kBusError;
      case CandumpFrameKind::kDropCount:
        total_dropped_frames_ += line_.dropped_frames;
        return IoStatus::kOverflow;
      default: return IoStatus::kNotPlinth;
    }
  }
  if (in_.bad()) {
    ended_ = true;
    error_ = join({path_, ":", std::to_string(line_number_ + 1), ": read error"});
    return IoStatus::kIoError;
  }
  return IoStatus::kEndOfInput;
}

CandumpLogWriterOpenResult CandumpLogWriter::open(std::string path, std::string interface_name,
                                                  Clock clock) {
  CandumpLogWriterOpenResult result;
  bool has_blank = false;
  for (const char c : interface_name) has_blank = has_blank || is_blank(c) || c == '\n';
  if (interface_name.empty() || interface_name.size() > kCandumpMaxInterfaceLength || has_blank) {
    result.message =
        join({"log interface name ", (quoted)(interface_name),  // not std::quoted (ADL)
              ": must be 1 to 15 characters without spaces"});
    return result;
  }
  std::ofstream out(path, std::ios::out | std::ios::trunc);
  if (!out) {
    result.message = path + ": cannot open the log for writing";
    return result;
  }
  result.writer.emplace(CandumpLogWriter(std::move(path), std::move(interface_name),
                                         std::move(clock), std::move(out)));
  return result;
}

CandumpLogWriter::CandumpLogWriter(std::string path, std::string interface_name, Clock clock,
                                   std::ofstream out)
    : path_(std::move(path)),
      interface_name_(std::move(interface_name)),
      clock_(std::move(clock)),
      out_(std::move(out)) {}

IoStatus CandumpLogWriter::send(const can::CanFrame& frame) {
  if (frame.id > kStandardIdMask || frame.length > kMaxClassicLength) {
    error_ = join({path_, ": cannot log a frame with identifier ", std::to_string(frame.id),
                   " and length ", std::to_string(frame.length),
                   " (classic, standard identifiers only)"});
    return IoStatus::kIoError;
  }
  const std::int64_t timestamp_ns = clock_();
  if (timestamp_ns < 0) {
    error_ = join({path_, ": negative timestamp ", std::to_string(timestamp_ns), " ns"});
    return IoStatus::kIoError;
  }
  out_ << format_candump_line(timestamp_ns, interface_name_, frame) << '\n';
  if (!out_) {
    error_ = path_ + ": write failed";
    return IoStatus::kIoError;
  }
  return IoStatus::kOk;
}

bool CandumpLogWriter::flush() {
  if (!out_.flush()) {
    error_ = path_ + ": write failed";
    return false;
  }
  return true;
}

namespace {

// "1700000000.250000": a log's timestamp as candump writes it.
std::string log_time_text(std::int64_t t_ns) {
  char text[40];
  const std::int64_t us = t_ns / 1000;
  std::snprintf(text, sizeof text, "%s%lld.%06lld", us < 0 ? "-" : "",
                static_cast<long long>((us < 0 ? -us : us) / 1'000'000),
                static_cast<long long>((us < 0 ? -us : us) % 1'000'000));
  return text;
}

// "0.250000 s": a step between timestamps, microseconds.
std::string log_step_text(std::int64_t step_ns) {
  return log_time_text(step_ns < 0 ? -step_ns : step_ns) + " s";
}

}  // namespace

LogTimeCheck::LogTimeCheck() { last_ns_by_id_.fill(-1); }

LogTimeStep LogTimeCheck::check(std::int64_t t_ns, std::uint32_t id) const {
  if (!started_) return {};
  const std::int64_t step = t_ns - previous_ns_;
  if (step < 0) return {LogTimeProblem::kWentBack, step};
  if (t_ns == last_ns_by_id_[id & kStandardIdMask]) return {LogTimeProblem::kStoodStill, step};
  if (static_cast<double>(step) > kMaxLogGapS * 1e9) return {LogTimeProblem::kJumped, step};
  return {LogTimeProblem::kNone, step};
}

void LogTimeCheck::take(std::int64_t t_ns, std::uint32_t id) {
  started_ = true;
  previous_ns_ = t_ns;
  last_ns_by_id_[id & kStandardIdMask] = t_ns;
}

std::string LogTimeCheck::describe(const LogTimeStep& step, std::int64_t t_ns) const {
  switch (step.problem) {
    case LogTimeProblem::kNone:
      return "";
    case LogTimeProblem::kWentBack:
      return "timestamp goes back by " + log_step_text(step.step_ns) + " (" + log_time_text(t_ns) +
             " after " + log_time_text(previous_ns_) + ")";
    case LogTimeProblem::kStoodStill:
      return "timestamp stands still (" + log_time_text(t_ns) +
             ", the previous frame's of this identifier)";
    case LogTimeProblem::kJumped: {
      char limit[32];
      std::snprintf(limit, sizeof limit, "%g", kMaxLogGapS);
      return "timestamp jumps forward by " + log_step_text(step.step_ns) + " (" +
             log_time_text(t_ns) + " after " + log_time_text(previous_ns_) + "; more than the " +
             limit + " s a log's frames may be apart)";
    }
  }
  return "";
}

}  // namespace plinth::hal
