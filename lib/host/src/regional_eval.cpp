#include "plinth/host/regional_eval.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string_view>
#include <vector>

#include "plinth/host/csv_line.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/monitor/regional_alert.h"

namespace plinth::host {
namespace {

constexpr std::array<std::string_view, 8> kInfoColumns{
    "rsn", "earthquake", "station", "magnitude", "rrup_km", "rjb_km", "rhyp_km", "vs30_m_s"};
// The flatfile's distances come rounded to 0.01 km: their order is checked within it.
constexpr double kDistanceRoundingKm = 0.01;

double number(const std::string& text, const std::string& where, std::string_view field) {
  const std::string at = where + ": " + std::string(field) + ": ";
  if (text.empty()) throw InputError(at + "empty");
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE) {
    throw InputError(at + "not a number: \"" + text + "\"");
  }
  if (!std::isfinite(v)) throw InputError(at + "not finite: " + text);
  return v;
}

double in_range(const std::string& text, const std::string& where, std::string_view field,
                double low, double high, bool low_open) {
  const double v = number(text, where, field);
  if ((low_open ? !(v > low) : !(v >= low)) || !(v <= high)) {
    throw InputError(where + ": " + std::string(field) + ": expected " +
                     std::string(low_open ? "> " : ">= ") + number_text(low) + " and <= " +
                     number_text(high) + ", got " + text);
  }
  return v;
}

}  // namespace

std::map<int, RecordSource> read_record_info(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open (--record-info)");
  std::string line;
  std::vector<std::string> f;
  if (!std::getline(in, line) || !split_csv(line, f) || f.size() != kInfoColumns.size() ||
      !std::equal(f.begin(), f.end(), kInfoColumns.begin())) {
    std::string expected;
    for (std::string_view c : kInfoColumns) {
      if (!expected.empty()) expected += ',';
      expected.append(c);
    }
    throw InputError(path + ":1: expected the header \"" + expected + "\"");
  }
  std::map<int, RecordSource> out;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::string where = path + ":" + std::to_string(n);
    if (!split_csv(line, f)) throw InputError(where + ": unterminated quoted field");
    if (f.size() != kInfoColumns.size()) {
      throw InputError(where + ": expected " + std::to_string(kInfoColumns.size()) +
                       " fields, got " + std::to_string(f.size()));
    }
    RecordSource s;
    const double rsn = in_range(f[0], where, "rsn", 1.0, 1e9, false);
    if (rsn != std::floor(rsn)) throw InputError(where + ": rsn: expected a whole number, got " + f[0]);
    s.rsn = static_cast<int>(rsn);
    s.earthquake = f[1];
    s.station = f[2];
    s.magnitude = in_range(f[3], where, "magnitude", 0.0, kMaxRecordMagnitude, true);
    s.rrup_km = in_range(f[4], where, "rrup_km", 0.0, kMaxRecordDistanceKm, false);
    s.rjb_km = in_range(f[5], where, "rjb_km", 0.0, kMaxRecordDistanceKm, false);
    s.rhyp_km = in_range(f[6], where, "rhyp_km", 0.0, kMaxRecordDistanceKm, true);
    s.vs30_m_s = in_range(f[7], where, "vs30_m_s", 0.0, kMaxRecordVs30M_s, true);
    if (s.rjb_km > s.rrup_km + kDistanceRoundingKm) {
      throw InputError(where + ": rjb_km: above rrup_km (" + f[5] + " > " + f[4] +
                       "): the closest distance to the rupture is never farther than its surface "
                       "projection's");
    }
    if (s.rrup_km > s.rhyp_km + kDistanceRoundingKm) {
      throw InputError(where + ": rrup_km: above rhyp_km (" + f[4] + " > " + f[6] +
                       "): the hypocentre is a point of the rupture");
    }
    if (!out.emplace(s.rsn, s).second) {
      throw InputError(where + ": rsn: " + f[0] + " given twice");
    }
  }
  if (out.empty()) throw InputError(path + ": no rows");
  return out;
}

int record_rsn(const std::string& file_name) {
  const auto bad = [&] {
    return InputError(file_name + ": its name does not begin with RSN<number>_ (a PEER record "
                      "name): --record-info matches records by RSN");
  };
  if (file_name.rfind("RSN", 0) != 0) throw bad();
  std::size_t end = 3;
  while (end < file_name.size() && file_name[end] >= '0' && file_name[end] <= '9') ++end;
  if (end == 3 || end > 12 || end >= file_name.size() || file_name[end] != '_') throw bad();
  return std::stoi(file_name.substr(3, end - 3));
}

