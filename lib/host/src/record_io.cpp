#include "plinth/host/record_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/host/input_error.h"
#include "plinth/host/text_file.h"

namespace plinth::host {

namespace {

// ---- small text helpers ------------------------------------------------------------------------

// Walks a file's text line by line, counting lines (1-based) and dropping a trailing '\r'.
class LineReader {
 public:
  LineReader(std::string_view text, const std::string& origin) : text_(text), origin_(origin) {}

  bool next(std::string_view& line) {
    if (position_ >= text_.size()) return false;
    const std::size_t end = std::min(text_.find('\n', position_), text_.size());
    line = text_.substr(position_, end - position_);
    position_ = end + 1;
    ++line_number_;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    return true;
  }

  [[nodiscard]] std::size_t line_number() const { return line_number_; }
  [[nodiscard]] const std::string& origin() const { return origin_; }

  // "<origin>:<line>: <what>", or "<origin>: <what>" before the first line.
  [[noreturn]] void fail_at(std::size_t line, const std::string& what) const {
    const std::string where = line == 0 ? origin_ : origin_ + ":" + std::to_string(line);
    throw InputError(where + ": " + what);
  }
  [[noreturn]] void fail(const std::string& what) const { fail_at(line_number_, what); }

 private:
  std::string_view text_;
  const std::string& origin_;
  std::size_t position_ = 0;
  std::size_t line_number_ = 0;
};

// A line of the file a message is about.
struct Where {
  const LineReader& reader;
  std::size_t line;

