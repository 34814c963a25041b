#include "sweep_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "gnuplot.h"
#include "plinth/host/input_error.h"
#include "plinth/host/sweep_impulse.h"
#include "plinth/host/sweep_parameter.h"
#include "plinth/host/sweep_search.h"

namespace plinth::sim {
namespace {

using plinth::host::InputError;
using plinth::host::SweepTable;
using Field = std::optional<double>;

// Axis labels in gnuplot's enhanced text.
std::string axis_label(const std::string& name) {
  static const std::map<std::string, std::string> labels = {
      {"mu_s", "μ_s"}, {"epsilon", "ε = e/b"},   {"lambda", "λ = h/b"},   {"T", "T (s)"},
      {"xi", "ξ"},     {"u_max", "u_{max} (m)"}, {"mass_ratio", "m_b/m"}, {"impulse", "|I| (m/s)"}};
  const auto it = labels.find(name);
  return it == labels.end() ? name : it->second;
}

// "slide_rocking" -> "slide rocking" (an underscore would be a subscript).
std::string title_of(std::string name) {
  std::replace(name.begin(), name.end(), '_', ' ');
  return name;
}

// A gnuplot single-quoted string.
std::string quoted(const std::string& text) {
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

std::string number(double value) { return plinth::host::format_value(value); }

Field parse_field(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(value)) return std::nullopt;
  return value;
}

// The table as numbers (text fields become nothing); columns by header name.
struct Columns {
  std::vector<std::string> names;
  std::vector<std::vector<std::string>> text;  // [row][column]

  [[nodiscard]] std::size_t index(const std::string& name) const {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw InputError("plot: the CSV has no column '" + name + "'");
    return static_cast<std::size_t>(it - names.begin());
  }
  [[nodiscard]] Field at(std::size_t row, std::size_t column) const {
    return parse_field(text[row][column]);
  }
  // (first column, `column`) of every row; empty when `column` has no value at all.
  [[nodiscard]] std::vector<std::pair<double, Field>> curve(std::size_t column) const {
    std::vector<std::pair<double, Field>> points;
    bool any = false;
    for (std::size_t r = 0; r < text.size(); ++r) {
      if (const Field x = at(r, 0)) {
        points.emplace_back(*x, at(r, column));
        any = any || points.back().second.has_value();
      }
    }
    if (!any) points.clear();
    return points;
  }
};

Columns columns_of(const SweepTable& table) {
  Columns c;
  c.names = plinth::host::csv_fields(table.header);
  for (const std::string& row : table.rows) c.text.push_back(plinth::host::csv_fields(row));
  return c;
}

// A gnuplot script being built: datablocks first, then the plot, drawn once per terminal.
class Script {
 public:
  // Points (x, y); a missing y ends a line segment (a blank line in the datablock).
  void block(const std::string& name, const std::vector<std::pair<double, Field>>& points) {
    head_ << '$' << name << " << EOD\n";
    bool gap = false;
    for (const auto& [x, y] : points) {
      if (!y) {
        gap = true;
        continue;
      }
      if (gap) head_ << '\n';
      gap = false;
      head_ << number(x) << ' ' << number(*y) << '\n';
    }
    head_ << "EOD\n";
  }
  void raw_block(const std::string& name, const std::string& lines) {
    head_ << '$' << name << " << EOD\n" << lines << "EOD\n";
  }
  void line(const std::string& text) { body_ << text << '\n'; }
  // Panels side by side (set multiplot ... unset multiplot in the body): drawn once per
  // terminal, as replot would redraw the last panel only.
  void multiplot(const std::string& size) {
    multiplot_ = true;
    size_ = size;
  }

  [[nodiscard]] std::string text(const std::string& stem, const std::string& source) const {
    std::ostringstream out;
    const std::string name = comment_text(std::filesystem::path(stem).filename().string());
    out << "# Drawn by plinth-sweep from " << comment_text(source)
        << " (docs/sweep.md); file names are arguments: gnuplot -c " << name << ".gp " << name
        << ".png " << name << ".svg\n"
        << "set encoding utf8\n"
        << head_.str() << "set terminal pngcairo size " << size_ << " enhanced font 'sans,11'\n"
        << "set output ARG1\n"
        << body_.str() << "set terminal svg size " << size_ << " dynamic enhanced font 'sans,11'\n"
        << "set output ARG2\n"
        << (multiplot_ ? body_.str() : std::string("replot\n")) << "unset output\n";
    return out.str();
  }

