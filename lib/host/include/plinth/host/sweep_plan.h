// A sweep as a plan of jobs that each make one CSV row (docs/sweep.md): what plinth-sweep runs,
// shards, resumes and merges. The PGA modes are here; the impulse modes in sweep_impulse.h.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/host/job_runner.h"
#include "plinth/host/record_io.h"
#include "plinth/host/sweep_parameter.h"
#include "plinth/host/sweep_search.h"
#include "plinth/host/sweep_table.h"

namespace plinth::host {

struct SweepPlan {
  std::string settings;           // the settings line (sweep_table.h)
  std::string header;             // the CSV header
  std::size_t key_columns = 1;    // the first fields of a row that name its grid point
  std::vector<std::string> keys;  // each row's key, in grid order
  // The CSV row of job i (starting with keys[i]); called from several threads at once. Adds
  // its simulations to *simulations; throws JobCancelled when *stop turns true.
  std::function<std::string(std::size_t i, const std::atomic<bool>* stop, std::size_t* simulations)>
      row;
  std::function<std::string(std::size_t i)> describe;  // "--param mu_s = 0.3", for messages
};

// Runs the jobs of `indices` (run_jobs; rows.size() becomes plan.keys.size()); rows[i] is set
// before run.on_done(i). Returns false when the stop flag ended the run. Throws as run_jobs:
// a row's InputError with its describe(i) in front.
bool run_plan(const SweepPlan& plan, const std::vector<std::size_t>& indices, const JobRun& run,
              std::vector<std::string>& rows, std::size_t* simulations = nullptr);

// One parameter (mode "thresholds"): a row per value, "<value>,<threshold of each event in g>"
// under the header "<param>,sliding,rocking,...,overturned" (empty where the event does not
// occur up to pga_max). Every value's scene is built and checked before the plan is returned.
// With `compare_ground` (the scene must have a base), each row also holds the thresholds of
// the value's ground_counterpart, in columns "<event>_ground" for the events it can have
// (possible_events), and the settings line says "compare=ground". A ground scene the same for
// several values (a parameter the ground lacks) is searched once.
[[nodiscard]] SweepPlan plan_thresholds(const SceneParams& base, const Record& record,
                                        SweepParameter parameter, const GridAxis& axis,
                                        const SweepSettings& settings, bool compare_ground = false);

// Two parameters (mode "threshold_map"): a row "<p1>,<p2>,<event>" per cell, the first
// occurrence of `event`, cells in the order p1 then p2. Every cell is checked first. With
// `compare_ground`, also "<event>_ground", the cell's ground_counterpart's; refused when the
// block on the ground cannot have `event`.
[[nodiscard]] SweepPlan plan_threshold_map(const SceneParams& base, const Record& record,
                                           SweepParameter parameter1, const GridAxis& axis1,
                                           SweepParameter parameter2, const GridAxis& axis2,
                                           SweepEvent event, SweepSettings settings,
                                           bool compare_ground = false);

}  // namespace plinth::host
