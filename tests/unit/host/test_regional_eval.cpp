// Regional alerts evaluated by simulation (regional_eval.h, docs/regional.md "Evaluation"): the
// record-info CSV (the bundled one against SOURCES.md's table and the folder's files; bad
// inputs), and the alert model (timing, intensity error, the room's probability).
#include "plinth/host/regional_eval.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "plinth/host/input_error.h"

namespace plinth::host {
namespace {

const std::string kPWaveDir = PLINTH_SOURCE_DIR "/sim/data/records/pwave/";
const std::string kHeader = "rsn,earthquake,station,magnitude,rrup_km,rjb_km,rhyp_km,vs30_m_s\n";

std::string write_file(const std::string& name, const std::string& text) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("regional_eval_" + name)).string();
  std::ofstream(path) << text;
  return path;
}

// The message of the InputError `f` throws ("" when none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// SOURCES.md's station table: | RSN | earthquake, date | station | M | Rrup | Rjb | Rhyp | Vs30 |
TEST(RecordInfo, BundledCsvMatchesSourcesTableAndFiles) {
  const auto info = read_record_info(kPWaveDir + "stations.csv");
  std::ifstream sources(kPWaveDir + "SOURCES.md");
  std::set<int> in_table;
  for (std::string line; std::getline(sources, line);) {
    // A station row: 8 cells, the first a number (the files' table has paths and SHA-1s).
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, '|');) {
      const auto first = cell.find_first_not_of(' ');
      const auto last = cell.find_last_not_of(' ');
      cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
    }
    if (line.rfind("| ", 0) != 0 || cells.size() != 9 || cells[1].empty() ||
        cells[1].find_first_not_of("0123456789") != std::string::npos) {
      continue;
    }
    const int rsn = std::stoi(cells[1]);
    in_table.insert(rsn);
    ASSERT_EQ(info.count(rsn), 1U) << "RSN " << rsn;
    const RecordSource& s = info.at(rsn);
    EXPECT_EQ(s.station, cells[3]) << rsn;
    EXPECT_NEAR(s.magnitude, std::stod(cells[4]), 1e-9) << rsn;
    EXPECT_NEAR(s.rrup_km, std::stod(cells[5]), 1e-9) << rsn;
    EXPECT_NEAR(s.rjb_km, std::stod(cells[6]), 1e-9) << rsn;
    EXPECT_NEAR(s.rhyp_km, std::stod(cells[7]), 1e-9) << rsn;
    EXPECT_EQ(std::lround(s.vs30_m_s), std::stol(cells[8])) << rsn;
  }
  EXPECT_EQ(in_table.size(), 15U);
  EXPECT_EQ(info.size(), in_table.size());
  // Every bundled file has its station's row.
  for (const auto& entry : std::filesystem::directory_iterator(kPWaveDir)) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".AT2") continue;
    EXPECT_NO_THROW((void)record_source(info, name, "stations.csv")) << name;
  }
}

TEST(RecordInfo, ReadsQuotedNamesAndMatchesByRsn) {
  const std::string path = write_file(
      "ok.csv", kHeader + "2622,\"Chi-Chi, Taiwan-03\",TCU071,6.20,16.46,15.04,21.95,624.85\n");
  const auto info = read_record_info(path);
  const RecordSource& s = record_source(info, "RSN2622_CHICHI.03_TCU071V.AT2", path);
  EXPECT_EQ(s.earthquake, "Chi-Chi, Taiwan-03");
  EXPECT_DOUBLE_EQ(s.rhyp_km, 21.95);
  EXPECT_EQ(record_rsn("RSN7_X.AT2"), 7);
}

TEST(RecordInfo, RefusesARecordWithoutARowNamingIt) {
  const std::string path =
      write_file("one.csv", kHeader + "963,Northridge-01,ORR,6.69,20.72,20.11,44.29,450.28\n");
  const auto info = read_record_info(path);
  const std::string e = error_of([&] { (void)record_source(info, "RSN990_NORTHR_LAC090.AT2", path); });
  EXPECT_NE(e.find("RSN990_NORTHR_LAC090.AT2: no row for RSN 990"), std::string::npos) << e;
  const std::string name = error_of([&] { (void)record_source(info, "LAC090.AT2", path); });
  EXPECT_NE(name.find("LAC090.AT2: its name does not begin with RSN<number>_"), std::string::npos)
      << name;
  EXPECT_NE(error_of([] { (void)record_rsn("RSN_X.AT2"); }), "");
  EXPECT_NE(error_of([] { (void)record_rsn("RSN12"); }), "");
}

struct BadRow {
  const char* name;
  std::string text;      // the file's contents
  const char* expected;  // in the message
};

class RecordInfoBad : public ::testing::TestWithParam<BadRow> {};

