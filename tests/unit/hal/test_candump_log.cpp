// The candump log reader and writer: golden lines as can-utils writes and reads them, every
// malformed case, the FrameSource / FrameSink behaviour, a write-read round trip, and a round
// trip through can-utils' own log2asc / asc2log when they are installed.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "plinth/hal/candump_log.h"

namespace plinth::hal {
namespace {

namespace fs = std::filesystem;

// Text parts joined (GCC 12 warns falsely on `"literal" + std::string` at -O3).
std::string join(std::initializer_list<std::string_view> parts) {
  std::string out;
  for (const std::string_view part : parts) out += part;
  return out;
}

// The reader of `path`, which must open (a test that cannot open it fails).
CandumpLogReader reader_of(const std::string& path) {
  CandumpLogReaderOpenResult opened = CandumpLogReader::open(path);
  if (!opened.ok()) throw std::runtime_error(opened.message);
  return std::move(*opened.reader);
}

CandumpLogWriter writer_of(const std::string& path, const std::string& interface_name,
                           CandumpLogWriter::Clock clock) {
  CandumpLogWriterOpenResult opened =
      CandumpLogWriter::open(path, interface_name, std::move(clock));
  if (!opened.ok()) throw std::runtime_error(opened.message);
  return std::move(*opened.writer);
}

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            join({"plinth-candump-", info->name(), "-", std::to_string(::getpid())});
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  [[nodiscard]] std::string file(const std::string& name) const { return (path_ / name).string(); }
  [[nodiscard]] std::string write(const std::string& name, const std::string& text) const {
    const std::string path = file(name);
    std::ofstream(path) << text;
    return path;
  }

