// Parameter sweeps (plinth-sweep): for each value of one or two scene parameters, the smallest
// PGA at which each kind of event first occurs under a record; the threads, shards and
// cancellation every sweep mode shares. Impulse maps and curves: sweep_impulse.h; the CSV
// files: sweep_table.h.
#pragma once

#include <array>
#include <atomic>
#include <bitset>
#include <cstddef>
#include <exception>
#include <functional>
#include <iosfwd>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/host/record_io.h"
#include "plinth/host/sweep_table.h"

namespace plinth::host {

// The events a sweep looks for, in the order of the CSV columns.
enum class SweepEvent : unsigned char {
  kSliding,       // a kSlidingStart event
  kRocking,       // a kRockingStart event
  kSlideRocking,  // any event leaving the block in Phase::kSlideRocking
  kOutOfBase,     // kOutOfBase
  kBaseStopHit,   // kBaseStopHit
  kSlideStopHit,  // kSlideStopHit
  kFell,          // kFell
  kOverturned,    // kOverturned
};
inline constexpr std::size_t kSweepEventCount = 8;

// A set of events, indexed by SweepEvent.
using EventSet = std::bitset<kSweepEventCount>;
inline const EventSet kAllEvents = EventSet{}.set();

// "sliding", "rocking", "slide_rocking", "out_of_base", "base_stop_hit", "slide_stop_hit",
// "fell", "overturned".
[[nodiscard]] const char* sweep_event_name(SweepEvent event);

// Throws InputError("--event: unknown event 'x' (one of sliding, ...)").
[[nodiscard]] SweepEvent parse_sweep_event(const std::string& text);

// The events the scene's features allow (guards.h, features_of): sliding and slide_rocking
// need friction, base stop hits base stops, leaving the support and falling a support without
// sliding stops, sliding stop hits sliding stops.
[[nodiscard]] EventSet possible_events(const Scene& scene);

struct SweepSettings {
  double pga_max_g = 2.0;      // largest PGA scanned, in g (the scene's gravity)
  double tolerance_g = 0.001;  // width of the final bisection bracket, in g
  int scan_points = 40;        // grid PGA = pga_max * k / scan_points, k = 1..scan_points
  double dt = 5e-4;            // solver step, s
  // The events searched; the others are left empty. A threshold does not depend on which
  // other events are searched with it, so searching fewer only saves simulations.
  EventSet events = kAllEvents;
  // Skips the scan points below the PGA at which the block provably stays in full contact
  // (quiet_pga_g); off only to test that it changes nothing.
  bool skip_quiet_scan = true;
};

// Throws InputError when a setting is out of range (non-finite, not positive, no points).
void validate(const SweepSettings& settings);

// Which events occurred in one simulation; indexed by SweepEvent.
struct Occurrences {
  std::array<bool, kSweepEventCount> occurred{};

