#!/usr/bin/env bash
# The Debian packages (cmake/packaging.cmake; docs/install.md) as dpkg sees them: CPack builds
# them from this build tree (as the package preset does from its own), then
#   - each package's control fields (name, version, architecture, Depends), plinth-monitor's
#     conffiles (/etc/plinth/box.toml) and its files (programs, units naming /usr/bin and /etc,
#     the user, the data);
#   - Depends against dpkg-shlibdeps on the packaged programs (no shared library left out) and
#     against tools/install-deps.sh --runtime (the box's package list says the same);
#   - dpkg installs all three into a temporary root (dpkg --root, the maintainer scripts run
#     outside a chroot with DPKG_ROOT: --force-script-chrootless; --force-depends, the root has
#     no other package): files in place, the user plinth made by the postinst, the conffile
#     registered; a reinstall (an upgrade's path) keeps an edited box.toml; a removal keeps
#     it, a purge removes it, and neither touches the captures in /var/lib/plinth-monitor.
# The machine's own dpkg database and files are not touched.
# Usage: test_package.sh BUILD_DIR SOURCE_DIR [CPACK]
set -u
build=$(cd "${1:?usage: $0 BUILD_DIR SOURCE_DIR [CPACK]}" && pwd)
src=$(cd "${2:?usage: $0 BUILD_DIR SOURCE_DIR [CPACK]}" && pwd)
cpack=${3:-cpack}
# shellcheck source=tests/cli/checks.sh
source "$src/tests/cli/checks.sh"
for tool in dpkg dpkg-deb dpkg-shlibdeps systemd-sysusers; do
  if ! command -v "$tool" >/dev/null; then
    echo "skipped: $tool not found (tools/install-deps.sh installs dpkg-dev and systemd)"
    exit 77
  fi
done
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
version=$(sed -n 's/^set(CPACK_PACKAGE_VERSION "\(.*\)")$/\1/p' "$build/CPackConfig.cmake")
arch=$(sed -n 's/^set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE "\(.*\)")$/\1/p' "$build/CPackConfig.cmake")

(cd "$build" && "$cpack" -G DEB -B "$tmp/out") >"$tmp/cpack.log" 2>&1
check "cpack -G DEB" $? "$(tail -5 "$tmp/cpack.log")"
deb() { echo "$tmp/out/${1}_${version}_${arch}.deb"; }
for p in plinth-monitor plinth-tools libplinth-dev; do
  [ -s "$(deb "$p")" ]
  check "built $(basename "$(deb "$p")")" $? "$(ls "$tmp/out")"
done
field() { dpkg-deb -f "$(deb "$1")" "$2"; }

# Control fields.
[ "$(field plinth-monitor Package)" = plinth-monitor ] &&
  [ "$(field plinth-monitor Version)" = "$version" ] &&
  [ "$(field plinth-monitor Architecture)" = "$(dpkg --print-architecture)" ]
check "plinth-monitor: Package, Version $version, Architecture $arch" $? \
  "$(dpkg-deb -f "$(deb plinth-monitor)")"
for dep in libmosquitto1 libgpiod2 libsystemd0 libtomlplusplus3 systemd; do
  field plinth-monitor Depends | tr ',' '\n' | grep -q "^ *$dep\b"
  check "plinth-monitor Depends: $dep" $? "$(field plinth-monitor Depends)"
done
field plinth-tools Depends | grep -q "plinth-monitor (= $version)" &&
  field plinth-tools Depends | grep -q "gnuplot-nox" &&
  field libplinth-dev Depends | grep -q "libeigen3-dev"
check "plinth-tools needs plinth-monitor $version and gnuplot; libplinth-dev needs Eigen" $? \
  "$(field plinth-tools Depends); $(field libplinth-dev Depends)"
dpkg-deb -e "$(deb plinth-monitor)" "$tmp/control"
[ "$(cat "$tmp/control/conffiles")" = /etc/plinth/box.toml ] &&
  [ -x "$tmp/control/postinst" ] && [ -x "$tmp/control/prerm" ] && [ -x "$tmp/control/postrm" ]
check "plinth-monitor: conffiles /etc/plinth/box.toml, postinst, prerm, postrm" $? \
  "$(ls -l "$tmp/control")"

# Files.
dpkg-deb -x "$(deb plinth-monitor)" "$tmp/x-monitor"
dpkg-deb -x "$(deb plinth-tools)" "$tmp/x-tools"
dpkg-deb -x "$(deb libplinth-dev)" "$tmp/x-dev"
missing=""
for f in x-monitor/usr/bin/plinth-monitor x-monitor/usr/bin/plinth-replay \
  x-monitor/usr/bin/plinth-commission \
  x-monitor/etc/plinth/box.toml x-monitor/usr/lib/systemd/system/plinth-monitor@.service \
  x-monitor/usr/lib/systemd/system/plinth-monitor@.socket \
  x-monitor/usr/lib/sysusers.d/plinth-monitor.conf x-monitor/usr/lib/udev/rules.d/60-plinth-gpio.rules \
  x-monitor/usr/share/plinth/plinth.dbc x-monitor/usr/share/plinth/scenes/paper-eccentric.toml \
  x-monitor/usr/share/doc/plinth-monitor/copyright \
  x-tools/usr/bin/plinth-sim x-tools/usr/bin/plinth-event-plot x-tools/usr/share/plinth/event-plot.gp \
  x-tools/usr/share/plinth/records/SOURCES.md x-dev/usr/include/plinth/core/simulator.h; do
  [ -e "$tmp/$f" ] || missing+=" $f"
