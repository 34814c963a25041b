#!/usr/bin/env bash
# plinth installed (cmake --install into a temporary prefix) and run from there with the source
# and build trees out of reach: a private mount namespace lays an empty tmpfs over both, so a
# program that looked for its data in the checkout would fail (docs/install.md). Checked: no
# installed file names the source or build tree; every installed program answers --version with
# the build's version; plinth-monitor replays the quick start with the installed box.toml, example
# scene and record (its alarm timeline, a capture); plinth-event-plot draws that capture with the
# installed gnuplot script and the plinth-monitor beside it (PATH without the prefix);
# plinth-accuracy --quick runs on the installed scenes and records; plinth-sim on an installed
# scene; and a small project finds the freestanding core with find_package(plinth) and links it.
# Skips (77) where no mount namespace can be made (not root, or unshare refused).
# Usage: test_install.sh BUILD_DIR SOURCE_DIR [CMAKE [sanitized]]
#   sanitized: a build under ASan + UBSan, whose checks carry their source locations (file
#   names) in the programs: the search for source paths is left out; the hidden trees still show
#   that nothing reads from them.
set -u
build=$(cd "${1:?usage: $0 BUILD_DIR SOURCE_DIR [CMAKE]}" && pwd)
src=$(cd "${2:?usage: $0 BUILD_DIR SOURCE_DIR [CMAKE]}" && pwd)
cmake=${3:-cmake}
sanitized=${4:-}
# shellcheck source=tests/cli/checks.sh
source "$src/tests/cli/checks.sh"
if ! unshare -m true 2>/dev/null; then
  echo "skipped: cannot make a mount namespace here (unshare -m: needs root)"
  exit 77
fi
tmp=$(mktemp -d /tmp/plinth-install-test.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
case "$tmp/" in "$src/"* | "$build/"*) echo "temporary folder inside the tree: $tmp" >&2; exit 2 ;; esac
prefix=$tmp/prefix

"$cmake" --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1
check "cmake --install into $prefix" $? "$(tail -3 "$tmp/install.log")"
echo "# edited on site" >>"$prefix/etc/plinth/box.toml"
"$cmake" --install "$build" --prefix "$prefix" >"$tmp/install2.log" 2>&1 &&
  tail -1 "$prefix/etc/plinth/box.toml" | grep -q "edited on site"
