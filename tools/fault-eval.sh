#!/usr/bin/env bash
# The fault table of docs/safety.md ("Fault injection", "Results"): every single-fault class of
# issue 32 on the earthquakes the box's choices were not made on (sim/data/records/eval/), the
# three eval scenes, N true statues each, a PGA grid; each faulted run set against the
# fault-free box of the same cases (with the statue sensor for its faults, without for the
# ground's and for reset/restart), collapses only.
#
#   tools/fault-eval.sh [OUT_DIR] [STATUES] [PGA_STEPS]     (defaults: build/fault-eval 10 6)
#
# Environment: PLINTH_EVAL (default build/release/sim/plinth-eval), JOBS (default 2).
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-build/fault-eval}
statues=${2:-10}
steps=${3:-6}
eval_bin=${PLINTH_EVAL:-build/release/sim/plinth-eval}
jobs=${JOBS:-2}
mkdir -p "$out"
cases=(--scene sim/scenes/eval/ground-slender.toml --scene sim/scenes/eval/isolated.toml
  --scene sim/scenes/eval/isolated-stops.toml --record sim/data/records/eval/*.AT2
  --statues "$statues" --pga-from 0.2g --pga-to 2.5g --pga-steps "$steps" --jobs "$jobs")
run() { # NAME ARGS...: one runs file, its wall time said
  local name=$1 start
  shift
  start=$(date +%s)
  "$eval_bin" run "${cases[@]}" --out "$out/$name.csv" "$@" >"$out/$name.log" 2>&1
  echo "$name: $(($(date +%s) - start)) s"
}
# The fault-free boxes: every run (their collapses are the faulted runs' cases).
run base
run base-statue --statue-sensor
statue_faults=(statue_at_rest statue_stuck:@motion statue_gain:0.5 statue_gain:57.3
  statue_bias:2 statue_axes_swapped statue_sign:y statue_delay:0.1 statue_dropout:5:@motion
  statue_neighbour statue_on_plinth)
ground_faults=(ground_gain:x=0.5 ground_heading:90 ground_pair_primary:heading:90
  ground_pair_second:heading:90 reset:@alarm restart:@alarm)
for f in "${statue_faults[@]}" "${ground_faults[@]}"; do
  kind=${f%%:@*}
  at=start
  [[ "$f" == *:@* ]] && at=${f##*:@}
  name=$(echo "$kind" | tr ':=.' '___')
  if [[ "$kind" == statue_* ]]; then
    run "$name" --statue-sensor --fault "$kind" --fault-at "$at" --collapses-of "$out/base-statue.csv"
    against=$out/base-statue.csv
  else
    run "$name" --fault "$kind" --fault-at "$at" --collapses-of "$out/base.csv"
    against=$out/base.csv
  fi
  "$eval_bin" fault-report "$out/$name.csv" --against "$against" --json "$out/$name.json" \
    >"$out/$name.report" 2>&1 || echo "$name: fault-report failed (see $out/$name.report)"
  # The statue sensor's faults against the box without the sensor too (issue 32's target).
  if [[ "$kind" == statue_* ]]; then
    "$eval_bin" fault-report "$out/$name.csv" --against "$out/base.csv" \
      >"$out/$name.without-sensor.report" 2>&1 ||
      echo "$name: fault-report failed (see $out/$name.without-sensor.report)"
  fi
done
# The fault-free sensor against the box without it: the lead the sensor itself costs.
"$eval_bin" fault-report "$out/base-statue.csv" --against "$out/base.csv" \
  >"$out/base-statue.without-sensor.report" 2>&1 ||
  echo "base-statue: fault-report failed (see $out/base-statue.without-sensor.report)"
