// Number checks shared by the command-line tools (CLI11's PositiveNumber lets NaN through and
// prints DBL_MAX in its message).
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace plinth::cli {

inline const CLI::Validator kFinite(
    [](const std::string& text) -> std::string {
      double value = 0.0;
      if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value)) {
        return "must be a finite number, got '" + text + "'";
      }
      return {};
    },
    "FINITE");

inline const CLI::Validator kFinitePositive(
    [](const std::string& text) -> std::string {
      double value = 0.0;
      if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) || value <= 0.0) {
        return "must be a finite number greater than zero, got '" + text + "'";
      }
      return {};
    },
    "POSITIVE");

}  // namespace plinth::cli