const RecordSource& record_source(const std::map<int, RecordSource>& info,
                                  const std::string& file_name, const std::string& info_path) {
  const int rsn = record_rsn(file_name);
  const auto it = info.find(rsn);
  if (it == info.end()) {
    throw InputError(file_name + ": no row for RSN " + std::to_string(rsn) + " in " + info_path +
                     " (--record-info: tools/pwave-stations.py writes one)");
  }
  return it->second;
}

void validate(const RegionalAlertModel& m) {
  const auto check = [](double v, bool ok, const char* field) {
    if (!std::isfinite(v) || !ok) {
      throw InputError(std::string(field) + ": out of range: " + std::to_string(v));
    }
  };
  check(m.latency_median_s, m.latency_median_s >= 0.0 && m.latency_median_s <= 600.0,
        "--regional-latency (s, 0 to 600)");
  check(m.latency_sd_s, m.latency_sd_s >= 0.0 && m.latency_sd_s <= 60.0,
        "--regional-latency-sd (s, 0 to 60)");
  check(m.latency_floor_s, m.latency_floor_s >= 0.0 && m.latency_floor_s <= m.latency_median_s,
        "the latency's floor (s, 0 to the median)");
  check(m.s_wave_speed_km_s, m.s_wave_speed_km_s > 0.0 && m.s_wave_speed_km_s <= 10.0,
        "the S waves' speed (km/s, above 0, at most 10)");
  check(m.error_bias_ln, std::fabs(m.error_bias_ln) <= 3.0, "--regional-bias (ln, -3 to 3)");
  check(m.error_sigma_ln, m.error_sigma_ln >= 0.0 && m.error_sigma_ln <= 3.0,
        "--regional-sigma (ln, 0 to 3)");
  check(m.declared_sigma_ln, m.declared_sigma_ln >= 0.0 && m.declared_sigma_ln <= 3.0,
        "the declared sigma_ln (0 to 3: the room's range)");
}

SimulatedRegionalAlert simulate_regional_alert(const RegionalAlertModel& model,
                                               const RecordSource& source,
                                               const RecordPhases& phases, double true_pga_g,
                                               const LognormalFragility& fragility,
                                               std::uint64_t seed) {
  if (!(true_pga_g > 0.0) || !std::isfinite(true_pga_g)) {
    throw InputError("the regional alert: the run's PGA must be above 0 g");
  }
  std::mt19937_64 random(seed);
  std::normal_distribution<double> gauss;
  const double latency =
      std::max(model.latency_floor_s, model.latency_median_s + model.latency_sd_s * gauss(random));
  const double eps = model.error_bias_ln + model.error_sigma_ln * gauss(random);
  SimulatedRegionalAlert a;
  const double s_travel = source.rhyp_km / model.s_wave_speed_km_s;
  a.origin_s = phases.strong_motion_s - s_travel;
  a.alert_s = a.origin_s + latency;
  a.s_arrival_s = a.origin_s + s_travel;
  a.pga_g = std::min(kMaxAlertPgaG, true_pga_g * std::exp(eps));
  a.sigma_ln = model.declared_sigma_ln;

  // The box's own room, as the box would take the alert at its receipt.
  monitor::RegionalAlertSettings settings;
  settings.fragility_known = true;
  settings.fragility = fragility;
  monitor::RegionalAlertState room;
  const Error e = monitor::RegionalAlertState::create(settings, room);
  if (!e.ok()) throw InputError(std::string("the regional room: ") + e.field + " " + e.reason);
  monitor::RegionalAlert alert;
  alert.event_id = static_cast<std::uint32_t>(source.rsn);
  alert.version = 0;
  alert.magnitude = static_cast<Real>(source.magnitude);
  alert.distance_km = static_cast<Real>(source.rhyp_km);  // shown only: the epicentre's is not known
  alert.origin_age_s = static_cast<Real>(latency);
  alert.pga_g = static_cast<Real>(a.pga_g);
  alert.sigma_ln = static_cast<Real>(a.sigma_ln);
  alert.s_arrival_in_s = static_cast<Real>(a.s_arrival_s - a.alert_s);
  constexpr std::int64_t kReceiptNs = 1'000'000'000;  // any time of the room's clock
  const monitor::RegionalOutcome outcome = room.receive(alert, kReceiptNs);
  if (!outcome.accepted()) {
    throw InputError("RSN " + std::to_string(source.rsn) + ": the regional room refused the alert: " +
                     monitor::regional_refusal_name(outcome.refusal) + " " + outcome.field);
  }
  a.probability = static_cast<double>(room.status().probability);
  return a;
}

}  // namespace plinth::host
