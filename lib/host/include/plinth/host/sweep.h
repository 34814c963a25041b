// Parameter sweeps: for each value of one scene parameter, the smallest PGA at which each kind
// of event first occurs under a record (plinth-sweep).
#pragma once

#include <array>
#include <cstddef>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/host/record_io.h"

namespace plinth::host {

// The events a sweep looks for, in the order of the CSV columns.
enum class SweepEvent : unsigned char {
  kSliding,        // a kSlidingStart event
  kRocking,        // a kRockingStart event
  kSlideRocking,   // any event leaving the block in Phase::kSlideRocking
  kOutOfBase,      // kOutOfBase
  kBaseStopHit,    // kBaseStopHit
  kSlideStopHit,   // kSlideStopHit
  kFell,           // kFell
  kOverturned,     // kOverturned
};
inline constexpr std::size_t kSweepEventCount = 8;

// "sliding", "rocking", "slide_rocking", "out_of_base", "base_stop_hit", "slide_stop_hit",
// "fell", "overturned".
[[nodiscard]] const char* sweep_event_name(SweepEvent event);

struct SweepSettings {
  double pga_max_g = 2.0;     // largest PGA scanned, in g (the scene's gravity)
  double tolerance_g = 0.001; // width of the final bisection bracket, in g
  int scan_points = 40;       // grid PGA = pga_max * k / scan_points, k = 1..scan_points
  double dt = 5e-4;           // solver step, s
};

// Throws InputError when a setting is out of range (non-finite, not positive, no points).
void validate(const SweepSettings& settings);

// Which events occurred in one simulation; indexed by SweepEvent.
struct Occurrences {
  std::array<bool, kSweepEventCount> occurred{};

  [[nodiscard]] bool operator[](SweepEvent e) const {
    return occurred[static_cast<std::size_t>(e)];
  }
};

// One simulation from rest under `record` scaled to a peak of `pga_mps2` (m/s2), with step
// settings.dt, until the record's end + 2 s or a terminal phase. Throws InputError when the
// record is all zeros or the step is too large for the scene.
[[nodiscard]] Occurrences simulate_occurrences(const Scene& scene, const Record& record,
                                               double pga_mps2, const SweepSettings& settings);

// For each event, the smallest PGA (in g) found at which it occurs, or nothing when it does not
// occur on the scan grid up to settings.pga_max_g. The search does not assume that an event
// keeps occurring above its threshold: the grid is scanned, the first grid interval where the
// event appears is bisected to settings.tolerance_g, and the result is checked once more:
// the event occurs at the reported value thr and does not occur at thr - tolerance (when
// thr - tolerance > 0); if it does, the search goes on below. No event is assumed at PGA 0.
// `simulations`, when given, is increased by the number of simulations run.
[[nodiscard]] std::array<std::optional<double>, kSweepEventCount> first_occurrence_thresholds(
    const Scene& scene, const Record& record, const SweepSettings& settings,
    std::size_t* simulations = nullptr);

// The scene parameters a sweep can vary (dimensionless where the paper's are).
enum class SweepParameter : unsigned char {
  kMuS,        // "mu_s": static friction; kinetic = 0.8 mu_s; adds [friction] when absent
  kEpsilon,    // "epsilon": eccentricity = epsilon b
  kLambda,     // "lambda": h = lambda b; mass and inertia follow (mass per unit height kept)
  kPeriod,     // "T": base period, s (needs a base)
  kXi,         // "xi": base damping ratio (needs a base)
  kUMax,       // "u_max": base stop gap, m (needs base stops)
  kMassRatio,  // "mass_ratio": m_b / m (needs a base)
};

[[nodiscard]] const char* sweep_parameter_name(SweepParameter parameter);

// Throws InputError("--param: unknown parameter 'x' (one of mu_s, epsilon, ...)").
[[nodiscard]] SweepParameter parse_sweep_parameter(const std::string& text);

// `params` with the parameter set to `value`, in SI. lambda keeps the block's mass per unit of
// height (m scales with h, I_C = homogeneous_rectangle_inertia) and the base's mass ratio.
// Throws InputError naming the parameter and the value when the scene has no base (T, xi,
// mass_ratio) or no base stops (u_max), or when make_scene refuses the result.
[[nodiscard]] SceneParams with_parameter(SceneParams params, SweepParameter parameter,
                                         double value);

// `steps` values from `from` to `to` inclusive, evenly spaced (one value: `from`). Throws
// InputError on steps < 1, non-finite bounds, or from > to.
[[nodiscard]] std::vector<double> sweep_values(double from, double to, int steps);

struct SweepRow {
  double value = 0.0;
  std::array<std::optional<double>, kSweepEventCount> thresholds_g;
};

struct SweepStats {
  std::size_t simulations = 0;
};

// Sweeps `parameter` over the values of shard `shard_index`/`shard_count` (1-based: the values
// whose index % shard_count == shard_index - 1) on `jobs` threads. Rows come back in value
// order and do not depend on jobs or sharding. Every value is checked (with_parameter) before
// any simulation runs. Throws InputError on bad jobs or shard numbers, bad values, and errors
// of the simulations (the one of the lowest value index).
[[nodiscard]] std::vector<SweepRow> run_sweep(const SceneParams& base, SweepParameter parameter,
                                              const std::vector<double>& values,
                                              const Record& record, const SweepSettings& settings,
                                              int jobs, int shard_index, int shard_count,
                                              SweepStats* stats = nullptr);

// CSV: header "<param>,sliding,rocking,...,overturned", one line per row; thresholds in g
// (%.6g), empty where the event does not occur up to pga_max.
void write_sweep_csv(std::ostream& out, SweepParameter parameter,
                     const std::vector<SweepRow>& rows);

}  // namespace plinth::host
