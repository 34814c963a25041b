// One table per enum: its values' names, read both ways (name and parse), so a name is written
// once. Freestanding: constexpr, no heap.
//
//   inline constexpr NameTable<Phase, 3> kPhaseNames{{{
//       {Phase::kFullContact, "full_contact"}, {Phase::kSliding, "sliding"}, ...}}};
//   kPhaseNames.name(Phase::kSliding)          -> "sliding"
//   kPhaseNames.parse("sliding", phase)        -> true, phase = Phase::kSliding
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace plinth {

template <class Enum>
struct NamedValue {
  Enum value;
  const char* name;
};

template <class Enum, std::size_t N>
struct NameTable {
  using value_type = Enum;

  std::array<NamedValue<Enum>, N> entries;

  // The value's name; `fallback` for a value not in the table (a corrupted or foreign value).
  [[nodiscard]] constexpr const char* name(Enum value, const char* fallback = "invalid") const {
    for (const NamedValue<Enum>& e : entries) {
      if (e.value == value) return e.name;
    }
    return fallback;
  }

  // True, with `out` set, when `text` is one of the names; `out` is untouched otherwise.
  [[nodiscard]] constexpr bool parse(std::string_view text, Enum& out) const {
    for (const NamedValue<Enum>& e : entries) {
      if (text == e.name) {
        out = e.value;
        return true;
      }
    }
    return false;
  }

  // The values in the table's order (to iterate over every value of the enum).
  [[nodiscard]] constexpr std::array<Enum, N> values() const {
    std::array<Enum, N> out{};
    for (std::size_t i = 0; i < N; ++i) out[i] = entries[i].value;
    return out;
  }

  [[nodiscard]] constexpr std::size_t size() const { return N; }
  [[nodiscard]] constexpr auto begin() const { return entries.begin(); }
  [[nodiscard]] constexpr auto end() const { return entries.end(); }
};

// `prefix` then the table's names, "a, b, c", as a constant (std::array<char, ...>, 0-ended)
// for an Error's reason or a message: joined_names<kStepperNames>("must be one of ").data().
template <const auto& kTable, std::size_t P>
[[nodiscard]] consteval auto joined_names(const char (&prefix)[P]) {
  constexpr std::size_t kNames = [] {
    std::size_t size = 2 * (kTable.size() - 1);  // the separators
    for (const auto& e : kTable) size += std::string_view(e.name).size();
    return size;
  }();
  std::array<char, P + kNames> out{};  // P counts prefix's '\0', which ends `out` instead
  std::size_t at = 0;
  for (std::size_t i = 0; i + 1 < P; ++i) out[at++] = prefix[i];
  bool first = true;
  for (const auto& e : kTable) {
    if (!first) {
      out[at++] = ',';
      out[at++] = ' ';
    }
    first = false;
    for (const char* c = e.name; *c != '\0'; ++c) out[at++] = *c;
  }
  return out;
}

}  // namespace plinth