 private:
  fs::path path_;
};

CandumpLine parse_ok(const std::string& text) {
  CandumpLine line;
  const std::string problem = parse_candump_line(text, line);
  EXPECT_EQ(problem, "") << "line: " << text;
  return line;
}

// The reason a malformed line is refused ("" if it is not).
std::string problem_of(const std::string& text) {
  CandumpLine line;
  return parse_candump_line(text, line);
}

can::CanFrame frame_of(std::uint32_t id, std::vector<std::uint8_t> bytes) {
  can::CanFrame frame;
  frame.id = id;
  frame.length = static_cast<std::uint8_t>(bytes.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) frame.data[i] = bytes[i];
  return frame;
}

void expect_same_frame(const can::CanFrame& actual, const can::CanFrame& expected) {
  EXPECT_EQ(actual.id, expected.id);
  ASSERT_EQ(actual.length, expected.length);
  for (std::size_t i = 0; i < expected.length; ++i)
    EXPECT_EQ(actual.data[i], expected.data[i]) << i;
}

// ---------------------------------------------------------------------------------------------
// Golden lines

TEST(CandumpLine, ClassicFrameAsCandumpWritesIt) {
  const CandumpLine line = parse_ok("(1700000000.123456) vcan0 301#0011223344556677");
  EXPECT_EQ(line.kind, CandumpFrameKind::kClassic);
  EXPECT_EQ(line.timestamp_ns, 1'700'000'000'123'456'000);
  EXPECT_EQ(line.interface_name, "vcan0");
  EXPECT_EQ(line.id, 0x301U);
  EXPECT_FALSE(line.extended);
  ASSERT_EQ(line.length, 8);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(line.data[i], 0x11 * i);
  EXPECT_EQ(line.raw_dlc, 0);
}

TEST(CandumpLine, ZeroPaddedSecondsAsCandumpPrintsThem) {
  // candump -l prints "(%010lu.%06lu)".
  const CandumpLine line = parse_ok("(0000000012.000345) can0 123#DEADBEEF");
  EXPECT_EQ(line.timestamp_ns, 12'000'345'000);
  EXPECT_EQ(line.length, 4);
  EXPECT_EQ(line.data[0], 0xDE);
  EXPECT_EQ(line.data[3], 0xEF);
}

TEST(CandumpLine, LowerAndMixedCaseHex) {
  const CandumpLine lower = parse_ok("(1.000000) vcan0 7ff#aabbccddeeff0a0b");
  EXPECT_EQ(lower.id, 0x7FFU);
  EXPECT_EQ(lower.data[0], 0xAA);
  EXPECT_EQ(lower.data[7], 0x0B);
  const CandumpLine mixed = parse_ok("(1.000000) vcan0 3aB#aB");
  EXPECT_EQ(mixed.id, 0x3ABU);
  EXPECT_EQ(mixed.data[0], 0xAB);
}

TEST(CandumpLine, FewerThanEightBytesAndNone) {
  EXPECT_EQ(parse_ok("(1.000000) vcan0 123#0102").length, 2);
  const CandumpLine empty = parse_ok("(1.000000) vcan0 123#");
  EXPECT_EQ(empty.kind, CandumpFrameKind::kClassic);
  EXPECT_EQ(empty.length, 0);
}

TEST(CandumpLine, DotSeparatedBytesAsCansendAccepts) {
  const CandumpLine line = parse_ok("(1.000000) vcan0 123#01.02.03");
  ASSERT_EQ(line.length, 3);
  EXPECT_EQ(line.data[2], 0x03);
}

TEST(CandumpLine, RemoteRequests) {
  const CandumpLine plain = parse_ok("(1.000000) vcan0 123#R");
  EXPECT_EQ(plain.kind, CandumpFrameKind::kRemote);
  EXPECT_EQ(plain.length, 0);
  EXPECT_EQ(parse_ok("(1.000000) vcan0 123#r").kind, CandumpFrameKind::kRemote);
  EXPECT_EQ(parse_ok("(1.000000) vcan0 123#R5").length, 5);
  const CandumpLine extended = parse_ok("(1.000000) vcan0 12345678#R");
  EXPECT_EQ(extended.kind, CandumpFrameKind::kRemote);
  EXPECT_TRUE(extended.extended);
}

TEST(CandumpLine, ExtendedFrame) {
  const CandumpLine line = parse_ok("(1.000000) vcan0 12345678#00");
  EXPECT_EQ(line.kind, CandumpFrameKind::kExtended);
  EXPECT_TRUE(line.extended);
  EXPECT_EQ(line.id, 0x12345678U);
  // An 8-digit identifier is extended even when its value would fit 11 bits.
  EXPECT_EQ(parse_ok("(1.000000) vcan0 00000301#00").kind, CandumpFrameKind::kExtended);
}

TEST(CandumpLine, CanFdFrames) {
  const CandumpLine line = parse_ok("(1.000000) vcan0 123##1001122");
  EXPECT_EQ(line.kind, CandumpFrameKind::kFd);
  EXPECT_EQ(line.fd_flags, 1);
  ASSERT_EQ(line.length, 3);
  EXPECT_EQ(line.data[2], 0x22);
  const CandumpLine longest = parse_ok(join({"(1.000000) vcan0 123##0", std::string(128, 'A')}));
  EXPECT_EQ(longest.length, 64);
}

TEST(CandumpLine, ErrorFrame) {
  const CandumpLine line = parse_ok("(1.000000) vcan0 20000080#0000000000000000");
  EXPECT_EQ(line.kind, CandumpFrameKind::kErrorFrame);
  EXPECT_EQ(line.id, 0x80U);  // the error class, without CAN_ERR_FLAG
}

TEST(CandumpLine, RawDlcSuffix) {
  const CandumpLine line = parse_ok("(1.000000) vcan0 123#0011223344556677_9");
  EXPECT_EQ(line.kind, CandumpFrameKind::kClassic);
  EXPECT_EQ(line.length, 8);
  EXPECT_EQ(line.raw_dlc, 9);
}

TEST(CandumpLine, DirectionTokenAsAsc2logWritesIt) {
  EXPECT_EQ(parse_ok("(1.000000) can0 301#00 R").kind, CandumpFrameKind::kClassic);
  EXPECT_EQ(parse_ok("(1.000000) can0 301#00 T").kind, CandumpFrameKind::kClassic);
}

TEST(CandumpLine, CommentsBlankLinesAndCarriageReturns) {
  EXPECT_EQ(parse_ok("").kind, CandumpFrameKind::kComment);
  EXPECT_EQ(parse_ok("   ").kind, CandumpFrameKind::kComment);
  EXPECT_EQ(parse_ok("# recorded on the bench").kind, CandumpFrameKind::kComment);
  EXPECT_EQ(parse_ok("(1.000000) vcan0 301#00\r").length, 1);
  EXPECT_EQ(parse_ok("(1.000000)\tvcan0\t301#00").length, 1);
}

// ---------------------------------------------------------------------------------------------
// Malformed lines: each refused with a reason that says what is wrong.

struct Malformed {
  const char* line;
  const char* reason_contains;
};

TEST(CandumpLine, EveryMalformedCaseIsRefusedWithItsReason) {
  const Malformed cases[] = {
      {"(1.000000) vcan0 301#00112", "odd number of hex digits"},  // truncated hex
      {"(1.000000) vcan0 301#0", "odd number of hex digits"},
      {"(1.000000) vcan0 301#0011223344556677889", "odd number of hex digits"},
      {"(1.000000) vcan0 800#00", "above 7FF"},
      {"(1.000000) vcan0 FFF#00", "above 7FF"},
      {"(1.000000) vcan0 40000000#00", "above 1FFFFFFF"},
      {"(1.000000) vcan0 FFFFFFFF#00", "above 1FFFFFFF"},
      {"(1.000000) vcan0 3011#00", "3 (standard) or 8 (extended)"},
      {"(1.000000) vcan0 30#00", "3 (standard) or 8 (extended)"},
      {"(1.000000) vcan0 #00", "3 (standard) or 8 (extended)"},
      {"(1.000000) vcan0 3G1#00", "not hexadecimal"},
      {"(1.000000) vcan0 301#001122334455667788", "9 data bytes, at most 8"},
      {"(1.000000) vcan0 301#00GG", "'G' in the data is not a hex digit"},
      {"(1.000000) vcan0 301#0.0", "separator '.' inside a byte"},
      {"(1.000000) vcan0 301", "no '#'"},
      {"(1.000000) vcan0 123#R9", "remote request length"},
      {"(1.000000) vcan0 123#Rxx", "remote request length"},
      {"(1.000000) vcan0 123#R1x", "after the remote request"},
      {"(1.000000) vcan0 123##", "flags hex digit"},
      {"(1.000000) vcan0 123##G00", "flags hex digit"},
      {"(1.000000) vcan0 123#00_9", "raw DLC"},
      {"(1.000000) vcan0 123#0011223344556677_5", "raw DLC"},
      {"(1.000000) vcan0 123#0011223344556677_", "raw DLC"},
      {"(1700000000.12345) vcan0 301#00", "six decimals"},
      {"(1700000000.1234567) vcan0 301#00", "six decimals"},
      {"(1700000000) vcan0 301#00", "six decimals"},
      {"(.123456) vcan0 301#00", "six decimals"},
      {"(abc.123456) vcan0 301#00", "six decimals"},
      {"(nan) vcan0 301#00", "six decimals"},
      {"(NaN.000000) vcan0 301#00", "six decimals"},
      {"(1.00000x) vcan0 301#00", "six decimals"},
      {"(-1.000000) vcan0 301#00", "six decimals"},
      {"(+1.000000) vcan0 301#00", "six decimals"},
      {"(1e9.000000) vcan0 301#00", "six decimals"},
      {"(1700000000.123456 vcan0 301#00", "six decimals"},
      {"(99999999999.000000) vcan0 301#00", "too large"},
      {"1700000000.123456 vcan0 301#00", "expected a line"},
      {"NPTS=  12064, DT=   .0029 SEC", "expected a line"},
      {"(1.000000)", "missing the interface name"},
      {"(1.000000) vcan0", "missing the frame"},
      {"(1.000000) an_interface_name_far_too_long 301#00", "longer than 15"},
      // The frame where the interface belongs is said as such, whatever its length.
      {"(1.000000) 301#0011223344556677", "no interface name between the timestamp and the frame"},
      {"(1.000000) 1FFFFFFF#0011223344556677", "no interface name"},
      {"(1.000000) 301#00 R", "no interface name"},
      {"(1.000000)vcan0 301#00", "no space after the timestamp '(1.000000)'"},
      {"(1.000000) vcan0 301#00 X", "only R or T"},
      {"(1.000000) vcan0 301#00 R extra", "unexpected text after the frame"},
  };
  for (const Malformed& c : cases) {
    const std::string problem = problem_of(c.line);
    EXPECT_NE(problem.find(c.reason_contains), std::string::npos)
        << "line: " << c.line << "\nreason: " << problem;
  }
  // 65 bytes do not fit a CAN FD frame.
  EXPECT_NE(
      problem_of(join({"(1.000000) vcan0 123##0", std::string(130, '0')})).find("65 data bytes"),
      std::string::npos);
}

TEST(CandumpLine, GarbageBytesNeverCrash) {
  std::string garbage = "(1.000000) vcan0 301#";
  garbage += '\0';
  garbage += "\xff\x80";
  EXPECT_NE(problem_of(garbage), "");
  EXPECT_NE(problem_of(std::string("\0\0\0", 3)), "");
  EXPECT_NE(problem_of(join({"(1.000000) vcan0 ", std::string(100000, 'A'), "#00"})), "");
  EXPECT_NE(problem_of(join({"(1.000000) vcan0 301#", std::string(100001, 'A')})), "");
  EXPECT_NE(problem_of("((((((("), "");
  EXPECT_NE(problem_of("()"), "");
  EXPECT_NE(problem_of("(.)"), "");
}

TEST(CandumpLine, LongTokensAreQuotedShort) {
  const std::string problem = problem_of(join({"(1.000000) vcan0 ", std::string(500, 'A'), "#00"}));
  EXPECT_LT(problem.size(), 200U) << problem;
}

// ---------------------------------------------------------------------------------------------
// Formatting

TEST(CandumpFormat, AsCandumpWritesIt) {
  EXPECT_EQ(format_candump_line(1'700'000'000'123'456'789, "vcan0",
                                frame_of(0x301, {0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77})),
            "(1700000000.123456) vcan0 301#0011223344556677");
  EXPECT_EQ(format_candump_line(12'000'345'000, "can0", frame_of(0x7, {0xAB, 0xCD})),
            "(0000000012.000345) can0 007#ABCD");
  EXPECT_EQ(format_candump_line(0, "vcan0", frame_of(0x7FF, {})), "(0000000000.000000) vcan0 7FF#");
}

// ---------------------------------------------------------------------------------------------
// DROPCOUNT lines: candump -d's report of the frames its socket lost

TEST(CandumpDropCount, AsCandumpWritesIt) {
  // can-utils' candump.c: "DROPCOUNT: dropped %u CAN frame%s on '%s' socket (total drops %u)".
  const CandumpLine many =
      parse_ok("DROPCOUNT: dropped 410 CAN frames on 'vcan0' socket (total drops 410)");
  EXPECT_EQ(many.kind, CandumpFrameKind::kDropCount);
  EXPECT_EQ(many.dropped_frames, 410U);
  EXPECT_EQ(many.total_dropped_frames, 410U);
  EXPECT_EQ(many.interface_name, "vcan0");
  // One frame; candump before 2020.12 names the socket by its command-line argument, filters
  // and all; the largest 32-bit counts; a CR LF line end.
  const CandumpLine one = parse_ok(
      "DROPCOUNT: dropped 1 CAN frame on 'vcan0,300:C0000780' socket (total drops 4294967295)\r");
  EXPECT_EQ(one.kind, CandumpFrameKind::kDropCount);
  EXPECT_EQ(one.dropped_frames, 1U);
  EXPECT_EQ(one.total_dropped_frames, 4294967295U);
  EXPECT_EQ(one.interface_name, "vcan0,300:C0000780");
  EXPECT_EQ(parse_ok("DROPCOUNT: dropped 4294967295 CAN frames on 'any' socket (total drops 0)")
                .dropped_frames,
            4294967295U)
      << "a counter that wrapped: the total below the count";
}

TEST(CandumpDropCount, MalformedIsRefusedSayingWhatCandumpWrites) {
  const std::string shape = "expected a DROPCOUNT line as candump -d writes it, 'DROPCOUNT: "
                            "dropped N CAN frames on 'vcan0' socket (total drops T)', got '";
  for (const char* text : {
           "DROPCOUNT:",
           "DROPCOUNT: lost 3 frames",
           "DROPCOUNT: dropped 3 CAN frames",
           "DROPCOUNT: dropped 3 CAN frames on 'vcan0' socket",
           "DROPCOUNT: dropped 3 CAN frames on 'vcan0' socket (total drops 3",
           "DROPCOUNT: dropped 3 CAN frames on 'vcan0' socket (total drops 3) and more",
           "DROPCOUNT: dropped 3 CAN frames on '' socket (total drops 3)",
           "DROPCOUNT: dropped 3 frames on 'vcan0' socket (total drops 3)",
           "DROPCOUNT: dropped 3 CAN frames on vcan0 socket (total drops 3)",
       }) {
    const std::string problem = problem_of(text);
    EXPECT_EQ(problem.rfind(shape, 0), 0U) << text << " -> " << problem;
  }
  EXPECT_EQ(problem_of("DROPCOUNT: dropped 0 CAN frames on 'vcan0' socket (total drops 0)"),
            "DROPCOUNT line: the count '0' is not a number of frames from 1 to 4294967295");
  // candump before 2023.03 printed its counters with %d: past 2^31 they came out negative.
  EXPECT_EQ(problem_of("DROPCOUNT: dropped -5 CAN frames on 'vcan0' socket (total drops 12)"),
            "DROPCOUNT line: the count '-5' is not a number of frames from 1 to 4294967295");
  EXPECT_EQ(
      problem_of("DROPCOUNT: dropped 4294967296 CAN frames on 'vcan0' socket (total drops 1)"),
      "DROPCOUNT line: the count '4294967296' is not a number of frames from 1 to 4294967295");
  EXPECT_EQ(problem_of("DROPCOUNT: dropped 12a CAN frames on 'vcan0' socket (total drops 1)"),
            "DROPCOUNT line: the count '12a' is not a number of frames from 1 to 4294967295");
  EXPECT_EQ(problem_of("DROPCOUNT: dropped 2 CAN frames on 'vcan0' socket (total drops -1)"),
            "DROPCOUNT line: the total '-1' is not a number of frames from 0 to 4294967295");
  EXPECT_EQ(problem_of("DROPCOUNT: dropped 2 CAN frames on 'vcan0' socket (total drops )"),
            "DROPCOUNT line: the total '' is not a number of frames from 0 to 4294967295");
  // Found by fuzz_candump: a quote in the name, two readings of the line.
  EXPECT_EQ(problem_of("DROPCOUNT: dropped 410 CAN frames on 'vcan0' socket (tfra00780' socket "
                       "(total drops 411)"),
            "DROPCOUNT line: the socket name 'vcan0' socket (tfra00780' holds a quote: it cannot "
            "be read back unambiguously");
}

TEST(CandumpDropCount, WrittenAsCandumpWritesItAndReadBack) {
  const std::string line = format_candump_drop_line(410, "vcan0", 412);
  EXPECT_EQ(line, "DROPCOUNT: dropped 410 CAN frames on 'vcan0' socket (total drops 412)");
  EXPECT_EQ(format_candump_drop_line(1, "can0", 1),
            "DROPCOUNT: dropped 1 CAN frame on 'can0' socket (total drops 1)");
  const CandumpLine back = parse_ok(line);
  EXPECT_EQ(back.dropped_frames, 410U);
  EXPECT_EQ(back.total_dropped_frames, 412U);
  EXPECT_EQ(back.interface_name, "vcan0");
  EXPECT_EQ(format_candump_drop_line(0, "vcan0", 0), "") << "no frame lost: no line";
  EXPECT_EQ(format_candump_drop_line(1, "", 1), "");
  EXPECT_EQ(format_candump_drop_line(1, "it's", 1), "");
  EXPECT_EQ(describe_candump_drop(back),
            "candump lost 410 CAN frames on 'vcan0' before this line (its socket overflowed; 412 "
            "in all so far)");
  EXPECT_EQ(describe_candump_drop(parse_ok(format_candump_drop_line(1, "can0", 1))),
            "candump lost 1 CAN frame on 'can0' before this line (its socket overflowed; 1 in "
            "all so far)");
}

// ---------------------------------------------------------------------------------------------
// The reader as a FrameSource

TEST(CandumpLogReader, StatusPerLineAndEndOfInput) {
  TempDir dir;
  const std::string path = dir.write("mixed.log",
                                     "# a comment\n"
                                     "(1700000000.000000) vcan0 301#0011223344556677\n"
                                     "\n"
                                     "(1700000000.005000) vcan0 12345678#00\n"
                                     "(1700000000.006000) vcan0 123#R\n"
                                     "(1700000000.007000) vcan0 123##1001122\n"
                                     "(1700000000.008000) vcan0 20000004#0004000000000000\n"
                                     "(1700000000.009000) vcan0 301#0011223344556677_A\n"
                                     "(1700000000.010000) vcan0 123#0102\n");
  CandumpLogReader reader = reader_of(path);
  TimedFrame timed;
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  EXPECT_EQ(timed.timestamp_ns, 1'700'000'000'000'000'000);
  expect_same_frame(timed.frame, frame_of(0x301, {0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77}));
  EXPECT_EQ(reader.line_number(), 2U);
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kNotPlinth);  // extended
  EXPECT_EQ(timed.timestamp_ns, 1'700'000'000'005'000'000);
  EXPECT_EQ(reader.last_line().kind, CandumpFrameKind::kExtended);
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kNotPlinth);  // remote request
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kNotPlinth);  // CAN FD
  EXPECT_EQ(reader.last_line().kind, CandumpFrameKind::kFd);
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kBusError);   // error frame
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kNotPlinth);  // DLC 10 on the wire
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  expect_same_frame(timed.frame, frame_of(0x123, {0x01, 0x02}));
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
}