TEST_P(RecordInfoBad, IsRefusedNamingFileLineAndField) {
  const BadRow& bad = GetParam();
  const std::string path = write_file(std::string(bad.name) + ".csv", bad.text);
  const std::string e = error_of([&] { (void)read_record_info(path); });
  EXPECT_NE(e.find(path), std::string::npos) << e;
  EXPECT_NE(e.find(bad.expected), std::string::npos) << e;
}

const std::string kGood = "963,Northridge-01,ORR,6.69,20.72,20.11,44.29,450.28\n";

INSTANTIATE_TEST_SUITE_P(
    Rows, RecordInfoBad,
    ::testing::Values(
        BadRow{"header", "rsn,magnitude\n" + kGood, ":1: expected the header"},
        BadRow{"empty", kHeader, "no rows"},
        BadRow{"fields", kHeader + "963,Northridge-01,ORR,6.69,20.72\n", ":2: expected 8 fields, got 5"},
        BadRow{"nan", kHeader + "963,N,ORR,nan,20.72,20.11,44.29,450\n", ":2: magnitude: not finite"},
        BadRow{"text", kHeader + "963,N,ORR,6.69,far,20.11,44.29,450\n", ":2: rrup_km: not a number"},
        BadRow{"magnitude", kHeader + "963,N,ORR,11,20.72,20.11,44.29,450\n", ":2: magnitude: expected > 0"},
        BadRow{"negative", kHeader + "963,N,ORR,6.69,20.72,-1,44.29,450\n", ":2: rjb_km: expected >= 0"},
        BadRow{"rhyp0", kHeader + "963,N,ORR,6.69,0,0,0,450\n", ":2: rhyp_km: expected > 0"},
        BadRow{"vs30", kHeader + "963,N,ORR,6.69,20.72,20.11,44.29,0\n", ":2: vs30_m_s: expected > 0"},
        BadRow{"order", kHeader + "963,N,ORR,6.69,20.72,20.11,14.29,450\n", ":2: rrup_km: above rhyp_km"},
        BadRow{"rjb", kHeader + "963,N,ORR,6.69,20.72,30.11,44.29,450\n", ":2: rjb_km: above rrup_km"},
        BadRow{"rsn", kHeader + "9.5,N,ORR,6.69,20.72,20.11,44.29,450\n", ":2: rsn: expected a whole number"},
        BadRow{"twice", kHeader + kGood + kGood, ":3: rsn: 963 given twice"},
        BadRow{"quote", kHeader + "963,\"N,ORR,6.69,20.72,20.11,44.29,450\n", ":2: unterminated quoted field"}),
    [](const ::testing::TestParamInfo<BadRow>& i) { return std::string(i.param.name); });

TEST(RecordInfo, MissingFileIsNamed) {
  const std::string e = error_of([] { (void)read_record_info("/nonexistent/stations.csv"); });
  EXPECT_NE(e.find("/nonexistent/stations.csv: cannot open"), std::string::npos) << e;
}

// ---- the alert model

RecordSource source_at(double rhyp_km) {
  RecordSource s;
  s.rsn = 990;
  s.magnitude = 6.69;
  s.rrup_km = s.rjb_km = rhyp_km / 2.0;
  s.rhyp_km = rhyp_km;
  s.vs30_m_s = 365.0;
  return s;
}

RecordPhases phases_with_strong_motion(double t) {
  RecordPhases p;
  p.strong_motion_s = t;
  return p;
}

const LognormalFragility kStatue{0.8, 0.6};

TEST(RegionalAlertModel, TimesFollowTheDistanceAndTheLatency) {
  RegionalAlertModel m;
  m.latency_sd_s = 0.0;  // the median alone
  const SimulatedRegionalAlert a =
      simulate_regional_alert(m, source_at(70.0), phases_with_strong_motion(12.0), 0.5, kStatue, 1);
  // S travel 70 / 3.5 = 20 s: origin 8 s before the record began; the alert 6.9 s after it.
  EXPECT_NEAR(a.origin_s, -8.0, 1e-12);
  EXPECT_NEAR(a.s_arrival_s, 12.0, 1e-12);
  EXPECT_NEAR(a.alert_s, -8.0 + 6.9, 1e-12);
  EXPECT_FALSE(a.blind());
  // Near the source the S waves come before the alert: the blind zone (6.9 x 3.5 = 24.15 km).
  EXPECT_TRUE(simulate_regional_alert(m, source_at(24.0), phases_with_strong_motion(5.0), 0.5,
                                      kStatue, 1)
                  .blind());
  EXPECT_FALSE(simulate_regional_alert(m, source_at(24.3), phases_with_strong_motion(5.0), 0.5,
                                       kStatue, 1)
                   .blind());
}

