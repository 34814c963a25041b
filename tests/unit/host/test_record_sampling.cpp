// Records at a sensor's rate and scaled as the command lines ask (lib/host/record_sampling.h).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/host/input_error.h"
#include "plinth/host/record_sampling.h"

namespace plinth::host {
namespace {

Record record_of(std::vector<double> horizontal, double dt) {
  Record r;
  r.dt = dt;
  r.horizontal = std::move(horizontal);
  return r;
}

std::string scale_error(const Record& r, const std::string& pga) {
  try {
    (void)record_scale(r, "quake.AT2", pga, std::nullopt, kStandardGravity);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RecordScale, PgaOverThePeakElseTheScaleElseOne) {
  const Record r = record_of({0.0, -2.0 * kStandardGravity, 1.0}, 0.01);
  EXPECT_DOUBLE_EQ(record_scale(r, "quake.AT2", "0.5g", std::nullopt, kStandardGravity), 0.25);
  EXPECT_DOUBLE_EQ(record_scale(r, "quake.AT2", "", -3.0, kStandardGravity), -3.0);
  EXPECT_DOUBLE_EQ(record_scale(r, "quake.AT2", "", std::nullopt, kStandardGravity), 1.0);
}

TEST(RecordScale, OneMessagePerProblem) {
  const Record r = record_of({0.0, 1.0}, 0.01);
  EXPECT_EQ(scale_error(r, "-0.3g"),
            "--pga -0.3g: must be greater than zero (use --scale with a negative factor to mirror "
            "the record)");
  EXPECT_EQ(scale_error(r, "0g").rfind("--pga 0g: must be greater than zero", 0), 0U);
  EXPECT_EQ(scale_error(r, "500g"),
            "--pga 500g: the scaled record's peak would be 500 g, limit 100 g");
  EXPECT_THROW((void)record_scale(r, "quake.AT2", "", 1e308, kStandardGravity), InputError);
  EXPECT_NE(scale_error(r, "0.3").find("--pga"), std::string::npos);  // no unit
  EXPECT_EQ(scale_error(record_of({0.0, 0.0}, 0.01), "0.3g"),
            "quake.AT2: record is all zeros, cannot scale to --pga");
}

TEST(SampleCount, WholeSamplesOverTheDuration) {
  EXPECT_EQ(sample_count(1.0, 200.0), 201U);
  EXPECT_EQ(sample_count(0.0, 200.0), 1U);
  EXPECT_EQ(sample_count(1.0049, 200.0), 201U);
  EXPECT_EQ(sample_count(34.9827, 200.0), 6997U);
  // A product a hair below a whole number counts as that number.
  EXPECT_EQ(sample_count(0.3 - 1e-12, 10.0), 4U);
}

TEST(Resample, AtItsOwnRateTheRecordsSamplesAsTheyAre) {
  const Record r = record_of({0.1, 0.2, 0.3, 0.4}, 0.0029);
  const std::vector<double> out = resample(r.horizontal_signal(), 1.0 / 0.0029, 6);
  ASSERT_EQ(out.size(), 6U);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(out[k], r.horizontal[k]) << k;  // bit for bit
  EXPECT_EQ(out[4], 0.0);  // after the last sample
  EXPECT_EQ(out[5], 0.0);
}

TEST(Resample, ElseInterpolatedAsTheSolverReadsAndTheLastSampleKept) {
  // 8 samples, 0.07 s: at 300 Hz sample 21 is the last one in exact arithmetic, and 21 / 300 s
  // lands just past it in floating point, where SampledSignal::at reads zero.
  const Record r = record_of({0.0, 1.0, -1.0, 2.0, 0.5, -0.5, 3.0, 2.5}, 0.01);
  const SampledSignal signal = r.horizontal_signal();
  const std::size_t count = sample_count(r.duration(), 300.0);
  ASSERT_EQ(count, 22U);
  const std::vector<double> out = resample(signal, 300.0, count);
  for (std::size_t k = 0; k + 1 < count; ++k) {
    EXPECT_EQ(out[k], signal.at(static_cast<double>(k) / 300.0)) << k;
  }
  EXPECT_EQ(signal.at(21.0 / 300.0), 0.0);  // the solver's reading: past the end
  EXPECT_EQ(out[count - 1], 2.5);
  EXPECT_EQ(resample(SampledSignal{}, 300.0, 3), std::vector<double>(3, 0.0));
}

}  // namespace
}  // namespace plinth::host