TEST(CandumpLogReader, MalformedLineNamesFileAndLineAndReadingGoesOn) {
  TempDir dir;
  const std::string path = dir.write("bad.log",
                                     "(1.000000) vcan0 301#00\n"
                                     "(1.000100) vcan0 301#00112\n"
                                     "(1.000200) vcan0 302#01\n");
  CandumpLogReader reader = reader_of(path);
  TimedFrame timed;
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kIoError);
  EXPECT_EQ(reader.error().rfind(path + ":2: ", 0), 0U) << reader.error();
  EXPECT_NE(reader.error().find("odd number of hex digits"), std::string::npos);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  EXPECT_EQ(timed.frame.id, 0x302U);
  EXPECT_EQ(reader.error(), "");
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
}

// A DROPCOUNT line is kOverflow with its count (frames lost before the next frame), line by
// line; the total runs on; a malformed one is an error naming the file and the line.
TEST(CandumpLogReader, DropCountIsAnOverflowWithItsLineAndCount) {
  TempDir dir;
  const std::string path =
      dir.write("drops.log",
                "(1.000000) vcan0 301#00\n"
                "DROPCOUNT: dropped 410 CAN frames on 'vcan0' socket (total drops 410)\n"
                "(1.100000) vcan0 301#01\n"
                "# a comment\n"
                "DROPCOUNT: dropped 1 CAN frame on 'vcan0' socket (total drops 411)\n"
                "(1.200000) vcan0 301#02\n"
                "DROPCOUNT: dropped some CAN frames on 'vcan0' socket (total drops 411)\n"
                "(1.300000) vcan0 301#03\n"
                "DROPCOUNT: dropped 7 CAN frames on 'vcan0' socket (total drops 418)\n");
  CandumpLogReader reader = reader_of(path);
  TimedFrame timed;
  EXPECT_EQ(reader.total_dropped_frames(), 0U);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOverflow);
  EXPECT_EQ(reader.line_number(), 2U);
  EXPECT_EQ(reader.dropped_frames(), 410U);
  EXPECT_EQ(reader.total_dropped_frames(), 410U);
  EXPECT_EQ(reader.last_line().interface_name, "vcan0");
  EXPECT_EQ(reader.last_line().kind, CandumpFrameKind::kDropCount);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  EXPECT_EQ(timed.frame.data[0], 0x01);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOverflow);
  EXPECT_EQ(reader.line_number(), 5U);
  EXPECT_EQ(reader.dropped_frames(), 1U);
  EXPECT_EQ(reader.total_dropped_frames(), 411U);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kIoError);
  EXPECT_EQ(reader.error(), path + ":7: DROPCOUNT line: the count 'some' is not a number of "
                                   "frames from 1 to 4294967295");
  EXPECT_EQ(reader.total_dropped_frames(), 411U) << "a malformed line counts nothing";
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  EXPECT_EQ(timed.frame.data[0], 0x03);
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOverflow) << "the last line: lost at the end";
  EXPECT_EQ(reader.line_number(), 9U);
  EXPECT_EQ(reader.total_dropped_frames(), 418U);
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
}