  [[nodiscard]] bool operator[](SweepEvent e) const {
    return occurred[static_cast<std::size_t>(e)];
  }
};

// Thrown from a search or a sweep when its stop flag turned true: what was running is dropped.
class SweepCancelled : public std::exception {
 public:
  [[nodiscard]] const char* what() const noexcept override { return "sweep cancelled"; }
};

// One simulation from rest under `record` scaled to a peak of `pga_mps2` (m/s2), with step
// settings.dt, until the record's end + 2 s, a terminal phase, or every event of
// settings.events the scene allows has occurred (the others may then be missing). Throws
// InputError when the record is all zeros or the step is too large for the scene.
[[nodiscard]] Occurrences simulate_occurrences(const Scene& scene, const Record& record,
                                               double pga_mps2, const SweepSettings& settings);

// The PGA (in g) below which the block provably stays in full contact under `record`: no
// event at all. Full contact is linear (Eq 1), so one run of the base alone at unit scale
// gives the peak absolute acceleration and base displacement per unit PGA; the first of Eq 15
// (mu_s g), Eq 16 (min(b1, b2) g / h, either direction) and Eq 28 (u_max) bounds it. Infinity
// when nothing can happen.
[[nodiscard]] double quiet_pga_g(const Scene& scene, const Record& record, double dt);

// The first-occurrence search shared by the PGA thresholds and the impulse curves. `simulate`
// runs at a level in (0, level_max] (PGA in g, impulse in m/s) and reports the events of
// `events`; levels <= `quiet_below` are taken as showing none (not simulated). The grid
// level_max * k / scan_points is scanned; for each event the first grid interval showing it is
// bisected to `tolerance`, and the result thr is checked: the event occurs at thr and not at
// thr - tolerance (when > 0); if it does, the search goes on below. Each event's search uses
// only the scan and its own bisection (runs are shared as a cache), so its result does not
// depend on the other events searched. Nothing is assumed at level 0.
struct SearchGrid {
  double level_max = 1.0;
  int scan_points = 40;
  double tolerance = 1e-3;
  double quiet_below = 0.0;
};
[[nodiscard]] std::array<std::optional<double>, kSweepEventCount> first_occurrences(
    const std::function<Occurrences(double level)>& simulate, const SearchGrid& grid,
    EventSet events, const std::atomic<bool>* stop = nullptr, std::size_t* simulations = nullptr);

// For each event of settings.events the scene allows, the smallest PGA (in g) at which it
// occurs (first_occurrences on PGA), or nothing when it does not occur on the scan grid up to
// settings.pga_max_g. `simulations`, when given, is increased by the number of simulations
// run. Throws SweepCancelled when *stop turns true.
[[nodiscard]] std::array<std::optional<double>, kSweepEventCount> first_occurrence_thresholds(
    const Scene& scene, const Record& record, const SweepSettings& settings,
    std::size_t* simulations = nullptr, const std::atomic<bool>* stop = nullptr);

// The scene parameters a sweep can vary (dimensionless where the paper's are).
enum class SweepParameter : unsigned char {
  kMuS,        // "mu_s": static friction; kinetic = 0.8 mu_s; adds [friction] when absent
  kEpsilon,    // "epsilon": eccentricity = epsilon b
  kLambda,     // "lambda": h = lambda b; mass and inertia follow (mass per unit height kept)
  kPeriod,     // "T": base period, s (needs a base)
  kXi,         // "xi": base damping ratio (needs a base)
  kUMax,       // "u_max": base stop gap, m (needs base stops)
  kMassRatio,  // "mass_ratio": m_b / m (needs a base)
};

[[nodiscard]] const char* sweep_parameter_name(SweepParameter parameter);

// Throws InputError("<option>: unknown parameter 'x' (one of mu_s, epsilon, ...)").
[[nodiscard]] SweepParameter parse_sweep_parameter(const std::string& text,
                                                   const std::string& option = "--param");

// `params` with the parameter set to `value`, in SI. lambda keeps the block's mass per unit of
// height (m scales with h, I_C = homogeneous_rectangle_inertia) and the base's mass ratio.
// Throws InputError naming the parameter and the value when the scene has no base (T, xi,
// mass_ratio) or no base stops (u_max), or when make_scene refuses the result.
[[nodiscard]] SceneParams with_parameter(SceneParams params, SweepParameter parameter, double value,
                                         const std::string& option = "--param");

// Whether the parameter exists only with a base (T, xi, u_max, mass_ratio): the block on the
// ground does not have it.
[[nodiscard]] bool parameter_needs_base(SweepParameter parameter);

// The non-isolated counterpart of a scene (the paper's section 5 comparisons, Figs. 9-10): the
// same block (geometry, mass, inertia, eccentricity) under the same gravity standing on the
// ground, with the same friction between block and ground as between block and base (or none,
// as on the base). It has no base, no base stops, and neither the support's edge nor the sliding
// stops, which belong to the base plate. Its possible events (possible_events) are rocking,
// overturned and, with friction, sliding and slide_rocking.
[[nodiscard]] SceneParams ground_counterpart(const SceneParams& params);

// The CSV columns of the counterpart on the ground carry its event's name with this suffix
// ("rocking_ground"); they come after the scene's own columns, and only for the events the
// block on the ground can have.
inline constexpr const char* kGroundSuffix = "_ground";

// Results computed once per key and shared between the jobs of a plan (the thresholds of a
// counterpart on the ground that does not depend on the swept parameter: T, xi, ...). The
// first job asking for a key computes it; others asking meanwhile wait for it. A computation
// that throws stores nothing (the next job asking tries again). Thread-safe.
template <class T>
class OnceCache {
 public:
  template <class Compute>
  T get(const std::string& key, Compute&& compute) {
    std::shared_ptr<Entry> entry;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      std::shared_ptr<Entry>& slot = entries_[key];
      if (!slot) slot = std::make_shared<Entry>();
      entry = slot;
    }
    const std::lock_guard<std::mutex> lock(entry->mutex);
    if (!entry->value) entry->value = compute();
    return *entry->value;
  }

 private:
  struct Entry {
    std::mutex mutex;
    std::optional<T> value;
  };
  std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Entry>> entries_;
};

// Throws InputError naming --compare-ground when the scene has no base (it is already the
// block on the ground).
void require_base_to_compare(const SceneParams& params);

// The counterparts on the ground of the scenes of a plan (ground_counterpart, make_scene), and
// the fingerprint of each: the key of its results in an OnceCache, equal for equal scenes.
struct GroundScenes {
  std::vector<Scene> scenes;
  std::vector<std::string> keys;
};
[[nodiscard]] GroundScenes ground_scenes(const std::vector<Scene>& scenes);

// Threads, shards and cancellation of a sweep's jobs (one job per CSV row).
struct SweepRun {
  int jobs = 1;
  int shard_index = 1;  // 1-based: the jobs whose index % shard_count == shard_index - 1
  int shard_count = 1;
  const std::atomic<bool>* stop = nullptr;  // once true, no job starts and running ones end
  // Called after each job that finished, one call at a time, from the worker threads.
  std::function<void(std::size_t index)> on_done;
};

