#include "plinth/host/cli.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>

#include "plinth/version/version.h"

namespace plinth::host {
namespace {

// The validator's message for `text`, or empty when it is a finite number (> 0 if asked).
std::string check_finite(const std::string& text, bool positive) {
  double value = 0.0;
  if (CLI::detail::lexical_cast(text, value) && std::isfinite(value) &&
      (!positive || value > 0.0)) {
    return {};
  }
  std::string message("must be a finite number");
  if (positive) message.append(" greater than zero");
  return message.append(", got '").append(text).append("'");
}

}  // namespace

const CLI::Validator kFinite([](const std::string& text) { return check_finite(text, false); },
                             "FINITE");
const CLI::Validator kFinitePositive(
    [](const std::string& text) { return check_finite(text, true); }, "POSITIVE");

std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv) {
  // "plinth-sim 0.1.0 (v0.1.0-12-g1234abc)": the program's own name, as installed.
  std::string program = argc > 0 && argv[0] != nullptr ? argv[0] : "plinth";
  program.erase(0, program.find_last_of('/') + 1);
  app.set_version_flag("--version", program + " " + version::kVersionText,
                       "print the version and the git description it was built from, and exit");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  return std::nullopt;
}

int run_tool(const char* name, const std::function<int()>& run) {
  try {
    return run();
  } catch (const std::exception& error) {  // InputError (the user's input) and anything else
    std::fprintf(stderr, "%s: error: %s\n", name, error.what());
    return 1;
  }
}

}  // namespace plinth::host
