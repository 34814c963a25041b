// What one microcontroller image replays: the scenes, the estimator's steps per sample and the
// ground motion record, compiled in. Defined by a source plinth-embed-record generates from the
// same scene files, record files and scale a plinth-monitor --replay command line takes, so that
// the image and plinth-monitor can be compared (docs/microcontroller.md).
#pragma once

#include <span>

#include "plinth/core/scene.h"
#include "plinth/hal/compiled_record.h"

namespace plinth::firmware {

struct ReplayCase {
  const char* name = "";
  const char* command = "";  // the plinth-monitor options it reproduces
  // The statues of each axis, the scene file's first, then the other members of the ensemble its
  // [uncertainty] table declares (plinth/core/ensemble_design.h), as plinth-monitor builds them.
  std::span<const SceneParams> x;
  std::span<const SceneParams> y;  // empty: one axis
  int steps_per_sample = 0;  // 0: the estimator's default
  bool forecast = true;      // false: off (plinth-monitor --no-forecast) in a build that has it
  // A statue sensor (record_replay.h: configure_replay_statue_sensor) fed the nominal statue's
  // own rotation each sample: what the statue sensor's update costs.
  bool statue_sensor = false;
  hal::CompiledRecord record;
};

extern const ReplayCase kReplayCase;

}  // namespace plinth::firmware
