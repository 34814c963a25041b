#!/usr/bin/env bash
# The box built for arm64 (Debian's cross toolchain and arm64 libraries, preset package-arm64)
# against the box on this machine: cross-builds plinth-monitor alone, runs it under qemu-aarch64
# (qemu-user) on the quick start's replay (paper-eccentric.toml, Buia 1976 x6.5), runs this
# machine's plinth-monitor on the same, and checks the same alarm timeline (every alarm line:
# time, level, previous level, cause, latch, sequence) and the same phase events (names, axes,
# times within 1 µs), and that the arm64 build reports the same version (its git description is
# the reference's, given to its configure step). See docs/install.md.
#
# Usage: tools/arm64-replay.sh --monitor PLINTH_MONITOR --work DIR [--cmake CMAKE] [--launcher PROG]
#   --monitor   this machine's plinth-monitor (the reference)
#   --work DIR  the cross build tree and the runs' files (kept)
#   --launcher  compiler launcher for the cross build (e.g. ccache)
# Exit status: 0 the same, 1 a difference or a failed build or run, 2 usage, 77 the cross
# compiler, qemu-aarch64 or the arm64 libraries are missing (tools/install-deps.sh installs them).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
src=$(dirname "$here")
monitor="" work="" cmake=cmake launcher=""
usage() {
  echo "usage: $0 --monitor FILE --work DIR [--cmake CMAKE] [--launcher PROG]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --monitor) monitor=${2:-}; shift 2 ;;
    --work) work=${2:-}; shift 2 ;;
    --cmake) cmake=${2:-}; shift 2 ;;
    --launcher) launcher=${2:-}; shift 2 ;;
    *) usage ;;
  esac
done
[ -x "$monitor" ] && [ -n "$work" ] || usage
for tool in aarch64-linux-gnu-g++ qemu-aarch64; do
  if ! command -v "$tool" >/dev/null; then
    echo "skipped: $tool not found (tools/install-deps.sh installs g++-aarch64-linux-gnu and qemu-user)"
    exit 77
  fi
done
if ! PKG_CONFIG_LIBDIR=/usr/lib/aarch64-linux-gnu/pkgconfig pkg-config --exists libmosquitto; then
  echo "skipped: no arm64 libraries (tools/install-deps.sh installs libmosquitto-dev:arm64 and the rest)"
  exit 77
fi

mkdir -p "$work"
build=$work/build
# The cross build describes itself as the reference does (a commit made since the reference was
# built must not make them differ): the description in its --version's parentheses.
native_version=$("$monitor" --version)
description=${native_version##*(}
description=${description%)}
configure=("$cmake" --preset package-arm64 -S "$src" -B "$build"
           "-DPLINTH_GIT_DESCRIPTION=$description")
[ -z "$launcher" ] || configure+=("-DCMAKE_CXX_COMPILER_LAUNCHER=$launcher")
start=$SECONDS
(cd "$src" && "${configure[@]}") >"$work/configure.log" 2>&1 ||
  { tail -n 30 "$work/configure.log"; echo "arm64-replay: configure failed ($work/configure.log)"; exit 1; }
"$cmake" --build "$build" --target plinth-monitor >"$work/build.log" 2>&1 ||
  { tail -n 30 "$work/build.log"; echo "arm64-replay: build failed ($work/build.log)"; exit 1; }
echo "arm64-replay: plinth-monitor cross-built for arm64 in $((SECONDS - start)) s"
arm64=$build/firmware/linux/plinth-monitor
file_type=$(head -c 20 "$arm64" | od -An -tx1 | tr -d ' \n')
# ELF, 64-bit, little-endian, e_machine 0xb7 (AArch64) at bytes 18-19.
[ "${file_type:0:8}" = 7f454c46 ] && [ "${file_type:36:4}" = b700 ] ||
  { echo "arm64-replay: $arm64 is not an AArch64 ELF file ($file_type)"; exit 1; }

replay=(--scene "$src/sim/scenes/paper-eccentric.toml"
        --replay "$src/sim/data/records/friuli1976-09-15_buia_000.AT2" --scale 6.5)
"$monitor" "${replay[@]}" >"$work/amd64.jsonl"
start=$SECONDS
qemu-aarch64 -L /usr/aarch64-linux-gnu "$arm64" "${replay[@]}" >"$work/arm64.jsonl" \
  2>"$work/arm64.err" || { cat "$work/arm64.err"; echo "arm64-replay: the arm64 run failed"; exit 1; }
echo "arm64-replay: qemu-aarch64 ran the replay in $((SECONDS - start)) s"
arm_version=$(qemu-aarch64 -L /usr/aarch64-linux-gnu "$arm64" --version)

python3 - "$work/amd64.jsonl" "$work/arm64.jsonl" "$native_version" "$arm_version" <<'PY'
import json, sys
def lines(path, kind):
    return [json.loads(l) for l in open(path) if l.startswith('{"type": "%s"' % kind)]
native, arm = sys.argv[1], sys.argv[2]
failed = 0
def check(ok, what):
    global failed
    print(("ok - " if ok else "not ok - ") + what)
    failed += not ok
a, b = lines(native, "alarm"), lines(arm, "alarm")
check(a == b and len(a) >= 4, "the same alarm timeline: %s" % [(x["t"], x["level"]) for x in b])
ea, eb = lines(native, "event"), lines(arm, "event")
same = len(ea) == len(eb) and all(
    x["event"] == y["event"] and x["axis"] == y["axis"] and abs(x["t"] - y["t"]) < 1e-6
    for x, y in zip(ea, eb))
check(same and ea, "the same phase events: %s" % [(y["t"], y["event"]) for y in eb])
sa, sb = lines(native, "summary")[0], lines(arm, "summary")[0]
check(sa["final_phase"] == sb["final_phase"] == "overturned",
      "both end overturned: %s, %s" % (sa["final_phase"], sb["final_phase"]))
check(sys.argv[3] == sys.argv[4], "the same version: %s / %s" % (sys.argv[3], sys.argv[4]))
print("%d passed, %d failed" % (4 - failed, failed))
sys.exit(1 if failed else 0)
PY
