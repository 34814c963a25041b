// Running a list of independent jobs on threads: a shard of them, a stop flag that ends the run
// cleanly, errors reported for the job that raised them, and values computed once and shared
// between jobs. Knows nothing of what the jobs do (plinth-sweep's rows: sweep_plan.h).
#pragma once

#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace plinth::host {

// Thrown by a job that found its stop flag raised: what it was doing is dropped.
class JobCancelled : public std::exception {
 public:
  [[nodiscard]] const char* what() const noexcept override { return "cancelled"; }
};

// Threads, shard and cancellation of a run of jobs.
struct JobRun {
  int jobs = 1;         // threads
  int shard_index = 1;  // 1-based: the jobs whose index % shard_count == shard_index - 1
  int shard_count = 1;
  const std::atomic<bool>* stop = nullptr;  // once true, no job starts and running ones end
  // Called after each job that finished, one call at a time, from the worker threads.
  std::function<void(std::size_t index)> on_done;
};

// Throws InputError naming --jobs on jobs < 1, --shard on a shard i/N outside 1 <= i <= N.
void validate(const JobRun& run);

// The job indices of `count` that belong to the run's shard, ascending.
[[nodiscard]] std::vector<std::size_t> shard_indices(std::size_t count, const JobRun& run);

// Runs job(i) for each i of `indices` on run.jobs threads. An InputError of a job is rethrown
// with `describe(i) + ": "` in front, the one of the lowest index first, after every thread
// has ended. Returns false when the stop flag (or a job's JobCancelled) ended the run; jobs
// not finished were not reported to on_done.
bool run_jobs(const std::vector<std::size_t>& indices, const JobRun& run,
              const std::function<void(std::size_t)>& job,
              const std::function<std::string(std::size_t)>& describe);

// `size` values, each computed once by the first job asking for it; jobs asking meanwhile wait
// for it. A computation that throws stores nothing (the next job asking tries again).
// Thread-safe.
template <class T>
class OnceCache {
 public:
  explicit OnceCache(std::size_t size) : entries_(size) {}

  template <class Compute>
  T get(std::size_t index, Compute&& compute) {
    Entry& entry = entries_.at(index);
    const std::lock_guard<std::mutex> lock(entry.mutex);
    if (!entry.value) entry.value = compute();
    return *entry.value;
  }

 private:
  struct Entry {
    std::mutex mutex;
    std::optional<T> value;
  };
  std::vector<Entry> entries_;
};

}  // namespace plinth::host