TEST(RegionalAlertModel, LatencyAndErrorAreDrawnFromTheirDistributions) {
  const RegionalAlertModel m;
  std::vector<double> latency;
  std::vector<double> eps;
  for (std::uint64_t seed = 1; seed <= 4000; ++seed) {
    const SimulatedRegionalAlert a = simulate_regional_alert(
        m, source_at(100.0), phases_with_strong_motion(30.0), 0.4, kStatue, seed);
    latency.push_back(a.alert_s - a.origin_s);
    eps.push_back(std::log(a.pga_g / 0.4));
    EXPECT_GE(latency.back(), m.latency_floor_s);
    EXPECT_DOUBLE_EQ(a.sigma_ln, m.declared_sigma_ln);
  }
  const auto mean_sd = [](const std::vector<double>& x) {
    double s = 0.0;
    double s2 = 0.0;
    for (double v : x) s += v;
    const double mean = s / static_cast<double>(x.size());
    for (double v : x) s2 += (v - mean) * (v - mean);
    return std::pair{mean, std::sqrt(s2 / static_cast<double>(x.size() - 1))};
  };
  const auto [lat_mean, lat_sd] = mean_sd(latency);
  const auto [eps_mean, eps_sd] = mean_sd(eps);
  // 4000 draws: the mean within ~4 standard errors; the floor at 3 s cuts 2.5 % of the tail.
  EXPECT_NEAR(lat_mean, 6.9, 0.15);
  EXPECT_NEAR(lat_sd, 2.0, 0.15);
  EXPECT_NEAR(eps_mean, 0.0, 0.05);
  EXPECT_NEAR(eps_sd, std::log(2.0), 0.05);
  // The same seed, the same alert.
  const SimulatedRegionalAlert a = simulate_regional_alert(
      m, source_at(100.0), phases_with_strong_motion(30.0), 0.4, kStatue, 17);
  const SimulatedRegionalAlert b = simulate_regional_alert(
      m, source_at(100.0), phases_with_strong_motion(30.0), 0.4, kStatue, 17);
  EXPECT_EQ(a.alert_s, b.alert_s);
  EXPECT_EQ(a.pga_g, b.pga_g);
}

TEST(RegionalAlertModel, ThePredictionScalesWithTheRunsPgaAndBiasMovesIt) {
  RegionalAlertModel m;
  const auto at = [&](double pga) {
    return simulate_regional_alert(m, source_at(60.0), phases_with_strong_motion(20.0), pga,
                                   kStatue, 5);
  };
  EXPECT_NEAR(at(1.2).pga_g / at(0.4).pga_g, 3.0, 1e-9);  // the same draw, scaled
  m.error_sigma_ln = 0.0;
  m.error_bias_ln = std::log(0.5);  // a system that predicts half the shaking
  EXPECT_NEAR(at(0.4).pga_g, 0.2, 1e-12);
  // Capped at the room's range.
  m.error_bias_ln = 0.0;
  EXPECT_DOUBLE_EQ(at(20.0).pga_g, kMaxAlertPgaG);
}

TEST(RegionalAlertModel, ProbabilityIsTheRoomsFragilityUnderTheAlertsScatter) {
  RegionalAlertModel m;
  m.error_sigma_ln = 0.0;
  m.declared_sigma_ln = 0.5;
  const SimulatedRegionalAlert a = simulate_regional_alert(
      m, source_at(60.0), phases_with_strong_motion(20.0), 1.2, kStatue, 3);
  // Phi(ln(1.2 / 0.8) / sqrt(0.6^2 + 0.5^2)), the box's rule.
  const double z = std::log(1.2 / 0.8) / std::sqrt(0.36 + 0.25);
  EXPECT_NEAR(a.probability, 0.5 * std::erfc(-z / std::sqrt(2.0)), 1e-5);
  // At the median, one half.
  EXPECT_NEAR(simulate_regional_alert(m, source_at(60.0), phases_with_strong_motion(20.0), 0.8,
                                      kStatue, 3)
                  .probability,
              0.5, 1e-5);
}

TEST(RegionalAlertModel, InvalidModelsAreRefusedNamingTheOption) {
  RegionalAlertModel m;
  m.latency_median_s = std::nan("");
  EXPECT_NE(error_of([&] { validate(m); }).find("--regional-latency"), std::string::npos);
  m = RegionalAlertModel{};
  m.error_sigma_ln = -0.1;
  EXPECT_NE(error_of([&] { validate(m); }).find("--regional-sigma"), std::string::npos);
  m = RegionalAlertModel{};
  m.latency_sd_s = 100.0;
  EXPECT_NE(error_of([&] { validate(m); }).find("--regional-latency-sd"), std::string::npos);
  m = RegionalAlertModel{};
  m.error_bias_ln = 5.0;
  EXPECT_NE(error_of([&] { validate(m); }).find("--regional-bias"), std::string::npos);
  EXPECT_EQ(error_of([] { validate(RegionalAlertModel{}); }), "");
}

}  // namespace
}  // namespace plinth::host