check "a second cmake --install keeps the edited etc/plinth/box.toml" $? "$(grep -i box.toml "$tmp/install2.log")"
expected=$("$build/firmware/linux/plinth-monitor" --version)
expected=${expected#plinth-monitor }

# Layout.
for f in bin/plinth-monitor bin/plinth-replay bin/plinth-sim bin/plinth-sweep bin/plinth-eval \
  bin/plinth-accuracy bin/plinth-event-plot share/plinth/plinth.dbc share/plinth/event-plot.gp \
  share/plinth/examples/box.toml share/plinth/scenes/paper-eccentric.toml \
  share/plinth/records/friuli1976-09-15_buia_000.AT2 etc/plinth/box.toml \
  lib/systemd/system/plinth-monitor@.service lib/systemd/system/plinth-monitor@.socket \
  lib/sysusers.d/plinth-monitor.conf include/plinth/core/simulator.h; do
  [ -e "$prefix/$f" ]
  check "installed: $f" $? "missing"
done
# Debug information (the sanitize preset's -g1) names the sources by design: a program's or
# library's is looked at without it (objcopy --strip-debug).
if [ "$sanitized" = sanitized ]; then
  echo "# source paths not looked for: a sanitized build's checks carry their file names"
fi
found=""
while IFS= read -r f; do
  if objcopy --strip-debug "$f" "$tmp/stripped" 2>/dev/null; then
    grep -qF -e "$src" -e "$build" "$tmp/stripped" || continue
  fi
  found+=" ${f#"$prefix"/}"
done < <([ "$sanitized" = sanitized ] || grep -rlF -e "$src" -e "$build" "$prefix" 2>/dev/null)
[ -z "$found" ]
check "no installed file names the source or build tree (debug information aside)" $? "$found"
grep -q "^ExecStart=$prefix/bin/plinth-monitor --config \${PLINTH_BOX}" \
  "$prefix/lib/systemd/system/plinth-monitor@.service" &&
  grep -q "^Environment=PLINTH_BOX=$prefix/etc/plinth/box.toml" \
    "$prefix/lib/systemd/system/plinth-monitor@.service"
check "the unit names the install's plinth-monitor and box.toml" $? \
  "$(grep -E '^(ExecStart|Environment)=' "$prefix/lib/systemd/system/plinth-monitor@.service")"

# A project using the installed core (find_package(plinth) -> plinth::core).
mkdir -p "$tmp/consumer"
cat >"$tmp/consumer/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.25)
project(consumer LANGUAGES CXX)
set(CMAKE_CXX_STANDARD 20)
find_package(plinth 0.1 REQUIRED)
add_executable(consumer main.cpp)
target_link_libraries(consumer PRIVATE plinth::core)
EOF
cat >"$tmp/consumer/main.cpp" <<'EOF'
// The paper's corrected Eq 36 at xi = 0.2: the full-contact response peaks at 0.821 (closed_forms.h).
#include <cstdio>
#include "plinth/core/closed_forms.h"
#if !defined(PLINTH_MAX_ENSEMBLE_MEMBERS) || !defined(PLINTH_REAL_FLOAT)
#error "plinth::core's compile definitions did not come with it"
#endif
int main() {
  std::printf("%.3f %d\n", static_cast<double>(plinth::peak_acceleration_factor(0.2)),
              PLINTH_MAX_ENSEMBLE_MEMBERS);
}
EOF

# Everything below runs with the source and build trees hidden under empty tmpfs mounts.
cat >"$tmp/hidden.sh" <<'EOF'
set -u
prefix=$1 src=$2 build=$3 tmp=$4 cmake=$5
# The build tree first: it may lie inside the source tree.
mount -t tmpfs plinth-hidden "$build" && mount -t tmpfs plinth-hidden "$src" || exit 90
[ ! -e "$src/CMakeLists.txt" ] && [ ! -e "$build/CMakeCache.txt" ] || exit 91
export PATH=/usr/sbin:/usr/bin:/sbin:/bin
unset PLINTH_MONITOR PLINTH_SOURCE_DIR
cd "$tmp"
for p in plinth-monitor plinth-replay plinth-commission plinth-sim plinth-sweep plinth-eval \
  plinth-accuracy plinth-event-plot; do
  echo "version $p $("$prefix/bin/$p" --version 2>&1)"
done
share=$prefix/share/plinth
"$prefix/bin/plinth-monitor" --config "$prefix/etc/plinth/box.toml" \
  --scene "$share/scenes/paper-eccentric.toml" \
  --replay "$share/records/friuli1976-09-15_buia_000.AT2" --scale 6.5 \
  --record-dir "$tmp/captures" >"$tmp/monitor.jsonl" 2>"$tmp/monitor.err"
echo "monitor $?"
"$prefix/bin/plinth-event-plot" --scene "$share/scenes/paper-eccentric.toml" \
  "$tmp/captures/event-001.log" -- --stuck-samples 0 >"$tmp/plot.out" 2>&1
echo "plot $?"
"$prefix/bin/plinth-accuracy" --quick --out-dir "$tmp/accuracy" >"$tmp/accuracy.out" 2>&1
echo "accuracy $?"
"$prefix/bin/plinth-sim" --scene "$share/scenes/paper-isolated.toml" \
  --record "$share/records/irpinia1980_brienza_000.AT2" --scale 20 \
  --events "$tmp/sim.jsonl" >/dev/null 2>"$tmp/sim.err"
echo "sim $?"
"$cmake" -S "$tmp/consumer" -B "$tmp/consumer/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  "-DCMAKE_PREFIX_PATH=$prefix" >"$tmp/consumer.log" 2>&1 &&
  "$cmake" --build "$tmp/consumer/build" >>"$tmp/consumer.log" 2>&1 &&
  echo "consumer 0 $("$tmp/consumer/build/consumer")" || echo "consumer 1"
EOF
unshare -m bash "$tmp/hidden.sh" "$prefix" "$src" "$build" "$tmp" "$cmake" >"$tmp/hidden.out" 2>&1
rc=$?
[ $rc -eq 0 ] && [ -s "$tmp/hidden.out" ]
check "source and build trees hidden (tmpfs over both)" $? "exit $rc: $(tail -3 "$tmp/hidden.out")"
result() { sed -n "s/^$1 //p" "$tmp/hidden.out"; }

for p in plinth-monitor plinth-replay plinth-commission plinth-sim plinth-sweep plinth-eval \
  plinth-accuracy plinth-event-plot; do
  got=$(result "version $p")
  [ "$got" = "$p $expected" ]
  check "installed $p --version: $expected" $? "$got"
done
[ "$(result monitor)" = 0 ] && python3 - "$tmp/monitor.jsonl" <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
alarms = [(l["level"], l["cause"]) for l in lines if l["type"] == "alarm"]
levels = [level for level, _ in alarms]
# The start-up's fault changes its cause (no sample yet, then the conditioner's window): an
# event each (docs/safety.md).
assert alarms[:2] == [("fault", "sensor_timeout"), ("fault", "not_calibrated")], alarms
assert levels == ["fault", "fault", "normal", "advisory", "warning", "alarm"], levels
assert lines[-1]["final_phase"] == "overturned", lines[-1]
PY
check "installed plinth-monitor with etc/plinth/box.toml: the quick start's alarm timeline" $? \
  "$(result monitor): $(head -c 300 "$tmp/monitor.err")"
[ "$(result plot)" = 0 ] && [ -s "$tmp/captures/event-001.png" ]
check "installed plinth-event-plot draws the capture (its gnuplot script, its plinth-monitor)" $? \
  "$(head -c 300 "$tmp/plot.out")"
[ "$(result accuracy)" = 0 ]
check "installed plinth-accuracy --quick on the installed scenes and records" $? \
  "$(tail -c 300 "$tmp/accuracy.out")"
[ "$(result sim)" = 0 ] && grep -q rocking_start "$tmp/sim.jsonl"
check "installed plinth-sim on an installed scene and record" $? "$(head -c 300 "$tmp/sim.err")"
got=$(result consumer)
[ "$got" = "0 0.821 17" ]
check "find_package(plinth): plinth::core links, its definitions come with it" $? \
  "$got: $(tail -5 "$tmp/consumer.log")"

finish
