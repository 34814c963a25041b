#!/usr/bin/env bash
# The README's second command, and what CI runs: install what is missing, then build and run
# every test twice, optimised (warnings as errors) and under ASan + UBSan, then the fuzzers'
# short runs (clang, docs/fuzzing.md).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/install-deps.sh
# fuzz: the libFuzzer targets alone (clang), each run for a bounded number of executions.
for preset in release sanitize fuzz; do
  echo "== $preset: configure and build"
  cmake --preset "$preset" >/dev/null
  cmake --build --preset "$preset"
  echo "== $preset: test"
  ctest --preset "$preset"
done
