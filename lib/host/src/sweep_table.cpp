#include "plinth/host/sweep_table.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <ostream>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "plinth/host/csv_line.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/text_file.h"

namespace plinth::host {
namespace {

constexpr const char* kSettingsPrefix = "# plinth-sweep ";

// FNV-1a, 64 bits, over the bit patterns of a sequence of doubles.
class Fnv1a {
 public:
  Fnv1a& add(double value) {
    auto bits = std::bit_cast<std::uint64_t>(value);
    for (int i = 0; i < 8; ++i) {
      hash_ = (hash_ ^ (bits & 0xffU)) * 0x100000001b3ULL;
      bits >>= 8;
    }
    return *this;
  }
  Fnv1a& add(bool flag) { return add(flag ? 1.0 : 0.0); }
  [[nodiscard]] std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash_));
    return text;
  }

 private:
  std::uint64_t hash_ = 0xcbf29ce484222325ULL;
};

std::size_t count_fields(const std::string& line) {
  std::size_t fields = 1;
  for (const char c : line) fields += c == ',' ? 1 : 0;
  return fields;
}

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  if (!text.empty() && text.back() == separator) parts.emplace_back();
  return parts;
}

// The fields of a CSV line as a spreadsheet may have saved them: quoted (split_csv), with
// spaces and tabs around them, which are not part of them.
std::vector<std::string> spreadsheet_fields(const std::string& line) {
  std::vector<std::string> fields;
  if (!split_csv(line, fields)) fields = split(line, ',');  // an unterminated quote: as it is
  for (std::string& field : fields) {
    const std::size_t first = field.find_first_not_of(" \t");
    const std::size_t last = field.find_last_not_of(" \t");
    field = first == std::string::npos ? std::string() : field.substr(first, last - first + 1);
  }
  return fields;
}

std::string join_fields(const std::vector<std::string>& fields, std::size_t count) {
  std::string out;
  for (std::size_t i = 0; i < count && i < fields.size(); ++i) {
    if (i > 0) out += ',';
    out += fields[i];
  }
  return out;
}

// A line of a sweep file as plinth-sweep writes it, from the line as saved by another program:
// its fields unquoted and trimmed; the empty fields a spreadsheet pads short lines with
// dropped (never below `keep` fields); a number in a key column (one of the first
// `key_columns`) as format_value writes it, in another column as format_result does ("0.50"
// and "5.0E-01" are 0.5). Other text is kept as it is.
std::string canonical_line(const std::string& line, std::size_t keep, std::size_t key_columns,
                           bool numbers) {
  std::vector<std::string> fields = spreadsheet_fields(line);
  std::size_t count = fields.size();
  while (count > std::max<std::size_t>(keep, 1) && fields[count - 1].empty()) --count;
  if (numbers) {
    for (std::size_t i = 0; i < count; ++i) {
      const std::string& field = fields[i];
      if (field.empty()) continue;
      char* end = nullptr;
      const double value = std::strtod(field.c_str(), &end);
      if (end == field.c_str() || *end != '\0' || !std::isfinite(value)) continue;
      fields[i] = i < key_columns ? format_value(value) : format_result(value);
    }
  }
  return join_fields(fields, count);
}

// The file's text with its line endings made '\n' (CRLF, or a lone CR of classic Mac files)
// and a UTF-8 byte order mark removed.
std::string unix_text(const std::string& text) {
  const std::size_t start = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = start; i < text.size(); ++i) {
    if (text[i] != '\r') {
      out += text[i];
    } else if (i + 1 >= text.size() || text[i + 1] != '\n') {
      out += '\n';
    }
  }
  return out;
}

}  // namespace

