// libFuzzer target: the scene file loader (TOML), lib/host/src/scene_toml.cpp. A scene it
// returns has passed make_scene: its derived quantities must be finite and physical.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_check.h"
#include "plinth/host/input_error.h"
#include "plinth/host/scene_toml.h"

namespace {

bool positive(double x) { return std::isfinite(x) && x > 0.0; }
bool non_negative(double x) { return std::isfinite(x) && x >= 0.0; }

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using plinth::fuzz::check;
  const std::string text(plinth::fuzz::as_text(data, size));
  try {
    const plinth::Scene scene = plinth::host::load_scene_text(text, "fuzz.toml");
    check(positive(scene.b) && positive(scene.h) && positive(scene.m), "block b, h, m > 0");
    check(positive(scene.inertia_c) && positive(scene.g), "inertia and gravity > 0");
    check(positive(scene.total_mass) && std::isfinite(scene.impact_inertia), "masses finite");
    check(non_negative(scene.omega) && non_negative(scene.stiffness), "base finite");
    check(non_negative(scene.damping), "damping finite");
  } catch (const plinth::host::InputError& error) {
    check(std::string(error.what()).starts_with("fuzz.toml"), "message names the file");
  }
  return 0;
}
