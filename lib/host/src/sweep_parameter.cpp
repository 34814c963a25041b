#include "plinth/host/sweep_parameter.h"

#include <cmath>
#include <map>

#include "plinth/host/input_error.h"
#include "plinth/host/parse_name.h"
#include "plinth/host/sweep_table.h"

namespace plinth::host {

SweepParameter parse_sweep_parameter(const std::string& text, const std::string& option) {
  return parse_name<kSweepParameterNames>(text, option, "parameter");
}

bool parameter_needs_base(SweepParameter parameter) {
  return parameter == SweepParameter::kPeriod || parameter == SweepParameter::kXi ||
         parameter == SweepParameter::kMassRatio || parameter == SweepParameter::kUMax;
}

SceneParams ground_counterpart(const SceneParams& params) {
  SceneParams ground;
  ground.gravity = params.gravity;
  ground.block = params.block;
  ground.has_friction = params.has_friction;
  ground.friction = params.friction;
  return ground;
}

std::string describe_value(const std::string& option, SweepParameter parameter, double value) {
  return option + " " + sweep_parameter_name(parameter) + " = " + format_value(value);
}

Scene sweep_scene(const SceneParams& base, SweepParameter parameter, double value,
                  const std::string& option) {
  SceneParams p = base;
  const std::string what = describe_value(option, parameter, value);
  if (!std::isfinite(value)) throw InputError(what + ": not a finite number");
  if (parameter_needs_base(parameter) && !p.has_base) {
    throw InputError(what + ": the scene has no [base] (a block on the ground)");
  }
  switch (parameter) {
    case SweepParameter::kMuS:
      p.has_friction = true;
      p.friction.static_coefficient = value;
      p.friction.kinetic_coefficient = 0.8 * value;
      break;
    case SweepParameter::kEpsilon:
      p.block.eccentricity = value * p.block.half_width;
      break;
    case SweepParameter::kLambda: {
      const double h = value * p.block.half_width;
      const double old_h = p.block.com_height;
      if (old_h > 0.0 && h > 0.0) {
        const double factor = h / old_h;
        p.block.mass *= factor;
        p.base.mass *= factor;  // keeps m_b / m
      }
      p.block.com_height = h;
      p.block.inertia = homogeneous_rectangle_inertia(p.block.mass, p.block.half_width, h);
      break;
    }
    case SweepParameter::kPeriod:
      p.base.period = value;
      break;
    case SweepParameter::kXi:
      p.base.damping_ratio = value;
      break;
    case SweepParameter::kUMax:
      if (!p.has_base_stops) throw InputError(what + ": the scene has no [base_stops]");
      p.base_stops.max_displacement = value;
      break;
    case SweepParameter::kMassRatio:
      p.base.mass = value * p.block.mass;
      break;
  }
  Scene scene;
  if (const Error e = make_scene(p, scene); !e.ok()) {
    throw InputError(what + ": " + e.field + ": " + e.reason);
  }
  return scene;
}

std::vector<Scene> sweep_scenes(const SceneParams& base, SweepParameter parameter,
                                const std::vector<double>& values) {
  std::vector<Scene> scenes;
  scenes.reserve(values.size());
  for (const double value : values) scenes.push_back(sweep_scene(base, parameter, value));
  return scenes;
}

void require_base_to_compare(const SceneParams& params) {
  if (!params.has_base) {
    throw InputError(
        "--compare-ground: the scene has no [base]: it is already the block on the ground "
        "(compare needs the isolated scene)");
  }
}

GroundScenes ground_scenes(const std::vector<Scene>& scenes) {
  GroundScenes ground;
  std::map<std::string, std::size_t> index;  // fingerprint -> index in ground.distinct
  for (const Scene& scene : scenes) {
    const SceneParams params = ground_counterpart(scene.params);
    const auto [it, added] = index.emplace(fingerprint(params), ground.distinct.size());
    if (added) {
      ground.distinct.emplace_back();
      if (const Error e = make_scene(params, ground.distinct.back()); !e.ok()) {
        throw InputError("--compare-ground: the block on the ground: " + std::string(e.field) +
                         ": " + e.reason);
      }
    }
    ground.of.push_back(it->second);
  }
  return ground;
}

}  // namespace plinth::host
