// Shared by the plinth-sweep test suites: the Brienza record, InputError messages, whole runs.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "bundled_records.h"
#include "plinth/host/input_error.h"
#include "plinth/host/job_runner.h"
#include "plinth/host/record_io.h"
#include "plinth/host/sweep_plan.h"

namespace plinth::host::testing {

inline const Record& brienza() {
  static const Record record = ::plinth::testing::brienza();
  return record;
}

// The message of the InputError `f` throws, or "(no InputError)".
template <class F>
std::string input_error_text(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// Every row of `plan`, on `jobs` threads.
inline std::vector<std::string> run_whole_plan(const SweepPlan& plan, int jobs = 2) {
  JobRun run;
  run.jobs = jobs;
  std::vector<std::string> rows;
  EXPECT_TRUE(run_plan(plan, shard_indices(plan.keys.size(), run), run, rows));
  return rows;
}

}  // namespace plinth::host::testing