 private:
  std::ostringstream head_;
  std::ostringstream body_;
  bool multiplot_ = false;
  std::string size_ = "960,640";
};

// A line style per curve: dash type, point type, colour (the paper's maps tell events apart
// by line style; colour helps on screen).
constexpr std::array<const char*, 8> kColours = {"#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd",
                                                 "#8c564b", "#e377c2", "#17becf", "#d62728"};
// `thin`: the same style with thin lines and small points, for the block on the ground (the
// paper draws the non-isolated system's curves thin).
std::string style(std::size_t k, std::size_t rows, bool thin = false) {
  const std::size_t every = std::max<std::size_t>(1, rows / 15);  // points that leave dashes seen
  return "dt " + std::to_string(k % 5 + 1) + " pt " + std::to_string(k + 4) + " pi " +
         std::to_string(every) + (thin ? " ps 0.6 lw 1" : " ps 1 lw 2") + " lc rgb '" +
         kColours[k % kColours.size()] + "'";
}

// The column of the block on the ground matching `name` ("rocking" -> "rocking_ground").
std::string ground_column(const std::string& name) {
  return name + plinth::host::kGroundSuffix;
}

bool has_column(const Columns& c, const std::string& name) {
  return std::find(c.names.begin(), c.names.end(), name) != c.names.end();
}

// Whether the block on the ground lacks the swept parameter (T, xi, u_max, mass_ratio): its
// thresholds are then the same for every value and drawn as points on the y axis.
bool ground_lacks(const std::string& parameter) {
  try {
    return plinth::host::parameter_needs_base(plinth::host::parse_sweep_parameter(parameter));
  } catch (const InputError&) {
    return false;
  }
}

// The x range of the first column, widened a little each side; the left end is where points
// on the axis go.
std::pair<double, double> x_range(const Columns& c) {
  double lo = INFINITY;
  double hi = -INFINITY;
  for (std::size_t r = 0; r < c.text.size(); ++r) {
    if (const Field x = c.at(r, 0)) {
      lo = std::min(lo, *x);
      hi = std::max(hi, *x);
    }
  }
  if (!(lo <= hi)) return {0.0, 1.0};
  const double pad = hi > lo ? 0.04 * (hi - lo) : 0.1 * std::max(std::fabs(lo), 1.0);
  return {lo - pad, hi + pad};
}

// A curve of the block on the ground: column "<name>_ground", drawn `thin` ("with lines ...")
// against a parameter the ground has, else as points on the y axis (`axis`: "pt 5 ps 2 ...").
struct GroundCurve {
  std::string name;
  std::string title;
  std::string thin;
  std::string axis;
};

// Adds the ground curves that have data to `plot` (after the scene's own), against a
// parameter the ground lacks at x = x_left. Returns whether any was drawn on the axis.
bool ground_curves(Script& s, const Columns& c, const std::vector<GroundCurve>& curves,
                   double x_left, std::string& plot) {
  const bool on_axis = ground_lacks(c.names[0]);
  bool drawn = false;
  for (const GroundCurve& curve : curves) {
    const std::string column = ground_column(curve.name);
    if (!has_column(c, column)) continue;
    auto points = c.curve(c.index(column));
    if (points.empty()) continue;  // never up to the scan's maximum
    if (on_axis) {
      for (auto& point : points) point.first = x_left;
    }
    s.block(column, points);
    plot += ", \\\n     $" + column + " using 1:2 " +
            (on_axis ? "with points " + curve.axis + " title " +
                           quoted(curve.title + ", on the ground (no base: on the axis)")
                     : curve.thin + " title " + quoted(curve.title + ", on the ground"));
    drawn = drawn || on_axis;
  }
  return drawn;
}

// A column an older plinth-sweep did not write (sweep_table.h, kAddedColumns).
bool added_later(const std::string& name) {
  return std::any_of(plinth::host::kAddedColumns.begin(), plinth::host::kAddedColumns.end(),
                     [&](const plinth::host::AddedColumn& a) { return name == a.name; });
}

void common_setup(Script& s, const std::string& title) {
  s.line("set title " + quoted(title));
  s.line("set grid lc rgb '#d0d0d0'");
  s.line("set key below");
  s.line("set border lw 1.2");
}

double setting_number(const std::map<std::string, std::string>& settings, const std::string& key,
                      double fallback) {
  const auto it = settings.find(key);
  if (it == settings.end()) return fallback;
  const Field value = parse_field(it->second);
  return value ? *value : fallback;
}

// One parameter: a curve per event, the region above the lowest collapse curve shaded.
void thresholds_plot(Script& s, const Columns& c,
                     const std::map<std::string, std::string>& settings) {
  const double pga_max = setting_number(settings, "pga_max_g", 2.0);
  std::vector<std::pair<double, Field>> collapse;
  for (std::size_t r = 0; r < c.text.size(); ++r) {
    const Field x = c.at(r, 0);
    if (!x) continue;
    Field lowest;
    for (const char* name : {"fell", "overturned"}) {
      const Field y = c.at(r, c.index(name));
      if (y && (!lowest || *y < *lowest)) lowest = y;
    }
    collapse.emplace_back(*x, lowest);
  }
  s.block("collapse", collapse);
  std::vector<std::string> curves;
  for (std::size_t e = 0; e < plinth::host::kSweepEventCount; ++e) {
    const std::string name = plinth::host::kSweepEventNames.entries[e].name;  // the CSV's order
    if (!has_column(c, name) && added_later(name)) continue;  // an older file: not searched
    const auto points = c.curve(c.index(name));
    if (points.empty()) continue;  // not up to pga_max anywhere: no entry in the key
    s.block(name, points);
    curves.push_back("$" + name + " using 1:2 with linespoints " + style(e, c.text.size()) +
                     " title " + quoted(title_of(name)));
  }
  std::string plot = "plot $collapse using 1:2:(" + number(pga_max) +
                     ") with filledcurves fc rgb '#d62728' fs transparent solid 0.12 noborder "
                     "title 'collapse: above the lowest of fell, overturned'";
  for (const std::string& curve : curves) plot += ", \\\n     " + curve;
  if (curves.empty()) plot += ", 1/0 notitle";
  // With --compare-ground: the block on the ground, thin (or on the axis).
  std::vector<GroundCurve> ground;
  for (std::size_t e = 0; e < plinth::host::kSweepEventCount; ++e) {
    const std::string name = plinth::host::kSweepEventNames.entries[e].name;
    ground.push_back({name, title_of(name), "with linespoints " + style(e, c.text.size(), true),
                      "pt " + std::to_string(e + 4) + " ps 2 lw 2 lc rgb '" +
                          kColours[e % kColours.size()] + "'"});
  }
  const auto [x_lo, x_hi] = x_range(c);
  const bool on_axis = ground_curves(s, c, ground, x_lo, plot);
  s.line("set xlabel " + quoted(axis_label(c.names[0])));
  s.line("set ylabel 'first-occurrence PGA (g)'");
  s.line("set yrange [0:" + number(pga_max) + "]");
  s.line("set offsets graph 0.02, graph 0.02, 0, 0");
  if (on_axis) {
    s.line("set xrange [" + number(x_lo) + ":" + number(x_hi) + "]");
    s.line("unset clip points");
  }
  s.line(plot);
}

// Two parameters: a heat map of one event's first-occurrence PGA; with --compare-ground, the
// block on the ground in a second panel beside it, on the same colour scale.
void threshold_map_plot(Script& s, const Columns& c,
                        const std::map<std::string, std::string>& settings,
                        const std::vector<plinth::host::GridAxis>& grid, const std::string& title) {
  const double pga_max = setting_number(settings, "pga_max_g", 2.0);
  const bool ground = c.names.size() > 3 && c.names[3] == ground_column(c.names[2]);
  std::string cells;
  std::string previous;
  for (std::size_t r = 0; r < c.text.size(); ++r) {
    const Field x = c.at(r, 0);
    const Field y = c.at(r, 1);
    if (!x || !y) continue;
    if (!previous.empty() && c.text[r][0] != previous) cells += '\n';  // a new scan line
    previous = c.text[r][0];
    cells += number(*x) + ' ' + number(*y);
    for (std::size_t column = 2; column < (ground ? 4U : 3U); ++column) {
      const Field z = c.at(r, column);
      cells += ' ' + (z ? number(*z) : std::string("NaN"));
    }
    cells += '\n';
  }
  s.raw_block("cells", cells);
  s.line("set xlabel " + quoted(axis_label(c.names[0])));
  s.line("set ylabel " + quoted(axis_label(c.names[1])));
  s.line("set cblabel " + quoted("first-occurrence PGA of " + title_of(c.names[2]) + " (g)"));
  s.line("set cbrange [0:" + number(pga_max) + "]");
  s.line("set palette defined (0 '#fde725', 0.35 '#21918c', 0.7 '#3b528b', 1 '#440154')");
  s.line(
      "set object 1 rectangle from graph 0,0 to graph 1,1 behind fc rgb '#e8e8e8' fs solid "
      "noborder");
  s.line("set key outside right bottom");
  s.line("set tics out");
  s.line("unset grid");
  s.line("set autoscale fix");
  const bool image = grid.size() == 2 && grid[0].steps >= 2 && grid[1].steps >= 2;
  const std::string style = image ? "with image" : "with points pt 5 ps 4 palette";
  const std::string none = ", 1/0 with boxes fs solid 1.0 border lc rgb '#999999' fc rgb "
                           "'#e8e8e8' title " +
                           quoted("grey: none up to " + number(pga_max) + " g");
  if (!ground) {
    s.line("plot $cells using 1:2:3 " + style + " notitle" + none);
    return;
  }
  s.multiplot("1280,560");
  // Fixed margins: both panels the same size, the key and the colour box in the margins.
  s.line("set multiplot layout 1,2 margins 0.06,0.88,0.17,0.88 spacing 0.08 title " +
         quoted(title));
  s.line("set key at screen 0.5,0.02 center bottom");
  s.line("set title 'isolated'");
  s.line("unset colorbox");  // the same scale as the panel on the right's
  s.line("plot $cells using 1:2:3 " + style + " notitle");
  s.line("set colorbox");
  s.line("set title " + quoted(ground_lacks(c.names[0]) || ground_lacks(c.names[1])
                                   ? "on the ground (no base: the same along a base parameter)"
                                   : "on the ground (no base)"));
  s.line("plot $cells using 1:2:4 " + style + " notitle" + none);
  s.line("unset multiplot");
}

// The (|I|, mu_s) plane: simulated starts as points, the closed-form curves over them.
void impulse_map_plot(Script& s, const Columns& c) {
  const std::size_t mu = c.index("mu_s");
  const std::size_t impulse = c.index("impulse");
  const std::size_t simulated = c.index("simulated");
  const std::size_t predicted = c.index("predicted");
  if (c.text.empty()) throw InputError("plot: the impulse map has no rows");
  const Field c_r = c.at(0, c.index("c_r"));
  const Field c_sr = c.at(0, c.index("c_sr"));
  double i_max = 0.0;
  double mu_max = 0.0;
  double slope = 0.0;             // C_S: mu_s per |I| (Eq 38)
  std::map<double, double> c_rs;  // |I| -> Eq 41
  for (std::size_t r = 0; r < c.text.size(); ++r) {
    const Field i = c.at(r, impulse);
    const Field m = c.at(r, mu);
    if (!i || !m) continue;
    i_max = std::max(i_max, *i);
    mu_max = std::max(mu_max, *m);
    if (const Field cs = c.at(r, c.index("c_s")); cs && *cs > 0.0) slope = *m / *cs;
    if (const Field rs = c.at(r, c.index("c_rs")); rs && c_r && *i >= *c_r) c_rs[*i] = *rs;
  }
  const auto starts = plinth::host::kImpulseStartNames.values();
  const std::array<const char*, 5> colours = {"#b0b0b0", "#1f77b4", "#ff7f0e", "#2ca02c",
                                              "#d62728"};
  const std::array<int, 5> points = {1, 5, 7, 9, 3};
  std::string plot = "plot ";
  std::string differ;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const std::string name = plinth::host::impulse_start_name(starts[k]);
    std::string lines;
    for (std::size_t r = 0; r < c.text.size(); ++r) {
      const Field i = c.at(r, impulse);
      const Field m = c.at(r, mu);
      if (c.text[r][simulated] != name || !i || !m) continue;  // numbers only reach the script
      const std::string point = number(*i) + ' ' + number(*m) + '\n';
      lines += point;
      if (c.text[r][predicted] != name) differ += point;
    }
    s.raw_block(name, lines.empty() ? "NaN NaN\n" : lines);
    plot += "$" + name + " using 1:2 with points pt " + std::to_string(points[k]) +
            " ps 1.1 lc rgb '" + colours[k] + "' title " + quoted("simulated: " + title_of(name)) +
            ", \\\n     ";
  }
  s.raw_block("differ", differ.empty() ? "NaN NaN\n" : differ);
  plot +=
      "$differ using 1:2 with points pt 6 ps 2 lw 1.5 lc rgb 'black' title "
      "'closed forms say otherwise'";
  if (c_r && c_sr) {
    // C_S up to C_R, C_R and C_SR from their meeting point, C_RS from it too (Eq 41 = b1/h
    // at the rocking threshold).
    const double top = 1.05 * mu_max;
    const double right = 1.05 * i_max;
    s.raw_block("c_s", "0 0\n" + number(std::min(*c_r, top / std::max(slope, 1e-12))) + " " +
                           number(std::min(*c_sr, top)) + "\n");
    s.raw_block(
        "c_r", number(*c_r) + " " + number(*c_sr) + "\n" + number(*c_r) + " " + number(top) + "\n");
    s.raw_block("c_sr", number(*c_r) + " " + number(*c_sr) + "\n" + number(right) + " " +
                            number(*c_sr) + "\n");
    std::string rs = number(*c_r) + " " + number(*c_sr) + "\n";
    for (const auto& [i, m] : c_rs) rs += number(i) + " " + number(m) + "\n";
    s.raw_block("c_rs", rs);
    plot += ", \\\n     $c_s with lines dt 1 lw 2.5 lc rgb 'black' title 'C_S (Eq 38)'";
    plot += ", \\\n     $c_r with lines dt 2 lw 2.5 lc rgb 'black' title 'C_R (Eq 37)'";
    plot += ", \\\n     $c_sr with lines dt 3 lw 2.5 lc rgb '#555555' title 'C_{SR} (Eq 39)'";
    plot += ", \\\n     $c_rs with lines dt 4 lw 2.5 lc rgb '#8b0000' title 'C_{RS} (Eq 41)'";
    s.line("set xrange [0:" + number(right) + "]");
    s.line("set yrange [0:" + number(top) + "]");
  }
  s.line("set xlabel " + quoted(axis_label("impulse")));
  s.line("set ylabel " + quoted(axis_label("mu_s")));
  s.line(plot);
}

// Impulse curves: simulated thresholds and closed forms against the parameter.
void impulse_curve_plot(Script& s, const Columns& c) {
  const std::array<const char*, 4> names = {"rocking", "overturned", "rocking_closed_form",
                                            "overturned_closed_form"};
  const std::array<const char*, 4> titles = {"rocking (simulated)", "overturned (simulated)",
                                             "rocking, closed form (Eq 37)",
                                             "overturned, closed form (energy)"};
  const std::array<std::string, 4> styles = {
      "with linespoints dt 1 pt 7 ps 0.8 lw 2 lc rgb '#ff7f0e'",
      "with linespoints dt 1 pt 5 ps 0.8 lw 2 lc rgb '#d62728'",
      "with lines dt 2 lw 2 lc rgb 'black'", "with lines dt 4 lw 2 lc rgb '#555555'"};
  std::string plot = "plot ";
  bool first = true;
  for (std::size_t k = 0; k < names.size(); ++k) {
    const auto points = c.curve(c.index(names[k]));
    if (points.empty()) continue;
    s.block(names[k], points);
    plot += std::string(first ? "" : ", \\\n     ") + "$" + names[k] + " using 1:2 " + styles[k] +
            " title " + quoted(titles[k]);
    first = false;
  }
  if (first) plot += "1/0 notitle";
  // With --compare-ground: the block on the ground, thin (or on the axis).
  const std::vector<GroundCurve> ground = {
      {"overturned", "overturned (simulated)",
       "with linespoints dt 1 pt 5 ps 0.5 lw 1 lc rgb '#d62728'", "pt 5 ps 2 lc rgb '#d62728'"},
      {"overturned_closed_form", "overturned, closed form (energy)",
       "with lines dt 4 lw 1 lc rgb '#555555'", "pt 6 ps 2 lw 2 lc rgb '#555555'"}};
  const auto [x_lo, x_hi] = x_range(c);
  const bool on_axis = ground_curves(s, c, ground, x_lo, plot);
  s.line("set xlabel " + quoted(axis_label(c.names[0])));
  s.line("set ylabel 'smallest impulse |I| (m/s)'");
  s.line("set yrange [0:*]");
  s.line("set offsets graph 0.02, graph 0.02, 0, 0");
  if (on_axis) {
    s.line("set xrange [" + number(x_lo) + ":" + number(x_hi) + "]");
    s.line("unset clip points");
  }
  s.line(plot);
}

}  // namespace

