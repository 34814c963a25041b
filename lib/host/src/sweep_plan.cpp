#include "plinth/host/sweep_plan.h"

#include <memory>
#include <optional>
#include <utility>

#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"

namespace plinth::host {
namespace {

// The settings line of a PGA sweep: the scene, the record and the search.
SettingsLine pga_settings(const std::string& mode, const std::vector<GridAxis>& grid,
                          const SceneParams& base, const Record& record, const SweepSettings& s) {
  SettingsLine line(mode, grid);
  line.add("scene", fingerprint(base))
      .add("record", fingerprint(record))
      .add("pga_max_g", s.pga_max_g)
      .add("tol_g", s.tolerance_g)
      .add("scan_points", std::to_string(s.scan_points))
      .add("dt", s.dt);
  return line;
}

// ",<name><suffix>" for each event of `events`, in SweepEvent order.
std::string event_columns(const EventSet& events, const char* suffix) {
  std::string columns;
  for (const auto& [event, name] : kSweepEventNames) {
    if (!events[static_cast<std::size_t>(event)]) continue;
    columns += ',';
    columns += name;
    columns += suffix;
  }
  return columns;
}

// ",<threshold in g>" for each event of `events` (empty where there is none).
std::string threshold_fields(const EventSet& events, const Thresholds& thresholds) {
  std::string fields;
  for (std::size_t e = 0; e < kSweepEventCount; ++e) {
    if (!events[e]) continue;
    fields += ',';
    fields += format_result(thresholds[e]);
  }
  return fields;
}

// The counterparts on the ground of the scenes of a plan, the events they can have, and the
// thresholds of each distinct one, searched once.
struct GroundPlan {
  explicit GroundPlan(GroundScenes scenes)
      : ground(std::move(scenes)), thresholds(ground.distinct.size()) {}

