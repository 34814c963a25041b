#include "plinth/host/units.h"

#include <cctype>
#include <cmath>
#include <cstdlib>

#include "plinth/host/input_error.h"

namespace plinth::host {
namespace {

std::string lowercase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

}  // namespace

double parse_acceleration(const std::string& text, double gravity, const std::string& what) {
  const char* begin = text.c_str();
  char* end = nullptr;
  const double value = std::strtod(begin, &end);
  if (end == begin || !std::isfinite(value)) {
    throw InputError(what + ": '" + text + "' is not a number with a unit (e.g. 0.3g, 2.5m/s2)");
  }
  std::string unit = lowercase(end);
  while (!unit.empty() && unit.front() == ' ') unit.erase(unit.begin());
  if (unit == "g") return value * gravity;
  if (unit == "m/s2" || unit == "m/s^2") return value;
  if (unit == "cm/s2" || unit == "cm/s^2" || unit == "gal") return value * 0.01;
  if (unit.empty()) {
    throw InputError(what + ": '" + text + "' has no unit; write e.g. 0.3g or 2.5m/s2");
  }
  throw InputError(what + ": unknown unit '" + unit + "' (use g, m/s2, cm/s2 or gal)");
}

}  // namespace plinth::host
