// The command-line tools' shared CLI11 pieces: number checks, parsing with the tools' exit
// codes, and the end of main.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>

#include "plinth/host/input_error.h"  // shown, printable

namespace plinth::host {

// A finite number; a finite number greater than zero. (CLI11's PositiveNumber lets NaN through
// and prints DBL_MAX in its message.)
extern const CLI::Validator kFinite;
extern const CLI::Validator kFinitePositive;

// Parses the command line, after adding --version (the program's name from argv[0] and
// plinth/version/version.h's kVersionText). Empty: go on. Otherwise CLI11 has printed the help or the usage
// error, and the tool exits with this code: 0 after --help (or --version), 2 on a usage error.
// Every option means something, so these are usage errors too, for every program:
//  - an empty value ("--pga ''", "--out=", an empty positional): refused, not taken as absent;
//  - an option of the program itself given with a subcommand (which has its own options);
//  - what `checks` refuses, after the parse (refuse_without_effect: an option with no effect in
//    the mode the command line chose).
[[nodiscard]] std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv,
                                                    const std::function<void()>& checks = {});

// For parse_command_line's `checks`: when `applies` is false, the first of `options` given on
// the command line (of `app`) is refused: "<option>: <reason>". The reason says what the option
// does and why the chosen mode has no use for it.
void refuse_without_effect(const CLI::App& app, std::initializer_list<const char*> options,
                           bool applies, const std::string& reason);


// Runs a tool's work and returns its exit code: `run`'s, or 1 after an InputError or any other
// exception, printed on stderr as "NAME: error: what".
[[nodiscard]] int run_tool(const char* name, const std::function<int()>& run);

}  // namespace plinth::host
