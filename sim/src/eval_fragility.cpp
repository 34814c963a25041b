#include "eval_fragility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>

#include "gnuplot.h"
#include "plinth/host/input_error.h"
#include "plinth/host/json_text.h"

namespace plinth::sim {
namespace {

using host::CollapseIntensity;
using host::EvalCaseRows;
using host::InputError;

std::string number(double v, int digits) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

std::string g_text(double v) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", v);
  return buffer;
}

CollapseIntensity intensity_of(const EvalCaseRows& c, CollapseIntensityRule rule) {
  if (c.first_collapse < 0) return {c.grid.top_g(), std::numeric_limits<double>::infinity()};
  const double at = c.grid.at(c.first_collapse);
  if (rule == CollapseIntensityRule::kGridPoint) return {at, at};
  return {c.first_collapse > 0 ? c.grid.at(c.first_collapse - 1) : 0.0, at};
}

// A legend entry: letters, digits and . _ - + ( ) and spaces kept, anything else '?', so that the
// single-quoted gnuplot string holds no quote (and noenhanced reads no markup).
std::string legend_text(const std::string& name) {
  std::string out;
  for (const char c : name) {
    const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                       c == '.' || c == '_' || c == '-' || c == '+' || c == '(' || c == ')' ||
                       c == ' ';
    out += plain ? c : '?';
  }
  return out;
}

}  // namespace

bool parse_collapse_intensity(const std::string& text, CollapseIntensityRule& rule) {
  if (text == "interval" || text == "grid") {
    rule = text == "grid" ? CollapseIntensityRule::kGridPoint : CollapseIntensityRule::kInterval;
    return true;
  }
  return false;
}

const char* collapse_intensity_name(CollapseIntensityRule rule) {
  return rule == CollapseIntensityRule::kGridPoint ? "grid" : "interval";
}

std::vector<SceneFragility> scene_fragilities(const host::EvalTable& table, const std::string& path,
                                              CollapseIntensityRule rule) {
  if (!table.has_grid) {
    throw InputError(path + ": no seed and pga grid columns (written by a plinth-eval before the "
                            "collapse margin): a fragility needs each case's grid; run plinth-eval "
                            "run again");
  }
  std::vector<std::string> order;
  std::map<std::string, std::vector<CollapseIntensity>> intensities;
  std::map<std::string, std::map<double, EmpiricalPoint>> points;
  std::map<std::string, double> top;
  for (const EvalCaseRows& c : host::eval_cases(table.runs, path)) {
    if (intensities.find(c.scene) == intensities.end()) order.push_back(c.scene);
    intensities[c.scene].push_back(intensity_of(c, rule));
    top[c.scene] = std::max(top[c.scene], c.grid.top_g());
    for (int i = 0; i < c.grid.steps; ++i) {
      const double x = c.grid.at(i);
      EmpiricalPoint& p = points[c.scene][std::round(x * 1e6) / 1e6];
      p.pga_g = x;
      ++p.cases;
      p.collapsed += c.first_collapse >= 0 && c.first_collapse <= i ? 1 : 0;
    }
  }
  std::vector<SceneFragility> scenes;
  for (const std::string& scene : order) {
    SceneFragility s;
    s.scene = scene;
    s.fit = host::fit_lognormal_fragility(intensities[scene]);
    s.top_g = top[scene];
    for (const auto& [key, p] : points[scene]) s.points.push_back(p);
    scenes.push_back(std::move(s));
  }
  return scenes;
}

std::string fragility_text(const std::vector<SceneFragility>& scenes, CollapseIntensityRule rule) {
  std::string out =
      "plinth-eval fragility: P(collapse | PGA) = Phi(ln(PGA / median) / beta) per scene, maximum "
      "likelihood; a case's collapse intensity " +
      std::string(rule == CollapseIntensityRule::kInterval
                      ? "lies between the grid point below its lowest collapsing PGA and that PGA"
                      : "is its lowest collapsing PGA on the grid") +
      " (--collapse-intensity " + collapse_intensity_name(rule) +
      "); a case that never collapses is censored at its grid's top\n";
  for (const SceneFragility& s : scenes) {
    const host::FragilityFit& f = s.fit;
    out += s.scene + ": ";
    if (f.fitted()) {
      out += "median " + number(f.curve.median_g, 3) + " g (95 % " +
             number(f.median_ci95_low_g, 3) + " to " + number(f.median_ci95_high_g, 3) +
             " g), beta " + number(f.curve.beta, 3) + " (se " + number(f.beta_se, 3) + "); ";
    } else {
      out += "no fit: " + f.no_fit + "; ";
    }
    out += std::to_string(f.cases) + " cases, " + std::to_string(f.collapsed) + " collapsed, " +
           std::to_string(f.cases - f.collapsed) + " stood up to " + g_text(s.top_g) + " g\n";
  }
  return out;
}

