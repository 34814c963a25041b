#include "sweep_output.h"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

#include "plinth/host/input_error.h"
#include "plinth/host/run_progress.h"
#include "plinth/host/output_file.h"

namespace plinth::sim {
namespace {

using plinth::host::InputError;
using plinth::host::SweepTable;


// Moves `path` aside to the first free name `path`.kept, `path`.kept-2, ... and returns it: rows
// this run cannot continue are never thrown away.
std::string set_aside(const std::string& path) {
  std::string kept = path + ".kept";
  for (int n = 2; std::filesystem::exists(kept); ++n) kept = path + ".kept-" + std::to_string(n);
  std::error_code error;
  std::filesystem::rename(path, kept, error);
  if (error) {
    throw InputError(path + ": cannot be resumed, and cannot be moved aside to " + kept + " (" +
                     error.message() + "); move it, or give another --out");
  }
  return kept;
}

// Rows of `path` that belong to this sweep, placed by key ("" elsewhere); nothing when the file
// is absent. A file that differs only in line endings or formatting (a spreadsheet's quotes,
// spaces, padding, number formats) is read as the same rows (read_sweep_table). A file from
// another sweep, or not a sweep CSV, is moved aside (set_aside), with a note saying why and
// where its rows are.
std::vector<std::string> resumable_rows(const std::string& path,
                                        const plinth::host::SweepPlan& plan,
                                        const std::vector<bool>& in_shard) {
  std::vector<std::string> none(plan.keys.size());
  if (!std::filesystem::exists(path)) return none;
  SweepTable table;
  std::size_t dropped = 0;
  try {
    table = plinth::host::read_sweep_table(path, &dropped);
  } catch (const InputError& e) {
    const std::string kept = set_aside(path);
    std::fprintf(stderr, "plinth-sweep: note: %s; not resumed: it is kept as %s\n", e.what(),
                 kept.c_str());
    return none;
  }
  const std::string difference =
      plinth::host::settings_difference(table.settings, "the file", plan.settings, "this run");
  const std::vector<const plinth::host::AddedColumn*> added =
      plinth::host::columns_added_since(table);
  if (difference.empty() && table.header != plan.header && !added.empty()) {
    // The same sweep by an older plinth-sweep: said so, with why its rows cannot be reused.
    const std::string kept = set_aside(path);
    std::fprintf(stderr,
                 "plinth-sweep: note: %s was %s; not resumed, as %s: its %zu row(s) are kept "
                 "as %s\n",
                 path.c_str(), plinth::host::older_version_text(added).c_str(), added.front()->why,
                 table.rows.size(), kept.c_str());
    return none;
  }
  if (!difference.empty() || table.header != plan.header) {
    const std::string kept = set_aside(path);
    std::fprintf(stderr,
                 "plinth-sweep: note: %s comes from another sweep (%s); not resumed: its %zu "
                 "row(s) are kept as %s\n",
                 path.c_str(), difference.empty() ? "other columns" : difference.c_str(),
                 table.rows.size(), kept.c_str());
    return none;
  }
  std::vector<std::string> placed =
      plinth::host::place_rows(table.rows, plan.keys, plan.key_columns, path);
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (!placed[i].empty() && !in_shard[i]) {
      throw InputError(path + ": holds row '" + plan.keys[i] +
                       "' of another shard; give the --shard that wrote it, or another --out");
    }
  }
  if (dropped > 0) {
    std::fprintf(stderr, "plinth-sweep: note: %s: %zu incomplete row(s) dropped\n", path.c_str(),
                 dropped);
  }
  return placed;
}

}  // namespace


void write_table_file(const SweepTable& table, const std::string& path) {
  plinth::host::OutputFile out("--out", path);  // a temporary renamed once complete
  plinth::host::write_sweep_table(out.stream(), table);
  out.commit();
}

SweepOutcome run_to_file(const plinth::host::SweepPlan& plan, plinth::host::JobRun run,
                         const OutputOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  const std::vector<std::size_t> shard = plinth::host::shard_indices(plan.keys.size(), run);
  std::vector<bool> in_shard(plan.keys.size(), false);
  for (const std::size_t i : shard) in_shard[i] = true;

  const std::string partial_path = options.out_path + ".partial";
  std::vector<std::string> rows(plan.keys.size());
  if (!options.fresh) {
    rows = resumable_rows(options.out_path, plan, in_shard);
    const std::vector<std::string> partial = resumable_rows(partial_path, plan, in_shard);
    for (std::size_t i = 0; i < rows.size(); ++i) {
      if (rows[i].empty()) rows[i] = partial[i];
    }
  }
  SweepOutcome outcome;
  outcome.rows_total = shard.size();
  std::vector<std::size_t> todo;
  for (const std::size_t i : shard) {
    if (rows[i].empty()) {
      todo.push_back(i);
    } else {
      ++outcome.rows_resumed;
    }
  }

  // Rows are appended here as they finish, so a kill loses none; the file in grid order is
  // written at the end.
  std::ofstream partial(partial_path, std::ios::trunc);
  if (!partial) throw InputError(partial_path + ": cannot open for writing");
  partial << plan.settings << '\n' << plan.header << '\n';
  for (const std::string& row : rows) {
    if (!row.empty()) partial << row << '\n';
  }
  partial.flush();

  plinth::host::ProgressBar progress(shard.size(), outcome.rows_resumed, "rows");
  std::size_t done = outcome.rows_resumed;
  run.on_done = [&](std::size_t i) {
    partial << rows[i] << '\n' << std::flush;
    progress.update(++done);
  };
  const auto finish = [&] {
    progress.finish();
    SweepTable table{plan.settings, plan.header, {}};
    for (const std::string& row : rows) {
      if (!row.empty()) table.rows.push_back(row);
    }
    partial.close();
    write_table_file(table, options.out_path);
    std::filesystem::remove(partial_path);
    outcome.rows_written = table.rows.size();
    outcome.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  try {
    outcome.interrupted = !plinth::host::run_plan(plan, todo, run, rows, &outcome.simulations);
  } catch (...) {
    finish();
    throw;
  }
  finish();
  return outcome;
}

}  // namespace plinth::sim
