#include "plinth/host/pwave_records.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"

namespace plinth::host {

void attach_vertical(Record& record, const Record& vertical, const std::string& vertical_origin) {
  if (!record.vertical.empty()) {
    throw InputError(vertical_origin + ": the record " + record.name +
                     " has a vertical column of its own already");
  }
  if (std::fabs(vertical.dt - record.dt) > 1e-9 * record.dt) {
    throw InputError(vertical_origin + ": sampling interval " + number_text(vertical.dt) +
                     " s differs from its horizontal record's " + number_text(record.dt) + " s");
  }
  const std::size_t n = std::min(record.horizontal.size(), vertical.horizontal.size());
  record.horizontal.resize(n);
  record.vertical.assign(vertical.horizontal.begin(),
                         vertical.horizontal.begin() + static_cast<std::ptrdiff_t>(n));
}

std::size_t aic_pick(std::span<const double> x) {
  const std::size_t n = x.size();
  if (n < 4) return 0;
  // Prefix sums of x and x^2 give each side's variance in O(1).
  std::vector<double> sum(n + 1, 0.0), sum2(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    sum[i + 1] = sum[i] + x[i];
    sum2[i + 1] = sum2[i] + x[i] * x[i];
  }
  const auto variance = [&](std::size_t from, std::size_t to) {
    const double m = static_cast<double>(to - from);
    const double mean = (sum[to] - sum[from]) / m;
    const double v = (sum2[to] - sum2[from]) / m - mean * mean;
    return std::max(v, std::numeric_limits<double>::min());
  };
  // Each side at least 2 % of the series (and 2 samples): one sample has no variance, and a
  // few at an edge would win on it.
  const std::size_t edge = std::max<std::size_t>(2, n / 50);
  std::size_t best = edge;
  double best_aic = std::numeric_limits<double>::infinity();
  for (std::size_t k = edge; k + edge <= n; ++k) {
    const double aic = static_cast<double>(k) * std::log(variance(0, k)) +
                       static_cast<double>(n - k - 1) * std::log(variance(k, n));
    if (aic < best_aic) {
      best_aic = aic;
      best = k;
    }
  }
  return best;
}

RecordPhases record_phases(const Record& record) {
  RecordPhases phases;
  const double peak = record.peak_horizontal();
  std::size_t strong = 0;
  while (strong < record.horizontal.size() &&
         std::fabs(record.horizontal[strong]) < kStrongMotionFraction * peak) {
    ++strong;
  }
  phases.strong_motion_s = static_cast<double>(strong) * record.dt;
  if (record.vertical.empty() || phases.strong_motion_s < 1.0) return phases;
  const std::size_t n = std::min(strong, record.vertical.size());
  phases.p_pick_s =
      static_cast<double>(aic_pick(std::span<const double>(record.vertical.data(), n))) *
      record.dt;
  return phases;
}

namespace {

// Least squares of y = c0 + c1 x; sigma with n - 2 degrees of freedom. When x does not vary:
// c1 = 0, c0 the mean, n - 1 degrees of freedom.
PWaveFitPoint fit_line(double window_s, const std::vector<const PWaveWindowSample*>& s) {
  PWaveFitPoint p;
  p.window_s = window_s;
  p.samples = s.size();
  const auto n = static_cast<double>(s.size());
  double mx = 0, my = 0;
  for (const PWaveWindowSample* q : s) {
    mx += q->ln_tau_c;
    my += q->ln_pga_over_pa;
  }
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0;
  for (const PWaveWindowSample* q : s) {
    sxx += (q->ln_tau_c - mx) * (q->ln_tau_c - mx);
    sxy += (q->ln_tau_c - mx) * (q->ln_pga_over_pa - my);
  }
  p.c1 = sxx > 0.0 ? sxy / sxx : 0.0;
  p.c0 = my - p.c1 * mx;
  double ssr = 0;
  for (const PWaveWindowSample* q : s) {
    const double r = q->ln_pga_over_pa - p.c0 - p.c1 * q->ln_tau_c;
    ssr += r * r;
  }
  p.sigma = std::sqrt(ssr / (n - (sxx > 0.0 ? 2.0 : 1.0)));
  return p;
}

}  // namespace

std::vector<PWaveFitPoint> fit_pwave_predictor(const std::vector<PWaveWindowSample>& samples,
                                               const std::vector<double>& windows_s) {
  std::vector<PWaveFitPoint> table;
  for (const double w : windows_s) {
    std::vector<const PWaveWindowSample*> at;
    for (const PWaveWindowSample& s : samples) {
      if (std::fabs(s.window_s - w) < 1e-9) at.push_back(&s);
    }
    PWaveFitPoint p;
    p.window_s = w;
    p.samples = at.size();
    if (at.size() >= kMinFitSamples) p = fit_line(w, at);
    table.push_back(p);
  }
  const auto fitted = [](const PWaveFitPoint& p) { return p.samples >= kMinFitSamples; };
  const auto first = std::find_if(table.begin(), table.end(), fitted);
  if (first == table.end()) {
    throw InputError("pwave-fit: no window has " + std::to_string(kMinFitSamples) +
                     " triggered records open at it (more records, or a lower --pga?)");
  }
  // Windows without enough samples borrow their neighbour's line.
  for (auto it = table.begin(); it != first; ++it) {
    const std::size_t n = it->samples;
    *it = *first;
    it->window_s = windows_s[static_cast<std::size_t>(it - table.begin())];
    it->samples = n;
    it->borrowed = true;
  }
  for (std::size_t i = 1; i < table.size(); ++i) {
    if (fitted(table[i])) continue;
    const std::size_t n = table[i].samples;
    table[i] = table[i - 1];
    table[i].window_s = windows_s[i];
    table[i].samples = n;
    table[i].borrowed = true;
  }
  return table;
}

PWaveCrossValidation cross_validate_pwave_predictor(
    const std::vector<PWaveWindowSample>& samples, const std::vector<std::string>& group,
    const std::vector<double>& windows_s) {
  if (group.size() != samples.size()) {
    throw InputError("pwave-fit: " + std::to_string(group.size()) + " groups for " +
                     std::to_string(samples.size()) + " samples");
  }
  PWaveCrossValidation cv;
  cv.groups = group;
  std::sort(cv.groups.begin(), cv.groups.end());
  cv.groups.erase(std::unique(cv.groups.begin(), cv.groups.end()), cv.groups.end());
  if (cv.groups.size() < 2) {
    throw InputError("pwave-fit: leaving one earthquake out needs two earthquakes or more, got " +
                     std::to_string(cv.groups.size()));
  }
  cv.pooled = fit_pwave_predictor(samples, windows_s);
  const std::size_t windows = windows_s.size();
  std::vector<double> pooled_sq(windows, 0.0);
  std::vector<std::size_t> pooled_count(windows, 0);
  for (const std::string& left_out : cv.groups) {
    std::vector<PWaveWindowSample> others;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (group[i] != left_out) others.push_back(samples[i]);
    }
    const std::vector<PWaveFitPoint> table = fit_pwave_predictor(others, windows_s);
    std::vector<double> sq(windows, 0.0);
    std::vector<std::size_t> count(windows, 0);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (group[i] != left_out) continue;
      for (std::size_t w = 0; w < windows; ++w) {
        if (std::fabs(samples[i].window_s - windows_s[w]) >= 1e-9) continue;
        const double r =
            samples[i].ln_pga_over_pa - table[w].c0 - table[w].c1 * samples[i].ln_tau_c;
        sq[w] += r * r;
        ++count[w];
      }
    }
    std::vector<double> rms(windows, 0.0);
    for (std::size_t w = 0; w < windows; ++w) {
      if (count[w] > 0) rms[w] = std::sqrt(sq[w] / static_cast<double>(count[w]));
      pooled_sq[w] += sq[w];
      pooled_count[w] += count[w];
    }
    cv.rms.push_back(rms);
    cv.count.push_back(count);
  }
  for (std::size_t w = 0; w < windows; ++w) {
    cv.pooled[w].samples = pooled_count[w];
    cv.pooled[w].sigma =
        pooled_count[w] > 0 ? std::sqrt(pooled_sq[w] / static_cast<double>(pooled_count[w]))
                            : 0.0;
  }
  return cv;
}

}  // namespace plinth::host
