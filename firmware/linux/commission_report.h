// plinth-commission's report (docs/commissioning.md): the JSON a box reads at start and a
// person reads later, the picture (gnuplot) and the terminal's summary; the reports' names in the
// recorder's folder (commission-NNN.json, .png, .log beside the captures). Host code: allocates
// and throws.
#pragma once

#include <string>
#include <vector>

#include "commission_checks.h"
#include "commission_settings.h"

namespace plinth::firmware {

// What the report says besides the checks.
struct ReportContext {
  std::string version;   // kVersionText
  std::string time_utc;  // when the check ended, ISO 8601
  std::string box_file;  // the box file's path as given
  std::string box_file_sha256;
  std::string mounting_sha256;  // mounting_sha256(config)
  std::string interface_name;   // live: the CAN interface
  std::string log_path;         // a log's review: the log, and its SHA-256
  std::string log_sha256;
  std::string record_name;   // the session's frames kept beside the report ("" none)
  std::string picture_name;  // the picture beside the report ("" none)
  std::string picture_note;  // why there is no picture
  CommissioningSettings settings;
  double sample_rate_hz = 200.0;
  int axis_count = 1;
};

// The report: {"type": "commissioning", "format": 1, "result": "pass" | "fail", ...}.
[[nodiscard]] std::string report_json(const CommissionResult& result, const ReportContext& context);

// The summary a custodian reads on the terminal: the verdict, each failure, the notes.
[[nodiscard]] std::string summary_text(const CommissionResult& result);

// The picture as PNG bytes: one panel per sensor heard, the raise of its +x and +y sides over
// the session (and the statue sensor's gyroscope over each raise), each step's window shaded
// green (passed) or red (failed). gnuplot runs in a private folder on fixed file names; its only
// inputs are numbers, the program's own labels and `title` reduced to plain characters. Empty
// with `error` set when gnuplot is missing or fails.
[[nodiscard]] std::string draw_picture(const CommissionResult& result, const std::string& title,
                                       std::string& error);

// Reports in a folder: commission-<index>.json (at least three digits).
[[nodiscard]] std::string report_stem(int index);
// The index of the highest commission-NNN.json in `directory` (0: none; the folder unreadable
// or missing: 0 too).
[[nodiscard]] int newest_report_index(const std::string& directory);

// Writes `text` to `directory`/`name` whole or not at all, as the recorder writes its captures
// (docs/monitor.md, "Event recorder"): into ".name.partial" (created afresh), flushed (fsync),
// renamed, the folder flushed. Never over an existing file: false with `error` saying so, as for
// any failed step (the partial file is then removed).
[[nodiscard]] bool write_report_file(const std::string& directory, const std::string& name,
                                     const std::string& text, std::string& error);

// ISO 8601 UTC of the wall clock now: "2025-05-12T09:41:07Z".
[[nodiscard]] std::string utc_now();

}  // namespace plinth::firmware
