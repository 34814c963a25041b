#!/usr/bin/env bash
# The configure step refuses a libgpiod it does not support (firmware/linux/CMakeLists.txt):
# a libgpiod.pc of version 2.1.0 put first on PKG_CONFIG_PATH (the API libgpiod 2 changed) stops
# cmake with a message naming the version found and the versions supported; the same stand-in
# at 1.6.3, Debian 12's, configures.
# Usage: test_configure_gpiod.sh SOURCE_DIR [CMAKE]
set -u
src=${1:?usage: $0 SOURCE_DIR [CMAKE]}
cmake=${2:-cmake}
# shellcheck source=tests/cli/checks.sh
source "$src/tests/cli/checks.sh"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
real=$(pkg-config --variable=libdir libgpiod 2>/dev/null)
[ -n "$real" ] || { echo "skipped: no libgpiod.pc (libgpiod-dev)"; exit 77; }
# stand_in VERSION: a libgpiod.pc of that version over the real library.
stand_in() {
  mkdir -p "$tmp/pc-$1"
  sed "s/^Version:.*/Version: $1/" "$(pkg-config --variable=pcfiledir libgpiod)/libgpiod.pc" \
    >"$tmp/pc-$1/libgpiod.pc"
}
configure() {
  PKG_CONFIG_PATH="$tmp/pc-$1" "$cmake" -S "$src" -B "$tmp/build-$1" -G Ninja \
    -DPLINTH_BUILD_TESTS=OFF -DPLINTH_BUILD_BENCHMARKS=OFF >"$tmp/out-$1" 2>&1
}
stand_in 2.1.0
configure 2.1.0
rc=$?
[ $rc -ne 0 ] && grep -q "libgpiod 2.1.0" "$tmp/out-2.1.0" &&
  grep -q "need libgpiod 1.6 or a later 1.x" "$tmp/out-2.1.0"
check "libgpiod 2.1.0 refused at configure, the versions named" $? \
  "exit $rc: $(grep -A3 'CMake Error' "$tmp/out-2.1.0" | head -5)"
stand_in 1.6.3
configure 1.6.3
check "libgpiod 1.6.3 configures" $? "$(grep -A3 'CMake Error' "$tmp/out-1.6.3" | head -5)"
finish