  [[noreturn]] void fail(const std::string& what) const { reader.fail_at(line, what); }
};

bool is_space(char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; }
bool is_alnum(char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; }
bool is_digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

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

std::string uppercase(std::string_view text) {
  std::string result(text);
  std::transform(result.begin(), result.end(), result.begin(), [](char c) {
    return static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  });
  return result;
}

// Splits on white space and, when `commas` is set, on commas too.
std::vector<std::string_view> split_words(std::string_view text, bool commas) {
  const auto separates = [commas](char c) { return is_space(c) || (commas && c == ','); };
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && separates(text[i])) ++i;
    const std::size_t start = i;
    while (i < text.size() && !separates(text[i])) ++i;
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

std::string quote(std::string_view text) {
  constexpr std::size_t kShown = 40;  // characters of a bad token shown in a message
  std::string result(1, '\'');
  result.append(text.substr(0, kShown));
  if (text.size() > kShown) result.append("...");
  result.push_back('\'');
  return result;
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

bool is_number(std::string_view token) {
  double ignored = 0.0;
  return parse_number(token, ignored) != NumberStatus::kNotANumber;
}

// Parses a finite number or fails on the reader's current line.
double parse_finite(const LineReader& reader, std::string_view token) {
  double value = 0.0;
  const NumberStatus status = parse_number(token, value);
  if (status == NumberStatus::kOk && std::isfinite(value)) return value;
  if (status == NumberStatus::kNotANumber) reader.fail(quote(token) + " is not a number");
  if (status == NumberStatus::kOutOfRange) {
    reader.fail("value " + quote(token) + " is out of the range of double");
  }
  reader.fail("value " + quote(token) + " is not finite");
}

// A sample: a finite number times `factor` (to m/s2), within kMaxRecordAccelerationG.
double parse_acceleration(const LineReader& reader, std::string_view token, double factor) {
  const double value = parse_finite(reader, token) * factor;
  if (!(std::abs(value) <= kMaxRecordAccelerationG * static_cast<double>(kStandardGravity))) {
    reader.fail("value " + quote(token) + " is beyond the " +
                format_number(kMaxRecordAccelerationG) + " g an accelerogram can hold");
  }
  return value;
}

// Factor from an acceleration unit to m/s2 ("g", "cm/s^2", "CM/S/S", "gal", "m/s2", ...).
std::optional<double> acceleration_factor(std::string_view unit, double gravity) {
  std::string name = lowercase(trim(unit));
  if (name == "g") return gravity;
  if (name == "gal") return 0.01;
  double factor = 1.0;
  if (name.starts_with("cm/")) {
    factor = 0.01;
    name.erase(0, 1);
  } else if (name.starts_with("mm/")) {
    factor = 0.001;
    name.erase(0, 1);
  }
  if (name == "m/s2" || name == "m/s^2" || name == "m/s/s" || name == "m/sec2" ||
      name == "m/sec^2" || name == "m/sec/sec") {
    return factor;
  }
  return std::nullopt;
}

// ---- sampling: NPTS and DT within the limits ---------------------------------------------------

struct Sampling {
  std::size_t count = 0;  // samples the header announces
  double dt = 0.0;        // s
};

// Checks what the header implies: no count or duration a file cannot honestly hold.
// `count_key` and `dt_key` are the header's names ("NPTS", "DT").
void check_sampling(const Where& where, const Sampling& sampling, std::string_view count_key,
                    std::string_view dt_key) {
  const std::string count_text = std::string(count_key) + "=" + std::to_string(sampling.count);
  const std::string dt_text = std::string(dt_key) + "=" + format_number(sampling.dt);
  if (sampling.count == 0)
    where.fail(std::string(count_key) + " must be positive, found " + count_text);
  if (sampling.count > kMaxRecordSamples) {
    where.fail(count_text + " exceeds the limit of " + std::to_string(kMaxRecordSamples) +
               " samples");
  }
  if (!(sampling.dt > 0.0)) where.fail(std::string(dt_key) + " must be positive, found " + dt_text);
  if (sampling.dt < kMinRecordDt || sampling.dt > kMaxRecordDt) {
    where.fail(dt_text + " s is outside the limits [" + format_number(kMinRecordDt) + ", " +
               format_number(kMaxRecordDt) + "] s");
  }
  const double duration = static_cast<double>(sampling.count - 1) * sampling.dt;
  if (duration > kMaxRecordDuration) {
    where.fail(count_text + " and " + dt_text + " make a record of " + format_number(duration) +
               " s, longer than the limit of " + format_number(kMaxRecordDuration) + " s");
  }
}

// Reads the values after a header: `pending` (the line already read, may be empty) and the
// following lines, any number per line, exactly `count` of them.
std::vector<double> read_values(LineReader& reader, std::string_view pending, std::size_t count,
                                double factor, std::string_view count_key) {
  std::vector<double> values;
  // Grown as values come: a header announcing millions of samples reserves no more than this.
  constexpr std::size_t kReserveAtMost = std::size_t{1} << 16;
  values.reserve(std::min(count, kReserveAtMost));
  std::string_view line = pending;
  bool have_line = !pending.empty();
  const std::string count_text = std::string(count_key) + "=" + std::to_string(count);
  while (have_line || reader.next(line)) {
    have_line = false;
    for (const std::string_view token : split_words(line, false)) {
      if (values.size() == count) reader.fail("more values than " + count_text);
      values.push_back(parse_acceleration(reader, token, factor));
    }
  }
  if (values.size() < count) {
    reader.fail("truncated data: found " + std::to_string(values.size()) + " values, " +
                count_text);
  }
  return values;
}

// ---- AT2 ---------------------------------------------------------------------------------------

constexpr std::size_t kAt2HeaderLines = 4;

// Where `word` stands in `upper` as a word of its own (not inside another word); npos if not.
std::size_t find_word(std::string_view upper, std::string_view word) {
  for (std::size_t at = upper.find(word); at != std::string_view::npos;
       at = upper.find(word, at + 1)) {
    const bool starts = at == 0 || !is_alnum(upper[at - 1]);
    const std::size_t end = at + word.size();
    const bool ends = end == upper.size() || !is_alnum(upper[end]);
    if (starts && ends) return at;
  }
  return std::string_view::npos;
}

// Line 3: "ACCELERATION TIME SERIES IN UNITS OF G" (NGA), "... TIME HISTORY IN UNITS OF G.
// FILTER POINTS: ..." (pre-NGA). Returns the factor to m/s2.
double read_at2_units(const Where& where, std::string_view line, double gravity) {
  const std::string upper = uppercase(line);
  for (const char* other : {"VELOCITY", "DISPLACEMENT"}) {
    if (find_word(upper, other) != std::string::npos) {
      where.fail(std::string("this is a ") + lowercase(other) + " file (" + quote(trim(line)) +
                 "); expected an acceleration time series (AT2)");
    }
  }
  const std::size_t units = find_word(upper, "UNITS");
  const std::vector<std::string_view> words =
      units == std::string::npos ? std::vector<std::string_view>{}
                                 : split_words(std::string_view(line).substr(units), true);
  if (words.size() < 3 || uppercase(words[1]) != "OF") {
    where.fail("cannot find 'UNITS OF G' in the header line");
  }
  std::string_view unit = words[2];
  while (!unit.empty() && (unit.back() == '.' || unit.back() == ';')) unit.remove_suffix(1);
  const std::optional<double> factor = acceleration_factor(unit, gravity);
  if (!factor) {
    where.fail("units are " + quote(unit) + ", expected G (or an acceleration: cm/s2, m/s2)");
  }
  return *factor;
}

// The value after `key` and '=' (or ':') in `line`, spaces allowed around '='; nullopt when the
// key is absent or not followed by '='.
std::optional<std::string_view> labelled_value(std::string_view line, std::string_view upper,
                                               std::string_view key) {
  const std::size_t at = find_word(upper, key);
  if (at == std::string_view::npos) return std::nullopt;
  std::size_t i = at + key.size();
  while (i < line.size() && is_space(line[i])) ++i;
  if (i >= line.size() || (line[i] != '=' && line[i] != ':')) return std::nullopt;
  ++i;
  while (i < line.size() && is_space(line[i])) ++i;
  return line.substr(i);
}

std::size_t parse_npts_text(const Where& where, std::string_view text, bool whole) {
  std::size_t npts = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, npts);
  const bool digits = !text.empty() && is_digit(text.front());
  const bool complete = !whole || stop == end;
  const bool separated = stop == end || (!is_alnum(*stop) && *stop != '.');
  if (!digits || !complete || !separated) {
    where.fail("cannot find NPTS= (a positive whole number) in the header line, found " +
               quote(split_words(text, true).empty() ? "" : split_words(text, true)[0]));
  }
  if (error != std::errc{})
    where.fail("NPTS=" + std::string(text.data(), stop) + " is out of range");
  return npts;
}

double parse_dt_text(const Where& where, std::string_view text, bool whole) {
  // The number may have its unit glued on (".00244SEC"): take the longest numeric prefix.
  double dt = 0.0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, dt);
  if (stop == text.data() || (whole && stop != end))
    where.fail("cannot find DT= in the header line");
  const std::string digits(text.data(), stop);
  if (error != std::errc{} || !std::isfinite(dt))
    where.fail("DT=" + digits + " is not a finite number");
  return dt;
}

// Line 4, "NPTS=  5372, DT=   .0100 SEC," and its variants, or "4096    0.0100    NPTS, DT".
Sampling read_at2_sampling(const Where& where, std::string_view line) {
  const std::string upper = uppercase(line);
  const std::optional<std::string_view> npts_text = labelled_value(line, upper, "NPTS");
  const std::optional<std::string_view> dt_text = labelled_value(line, upper, "DT");
  Sampling sampling;
  if (npts_text || dt_text) {
    if (!npts_text) where.fail("cannot find NPTS= in the header line");
    if (!dt_text) where.fail("cannot find DT= in the header line");
    sampling.count = parse_npts_text(where, *npts_text, false);
    sampling.dt = parse_dt_text(where, *dt_text, false);
    return sampling;
  }
  // Values before their labels: the numbers in order, then the labels in the same order.
  const std::size_t npts_at = find_word(upper, "NPTS");
  const std::size_t dt_at = find_word(upper, "DT");
  if (npts_at == std::string::npos) where.fail("cannot find NPTS= in the header line");
  if (dt_at == std::string::npos) where.fail("cannot find DT= in the header line");
  const std::vector<std::string_view> values =
      split_words(std::string_view(line).substr(0, std::min(npts_at, dt_at)), true);
  if (values.size() != 2) {
    where.fail("expected two numbers before 'NPTS, DT' in the header line, found " +
               std::to_string(values.size()));
  }
  const bool npts_first = npts_at < dt_at;
  sampling.count = parse_npts_text(where, values[npts_first ? 0 : 1], true);
  sampling.dt = parse_dt_text(where, values[npts_first ? 1 : 0], true);
  return sampling;
}

Record parse_at2(std::string_view text, const std::string& origin, double gravity) {
  LineReader reader(text, origin);
  std::array<std::string_view, kAt2HeaderLines> lines;
  for (std::size_t i = 0; i < kAt2HeaderLines; ++i) {
    if (!reader.next(lines[i])) {
      reader.fail_at(i + 1, "truncated header: file ends before header line " +
                                std::to_string(i + 1) + " of " + std::to_string(kAt2HeaderLines));
    }
  }
  const double factor = read_at2_units(Where{reader, 3}, lines[2], gravity);
  const Where line4{reader, 4};
  const Sampling sampling = read_at2_sampling(line4, lines[3]);
  check_sampling(line4, sampling, "NPTS", "DT");

  Record record;
  const std::string_view name = trim(lines[1]);
  record.name = name.empty() ? std::filesystem::path(origin).stem().string() : std::string(name);
  record.dt = sampling.dt;
  record.horizontal = read_values(reader, {}, sampling.count, factor, "NPTS");
  return record;
}

// ---- ESM / ITACA ASCII -------------------------------------------------------------------------

struct HeaderValue {
  std::string value;
  std::size_t line = 0;
};

// "KEY: value" with KEY in capitals, digits and _/^.()- (ESM writes e.g. "PGA_CM/S^2: 0.3").
std::optional<std::pair<std::string_view, std::string_view>> esm_header_line(
    std::string_view line) {
  const std::size_t colon = line.find(':');
  if (colon == std::string_view::npos || colon == 0) return std::nullopt;
  const std::string_view key = line.substr(0, colon);
  for (const char c : key) {
    const bool allowed = std::isupper(static_cast<unsigned char>(c)) != 0 || is_digit(c) ||
                         std::string_view("_/^.()-").find(c) != std::string_view::npos;
    if (!allowed) return std::nullopt;
  }
  return std::pair{key, trim(line.substr(colon + 1))};
}

// Reads the header up to the first value line, returned through `first_values`.
std::map<std::string, HeaderValue, std::less<>> read_esm_header(LineReader& reader,
                                                                std::string_view& first_values) {
  std::map<std::string, HeaderValue, std::less<>> header;
  std::string_view line;
  while (reader.next(line)) {
    if (trim(line).empty()) continue;
    const std::vector<std::string_view> words = split_words(line, false);
    if (is_number(words.front())) {
      first_values = line;
      return header;
    }
    const auto entry = esm_header_line(line);
    if (!entry)
      reader.fail("expected a header line 'KEY: value' or the first value, found " +
                  quote(trim(line)));
    const auto [at, inserted] = header.try_emplace(
        std::string(entry->first), HeaderValue{std::string(entry->second), reader.line_number()});
    if (!inserted) {
      reader.fail(std::string(entry->first) + " is repeated (first on line " +
                  std::to_string(at->second.line) + ")");
    }
  }
  first_values = {};
  return header;
}

const HeaderValue& required(const LineReader& reader,
                            const std::map<std::string, HeaderValue, std::less<>>& header,
                            std::string_view key) {
  const auto found = header.find(key);
  if (found == header.end() || found->second.value.empty()) {
    reader.fail_at(0, "missing header line '" + std::string(key) + ": <value>' (ESM/ITACA format)");
  }
  return found->second;
}

std::string esm_name(const std::map<std::string, HeaderValue, std::less<>>& header,
                     const std::string& origin) {
  const auto value = [&header](std::string_view key) {
    const auto found = header.find(key);
    return found == header.end() ? std::string() : found->second.value;
  };
  std::string station = value("NETWORK");
  if (!station.empty() && !value("STATION_CODE").empty()) station += ".";
  station += value("STATION_CODE");
  std::string name;
  for (const std::string& part :
       {value("EVENT_NAME"), value("EVENT_DATE_YYYYMMDD"), station, value("STREAM")}) {
    if (part.empty()) continue;
    if (!name.empty()) name += ", ";
    name += part;
  }
  return name.empty() ? std::filesystem::path(origin).stem().string() : name;
}

Record parse_esm(std::string_view text, const std::string& origin, double gravity) {
  LineReader reader(text, origin);
  std::string_view first_values;
  const auto header = read_esm_header(reader, first_values);

  const HeaderValue& interval = required(reader, header, "SAMPLING_INTERVAL_S");
  const HeaderValue& ndata = required(reader, header, "NDATA");
  const HeaderValue& units = required(reader, header, "UNITS");
  if (const auto type = header.find("DATA_TYPE");
      type != header.end() && uppercase(type->second.value) != "ACCELERATION") {
    reader.fail_at(type->second.line,
                   "DATA_TYPE is " + quote(type->second.value) + ", expected ACCELERATION");
  }
  const std::optional<double> factor = acceleration_factor(units.value, gravity);
  if (!factor) {
    reader.fail_at(units.line, "UNITS " + quote(units.value) +
                                   " is not an acceleration (expected cm/s^2, m/s^2 or g)");
  }
  Sampling sampling;
  sampling.dt = parse_dt_text(Where{reader, interval.line}, interval.value, true);
  sampling.count = parse_npts_text(Where{reader, ndata.line}, ndata.value, true);
  check_sampling(Where{reader, ndata.line}, sampling, "NDATA", "SAMPLING_INTERVAL_S");

  Record record;
  record.name = esm_name(header, origin);
  record.dt = sampling.dt;
  record.horizontal = read_values(reader, first_values, sampling.count, *factor, "NDATA");
  return record;
}

// ---- CSV ---------------------------------------------------------------------------------------

constexpr double kStartTolerance = 1e-9;    // s
constexpr double kStepRelTolerance = 1e-6;  // of dt

// The unit inside "name [unit]"; nullopt when there are no brackets.
std::optional<std::string_view> bracketed_unit(std::string_view column) {
  const std::size_t open = column.find('[');
  if (open == std::string_view::npos) return std::nullopt;
  const std::size_t close = column.find(']', open);
  if (close == std::string_view::npos) return std::nullopt;
  return trim(column.substr(open + 1, close - open - 1));
}

std::string describe_column(std::string_view column, std::size_t index) {
  return "column " + std::to_string(index + 1) + " " + quote(column);
}

// Factor from the unit in "name [unit]" to m/s2; fails when the unit is missing or unknown.
double csv_column_factor(const LineReader& reader, std::string_view column, std::size_t index,
                         double gravity) {
  const std::optional<std::string_view> unit = bracketed_unit(column);
  if (!unit) {
    reader.fail("missing unit in " + describe_column(column, index) + ": write e.g. 'a [m/s2]'");
  }
  const std::optional<double> factor = acceleration_factor(*unit, gravity);
  if (!factor) {
    reader.fail("unknown unit " + quote(lowercase(*unit)) + " in " +
                describe_column(column, index) + " (expected g, m/s2, cm/s2 or gal)");
  }
  return *factor;
}

// Reads the header line and returns the factor to m/s2 of each acceleration column.
std::vector<double> read_csv_header(const LineReader& reader, std::string_view line,
                                    double gravity) {
  const std::vector<std::string_view> columns = split_commas(line);
  if (columns.size() < 2 || columns.size() > 3) {
    reader.fail("header must have 2 or 3 columns ('t,<name> [unit][,v [unit]]'), found " +
                std::to_string(columns.size()));
  }
  const std::optional<std::string_view> time_unit = bracketed_unit(columns[0]);
  if (time_unit && lowercase(*time_unit) != "s") {
    reader.fail("unknown unit " + quote(lowercase(*time_unit)) + " in " +
                describe_column(columns[0], 0) + " (expected s)");
  }
  std::vector<double> factors;
  for (std::size_t i = 1; i < columns.size(); ++i) {
    factors.push_back(csv_column_factor(reader, columns[i], i, gravity));
  }
  return factors;
}

// Reads the next line that is neither blank nor a '#' comment; false at the end of the file.
bool next_content_line(LineReader& reader, std::string_view& line) {
  while (reader.next(line)) {
    const std::string_view content = trim(line);
    if (!content.empty() && content.front() != '#') return true;
  }
  return false;
}

// Checks the time of row k (times[k]) against t = 0 and the first step, within the limits.
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
  if (k == 1) {
    check_sampling(Where{reader, reader.line_number()}, Sampling{2, dt}, "rows", "time step");
  }
  const double step = t - times[k - 1];
  if (std::abs(step - dt) > kStepRelTolerance * dt) {
    reader.fail("non-uniform time step: " + format_number(step) + " s after a first step of " +
                format_number(dt) + " s");
  }
  if (k >= kMaxRecordSamples || t > kMaxRecordDuration) {
    check_sampling(Where{reader, reader.line_number()}, Sampling{k + 1, dt}, "rows", "time step");
  }
}