TEST(CandumpLogReader, EmptyFileEndsAtOnce) {
  TempDir dir;
  CandumpLogReader reader = reader_of(dir.write("empty.log", ""));
  TimedFrame timed;
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
}

TEST(CandumpLogReader, LastLineWithoutNewline) {
  TempDir dir;
  CandumpLogReader reader = reader_of(dir.write("no-newline.log", "(1.000000) vcan0 301#AB"));
  TimedFrame timed;
  ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk);
  EXPECT_EQ(timed.frame.data[0], 0xAB);
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
}

TEST(CandumpLogReader, MissingFileIsRefusedNamingIt) {
  const CandumpLogReaderOpenResult opened = CandumpLogReader::open("/nonexistent/dir/none.log");
  EXPECT_FALSE(opened.ok());
  EXPECT_NE(opened.message.find("/nonexistent/dir/none.log: cannot open"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// The writer as a FrameSink, and back

TEST(CandumpLogWriter, RoundTripWriteThenReadBackEquals) {
  TempDir dir;
  const std::string path = dir.file("round.log");
  std::vector<can::CanFrame> frames = {
      frame_of(0x301, {0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77}),
      frame_of(0x311, {0xFF, 0xFE, 0x01, 0x80, 0x7F, 0x00, 0xA5, 0x5A}),
      frame_of(0x000, {}),
      frame_of(0x7FF, {0xAB}),
      frame_of(0x340, {0x01, 0x02, 0x03}),
  };
  // Timestamps with sub-microsecond parts: the log keeps whole microseconds.
  std::vector<std::int64_t> stamps = {1'700'000'000'000'000'000, 1'700'000'000'005'000'999,
                                      1'700'000'001'000'000'000, 1'700'000'001'999'999'999, 5};
  std::size_t next = 0;
  {
    CandumpLogWriter writer = writer_of(path, "vcan0", [&] { return stamps[next]; });
    for (next = 0; next < frames.size(); ++next)
      ASSERT_EQ(writer.send(frames[next]), IoStatus::kOk);
    ASSERT_TRUE(writer.flush());
  }
  CandumpLogReader reader = reader_of(path);
  TimedFrame timed;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk) << reader.error();
    expect_same_frame(timed.frame, frames[i]);
    EXPECT_EQ(timed.timestamp_ns, stamps[i] / 1000 * 1000);
    EXPECT_EQ(reader.last_line().interface_name, "vcan0");
  }
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
}

TEST(CandumpLogWriter, InterfaceNameIsConfigurable) {
  TempDir dir;
  const std::string path = dir.file("can1.log");
  {
    CandumpLogWriter writer = writer_of(path, "can1", [] { return std::int64_t{1'000'000}; });
    ASSERT_EQ(writer.send(frame_of(0x301, {0x01})), IoStatus::kOk);
    ASSERT_TRUE(writer.flush());
  }
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "(0000000000.001000) can1 301#01");
}

