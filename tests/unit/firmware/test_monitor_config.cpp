// The box's configuration file (firmware/linux/monitor_config.h).
#include <gtest/gtest.h>

#include <fstream>
#include <cctype>
#include <set>
#include <string>
#include <string_view>

#include "box_file_error.h"
#include "monitor_config.h"
#include "plinth/host/input_error.h"
#include "test_paths.h"

namespace plinth::firmware {
namespace {

using ::plinth::testing::kSource;

using testing::box_file_error;

TEST(MonitorConfigFile, TheExampleSetsEveryField) {
  const MonitorFile f = load_monitor_file(kSource + "/firmware/monitor.example.toml", MonitorConfig{});
  EXPECT_EQ(f.config.ground_node, 1);
  EXPECT_EQ(f.config.estimator.sample_rate_hz, 200.0);
  EXPECT_EQ(f.config.estimator.solver.stepper, Stepper::kRk4Located);
  EXPECT_TRUE(f.config.estimator.solver.exact_full_contact);
  EXPECT_EQ(f.config.conditioning.sensor_to_statue(0, 1), -1.0);
  EXPECT_EQ(f.config.conditioning.sensor_to_statue(1, 0), 1.0);
  EXPECT_EQ(f.config.conditioning.startup_window_s, 10.0);
  EXPECT_EQ(f.config.alarm.warning.on, 0.5);
  EXPECT_EQ(f.config.alarm.alarm.off, 0.55);
  EXPECT_EQ(f.config.alarm.alarm_forecast.on, 0.375);
  EXPECT_EQ(f.config.forecast.continuation, Continuation::kRecentWindow);
  EXPECT_EQ(f.config.forecast.work_steps_per_s, 200000.0);
  EXPECT_EQ(f.config.sensor_health.max_valid_g, 8.192);
  EXPECT_EQ(f.config.status_interval_s, 0.1);
  EXPECT_EQ(f.config.axis_count, 1);
  EXPECT_TRUE(f.second_scene_path.empty());
}

TEST(MonitorConfigFile, TheForecastsKeys) {
  const MonitorFile f = load_monitor_text(
      "[forecast]\nenabled = false\ncontinuation = \"strongest_window\"\nhorizon_s = 3\n"
      "[alarm_policy]\nalarm_forecast = { on = 0.6, off = 0.5 }\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_FALSE(f.config.forecast.enabled);
  EXPECT_EQ(f.config.forecast.continuation, Continuation::kStrongestWindow);
  EXPECT_EQ(f.config.forecast.horizon_s, 3.0);
  EXPECT_EQ(f.config.alarm.alarm_forecast.on, 0.6);
  EXPECT_EQ(f.config.alarm.alarm_forecast.off, 0.5);
  EXPECT_NE(box_file_error("[forecast]\ncontinuation = \"crystal_ball\"\n")
                .find("box.toml:2: forecast.continuation: expected \"recent_window\" or "
                      "\"strongest_window\""),
            std::string::npos);
}

// [pwave] (docs/monitor.md): absent, the stage is off; present, on with its keys, the channel's
// fitted table unless it gives one; every bad value named with its key, line and limit.
TEST(MonitorConfigFile, ThePWaveTable) {
  if (!monitor::kPWaveStageBuiltIn) {
    EXPECT_NE(box_file_error("[pwave]\n").find("PLINTH_PWAVE_STAGE=OFF"), std::string::npos);
    return;
  }
  const auto pwave = [](const MonitorFile& f) {
    return *monitor::built_part<monitor::PWaveSettings>(f.config.pwave);
  };
  EXPECT_FALSE(load_monitor_text("", "/etc/plinth/box.toml", MonitorConfig{}).config.pwave.enabled);
  const MonitorFile empty = load_monitor_text("[pwave]\n", "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_TRUE(pwave(empty).enabled);
  EXPECT_EQ(pwave(empty).channel, monitor::PWaveChannel::kVertical);
  EXPECT_EQ(pwave(empty).predictor[0].ln_pga_over_pa, monitor::kDefaultVerticalPredictor[0].ln_pga_over_pa);
  // A horizontal box takes the horizontal table.
  const MonitorFile h = load_monitor_text("[pwave]\nchannel = \"horizontal\"\nhold_s = 20\n"
                                          "max_retry_s = 1.5\ndetrigger_ratio = 3\n"
                                          "[alarm_policy]\nwarning_pwave = { on = 0.7, off = 0.5 }\n",
                                          "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_EQ(pwave(h).channel, monitor::PWaveChannel::kHorizontal);
  EXPECT_EQ(pwave(h).predictor[3].sigma_ln, monitor::kDefaultHorizontalPredictor[3].sigma_ln);
  EXPECT_EQ(pwave(h).hold_s, 20.0);
  EXPECT_EQ(pwave(h).max_retry_s, 1.5);
  EXPECT_EQ(pwave(h).detrigger_ratio, 3.0);
  EXPECT_EQ(h.config.alarm.warning_pwave.on, 0.7);
  // The table plinth-eval pwave-fit prints.
  const MonitorFile fitted = load_monitor_text(
      "[pwave]\nchannel = \"vertical\"\npredictor = [\n"
      "  { window_s = 0.5, ln_pga_over_pa = 3.1, tau_c_exponent = 0.0, sigma_ln = 0.65 },\n"
      "  { window_s = 1.0, ln_pga_over_pa = 2.7, tau_c_exponent = 0.1, sigma_ln = 0.8 },\n]\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_EQ(pwave(fitted).predictor_points, 2U);
  EXPECT_EQ(pwave(fitted).predictor[1].tau_c_exponent, 0.1);
  EXPECT_EQ(pwave(fitted).predictor[1].sigma_ln, 0.8);

  const auto refused = [](const std::string& text, const std::string& message) {
    const std::string error = box_file_error(text);
    EXPECT_NE(error.find(message), std::string::npos) << text << " gave: " << error;
  };
  refused("[pwave]\nsta_s = 12\n", "box.toml:2: pwave.sta_s: must be shorter than pwave.lta_s (limit 10)");
  refused("[pwave]\n\nlowpass_hz = 150\n", "box.toml:3: pwave.lowpass_hz: must be below half the sample rate (limit 100)");
  refused("[pwave]\ntrigger_ratio = -1\n", "box.toml:2: pwave.trigger_ratio: must be greater than zero");
  refused("[pwave]\ntrigger_ratio = 1\n", "pwave.trigger_ratio: must exceed 1 (limit 1)");
  refused("[pwave]\nchannel = \"diagonal\"\n",
          "box.toml:2: pwave.channel: expected \"vertical\" or \"horizontal\", got \"diagonal\"");
  refused("[pwave]\nhold_s = \"long\"\n", "box.toml:2: pwave.hold_s: expected a number");
  refused("[pwave]\nmax_retry_s = 0\n", "box.toml:2: pwave.max_retry_s: must be greater than zero");
  refused("[pwave]\ndetrigger_ratio = 8\n",
          "box.toml:2: pwave.detrigger_ratio: must be below pwave.trigger_ratio (limit 8)");
  refused("[pwave]\nenabled = true\n", "box.toml:2: pwave.enabled: unknown key");
  refused("[pwave]\npredictor = 3\n", "pwave.predictor: expected an array of tables");
  refused("[pwave]\npredictor = []\n", "pwave.predictor: must have 1 to 8 points, has 0");
  refused("[pwave]\npredictor = [\n { window_s = 0.5, ln_pga_over_pa = 3, sigma_ln = 0.6 },\n"
          " { window_s = 1.0, ln_pga_over_pa = 2, sigma_ln = -1 },\n]\n",
          "pwave.predictor[1].sigma_ln: must be greater than zero");
  refused("[pwave]\npredictor = [\n { window_s = 1.0, ln_pga_over_pa = 3, sigma_ln = 0.6 },\n"
          " { window_s = 0.5, ln_pga_over_pa = 2, sigma_ln = 0.6 },\n]\n",
          "pwave.predictor[1].window_s: must increase from point to point (limit 1)");
  refused("[pwave]\npredictor = [ { window_s = 0.5, sigma_ln = 0.6 } ]\n",
          "pwave.predictor[0]: no ln_pga_over_pa");
  refused("[pwave]\npredictor = [ { window_s = 0.5, ln_pga_over_pa = 3, sigma_ln = 0.6, c2 = 1 } ]\n",
          "pwave.predictor[0].c2: unknown key");
  refused("[alarm_policy]\nwarning_pwave.on = 1.5\n", "alarm_policy.warning_pwave.on");
}

TEST(MonitorConfigFile, ValuesOverTheDefaults) {
  const MonitorFile f = load_monitor_text(
      "[estimator]\nsample_rate_hz = 1000\nsteps_per_sample = 2\nstepper = \"heun_located\"\n"
      "exact_full_contact = false\n"
      "[conditioning]\nunit = \"m/s2\"\n"
      "[alarm_policy]\nwarning.on = 0.6\nlatch_warning = false\n"
      "[monitor]\nground_node = 7\nsecond_scene = \"y.toml\"\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_EQ(f.config.estimator.sample_rate_hz, 1000.0);
  EXPECT_EQ(f.config.estimator.steps_per_sample, 2);
  EXPECT_EQ(f.config.estimator.solver.stepper, Stepper::kHeunLocated);
  EXPECT_FALSE(f.config.estimator.solver.exact_full_contact);
  EXPECT_EQ(f.config.conditioning.unit, monitor::AccelerationUnit::kMetresPerSecondSquared);
  EXPECT_EQ(f.config.alarm.warning.on, 0.6);
  EXPECT_EQ(f.config.alarm.warning.off, 0.4);  // the default kept
  EXPECT_FALSE(f.config.alarm.latch_warning);
  EXPECT_EQ(f.config.ground_node, 7);
  EXPECT_EQ(f.second_scene_path, "/etc/plinth/y.toml");
  EXPECT_EQ(f.config.axis_count, 2);
}

TEST(MonitorConfigFile, BadInputNamesFileLineAndKey) {
  EXPECT_EQ(box_file_error("[estimator]\nsteps = 4\n"),
            "/etc/plinth/box.toml:2: estimator.steps: unknown key (docs/monitor.md lists them)");
  EXPECT_EQ(box_file_error("[estimator]\nsample_rate_hz = \"fast\"\n"),
            "/etc/plinth/box.toml:2: estimator.sample_rate_hz: expected a number");
  EXPECT_EQ(box_file_error("[estimator]\nstepper = \"rk45\"\n"),
            "/etc/plinth/box.toml:2: estimator.stepper: expected \"rk4_located\", "
            "\"rk4_step_end\", \"heun_located\" or \"semi_implicit_euler\"");
  EXPECT_EQ(box_file_error("[sensor_health]\n\ntimeout_s = 0.001\n")
                .rfind("/etc/plinth/box.toml:3: sensor_health.timeout_s: ", 0),
            0U);
  EXPECT_EQ(box_file_error("[alarm_policy]\nwarning = { on = 0.5, off = 0.6 }\n")
                .rfind("/etc/plinth/box.toml:2: alarm_policy.warning.off: ", 0),
            0U);
  EXPECT_EQ(
      box_file_error("[conditioning]\nsensor_to_statue = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]\n")
          .rfind("/etc/plinth/box.toml:2: conditioning.sensor_to_statue: ", 0),
      0U);
  EXPECT_EQ(box_file_error("[conditioning]\nsensor_to_statue = [[1, 0], [0, 1]]\n"),
            "/etc/plinth/box.toml:2: conditioning.sensor_to_statue: expected three rows of three "
            "numbers (statue = R sensor)");
  EXPECT_EQ(box_file_error("[conditioning]\nunit = \"gal\"\n"),
            "/etc/plinth/box.toml:2: conditioning.unit: expected \"g\" or \"m/s2\", got \"gal\"");
  EXPECT_EQ(box_file_error("[monitor]\nground_node = 16\n"),
            "/etc/plinth/box.toml:2: monitor.ground_node: must lie in [1, 15]");
  EXPECT_EQ(box_file_error("[estimator]\nsample_rate_hz = nan\n")
                .rfind("/etc/plinth/box.toml:2: estimator.sample_rate_hz: ", 0),
            0U);
  EXPECT_NE(box_file_error("[estimator\n").find("TOML syntax error"), std::string::npos);
  EXPECT_EQ(box_file_error("[alarm_policy]\nlatch_alarm = 1\n"),
            "/etc/plinth/box.toml:2: alarm_policy.latch_alarm: expected true or false");
  try {
    (void)load_monitor_file("/nowhere/box.toml", MonitorConfig{});
    ADD_FAILURE();
  } catch (const host::InputError& e) {
    EXPECT_STREQ(e.what(), "/nowhere/box.toml: cannot open configuration file (no such file)");
  }
}

// [statue_sensor]: its presence configures the IMU; its mounting, health and the filter's keys.
TEST(MonitorConfigFile, TheStatueSensorsTables) {
  const MonitorFile f = load_monitor_text(
      "[statue_sensor]\nnode = 5\nheight_m = 1.2\noffset_x_m = -0.05\n"
      "sensor_to_statue = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]\n"
      "health = { timeout_s = 0.04, stuck_samples = 0, rate_full_scale_rad_s = 8.0, "
      "rate_max_valid_rad_s = 8.5, acceleration_max_valid_g = 8.1 }\n"
      "[statue_filter]\nrate_noise_rad_s = 0.004\nmemory_s = 5\n"
      "acceleration_noise_m_s2 = 0.05\nacceleration_bias_m_s2 = 0.2\nslide_tolerance = 0.1\n"
      "slide_filter_s = 0.04\nslide_onset_s = 0.06\nslide_end_s = 0.2\n"
      "slide_on_isolated_base = true\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  const StatueSensorSettings& s = f.config.statue_sensor;
  EXPECT_TRUE(s.present);
  EXPECT_EQ(s.node, 5);
  EXPECT_EQ(s.height_m, 1.2);
  EXPECT_EQ(s.offset_x_m, -0.05);
  EXPECT_EQ(s.sensor_to_statue(0, 1), -1.0);
  EXPECT_EQ(s.health.timeout_s, 0.04);
  EXPECT_EQ(s.health.stuck_samples, 0);
  EXPECT_EQ(s.health.rate_full_scale_rad_s, 8.0);
  EXPECT_EQ(s.health.rate_max_valid_rad_s, 8.5);
  EXPECT_EQ(s.health.acceleration_max_valid_g, 8.1);
  EXPECT_EQ(s.filter.rate_noise_rad_s, 0.004);
  EXPECT_EQ(s.filter.memory_s, 5.0);
  EXPECT_EQ(s.filter.acceleration_noise_m_s2, 0.05);
  EXPECT_EQ(s.filter.acceleration_bias_m_s2, 0.2);
  EXPECT_EQ(s.filter.slide_tolerance, 0.1);
  EXPECT_EQ(s.filter.slide_filter_s, 0.04);
  EXPECT_EQ(s.filter.slide_onset_s, 0.06);
  EXPECT_EQ(s.filter.slide_end_s, 0.2);
  EXPECT_TRUE(s.filter.slide_on_isolated_base);
  EXPECT_FALSE(load_monitor_text("[monitor]\nground_node = 2\n", "/etc/plinth/box.toml",
                                 MonitorConfig{})
                   .config.statue_sensor.present);

  // Errors name the file, the line and the key.
  EXPECT_EQ(box_file_error("[statue_sensor]\nheight_m = 1\n"),
            "/etc/plinth/box.toml:1: statue_sensor: no node (statue_sensor.node gives the IMU's "
            "CAN node)");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 0\n"),
            "/etc/plinth/box.toml:2: statue_sensor.node: must lie in [1, 15]");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 1\n"),
            "/etc/plinth/box.toml:2: statue_sensor.node: is an accelerometer's node; each "
            "sensor has its own");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\nnoise = 3\n"),
            "/etc/plinth/box.toml:3: statue_sensor.noise: unknown key (docs/monitor.md lists "
            "them)");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\nheight_m = \"tall\"\n"),
            "/etc/plinth/box.toml:3: statue_sensor.height_m: expected a number");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\nheight_m = -1\n"),
            "/etc/plinth/box.toml:3: statue_sensor.height_m: must be finite and >= 0");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\n"
                           "sensor_to_statue = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]\n")
                .rfind("/etc/plinth/box.toml:3: statue_sensor.sensor_to_statue: ", 0),
            0U);
  // A key the file leaves at its default: the file named without a line.
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\n[statue_sensor.health]\n"
                           "rate_full_scale_rad_s = 20\n"),
            "/etc/plinth/box.toml: statue_sensor.health.rate_max_valid_rad_s: must not be below "
            "rate_full_scale_rad_s");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\nhealth.max_bridge_samples = 1.5\n"),
            "/etc/plinth/box.toml:3: statue_sensor.health.max_bridge_samples: expected an "
            "integer");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\n[statue_filter]\nmemory_s = 0\n")
                .rfind("/etc/plinth/box.toml:4: statue_filter.memory_s: must lie in [1, 600] s",
                       0),
            0U);
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\n[statue_filter]\nslide_tolerance = 1\n"),
            "/etc/plinth/box.toml:4: statue_filter.slide_tolerance: must lie in [0, 0.5]");
  // The keys that decide how far the sensor may lower the risk: bounded, the key named
  // (docs/statue-filter.md, "Bounds").
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\n[statue_filter]\n"
                           "unexplained_score = 1e300\n"),
            "/etc/plinth/box.toml:4: statue_filter.unexplained_score: must lie in [2, 50]");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\n[statue_filter]\nrest_rate_rad_s = 100\n"),
            "/etc/plinth/box.toml:4: statue_filter.rest_rate_rad_s: must lie in (0, 0.05] rad/s");
  EXPECT_EQ(box_file_error("[statue_sensor]\nnode = 2\n[statue_filter]\n"
                           "slide_on_isolated_base = 1\n"),
            "/etc/plinth/box.toml:4: statue_filter.slide_on_isolated_base: expected true or false");
  EXPECT_EQ(box_file_error("[statue_filter]\nmemory_s = 3\n"),
            "/etc/plinth/box.toml:1: statue_filter: no [statue_sensor] table (the filter weighs "
            "its measurements)");
}