Record parse_csv(std::string_view text, const std::string& origin, double gravity) {
  LineReader reader(text, origin);
  std::string_view line;
  if (!next_content_line(reader, line)) reader.fail("no header line 't,<name> [unit]'");
  const std::vector<double> factors = read_csv_header(reader, line, gravity);
  const std::size_t column_count = factors.size() + 1;

  Record record;
  record.name = std::filesystem::path(origin).stem().string();
  std::vector<double> times;
  while (next_content_line(reader, line)) {
    const std::vector<std::string_view> fields = split_commas(line);
    if (fields.size() != column_count) {
      reader.fail("expected " + std::to_string(column_count) + " columns, found " +
                  std::to_string(fields.size()));
    }
    times.push_back(parse_finite(reader, fields[0]));
    check_time(reader, times);
    record.horizontal.push_back(parse_acceleration(reader, fields[1], factors[0]));
    if (column_count == 3)
      record.vertical.push_back(parse_acceleration(reader, fields[2], factors[1]));
  }
  if (times.empty()) reader.fail("no data rows");
  if (times.size() < 2) reader.fail("need at least 2 data rows to define the time step");
  record.dt = times[1] - times[0];
  return record;
}

// ---- format detection --------------------------------------------------------------------------

constexpr std::size_t kDetectionLines = 100;  // an ESM header has 64

