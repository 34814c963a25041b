#include "plinth/host/job_runner.h"

#include <algorithm>
#include <thread>

#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"

namespace plinth::host {

void parse_shard(const std::string& text, int& index, int& count) {
  const auto fail = [&] {
    return InputError("--shard: expected i/N with 1 <= i <= N, got '" + text + "'");
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) throw fail();
  const std::string a = text.substr(0, slash);
  const std::string b = text.substr(slash + 1);
  const auto digits = [](const std::string& s) {
    return !s.empty() && s.size() <= 6 && s.find_first_not_of("0123456789") == std::string::npos;
  };
  if (!digits(a) || !digits(b)) throw fail();
  index = std::stoi(a);
  count = std::stoi(b);
  if (count < 1 || index < 1 || index > count) throw fail();
}

void validate(const JobRun& run) {
  if (run.jobs < 1 || run.jobs > kMaxJobs) {
    throw InputError("--jobs: must be 1 to " + std::to_string(kMaxJobs) + ", got " +
                     std::to_string(run.jobs));
  }
  if (run.shard_count < 1 || run.shard_index < 1 || run.shard_index > run.shard_count) {
    throw InputError("--shard: must be i/N with 1 <= i <= N, got " +
                     std::to_string(run.shard_index) + "/" + std::to_string(run.shard_count));
  }
}

std::vector<std::size_t> shard_indices(std::size_t count, const JobRun& run) {
  validate(run);
  std::vector<std::size_t> indices;
  const auto shards = static_cast<std::size_t>(run.shard_count);
  for (std::size_t i = static_cast<std::size_t>(run.shard_index - 1); i < count; i += shards) {
    indices.push_back(i);
  }
  return indices;
}

bool run_jobs(const std::vector<std::size_t>& indices, const JobRun& run,
              const std::function<void(std::size_t)>& job,
              const std::function<std::string(std::size_t)>& describe) {
  validate(run);
  std::atomic<std::size_t> next{0};
  std::atomic<bool> cancelled{false};
  std::mutex done_mutex;
  std::vector<std::exception_ptr> errors(indices.size());
  const auto stopped = [&] { return run.stop != nullptr && run.stop->load(); };
  auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= indices.size()) return;
      if (stopped()) {
        cancelled = true;
        return;
      }
      const std::size_t i = indices[k];
      try {
        job(i);
        if (run.on_done) {
          const std::lock_guard<std::mutex> lock(done_mutex);
          run.on_done(i);
        }
      } catch (const JobCancelled&) {
        cancelled = true;
        return;
      } catch (const InputError& e) {
        errors[k] = std::make_exception_ptr(InputError(describe(i) + ": " + e.what()));
      } catch (...) {
        errors[k] = std::current_exception();
      }
    }
  };
  const std::size_t threads =
      std::min(static_cast<std::size_t>(run.jobs), std::max<std::size_t>(indices.size(), 1));
  if (threads <= 1) {
    worker();
  } else {
    std::vector<std::thread> pool;
    pool.reserve(threads);
    for (std::size_t t = 0; t < threads; ++t) pool.emplace_back(worker);
    for (std::thread& t : pool) t.join();
  }
  for (const std::exception_ptr& e : errors) {
    if (e) std::rethrow_exception(e);
  }
  return !cancelled.load();
}

}  // namespace plinth::host