TEST(CandumpLogWriter, RefusesWhatALogCannotHold) {
  TempDir dir;
  std::int64_t now = 0;
  CandumpLogWriter writer = writer_of(dir.file("refuse.log"), "vcan0", [&] { return now; });
  EXPECT_EQ(writer.send(frame_of(0x800, {0x00})), IoStatus::kIoError);
  EXPECT_NE(writer.error().find("standard identifiers only"), std::string::npos);
  can::CanFrame too_long = frame_of(0x301, {});
  too_long.length = 9;
  EXPECT_EQ(writer.send(too_long), IoStatus::kIoError);
  now = -1;
  EXPECT_EQ(writer.send(frame_of(0x301, {0x00})), IoStatus::kIoError);
  EXPECT_NE(writer.error().find("negative timestamp"), std::string::npos);
}

TEST(CandumpLogWriter, BadInterfaceNameOrPathIsRefused) {
  TempDir dir;
  const auto clock = [] { return std::int64_t{0}; };
  for (const char* name : {"", "has space", "sixteen_chars_xx"}) {
    const CandumpLogWriterOpenResult opened =
        CandumpLogWriter::open(dir.file("a.log"), name, clock);
    EXPECT_FALSE(opened.ok()) << name;
    EXPECT_NE(opened.message.find("must be 1 to 15 characters without spaces"), std::string::npos)
        << opened.message;
  }
  const CandumpLogWriterOpenResult opened =
      CandumpLogWriter::open("/nonexistent/dir/out.log", "vcan0", clock);
  EXPECT_FALSE(opened.ok());
  EXPECT_NE(opened.message.find("/nonexistent/dir/out.log"), std::string::npos);
}

