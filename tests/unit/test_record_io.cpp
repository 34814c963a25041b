// Accelerogram readers: the bundled PEER AT2 records, small CSV files, and every input error.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <functional>
#include <ostream>
#include <random>
#include <string>

#include "plinth/host/input_error.h"
#include "plinth/host/record_io.h"

namespace plinth::host {
namespace {

using ::testing::HasSubstr;

constexpr double kGravity = 9.80665;  // m/s2
const std::string kRecordsDir = PLINTH_SOURCE_DIR "/sim/data/records/";

// The message of the InputError thrown by read, or "" (and a failure) when none is thrown.
std::string input_error_message(const std::function<Record()>& read) {
  try {
    (void)read();
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return "";
}

// ---- bundled records ---------------------------------------------------------------------------

struct BundledRecord {
  const char* file;
  const char* name;  // header line 2
  std::size_t npts;
  double dt;           // s
  double pga;          // g, SOURCES.md table
  double time_of_pga;  // s, SOURCES.md table (2 decimals)
};

void PrintTo(const BundledRecord& record, std::ostream* out) { *out << record.file; }

class BundledRecordTest : public ::testing::TestWithParam<BundledRecord> {};

TEST_P(BundledRecordTest, MatchesSourcesTable) {
  const BundledRecord& expected = GetParam();
  const Record record = read_record(kRecordsDir + expected.file, kGravity);

  EXPECT_EQ(record.name, expected.name);
  ASSERT_EQ(record.horizontal.size(), expected.npts);
  EXPECT_DOUBLE_EQ(record.dt, expected.dt);
  EXPECT_TRUE(record.vertical.empty());
  EXPECT_NEAR(record.peak_horizontal() / kGravity, expected.pga, 1e-4);

  std::size_t peak_index = 0;
  for (std::size_t i = 0; i < record.horizontal.size(); ++i) {
    if (std::abs(record.horizontal[i]) > std::abs(record.horizontal[peak_index])) peak_index = i;
  }
  EXPECT_NEAR(static_cast<double>(peak_index) * record.dt, expected.time_of_pga, 0.005 + 1e-9);
  EXPECT_NEAR(record.duration(), static_cast<double>(expected.npts - 1) * expected.dt, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(
    SimDataRecords, BundledRecordTest,
    ::testing::Values(
        BundledRecord{"irpinia1980_calitri_000.AT2", "Irpinia Italy-01, 11/23/1980, Calitri, 0",
                      14672, 0.0024, 0.1264, 6.29},
        BundledRecord{"irpinia1980_calitri_270.AT2", "Irpinia Italy-01, 11/23/1980, Calitri, 270",
                      14672, 0.0024, 0.1364, 8.17},
        BundledRecord{"irpinia1980_brienza_000.AT2", "Irpinia Italy-01, 11/23/1980, Brienza, 0",
                      12064, 0.0029, 0.2196, 12.03},
        BundledRecord{"irpinia1980_brienza_270.AT2", "Irpinia Italy-01, 11/23/1980, Brienza, 270",
                      12064, 0.0029, 0.1827, 11.21},
        BundledRecord{"irpinia1980_bagnoli_000.AT2",
                      "Irpinia Italy-01, 11/23/1980, Bagnoli Irpinio, 0", 12712, 0.0029, 0.1297,
                      6.21},
        BundledRecord{"irpinia1980_bagnoli_270.AT2",
                      "Irpinia Italy-01, 11/23/1980, Bagnoli Irpinio, 270", 12712, 0.0029, 0.1897,
                      3.90},
        BundledRecord{"friuli1976-09-15_buia_000.AT2", "Friuli Italy-02, 9/15/1976, Buia, 0", 5286,
                      0.0050, 0.1103, 3.06},
        BundledRecord{"friuli1976-09-15_buia_270.AT2", "Friuli Italy-02, 9/15/1976, Buia, 270",
                      5286, 0.0050, 0.0936, 3.60},
        BundledRecord{"friuli1976-09-11_buia_NS.AT2", "Fruili Italy-03, 9/11/1976, Buia, NS", 7769,
                      0.00244, 0.0447, 1.82},
        BundledRecord{"elcentro1940_180.AT2",
                      "Imperial Valley-02, 5/19/1940, El Centro Array #9, 180", 5372, 0.0100,
                      0.2808, 2.18}),
    [](const ::testing::TestParamInfo<BundledRecord>& param_info) {
      std::string name = std::filesystem::path(param_info.param.file).stem().string();
      for (char& c : name) {
        if (std::isalnum(static_cast<unsigned char>(c)) == 0) c = '_';
      }
      return name;
    });

TEST(BundledRecords, BrienzaFirstAndLastValuesConvertFromG) {
  const Record record = read_at2(kRecordsDir + "irpinia1980_brienza_000.AT2", kGravity);
  ASSERT_EQ(record.horizontal.size(), 12064U);
  EXPECT_DOUBLE_EQ(record.horizontal.front(), -.3251592E-05 * kGravity);
  EXPECT_DOUBLE_EQ(record.horizontal.back(), .1152733E-04 * kGravity);
  EXPECT_NEAR(record.peak_horizontal(), 0.2196351 * kGravity, 1e-12);
}

TEST(BundledRecords, SecGluedToDtIsRead) {
  // Line 4 reads "NPTS=   7769, DT=   .00244SEC,   4 POLE @ ...".
  const Record record = read_at2(kRecordsDir + "friuli1976-09-11_buia_NS.AT2", kGravity);
  EXPECT_DOUBLE_EQ(record.dt, 0.00244);
  EXPECT_EQ(record.horizontal.size(), 7769U);
}

// ---- temporary files ---------------------------------------------------------------------------

// Each test gets its own directory under the system temp dir, removed afterwards.
class RecordFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::random_device random;
    dir_ = std::filesystem::temp_directory_path() /
           ("plinth_record_io_" + std::string(info->name()) + "_" + std::to_string(random()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  // Writes text to dir/name and returns the path.
  std::string write(const std::string& name, const std::string& text) const {
    const std::filesystem::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << text;
    return path.string();
  }

  std::filesystem::path dir_;
};

// ---- AT2 ---------------------------------------------------------------------------------------

const std::string kAt2Title = "PEER NGA STRONG MOTION DATABASE RECORD\n";
const std::string kAt2Event = "  Test Event, 1/2/2000, Station, 90   \n";
const std::string kAt2Units = "ACCELERATION TIME SERIES IN UNITS OF G\n";

std::string at2_text(const std::string& line4, const std::string& values) {
  return kAt2Title + kAt2Event + kAt2Units + line4 + "\n" + values;
}

const std::string kSevenValues =
    "   .1000000E-01  -.2000000E-01   .3000000E+00  -.4000000E-05   .5000000E-01\n"
    "  -.6000000E+00   .7000000E-01\n";

using At2Test = RecordFileTest;

TEST_F(At2Test, ReadsValuesNameAndDt) {
  const std::string path =
      write("ok.AT2", at2_text("NPTS=      7, DT=   .0100 SEC,", kSevenValues));
  const Record record = read_at2(path, 9.81);
  EXPECT_EQ(record.name, "Test Event, 1/2/2000, Station, 90");
  EXPECT_DOUBLE_EQ(record.dt, 0.01);
  ASSERT_EQ(record.horizontal.size(), 7U);
  EXPECT_DOUBLE_EQ(record.horizontal[0], 0.01 * 9.81);
  EXPECT_DOUBLE_EQ(record.horizontal[3], -4e-6 * 9.81);
  EXPECT_DOUBLE_EQ(record.horizontal[6], 0.07 * 9.81);
  EXPECT_DOUBLE_EQ(record.peak_horizontal(), 0.6 * 9.81);
  EXPECT_DOUBLE_EQ(record.duration(), 0.06);
}

TEST_F(At2Test, GluedSecAndExponentDt) {
  const std::string glued =
      write("glued.AT2", at2_text("NPTS=7, DT=   .00244SEC, 4 POLE", kSevenValues));
  EXPECT_DOUBLE_EQ(read_at2(glued, kGravity).dt, 0.00244);
  const std::string exponent = write("exp.AT2", at2_text("NPTS= 7 DT= 2.5E-03 SEC", kSevenValues));
  EXPECT_DOUBLE_EQ(read_at2(exponent, kGravity).dt, 0.0025);
}

TEST_F(At2Test, CrlfLineEndingsAreAccepted) {
  const std::string path =
      write("crlf.AT2",
            "TITLE\r\nEv, 1/1/2000, St, 0\r\nIN UNITS OF G\r\nNPTS= 2, DT= .01 SEC\r\n"
            "   .1E+00  -.2E+00\r\n");
  const Record record = read_at2(path, 1.0);
  EXPECT_EQ(record.name, "Ev, 1/1/2000, St, 0");
  ASSERT_EQ(record.horizontal.size(), 2U);
  EXPECT_DOUBLE_EQ(record.horizontal[1], -0.2);
}

TEST_F(At2Test, MissingFile) {
  const std::string path = (dir_ / "absent.AT2").string();
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("cannot open"));
}

TEST_F(At2Test, TruncatedHeader) {
  const std::string path = write("short.AT2", kAt2Title + kAt2Event);
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":3:"));
  EXPECT_THAT(message, HasSubstr("truncated header"));
}

TEST_F(At2Test, UnitsOtherThanG) {
  const std::string path =
      write("cms2.AT2", kAt2Title + kAt2Event + "ACCELERATION TIME SERIES IN UNITS OF CM/S/S\n" +
                            "NPTS= 7, DT= .01 SEC\n" + kSevenValues);
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":3:"));
  EXPECT_THAT(message, HasSubstr("units are 'CM/S/S'"));
}

TEST_F(At2Test, MissingNpts) {
  const std::string path = write("nonpts.AT2", at2_text("DT= .01 SEC", kSevenValues));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":4:"));
  EXPECT_THAT(message, HasSubstr("cannot find NPTS="));
}