bool looks_like_at2(const std::array<std::string, 4>& upper) {
  const std::string& title = upper[0];
  const bool titled = title.find("STRONG MOTION") != std::string::npos ||
                      title.find("STRONG-MOTION") != std::string::npos || title.starts_with("PEER");
  const bool described = upper[2].find("UNITS") != std::string::npos &&
                         find_word(upper[3], "NPTS") != std::string::npos;
  return titled || described;
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

// ---- formats -----------------------------------------------------------------------------------

const char* record_format_name(RecordFormat format) {
  switch (format) {
    case RecordFormat::kAt2:
      return "PEER AT2";
    case RecordFormat::kEsm:
      return "ESM/ITACA ASCII";
    case RecordFormat::kCsv:
      return "CSV";
  }
  return "unknown";
}

std::optional<RecordFormat> detect_record_format(std::string_view text) {
  const std::string origin;
  LineReader reader(text, origin);
  std::array<std::string, 4> first_upper;
  std::optional<std::string_view> first_content;
  std::string_view line;
  for (std::size_t i = 0; i < kDetectionLines && reader.next(line); ++i) {
    if (line.starts_with("SAMPLING_INTERVAL_S:") || (i == 0 && line.starts_with("EVENT_NAME:"))) {
      return RecordFormat::kEsm;
    }
    if (i < first_upper.size()) first_upper[i] = uppercase(line.substr(0, 200));
    const std::string_view content = trim(line);
    if (!first_content && !content.empty() && content.front() != '#') first_content = content;
  }
  if (looks_like_at2(first_upper)) return RecordFormat::kAt2;
  if (first_content && first_content->find(',') != std::string_view::npos &&
      std::tolower(static_cast<unsigned char>(first_content->front())) == 't') {
    return RecordFormat::kCsv;
  }
  return std::nullopt;
}

Record parse_record(std::string_view text, RecordFormat format, const std::string& origin,
                    double gravity) {
  switch (format) {
    case RecordFormat::kAt2:
      return parse_at2(text, origin, gravity);
    case RecordFormat::kEsm:
      return parse_esm(text, origin, gravity);
    case RecordFormat::kCsv:
      return parse_csv(text, origin, gravity);
  }
  throw InputError(origin + ": unknown record format");
}

// ---- files -------------------------------------------------------------------------------------

Record read_at2(const std::string& path, double gravity) {
  return parse_at2(read_text_file(path, kMaxRecordFileBytes, "record"), path, gravity);
}

Record read_esm(const std::string& path, double gravity) {
  return parse_esm(read_text_file(path, kMaxRecordFileBytes, "record"), path, gravity);
}

Record read_csv_record(const std::string& path, double gravity) {
  return parse_csv(read_text_file(path, kMaxRecordFileBytes, "record"), path, gravity);
}

Record read_record(const std::string& path, double gravity) {
  const std::string text = read_text_file(path, kMaxRecordFileBytes, "record");
  if (const std::optional<RecordFormat> format = detect_record_format(text)) {
    return parse_record(text, *format, path, gravity);
  }
  const std::string extension = lowercase(std::filesystem::path(path).extension().string());
  if (extension == ".at2") return parse_at2(text, path, gravity);
  if (extension == ".asc") return parse_esm(text, path, gravity);
  if (extension == ".csv") return parse_csv(text, path, gravity);
  throw InputError(path +
                   ": unknown record format (expected a PEER AT2 file, an ESM/ITACA ASCII file or "
                   "a CSV file 't,<name> [unit]'; see docs/record-formats.md)");
}

}  // namespace plinth::host
