// Running a sweep plan into its CSV file: rows already in the file (or in <out>.partial) are
// kept and not run again, rows are appended to <out>.partial as they finish, the finished file
// is written in grid order; a progress bar on a terminal; SIGINT / SIGTERM stop cleanly.
#pragma once

#include <atomic>
#include <cstddef>
#include <string>

#include "plinth/host/job_runner.h"
#include "plinth/host/sweep_plan.h"
#include "plinth/host/sweep_table.h"

namespace plinth::sim {

struct OutputOptions {
  std::string out_path;
  bool fresh = false;  // ignore rows already in the files
};

struct SweepOutcome {
  std::size_t rows_total = 0;    // rows of this shard
  std::size_t rows_resumed = 0;  // found in the files and kept
  std::size_t rows_written = 0;  // in the file at the end
  std::size_t simulations = 0;
  bool interrupted = false;
  double wall_seconds = 0.0;
};

// Runs the jobs of the run's shard that the files do not hold yet. Throws InputError on bad
// files (a row of another shard, a row twice) and the plan's errors, after writing the rows
// finished so far.
SweepOutcome run_to_file(const plinth::host::SweepPlan& plan, plinth::host::JobRun run,
                         const OutputOptions& options);

// Writes `table` to `path` through a temporary file renamed over it.
void write_table_file(const plinth::host::SweepTable& table, const std::string& path);

}  // namespace plinth::sim
