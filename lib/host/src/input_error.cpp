#include "plinth/host/input_error.h"

#include <cstdio>
#include <string>

#include "plinth/host/limits.h"

namespace plinth::host {

namespace {

// The escapes of shown() and printable(); `keep_line_breaks`: a line feed stays one.
std::string escaped(std::string_view text, bool keep_line_breaks) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (text.substr(i, 3) == "\xEF\xBB\xBF") {
      out += "\\ufeff";
      i += 2;
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\n') {
      out += keep_line_breaks ? "\n" : "\\n";
    } else if (c < 0x20 || c == 0x7F) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      out += hex;
    } else if (c == '\\' && !keep_line_breaks) {
      out += "\\\\";
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}

}  // namespace

std::string shown(std::string_view text) {
  std::string out(1, '\'');
  out += escaped(text, false);
  out += '\'';
  return out;
}

std::string printable(std::string_view message) { return escaped(message, true); }

void throw_if_simulator_error(const Error& e, const Scene& scene, double step) {
  if (e.ok()) return;
  if (std::string(e.field) != "solver.step" || !scene.has_base()) {
    throw InputError(std::string(e.field) + ": " + e.reason);
  }
  // The step is the tools' --dt; the limit comes from the base's fastest mode (stability.h).
  const BaseParams& base = scene.params.base;
  const std::string keys = "base.period T = " + number_text(base.period, 4) +
                           " s, base mass m_b = " + number_text(base.mass, 4) +
                           " kg (base.mass_ratio or base.mass), base.damping_ratio xi = " + number_text(base.damping_ratio, 4);
  if (!(e.limit >= kSmallestUsableStep)) {
    throw InputError("the scene's base (" + keys +
                     ") is too stiff or too light to integrate at any usable step: its largest "
                     "stable step is " + number_text(e.limit, 3) + " s, below " +
                     number_text(kSmallestUsableStep) +
                     " s; a longer base.period or a heavier base");
  }
  throw InputError("--dt " + number_text(step) + ": too large for a stable integration of this " +
                   "scene's base (" + keys + ": a stiff or light base); the largest stable step "
                   "is " + number_text(e.limit, 3) + " s");
}

}  // namespace plinth::host
