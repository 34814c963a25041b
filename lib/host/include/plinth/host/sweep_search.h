// The search at the heart of plinth-sweep (docs/sweep.md): which events one simulation under a
// scaled record shows, and the smallest level (PGA, impulse) at which each first occurs, by a
// scan and a bisection checked one tolerance below.
#pragma once

#include <array>
#include <atomic>
#include <bitset>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "plinth/core/name_table.h"
#include "plinth/core/scene.h"
#include "plinth/host/record_io.h"

namespace plinth::host {

// The events a sweep looks for, in the order of the CSV columns.
enum class SweepEvent : unsigned char {
  kSliding,       // a kSlidingStart event
  kRocking,       // a kRockingStart event
  kSlideRocking,  // any event leaving the block in Phase::kSlideRocking
  kOutOfBase,     // kOutOfBase
  kBaseStopHit,   // kBaseStopHit
  kSlideStopHit,  // kSlideStopHit
  kFell,          // kFell
  kOverturned,    // kOverturned
  kLiftOff,       // kLiftOff: the model ends (its threshold bounds where the others are valid)
};
inline constexpr std::size_t kSweepEventCount = 9;

// The CSV columns' names, in the order above.
inline constexpr NameTable<SweepEvent, kSweepEventCount> kSweepEventNames{{{
    {SweepEvent::kSliding, "sliding"},
    {SweepEvent::kRocking, "rocking"},
    {SweepEvent::kSlideRocking, "slide_rocking"},
    {SweepEvent::kOutOfBase, "out_of_base"},
    {SweepEvent::kBaseStopHit, "base_stop_hit"},
    {SweepEvent::kSlideStopHit, "slide_stop_hit"},
    {SweepEvent::kFell, "fell"},
    {SweepEvent::kOverturned, "overturned"},
    {SweepEvent::kLiftOff, "lift_off"},
}}};
[[nodiscard]] constexpr const char* sweep_event_name(SweepEvent event) {
  return kSweepEventNames.name(event);
}

// Throws InputError("--event: unknown event 'x' (one of sliding, ...)").
[[nodiscard]] SweepEvent parse_sweep_event(const std::string& text);

// A set of events, indexed by SweepEvent.
using EventSet = std::bitset<kSweepEventCount>;
inline const EventSet kAllEvents = EventSet{}.set();

// The events the scene's features allow (features_of, scene.h): sliding and slide_rocking need
// friction, base stop hits base stops, leaving the support and falling a support without
// sliding stops, sliding stop hits sliding stops. Every scene can lift off.
[[nodiscard]] EventSet possible_events(const Scene& scene);

// Which events occurred in one simulation; indexed by SweepEvent.
struct Occurrences {
  std::array<bool, kSweepEventCount> occurred{};

  [[nodiscard]] bool operator[](SweepEvent e) const {
    return occurred[static_cast<std::size_t>(e)];
  }
};

// The first level of each event, indexed by SweepEvent; none where it did not occur.
using Thresholds = std::array<std::optional<double>, kSweepEventCount>;

struct SweepSettings {
  double pga_max_g = 2.0;      // largest PGA scanned, in g (the scene's gravity)
  double tolerance_g = 0.001;  // width of the final bisection bracket, in g
  int scan_points = 40;        // grid PGA = pga_max * k / scan_points, k = 1..scan_points
  double dt = 5e-4;            // solver step, s
  // The events searched; the others are left empty. A threshold does not depend on which
  // other events are searched with it, so searching fewer only saves simulations.
  EventSet events = kAllEvents;
  // Skips the scan points below the PGA at which the block provably stays in full contact
  // (quiet_pga_g); off only to test that it changes nothing.
  bool skip_quiet_scan = true;
};

// Throws InputError when a setting is out of range (non-finite, not positive, no points).
void validate(const SweepSettings& settings);

// Throws InputError naming the record when it cannot be scaled to a PGA (all zeros).
void require_scalable(const Record& record);

// One simulation from rest under `record` scaled to a peak of `pga_mps2` (m/s2), with step
// settings.dt, until the record's end + 2 s, a terminal phase, or every event of
// settings.events the scene allows has occurred (the others may then be missing). Throws
// InputError when the record is all zeros or the step is too large for the scene.
[[nodiscard]] Occurrences simulate_occurrences(const Scene& scene, const Record& record,
                                               double pga_mps2, const SweepSettings& settings);

// The PGA (in g) below which the block provably stays in full contact under `record`: no
// event at all. Full contact is linear (Eq 1), so one run of the base alone at unit scale
// gives the peak absolute acceleration and base displacement per unit PGA; the first of Eq 15
// (mu_s g), Eq 16 (min(b1, b2) g / h, either direction) and Eq 28 (u_max) bounds it. Infinity
// when nothing can happen.
[[nodiscard]] double quiet_pga_g(const Scene& scene, const Record& record, double dt);

// The first-occurrence search shared by the PGA thresholds and the impulse curves. `simulate`
// runs at a level in (0, level_max] (PGA in g, impulse in m/s) and reports the events of
// `events`; levels <= `quiet_below` are taken as showing none (not simulated). The grid
// level_max * k / scan_points is scanned; for each event the first grid interval showing it is
// bisected to `tolerance`, and the result thr is checked: the event occurs at thr and not at
// thr - tolerance (when > 0); if it does, the search goes on below. Each event's search uses
// only the scan and its own bisection (runs are shared as a cache), so its result does not
// depend on the other events searched. Nothing is assumed at level 0. Throws JobCancelled
// (job_runner.h) once *stop turns true.
struct SearchGrid {
  double level_max = 1.0;
  int scan_points = 40;
  double tolerance = 1e-3;
  double quiet_below = 0.0;
};
[[nodiscard]] Thresholds first_occurrences(const std::function<Occurrences(double level)>& simulate,
                                           const SearchGrid& grid, EventSet events,
                                           const std::atomic<bool>* stop = nullptr,
                                           std::size_t* simulations = nullptr);

// For each event of settings.events the scene allows, the smallest PGA (in g) at which it
// occurs (first_occurrences on PGA), or nothing when it does not occur on the scan grid up to
// settings.pga_max_g. `simulations`, when given, is increased by the number of simulations
// run. Throws JobCancelled when *stop turns true.
[[nodiscard]] Thresholds first_occurrence_thresholds(const Scene& scene, const Record& record,
                                                     const SweepSettings& settings,
                                                     std::size_t* simulations = nullptr,
                                                     const std::atomic<bool>* stop = nullptr);

}  // namespace plinth::host
