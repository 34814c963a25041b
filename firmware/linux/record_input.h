// The record replay's input (record_replay.h): the ground records read at the sensor rate and
// scaled, as the ideal ground sensor's samples in m/s2. plinth-monitor --replay feeds them to
// the box's loop (inputs.cpp); plinth-embed-record compiles them into the microcontroller image.
// Host code (reads files, allocates, throws plinth::host::InputError).
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace plinth::firmware {

struct RecordReplayOptions {
  std::string path;               // horizontal record of the statue's axis 1 (x): .AT2 or .csv
  std::string y_path;             // axis 2 (y); empty: none
  std::string vertical_path;      // vertical record; empty: the x file's vertical column, if any
  std::string pga;                // scale every record so that x peaks at this ("0.3g"); or
  std::optional<double> scale;    // scale factor; neither: 1
  std::optional<double> rate_hz;  // sensor rate; default: the record's within 100-1000 Hz, or 200
};

struct RecordSamples {
  double rate_hz = 0.0;
  std::vector<Eigen::Vector3d> samples;  // m/s2; z = gravity + the vertical acceleration
  bool vertical = false;  // a vertical record was read (--vertical or the x file's column)
};

// Sample k is each record at k / rate_hz (host::resample), times the scale; from 0 to the x
// record's duration. The error messages name the options as the command lines do ("--pga").
[[nodiscard]] RecordSamples record_samples(const RecordReplayOptions& options, double gravity);

}  // namespace plinth::firmware
