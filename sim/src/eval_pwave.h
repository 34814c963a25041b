// plinth-eval's P-wave parts (docs/pwave.md): three-component records (--record H --vertical V)
// and `plinth-eval pwave-fit`, which runs the box's P-wave stage (lib/monitor p_wave.h) on
// records scaled to given PGAs and fits its predictor table.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

#include "plinth/host/record_io.h"

namespace plinth::sim {

// The records of --record, each joined with the --vertical of the same rank when any is given
// (then there must be as many): a vertical's file is read as any record and its one component
// becomes the record's vertical (host::attach_vertical). Throws InputError naming the option.
[[nodiscard]] std::vector<host::Record> read_records(const std::vector<std::string>& records,
                                                     const std::vector<std::string>& verticals);

// Adds `pwave-fit` to the application; the returned function runs it once parsed (its exit
// code), and says whether it was the command parsed.
struct Subcommand {
  CLI::App* command = nullptr;
  std::function<int()> run;
};
[[nodiscard]] Subcommand add_pwave_fit(CLI::App& app);

}  // namespace plinth::sim
