// Running gnuplot on a script the tools write, with file names passed as data: the script reads
// them as ARG1, ARG2, ... (gnuplot -c SCRIPT ARGS), never as text inside its commands, so no
// name (a newline, a quote) can add a command. Shared by plinth-sweep and plinth-accuracy.
#pragma once

#include <string>
#include <vector>

namespace plinth::sim {

// The gnuplot executable on PATH. Throws InputError with the Debian package to install.
[[nodiscard]] std::string find_gnuplot();

// Runs `gnuplot -c script args...` without a shell and waits for it. Throws InputError with
// gnuplot's own messages when it fails.
void run_gnuplot(const std::string& script_path, const std::vector<std::string>& args);

// `text` for a '#' comment line of a script: control characters (a newline would end the
// comment) become '?'.
[[nodiscard]] std::string comment_text(std::string text);

// A private temporary folder (mkdtemp) for one plot: its data, its script and its image under
// fixed names, so that gnuplot reads and writes no name of the user's; the image is then copied
// to the user's path. Removed with everything in it when destroyed. Throws InputError when it
// cannot be made.
class PlotFolder {
 public:
  PlotFolder();
  ~PlotFolder();
  PlotFolder(const PlotFolder&) = delete;
  PlotFolder& operator=(const PlotFolder&) = delete;

  [[nodiscard]] std::string path(const std::string& name) const;  // folder/name
  // Runs gnuplot on the folder's `script`, then copies its `image` to `to` (through to.tmp).
  void draw(const std::string& script, const std::string& image, const std::string& to) const;

 private:
  std::string folder_;
};

}  // namespace plinth::sim