std::string format_value(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

std::string format_result(const std::optional<double>& value) {
  if (!value) return {};
  char text[64];
  std::snprintf(text, sizeof text, "%.6g", *value);
  return text;
}

std::vector<double> sweep_values(double from, double to, int steps, const std::string& prefix,
                                 const std::string& suffix) {
  const std::string from_option = prefix + "from" + suffix;
  const std::string to_option = prefix + "to" + suffix;
  if (steps < 1) {
    throw InputError(prefix + "steps" + suffix + ": must be at least 1, got " +
                     std::to_string(steps));
  }
  if (!std::isfinite(from)) throw InputError(from_option + ": must be a finite number");
  if (!std::isfinite(to)) throw InputError(to_option + ": must be a finite number");
  if (from > to) {
    throw InputError(from_option + " " + format_value(from) + " is greater than " + to_option +
                     " " + format_value(to));
  }
  (void)bounded_count(steps, kMaxSweepAxisValues,
                      prefix + "steps" + suffix + " " + std::to_string(steps),
                      "the axis would have", "values");
  std::vector<double> values;
  values.reserve(static_cast<std::size_t>(steps));
  for (int i = 0; i < steps; ++i) {
    values.push_back(i == 0           ? from
                     : i == steps - 1 ? to
                                      : from + (to - from) * static_cast<double>(i) / (steps - 1));
  }
  return values;
}

std::string fingerprint(const SceneParams& p) {
  Fnv1a h;
  h.add(p.gravity)
      .add(p.block.half_width)
      .add(p.block.com_height)
      .add(p.block.eccentricity)
      .add(p.block.mass)
      .add(p.block.inertia)
      .add(p.has_base)
      .add(p.base.mass)
      .add(p.base.period)
      .add(p.base.damping_ratio)
      .add(p.has_friction)
      .add(p.friction.static_coefficient)
      .add(p.friction.kinetic_coefficient)
      .add(p.has_base_stops)
      .add(p.base_stops.max_displacement)
      .add(p.base_stops.restitution)
      .add(p.has_support)
      .add(p.support.clearance)
      .add(p.has_sliding_stops)
      .add(p.sliding_stops.restitution);
  return h.hex();
}

std::string fingerprint(const Record& record) {
  Fnv1a h;
  h.add(record.dt);
  for (const double a : record.horizontal) h.add(a);
  return h.hex();
}

SettingsLine::SettingsLine(const std::string& mode, const std::vector<GridAxis>& grid)
    : text_(kSettingsPrefix + mode + " grid=") {
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (i > 0) text_ += ',';
    text_ += grid[i].name + ":" + format_value(grid[i].from) + ":" + format_value(grid[i].to) +
             ":" + std::to_string(grid[i].steps);
  }
}

SettingsLine& SettingsLine::add(const std::string& key, const std::string& value) {
  text_ += " " + key + "=" + value;
  return *this;
}

std::map<std::string, std::string> parse_settings(const std::string& line,
                                                  const std::string& where) {
  if (line.rfind(kSettingsPrefix, 0) != 0) {
    throw InputError(where + ": not a plinth-sweep CSV (its first line must start with '" +
                     kSettingsPrefix + "')");
  }
  std::map<std::string, std::string> settings;
  const std::vector<std::string> words =
      split(line.substr(std::string(kSettingsPrefix).size()), ' ');
  if (words.empty() || words[0].empty())
    throw InputError(where + ": the settings line names no mode");
  settings["mode"] = words[0];
  for (std::size_t i = 1; i < words.size(); ++i) {
    const std::size_t equals = words[i].find('=');
    if (equals == std::string::npos || equals == 0) {
      throw InputError(where + ": bad setting '" + words[i] + "' (expected key=value)");
    }
    settings[words[i].substr(0, equals)] = words[i].substr(equals + 1);
  }
  return settings;
}

std::string settings_difference(const std::string& a, const std::string& a_name,
                                const std::string& b, const std::string& b_name) {
  std::map<std::string, std::string> first;
  std::map<std::string, std::string> second;
  try {
    first = parse_settings(a, a_name);
    second = parse_settings(b, b_name);
  } catch (const InputError&) {
    return {};
  }
  std::map<std::string, std::pair<std::string, std::string>> both;
  for (const auto& [key, value] : first) both[key].first = value;
  for (const auto& [key, value] : second) both[key].second = value;
  std::string text;
  for (const auto& [key, values] : both) {
    if (values.first == values.second) continue;
    if (!text.empty()) text += "; ";
    text += key;
    text += ": ";
    text += values.first.empty() ? std::string("none") : values.first;
    text += " in ";
    text += a_name;
    text += ", ";
    text += values.second.empty() ? std::string("none") : values.second;
    text += " in ";
    text += b_name;
  }
  return text;
}

