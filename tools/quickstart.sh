#!/usr/bin/env bash
# The README's first command: install what is missing, build (Release), and run the main job
# on the bundled default: plinth-sim on the paper's Fig. 8 case H (eccentric block, base
# stops, Buia 1976 record scaled by 6.5).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target plinth-sim
echo
exec build/release/sim/plinth-sim \
  --scene sim/scenes/paper-eccentric.toml \
  --record sim/data/records/friuli1976-09-15_buia_000.AT2 --scale 6.5 \
  --out build/release/quickstart.csv --events build/release/quickstart-events.jsonl
