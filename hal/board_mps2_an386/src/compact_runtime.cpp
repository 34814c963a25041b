// Runtime routines in place of the toolchain's, for flash: libgcc's and newlib's are written for
// speed, and plinth calls them only to print, to encode times and while starting. Compiled
// without LTO and as freestanding code (no builtins): the calls appear only in LTO's generated
// code, and a loop here must not become a call to itself.
//
// 64-bit integer division (__aeabi_uldivmod, __aeabi_ldivmod: Arm's RTABI, section 4.3.1):
// libgcc's __udivmoddi4 alone is 700 bytes, this about 270. Normalised long division, one compare
// and subtract per quotient bit (a day in nanoseconds by a millisecond: 27 bits). board_check
// checks it.
#include <cstddef>
#include <cstdint>

namespace {

// n / d, and n % d in `remainder`. d = 0, which plinth never divides by: the quotient saturates
// and the remainder is n.
[[gnu::noinline]] std::uint64_t unsigned_division(std::uint64_t n, std::uint64_t d,
                                                  std::uint64_t* remainder) {
  if (d == 0) {
    *remainder = n;
    return ~std::uint64_t{0};
  }
  if (d > n) {
    *remainder = n;
    return 0;
  }
  int shift = __builtin_clzll(d) - __builtin_clzll(n);  // d's top bit under n's
  d <<= shift;
  std::uint64_t q = 0;
  for (;;) {
    if (n >= d) {
      n -= d;
      q |= 1;
    }
    if (shift-- == 0) break;
    q <<= 1;
    d >>= 1;
  }
  *remainder = n;
  return q;
}

std::uint64_t magnitude(std::int64_t v) {
  const auto u = static_cast<std::uint64_t>(v);
  return v < 0 ? 0 - u : u;
}

}  // namespace

// Called by the wrappers below with the dividend and divisor where the ABI passes them (r0:r1,
// r2:r3) and where to put the remainder (on the stack).
extern "C" [[gnu::used]] std::uint64_t plinth_udivmod64(std::uint64_t n, std::uint64_t d,
                                                        std::uint64_t* remainder) {
  return unsigned_division(n, d, remainder);
}

// C's truncating division: the quotient's sign is the operands' product's, the remainder's the
// dividend's.
extern "C" [[gnu::used]] std::int64_t plinth_sdivmod64(std::int64_t n, std::int64_t d,
                                                       std::int64_t* remainder) {
  std::uint64_t r = 0;
  const std::uint64_t q = unsigned_division(magnitude(n), magnitude(d), &r);
  *remainder = static_cast<std::int64_t>(n < 0 ? 0 - r : r);
  return static_cast<std::int64_t>((n < 0) != (d < 0) ? 0 - q : q);
}

// The ABI returns the quotient in r0:r1 and the remainder in r2:r3, which no C++ return does:
// the remainder goes through an 8-byte slot of the wrapper's frame (the stack stays 8-aligned).
#define PLINTH_DIVMOD_WRAPPER(name, helper)          \
  extern "C" [[gnu::naked, gnu::used]] void name() { \
    asm("push {r4, lr}\n"                            \
        "sub sp, sp, #16\n"                          \
        "add r4, sp, #8\n"                           \
        "str r4, [sp]\n"                             \
        "bl " #helper "\n"                           \
        "ldrd r2, r3, [sp, #8]\n"                    \
        "add sp, sp, #16\n"                          \
        "pop {r4, pc}\n");                           \
  }
PLINTH_DIVMOD_WRAPPER(__aeabi_uldivmod, plinth_udivmod64)
PLINTH_DIVMOD_WRAPPER(__aeabi_ldivmod, plinth_sdivmod64)
#undef PLINTH_DIVMOD_WRAPPER

// newlib's strlen is 220 bytes of word-at-a-time code; the console's lines are short.
extern "C" std::size_t strlen(const char* s) {
  const char* end = s;
  while (*end != '\0') ++end;
  return static_cast<std::size_t>(end - s);
}