std::vector<GridAxis> parse_grid(const std::string& line, const std::string& where) {
  const auto settings = parse_settings(line, where);
  const auto it = settings.find("grid");
  if (it == settings.end()) throw InputError(where + ": the settings line has no grid=");
  std::vector<GridAxis> grid;
  for (const std::string& axis_text : split(it->second, ',')) {
    const std::vector<std::string> parts = split(axis_text, ':');
    GridAxis axis;
    bool ok = parts.size() == 4 && !parts[0].empty();
    try {
      if (ok) {
        axis.name = parts[0];
        std::size_t used = 0;
        axis.from = std::stod(parts[1], &used);
        ok = ok && used == parts[1].size();
        axis.to = std::stod(parts[2], &used);
        ok = ok && used == parts[2].size();
        axis.steps = std::stoi(parts[3], &used);
        ok = ok && used == parts[3].size() && axis.steps >= 1 && axis.from <= axis.to;
      }
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok) {
      throw InputError(where + ": bad grid axis '" + axis_text + "' (expected name:from:to:steps)");
    }
    grid.push_back(axis);
  }
  if (grid.empty() || grid.size() > 2) {
    throw InputError(where + ": the grid must have one or two axes");
  }
  return grid;
}

std::vector<std::string> grid_keys(const std::vector<GridAxis>& grid) {
  std::vector<std::string> keys{""};
  for (const GridAxis& axis : grid) {
    std::vector<std::string> longer;
    for (const std::string& prefix : keys) {
      for (const double value : sweep_values(axis.from, axis.to, axis.steps)) {
        longer.push_back(prefix.empty() ? format_value(value) : prefix + "," + format_value(value));
      }
    }
    keys = std::move(longer);
  }
  return keys;
}

std::vector<std::string> csv_fields(const std::string& row) { return split(row, ','); }

std::string row_key(const std::string& row, std::size_t key_columns) {
  std::size_t end = 0;
  for (std::size_t k = 0; k < key_columns; ++k) {
    end = row.find(',', k == 0 ? 0 : end + 1);
    if (end == std::string::npos) return row;
  }
  return row.substr(0, end);
}

namespace {

// Problems of a row's result fields (after the key columns): a number there is a threshold, so
// it must be finite and not negative; names (an impulse map's "sliding") and empty fields are
// results too. Empty when the row is sound.
std::string result_field_problem(const std::vector<std::string>& header,
                                 const std::vector<std::string>& fields, std::size_t key_columns) {
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const std::string& field = fields[i];
    if (field.empty()) continue;
    char* end = nullptr;
    const double value = std::strtod(field.c_str(), &end);
    if (end == field.c_str() || *end != '\0') continue;  // a name
    const std::string column = i < header.size() ? header[i] : std::to_string(i + 1);
    if (!std::isfinite(value)) return "column " + column + ": '" + field + "' is not finite";
    if (i >= key_columns && value < 0.0) {
      return "column " + column + ": '" + field + "' is negative";
    }
  }
  return {};
}

}  // namespace

SweepTable read_sweep_table(const std::string& path, std::size_t* dropped) {
  std::istringstream in(unix_text(read_text_file(path, kMaxSweepTableBytes, "sweep CSV")));
  SweepTable table;
  if (!std::getline(in, table.settings)) throw InputError(path + ": empty file, not a sweep CSV");
  // The settings line as one field (a spreadsheet splits it at the grid's commas, or quotes
  // it, and pads it with empty fields), its words one space apart.
  {
    std::istringstream words(canonical_line(table.settings, 0, 0, false));
    std::string word;
    std::string settings;
    while (words >> word) settings += (settings.empty() ? "" : " ") + word;
    if (settings.rfind("#plinth-sweep", 0) == 0) settings = "# " + settings.substr(1);
    table.settings = settings;
  }
  const std::size_t key_columns = parse_grid(table.settings, path + ":1").size();
  if (!std::getline(in, table.header)) throw InputError(path + ":2: missing the CSV header");
  table.header = canonical_line(table.header, 0, 0, false);
  if (table.header.empty()) throw InputError(path + ":2: missing the CSV header");
  const std::vector<std::string> header = csv_fields(table.header);
  const std::size_t fields = count_fields(table.header);
  std::string line;
  for (int number = 3; std::getline(in, line); ++number) {
    if (line.find_first_not_of(", \t\"") == std::string::npos) continue;  // an empty row
    line = canonical_line(line, fields, key_columns, true);
    if (count_fields(line) != fields && dropped != nullptr) {
      ++*dropped;
      continue;
    }
    if (count_fields(line) != fields) {
      throw InputError(path + ":" + std::to_string(number) + ": " +
                       std::to_string(count_fields(line)) + " fields, the header has " +
                       std::to_string(fields) + " (a truncated row?)");
    }
    const std::string problem = result_field_problem(header, csv_fields(line), key_columns);
    if (!problem.empty()) {
      throw InputError(path + ":" + std::to_string(number) + ": " + problem +
                       " (not a value plinth-sweep writes)");
    }
    table.rows.push_back(line);
  }
  return table;
}

