// plinth-monitor --trace FILE: one tab-separated line per sensor sample the estimators took,
// what the event picture (tools/plinth-event-plot) draws: time, risk, alarm levels, and per axis
// the ground acceleration the model sees, the block's rotation and its phase. Meant for replays
// (a capture of the event recorder); live it costs one buffered write per sample.
// Host code: may allocate and throw.
#pragma once

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>

#include "plinth/firmware/monitor.h"

namespace plinth::firmware {

class SampleTrace {
 public:
  // Creates `path` and writes its header (the columns, the codes of levels and phases). Throws
  // host::InputError naming the file when it cannot be written.
  SampleTrace(const std::string& path, int axis_count, double t_origin);
  // A line when the monitor took a new sample since the previous call: the update's status, and
  // the ground acceleration each axis's nominal statue took (`monitor`'s ensembles).
  void after_update(const MonitorUpdate& update, const Monitor& monitor);
  // Flushes and closes; throws host::InputError on a write error (a full disk).
  void close();

 private:
  struct CloseFile {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::string path_;
  std::unique_ptr<std::FILE, CloseFile> file_;
  int axis_count_;
  double t_origin_;
  std::int64_t last_sample_ns_ = -1;
};

}  // namespace plinth::firmware
