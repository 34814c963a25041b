// Cortex-M start-up: the vector table, the reset handler and the fault handler. Freestanding and
// heap-free: no newlib start files (crt0, __libc_init_array), the C++ constructors are run here.
#include <array>
#include <cstddef>
#include <cstdint>

#include "plinth/hal/board.h"
#include "plinth/hal/semihosting.h"

// Symbols of the linker script (mps2_an386.ld.in).
extern "C" {
extern std::uint32_t __data_load[];
extern std::uint32_t __data_start[];
extern std::uint32_t __data_end[];
extern std::uint32_t __bss_start[];
extern std::uint32_t __bss_end[];
extern std::uint32_t __stack_limit[];
extern std::uint32_t __stack_top[];
using Constructor = void (*)();
extern Constructor __init_array_start[];
extern Constructor __init_array_end[];

[[noreturn]] void plinth_reset_handler();
[[noreturn]] void plinth_fault_handler();
}

namespace {

constexpr std::uint32_t kStackPaint = 0x57AC57AC;
// Words below the stack pointer the reset handler leaves unpainted (its own frame).
constexpr std::size_t kPaintMarginWords = 16;
// Coprocessor access control: CP10 and CP11 (the FPU) full access, bits 20-23.
volatile std::uint32_t* const kCpacr = reinterpret_cast<volatile std::uint32_t*>(0xE000ED88);
constexpr std::uint32_t kCpacrFpuFullAccess = 0xFu << 20;

using Handler = void (*)();

}  // namespace

// The vector table after the initial stack pointer (the linker script writes that first word):
// reset, then NMI .. SysTick (14 exceptions) and the board's 32 interrupts, all faults here.
constexpr std::size_t kVectors = 1 + 14 + 32;
constexpr std::array<Handler, kVectors> vector_table() {
  std::array<Handler, kVectors> table{};
  table[0] = plinth_reset_handler;
  for (std::size_t i = 1; i < kVectors; ++i) table[i] = plinth_fault_handler;
  return table;
}
extern "C" __attribute__((section(".vectors"), used)) constexpr std::array<Handler, kVectors>
    plinth_vector_table = vector_table();

// No floating-point instruction may run before the FPU is enabled: the first statements.
extern "C" void plinth_reset_handler() {
  *kCpacr = *kCpacr | kCpacrFpuFullAccess;
  asm volatile("dsb\n\tisb" ::: "memory");

  for (std::uint32_t *from = __data_load, *to = __data_start; to < __data_end;) *to++ = *from++;
  for (std::uint32_t* to = __bss_start; to < __bss_end;) *to++ = 0;
  // Paint the stack below this frame: stack_used_bytes() finds the deepest overwritten word.
  std::uint32_t* sp = nullptr;
  asm volatile("mov %0, sp" : "=r"(sp));
  for (std::uint32_t* word = __stack_limit; word < sp - kPaintMarginWords;) *word++ = kStackPaint;

  for (Constructor* c = __init_array_start; c < __init_array_end; ++c) (*c)();
  plinth::hal::semihosting::exit(plinth_board_main());
}

// Any other exception is a fault of this program: say which (IPSR) and stop with status 3.
extern "C" void plinth_fault_handler() {
  std::uint32_t ipsr = 0;
  asm volatile("mrs %0, ipsr" : "=r"(ipsr));
  char text[] = "plinth: fault: exception 00\n";
  const std::uint32_t exception = ipsr & 0x1FF;
  text[sizeof text - 4] = static_cast<char>('0' + exception / 10 % 10);
  text[sizeof text - 3] = static_cast<char>('0' + exception % 10);
  plinth::hal::semihosting::write(text);
  plinth::hal::semihosting::exit(3);
}

namespace plinth::hal::board {

std::size_t stack_size_bytes() {
  return static_cast<std::size_t>(__stack_top - __stack_limit) * sizeof(std::uint32_t);
}

std::size_t stack_used_bytes() {
  const std::uint32_t* word = __stack_limit;
  while (word < __stack_top && *word == kStackPaint) ++word;
  return static_cast<std::size_t>(__stack_top - word) * sizeof(std::uint32_t);
}

}  // namespace plinth::hal::board
