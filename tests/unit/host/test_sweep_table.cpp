// plinth-sweep's CSV files: the settings line and its grid, reading and writing, merging the
// shards of a sweep, placing rows for a resume.
#include "plinth/host/sweep_table.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "plinth/host/input_error.h"
#include "test_support.h"
#include "test_sweep_support.h"

namespace plinth::host {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

SweepTable two_by_two(const std::vector<std::string>& rows) {
  return {SettingsLine("threshold_map", {{"lambda", 2, 4, 2}, {"epsilon", -0.5, 0.5, 2}})
              .add("dt", 5e-4)
              .text(),
          "lambda,epsilon,overturned", rows};
}

TEST(SweepTable, SettingsLineAndGrid) {
  const std::string line = SettingsLine("thresholds", {{"mu_s", 0.1, 1.5, 50}})
                               .add("pga_max_g", 2.0)
                               .add("x", "y")
                               .text();
  EXPECT_EQ(line, "# plinth-sweep thresholds grid=mu_s:0.1:1.5:50 pga_max_g=2 x=y");
  const auto settings = parse_settings(line, "f.csv");
  EXPECT_EQ(settings.at("mode"), "thresholds");
  EXPECT_EQ(settings.at("pga_max_g"), "2");
  const auto grid = parse_grid(two_by_two({}).settings, "f.csv");
  ASSERT_EQ(grid.size(), 2u);
  EXPECT_EQ(grid[1].name, "epsilon");
  EXPECT_EQ(grid[1].from, -0.5);
  EXPECT_THAT(grid_keys(grid), ElementsAre("2,-0.5", "2,0.5", "4,-0.5", "4,0.5"));
  EXPECT_THAT(grid_keys({{"T", 1, 2, 3}}), ElementsAre("1", "1.5", "2"));

  EXPECT_THAT(testing::input_error_text([] { (void)parse_settings("mu_s,sliding", "f.csv"); }),
              HasSubstr("f.csv: not a plinth-sweep CSV"));
  EXPECT_THAT(testing::input_error_text(
                  [] { (void)parse_grid("# plinth-sweep x grid=mu_s:1:0:3", "f.csv"); }),
              HasSubstr("f.csv: bad grid axis 'mu_s:1:0:3'"));
  EXPECT_THAT(testing::input_error_text([] { (void)parse_grid("# plinth-sweep x dt=1", "f.csv"); }),
              HasSubstr("no grid="));
}

TEST(SweepTable, ValuesNameTheirOptions) {
  EXPECT_THAT(sweep_values(0.1, 1.5, 1), ElementsAre(0.1));
  EXPECT_THAT(testing::input_error_text([] { (void)sweep_values(1.0, 0.5, 3, "--mu-"); }),
              HasSubstr("--mu-from 1 is greater than --mu-to 0.5"));
  EXPECT_THAT(testing::input_error_text([] { (void)sweep_values(0.0, 1.0, 0, "--", "2"); }),
              HasSubstr("--steps2: must be at least 1, got 0"));
}

TEST(SweepTable, FormatsAndFingerprints) {
  EXPECT_EQ(format_value(0.1 + 0.2), "0.3");
  EXPECT_EQ(format_result(0.123456789), "0.123457");
  EXPECT_EQ(format_result(std::nullopt), "");
  SceneParams a = plinth::testing::paper_isolated();
  SceneParams b = a;
  EXPECT_EQ(fingerprint(a), fingerprint(b));
  EXPECT_EQ(fingerprint(a).size(), 16u);
  b.base.damping_ratio = 0.2000001;
  EXPECT_NE(fingerprint(a), fingerprint(b));
  EXPECT_EQ(row_key("2,-0.5,1.25", 2), "2,-0.5");
  EXPECT_EQ(row_key("0.3,,", 1), "0.3");
  EXPECT_THAT(csv_fields("0.3,,"), ElementsAre("0.3", "", ""));
  EXPECT_THAT(csv_fields("mu_s"), ElementsAre("mu_s"));
}

TEST(SweepTable, FilesReadBackAsWritten) {
  const std::string path = ::testing::TempDir() + "sweep_table_roundtrip.csv";
  const SweepTable table = two_by_two({"2,-0.5,1.5", "4,0.5,"});
  {
    std::ofstream out(path);
    write_sweep_table(out, table);
  }
  const SweepTable back = read_sweep_table(path);
  EXPECT_EQ(back.settings, table.settings);
  EXPECT_EQ(back.header, table.header);
  EXPECT_EQ(back.rows, table.rows);

  // A row cut short (a killed writer): refused, or dropped and counted for a resume.
  {
    std::ofstream out(path, std::ios::app);
    out << "2,0.5\n";
  }
  EXPECT_THAT(testing::input_error_text([&] { (void)read_sweep_table(path); }),
              HasSubstr(":5: 2 fields, the header has 3"));
  std::size_t dropped = 0;
  EXPECT_EQ(read_sweep_table(path, &dropped).rows.size(), 2u);
  EXPECT_EQ(dropped, 1u);
  std::filesystem::remove(path);
  EXPECT_THAT(testing::input_error_text([&] { (void)read_sweep_table(path); }),
              HasSubstr("cannot open"));
}

TEST(SweepTable, MergeJoinsShardsInGridOrder) {
  const SweepTable first = two_by_two({"2,-0.5,1", "4,-0.5,3"});
  const SweepTable second = two_by_two({"4,0.5,4", "2,0.5,"});
  const SweepTable merged = merge_sweep_tables({second, first}, {"b.csv", "a.csv"});
  EXPECT_THAT(merged.rows, ElementsAre("2,-0.5,1", "2,0.5,", "4,-0.5,3", "4,0.5,4"));
  EXPECT_EQ(merged.settings, first.settings);
}

TEST(SweepTable, MergeRefusesWhatDoesNotFit) {
  const SweepTable first = two_by_two({"2,-0.5,1", "4,-0.5,3"});
  SweepTable other = two_by_two({"4,0.5,4", "2,0.5,"});
  other.settings += " pga_max_g=3";
  EXPECT_THAT(testing::input_error_text([&] {
                (void)merge_sweep_tables({first, other}, {"a.csv", "b.csv"});
              }),
              HasSubstr("merge: b.csv and a.csv come from different sweeps"));
  SweepTable renamed = two_by_two({"4,0.5,4", "2,0.5,"});
  renamed.header = "lambda,epsilon,fell";
  EXPECT_THAT(testing::input_error_text([&] {
                (void)merge_sweep_tables({first, renamed}, {"a.csv", "b.csv"});
              }),
              HasSubstr("different headers"));
  EXPECT_THAT(testing::input_error_text([&] {
                (void)merge_sweep_tables({first, first}, {"a.csv", "c.csv"});
              }),
              HasSubstr("row '2,-0.5' is in both a.csv and c.csv"));
  EXPECT_THAT(testing::input_error_text([&] { (void)merge_sweep_tables({first}, {"a.csv"}); }),
              HasSubstr("merge: 2 of 4 rows are missing ('2,0.5', '4,0.5')"));
  EXPECT_THAT(testing::input_error_text(
                  [&] { (void)merge_sweep_tables({two_by_two({"3,0.5,1"})}, {"a.csv"}); }),
              HasSubstr("a.csv: row '3,0.5' is not a point of this sweep's grid"));
  EXPECT_THAT(testing::input_error_text([&] {
                (void)place_rows({"2,1", "2,2"}, {"1", "2"}, 1, "p.csv");
              }),
              HasSubstr("p.csv: row '2' appears twice"));
  EXPECT_THAT(testing::input_error_text([] { (void)merge_sweep_tables({}, {}); }),
              HasSubstr("no input files"));
}

// Issue 33: a file written before a column was added (lift_off) is named as an older
// plinth-sweep's, for the modes whose files have that column only.
TEST(SweepTable, AFileWithoutAnAddedColumnIsAnOlderVersions) {
  const std::string events =
      "mu_s,sliding,rocking,slide_rocking,out_of_base,base_stop_hit,slide_stop_hit,fell,overturned";
  const std::string thresholds = SettingsLine("thresholds", {{"mu_s", 0.2, 0.5, 4}}).text();
  const SweepTable older{thresholds, events, {}};
  const std::vector<const AddedColumn*> missing = columns_added_since(older);
  ASSERT_EQ(missing.size(), 1u);
  EXPECT_STREQ(missing[0]->name, "lift_off");
  EXPECT_EQ(older_version_text(missing),
            "written by a plinth-sweep older than its lift_off column (plinth 0.1.0 from commit "
            "4a3615a of 2026-11-28, when lift-off began to end a run)");
  EXPECT_TRUE(columns_added_since({thresholds, events + ",lift_off", {}}).empty());
  const std::string curve = SettingsLine("impulse_curve", {{"T", 1.0, 2.0, 2}}).text();
  EXPECT_EQ(columns_added_since({curve, "T,rocking,overturned", {}}).size(), 1u);
  // A map of one event, an impulse map, a file that is no sweep: nothing to say.
  const std::string map = SettingsLine("threshold_map", {{"mu_s", 0.2, 0.5, 2}}).text();
  EXPECT_TRUE(columns_added_since({map, "mu_s,T,overturned", {}}).empty());
  EXPECT_TRUE(columns_added_since({"not a sweep", events, {}}).empty());
  EXPECT_EQ(older_version_text({}), "");
  // Merging it with a shard of this version names it.
  SweepTable newer = older;
  newer.header += ",lift_off";
  EXPECT_THAT(testing::input_error_text([&] {
                (void)merge_sweep_tables({newer, older}, {"new.csv", "old.csv"});
              }),
              HasSubstr("merge: old.csv and new.csv have different headers (old.csv was written "
                        "by a plinth-sweep older than its lift_off column"));
}

// Messages about settings lines that differ name the settings, not just the lines.
TEST(SweepTable, SettingsDifferenceNamesTheSettings) {
  const std::string plain = SettingsLine("thresholds", {{"mu_s", 0.1, 1.5, 50}})
                                .add("pga_max_g", 2.0)
                                .add("tol_g", 0.001)
                                .text();
  const std::string compared = SettingsLine("thresholds", {{"mu_s", 0.1, 1.5, 50}})
                                   .add("pga_max_g", 3.0)
                                   .add("tol_g", 0.001)
                                   .add("compare", "ground")
                                   .text();
  EXPECT_EQ(settings_difference(compared, "a.csv", plain, "b.csv"),
            "compare: ground in a.csv, none in b.csv; pga_max_g: 3 in a.csv, 2 in b.csv");
  EXPECT_EQ(settings_difference(plain, "a.csv", plain, "b.csv"), "");
  EXPECT_EQ(settings_difference("mu_s,sliding", "a.csv", plain, "b.csv"), "");

  SweepTable first = two_by_two({"2,-0.5,1,0.5", "4,-0.5,3,1"});
  first.header = "lambda,epsilon,overturned,overturned_ground";
  first.settings += " compare=ground";
  SweepTable second = two_by_two({"4,0.5,4", "2,0.5,"});
  EXPECT_THAT(testing::input_error_text([&] {
                (void)merge_sweep_tables({first, second}, {"a.csv", "b.csv"});
              }),
              HasSubstr("merge: b.csv and a.csv come from different sweeps (their settings lines "
                        "differ: compare: none in b.csv, ground in a.csv)"));
}

}  // namespace
}  // namespace plinth::host
