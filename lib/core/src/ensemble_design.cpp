#include "plinth/core/ensemble_design.h"

namespace plinth {

namespace {

// Column `column` of a 2^k-run design at run `run`: the product of the base factors whose bits
// are set in `column` (column 1 = A, 2 = B, 3 = AB, ...), each factor -1 or +1 by the run's bit.
Real interaction(unsigned column, unsigned run) {
  Real sign = 1.0;
  for (unsigned bit = 0; (1U << bit) <= column; ++bit) {
    if ((column >> bit & 1U) != 0U) sign *= (run >> bit & 1U) != 0U ? Real(1) : -Real(1);
  }
  return sign;
}

// The columns that carry the parameters, base factors first: for 8 runs A, B, C, then
// D = ABC (resolution IV for four parameters), E = AB, F = AC, G = BC; for 16 runs A..D, then
// the interactions, highest order first.
constexpr std::array<unsigned, 7> kColumns8{0b001, 0b010, 0b100, 0b111, 0b011, 0b101, 0b110};
constexpr std::array<unsigned, 15> kColumns16{0b0001, 0b0010, 0b0100, 0b1000, 0b1111,
                                              0b0111, 0b1011, 0b1101, 0b1110, 0b0011,
                                              0b0101, 0b1001, 0b0110, 0b1010, 0b1100};

}  // namespace

int design_point_count(int dimensions) {
  if (dimensions < 0 || dimensions > kMaxUncertainParameters) return 0;
  if (dimensions <= 3) return 1 + (1 << dimensions);
  return dimensions <= 7 ? 1 + 8 : 1 + 16;
}

int two_level_design(int dimensions, std::span<DesignPoint> out) {
  const int count = design_point_count(dimensions);
  if (count == 0 || out.size() < static_cast<std::size_t>(count)) return 0;
  out[0] = DesignPoint{};
  const auto d = static_cast<std::size_t>(dimensions);
  for (unsigned run = 0; run + 1 < static_cast<unsigned>(count); ++run) {
    DesignPoint& z = out[run + 1];
    z = DesignPoint{};
    for (std::size_t i = 0; i < d; ++i) {
      const unsigned column = dimensions <= 3 ? 1U << i
                              : dimensions <= 7 ? kColumns8[i]
                                                : kColumns16[i];
      z[i] = interaction(column, run);
    }
  }
  return count;
}

}  // namespace plinth
