// What a TOML value is, for the messages of the TOML readers (scene files, the monitor's
// configuration): "expected a number, got a string".
#pragma once

#include <toml++/toml.h>

#include <string_view>

#include "plinth/core/name_table.h"

namespace plinth::host {

inline constexpr NameTable<toml::node_type, 10> kTomlNodeTypeNames{{{
    {toml::node_type::none, "nothing"},
    {toml::node_type::table, "a table"},
    {toml::node_type::array, "an array"},
    {toml::node_type::string, "a string"},
    {toml::node_type::integer, "an integer"},
    {toml::node_type::floating_point, "a float"},
    {toml::node_type::boolean, "a boolean"},
    {toml::node_type::date, "a date"},
    {toml::node_type::time, "a time"},
    {toml::node_type::date_time, "a date-time"},
}}};

[[nodiscard]] inline std::string_view toml_type_name(toml::node_type type) {
  return kTomlNodeTypeNames.name(type, "an unknown type");
}

}  // namespace plinth::host
