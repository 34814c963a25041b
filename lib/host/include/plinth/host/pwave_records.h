// Three-component records for the P-wave stage (docs/pwave.md): a horizontal record joined
// with its vertical file, the record's reference phases (where its P wave and its strong
// motion begin), and the fit of the stage's predictor table. Host-only.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "plinth/host/record_io.h"

namespace plinth::host {

// Gives `record` (a horizontal component) the vertical component read from another file:
// the same dt (to 1e-9 relative) is required; when the two files' npts differ (a station's
// components often end a few samples apart) both are cut to the span they share. Throws
// InputError naming `vertical_origin` for a dt that differs or a file that has a vertical
// column of its own already.
void attach_vertical(Record& record, const Record& vertical, const std::string& vertical_origin);

// The strong motion begins where the horizontal first reaches this fraction of its peak.
inline constexpr double kStrongMotionFraction = 0.2;

// Where a record's phases begin, s from its first sample; both keep when the record is scaled.
struct RecordPhases {
  double strong_motion_s = 0.0;  // first |a_h| >= kStrongMotionFraction * PGA
  // The P wave's arrival on the vertical, picked by the Akaike information criterion (Maeda
  // 1985: the split of the samples before the strong motion into two stationary parts) over
  // [0, strong_motion_s); -1 when there is no vertical or less than 1 s before the strong motion
  // (the record begins in it).
  double p_pick_s = -1.0;

  // How long the P wave comes before the strong motion, s; 0 without a pick.
  [[nodiscard]] double p_lead_s() const {
    return p_pick_s >= 0.0 ? strong_motion_s - p_pick_s : 0.0;
  }
};

[[nodiscard]] RecordPhases record_phases(const Record& record);

// The AIC pick of a series: the k minimising
//   k ln var(x[0, k)) + (n - k - 1) ln var(x[k, n)),
// i.e. where a quiet part ends and a louder one begins, each part at least 2 % of the series
// and 2 samples long. 0 for fewer than 4 samples.
[[nodiscard]] std::size_t aic_pick(std::span<const double> x);

// One sample of the predictor's fit: at window W after a trigger, ln(PGA / Pa) and ln(tau_c / 1 s).
struct PWaveWindowSample {
  double window_s = 0.0;
  double ln_pga_over_pa = 0.0;
  double ln_tau_c = 0.0;
};

// The table the stage reads (PWavePredictorPoint): per window, least squares of
//   ln(PGA / Pa) = c0 + c1 ln(tau_c / 1 s)
// over the samples at that window, sigma the residuals' standard deviation (n - 2 degrees of
// freedom; n - 1 when ln tau_c does not vary, c1 = 0 and c0 the mean). A window with fewer than kMinFitSamples samples takes the point before it (or, for
// the first, the next one that has enough), marked borrowed.
inline constexpr std::size_t kMinFitSamples = 5;
struct PWaveFitPoint {
  double window_s = 0.0;
  std::size_t samples = 0;
  double c0 = 0.0;
  double c1 = 0.0;
  double sigma = 0.0;
  bool borrowed = false;
};
// Throws InputError when no window has kMinFitSamples samples.
[[nodiscard]] std::vector<PWaveFitPoint> fit_pwave_predictor(
    const std::vector<PWaveWindowSample>& samples, const std::vector<double>& windows_s);

// Whether the table's terms generalise to other earthquakes: per window, the residuals of each
// group's samples (group[i] names the earthquake of samples[i]) under the table fitted on the
// other groups' samples alone (leave one group out). Throws InputError for fewer than two
// groups, a group per sample missing, or a fit without enough samples.
struct PWaveCrossValidation {
  // Per window, pooled over the groups: samples, sigma the residuals' root mean square (c0 and
  // c1 are the fit on all samples).
  std::vector<PWaveFitPoint> pooled;
  std::vector<std::string> groups;  // sorted
  // groups x windows: the group's residuals' root mean square and how many (0: none, rms 0).
  std::vector<std::vector<double>> rms;
  std::vector<std::vector<std::size_t>> count;
};
[[nodiscard]] PWaveCrossValidation cross_validate_pwave_predictor(
    const std::vector<PWaveWindowSample>& samples, const std::vector<std::string>& group,
    const std::vector<double>& windows_s);

}  // namespace plinth::host
