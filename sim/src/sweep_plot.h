// Plots of plinth-sweep's CSV files with gnuplot (Debian package gnuplot-nox): a PNG and an
// SVG of the same stem, and the gnuplot script that drew them (<stem>.gp), in the paper's
// conventions (docs/sweep.md).
#pragma once

#include <string>

#include "gnuplot.h"
#include "plinth/host/sweep_table.h"

namespace plinth::sim {

// The stem of a --plot argument ("map.png" -> "map"); throws InputError unless it ends with
// .png or .svg.
[[nodiscard]] std::string plot_stem(const std::string& plot_path);

// The gnuplot script that draws `table` into <stem>.png and <stem>.svg. Throws InputError when
// the table's mode or rows cannot be plotted.
[[nodiscard]] std::string gnuplot_script(const plinth::host::SweepTable& table,
                                         const std::string& stem);

// Writes <stem>.gp and runs gnuplot on it (the image names as ARG1, ARG2: gnuplot.h); throws
// InputError when gnuplot is missing or fails. Returns the two images' names ("map.png and
// map.svg").
std::string plot_sweep(const plinth::host::SweepTable& table, const std::string& plot_path);

}  // namespace plinth::sim
