#include "plinth/host/record_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "plinth/host/input_error.h"

namespace plinth::host {

namespace {

// ---- small text helpers ------------------------------------------------------------------------

// Reads text line by line, counting lines (1-based) and dropping a trailing '\r'.
class LineReader {
 public:
  explicit LineReader(const std::string& path) : path_(path), in_(path) {
    std::error_code error;
    if (!in_ || std::filesystem::is_directory(path, error)) {
      throw InputError(path + ": cannot open file");
    }
  }

  bool next(std::string& line) {
    if (!std::getline(in_, line)) return false;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
  }

  [[nodiscard]] std::size_t line_number() const { return line_number_; }

  // "<path>:<line>: <what>", or "<path>: <what>" before the first line.
  [[noreturn]] void fail_at(std::size_t line, const std::string& what) const {
    const std::string where = line == 0 ? path_ : path_ + ":" + std::to_string(line);
    throw InputError(where + ": " + what);
  }
  [[noreturn]] void fail(const std::string& what) const { fail_at(line_number_, what); }

 private:
  std::string path_;
  std::ifstream in_;
  std::size_t line_number_ = 0;
};

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }

std::string_view trim(std::string_view text) {
  while (!text.empty() && is_space(text.front())) text.remove_prefix(1);
  while (!text.empty() && is_space(text.back())) text.remove_suffix(1);
  return text;
}

std::string lowercase(std::string_view text) {
  std::string result(text);
  std::transform(result.begin(), result.end(), result.begin(), [](char c) {
    return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  });
  return result;
}

std::vector<std::string_view> split_whitespace(std::string_view text) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && is_space(text[i])) ++i;
    const std::size_t start = i;
    while (i < text.size() && !is_space(text[i])) ++i;
    if (i > start) tokens.push_back(text.substr(start, i - start));
  }
  return tokens;
}

std::vector<std::string_view> split_commas(std::string_view text) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  for (std::size_t comma = text.find(','); comma != std::string_view::npos;
       comma = text.find(',', start)) {
    fields.push_back(trim(text.substr(start, comma - start)));
    start = comma + 1;
  }
  fields.push_back(trim(text.substr(start)));
  return fields;
}

// ---- numbers -----------------------------------------------------------------------------------

// A number with 9 significant digits, for messages.
std::string format_number(double value) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value,
                                    std::chars_format::general, 9);
  return {buffer.data(), result.ptr};
}

enum class NumberStatus : unsigned char { kOk, kNotANumber, kOutOfRange };

