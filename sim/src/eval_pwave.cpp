#include "eval_pwave.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "plinth/core/scene.h"
#include "plinth/host/input_error.h"
#include "plinth/host/limits.h"
#include "plinth/host/pwave_records.h"
#include "plinth/host/record_sampling.h"
#include "plinth/host/units.h"
#include "plinth/monitor/p_wave.h"

namespace plinth::sim {

using host::InputError;

std::vector<host::Record> read_records(const std::vector<std::string>& records,
                                       const std::vector<std::string>& verticals) {
  if (!verticals.empty() && verticals.size() != records.size()) {
    throw InputError("--vertical: " + std::to_string(verticals.size()) + " given for " +
                     std::to_string(records.size()) +
                     " --record: the i-th --vertical belongs to the i-th --record");
  }
  std::vector<host::Record> out;
  for (std::size_t i = 0; i < records.size(); ++i) {
    out.push_back(host::read_record(records[i], kStandardGravity));
    if (verticals.empty()) continue;
    const host::Record v = host::read_record(verticals[i], kStandardGravity);
    host::attach_vertical(out.back(), v, "--vertical " + verticals[i]);
  }
  return out;
}

namespace {

struct FitOptions {
  std::vector<std::string> record_paths;
  std::vector<std::string> vertical_paths;
  std::vector<std::string> pgas{"0.3g", "0.6g", "1.2g"};
  double rate_hz = 200.0;
  std::string channel = "vertical";
  bool fit_tau_c = false;
  double lead_in_s = 2.0;
  bool trace = false;       // print every candidate's judgement and every refusal
  bool cross_validate = false;  // leave one earthquake out
  double max_retry_s = 0.0;  // the stage's S-wave guard, s (0: its default)
};

// --trace: what the stage did at the sample of time `now_s` (from the lead-in's start), its
// status `before` and after it; `candidate_s` keeps the latest candidate's start. Printed in
// record time (from the record's first sample).
void print_trace(const monitor::PWaveStatus& before, const monitor::PWaveStatus& s,
                 double lead_in_s, double now_s, double& candidate_s) {
  if (s.rejected_not_after_quiet > before.rejected_not_after_quiet) {
    std::printf("#   %.3f s: excitation refused (not after quiet), %.3f s after its first "
                "candidate\n",
                now_s - lead_in_s, now_s - s.excitation_onset_s);
  }
  if (s.candidates > before.candidates) candidate_s = now_s;
  if (before.state != monitor::PWaveState::kCandidate ||
      s.state == monitor::PWaveState::kCandidate) {
    return;
  }
  std::printf("#   candidate %.3f s (excitation +%.3f s): ", candidate_s - lead_in_s,
              candidate_s - s.excitation_onset_s);
  if (s.triggers > before.triggers) {
    std::printf("trigger, tau_p %.2f s, tau_c %.2f s, Pa %.3g m/s2, peak |a_h| / Pa %.2f, "
                "predicted %.3g g\n",
                s.tau_p_s, s.tau_c_s, s.pa_m_s2, s.horizontal_m_s2 / s.pa_m_s2,
                s.predicted_pga_g);
  } else {
    std::printf("rejected, %s\n", monitor::kPWaveRejectionNames.name(s.last_rejection));
  }
}

// The box's 2 s of quiet before a record (plinth-eval run's lead-in), then the record scaled by
// gamma at the box's rate, through the stage; what it saw of its first trigger.
struct StageTrace {
  bool triggered = false;
  double onset_s = 0.0;  // from the record's first sample
  monitor::PWaveStatus at_close;
  std::vector<host::PWaveWindowSample> samples;
};

StageTrace trace_stage(const host::Record& record, double gamma, const FitOptions& opt,
                       const monitor::PWaveSettings& settings,
                       const std::vector<double>& windows) {
  monitor::PWaveStage stage;
  const Error e = monitor::PWaveStage::create(settings, stage);
  if (!e.ok()) throw InputError(std::string("the P-wave stage: ") + e.field + " " + e.reason);
  const std::size_t count = host::sample_count(record.duration(), opt.rate_hz);
  const std::vector<double> h = host::resample(record.horizontal_signal(), opt.rate_hz, count);
  const std::vector<double> v = host::resample(record.vertical_signal(), opt.rate_hz, count);
  const auto lead = static_cast<std::size_t>(std::llround(opt.lead_in_s * opt.rate_hz));
  const double pga = record.peak_horizontal() * gamma;
  StageTrace trace;
  std::size_t next_window = 0;
  double candidate_s = 0.0;
  for (std::size_t n = 0; n < lead + count; ++n) {
    const std::size_t k = n < lead ? count : n - lead;  // count: the quiet lead-in
    // The record as it is after a lead-in at rest: what the box's replay gives the stage
    // (record_replay_sample; plinth-eval run's copy of the stage takes the same).
    const Vector3r ground =
        k < count ? Vector3r(gamma * h[k], 0.0, gamma * v[k]) : Vector3r::Zero();
    const monitor::PWaveStatus before = stage.status();
    const monitor::PWaveStatus& s = stage.update(ground);
    if (opt.trace) {
      print_trace(before, s, opt.lead_in_s, static_cast<double>(n) * settings.sample_period_s,
                  candidate_s);
    }
    if (s.triggers == 0) continue;
    if (!trace.triggered) {
      trace.triggered = true;
      trace.onset_s = s.onset_s - opt.lead_in_s;
    }
    if (s.triggers > 1) break;  // only the first event
    // The window's samples up to and with the one that closed it.
    const bool closing = s.state == monitor::PWaveState::kHolding &&
                         trace.at_close.window_end == monitor::PWaveWindowEnd::kNone;
    if (s.state == monitor::PWaveState::kWindow || closing) {
      while (next_window < windows.size() && s.window_s >= windows[next_window] - 1e-9) {
        if (std::fabs(s.window_s - windows[next_window]) < 0.5 * settings.sample_period_s) {
          trace.samples.push_back(
              {windows[next_window], std::log(pga / s.pa_m_s2), std::log(s.tau_c_s)});
        }
        ++next_window;
      }
    }
    if (closing) trace.at_close = s;
  }
  return trace;
}

// The earthquake of a PEER file name, RSN<number>_<earthquake>_<station and component>.AT2.
std::string earthquake_of(const std::string& name) {
  const std::size_t first = name.find('_');
  const std::size_t second = first == std::string::npos ? first : name.find('_', first + 1);
  if (name.rfind("RSN", 0) != 0 || second == std::string::npos || second == first + 1) {
    throw InputError("--cross-validate: " + name +
                     ": not named RSN<number>_<earthquake>_..., the earthquake is unknown");
  }
  return name.substr(first + 1, second - first - 1);
}

int run_fit(const FitOptions& opt) {
  monitor::PWaveSettings settings;
  settings.sample_period_s = 1.0 / opt.rate_hz;
  if (!monitor::kPWaveChannelNames.parse(opt.channel, settings.channel)) {
    throw InputError("--channel: expected vertical or horizontal, got '" + opt.channel + "'");
  }
  settings.predictor = monitor::default_predictor(settings.channel);
  if (opt.max_retry_s > 0.0) settings.max_retry_s = opt.max_retry_s;
  std::vector<double> windows;
  for (int i = 1; i <= static_cast<int>(monitor::kMaxPWavePredictorPoints); ++i) {
    windows.push_back(0.5 * i);
  }
  const std::vector<host::Record> records = read_records(opt.record_paths, opt.vertical_paths);
  std::vector<host::PWaveWindowSample> samples;
  std::vector<std::string> earthquakes;  // of each sample, for --cross-validate
  std::printf("# record, PGA (g), P pick (s), strong motion (s), trigger (s), window end, W (s), "
              "Pa (m/s2), tau_c (s), tau_p (s), predicted PGA at the close (g, the box's default "
              "table)\n");
  for (std::size_t r = 0; r < records.size(); ++r) {
    const host::Record& record = records[r];
    if (record.vertical.empty()) {
      throw InputError(opt.record_paths[r] + ": pwave-fit needs its --vertical");
    }
    const host::RecordPhases phases = host::record_phases(record);
    const std::string name = std::filesystem::path(opt.record_paths[r]).filename().string();
    const std::string earthquake = opt.cross_validate ? earthquake_of(name) : std::string();
    for (const std::string& pga_text : opt.pgas) {
      const double pga =
          host::parse_acceleration(pga_text, kStandardGravity, "--pga") / kStandardGravity;
      if (!(pga > 0.0)) throw InputError("--pga: must be above 0 g, got " + pga_text);
      const double gamma = pga * kStandardGravity / record.peak_horizontal();
      const StageTrace t = trace_stage(record, gamma, opt, settings, windows);
      samples.insert(samples.end(), t.samples.begin(), t.samples.end());
      earthquakes.insert(earthquakes.end(), t.samples.size(), earthquake);
      const monitor::PWaveStatus& c = t.at_close;
      std::printf("%s, %.3g, %.2f, %.2f, %s, %s, %.2f, %.4g, %.3g, %.3g, %.3g\n", name.c_str(),
                  pga, phases.p_pick_s, phases.strong_motion_s,
                  t.triggered ? host::number_text(t.onset_s, 4).c_str() : "none",
                  monitor::kPWaveWindowEndNames.name(c.window_end), c.window_s, c.pa_m_s2,
                  c.tau_c_s, c.tau_p_s, c.predicted_pga_g);
    }
  }
  if (opt.trace) return 0;  // a trace, not a fit
  if (!opt.fit_tau_c) {
    for (host::PWaveWindowSample& s : samples) s.ln_tau_c = 0.0;  // c0 alone: the mean
  }
  const std::vector<host::PWaveFitPoint> table = host::fit_pwave_predictor(samples, windows);
  std::printf("\n# window_s, samples, ln_pga_over_pa, tau_c_exponent, sigma_ln%s\n",
              "  (borrowed: too few samples, the neighbour's line)");
  for (const host::PWaveFitPoint& p : table) {
    std::printf("%.1f, %zu, %.3f, %.3f, %.3f%s\n", p.window_s, p.samples, p.c0, p.c1, p.sigma,
                p.borrowed ? ", borrowed" : "");
  }
  if (opt.cross_validate) {
    const host::PWaveCrossValidation cv =
        host::cross_validate_pwave_predictor(samples, earthquakes, windows);
    std::printf("\n# leave one earthquake out (the earthquake from the file name, "
                "RSN<number>_<earthquake>_), %zu earthquakes: window_s, samples, sigma_ln of "
                "the residuals on the earthquake left out\n",
                cv.groups.size());
    for (const host::PWaveFitPoint& p : cv.pooled) {
      std::printf("%.1f, %zu, %.3f\n", p.window_s, p.samples, p.sigma);
    }
    std::printf("\n# per earthquake left out: earthquake, then per window samples:rms\n");
    for (std::size_t g = 0; g < cv.groups.size(); ++g) {
      std::printf("%s", cv.groups[g].c_str());
      for (std::size_t w = 0; w < windows.size(); ++w) {
        std::printf(", %zu:%.3f", cv.count[g][w], cv.rms[g][w]);
      }
      std::printf("\n");
    }
  }
  std::printf("\n# as C++ (p_wave.h) and as the box's file ([pwave] predictor)\n");
  for (const host::PWaveFitPoint& p : table) {
    std::printf("        {%.1f, %.3f, %.3f, %.3f},\n", p.window_s, p.c0, p.c1, p.sigma);
  }
  std::printf("[pwave]\nchannel = \"%s\"\npredictor = [\n",
              monitor::kPWaveChannelNames.name(settings.channel));
  for (const host::PWaveFitPoint& p : table) {
    std::printf("  { window_s = %.1f, ln_pga_over_pa = %.3f, tau_c_exponent = %.3f, "
                "sigma_ln = %.3f },\n",
                p.window_s, p.c0, p.c1, p.sigma);
  }
  std::printf("]\n");
  return 0;
}

}  // namespace

Subcommand add_pwave_fit(CLI::App& app) {
  auto opt = std::make_shared<FitOptions>();
  CLI::App* fit = app.add_subcommand(
      "pwave-fit", "run the P-wave stage on three-component records and fit its predictor");
  fit->add_option("--record", opt->record_paths, "horizontal records (repeat)")->required();
  fit->add_option("--vertical", opt->vertical_paths,
                  "their vertical components, the i-th for the i-th --record")
      ->required();
  fit->add_option("--pga", opt->pgas, "PGAs the records are scaled to (default 0.3g 0.6g 1.2g)");
  fit->add_option("--rate", opt->rate_hz, "the box's sample rate, Hz (default 200)")
      ->check(CLI::Range(50.0, 2000.0));
  fit->add_option("--channel", opt->channel, "vertical (default) or horizontal");
  fit->add_flag("--fit-tau-c", opt->fit_tau_c,
                "also fit tau_c's exponent (default: 0, the mean ratio alone)");
  fit->add_flag("--trace", opt->trace,
                "instead of the fit: each candidate's judgement and each excitation refused, up "
                "to the second trigger ('#' lines), on the samples plinth-eval run gives the "
                "stage (less the record's first sample)");
  fit->add_flag("--cross-validate", opt->cross_validate,
                "also the residuals' sigma on each earthquake under the fit without it (leave "
                "one earthquake out; the earthquake from the file name, RSN<number>_<name>_)");
  fit->add_option("--max-retry-s", opt->max_retry_s,
                  "the stage's S-wave guard: retries up to this long after an excitation's "
                  "first candidate, s (default: the stage's, 2)")
      ->check(CLI::Range(0.01, 3600.0));
  return {fit, [opt] { return run_fit(*opt); }};
}

}  // namespace plinth::sim