// Throws InputError on jobs < 1 or a shard i/N outside 1 <= i <= N.
void validate(const SweepRun& run);

// The job indices of `count` that belong to the run's shard, ascending.
[[nodiscard]] std::vector<std::size_t> shard_indices(std::size_t count, const SweepRun& run);

// Runs job(i) for each i of `indices` on run.jobs threads. An InputError of a job is
// rethrown with `describe(i) + ": "` in front, the one of the lowest index first, after every
// thread has ended. Returns false when the stop flag ended the run (jobs not finished were not
// reported to on_done).
bool run_jobs(const std::vector<std::size_t>& indices, const SweepRun& run,
              const std::function<void(std::size_t)>& job,
              const std::function<std::string(std::size_t)>& describe);

// A sweep as jobs that each make one CSV row: what plinth-sweep runs, resumes and merges.
struct SweepPlan {
  std::string settings;           // the settings line (sweep_table.h)
  std::string header;             // the CSV header
  std::size_t key_columns = 1;    // the first fields of a row that name its grid point
  std::vector<std::string> keys;  // each row's key, in grid order
  // The CSV row of job i (starting with keys[i]); called from several threads at once. Adds
  // its simulations to *simulations; throws SweepCancelled when *stop turns true.
  std::function<std::string(std::size_t i, const std::atomic<bool>* stop, std::size_t* simulations)>
      row;
  std::function<std::string(std::size_t i)> describe;  // "--param mu_s = 0.3", for messages
};

// Runs the jobs of `indices` (rows.size() == plan.keys.size()); rows[i] is set before
// run.on_done(i). Returns false when the stop flag ended the run. Throws as run_jobs.
bool run_plan(const SweepPlan& plan, const std::vector<std::size_t>& indices, const SweepRun& run,
              std::vector<std::string>& rows, std::size_t* simulations = nullptr);

// One parameter: a row of thresholds of every event per value (mode "thresholds", the
// write_sweep_csv format). Every value is checked before the plan is returned.
// With `compare_ground` (the scene must have a base), each row also holds the thresholds of
// the value's ground_counterpart, in columns "<event>_ground" for the events it can have
// (possible_events), and the settings line says "compare=ground". Ground scenes that are the
// same for several values (a parameter the ground lacks) are searched once (OnceCache).
[[nodiscard]] SweepPlan plan_thresholds(const SceneParams& base, const Record& record,
                                        SweepParameter parameter, const GridAxis& axis,
                                        const SweepSettings& settings,
                                        bool compare_ground = false);

// Two parameters (mode "threshold_map"): a row "<p1>,<p2>,<event>" per cell, the first
// occurrence of `event`, cells in the order p1 then p2. Every cell is checked first. With
// `compare_ground`, also "<event>_ground", the cell's ground_counterpart's; refused when the
// block on the ground cannot have `event`.
[[nodiscard]] SweepPlan plan_threshold_map(const SceneParams& base, const Record& record,
                                           SweepParameter parameter1, const GridAxis& axis1,
                                           SweepParameter parameter2, const GridAxis& axis2,
                                           SweepEvent event, SweepSettings settings,
                                           bool compare_ground = false);

struct SweepRow {
  double value = 0.0;
  std::array<std::optional<double>, kSweepEventCount> thresholds_g;
};

struct SweepStats {
  std::size_t simulations = 0;
};

// Sweeps `parameter` over the values of the run's shard. Rows come back in value order and do
// not depend on jobs or sharding. Every value is checked (with_parameter) before any
// simulation runs. Throws InputError on bad jobs or shard numbers, bad values, and errors of
// the simulations (the one of the lowest value index), SweepCancelled when stopped.
[[nodiscard]] std::vector<SweepRow> run_sweep(const SceneParams& base, SweepParameter parameter,
                                              const std::vector<double>& values,
                                              const Record& record, const SweepSettings& settings,
                                              int jobs, int shard_index, int shard_count,
                                              SweepStats* stats = nullptr);

// The scene of each value (with_parameter then make_scene), checked before anything runs.
[[nodiscard]] std::vector<Scene> sweep_scenes(const SceneParams& base, SweepParameter parameter,
                                              const std::vector<double>& values);

// "--param mu_s = 0.3" (option "--param"), the prefix of a value's error messages.
[[nodiscard]] std::string describe_value(const std::string& option, SweepParameter parameter,
                                         double value);

// CSV: header "<param>,sliding,rocking,...,overturned", one line per row; thresholds in g
// (%.6g), empty where the event does not occur up to pga_max.
void write_sweep_csv(std::ostream& out, SweepParameter parameter,
                     const std::vector<SweepRow>& rows);

// "<param>,sliding,rocking,...,overturned" and one row of it.
[[nodiscard]] std::string sweep_csv_header(SweepParameter parameter);
[[nodiscard]] std::string sweep_csv_row(const SweepRow& row);

}  // namespace plinth::host
