// Reading recorded ground accelerations: PEER NGA AT2 files and two-column CSV files.
#pragma once

#include <string>
#include <vector>

#include "plinth/core/excitation.h"

namespace plinth::host {

// A uniformly sampled ground acceleration record, owned, in m/s2.
struct Record {
  std::string name;                // AT2 line 2, e.g. "Irpinia Italy-01, 11/23/1980, Brienza, 0"; CSV: file stem
  double dt = 0.0;                 // s, > 0
  std::vector<double> horizontal;  // m/s2, finite, first sample at t = 0
  std::vector<double> vertical;    // m/s2, empty when the file has none

  [[nodiscard]] double duration() const;  // (n - 1) dt, s
  [[nodiscard]] double peak_horizontal() const;  // max |a|, m/s2
  [[nodiscard]] SampledSignal horizontal_signal() const;
  [[nodiscard]] SampledSignal vertical_signal() const;
};

// PEER NGA-West2 AT2: 4 header lines (units g; NPTS and DT read with a pattern from line 4),
// then NPTS values. Throws InputError naming the file and line for: missing file, unreadable
// header, NPTS or DT missing or non-positive, a value that is not a number or not finite,
// fewer or more values than NPTS.
[[nodiscard]] Record read_at2(const std::string& path, double gravity);

// Two-column CSV: a header line "t,<name> [unit]" with unit one of g, m/s2, cm/s2 (gal), then
// rows "time,acceleration". A third column "v [unit]" adds vertical acceleration. Times must
// start at 0 and be uniformly spaced (relative tolerance 1e-6). Lines starting with '#' are
// comments. Throws InputError naming file and line on any problem.
[[nodiscard]] Record read_csv_record(const std::string& path, double gravity);

// Dispatches on the extension: .AT2/.at2 -> read_at2, .csv -> read_csv_record.
[[nodiscard]] Record read_record(const std::string& path, double gravity);

}  // namespace plinth::host
