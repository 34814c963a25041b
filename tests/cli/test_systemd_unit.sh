#!/usr/bin/env bash
# The systemd unit (firmware/linux/systemd/plinth-monitor.service) as systemd reads it:
# `systemd-analyze verify` with no complaint (unknown keys and bad values are only warnings
# there, so any output fails), the supervision and hardening the box relies on, and systemd's
# own exposure score. ExecStart is pointed at the built binary (verify checks it exists).
# Skips (77) without systemd-analyze.
# Usage: test_systemd_unit.sh PLINTH_MONITOR SOURCE_DIR
set -u
monitor=${1:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
src=${2:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
unit_src=$src/firmware/linux/systemd/plinth-monitor.service
if ! command -v systemd-analyze >/dev/null; then
  echo "skipped: no systemd-analyze (package systemd)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
unit=$tmp/plinth-monitor.service
sed "s#^ExecStart=/usr/local/bin/plinth-monitor #ExecStart=$monitor #" "$unit_src" >"$unit"

# shellcheck source=tests/cli/checks.sh
source "$src/tests/cli/checks.sh"

grep -q "^ExecStart=$monitor " "$unit"
check "ExecStart runs plinth-monitor (pointed at the build)" $?
out=$(systemd-analyze verify "$unit" 2>&1)
rc=$?
[ $rc -eq 0 ] && [ -z "$out" ]
check "systemd-analyze verify: no complaint" $? "exit $rc: $out"

setting() { grep -Eq "^$1\$" "$unit"; }
for want in 'Type=notify' 'NotifyAccess=main' 'WatchdogSec=[0-9]+s' 'Restart=(always|on-failure)' \
  'User=plinth' 'NoNewPrivileges=yes' 'ProtectSystem=strict' \
  'ReadWritePaths=/var/lib/plinth-monitor' 'CapabilityBoundingSet=' 'DevicePolicy=closed' \
  'RestrictAddressFamilies=AF_CAN AF_UNIX AF_NETLINK AF_INET AF_INET6'; do
  setting "$want"
  check "$want" $?
done
# The event recorder writes inside the one writable folder.
record_dir=$(sed -n 's/.*--record-dir \([^ ]*\).*/\1/p' "$unit")
case "$record_dir" in /var/lib/plinth-monitor/*) r=0 ;; *) r=1 ;; esac
check "--record-dir is under ReadWritePaths" $r "$record_dir"

# systemd's exposure score (0 safest .. 10): at most 2.5 ("OK").
report=$(systemd-analyze security --offline=true "$unit" 2>&1)
score=$(printf '%s\n' "$report" | sed -n 's/.*Overall exposure level for .*: \([0-9.]*\) .*/\1/p')
awk -v s="$score" 'BEGIN { exit !(s != "" && s <= 2.5) }'
check "systemd-analyze security: exposure ${score:-?} <= 2.5" $? "$(printf '%s\n' "$report" | tail -3)"

finish
