// The record fuzz targets (AT2, ESM, CSV): parse the input as one format, and on success check
// what read_record promises its callers.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "plinth/host/input_error.h"
#include "plinth/host/record_io.h"

namespace plinth::fuzz {

inline constexpr double kGravity = 9.80665;  // m/s2

inline void check_record(const host::Record& record) {
  check(record.dt >= host::kMinRecordDt && record.dt <= host::kMaxRecordDt, "dt within limits");
  check(!record.horizontal.empty(), "at least one sample");
  check(record.horizontal.size() <= host::kMaxRecordSamples, "sample count within limit");
  check(record.vertical.empty() || record.vertical.size() == record.horizontal.size(),
        "vertical as long as horizontal");
  check(record.duration() <= host::kMaxRecordDuration, "duration within limit");
  const double limit = host::kMaxRecordAccelerationG * kGravity;
  for (const double a : record.horizontal) check(std::abs(a) <= limit, "horizontal sample bounded");
  for (const double a : record.vertical) check(std::abs(a) <= limit, "vertical sample bounded");
}

// Parses the input as `format`; an InputError is the expected answer to most inputs.
inline void fuzz_record(const std::uint8_t* data, std::size_t size, host::RecordFormat format) {
  const std::string_view text = as_text(data, size);
  (void)host::detect_record_format(text);
  try {
    check_record(host::parse_record(text, format, "fuzz", kGravity));
  } catch (const host::InputError& error) {
    check(std::string(error.what()).starts_with("fuzz"), "message names the origin");
  }
}

}  // namespace plinth::fuzz
