// The board under the box's loop: QEMU's mps2-an386 (a Cortex-M4F). Start-up (vector table,
// FPU on, .data and .bss set up, the stack painted), a free-running tick counter, the stack's
// high-water mark. The application provides `int plinth_board_main()`; its return value is the
// program's exit status (through semihosting: QEMU exits with it).
#pragma once

#include <cstddef>
#include <cstdint>

// The application's entry point, called once by the reset handler.
extern "C" int plinth_board_main();

namespace plinth::hal::board {

// The tick counter's rate: the board's system clock, 25 MHz. Under `qemu-system-arm -icount
// shift=0` virtual time advances 1 ns per instruction, so one tick is 40 instructions.
inline constexpr std::uint32_t kTickHz = 25'000'000;
// Ticks since start-up, wrapping at 2^32 (171 s); differences of two readings are exact.
[[nodiscard]] std::uint32_t ticks();

// The stack reserved by the linker script, bytes.
[[nodiscard]] std::size_t stack_size_bytes();
// The most of it ever used, bytes: the painted words overwritten since reset (a lower bound
// only if a function reserved stack it never wrote).
[[nodiscard]] std::size_t stack_used_bytes();

}  // namespace plinth::hal::board