  GroundScenes ground;
  EventSet events;  // the events they can have, of those searched
  OnceCache<Thresholds> thresholds;
};

std::shared_ptr<GroundPlan> ground_plan(const std::vector<Scene>& scenes,
                                        const EventSet& searched) {
  auto plan = std::make_shared<GroundPlan>(ground_scenes(scenes));
  // Friction, the only feature of the ground's that may differ, is the same for every value.
  plan->events = possible_events(plan->ground.distinct.front()) & searched;
  return plan;
}

// The thresholds of the ground counterpart of scene i, computed once per distinct one.
Thresholds ground_thresholds(GroundPlan& plan, std::size_t i, const Record& record,
                             const SweepSettings& settings, const std::atomic<bool>* stop,
                             std::size_t* simulations) {
  const std::size_t k = plan.ground.of[i];
  return plan.thresholds.get(k, [&] {
    try {
      return first_occurrence_thresholds(plan.ground.distinct[k], record, settings, simulations,
                                         stop);
    } catch (const InputError& e) {
      throw InputError(std::string("the block on the ground: ") + e.what());
    }
  });
}

// Why the block on the ground cannot have `event`.
std::string why_ground_lacks(SweepEvent event) {
  switch (event) {
    case SweepEvent::kSliding:
    case SweepEvent::kSlideRocking:
      return "the scene has no [friction]";
    case SweepEvent::kOutOfBase:
    case SweepEvent::kFell:
      return "it has no support's edge to leave";
    case SweepEvent::kBaseStopHit:
      return "it has no base stops";
    case SweepEvent::kSlideStopHit:
      return "it has no sliding stops";
    default:
      return "it cannot";
  }
}

}  // namespace

bool run_plan(const SweepPlan& plan, const std::vector<std::size_t>& indices, const JobRun& run,
              std::vector<std::string>& rows, std::size_t* simulations) {
  rows.resize(plan.keys.size());
  std::atomic<std::size_t> total{0};
  const bool finished = run_jobs(
      indices, run,
      [&](std::size_t i) {
        std::size_t runs = 0;
        std::string row = plan.row(i, run.stop, &runs);
        total += runs;
        rows[i] = std::move(row);
      },
      plan.describe);
  if (simulations != nullptr) *simulations += total.load();
  return finished;
}

SweepPlan plan_thresholds(const SceneParams& base, const Record& record, SweepParameter parameter,
                          const GridAxis& axis, const SweepSettings& settings,
                          bool compare_ground) {
  validate(settings);
  require_scalable(record);
  if (compare_ground) require_base_to_compare(base);
  const std::vector<double> values = sweep_values(axis.from, axis.to, axis.steps);
  auto scenes = std::make_shared<const std::vector<Scene>>(sweep_scenes(base, parameter, values));
  const std::shared_ptr<GroundPlan> ground =
      compare_ground ? ground_plan(*scenes, settings.events) : nullptr;
  auto shared_record = std::make_shared<const Record>(record);
  SweepPlan plan;
  SettingsLine line = pga_settings("thresholds", {axis}, base, record, settings);
  plan.header = sweep_parameter_name(parameter) + event_columns(kAllEvents, "");
  if (ground) {
    line.add("compare", "ground");
    plan.header += event_columns(ground->events, kGroundSuffix);
  }
  plan.settings = line.text();
  plan.keys = grid_keys({axis});
  const std::vector<std::string> keys = plan.keys;
  plan.row = [scenes, ground, shared_record, settings, keys](
                 std::size_t i, const std::atomic<bool>* stop, std::size_t* simulations) {
    std::string text = keys[i] + threshold_fields(kAllEvents, first_occurrence_thresholds(
                                                                  (*scenes)[i], *shared_record,
                                                                  settings, simulations, stop));
    if (ground) {
      text += threshold_fields(ground->events, ground_thresholds(*ground, i, *shared_record,
                                                                 settings, stop, simulations));
    }
    return text;
  };
  plan.describe = [parameter, values](std::size_t i) {
    return describe_value("--param", parameter, values[i]);
  };
  return plan;
}

SweepPlan plan_threshold_map(const SceneParams& base, const Record& record,
                             SweepParameter parameter1, const GridAxis& axis1,
                             SweepParameter parameter2, const GridAxis& axis2, SweepEvent event,
                             SweepSettings settings, bool compare_ground) {
  validate(settings);
  require_scalable(record);
  if (compare_ground) require_base_to_compare(base);
  if (parameter1 == parameter2) {
    throw InputError(std::string("--param2: must differ from --param (both ") +
                     sweep_parameter_name(parameter1) + ")");
  }
  const std::vector<double> values1 = sweep_values(axis1.from, axis1.to, axis1.steps);
  const std::vector<double> values2 = sweep_values(axis2.from, axis2.to, axis2.steps, "--", "2");
  (void)bounded_count(static_cast<double>(values1.size()) * static_cast<double>(values2.size()),
                      kMaxSweepRows,
                      "--steps " + std::to_string(values1.size()) + " and --steps2 " +
                          std::to_string(values2.size()),
                      "the map would have", "rows");
  auto scenes = std::make_shared<std::vector<Scene>>();
  scenes->reserve(values1.size() * values2.size());
  for (const double v1 : values1) {
    const Scene row = sweep_scene(base, parameter1, v1);
    for (const double v2 : values2) {
      scenes->push_back(sweep_scene(row.params, parameter2, v2, "--param2"));
    }
  }
  settings.events.reset();
  settings.events.set(static_cast<std::size_t>(event));
  const std::shared_ptr<GroundPlan> ground =
      compare_ground ? ground_plan(*scenes, settings.events) : nullptr;
  if (ground && ground->events.none()) {
    throw InputError(std::string("--compare-ground: the block on the ground cannot have ") +
                     sweep_event_name(event) + " (" + why_ground_lacks(event) +
                     "); it can have rocking, overturned, and with friction sliding and "
                     "slide_rocking");
  }
  auto shared_record = std::make_shared<const Record>(record);
  SweepPlan plan;
  SettingsLine line = pga_settings("threshold_map", {axis1, axis2}, base, record, settings);
  line.add("event", sweep_event_name(event));
  plan.header = std::string(sweep_parameter_name(parameter1)) + "," +
                sweep_parameter_name(parameter2) + "," + sweep_event_name(event);
  if (ground) {
    line.add("compare", "ground");
    plan.header += event_columns(ground->events, kGroundSuffix);
  }
  plan.settings = line.text();
  plan.key_columns = 2;
  plan.keys = grid_keys({axis1, axis2});
  const std::vector<std::string> keys = plan.keys;
  plan.row = [scenes, ground, shared_record, settings, keys](
                 std::size_t i, const std::atomic<bool>* stop, std::size_t* simulations) {
    std::string text =
        keys[i] + threshold_fields(settings.events,  // `event` alone
                                   first_occurrence_thresholds((*scenes)[i], *shared_record,
                                                               settings, simulations, stop));
    if (ground) {
      text += threshold_fields(ground->events, ground_thresholds(*ground, i, *shared_record,
                                                                 settings, stop, simulations));
    }
    return text;
  };
  const std::size_t columns = values2.size();
  plan.describe = [=](std::size_t i) {
    return describe_value("--param", parameter1, values1[i / columns]) + ", " +
           describe_value("--param2", parameter2, values2[i % columns]);
  };
  return plan;
}

}  // namespace plinth::host