// Issue 25: a value of the wrong type is reported as one, never as an unknown key. The walk
// covers every key the example file shows (commented ones too): each table given a number,
// each key given a table (or, where a table belongs, a boolean).
TEST(MonitorConfigFile, EveryKeyOfTheWrongTypeIsSaidToBeOne) {
  std::ifstream example(kSource + "/firmware/monitor.example.toml");
  ASSERT_TRUE(example);
  // By hand, not std::regex (GCC 12 warns falsely inside it under the sanitize preset).
  // A name: lower case and '_'; a table's may be dotted ("[statue_sensor.health]").
  const auto word_at = [](const std::string& text, std::size_t at, bool dotted = false) {
    std::size_t end = at;
    while (end < text.size() && (std::islower(static_cast<unsigned char>(text[end])) != 0 ||
                                 text[end] == '_' || (dotted && text[end] == '.'))) {
      ++end;
    }
    return text.substr(at, end - at);
  };
  std::string line;
  std::string table;
  bool array_of_tables = false;
  std::set<std::string> tables;
  int keys = 0;
  while (std::getline(example, line)) {
    // An optional "#" and spaces, then "[name]", "[[name]]" or "key = value".
    std::size_t at = line.rfind('#', 0) == 0 ? 1 : 0;
    while (at < line.size() && line[at] == ' ') ++at;
    if (at < line.size() && line[at] == '[') {
      array_of_tables = line.compare(at, 2, "[[") == 0;
      const std::size_t name_at = at + (array_of_tables ? 2 : 1);
      const std::string name = word_at(line, name_at, true);
      const std::string close = array_of_tables ? "]]" : "]";
      const std::size_t after = line.find_first_not_of(' ', name_at + name.size() + close.size());
      if (name.empty() || line.compare(name_at + name.size(), close.size(), close) != 0 ||
          (after != std::string::npos && line[after] != '#')) {
        continue;  // prose in a comment ("[uncertainty] table.")
      }
      table = name;
      if (!array_of_tables) tables.insert(table);
      continue;
    }
    const std::string key = word_at(line, at);
    const std::size_t equals = line.find_first_not_of(' ', at + key.size());
    if (table.empty() || key.empty() || equals == std::string::npos || line[equals] != '=') {
      continue;
    }
    const std::size_t value_at = line.find_first_not_of(' ', equals + 1);
    if (value_at == std::string::npos) continue;
    const char first = line[value_at];
    const bool value_like = std::string_view("-+.0123456789\"[{").find(first) !=
                                std::string_view::npos ||
                            line.compare(value_at, 4, "true") == 0 ||
                            line.compare(value_at, 5, "false") == 0;
    if (!value_like) continue;  // prose in a comment ("statue = R sensor")
    const std::string head = array_of_tables ? "[[" + table + "]]\nnode = 1\n" : "[" + table + "]\n";
    const std::string name = table + (array_of_tables ? "[0]." : ".") + key;
    const bool holds_a_table = first == '{';
    const std::string text = head + key + (holds_a_table ? " = true\n" : " = { x = 1 }\n");
    const std::string message = box_file_error(text);
    SCOPED_TRACE(text);
    EXPECT_EQ(message.find("unknown key"), std::string::npos) << message;
    if (key == "node" && array_of_tables) continue;  // given twice: the repeat is named
    EXPECT_NE(message.find(name + ": expected "), std::string::npos) << message;
    if (!holds_a_table) {
      EXPECT_NE(message.find("got a table"), std::string::npos) << message;
    }
    ++keys;
  }
  EXPECT_GT(keys, 60);
  for (const std::string& t : tables) {
    const std::string message = box_file_error(t + " = 3\n");
    EXPECT_NE(message.find(t + ": expected a table"), std::string::npos) << message;
  }
  EXPECT_GT(tables.size(), 12U);
}

