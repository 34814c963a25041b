#include "plinth/host/output_file.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "plinth/host/input_error.h"

namespace plinth::host {
namespace fs = std::filesystem;

void check_output_path(const std::string& option, const std::string& path) {
  if (path.empty()) throw InputError(option + ": an empty file name");
  const std::string prefix = option + " " + path + ": ";
  const fs::path parent = fs::path(path).parent_path();
  std::error_code error;
  if (!parent.empty()) {
    const fs::file_status folder = fs::status(parent, error);
    if (!fs::exists(folder)) {
      throw InputError(prefix + "the folder " + parent.string() + " does not exist");
    }
    if (!fs::is_directory(folder)) {
      throw InputError(prefix + parent.string() + " is not a folder");
    }
  }
  const fs::file_status status = fs::status(path, error);
  if (fs::is_directory(status)) throw InputError(prefix + "is a directory, expected a file");
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    throw InputError(prefix + "is not a regular file (a FIFO, socket or device)");
  }
}

void check_distinct_files(const std::vector<std::pair<std::string, std::string>>& outputs,
                          const std::vector<std::pair<std::string, std::string>>& inputs) {
  std::vector<std::pair<std::string, std::string>> all = outputs;
  all.insert(all.end(), inputs.begin(), inputs.end());
  const auto same = [](const std::string& a, const std::string& b) {
    std::error_code error;
    if (fs::weakly_canonical(a, error) == fs::weakly_canonical(b, error) && !error) return true;
    return fs::equivalent(a, b, error) && !error;
  };
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i].second.empty()) continue;
    for (std::size_t j = 0; j < all.size(); ++j) {
      if (j == i || all[j].second.empty() || (j < outputs.size() && j < i)) continue;
      if (same(outputs[i].second, all[j].second)) {
        throw InputError(outputs[i].first + " " + outputs[i].second + " and " + all[j].first + " " +
                         all[j].second + " name the same file" +
                         (j < outputs.size() ? "" : ": the output would overwrite the input"));
      }
    }
  }
}

OutputFile::OutputFile(std::string option, std::string path)
    : option_(std::move(option)), path_(std::move(path)) {
  check_output_path(option_, path_);
  temporary_ = path_ + ".partial-" + std::to_string(::getpid());
  out_.open(temporary_, std::ios::out | std::ios::trunc);
  if (!out_) {
    throw InputError(option_ + " " + path_ + ": cannot create a file in its folder");
  }
}

OutputFile::~OutputFile() {
  if (committed_) return;
  out_.close();
  std::error_code error;
  fs::remove(temporary_, error);
}

void OutputFile::commit() {
  out_.flush();
  const bool written = static_cast<bool>(out_);
  out_.close();
  if (!written || out_.fail()) {
    throw InputError(option_ + " " + path_ + ": write failed (disk full?)");
  }
  std::error_code error;
  fs::rename(temporary_, path_, error);
  if (error) throw InputError(option_ + " " + path_ + ": cannot replace it: " + error.message());
  committed_ = true;
}

}  // namespace plinth::host
