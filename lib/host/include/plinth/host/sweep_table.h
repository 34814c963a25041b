// The CSV files of plinth-sweep (docs/sweep.md): a settings line, a header, one row per job of
// the sweep's grid in grid order. Two files with the same settings line hold the same rows for
// the same keys, whatever threads or shards made them; that is what resuming and merging check.
#pragma once

#include <array>
#include <cstddef>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/host/record_io.h"

namespace plinth::host {

// %.10g: parameter values, as written in the keys of the rows and in messages.
[[nodiscard]] std::string format_value(double value);
// %.6g: results (thresholds in g, impulses in m/s); empty when there is none.
[[nodiscard]] std::string format_result(const std::optional<double>& value);

// 16 hex digits (FNV-1a over the bit patterns) identifying a scene's parameters or a record's
// samples, so that runs on other machines with other paths compare equal.
[[nodiscard]] std::string fingerprint(const SceneParams& params);
[[nodiscard]] std::string fingerprint(const Record& record);

// `steps` values from `from` to `to` inclusive, evenly spaced (one value: `from`). Throws
// InputError naming the options <prefix>from<suffix>, <prefix>to<suffix> and
// <prefix>steps<suffix> ("--from2", "--mu-steps") on steps < 1, non-finite bounds, or
// from > to.
[[nodiscard]] std::vector<double> sweep_values(double from, double to, int steps,
                                               const std::string& prefix = "--",
                                               const std::string& suffix = "");

// One axis of a sweep's grid: `steps` values of parameter `name` from `from` to `to`.
struct GridAxis {
  std::string name;
  double from = 0.0;
  double to = 0.0;
  int steps = 1;
};

// The first line of every file: "# plinth-sweep <mode> grid=<name>:<from>:<to>:<steps>[,...]
// key=value ..." with every setting the rows depend on (not threads or shards).
class SettingsLine {
 public:
  SettingsLine(const std::string& mode, const std::vector<GridAxis>& grid);
  SettingsLine& add(const std::string& key, const std::string& value);
  SettingsLine& add(const std::string& key, double value) { return add(key, format_value(value)); }
  [[nodiscard]] const std::string& text() const { return text_; }

 private:
  std::string text_;
};

// The settings of a settings line as key -> value ("mode" and "grid" included). Throws
// InputError naming `where` when the line is not a plinth-sweep settings line.
[[nodiscard]] std::map<std::string, std::string> parse_settings(const std::string& line,
                                                                const std::string& where);

// What differs between two settings lines, for messages: "compare: ground in a.csv, none in
// b.csv; tol_g: 0.05 in a.csv, 0.1 in b.csv" (keys in order; "none" where a line lacks the
// key; the mode and grid as keys "mode" and "grid"). Empty when they hold the same settings
// or one is not a settings line.
[[nodiscard]] std::string settings_difference(const std::string& a, const std::string& a_name,
                                              const std::string& b, const std::string& b_name);

// The grid of a settings line and the key of each of its rows, in grid order (the first axis
// varies slowest). Throws InputError naming `where` on a malformed grid.
[[nodiscard]] std::vector<GridAxis> parse_grid(const std::string& line, const std::string& where);
[[nodiscard]] std::vector<std::string> grid_keys(const std::vector<GridAxis>& grid);

// A plinth-sweep CSV file in memory.
struct SweepTable {
  std::string settings;           // the settings line
  std::string header;             // the CSV header
  std::vector<std::string> rows;  // CSV lines without their newline
};

// The comma-separated fields of a CSV row or header; an empty last field counts ("0.3,," has
// three).
[[nodiscard]] std::vector<std::string> csv_fields(const std::string& row);

// The key of a row: its first `key_columns` comma-separated fields.
[[nodiscard]] std::string row_key(const std::string& row, std::size_t key_columns);

// A sweep CSV is read whole; longer than this it is refused (text_file.h).
inline constexpr std::size_t kMaxSweepTableBytes = std::size_t{256} << 20;  // 256 MiB

// Reads a table. Throws InputError naming the file (and line) when it cannot be read (also a
// directory, a FIFO, a device, or longer than kMaxSweepTableBytes), lacks the settings line
// or header, holds a number that is not finite, or a negative number in a result column
// (after the grid's key columns), or a row has another number of fields than the header; when
// `dropped` is given, such rows (cut short by a kill) are skipped and counted instead.
[[nodiscard]] SweepTable read_sweep_table(const std::string& path, std::size_t* dropped = nullptr);

// A column plinth-sweep added to the files of some modes after files without it were written:
// a file of such a mode without the column is an older plinth-sweep's. It can still be read
// and plotted (the column's curve is left out), merged with its own shards, but not resumed:
// its rows are not what this version computes (`why`).
struct AddedColumn {
  const char* name;
  std::array<const char*, 2> modes;  // the settings line's modes whose files have it
  const char* since;                 // the version that added it
  const char* why;                   // why an older file's rows cannot be resumed
};
inline constexpr std::array<AddedColumn, 1> kAddedColumns{{
    {"lift_off",
     {"thresholds", "impulse_curve"},
     "plinth 0.1.0 from commit 4a3615a of 2026-11-28, when lift-off began to end a run",
     "its runs went on past lift-off, where this version's end"},
}};

// The columns of kAddedColumns that `table` (its settings line's mode) lacks: empty unless an
// older plinth-sweep wrote it.
[[nodiscard]] std::vector<const AddedColumn*> columns_added_since(const SweepTable& table);
// "written by a plinth-sweep older than its lift_off column (plinth 0.1.0 from ...)", for
// messages about such a table; "" when it lacks none.
[[nodiscard]] std::string older_version_text(const std::vector<const AddedColumn*>& missing);

// Writes the settings line, the header and the rows, each ended by '\n'.
void write_sweep_table(std::ostream& out, const SweepTable& table);

// Joins the tables of the shards of one sweep (`names` name them in messages): their settings
// lines and headers must be identical (a shard an older plinth-sweep wrote is named as such), no key may appear twice, and together they must hold
// every key of the grid; the result is in grid order. Throws InputError naming the files and
// keys at fault.
[[nodiscard]] SweepTable merge_sweep_tables(const std::vector<SweepTable>& parts,
                                            const std::vector<std::string>& names);

// `rows` placed at the index of their key in `keys` (the grid's keys, or a shard's), "" where
// no row has that key. Throws InputError naming `where` and the key when a row's key is not
// among `keys` or appears twice.
[[nodiscard]] std::vector<std::string> place_rows(const std::vector<std::string>& rows,
                                                  const std::vector<std::string>& keys,
                                                  std::size_t key_columns,
                                                  const std::string& where);

}  // namespace plinth::host