// Issue 33: the recorder's buffers hold every configured sensor's frames (the statue sensor's
// two a sample beside the ground sensor's) and recorder.bus_frames_hz of other traffic.
TEST(MonitorConfigFile, TheRecordersFrameRateCountsEverySensor) {
  MonitorFile file = load_monitor_text("[estimator]\nsample_rate_hz = 200.0\n", "box.toml",
                                       MonitorConfig{});
  EXPECT_DOUBLE_EQ(recorder_frame_rate_hz(file), 1.25 * 200 + 1 + 2000);
  file = load_monitor_text(
      "[estimator]\nsample_rate_hz = 200.0\n[statue_sensor]\nnode = 2\n[recorder]\n"
      "bus_frames_hz = 0\n",
      "box.toml", MonitorConfig{});
  EXPECT_DOUBLE_EQ(recorder_frame_rate_hz(file), 1.25 * 3 * 200 + 2) << "three frames a sample";
  file = load_monitor_text(
      "[estimator]\nsample_rate_hz = 1000.0\n[[sensor]]\nnode = 1\n[[sensor]]\nnode = 3\n"
      "role = \"plate\"\n[recorder]\nbus_frames_hz = 500\n",
      "box.toml", MonitorConfig{});
  EXPECT_DOUBLE_EQ(recorder_frame_rate_hz(file), 1.25 * 2 * 1000 + 2 + 500);
  EXPECT_EQ(box_file_error("[recorder]\nbus_frames_hz = -1\n"),
            "/etc/plinth/box.toml:2: recorder.bus_frames_hz: must be a number of frames/s in [0, "
            "25000] (a CAN bus at 1 Mbit/s carries at most about 21,000 frames/s)");
}

