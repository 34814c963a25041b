#!/usr/bin/env bash
# The README's second command, and what CI runs: install what is missing, then build and run
# every test twice, optimised (warnings as errors) and under ASan + UBSan, then the fuzzers'
# short runs (clang, docs/fuzzing.md). Each stage prints its wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
stage_start=$SECONDS
stage_done() { echo "== $1: $((SECONDS - stage_start)) s"; stage_start=$SECONDS; }
tools/install-deps.sh
stage_done "install"
# fuzz: the libFuzzer targets alone (clang), each run for a bounded number of executions.
for preset in release sanitize fuzz; do
  echo "== $preset: configure and build"
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
  stage_done "$preset build"
  echo "== $preset: test"
  ctest --preset "$preset"
  stage_done "$preset test"
done
echo "== all stages: ${SECONDS} s"