TEST_F(At2Test, ZeroNpts) {
  const std::string path = write("zeronpts.AT2", at2_text("NPTS= 0, DT= .01 SEC", ""));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":4:"));
  EXPECT_THAT(message, HasSubstr("NPTS must be positive"));
}

TEST_F(At2Test, NegativeNptsIsNotFound) {
  const std::string path = write("negnpts.AT2", at2_text("NPTS= -7, DT= .01 SEC", kSevenValues));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":4:"));
  EXPECT_THAT(message, HasSubstr("cannot find NPTS="));
}

TEST_F(At2Test, MissingDt) {
  const std::string path = write("nodt.AT2", at2_text("NPTS= 7, SEC", kSevenValues));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":4:"));
  EXPECT_THAT(message, HasSubstr("cannot find DT="));
}

TEST_F(At2Test, ZeroDt) {
  const std::string path = write("zerodt.AT2", at2_text("NPTS= 7, DT= .0000 SEC", kSevenValues));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":4:"));
  EXPECT_THAT(message, HasSubstr("DT must be positive"));
}

TEST_F(At2Test, TokenThatIsNotANumber) {
  const std::string path = write("token.AT2", at2_text("NPTS= 7, DT= .01 SEC",
                                                       "   .1E+00 .2E+00 .3E+00 .4E+00 .5E+00\n"
                                                       "   .6E+00 .7E+00X\n"));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":6:"));
  EXPECT_THAT(message, HasSubstr("'.7E+00X' is not a number"));
}