// Issue 33: the keys read apart, arrays of tables, given a value or a table: their type is
// named, never "unknown key" (sensor = 3 was one).
TEST(MonitorConfigFile, AnArrayOfTablesOfTheWrongTypeIsSaidToBeOne) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"sensor = 3\n",
       "box.toml:1: sensor: expected [[sensor]] tables (an array of tables), got an integer"},
      {"sensor = \"a\"\n", "sensor: expected [[sensor]] tables (an array of tables), got a string"},
      {"sensor = []\n", "sensor: expected [[sensor]] tables (an array of tables), got an empty"},
      {"sensor = [1, 2]\n", "sensor: expected [[sensor]] tables (an array of tables), got an array"},
      {"[sensor]\nnode = 1\n",
       "sensor: expected [[sensor]] tables (an array of tables), got a table"},
      {"[pwave]\npredictor = 3\n", "pwave.predictor: expected an array of tables { window_s"},
      {"[pwave.predictor]\nwindow_s = 1.0\n",
       "pwave.predictor: expected an array of tables { window_s, ln_pga_over_pa, tau_c_exponent, "
       "sigma_ln } (plinth-eval pwave-fit prints one), got a table"},
  };
  for (const auto& c : cases) {
    const std::string message = box_file_error(c.text);
    SCOPED_TRACE(c.text);
    EXPECT_EQ(message.find("unknown key"), std::string::npos) << message;
    EXPECT_NE(message.find(c.message), std::string::npos) << message;
  }
}

