// The scenes a sweep runs (docs/sweep.md): a base scene with one parameter set to each value,
// built and checked once, and the same block on the ground for --compare-ground.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "plinth/core/name_table.h"
#include "plinth/core/scene.h"

namespace plinth::host {

// The scene parameters a sweep can vary (dimensionless where the paper's are).
enum class SweepParameter : unsigned char {
  kMuS,        // "mu_s": static friction; kinetic = 0.8 mu_s; adds [friction] when absent
  kEpsilon,    // "epsilon": eccentricity = epsilon b
  kLambda,     // "lambda": h = lambda b; mass and inertia follow (mass per unit height kept)
  kPeriod,     // "T": base period, s (needs a base)
  kXi,         // "xi": base damping ratio (needs a base)
  kUMax,       // "u_max": base stop gap, m (needs base stops)
  kMassRatio,  // "mass_ratio": m_b / m (needs a base)
};

inline constexpr NameTable<SweepParameter, 7> kSweepParameterNames{{{
    {SweepParameter::kMuS, "mu_s"},
    {SweepParameter::kEpsilon, "epsilon"},
    {SweepParameter::kLambda, "lambda"},
    {SweepParameter::kPeriod, "T"},
    {SweepParameter::kXi, "xi"},
    {SweepParameter::kUMax, "u_max"},
    {SweepParameter::kMassRatio, "mass_ratio"},
}}};
[[nodiscard]] constexpr const char* sweep_parameter_name(SweepParameter parameter) {
  return kSweepParameterNames.name(parameter);
}

// Throws InputError("<option>: unknown parameter 'x' (one of mu_s, epsilon, ...)").
[[nodiscard]] SweepParameter parse_sweep_parameter(const std::string& text,
                                                   const std::string& option = "--param");

// Whether the parameter exists only with a base (T, xi, u_max, mass_ratio): the block on the
// ground does not have it.
[[nodiscard]] bool parameter_needs_base(SweepParameter parameter);

// "--param mu_s = 0.3" (option "--param"), the prefix of a value's error messages.
[[nodiscard]] std::string describe_value(const std::string& option, SweepParameter parameter,
                                         double value);

// The scene `base` with the parameter set to `value` (in SI), built and checked by make_scene.
// lambda keeps the block's mass per unit of height (m scales with h, I_C =
// homogeneous_rectangle_inertia) and the base's mass ratio. Throws InputError naming the option,
// the parameter and the value (describe_value) when the scene has no base (T, xi, mass_ratio)
// or no base stops (u_max), or make_scene refuses the result (with its field).
[[nodiscard]] Scene sweep_scene(const SceneParams& base, SweepParameter parameter, double value,
                                const std::string& option = "--param");

// sweep_scene of each value, all checked before the first simulation runs.
[[nodiscard]] std::vector<Scene> sweep_scenes(const SceneParams& base, SweepParameter parameter,
                                              const std::vector<double>& values);

// The non-isolated counterpart of a scene (the paper's section 5 comparisons, Figs. 9-10): the
// same block (geometry, mass, inertia, eccentricity) under the same gravity standing on the
// ground, with the same friction between block and ground as between block and base (or none,
// as on the base). It has no base, no base stops, and neither the support's edge nor the sliding
// stops, which belong to the base plate. Its possible events (possible_events) are rocking,
// overturned and, with friction, sliding and slide_rocking.
[[nodiscard]] SceneParams ground_counterpart(const SceneParams& params);

// Throws InputError naming --compare-ground when the scene has no base (it is already the
// block on the ground).
void require_base_to_compare(const SceneParams& params);

// The counterparts on the ground of a sweep's scenes, each distinct one built and checked once
// (a parameter the ground lacks, T or xi, gives one for the whole sweep).
struct GroundScenes {
  std::vector<Scene> distinct;
  std::vector<std::size_t> of;  // of[i]: the index in `distinct` of scenes[i]'s counterpart
};
[[nodiscard]] GroundScenes ground_scenes(const std::vector<Scene>& scenes);

// The CSV columns of the counterpart on the ground carry its event's name with this suffix
// ("rocking_ground"); they come after the scene's own columns, and only for the events the
// block on the ground can have.
inline constexpr const char* kGroundSuffix = "_ground";

}  // namespace plinth::host