TEST(CandumpLogWriter, WritesPlinthFramesAsEncoded) {
  TempDir dir;
  const std::string path = dir.file("plinth.log");
  can::SensorAcceleration sample;
  sample.node = 1;
  sample.ax_g = 0.5;
  sample.ay_g = -0.25;
  sample.az_g = 1.0;
  sample.sequence = 255;
  can::CanFrame frame;
  ASSERT_TRUE(can::encode(sample, frame).ok());
  {
    CandumpLogWriter writer =
        writer_of(path, "vcan0", [] { return std::int64_t{1'700'000'000'000'000'000}; });
    ASSERT_EQ(writer.send(frame), IoStatus::kOk);
  }
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  // 0.5 g = raw 2000 = 0x07D0, -0.25 g = -1000 = 0xFC18, 1 g = 4000 = 0x0FA0, little-endian.
  EXPECT_EQ(text, "(1700000000.000000) vcan0 301#D00718FCA00FFF00");
}

// ---------------------------------------------------------------------------------------------
// can-utils itself: our log through log2asc and back through asc2log must give the same frames
// at the same relative times (asc keeps times relative to the first frame, and channel 1 comes
// back as can0).

bool have_program(const std::string& path) { return ::access(path.c_str(), X_OK) == 0; }

TEST(CanUtilsCompatibility, Log2AscThenAsc2LogGivesTheSameFrames) {
  if (!have_program("/usr/bin/log2asc") || !have_program("/usr/bin/asc2log")) {
    GTEST_SKIP() << "can-utils not installed (sudo apt-get install can-utils)";
  }
  TempDir dir;
  const std::string ours = dir.file("ours.log");
  std::vector<can::CanFrame> frames = {
      frame_of(0x301, {0x00, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77}),
      frame_of(0x311, {0x05, 0x00, 0x00, 0x00, 0x10, 0x00, 0x00, 0x00}),
      frame_of(0x302, {0xFF, 0xFE}),
      frame_of(0x123, {}),
      frame_of(0x7FF, {0xDE, 0xAD, 0xBE, 0xEF}),
  };
  const std::int64_t start_ns = 1'700'000'000'000'000'000;
  const std::vector<std::int64_t> offsets_us = {0, 5'000, 5'001, 1'000'000, 2'345'678};
  std::size_t next = 0;
  {
    CandumpLogWriter writer =
        writer_of(ours, "vcan0", [&] { return start_ns + offsets_us[next] * 1000; });
    for (next = 0; next < frames.size(); ++next)
      ASSERT_EQ(writer.send(frames[next]), IoStatus::kOk);
  }
  const std::string asc = dir.file("ours.asc");
  const std::string back = dir.file("back.log");
  const std::string to_asc = "/usr/bin/log2asc -I '" + ours + "' -O '" + asc + "' vcan0";
  ASSERT_EQ(std::system(to_asc.c_str()), 0) << to_asc;
  const std::string to_log = "/usr/bin/asc2log -I '" + asc + "' -O '" + back + "' 2>/dev/null";
  ASSERT_EQ(std::system(to_log.c_str()), 0) << to_log;

  CandumpLogReader reader = reader_of(back);
  TimedFrame timed;
  std::int64_t first_ns = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    ASSERT_EQ(reader.receive(timed, 0), IoStatus::kOk) << "frame " << i << ": " << reader.error();
    if (i == 0) first_ns = timed.timestamp_ns;
    expect_same_frame(timed.frame, frames[i]);
    EXPECT_EQ((timed.timestamp_ns - first_ns) / 1000, offsets_us[i]) << "frame " << i;
  }
  EXPECT_EQ(reader.receive(timed, 0), IoStatus::kEndOfInput);
}

