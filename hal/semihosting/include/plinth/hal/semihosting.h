// Arm semihosting: the debugger's (here QEMU's) console and exit, reached with `bkpt 0xAB` from
// a Cortex-M. The board's stand-in for a serial console: no heap, no stdio, no newlib (newlib's
// semihosting stdio buffers its FILEs and formats numbers with malloc). QEMU runs it with
// `-semihosting-config enable=on,target=native`; without a debugger attached, `bkpt` faults.
#pragma once

#include <cstddef>
#include <cstdint>

namespace plinth::hal::semihosting {

// Writes `length` bytes to the host's standard output. Returns false when the host wrote less.
bool write(const char* text, std::size_t length);
// Writes a NUL-terminated string.
bool write(const char* text);

// Ends the program: the host (QEMU) exits with `code` (0..255).
[[noreturn]] void exit(int code);

}  // namespace plinth::hal::semihosting
