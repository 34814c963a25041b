// The board's tick counter: CMSDK APB timer 0 (0x40000000), counting down from 2^32 - 1 at the
// 25 MHz system clock, started on first use.
#include <cstdint>

#include "plinth/hal/board.h"

namespace plinth::hal::board {
namespace {

struct CmsdkTimer {
  volatile std::uint32_t control;  // bit 0: enable
  volatile std::uint32_t value;    // current count, counting down
  volatile std::uint32_t reload;   // loaded when the count reaches 0
};
CmsdkTimer* const kTimer0 = reinterpret_cast<CmsdkTimer*>(0x40000000);
constexpr std::uint32_t kEnable = 1;

}  // namespace

std::uint32_t ticks() {
  if ((kTimer0->control & kEnable) == 0) {
    kTimer0->reload = 0xFFFFFFFF;
    kTimer0->value = 0xFFFFFFFF;
    kTimer0->control = kEnable;
  }
  return ~kTimer0->value;
}

}  // namespace plinth::hal::board
