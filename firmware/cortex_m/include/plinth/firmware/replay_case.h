// What one microcontroller image replays: the scenes, the estimator's steps per sample and the
// ground motion record, compiled in. Defined by a source plinth-embed-record generates from the
// same scene files, record files and scale a plinth-monitor --replay command line takes, so that
// the image and plinth-monitor can be compared (docs/microcontroller.md).
#pragma once

#include "plinth/core/scene.h"
#include "plinth/hal/compiled_record.h"

namespace plinth::firmware {

struct ReplayCase {
  const char* name = "";
  const char* command = "";  // the plinth-monitor options it reproduces
  SceneParams scene_x;       // the statue's axis 1
  bool has_scene_y = false;  // two axes
  SceneParams scene_y;
  int steps_per_sample = 0;  // 0: the estimator's default
  hal::CompiledRecord record;
};

extern const ReplayCase kReplayCase;

}  // namespace plinth::firmware
