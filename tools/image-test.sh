#!/usr/bin/env bash
# The box's disk image built and booted under its own systemd in QEMU (docs/image.md): the
# plinth packages from a build tree (cpack) or a folder, the image from them
# (firmware/image/build-image.sh), then tests/integration/image_vm.py's sequence on it.
#
# Usage: tools/image-test.sh [options]
#   --arch A          amd64 (default) or arm64
#   --sequence S      short (default: the first boot, boot to monitoring, a replayed alarm in
#                     systemctl status and the journal, Modbus from the host) or full (also the
#                     interface coming back, the watchdog, a power cut mid-capture, an upgrade,
#                     removal and purge; about 11 min under TCG)
#   --build-dir DIR   a build tree whose packages cpack makes (default build/package-ARCH, the
#                     package / package-arm64 preset's, or else that preset configured and built
#                     in WORK/package-build); full: the newer packages too, the same with the
#                     Debian revision 2 (0.1.0-2)
#   --debs DIR        take the packages from DIR instead (full: and DIR/newer/ the newer ones)
#   --cpack CPACK     the cpack program (default cpack)
#   --work DIR        the image, the guest's disk and logs (default build/image-test-ARCH)
#   --cache DIR       build-image.sh --cache (default ${PLINTH_CACHE_DIR:-~/.cache/plinth}/image:
#                     the downloaded .debs and the Debian base, kept between runs)
# Exit status: 0 passed, 1 failed, 77 cannot run here (not root, a tool missing: the reason is
# printed; with CI=true 1 instead: CI must run it).
set -euo pipefail
me=image-test
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
arch=amd64 sequence=short build_dir="" debs="" cpack=cpack work="" cache=""
usage() {
  sed -n '/^# Usage:/,/^# Exit status/p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --arch) arch=${2:-}; shift 2 ;;
    --sequence) sequence=${2:-}; shift 2 ;;
    --build-dir) build_dir=${2:-}; shift 2 ;;
    --debs) debs=${2:-}; shift 2 ;;
    --cpack) cpack=${2:-}; shift 2 ;;
    --work) work=${2:-}; shift 2 ;;
    --cache) cache=${2:-}; shift 2 ;;
    *) usage ;;
  esac
done
case "$arch" in amd64 | arm64) ;; *) usage ;; esac
case "$sequence" in short | full) ;; *) usage ;; esac
work=${work:-$src/build/image-test-$arch}
cache=${cache:-${PLINTH_CACHE_DIR:-$HOME/.cache/plinth}/image}
skip() {
  echo "$me: cannot run here: $*" >&2
  if [ "${CI:-}" = true ]; then
    echo "$me: CI=true: the image's boot test must run in CI, failing" >&2
    exit 1
  fi
  exit 77
}
[ "$(id -u)" -eq 0 ] || skip "needs root (build-image.sh: mmdebstrap's root mode)"
mkdir -p "$work"
work=$(cd "$work" && pwd)
start=$SECONDS
lap() { echo "$me: [$((SECONDS - start)) s] $*"; }

# The packages.
if [ -z "$debs" ]; then
  preset=package$([ "$arch" = amd64 ] || echo -arm64)
  if [ -z "$build_dir" ]; then
    # The preset's own tree if it was built (cmake --workflow --preset ...), else one here.
    build_dir=$src/build/package-$arch
    if [ ! -f "$build_dir/CPackConfig.cmake" ]; then
      build_dir=$work/package-build
      lap "the packages' build (cmake --preset $preset in $build_dir; $work/package-build.log)"
      { cmake --preset "$preset" -S "$src" -B "$build_dir" &&
        cmake --build "$build_dir" --target plinth-monitor-component; } \
        >"$work/package-build.log" 2>&1 ||
        { tail -n 30 "$work/package-build.log"; echo "$me: the packages' build failed" >&2
          exit 1; }
    fi
  fi
  [ -f "$build_dir/CPackConfig.cmake" ] || skip "no build tree $build_dir"
  debs=$work/debs
  rm -rf "$debs"
  # The image holds plinth-monitor alone: its component is all cpack needs built.
  monitor_only=(-D CPACK_COMPONENTS_ALL=monitor)
  lap "the packages (cpack in $build_dir)"
  (cd "$build_dir" && "$cpack" -G DEB -B "$debs" "${monitor_only[@]}") >"$work/cpack.log" 2>&1 ||
    { tail -n 20 "$work/cpack.log"; echo "$me: cpack failed ($work/cpack.log)" >&2; exit 1; }
  if [ "$sequence" = full ]; then
    (cd "$build_dir" && "$cpack" -G DEB -B "$debs/newer" "${monitor_only[@]}" \
      -D CPACK_DEBIAN_PACKAGE_RELEASE=2) >>"$work/cpack.log" 2>&1 ||
      { tail -n 20 "$work/cpack.log"; echo "$me: cpack (revision 2) failed" >&2; exit 1; }
  fi
fi

# The image.
image=$work/plinth-box-$arch.img
lap "the image (firmware/image/build-image.sh; $work/build-image.log)"
status=0
"$src/firmware/image/build-image.sh" --arch "$arch" --debs "$debs" --out "$image" \
  --cache "$cache" >"$work/build-image.log" 2>&1 || status=$?
cat "$work/build-image.log"
[ "$status" -ne 77 ] || skip "build-image.sh cannot build here (above)"
[ "$status" -eq 0 ] || { echo "$me: the image's build failed" >&2; exit 1; }

# The guest.
lap "the $sequence sequence (tests/integration/image_vm.py)"
vm=(python3 "$src/tests/integration/image_vm.py" --image "$image" --work "$work/vm"
  --arch "$arch" --sequence "$sequence")
[ "$sequence" = short ] || vm+=(--newer-debs "$debs/newer")
status=0
"${vm[@]}" || status=$?
[ "$status" -ne 77 ] || skip "image_vm.py cannot run here (above)"
lap "done, status $status"
exit "$status"
