// Output files that are whole or absent: written to a temporary file beside the target and
// renamed over it once complete, so that an error, a signal or a crash never leaves a partial
// file that looks like a result. And outputs checked before any work: their folder exists,
// they are not a directory, FIFO or device, and no two of them (or an output and an input) name
// the same file, also through a symbolic or hard link.
#pragma once

#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace plinth::host {

// Throws InputError naming `option` and `path` when `path` cannot be an output file: empty, a
// folder that does not exist (or is not a folder), or a path that exists as anything but a
// regular file (a directory, a FIFO, a device).
void check_output_path(const std::string& option, const std::string& path);

// (option, path) pairs: the outputs first, then the inputs they must not overwrite. Throws
// InputError "--out x.csv and --events x.csv name the same file" when an output names the same
// file as another output or an input: the same path once normalised, or the same existing
// file (std::filesystem::equivalent: symbolic and hard links). Empty paths are skipped.
void check_distinct_files(const std::vector<std::pair<std::string, std::string>>& outputs,
                          const std::vector<std::pair<std::string, std::string>>& inputs = {});

// One output file. The constructor checks the path (check_output_path) and opens a temporary
// file "<path>.partial-<pid>" in the same folder; commit() flushes it and renames it to `path`;
// the destructor removes it when commit() was not reached.
class OutputFile {
 public:
  OutputFile(std::string option, std::string path);
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;
  ~OutputFile();

  [[nodiscard]] std::ostream& stream() { return out_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  // Throws InputError naming the option and the file when a write failed or the rename did.
  void commit();

 private:
  std::string option_;
  std::string path_;
  std::string temporary_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace plinth::host