TEST_F(At2Test, NanAndInfinityAreNotFinite) {
  for (const std::string bad : {"NaN", "-inf", "1E+999"}) {
    const std::string path =
        write("nan.AT2", at2_text("NPTS= 2, DT= .01 SEC", ".1E+00 " + bad + "\n"));
    const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
    EXPECT_THAT(message, HasSubstr(path + ":5:")) << bad;
    EXPECT_THAT(message, HasSubstr("'" + bad + "'")) << bad;
  }
  const std::string path = write("nan.AT2", at2_text("NPTS= 2, DT= .01 SEC", ".1E+00 nan\n"));
  EXPECT_THAT(input_error_message([&] { return read_at2(path, kGravity); }),
              HasSubstr("is not finite"));
}

TEST_F(At2Test, FewerValuesThanNpts) {
  const std::string path = write("few.AT2", at2_text("NPTS= 9, DT= .01 SEC", kSevenValues));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":6:"));
  EXPECT_THAT(message, HasSubstr("truncated data: found 7 values, NPTS=9"));
}

TEST_F(At2Test, MoreValuesThanNpts) {
  const std::string path = write("many.AT2", at2_text("NPTS= 6, DT= .01 SEC", kSevenValues));
  const std::string message = input_error_message([&] { return read_at2(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path + ":6:"));
  EXPECT_THAT(message, HasSubstr("more values than NPTS=6"));
}

// ---- CSV ---------------------------------------------------------------------------------------

using CsvTest = RecordFileTest;

TEST_F(CsvTest, GravityUnitsConvert) {
  const std::string path = write("g.csv", "t,a [g]\n0,0.1\n0.01,-0.25\n0.02,0\n");
  const Record record = read_csv_record(path, 9.81);
  EXPECT_EQ(record.name, "g");
  EXPECT_DOUBLE_EQ(record.dt, 0.01);
  ASSERT_EQ(record.horizontal.size(), 3U);
  EXPECT_DOUBLE_EQ(record.horizontal[0], 0.1 * 9.81);
  EXPECT_DOUBLE_EQ(record.horizontal[1], -0.25 * 9.81);
  EXPECT_DOUBLE_EQ(record.peak_horizontal(), 0.25 * 9.81);
  EXPECT_DOUBLE_EQ(record.duration(), 0.02);
  EXPECT_TRUE(record.vertical.empty());
  EXPECT_TRUE(record.vertical_signal().empty());
}

TEST_F(CsvTest, MetresPerSecondSquaredAreKept) {
  const std::string path = write("ms2.csv", "t [s],a [M/S2]\n0,1.5\n0.005,-2\n");
  const Record record = read_csv_record(path, kGravity);
  ASSERT_EQ(record.horizontal.size(), 2U);
  EXPECT_DOUBLE_EQ(record.horizontal[0], 1.5);
  EXPECT_DOUBLE_EQ(record.horizontal[1], -2.0);
  EXPECT_DOUBLE_EQ(record.dt, 0.005);
}

TEST_F(CsvTest, GalAndCentimetresPerSecondSquaredConvert) {
  for (const std::string unit : {"gal", "Gal", "cm/s2"}) {
    const std::string path = write("gal.csv", "t,a [" + unit + "]\n0,250\n0.02,-981\n");
    const Record record = read_csv_record(path, kGravity);
    ASSERT_EQ(record.horizontal.size(), 2U) << unit;
    EXPECT_DOUBLE_EQ(record.horizontal[0], 2.5) << unit;
    EXPECT_DOUBLE_EQ(record.horizontal[1], -9.81) << unit;
  }
}

TEST_F(CsvTest, VerticalColumn) {
  const std::string path = write("v.csv", "t,h [m/s2],v [g]\n0,1,0.5\n0.1,2,-0.5\n0.2,3,0\n");
  const Record record = read_csv_record(path, 10.0);
  ASSERT_EQ(record.vertical.size(), 3U);
  EXPECT_DOUBLE_EQ(record.vertical[0], 5.0);
  EXPECT_DOUBLE_EQ(record.vertical[1], -5.0);
  EXPECT_DOUBLE_EQ(record.horizontal[2], 3.0);

  const SampledSignal vertical = record.vertical_signal();
  EXPECT_EQ(vertical.count, 3U);
  EXPECT_DOUBLE_EQ(vertical.dt, 0.1);
  EXPECT_DOUBLE_EQ(vertical.at(0.05), 0.0);
  EXPECT_DOUBLE_EQ(vertical.at(0.15), -2.5);
  const SampledSignal horizontal = record.horizontal_signal();
  EXPECT_EQ(horizontal.values, record.horizontal.data());
  EXPECT_EQ(horizontal.count, 3U);
  EXPECT_DOUBLE_EQ(horizontal.at(0.05), 1.5);
}

TEST_F(CsvTest, CommentsBlankLinesAndSpacesAreSkipped) {
  const std::string path =
      write("comments.csv",
            "# recorded somewhere\n\n t , a [g] \n# first row\n0 , 1\n\n   \n0.5,2\n1.0,3\n");
  const Record record = read_csv_record(path, 1.0);
  ASSERT_EQ(record.horizontal.size(), 3U);
  EXPECT_DOUBLE_EQ(record.horizontal[2], 3.0);
  EXPECT_DOUBLE_EQ(record.dt, 0.5);
}

TEST_F(CsvTest, SmallTimingErrorsAreTolerated) {
  const std::string path = write("jitter.csv", "t,a [g]\n1e-10,0\n0.0100000001,0\n0.02,0\n");
  EXPECT_EQ(read_csv_record(path, 1.0).horizontal.size(), 3U);
}

// Reads text as CSV and returns the InputError message (and the path through path_out).
class CsvErrorTest : public RecordFileTest {
 protected:
  std::string error_for(const std::string& text) {
    path_ = write("bad.csv", text);
    return input_error_message([&] { return read_csv_record(path_, kGravity); });
  }
  std::string path_;
};

TEST_F(CsvErrorTest, MissingUnit) {
  const std::string message = error_for("t,a\n0,1\n0.1,2\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":1:"));
  EXPECT_THAT(message, HasSubstr("missing unit"));
}

TEST_F(CsvErrorTest, UnknownUnit) {
  const std::string message = error_for("# c\nt,a [ft/s2]\n0,1\n0.1,2\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":2:"));
  EXPECT_THAT(message, HasSubstr("unknown unit 'ft/s2'"));
}

TEST_F(CsvErrorTest, UnknownVerticalUnit) {
  const std::string message = error_for("t,a [g],v [km]\n0,1,1\n0.1,2,2\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":1:"));
  EXPECT_THAT(message, HasSubstr("unknown unit 'km'"));
}

TEST_F(CsvErrorTest, WrongNumberOfColumns) {
  const std::string message = error_for("t,a [g]\n0,1\n0.1,2,3\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":3:"));
  EXPECT_THAT(message, HasSubstr("expected 2 columns, found 3"));
}

TEST_F(CsvErrorTest, NonNumericValue) {
  const std::string message = error_for("t,a [g]\n0,1\n0.1,abc\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":3:"));
  EXPECT_THAT(message, HasSubstr("'abc' is not a number"));
}

TEST_F(CsvErrorTest, NonFiniteValue) {
  const std::string message = error_for("t,a [g]\n0,1\n0.1,inf\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":3:"));
  EXPECT_THAT(message, HasSubstr("not finite"));
}

TEST_F(CsvErrorTest, NonUniformTimeStep) {
  const std::string message = error_for("t,a [g]\n0,1\n0.1,2\n0.2,3\n0.31,4\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":5:"));
  EXPECT_THAT(message, HasSubstr("non-uniform time step"));
}

TEST_F(CsvErrorTest, DecreasingTime) {
  const std::string message = error_for("t,a [g]\n0,1\n-0.1,2\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":3:"));
  EXPECT_THAT(message, HasSubstr("time step must be positive"));
}

TEST_F(CsvErrorTest, TimeNotStartingAtZero) {
  const std::string message = error_for("t,a [g]\n0.01,1\n0.02,2\n");
  EXPECT_THAT(message, HasSubstr(path_ + ":2:"));
  EXPECT_THAT(message, HasSubstr("time must start at 0"));
}

TEST_F(CsvErrorTest, NoDataRows) {
  const std::string message = error_for("t,a [g]\n# nothing\n");
  EXPECT_THAT(message, HasSubstr(path_));
  EXPECT_THAT(message, HasSubstr("no data rows"));
}

TEST_F(CsvErrorTest, OneDataRow) {
  const std::string message = error_for("t,a [g]\n0,1\n");
  EXPECT_THAT(message, HasSubstr(path_));
  EXPECT_THAT(message, HasSubstr("at least 2 data rows"));
}

TEST_F(CsvErrorTest, EmptyFileHasNoHeader) {
  const std::string message = error_for("");
  EXPECT_THAT(message, HasSubstr(path_));
  EXPECT_THAT(message, HasSubstr("no header line"));
}

TEST_F(CsvErrorTest, MissingFile) {
  const std::string path = (dir_ / "absent.csv").string();
  const std::string message = input_error_message([&] { return read_csv_record(path, kGravity); });
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("cannot open"));
}

// ---- dispatch ----------------------------------------------------------------------------------

using ReadRecordTest = RecordFileTest;

TEST_F(ReadRecordTest, DispatchesOnExtension) {
  const std::string csv_text = "t,a [g]\n0,1\n0.25,2\n";
  const std::string at2 = at2_text("NPTS= 7, DT= .01 SEC", kSevenValues);
  EXPECT_EQ(read_record(write("upper.AT2", at2), 1.0).horizontal.size(), 7U);
  EXPECT_EQ(read_record(write("lower.at2", at2), 1.0).horizontal.size(), 7U);
  EXPECT_DOUBLE_EQ(read_record(write("lower.csv", csv_text), 1.0).dt, 0.25);
  EXPECT_DOUBLE_EQ(read_record(write("upper.CSV", csv_text), 1.0).dt, 0.25);
}

TEST_F(ReadRecordTest, UnknownExtension) {
  const std::string path = write("record.txt", "t,a [g]\n0,1\n0.25,2\n");
  const std::string message = input_error_message([&] { return read_record(path, 1.0); });
  EXPECT_THAT(message, HasSubstr(path));
  EXPECT_THAT(message, HasSubstr("unknown record format (expected .AT2 or .csv)"));
}

}  // namespace
}  // namespace plinth::host