void write_sweep_table(std::ostream& out, const SweepTable& table) {
  out << table.settings << '\n' << table.header << '\n';
  for (const std::string& row : table.rows) out << row << '\n';
}

std::vector<std::string> place_rows(const std::vector<std::string>& rows,
                                    const std::vector<std::string>& keys, std::size_t key_columns,
                                    const std::string& where) {
  std::unordered_map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < keys.size(); ++i) index.emplace(keys[i], i);
  std::vector<std::string> placed(keys.size());
  for (const std::string& row : rows) {
    const std::string key = row_key(row, key_columns);
    const auto it = index.find(key);
    if (it == index.end()) {
      throw InputError(where + ": row '" + key + "' is not a point of this sweep's grid");
    }
    if (!placed[it->second].empty()) {
      throw InputError(where + ": row '" + key + "' appears twice");
    }
    placed[it->second] = row;
  }
  return placed;
}

std::vector<const AddedColumn*> columns_added_since(const SweepTable& table) {
  std::vector<const AddedColumn*> missing;
  std::string mode;
  try {
    mode = parse_settings(table.settings, "")["mode"];
  } catch (const InputError&) {
    return missing;  // not a plinth-sweep file: nothing to say of its version
  }
  const std::vector<std::string> header = csv_fields(table.header);
  for (const AddedColumn& column : kAddedColumns) {
    const bool of_mode = std::find(column.modes.begin(), column.modes.end(), mode) !=
                         column.modes.end();
    if (of_mode && std::find(header.begin(), header.end(), column.name) == header.end()) {
      missing.push_back(&column);
    }
  }
  return missing;
}

std::string older_version_text(const std::vector<const AddedColumn*>& missing) {
  std::string text;
  for (const AddedColumn* column : missing) {
    text += text.empty() ? "written by a plinth-sweep older than its " : "; and its ";
    text += std::string(column->name) + " column (" + column->since + ")";
  }
  return text;
}

SweepTable merge_sweep_tables(const std::vector<SweepTable>& parts,
                              const std::vector<std::string>& names) {
  if (parts.empty()) throw InputError("merge: no input files");
  const SweepTable& first = parts.front();
  for (std::size_t p = 1; p < parts.size(); ++p) {
    if (parts[p].settings != first.settings) {
      const std::string difference =
          settings_difference(parts[p].settings, names[p], first.settings, names[0]);
      throw InputError("merge: " + names[p] + " and " + names[0] +
                       " come from different sweeps (their settings lines differ" +
                       (difference.empty() ? std::string() : ": " + difference) + "):\n  " +
                       parts[p].settings + "\n  " + first.settings);
    }
    if (parts[p].header != first.header) {
      // One of them an older plinth-sweep's: named, with the version that added the column.
      std::string older;
      for (const std::size_t q : {p, std::size_t{0}}) {
        const std::string text = older_version_text(columns_added_since(parts[q]));
        if (!text.empty()) older = " (" + names[q] + " was " + text + "; run its shard again)";
      }
      throw InputError("merge: " + names[p] + " and " + names[0] + " have different headers" +
                       older);
    }
  }
  const std::vector<std::string> keys = grid_keys(parse_grid(first.settings, names[0]));
  const std::size_t key_columns = parse_grid(first.settings, names[0]).size();
  std::vector<std::string> merged(keys.size());
  std::vector<std::size_t> owner(keys.size());
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const std::vector<std::string> placed = place_rows(parts[p].rows, keys, key_columns, names[p]);
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (placed[i].empty()) continue;
      if (!merged[i].empty()) {
        throw InputError("merge: row '" + keys[i] + "' is in both " + names[owner[i]] + " and " +
                         names[p]);
      }
      merged[i] = placed[i];
      owner[i] = p;
    }
  }
  std::size_t missing = 0;
  std::string examples;
  for (std::size_t i = 0; i < keys.size(); ++i) {
    if (!merged[i].empty()) continue;
    if (++missing <= 3)
      examples += (examples.empty() ? "" : ", ") + std::string("'") + keys[i] + "'";
  }
  if (missing > 0) {
    throw InputError("merge: " + std::to_string(missing) + " of " + std::to_string(keys.size()) +
                     " rows are missing (" + examples + (missing > 3 ? ", ..." : "") +
                     "): a shard not given, or not finished (rerun it to resume)");
  }
  return {first.settings, first.header, merged};
}

}  // namespace plinth::host
