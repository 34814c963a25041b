#include "plinth/hal/semihosting_can.h"

#include "plinth/hal/candump_format.h"
#include "plinth/hal/semihosting.h"

namespace plinth::hal {

IoStatus SemihostingCanPort::send(const can::CanFrame& frame) {
  char line[kCandumpLineCapacity + 1];
  const std::size_t length =
      format_candump_line(line, kCandumpLineCapacity, *now_ns_, interface_name_, frame);
  if (length == 0) return IoStatus::kIoError;
  line[length] = '\n';
  if (!semihosting::write(line, length + 1)) return IoStatus::kIoError;
  ++frames_sent_;
  return IoStatus::kOk;
}

}  // namespace plinth::hal
