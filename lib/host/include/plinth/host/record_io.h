// Reading recorded ground accelerations: every PEER AT2 header layout, ESM/ITACA ASCII files and
// two-column CSV files. The formats, their variants and the limits: docs/record-formats.md.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "plinth/core/excitation.h"

namespace plinth::host {

// A uniformly sampled ground acceleration record, owned, in m/s2.
struct Record {
  std::string name;  // AT2 line 2, e.g. "Irpinia Italy-01, 11/23/1980, Brienza, 0"; ESM: event,
                     // date, network.station, stream; CSV: file stem
  double dt = 0.0;                 // s, > 0
  std::vector<double> horizontal;  // m/s2, finite, first sample at t = 0
  std::vector<double> vertical;    // m/s2, empty when the file has none

  [[nodiscard]] double duration() const;  // (n - 1) dt, s
  [[nodiscard]] double peak_horizontal() const;  // max |a|, m/s2
  [[nodiscard]] SampledSignal horizontal_signal() const;
  [[nodiscard]] SampledSignal vertical_signal() const;
};

// What a record file may hold. Beyond these a file is refused with the limit in the message:
// nothing a file says can make a reader (or the run it feeds) allocate or loop without bound.
inline constexpr std::size_t kMaxRecordFileBytes = std::size_t{64} << 20;  // 64 MiB
inline constexpr std::size_t kMaxRecordSamples = 4'000'000;                // per component
inline constexpr double kMinRecordDt = 1e-5;                               // s (100 kHz)
inline constexpr double kMaxRecordDt = 1.0;                                // s
inline constexpr double kMaxRecordDuration = 3.0 * 3600.0;                 // s, (n - 1) dt
inline constexpr double kMaxRecordAccelerationG = 100.0;  // g: no accelerogram holds more

enum class RecordFormat : unsigned char {
  kAt2,  // PEER strong-motion database (NGA-West2, NGA-West1, pre-NGA), acceleration in g
  kEsm,  // ESM / ITACA ASCII ("KEY: value" header, SAMPLING_INTERVAL_S, NDATA, UNITS)
  kCsv,  // "t,<name> [unit][,v [unit]]" then rows
};

[[nodiscard]] const char* record_format_name(RecordFormat format);

// The format the text's first lines show, nullopt when they show none of the three.
[[nodiscard]] std::optional<RecordFormat> detect_record_format(std::string_view text);

// Parses a whole record file's text; `origin` names it in messages ("<origin>:<line>: ...")
// and gives a CSV record its name. Throws InputError on anything the format does not allow.
[[nodiscard]] Record parse_record(std::string_view text, RecordFormat format,
                                  const std::string& origin, double gravity);

// PEER AT2: 4 header lines. Line 2 is the name; line 3 says ACCELERATION ... IN UNITS OF G
// (pre-NGA files add ". FILTER POINTS: ..."); line 4 holds NPTS and DT in any published layout
// ("NPTS=  5372, DT=   .0100 SEC,", "NPTS =   7500 , DT =   .020 SEC ,", "NPTS=  12000,
// dt=  .00500", "4096    0.0100    NPTS, DT"). Then NPTS values. Throws InputError naming the
// file and line for: a missing, unreadable or oversized file, a velocity or displacement file,
// units that are not an acceleration, NPTS or DT missing or out of the limits above, a value
// that is not a finite number or beyond kMaxRecordAccelerationG, fewer or more values than NPTS.
[[nodiscard]] Record read_at2(const std::string& path, double gravity);

// ESM / ITACA ASCII: "KEY: value" header lines (SAMPLING_INTERVAL_S, NDATA and UNITS required;
// DATA_TYPE, when given, must be ACCELERATION), then NDATA values, one per line. UNITS cm/s^2
// (as ESM writes), m/s^2 or g. Errors as for read_at2, naming the header key's line.
[[nodiscard]] Record read_esm(const std::string& path, double gravity);

// Two-column CSV: a header line "t,<name> [unit]" with unit one of g, m/s2, cm/s2 (gal), then
// rows "time,acceleration". A third column "v [unit]" adds vertical acceleration. Times must
// start at 0 and be uniformly spaced (relative tolerance 1e-6). Lines starting with '#' are
// comments. Throws InputError naming file and line on any problem.
[[nodiscard]] Record read_csv_record(const std::string& path, double gravity);

// Reads any of the three, recognised from the content (detect_record_format); the extension
// (.AT2, .ASC, .csv, any case) decides only when the content shows no format.
[[nodiscard]] Record read_record(const std::string& path, double gravity);

}  // namespace plinth::host