// The time of a log's frames (LogTimeCheck): back, standing still per identifier, a jump beyond
// kMaxLogGapS, each described with its size; the first frame has no previous one.
TEST(LogTime, NamesWhatIsWrongWithTheSize) {
  constexpr std::int64_t kS = 1'000'000'000;
  constexpr std::int64_t t0 = 1'700'000'000 * kS;
  LogTimeCheck check;
  EXPECT_EQ(check.check(t0, 0x301).problem, LogTimeProblem::kNone);
  check.take(t0, 0x301);
  EXPECT_EQ(check.check(t0 + 5'000'000, 0x301).problem, LogTimeProblem::kNone);
  EXPECT_EQ(check.check(t0, 0x302).problem, LogTimeProblem::kNone) << "another identifier";
  const LogTimeStep still = check.check(t0, 0x301);
  EXPECT_EQ(still.problem, LogTimeProblem::kStoodStill);
  EXPECT_EQ(check.describe(still, t0),
            "timestamp stands still (1700000000.000000, the previous frame's of this identifier)");
  const LogTimeStep back = check.check(t0 - 250'000'000, 0x302);
  EXPECT_EQ(back.problem, LogTimeProblem::kWentBack);
  EXPECT_EQ(back.step_ns, -250'000'000);
  EXPECT_EQ(check.describe(back, t0 - 250'000'000),
            "timestamp goes back by 0.250000 s (1699999999.750000 after 1700000000.000000)");
  const auto limit = static_cast<std::int64_t>(kMaxLogGapS * 1e9);
  EXPECT_EQ(check.check(t0 + limit, 0x302).problem, LogTimeProblem::kNone) << "at the limit";
  const LogTimeStep jump = check.check(t0 + 3600 * kS, 0x302);
  EXPECT_EQ(jump.problem, LogTimeProblem::kJumped);
  EXPECT_EQ(check.describe(jump, t0 + 3600 * kS),
            "timestamp jumps forward by 3600.000000 s (1700003600.000000 after "
            "1700000000.000000; more than the 10 s a log's frames may be apart)");
  EXPECT_EQ(check.describe({}, t0), "");
  check.take(t0 + 3600 * kS, 0x302);
  EXPECT_EQ(check.previous_ns(), t0 + 3600 * kS);
  EXPECT_EQ(check.check(t0 + 3600 * kS + 1000, 0x301).problem, LogTimeProblem::kNone);
}

}  // namespace
}  // namespace plinth::hal
