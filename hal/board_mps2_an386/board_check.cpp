// Checks the board layer on QEMU's mps2-an386 (ctest board_check): semihosting output, the tick
// counter against a loop of known length (under -icount shift=0 one tick is 40 instructions),
// the stack's high-water mark against a frame of known size, the CAN stand-in's log line, and
// the runtime's 64-bit division (src/compact_runtime.cpp). Prints what it measured; exits 0 when
// all hold.
#include <cstddef>
#include <cstdint>

#include "plinth/hal/board.h"
#include "plinth/hal/can_codec.h"
#include "plinth/hal/semihosting.h"
#include "plinth/hal/semihosting_can.h"
#include "plinth/hal/text_line.h"

namespace {

namespace semihosting = plinth::hal::semihosting;

void print_number(const char* label, std::size_t value) {
  char text[96];
  plinth::hal::TextLine line(text, sizeof text);
  line.put(label).decimal(static_cast<std::uint64_t>(value)).put('\n');
  semihosting::write(line.c_str(), line.length());
}

// Two instructions per iteration (subs, bne).
std::uint32_t ticks_of_loop(std::uint32_t iterations) {
  const std::uint32_t start = plinth::hal::board::ticks();
  asm volatile("1: subs %0, #1\n\tbne 1b" : "+r"(iterations));
  return plinth::hal::board::ticks() - start;
}

// Writes kStackProbeBytes of stack.
constexpr std::size_t kStackProbeBytes = 1024;
[[gnu::noinline]] std::uint32_t use_stack() {
  volatile std::uint8_t block[kStackProbeBytes];
  for (std::size_t i = 0; i < kStackProbeBytes; ++i) block[i] = static_cast<std::uint8_t>(i);
  return block[kStackProbeBytes - 1];
}

// One 64-bit division through the runtime (__aeabi_uldivmod or __aeabi_ldivmod: the operands are
// volatile, so nothing is folded) against its known quotient and remainder.
template <class Int>
bool divides(Int n, Int d, Int quotient, Int remainder) {
  volatile Int dividend = n;
  volatile Int divisor = d;
  return dividend / divisor == quotient && dividend % divisor == remainder;
}

// Quotients of 0 to 64 bits, divisors of 1 to 64 bits, every sign, the extremes.
bool long_division_holds() {
  using U = std::uint64_t;
  using S = std::int64_t;
  constexpr U kMax = ~U{0};
  constexpr S kMin = S{-0x7FFFFFFFFFFFFFFF} - 1;
  return divides<U>(0, 7, 0, 0) && divides<U>(6, 7, 0, 6) && divides<U>(kMax, 1, kMax, 0) &&
         divides<U>(kMax, 10, 0x1999999999999999, 5) && divides<U>(kMax, kMax, 1, 0) &&
         divides<U>(kMax - 1, kMax, 0, kMax - 1) &&
         divides<U>(86'400'000'000'123'456, 1'000'000, 86'400'000'000, 123'456) &&
         divides<U>(U{1} << 63, 3, 0x2AAAAAAAAAAAAAAA, 2) &&
         divides<U>(0x123456789ABCDEF0, 0x100000001, 0x12345678, 0x88888878) &&
         divides<S>(-7, 2, -3, -1) && divides<S>(7, -2, -3, 1) && divides<S>(-7, -2, 3, -1) &&
         divides<S>(kMin, 1, kMin, 0) && divides<S>(kMin, 10, -922337203685477580, -8) &&
         divides<S>(-1'500'000'999, 1'000'000, -1'500, -999);
}

}  // namespace

extern "C" int plinth_board_main() {
  bool ok = semihosting::write("board_check: semihosting console\n");

  constexpr std::uint32_t kIterations = 1'000'000;
  const std::uint32_t ticks = ticks_of_loop(kIterations);
  print_number("board_check: ticks for 2000000 instructions: ", ticks);
  // 2e6 instructions at 40 per tick, plus the reads around the loop (within one tick each).
  ok = ok && ticks >= 2 * kIterations / 40 && ticks <= 2 * kIterations / 40 + 2;

  const std::size_t before = plinth::hal::board::stack_used_bytes();
  (void)use_stack();
  const std::size_t after = plinth::hal::board::stack_used_bytes();
  print_number("board_check: stack used before the probe, bytes: ", before);
  print_number("board_check: stack used after a 1024-byte frame, bytes: ", after);
  // The probe's frame starts at this frame's depth, which is at most `before`.
  ok = ok && after >= kStackProbeBytes && after <= before + kStackProbeBytes + 64 &&
       after < plinth::hal::board::stack_size_bytes();

  std::int64_t now_ns = 1'500'000'999;
  plinth::hal::SemihostingCanPort port("can0", &now_ns);
  plinth::hal::can::CanFrame frame;
  frame.id = 0x321;
  frame.length = 8;
  frame.data = {0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF};
  ok = ok && port.send(frame) == plinth::hal::IoStatus::kOk && port.frames_sent() == 1;
  now_ns = -1;  // a negative time cannot be logged
  ok = ok && port.send(frame) == plinth::hal::IoStatus::kIoError;

  const bool division = long_division_holds();
  semihosting::write(division ? "board_check: 64-bit division: ok\n"
                              : "board_check: 64-bit division: FAILED\n");
  ok = ok && division;

  semihosting::write(ok ? "board_check: ok\n" : "board_check: FAILED\n");
  return ok ? 0 : 1;
}
