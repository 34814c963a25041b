#include "plinth/host/text_file.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "plinth/host/input_error.h"

namespace plinth::host {

namespace {

std::string mebibytes(std::size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

}  // namespace

std::string read_text_file(const std::string& path, std::size_t max_bytes, std::string_view what) {
  const std::string prefix = path + ": cannot open " + std::string(what);
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) throw InputError(prefix + " (no such file)");
  if (std::filesystem::is_directory(status)) throw InputError(prefix + " (it is a directory)");
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(prefix + " (not a regular file: a FIFO, socket or device)");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(prefix);

  const std::string too_long = path + ": the " + std::string(what) + " is longer than the " +
                               mebibytes(max_bytes) + " limit";
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (!error && size > max_bytes) throw InputError(too_long);

  std::string text;
  std::array<char, 1 << 16> chunk{};
  // Bounded even when the file grows while it is read.
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    const auto count = static_cast<std::size_t>(in.gcount());
    if (text.size() + count > max_bytes) throw InputError(too_long);
    text.append(chunk.data(), count);
  }
  if (in.bad()) throw InputError(prefix + " (read error)");
  return text;
}

}  // namespace plinth::host
