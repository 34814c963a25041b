#!/usr/bin/env bash
# Plots a plinth-sweep CSV (any mode) into a PNG and an SVG of the same stem with gnuplot
# (Debian package gnuplot-nox), in the conventions of docs/sweep.md.
# Usage: tools/plot-sweep.sh map.csv map.png      (writes map.png, map.svg and map.gp)
# Finds plinth-sweep as $PLINTH_SWEEP, on PATH, or in the build folders of this checkout.
set -euo pipefail

if [[ $# -ne 2 ]]; then
  echo "usage: $0 map.csv out.png" >&2
  exit 2
fi
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sweep=${PLINTH_SWEEP:-}
if [[ -z "$sweep" ]]; then
  sweep=$(command -v plinth-sweep || true)
fi
if [[ -z "$sweep" ]]; then
  for candidate in "$root"/build/*/sim/plinth-sweep; do
    if [[ -x "$candidate" ]]; then
      sweep=$candidate
      break
    fi
  done
fi
if [[ -z "$sweep" ]]; then
  echo "plot-sweep: plinth-sweep not found: build it (cmake --build --preset release) or set PLINTH_SWEEP" >&2
  exit 1
fi
exec "$sweep" plot "$1" --out "$2"