done
[ -z "$missing" ]
check "the packages' files" $? "missing:$missing"
unit=$tmp/x-monitor/usr/lib/systemd/system/plinth-monitor@.service
grep -q '^ExecStart=/usr/bin/plinth-monitor ' "$unit" &&
  grep -q '^Environment=PLINTH_BOX=/etc/plinth/box.toml$' "$unit"
check "the packaged unit runs /usr/bin/plinth-monitor with /etc/plinth/box.toml" $? \
  "$(grep -E '^(ExecStart|Environment)=' "$unit")"
found=$(grep -rlF "$src" "$tmp"/x-* | tr '\n' ' ')
[ -z "$found" ]
check "no packaged file names the source tree" $? "$found"

# Depends against what the programs link (dpkg-shlibdeps reads debian/control).
names() { tr ',|' '\n\n' | sed 's/(.*//; s/ //g' | grep -v '^$' | sort -u; }
mkdir -p "$tmp/shlibs/debian"
printf 'Source: plinth\n\nPackage: plinth\nArchitecture: any\n' >"$tmp/shlibs/debian/control"
for pkg in monitor tools; do
  bins=()
  for b in "$tmp/x-$pkg"/usr/bin/*; do
    [ "$(head -c 4 "$b" | tr -d '\177')" = ELF ] && bins+=("$b")
  done
  linked=$(cd "$tmp/shlibs" && dpkg-shlibdeps -O "${bins[@]}" 2>"$tmp/shlibdeps.err" |
           sed 's/^shlibs:Depends=//' | names)
  declared=$(field "$( [ $pkg = monitor ] && echo plinth-monitor || echo plinth-tools)" Depends | names)
  left_out=$(comm -23 <(echo "$linked") <(echo "$declared") | tr '\n' ' ')
  [ -n "$linked" ] && [ -z "$left_out" ]
  check "plinth-$pkg Depends covers dpkg-shlibdeps ($(echo "$linked" | tr '\n' ' '))" $? \
    "left out: $left_out $(head -c 200 "$tmp/shlibdeps.err")"
done
# ... and against install-deps.sh --runtime (less the C and C++ runtime every Debian has).
declared=$( (field plinth-monitor Depends; echo ','; field plinth-tools Depends) | names |
           grep -vxE 'libc6|libgcc-s1|libstdc\+\+6|plinth-monitor|gnuplot')
runtime=$(bash "$src/tools/install-deps.sh" --runtime --list | sort -u)
[ "$declared" = "$runtime" ]
check "Depends = tools/install-deps.sh --runtime" $? \
  "Depends: $(echo "$declared" | tr '\n' ' '); --runtime: $(echo "$runtime" | tr '\n' ' ')"

# dpkg into a temporary root.
root=$tmp/root
mkdir -p "$root/var/lib/dpkg/info" "$root/var/lib/dpkg/updates" "$root/etc"
touch "$root/var/lib/dpkg/status" "$root/var/lib/dpkg/available"
rdpkg() { dpkg --root="$root" --force-script-chrootless --force-depends "$@"; }
rdpkg -i "$(deb plinth-monitor)" "$(deb plinth-tools)" "$(deb libplinth-dev)" >"$tmp/dpkg.log" 2>&1
check "dpkg --root -i the three packages" $? "$(tail -5 "$tmp/dpkg.log")"
status=$(dpkg-query --admindir="$root/var/lib/dpkg" -W -f='${Package} ${Status}\n' | sort | tr '\n' ';')
[ "$status" = "libplinth-dev install ok installed;plinth-monitor install ok installed;plinth-tools install ok installed;" ]
check "dpkg: all three installed" $? "$status"
"$root/usr/bin/plinth-monitor" --version | grep -q "^plinth-monitor $version "
check "the installed plinth-monitor runs" $? "$("$root/usr/bin/plinth-monitor" --version 2>&1)"
grep -q '^plinth:x:[0-9]*:[0-9]*:.*:/var/lib/plinth-monitor:' "$root/etc/passwd" 2>/dev/null &&
  grep -q '^plinth:' "$root/etc/group"
check "postinst: user and group plinth (systemd-sysusers)" $? "$(cat "$root/etc/passwd" 2>&1)"
conffiles=$(dpkg-query --admindir="$root/var/lib/dpkg" -W -f='${Conffiles}' plinth-monitor)
echo "$conffiles" | grep -q "^ /etc/plinth/box.toml [0-9a-f]\{32\}$"
check "dpkg registered the conffile /etc/plinth/box.toml" $? "$conffiles"
# An edited box.toml survives a reinstall (postinst configure with the old version).
echo "# edited on site" >>"$root/etc/plinth/box.toml"
mkdir -p "$root/var/lib/plinth-monitor/can0/events"
echo capture >"$root/var/lib/plinth-monitor/can0/events/event-001.log"
rdpkg --force-confold -i "$(deb plinth-monitor)" >"$tmp/dpkg2.log" 2>&1 &&
  tail -1 "$root/etc/plinth/box.toml" | grep -q "edited on site"
check "reinstall keeps the edited /etc/plinth/box.toml" $? "$(tail -3 "$tmp/dpkg2.log")"
rdpkg -r plinth-tools libplinth-dev plinth-monitor >"$tmp/dpkg3.log" 2>&1 &&
  [ ! -e "$root/usr/bin/plinth-monitor" ] && [ -e "$root/etc/plinth/box.toml" ]
check "remove: programs gone, configuration kept" $? "$(tail -3 "$tmp/dpkg3.log")"
rdpkg -P plinth-monitor >"$tmp/dpkg4.log" 2>&1 && [ ! -e "$root/etc/plinth/box.toml" ] &&
  [ -s "$root/var/lib/plinth-monitor/can0/events/event-001.log" ]
check "purge: configuration gone, the captures kept" $? "$(tail -3 "$tmp/dpkg4.log")"

finish
