// The P-wave stage on real three-component records (sim/data/records/pwave/): small quakes (the
// smallest bundled earthquakes' records scaled down) raise no warning for a statue that would
// not fall; the same records scaled up to shaking far past its median do, before the strong
// motion where the P wave comes early enough.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "plinth/core/scene.h"
#include "plinth/host/pwave_records.h"
#include "plinth/host/record_io.h"
#include "plinth/host/record_sampling.h"
#include "plinth/monitor/alarm_policy.h"
#include "plinth/monitor/p_wave.h"
#include "test_paths.h"

namespace plinth::monitor {
namespace {

struct Station {
  const char* horizontal;
  const char* vertical;
};

// Coalinga-05 (M 5.77) and Livermore-01 (M 5.80), the smallest earthquakes bundled, and two
// Northridge-01 stations 20-30 km away (SOURCES.md).
constexpr Station kStations[] = {
    {"RSN412_COALINGA_D-PVY045.AT2", "RSN412_COALINGA_D-PVY-UP.AT2"},
    {"RSN410_COALINGA_D-PLM270.AT2", "RSN410_COALINGA_D-PLM-UP.AT2"},
    {"RSN214_LIVERMOR_A-KOD180.AT2", "RSN214_LIVERMOR_A-KOD-UP.AT2"},
    {"RSN963_NORTHR_ORR090.AT2", "RSN963_NORTHR_ORR-UP.AT2"},
    {"RSN987_NORTHR_CEN155.AT2", "RSN987_NORTHR_CEN-UP.AT2"},
};

host::Record three_component(const Station& s) {
  const std::string dir = plinth::testing::kSource + "/sim/data/records/pwave/";
  host::Record r = host::read_at2(dir + s.horizontal, kStandardGravity);
  host::attach_vertical(r, host::read_at2(dir + s.vertical, kStandardGravity), s.vertical);
  return r;
}

struct Response {
  std::uint64_t triggers = 0;
  double first_onset_s = -1.0;  // record time of the first trigger's onset
  std::uint64_t refused = 0;    // excitations refused by the S-wave guard
  double highest_probability = 0.0;
  double first_warning_s = -1.0;  // record time at which P >= the policy's warning_pwave.on
};

// The record scaled to `pga_g`, after 20 s of quiet, at 200 Hz, through the stage of a statue
// with the given fragility (the conditioned samples an ideal sensor gives).
// max_retry_s: the S-wave guard's (0: the default's).
Response respond(const host::Record& record, double pga_g, LognormalFragility fragility,
                 double max_retry_s = 0.0) {
  constexpr double kRate = 200.0;
  constexpr double kQuietS = 20.0;
  PWaveSettings settings;
  settings.sample_period_s = 1.0 / kRate;
  settings.fragility_known = true;
  settings.fragility = fragility;
  if (max_retry_s > 0.0) settings.max_retry_s = max_retry_s;
  PWaveStage stage;
  EXPECT_TRUE(PWaveStage::create(settings, stage).ok());
  const double gamma = pga_g * kStandardGravity / record.peak_horizontal();
  const std::size_t n = host::sample_count(record.duration(), kRate);
  const std::vector<double> h = host::resample(record.horizontal_signal(), kRate, n);
  const std::vector<double> v = host::resample(record.vertical_signal(), kRate, n);
  const double on = AlarmPolicySettings{}.warning_pwave.on;
  Response out;
  for (std::size_t i = 0; i < static_cast<std::size_t>(kQuietS * kRate); ++i) {
    (void)stage.update(Vector3r::Zero());
  }
  for (std::size_t k = 0; k < n; ++k) {
    const PWaveStatus& s =
        stage.update(Vector3r(gamma * (h[k] - h[0]), 0.0, gamma * (v[k] - v[0])));
    out.triggers = s.triggers;
    out.refused = s.rejected_not_after_quiet;
    if (out.first_onset_s < 0.0 && s.triggers > 0) out.first_onset_s = double(s.onset_s) - kQuietS;
    out.highest_probability = std::max(out.highest_probability, double(s.probability));
    if (out.first_warning_s < 0.0 && s.probability >= on) {
      out.first_warning_s = static_cast<double>(k) / kRate;
    }
  }
  return out;
}

// A small quake: 0.05 g at the statue; its fragility's median is 0.6 g (beta 0.3): it would
// not fall. The stage may well trigger (it is an earthquake), and must not warn.
TEST(PWaveRecords, SmallQuakesRaiseNoWarningForAStatueThatWouldNotFall) {
  for (const Station& s : kStations) {
    const host::Record record = three_component(s);
    for (const double pga : {0.02, 0.05}) {
      const Response r = respond(record, pga, {0.6, 0.3});
      EXPECT_LT(r.highest_probability, AlarmPolicySettings{}.warning_pwave.on)
          << s.horizontal << " at " << pga << " g";
      EXPECT_EQ(r.first_warning_s, -1.0) << s.horizontal << " at " << pga << " g";
      RecordProperty(std::string(s.horizontal) + " " + std::to_string(pga),
                     "triggers " + std::to_string(r.triggers) + ", highest P " +
                         std::to_string(r.highest_probability));
    }
  }
}

// The same records at 2 g, 3.3 times the statue's median (P(collapse) 0.9999): a warning, and
// before the strong motion where the P wave comes at least 3 s before it (the reference
// phases, pwave_records.h). At the calibrated threshold (0.8) the stage needs a prediction of
// about twice the median: at 1.2 g, twice it, one of these stations is not warned by the stage.
TEST(PWaveRecords, ToppingShakingIsWarnedBeforeItsStrongMotionWhenThePWaveComesEarly) {
  int early = 0;
  for (const Station& s : kStations) {
    const host::Record record = three_component(s);
    const host::RecordPhases phases = host::record_phases(record);
    const Response r = respond(record, 2.0, {0.6, 0.3});
    EXPECT_EQ(r.triggers, 1U) << s.horizontal;
    EXPECT_GE(r.first_warning_s, 0.0) << s.horizontal;
    if (phases.p_lead_s() >= 3.0) {
      ++early;
      EXPECT_LT(r.first_warning_s, phases.strong_motion_s) << s.horizontal;
    }
  }
  EXPECT_GE(early, 3);  // most of these stations see the P wave early
}

// Every bundled record (each station's two horizontals with its vertical).
constexpr Station kAllRecords[] = {
    {"RSN1003_NORTHR_STN020.AT2", "RSN1003_NORTHR_STN-UP.AT2"},
    {"RSN1003_NORTHR_STN110.AT2", "RSN1003_NORTHR_STN-UP.AT2"},
    {"RSN1044_NORTHR_NWH090.AT2", "RSN1044_NORTHR_NWH-UP.AT2"},
    {"RSN1044_NORTHR_NWH360.AT2", "RSN1044_NORTHR_NWH-UP.AT2"},
    {"RSN1049_NORTHR_SUN190.AT2", "RSN1049_NORTHR_SUN-UP.AT2"},
    {"RSN1049_NORTHR_SUN280.AT2", "RSN1049_NORTHR_SUN-UP.AT2"},
    {"RSN1063_NORTHR_RRS228.AT2", "RSN1063_NORTHR_RRS-UP.AT2"},
    {"RSN1063_NORTHR_RRS318.AT2", "RSN1063_NORTHR_RRS-UP.AT2"},
    {"RSN1080_NORTHR_KAT000.AT2", "RSN1080_NORTHR_KAT-UP.AT2"},
    {"RSN1080_NORTHR_KAT090.AT2", "RSN1080_NORTHR_KAT-UP.AT2"},
    {"RSN174_IMPVALL.H_H-E11140.AT2", "RSN174_IMPVALL.H_H-E11-UP.AT2"},
    {"RSN174_IMPVALL.H_H-E11230.AT2", "RSN174_IMPVALL.H_H-E11-UP.AT2"},
    {"RSN179_IMPVALL.H_H-E04140.AT2", "RSN179_IMPVALL.H_H-E04-UP.AT2"},
    {"RSN179_IMPVALL.H_H-E04230.AT2", "RSN179_IMPVALL.H_H-E04-UP.AT2"},
    {"RSN181_IMPVALL.H_H-E06140.AT2", "RSN181_IMPVALL.H_H-E06-UP.AT2"},
    {"RSN181_IMPVALL.H_H-E06230.AT2", "RSN181_IMPVALL.H_H-E06-UP.AT2"},
    {"RSN214_LIVERMOR_A-KOD180.AT2", "RSN214_LIVERMOR_A-KOD-UP.AT2"},
    {"RSN214_LIVERMOR_A-KOD270.AT2", "RSN214_LIVERMOR_A-KOD-UP.AT2"},
    {"RSN2622_CHICHI.03_TCU071E.AT2", "RSN2622_CHICHI.03_TCU071V.AT2"},
    {"RSN2622_CHICHI.03_TCU071N.AT2", "RSN2622_CHICHI.03_TCU071V.AT2"},
    {"RSN410_COALINGA_D-PLM270.AT2", "RSN410_COALINGA_D-PLM-UP.AT2"},
    {"RSN410_COALINGA_D-PLM360.AT2", "RSN410_COALINGA_D-PLM-UP.AT2"},
    {"RSN412_COALINGA_D-PVY045.AT2", "RSN412_COALINGA_D-PVY-UP.AT2"},
    {"RSN412_COALINGA_D-PVY135.AT2", "RSN412_COALINGA_D-PVY-UP.AT2"},
    {"RSN963_NORTHR_ORR090.AT2", "RSN963_NORTHR_ORR-UP.AT2"},
    {"RSN963_NORTHR_ORR360.AT2", "RSN963_NORTHR_ORR-UP.AT2"},
    {"RSN987_NORTHR_CEN155.AT2", "RSN987_NORTHR_CEN-UP.AT2"},
    {"RSN987_NORTHR_CEN245.AT2", "RSN987_NORTHR_CEN-UP.AT2"},
    {"RSN990_NORTHR_LAC090.AT2", "RSN990_NORTHR_LAC-UP.AT2"},
    {"RSN990_NORTHR_LAC180.AT2", "RSN990_NORTHR_LAC-UP.AT2"},
};

// The S-wave guard (max_retry_s, p_wave.h) on every bundled record at 0.2, 0.6, 1.2 and 2.5 g:
// where a stage that retries for a minute triggers first before the strong motion, the guarded
// stage triggers at the same sample and warns at the same time (max_retry_s was chosen so:
// docs/pwave.md). Where the guard refuses an excitation, that stage's first trigger came after
// the strong motion or never.
TEST(PWaveRecords, TheSWaveGuardCostsNoTriggerBeforeTheStrongMotion) {
  int compared = 0;
  int refused = 0;
  for (const Station& s : kAllRecords) {
    const host::Record record = three_component(s);
    const host::RecordPhases phases = host::record_phases(record);
    for (const double pga : {0.2, 0.6, 1.2, 2.5}) {
      const Response guarded = respond(record, pga, {0.82, 0.63});
      const Response retrying = respond(record, pga, {0.82, 0.63}, 60.0);
      EXPECT_EQ(retrying.refused, 0U);
      SCOPED_TRACE(std::string(s.horizontal) + " at " + std::to_string(pga) + " g");
      if (guarded.refused > 0) ++refused;
      if (retrying.first_onset_s >= 0.0 && retrying.first_onset_s < phases.strong_motion_s) {
        ++compared;
        EXPECT_EQ(guarded.first_onset_s, retrying.first_onset_s);
        if (retrying.first_warning_s >= 0.0 && retrying.first_warning_s < phases.strong_motion_s) {
          EXPECT_EQ(guarded.first_warning_s, retrying.first_warning_s);
        }
      } else if (guarded.first_onset_s != retrying.first_onset_s) {
        EXPECT_TRUE(guarded.first_onset_s < 0.0 || guarded.first_onset_s >= phases.strong_motion_s);
      }
    }
  }
  EXPECT_GE(compared, 100);  // of 120: most records trigger before their strong motion
  EXPECT_GE(refused, 1);     // and the guard does act on them (RSN1080 KAT000 at 0.2 g)
  RecordProperty("compared", compared);
  RecordProperty("refused", refused);
}

}  // namespace
}  // namespace plinth::monitor