std::string plot_stem(const std::string& plot_path) {
  const std::filesystem::path p(plot_path);
  const std::string ext = p.extension().string();
  if (ext != ".png" && ext != ".svg") {
    throw InputError(
        "--plot: expected a file name ending in .png or .svg (both are written), "
        "got '" +
        plot_path + "'");
  }
  return (p.parent_path() / p.stem()).string();
}

std::string gnuplot_script(const SweepTable& table, const std::string& stem) {
  const auto settings = plinth::host::parse_settings(table.settings, "plot");
  const auto grid = plinth::host::parse_grid(table.settings, "plot");
  const Columns c = columns_of(table);
  const std::string& mode = settings.at("mode");
  Script s;
  if (mode == "thresholds") {
    common_setup(s, "First occurrence of each event against " + axis_label(c.names[0]));
    thresholds_plot(s, c, settings);
  } else if (mode == "threshold_map") {
    const std::string title = "First occurrence of " + title_of(c.names[2]) + " against " +
                              axis_label(c.names[0]) + " and " + axis_label(c.names[1]);
    common_setup(s, title);
    threshold_map_plot(s, c, settings, grid, title);
  } else if (mode == "impulse_map") {
    common_setup(s, "Motion an impulse starts with (section 5.3.1): simulation and closed forms");
    impulse_map_plot(s, c);
  } else if (mode == "impulse_curve") {
    common_setup(
        s, "Smallest impulses that start rocking and overturn, against " + axis_label(c.names[0]));
    impulse_curve_plot(s, c);
  } else {
    throw InputError("plot: unknown sweep mode '" + mode + "'");
  }
  return s.text(stem, std::filesystem::path(stem).filename().string() + " data");
}

std::string plot_sweep(const SweepTable& table, const std::string& plot_path) {
  (void)find_gnuplot();
  const std::vector<const plinth::host::AddedColumn*> added =
      plinth::host::columns_added_since(table);
  if (!added.empty()) {
    std::fprintf(stderr, "plinth-sweep: note: the CSV was %s; plotted without it: %s\n",
                 plinth::host::older_version_text(added).c_str(), added.front()->why);
  }
  const std::string stem = plot_stem(plot_path);
  const std::string script_path = stem + ".gp";
  {
    std::ofstream out(script_path);
    out << gnuplot_script(table, stem);
    if (!out.flush()) throw InputError(script_path + ": cannot write the gnuplot script");
  }
  run_gnuplot(script_path, {stem + ".png", stem + ".svg"});
  for (const char* ext : {".png", ".svg"}) {
    if (!std::filesystem::exists(stem + ext)) {
      throw InputError("gnuplot did not write " + stem + ext);
    }
  }
  return stem + ".png and " + stem + ".svg";
}

}  // namespace plinth::sim
