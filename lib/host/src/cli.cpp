#include "plinth/host/cli.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <iostream>
#include <sstream>
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

// Every option given with an empty value, in `app` and the subcommands chosen.
void refuse_empty_values(const CLI::App& app) {
  for (const CLI::Option* option : app.get_options()) {
    for (const std::string& value : option->results()) {
      if (value.empty()) {
        throw CLI::ValidationError(option->get_name(),
                                   "empty value: give one, or leave the option out");
      }
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) refuse_empty_values(*sub);
}

// The program's own options given with a subcommand, which has its own.
void refuse_options_beside_subcommand(const CLI::App& app) {
  const std::vector<CLI::App*> chosen = app.get_subcommands();
  if (chosen.empty()) return;
  for (const CLI::Option* option : app.get_options()) {
    if (option->count() == 0 || option == app.get_help_ptr() || option == app.get_version_ptr()) {
      continue;
    }
    throw CLI::ValidationError(option->get_name(),
                               "has no effect with the subcommand '" + chosen.front()->get_name() +
                                   "', which has its own options (" + app.get_name() + " " +
                                   chosen.front()->get_name() + " --help)");
  }
}

}  // namespace

void refuse_without_effect(const CLI::App& app, std::initializer_list<const char*> options,
                           bool applies, const std::string& reason) {
  if (applies) return;
  for (const char* option : options) {
    if (app.count(option) > 0) throw CLI::ValidationError(option, reason);
  }
}



const CLI::Validator kFinite([](const std::string& text) { return check_finite(text, false); },
                             "FINITE");
const CLI::Validator kFinitePositive(
    [](const std::string& text) { return check_finite(text, true); }, "POSITIVE");

std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv,
                                      const std::function<void()>& checks) {
  // "plinth-sim 0.1.0 (v0.1.0-12-g1234abc)": the program's own name, as installed.
  std::string program = argc > 0 && argv[0] != nullptr ? argv[0] : "plinth";
  program.erase(0, program.find_last_of('/') + 1);
  app.set_version_flag("--version", program + " " + version::kVersionText,
                       "print the version and the git description it was built from, and exit");
  try {
    app.parse(argc, argv);
    refuse_empty_values(app);
    refuse_options_beside_subcommand(app);
    if (checks) checks();
  } catch (const CLI::ParseError& e) {
    std::ostringstream failure;  // CLI11's message, printed with the user's text escaped
    const int code = app.exit(e, std::cout, failure);
    std::fputs(printable(failure.str()).c_str(), stderr);
    return code == 0 ? 0 : 2;
  }
  return std::nullopt;
}

int run_tool(const char* name, const std::function<int()>& run) {
  try {
    return run();
  } catch (const std::exception& error) {  // InputError (the user's input) and anything else
    std::fprintf(stderr, "%s: error: %s\n", name, printable(error.what()).c_str());
    return 1;
  }
}

}  // namespace plinth::host
