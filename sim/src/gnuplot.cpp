#include "gnuplot.h"

#include <fcntl.h>
#include <stdlib.h>  // mkdtemp
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "plinth/host/input_error.h"

extern char** environ;

namespace plinth::sim {
namespace {

using plinth::host::InputError;

constexpr const char* kInstallHint =
    "gnuplot is needed for plots and was not found on PATH: install the Debian package "
    "gnuplot-nox (apt-get install gnuplot-nox, or tools/install-deps.sh)";

}  // namespace

std::string find_gnuplot() {
  const char* path = std::getenv("PATH");
  std::istringstream in(path != nullptr ? path : "");
  std::string dir;
  while (std::getline(in, dir, ':')) {
    if (dir.empty()) continue;
    const std::string candidate = dir + "/gnuplot";
    if (::access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  throw InputError(kInstallHint);
}

void run_gnuplot(const std::string& script_path, const std::vector<std::string>& args) {
  const std::string gnuplot = find_gnuplot();
  const std::string error_path = (std::filesystem::temp_directory_path() /
                                  ("plinth-gnuplot-" + std::to_string(::getpid()) + ".txt"))
                                     .string();
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, error_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0600);
  std::vector<std::string> words = {gnuplot, "-c", script_path};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, gnuplot.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw InputError(kInstallHint);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  std::string errors;
  {
    std::ifstream in(error_path);
    std::ostringstream text;
    text << in.rdbuf();
    errors = text.str();
  }
  std::filesystem::remove(error_path);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    throw InputError("gnuplot failed on " + script_path + ":\n" + errors);
  }
}

PlotFolder::PlotFolder() {
  // Not TMPDIR: the folder's name goes into the script as text, so it is only letters we chose.
  std::string name = "/tmp/plinth-plot-XXXXXX";
  if (::mkdtemp(name.data()) == nullptr) throw InputError("--plot: cannot make a temporary folder");
  folder_ = name;
}

PlotFolder::~PlotFolder() {
  std::error_code ec;
  std::filesystem::remove_all(folder_, ec);
}

std::string PlotFolder::path(const std::string& name) const {
  return (std::filesystem::path(folder_) / name).string();
}

void PlotFolder::draw(const std::string& script, const std::string& image,
                      const std::string& to) const {
  run_gnuplot(path(script), {});
  const std::string temporary = to + ".tmp";
  std::error_code ec;
  std::filesystem::copy_file(path(image), temporary,
                             std::filesystem::copy_options::overwrite_existing, ec);
  if (!ec) std::filesystem::rename(temporary, to, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw InputError(to + ": cannot write the plot: " + ec.message());
  }
}

std::string comment_text(std::string text) {
  for (char& c : text) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7F) c = '?';
  }
  return text;
}

}  // namespace plinth::sim
