// A name given on the command line or in a file, read with its enum's NameTable
// (plinth/core/name_table.h): the error lists every name the table has.
#pragma once

#include <string>
#include <type_traits>

#include "plinth/core/name_table.h"
#include "plinth/host/input_error.h"

namespace plinth::host {

// The value `kTable` names `text`. Throws InputError("<where>: unknown <what> '<text>' (one of
// a, b, c)") when it has no such name.
template <const auto& kTable>
[[nodiscard]] auto parse_name(const std::string& text, const std::string& where,
                              const std::string& what) {
  typename std::remove_cvref_t<decltype(kTable)>::value_type value{};
  if (!kTable.parse(text, value)) {
    throw InputError(where + ": unknown " + what + " '" + text + "' (one of " +
                     joined_names<kTable>("").data() + ")");
  }
  return value;
}

}  // namespace plinth::host
