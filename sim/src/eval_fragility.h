// plinth-eval fragility: per scene, the lognormal fragility P(collapse | PGA) of its true statues,
// fitted by maximum likelihood (host::fit_lognormal_fragility) over its cases' collapse
// intensities as the runs file's grid tells them, with the empirical fraction collapsed at each
// grid point (docs/forecast.md).
#pragma once

#include <string>
#include <vector>

#include "plinth/host/eval_metrics.h"
#include "plinth/host/fragility_fit.h"

namespace plinth::sim {

// What a case's collapse intensity is taken to be, from its lowest collapsing PGA on the grid:
// kInterval, above the grid point below it and at most it (interval-censored; default);
// kGridPoint, exactly it (as a coarse incremental dynamic analysis reads it: biased upwards by
// up to one grid step). A case that never collapses is right-censored at its grid's top in both.
enum class CollapseIntensityRule { kInterval, kGridPoint };
[[nodiscard]] bool parse_collapse_intensity(const std::string& text, CollapseIntensityRule& rule);
[[nodiscard]] const char* collapse_intensity_name(CollapseIntensityRule rule);

// The fraction of a scene's cases that collapsed at or below a PGA of their grid.
struct EmpiricalPoint {
  double pga_g = 0.0;
  int cases = 0;      // cases whose grid has this point
  int collapsed = 0;  // of those, the ones whose lowest collapsing PGA is at most pga_g
};

struct SceneFragility {
  std::string scene;
  host::FragilityFit fit;
  double top_g = 0.0;  // the highest grid top of its cases, g (where the survivors are censored)
  std::vector<EmpiricalPoint> points;
};

// Per scene (in the order the scenes first appear). Throws InputError when the file records no
// grid (an earlier plinth-eval) or its cases' rows are not their grid's (host::eval_cases).
[[nodiscard]] std::vector<SceneFragility> scene_fragilities(const host::EvalTable& table,
                                                            const std::string& path,
                                                            CollapseIntensityRule rule);

[[nodiscard]] std::string fragility_text(const std::vector<SceneFragility>& scenes,
                                         CollapseIntensityRule rule);
// A list of {"scene", "median_g", "beta", "cases", "collapsed", ...} (null median and beta with a
// "no_fit" reason when the scene allows no fit).
[[nodiscard]] std::string fragility_json(const std::vector<SceneFragility>& scenes,
                                         CollapseIntensityRule rule);

// The fitted curves and the empirical points as a PNG (gnuplot, as plot_roc: a private folder,
// scene names reduced to plain characters in the legend). Throws InputError when gnuplot is
// missing or fails.
void plot_fragility(const std::vector<SceneFragility>& scenes, const std::string& png_path);

}  // namespace plinth::sim
