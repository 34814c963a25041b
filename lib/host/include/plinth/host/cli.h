// The command-line tools' shared CLI11 pieces: number checks, parsing with the tools' exit
// codes, and the end of main.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <optional>

namespace plinth::host {

// A finite number; a finite number greater than zero. (CLI11's PositiveNumber lets NaN through
// and prints DBL_MAX in its message.)
extern const CLI::Validator kFinite;
extern const CLI::Validator kFinitePositive;

// Parses the command line, after adding --version (the program's name from argv[0] and
// plinth/version/version.h's kVersionText). Empty: go on. Otherwise CLI11 has printed the help or the usage
// error, and the tool exits with this code: 0 after --help (or --version), 2 on a usage error.
[[nodiscard]] std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv);

// Runs a tool's work and returns its exit code: `run`'s, or 1 after an InputError or any other
// exception, printed on stderr as "NAME: error: what".
[[nodiscard]] int run_tool(const char* name, const std::function<int()>& run);

}  // namespace plinth::host
