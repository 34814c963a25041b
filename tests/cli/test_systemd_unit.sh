#!/usr/bin/env bash
# The systemd units (firmware/linux/systemd/plinth-monitor@.service and plinth-monitor@.socket)
# as systemd reads them, for the instance plinth-monitor@can0: `systemd-analyze verify` with no
# complaint (unknown keys and bad values are only warnings there, so any output fails), the
# binding to the interface's device, the supervision and hardening the box relies on, and
# systemd's own exposure score, which must not rise above 1.7 (1.9 before the template unit).
# Then socket activation as the socket unit does it (docs/install.md): in a private network
# namespace, systemd-socket-activate binds port 502 and passes the socket named "modbus" to
# plinth-monitor run as nobody without any capability, which serves mbpoll on it; without the
# socket the same user cannot bind the port, and a socket on another port than box.toml's is
# refused with both named. The units' @PLINTH_BINDIR@ is pointed at the build.
# Skips (77) without systemd-analyze; the socket part skips without a network namespace.
# Usage: test_systemd_unit.sh PLINTH_MONITOR SOURCE_DIR
set -u
monitor=${1:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
src=${2:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
monitor=$(cd "$(dirname "$monitor")" && pwd)/$(basename "$monitor")
units=$src/firmware/linux/systemd
if ! command -v systemd-analyze >/dev/null; then
  echo "skipped: no systemd-analyze (package systemd)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for u in plinth-monitor@.service plinth-monitor@.socket; do
  sed -e "s#@PLINTH_BINDIR@#$(dirname "$monitor")#g" -e "s#@PLINTH_SYSCONFDIR@#$tmp/etc#g" \
    "$units/$u" >"$tmp/$u"
done
unit=$tmp/plinth-monitor@.service
socket_unit=$tmp/plinth-monitor@.socket

# shellcheck source=tests/cli/checks.sh
source "$src/tests/cli/checks.sh"

grep -q "^ExecStart=$monitor " "$unit"
check "ExecStart runs plinth-monitor (pointed at the build)" $? "$(grep ExecStart "$unit")"
for instance in "plinth-monitor@can0.service" "plinth-monitor@can0.socket"; do
  out=$(cd "$tmp" && systemd-analyze verify "$tmp/$instance" 2>&1)
  rc=$?
  [ $rc -eq 0 ] && [ -z "$out" ]
  check "systemd-analyze verify $instance: no complaint" $? "exit $rc: $out"
done

# A setting, continuation lines joined.
setting() { sed -e ':a' -e '/\\$/N; s/\\\n *//; ta' "$2" | grep -Eq "^$1\$"; }
for want in 'Type=notify' 'NotifyAccess=main' 'WatchdogSec=[0-9]+s' 'Restart=(always|on-failure)' \
  'BindsTo=sys-subsystem-net-devices-%i.device' 'After=sys-subsystem-net-devices-%i.device .*' \
  'ExecStart=.* --can %i .*' 'StateDirectory=plinth-monitor/%i' \
  'User=plinth' 'NoNewPrivileges=yes' 'ProtectSystem=strict' \
  'ReadWritePaths=/var/lib/plinth-monitor/%i' 'CapabilityBoundingSet=' 'AmbientCapabilities=' \
  'DevicePolicy=closed' 'RestrictAddressFamilies=AF_CAN AF_UNIX AF_NETLINK AF_INET AF_INET6' \
  'CPUSchedulingPolicy=fifo' 'CPUSchedulingResetOnFork=yes' 'RestrictRealtime=yes' \
  'WantedBy=multi-user.target sys-subsystem-net-devices-%i.device'; do
  setting "$want" "$unit"
  check "service: $want" $?
done
for want in 'ListenStream=502' 'FileDescriptorName=modbus' 'Service=plinth-monitor@%i.service'; do
  setting "$want" "$socket_unit"
  check "socket: $want" $?
done
# The event recorder writes inside the one writable folder.
record_dir=$(sed -n 's/.*--record-dir \([^ ]*\).*/\1/p' "$unit")
case "$record_dir" in /var/lib/plinth-monitor/%i/*) r=0 ;; *) r=1 ;; esac
check "--record-dir is under ReadWritePaths" $r "$record_dir"

# systemd's exposure score (0 safest .. 10): 1.9 for the single unit this template replaced,
# 1.7 now (PrivateMounts=yes); it must not rise.
report=$(cd "$tmp" && systemd-analyze security --offline=true "$tmp/plinth-monitor@can0.service" 2>&1)
score=$(printf '%s\n' "$report" | sed -n 's/.*Overall exposure level for .*: \([0-9.]*\) .*/\1/p')
awk -v s="$score" 'BEGIN { exit !(s != "" && s <= 1.7) }'
check "systemd-analyze security: exposure ${score:-?} <= 1.7" $? "$(printf '%s\n' "$report" | tail -3)"

# Socket activation: Modbus on port 502 without privileges.
if ! unshare -n true 2>/dev/null || ! command -v systemd-socket-activate >/dev/null ||
  ! command -v mbpoll >/dev/null || ! command -v setpriv >/dev/null; then
  echo "# socket activation part skipped: needs unshare -n (root), systemd-socket-activate," \
       "mbpoll, setpriv"
  finish
  exit
fi
# nobody reads and runs copies in a folder of its own (the trees may lie under a private folder).
box_dir=$(mktemp -d /tmp/plinth-socket-test.XXXXXX)
trap 'rm -rf "$tmp" "$box_dir"' EXIT
printf '[modbus]\nlisten = "127.0.0.1:502"\n' >"$box_dir/box.toml"
cp "$monitor" "$box_dir/plinth-monitor"
cp "$src/sim/scenes/paper-eccentric.toml" "$src/sim/data/records/friuli1976-09-15_buia_000.AT2" \
  "$box_dir/"
chmod 755 "$box_dir" "$box_dir/plinth-monitor"
chmod 644 "$box_dir/box.toml" "$box_dir/paper-eccentric.toml" \
  "$box_dir/friuli1976-09-15_buia_000.AT2"
unprivileged=(setpriv --reuid=65534 --regid=65534 --clear-groups --inh-caps=-all
              --bounding-set=-all --)
run_box=("$box_dir/plinth-monitor" --scene "$box_dir/paper-eccentric.toml"
         --replay "$box_dir/friuli1976-09-15_buia_000.AT2" --scale 6.5 --speed 1
         --no-events --config "$box_dir/box.toml")
cat >"$tmp/activate.sh" <<'EOF'
tmp=$1 port=$2
shift 2
ip link set lo up || exit 90
systemd-socket-activate -l "127.0.0.1:$port" --fdname=modbus "$@" >"$tmp/box.out" 2>"$tmp/box.err" &
box=$!
for ((i = 0; i < 20; i++)); do
  mbpoll -m tcp -t 3 -0 -r 0 -c 32 -1 -p "$port" 127.0.0.1 >"$tmp/mbpoll.out" 2>&1 && break
  sleep 0.2
done
echo "user $(ps -o user= -p "$box")"
kill -TERM "$box" 2>/dev/null
wait "$box"
echo "exit $?"
EOF
unshare -n bash "$tmp/activate.sh" "$tmp" 502 "${unprivileged[@]}" "${run_box[@]}" >"$tmp/activate.out" 2>&1
grep -q '^\[31\]:' "$tmp/mbpoll.out" && grep -q '^user nobody$' "$tmp/activate.out" &&
  grep -q '^exit 0$' "$tmp/activate.out" &&
  tail -1 "$tmp/box.out" | grep -q '"modbus": {"listen": "127.0.0.1:502", .*"requests": [1-9]'
check "socket-activated on 502: plinth-monitor as nobody, no capability, answers mbpoll" $? \
  "$(tail -2 "$tmp/activate.out" | tr '\n' ' ') $(tail -3 "$tmp/mbpoll.out" | tr '\n' ' ') $(head -c 300 "$tmp/box.err")"
# The same user, no socket passed: the port is refused, as it would be under the unit without
# the socket unit.
unshare -n bash -c 'ip link set lo up && "$@"' _ "${unprivileged[@]}" "${run_box[@]}" \
  >/dev/null 2>"$tmp/bind.err"
rc=$?
[ $rc -eq 1 ] && grep -q 'cannot listen at 127.0.0.1:502: Permission denied' "$tmp/bind.err"
check "without the socket, nobody cannot bind 502 (the error says why)" $? \
  "exit $rc: $(head -c 300 "$tmp/bind.err")"
# A socket on another port than the configuration's: refused, both named.
unshare -n bash "$tmp/activate.sh" "$tmp" 1502 "${unprivileged[@]}" "${run_box[@]}" \
  >"$tmp/activate.out" 2>&1
grep -q "modbus.listen: the socket systemd passed as 'modbus' listens on port 1502, the configuration says 502" \
  "$tmp/box.err" && grep -q '^exit 1$' "$tmp/activate.out"
check "a socket on port 1502 against listen = 127.0.0.1:502: refused, both named" $? \
  "$(tail -1 "$tmp/activate.out") $(tail -2 "$tmp/box.err" | tr '\n' ' ')"

finish