// Parses the whole token as a decimal number (a leading '+' is allowed). Locale-independent.
NumberStatus parse_number(std::string_view token, double& value) {
  if (token.size() > 1 && token.front() == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  const char* end = token.data() + token.size();
  const auto [stop, error] = std::from_chars(token.data(), end, value);
  if (stop != end || token.empty()) return NumberStatus::kNotANumber;
  if (error == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (error != std::errc{}) return NumberStatus::kNotANumber;
  return NumberStatus::kOk;
}

// Parses a finite number or fails on the reader's current line.
double parse_finite(const LineReader& reader, std::string_view token) {
  double value = 0.0;
  const NumberStatus status = parse_number(token, value);
  if (status == NumberStatus::kOk && std::isfinite(value)) return value;
  std::string quoted(1, '\'');  // built only on failure: this runs for every sample
  quoted.append(token);
  quoted.push_back('\'');
  if (status == NumberStatus::kNotANumber) reader.fail(quoted + " is not a number");
  if (status == NumberStatus::kOutOfRange) reader.fail("value " + quoted + " is out of the range of double");
  reader.fail("value " + quoted + " is not finite");
}

// ---- AT2 ---------------------------------------------------------------------------------------

constexpr std::size_t kAt2HeaderLines = 4;

struct At2Header {
  std::string name;
  std::size_t npts = 0;
  double dt = 0.0;  // s
};

// Where the text after `key` starts in `line`, spaces skipped; npos when `key` is absent.
// (Hand-parsed: GCC 12's <regex> trips -Wmaybe-uninitialized in sanitizer builds.)
std::size_t value_start(std::string_view line, std::string_view key) {
  std::size_t at = line.find(key);
  if (at == std::string_view::npos) return at;
  at += key.size();
  while (at < line.size() && is_space(line[at])) ++at;
  return at;
}

void check_at2_units(const LineReader& reader, const std::string& line) {
  const std::string lower = lowercase(line);
  const std::size_t units = value_start(lower, "units");
  const std::size_t at = units == std::string::npos ? units : value_start(lower.substr(units), "of");
  if (at == std::string::npos || units + at >= lower.size()) {
    reader.fail("cannot find 'UNITS OF G' in the header line");
  }
  const std::vector<std::string_view> words = split_whitespace(std::string_view(line).substr(units + at));
  const std::string unit(words.front());
  if (lowercase(unit) != "g") reader.fail("units are '" + unit + "', expected G (acceleration in g)");
}

std::size_t parse_npts(const LineReader& reader, const std::string& line) {
  const std::size_t at = value_start(line, "NPTS=");
  if (at == std::string::npos || at >= line.size() || !std::isdigit(static_cast<unsigned char>(line[at]))) {
    reader.fail("cannot find NPTS= in the header line");
  }
  std::size_t npts = 0;
  const char* first = line.data() + at;
  const auto [stop, error] = std::from_chars(first, line.data() + line.size(), npts);
  if (error != std::errc{}) {
    const std::string digits(first, static_cast<std::size_t>(stop - first));
    reader.fail("NPTS=" + digits + " is out of range");
  }
  if (npts == 0) reader.fail("NPTS must be positive, found NPTS=0");
  return npts;
}

double parse_dt(const LineReader& reader, const std::string& line) {
  const std::size_t at = value_start(line, "DT=");
  if (at == std::string::npos || at >= line.size()) reader.fail("cannot find DT= in the header line");
  // The number may have its unit glued on (".00244SEC"): take the longest numeric prefix.
  const char* first = line.c_str() + at;
  char* stop = nullptr;
  const double dt = std::strtod(first, &stop);
  const std::string text(first, static_cast<std::size_t>(stop - first));
  if (stop == first) reader.fail("cannot find DT= in the header line");
  if (!std::isfinite(dt)) reader.fail("DT=" + text + " is not a finite number");
  if (dt <= 0.0) reader.fail("DT must be positive, found DT=" + text);
  return dt;
}

At2Header read_at2_header(LineReader& reader) {
  std::array<std::string, kAt2HeaderLines> lines;
  for (std::size_t i = 0; i < kAt2HeaderLines; ++i) {
    if (!reader.next(lines[i])) {
      reader.fail_at(i + 1, "truncated header: file ends before header line " +
                                std::to_string(i + 1) + " of " + std::to_string(kAt2HeaderLines));
    }
    if (i == 2) check_at2_units(reader, lines[i]);
  }
  At2Header header;
  header.name = std::string(trim(lines[1]));
  header.npts = parse_npts(reader, lines[3]);
  header.dt = parse_dt(reader, lines[3]);
  return header;
}

}  // namespace

// ---- Record ------------------------------------------------------------------------------------

double Record::duration() const { return horizontal_signal().duration(); }

double Record::peak_horizontal() const {
  double peak = 0.0;
  for (const double a : horizontal) peak = std::max(peak, std::abs(a));
  return peak;
}

SampledSignal Record::horizontal_signal() const {
  return {horizontal.data(), horizontal.size(), dt};
}

SampledSignal Record::vertical_signal() const { return {vertical.data(), vertical.size(), dt}; }

// ---- readers -----------------------------------------------------------------------------------

Record read_at2(const std::string& path, double gravity) {
  LineReader reader(path);
  const At2Header header = read_at2_header(reader);

  Record record;
  record.name = header.name.empty() ? std::filesystem::path(path).stem().string() : header.name;
  record.dt = header.dt;
  // Capped: a corrupt NPTS must not reserve gigabytes before the values are counted.
  record.horizontal.reserve(std::min<std::size_t>(header.npts, std::size_t{1} << 20));

  std::string line;
  while (reader.next(line)) {
    for (const std::string_view token : split_whitespace(line)) {
      if (record.horizontal.size() == header.npts) {
        reader.fail("more values than NPTS=" + std::to_string(header.npts));
      }
      record.horizontal.push_back(parse_finite(reader, token) * gravity);
    }
  }
  if (record.horizontal.size() < header.npts) {
    reader.fail("truncated data: found " + std::to_string(record.horizontal.size()) +
                " values, NPTS=" + std::to_string(header.npts));
  }
  return record;
}

namespace {

// ---- CSV ---------------------------------------------------------------------------------------

constexpr double kStartTolerance = 1e-9;    // s
constexpr double kStepRelTolerance = 1e-6;  // of dt

// The unit inside "name [unit]", lowercase; nullopt when there are no brackets.
std::optional<std::string> bracketed_unit(std::string_view column) {
  const std::size_t open = column.find('[');
  if (open == std::string_view::npos) return std::nullopt;
  const std::size_t close = column.find(']', open);
  if (close == std::string_view::npos) return std::nullopt;
  return lowercase(trim(column.substr(open + 1, close - open - 1)));
}

std::string describe_column(std::string_view column, std::size_t index) {
  return "column " + std::to_string(index + 1) + " '" + std::string(column) + "'";
}

// Factor from the unit in "name [unit]" to m/s2; fails when the unit is missing or unknown.
double acceleration_factor(const LineReader& reader, std::string_view column, std::size_t index,
                           double gravity) {
  const std::optional<std::string> unit = bracketed_unit(column);
  if (!unit) {
    reader.fail("missing unit in " + describe_column(column, index) + ": write e.g. 'a [m/s2]'");
  }
  if (*unit == "g") return gravity;
  if (*unit == "m/s2") return 1.0;
  if (*unit == "cm/s2" || *unit == "gal") return 0.01;
  reader.fail("unknown unit '" + *unit + "' in " + describe_column(column, index) +
              " (expected g, m/s2, cm/s2 or gal)");
}

// Reads the header line and returns the factor to m/s2 of each acceleration column.
std::vector<double> read_csv_header(const LineReader& reader, const std::string& line,
                                    double gravity) {
  const std::vector<std::string_view> columns = split_commas(line);
  if (columns.size() < 2 || columns.size() > 3) {
    reader.fail("header must have 2 or 3 columns ('t,<name> [unit][,v [unit]]'), found " +
                std::to_string(columns.size()));
  }
  const std::optional<std::string> time_unit = bracketed_unit(columns[0]);
  if (time_unit && *time_unit != "s") {
    reader.fail("unknown unit '" + *time_unit + "' in " + describe_column(columns[0], 0) +
                " (expected s)");
  }
  std::vector<double> factors;
  for (std::size_t i = 1; i < columns.size(); ++i) {
    factors.push_back(acceleration_factor(reader, columns[i], i, gravity));
  }
  return factors;
}

// Reads the next line that is neither blank nor a '#' comment; false at the end of the file.
bool next_content_line(LineReader& reader, std::string& line) {
  while (reader.next(line)) {
    const std::string_view content = trim(line);
    if (!content.empty() && content.front() != '#') return true;
  }
  return false;
}

void check_time(const LineReader& reader, const std::vector<double>& times) {
  const std::size_t k = times.size() - 1;
  const double t = times.back();
  if (k == 0) {
    if (std::abs(t) > kStartTolerance) {
      reader.fail("time must start at 0, found " + format_number(t) + " s");
    }
    return;
  }
  const double dt = times[1] - times[0];
  if (dt <= 0.0) reader.fail("time step must be positive, found " + format_number(dt) + " s");
  const double step = t - times[k - 1];
  if (std::abs(step - dt) > kStepRelTolerance * dt) {
    reader.fail("non-uniform time step: " + format_number(step) + " s after a first step of " +
                format_number(dt) + " s");
  }
}

}  // namespace

Record read_csv_record(const std::string& path, double gravity) {
  LineReader reader(path);
  std::string line;
  if (!next_content_line(reader, line)) reader.fail("no header line 't,<name> [unit]'");
  const std::vector<double> factors = read_csv_header(reader, line, gravity);
  const std::size_t column_count = factors.size() + 1;

  Record record;
  record.name = std::filesystem::path(path).stem().string();
  std::vector<double> times;
  while (next_content_line(reader, line)) {
    const std::vector<std::string_view> fields = split_commas(line);
    if (fields.size() != column_count) {
      reader.fail("expected " + std::to_string(column_count) + " columns, found " +
                  std::to_string(fields.size()));
    }
    times.push_back(parse_finite(reader, fields[0]));
    check_time(reader, times);
    record.horizontal.push_back(parse_finite(reader, fields[1]) * factors[0]);
    if (column_count == 3) record.vertical.push_back(parse_finite(reader, fields[2]) * factors[1]);
  }
  if (times.empty()) reader.fail("no data rows");
  if (times.size() < 2) reader.fail("need at least 2 data rows to define the time step");
  record.dt = times[1] - times[0];
  return record;
}

Record read_record(const std::string& path, double gravity) {
  const std::string extension = lowercase(std::filesystem::path(path).extension().string());
  if (extension == ".at2") return read_at2(path, gravity);
  if (extension == ".csv") return read_csv_record(path, gravity);
  throw InputError(path + ": unknown record format (expected .AT2 or .csv)");
}

}  // namespace plinth::host
