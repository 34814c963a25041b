// libFuzzer target: the two/three-column CSV record reader, lib/host/src/record_io.cpp.
#include "record_check.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  plinth::fuzz::fuzz_record(data, size, plinth::host::RecordFormat::kCsv);
  return 0;
}
