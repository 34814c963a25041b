#!/usr/bin/env bash
# The README's first command: install what is missing, build (Release), and run the main job
# on the bundled default: plinth-monitor replaying the paper's Fig. 8 case H (eccentric block on
# the isolated base with stops, Buia 1976 record scaled by 6.5), showing the alarm timeline,
# and the event recorder's capture drawn as a PNG (tools/plinth-event-plot).
# It installs what building and running these programs needs (tools/install-deps.sh --build: no
# test, emulation or cross tooling) and configures without the test suites; the second command
# (tools/test-all.sh) installs the rest and configures them back in.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh --build
cmake --preset release -DPLINTH_BUILD_TESTS=OFF -DPLINTH_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build --preset release --target plinth-monitor plinth-sim
echo
echo "plinth-monitor: alarm changes and phase events (all status lines: build/release/quickstart.jsonl)"
rm -rf build/release/quickstart-captures
build/release/firmware/linux/plinth-monitor \
  --scene sim/scenes/paper-eccentric.toml \
  --replay sim/data/records/friuli1976-09-15_buia_000.AT2 --scale 6.5 \
  --record-dir build/release/quickstart-captures >build/release/quickstart.jsonl
grep -E '"type": "(alarm|event|summary)"' build/release/quickstart.jsonl | cut -c 1-150
# The custodian's picture of the recorder's capture (gnuplot); the capture starts with the
# replay's noise-free lead-in, hence --stuck-samples 0 for its replay.
echo
PLINTH_MONITOR=build/release/firmware/linux/plinth-monitor tools/plinth-event-plot \
  --scene sim/scenes/paper-eccentric.toml build/release/quickstart-captures/event-001.log \
  -- --stuck-samples 0
