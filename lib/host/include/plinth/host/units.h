// Quantities with units on command lines: "0.3g", "2.94m/s2", "300gal".
#pragma once

#include <string>

namespace plinth::host {

// Parses an acceleration with its unit (g, m/s2, cm/s2 or gal) into m/s2, using `gravity` for
// g. Throws InputError naming `what` (e.g. "--pga") when the text is not a finite number
// followed by one of these units.
[[nodiscard]] double parse_acceleration(const std::string& text, double gravity,
                                        const std::string& what);

}  // namespace plinth::host
