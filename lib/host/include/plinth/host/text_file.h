// Reading a whole input file into memory, bounded: every host loader (records, scenes) goes
// through here so that no input can grow memory without limit or block the program.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace plinth::host {

// The contents of `path`, at most `max_bytes` long. Throws InputError naming the path and
// `what` (e.g. "record", "scene file") for: a missing or unreadable file, a directory, anything
// that is not a regular file (a FIFO would block, /dev/zero would never end), a file longer
// than `max_bytes`, and a read error.
[[nodiscard]] std::string read_text_file(const std::string& path, std::size_t max_bytes,
                                         std::string_view what);

}  // namespace plinth::host
