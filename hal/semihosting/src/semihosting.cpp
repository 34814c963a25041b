#include "plinth/hal/semihosting.h"

namespace plinth::hal::semihosting {
namespace {

// Operation numbers and the exit reason of the Arm semihosting specification (v2, 32-bit).
constexpr std::uint32_t kSysOpen = 0x01;
constexpr std::uint32_t kSysWrite = 0x05;
constexpr std::uint32_t kSysExitExtended = 0x20;
constexpr std::uint32_t kAdpStoppedApplicationExit = 0x20026;
constexpr std::uint32_t kOpenModeWrite = 4;  // "w"; the special name ":tt" is the console

// One semihosting call: operation in r0, its argument block in r1, the result in r0.
std::uint32_t call(std::uint32_t operation, const void* arguments) {
  register std::uint32_t r0 asm("r0") = operation;
  register const void* r1 asm("r1") = arguments;
  asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}

// The console's handle, opened on first use (-1 when the host refused).
std::int32_t console() {
  static std::int32_t handle = -2;
  if (handle == -2) {
    static constexpr char kConsoleName[] = ":tt";
    const std::uint32_t arguments[3] = {reinterpret_cast<std::uint32_t>(kConsoleName),
                                        kOpenModeWrite, sizeof kConsoleName - 1};
    handle = static_cast<std::int32_t>(call(kSysOpen, arguments));
  }
  return handle;
}

}  // namespace

bool write(const char* text, std::size_t length) {
  const std::int32_t handle = console();
  if (handle < 0) return false;
  const std::uint32_t arguments[3] = {static_cast<std::uint32_t>(handle),
                                      reinterpret_cast<std::uint32_t>(text), length};
  return call(kSysWrite, arguments) == 0;  // the bytes not written
}

bool write(const char* text) {
  std::size_t length = 0;
  while (text[length] != '\0') ++length;
  return write(text, length);
}

void exit(int code) {
  const std::uint32_t arguments[2] = {kAdpStoppedApplicationExit, static_cast<std::uint32_t>(code)};
  for (;;) call(kSysExitExtended, arguments);
}

}  // namespace plinth::hal::semihosting