// A directory was read as an empty file (the defaults, silently); /dev/zero grew memory.
TEST(MonitorConfigFile, DirectoriesAndDevicesAreRefusedUnread) {
  const std::string message_for_dir = [] {
    try {
      (void)load_monitor_file(kSource + "/firmware", MonitorConfig{});
    } catch (const host::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_EQ(message_for_dir,
            kSource + "/firmware: cannot open configuration file (it is a directory)");
  try {
    (void)load_monitor_file("/dev/zero", MonitorConfig{});
    ADD_FAILURE();
  } catch (const host::InputError& e) {
    EXPECT_STREQ(e.what(),
                 "/dev/zero: cannot open configuration file (not a regular file: a FIFO, socket or "
                 "device)");
  }
}

TEST(MonitorConfigFile, StatusInterval) {
  const MonitorFile f = load_monitor_text("[monitor]\nstatus_interval_s = 0.5\n",
                                          "/etc/plinth/box.toml", MonitorConfig{});
  EXPECT_EQ(f.config.status_interval_s, 0.5);
  EXPECT_EQ(MonitorConfig{}.status_interval_s, 0.1);
  EXPECT_EQ(box_file_error("[monitor]\nstatus_interval_s = 0\n"),
            "/etc/plinth/box.toml:2: monitor.status_interval_s: must lie in [1e-9, 1e6] s");
}

// plinth-monitor's command line over the file, over the defaults.
TEST(MonitorOverrides, TheCommandLineOverTheFile) {
  MonitorFile f = load_monitor_text(
      "[estimator]\nsteps_per_sample = 2\nsample_rate_hz = 500\n"
      "[monitor]\nstatus_interval_s = 0.5\nsecond_scene = \"y.toml\"\n"
      "[sensor_health]\nstuck_samples = 20\n"
      "[[sensor]]\nnode = 1\n[[sensor]]\nnode = 2\nsensor_health.stuck_samples = 30\n",
      "/etc/plinth/box.toml", MonitorConfig{});
  MonitorOverrides o;
  o.steps = 8;
  o.startup_window_s = 3.0;
  o.stuck_samples = 0;
  o.scene_y_path = "other.toml";
  apply_overrides(f, o);
  EXPECT_EQ(f.config.estimator.steps_per_sample, 8);
  EXPECT_EQ(f.config.estimator.sample_rate_hz, 500.0);  // not given: the file's
  EXPECT_EQ(f.config.status_interval_s, 0.5);
  EXPECT_EQ(f.second_scene_path, "other.toml");
  EXPECT_EQ(f.config.sensor_health.stuck_samples, 0);
  for (int i = 0; i < 2; ++i) {  // every sensor's
    EXPECT_EQ(f.config.sensors[static_cast<std::size_t>(i)].conditioning.startup_window_s, 3.0);
    EXPECT_EQ(f.config.sensors[static_cast<std::size_t>(i)].sensor_health.stuck_samples, 0);
  }
  o = MonitorOverrides{};
  o.config_path = "/etc/plinth/box.toml";
  o.node = 3;
  try {
    apply_overrides(f, o);
    ADD_FAILURE() << "--node with [[sensor]] tables accepted";
  } catch (const host::InputError& e) {
    EXPECT_STREQ(e.what(),
                 "--node names the single ground sensor; /etc/plinth/box.toml lists [[sensor]] "
                 "tables (give the nodes there)");
  }
}

TEST(MonitorOverrides, WithoutAFileTheCommandLinesDefaults) {
  MonitorOverrides o;
  o.rate_hz = 1000.0;
  o.status_interval_s = 0.02;
  o.node = 5;
  const MonitorFile f = configure_monitor(o);
  EXPECT_EQ(f.config.conditioning.startup_window_s, kBoxStartupWindowS);
  EXPECT_EQ(f.config.estimator.sample_rate_hz, 1000.0);
  EXPECT_EQ(f.config.status_interval_s, 0.02);
  EXPECT_EQ(f.config.ground_node, 5);
  EXPECT_EQ(f.config.sensor_count, 0);
  o.config_path = "/nowhere/box.toml";
  EXPECT_THROW((void)configure_monitor(o), host::InputError);
}

}  // namespace
}  // namespace plinth::firmware