std::string fragility_json(const std::vector<SceneFragility>& scenes, CollapseIntensityRule rule) {
  std::string out = "[";
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const SceneFragility& s = scenes[k];
    const host::FragilityFit& f = s.fit;
    const auto fitted = [&f](const std::string& value) { return f.fitted() ? value : "null"; };
    std::string ci95 = "[";
    ci95 += number(f.median_ci95_low_g, 5) + ", " + number(f.median_ci95_high_g, 5) + "]";
    out += k ? ",\n " : "";
    out += "{\"scene\": " + host::json_quoted(s.scene) + ", \"median_g\": " +
           fitted(number(f.curve.median_g, 5)) + ", \"beta\": " + fitted(number(f.curve.beta, 5)) +
           ", \"cases\": " + std::to_string(f.cases) + ", \"collapsed\": " +
           std::to_string(f.collapsed) + ", \"censored_at_g\": " + number(s.top_g, 5) +
           ", \"median_ci95_g\": " +
           fitted(ci95) +
           ", \"beta_se\": " + fitted(number(f.beta_se, 5)) + ", \"log_likelihood\": " +
           fitted(number(f.log_likelihood, 4)) + ", \"collapse_intensity\": " +
           host::json_quoted(collapse_intensity_name(rule)) + ", \"no_fit\": " +
           (f.fitted() ? "null" : host::json_quoted(f.no_fit)) + ", \"points\": [";
    for (std::size_t i = 0; i < s.points.size(); ++i) {
      const EmpiricalPoint& p = s.points[i];
      out += (i ? ", " : "") + std::string("{\"pga_g\": ") + number(p.pga_g, 5) +
             ", \"cases\": " + std::to_string(p.cases) + ", \"collapsed\": " +
             std::to_string(p.collapsed) + "}";
    }
    out += "]}";
  }
  return out + "]\n";
}

void plot_fragility(const std::vector<SceneFragility>& scenes, const std::string& png_path) {
  const PlotFolder folder;
  double top = 0.0;
  for (const SceneFragility& s : scenes) top = std::max(top, s.top_g);
  const double x_max = 1.1 * top;
  constexpr int kCurvePoints = 200;
  std::string plots;
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const SceneFragility& s = scenes[k];
    const std::string id = std::to_string(k);
    const std::string colour = " lc " + std::to_string(k + 1);
    {
      std::ofstream points(folder.path("points" + id + ".dat"));
      for (const EmpiricalPoint& p : s.points) {
        points << p.pga_g << ' ' << static_cast<double>(p.collapsed) / p.cases << '\n';
      }
      if (!points) throw InputError("--plot: cannot write the plot's data");
    }
    const std::string name = legend_text(s.scene);
    plots += (plots.empty() ? "" : ", ") + std::string("'") + folder.path("points" + id + ".dat") +
             "' using 1:2 with points pt 7" + colour + " title '" + name +
             (s.fit.fitted() ? ", collapsed by then'" : " (no fit), collapsed by then'");
    if (!s.fit.fitted()) continue;
    {
      std::ofstream curve(folder.path("fit" + id + ".dat"));
      for (int i = 1; i <= kCurvePoints; ++i) {
        const double x = x_max * i / kCurvePoints;
        curve << x << ' ' << s.fit.curve.probability(x) << '\n';
      }
      if (!curve) throw InputError("--plot: cannot write the plot's data");
    }
    plots += ", '" + folder.path("fit" + id + ".dat") + "' using 1:2 with lines lw 2" + colour +
             " title 'lognormal: median " + number(s.fit.curve.median_g, 2) + " g, beta " +
             number(s.fit.curve.beta, 2) + "'";
  }
  {
    std::ofstream gp(folder.path("fragility.gp"));
    gp << "set terminal pngcairo size 900,600 font ',11' noenhanced\n"
       << "set output '" << folder.path("fragility.png") << "'\n"
       << "set title 'plinth-eval: fragility of the true statues, per scene'\n"
       << "set xlabel 'PGA, g'\nset ylabel 'P(collapse)'\n"
       << "set xrange [0:" << x_max << "]\nset yrange [0:1.05]\n"
       << "set grid\nset key bottom right\n"
       << "plot " << plots << "\n";
    if (!gp) throw InputError("--plot: cannot write the gnuplot script");
  }
  folder.draw("fragility.gp", "fragility.png", png_path);
}

}  // namespace plinth::sim
