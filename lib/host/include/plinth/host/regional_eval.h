// Regional alerts evaluated by simulation (docs/regional.md, "Evaluation"): each record's source
// (magnitude and distances, from a CSV that tools/pwave-stations.py writes from the NGA-West2
// flatfile) and the alert a regional early-warning system would have sent for it: its time from
// a latency model and its PGA with the error of published early-warning performance. The alert
// goes to the box's own regional room (lib/monitor regional_alert.h), which gives the statue's
// probability of collapse under it. Host-only.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "plinth/core/fragility.h"
#include "plinth/host/pwave_records.h"

namespace plinth::host {

// One station's row of the record-info CSV (columns rsn, earthquake, station, magnitude,
// rrup_km, rjb_km, rhyp_km, vs30_m_s; the NGA-West2 flatfile's earthquake_magnitude, clstd_km,
// joyner_booredist_km, hypd_km, vs30_m_s_selectedforanalysis).
struct RecordSource {
  int rsn = 0;
  std::string earthquake;
  std::string station;
  double magnitude = 0.0;  // moment magnitude
  double rrup_km = 0.0;    // closest distance to the rupture, km
  double rjb_km = 0.0;     // Joyner-Boore distance, km
  double rhyp_km = 0.0;    // hypocentral distance, km
  double vs30_m_s = 0.0;   // m/s
};

// The accepted ranges (a row outside is refused, naming file, line and field).
inline constexpr double kMaxRecordMagnitude = 10.0;
inline constexpr double kMaxRecordDistanceKm = 20040.0;  // half the Earth's circumference
inline constexpr double kMaxRecordVs30M_s = 5000.0;

// Reads the CSV: the header must be exactly the columns above; every number finite and in
// range (magnitude (0, 10], distances [0, 20040] km with Rjb <= Rrup <= Rhyp within 0.01 km of
// rounding, rhyp > 0, Vs30 (0, 5000] m/s), each RSN once. Throws InputError naming the file, the
// line and the field.
[[nodiscard]] std::map<int, RecordSource> read_record_info(const std::string& path);

// The RSN of a PEER file name ("RSN963_NORTHR_ORR090.AT2": 963); throws InputError naming the
// file when it does not begin so.
[[nodiscard]] int record_rsn(const std::string& file_name);
// The row of the record's RSN; throws InputError naming the record and the info file when none.
[[nodiscard]] const RecordSource& record_source(const std::map<int, RecordSource>& info,
                                                const std::string& file_name,
                                                const std::string& info_path);

// The simulated regional system. Every default is a published figure or a stated assumption
// (docs/regional.md, "Evaluation", gives each source).
struct RegionalAlertModel {
  // s from the origin to the alert at the site: ShakeAlert characterised both Ridgecrest 2019
  // earthquakes (M 6.4 and 7.1) within 6.9 s of their origin times (Chung et al. 2020, BSSA,
  // "ShakeAlert earthquake early warning system performance during the 2019 Ridgecrest
  // earthquake sequence").
  double latency_median_s = 6.9;
  // s, the latency's standard deviation (normal, per run). An assumption: no published spread
  // was found; a Barstow M 4.9 alert came 12 s after its origin (Caltech,
  // reported by Pasadena Now, 2024), 5 s later.
  double latency_sd_s = 2.0;
  // s: no system alerts before the P wave has reached a few stations (ShakeAlert needs four; at
  // 6 km/s and typical station spacing that takes seconds). An assumption; the latency is cut
  // to it from below.
  double latency_floor_s = 3.0;
  // The S waves' speed, km/s: the alert's S arrival is origin + Rhyp / Vs (the crust's upper
  // layers, 3.5 km/s; the box's own duration term uses the same, regional_alert.h).
  double s_wave_speed_km_s = 3.5;
  // ln(predicted PGA / true PGA) ~ N(bias, sigma): ground motion scatters about a factor 2 around
  // the median even for a perfectly known source (Minson et al. 2019, Sci. Rep., doi
  // 10.1038/s41598-019-39384-y); sigma = ln 2. The bias is 0 by default (unbiased magnitude);
  // ShakeAlert underestimated Ridgecrest M 7.1 by 0.8 units (Chung et al. 2020): --regional-bias
  // tries that.
  double error_bias_ln = 0.0;
  double error_sigma_ln = 0.6931471805599453;  // ln 2
  // The sigma_ln the alert declares (the box's P(collapse) uses it): the model's own scatter.
  double declared_sigma_ln = 0.6931471805599453;
};

// Throws InputError naming the field (as --regional-... options) when a value is not finite or
// out of its range.
void validate(const RegionalAlertModel& model);

// The box's regional room accepts PGAs up to this (regional_alert.h's range); a higher
// prediction is sent as this.
inline constexpr double kMaxAlertPgaG = 10.0;

// One run's alert, times in s from the record's first sample (negative: before it).
struct SimulatedRegionalAlert {
  double origin_s = 0.0;     // strong_motion_s - Rhyp / Vs: the record's S arrival taken as
                             // the start of its strong motion (RecordPhases)
  double alert_s = 0.0;      // origin + latency (drawn)
  double s_arrival_s = 0.0;  // origin + Rhyp / Vs, as the alert sends it
  double pga_g = 0.0;        // predicted: true PGA x exp(eps), eps drawn
  double sigma_ln = 0.0;     // declared
  // The statue's probability of collapse under the alert, from the box's regional room
  // (monitor::RegionalAlertState, the fragility given) at its receipt.
  double probability = 0.0;
  // The alert comes at or after the S arrival it sends: the blind zone.
  [[nodiscard]] bool blind() const { return alert_s >= s_arrival_s; }
};

// The alert for a record of `source` scaled to `true_pga_g`, its draws from `seed` (the same
// seed, the same alert). Throws InputError when the room refuses it (naming the reason).
[[nodiscard]] SimulatedRegionalAlert simulate_regional_alert(const RegionalAlertModel& model,
                                                            const RecordSource& source,
                                                            const RecordPhases& phases,
                                                            double true_pga_g,
                                                            const LognormalFragility& fragility,
                                                            std::uint64_t seed);

}  // namespace plinth::host
