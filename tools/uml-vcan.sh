#!/usr/bin/env bash
# Runs a command on a real SocketCAN bus: boots Debian's user-mode Linux kernel (linux.uml, an
# ordinary process) on the host's root filesystem through hostfs, loads the CAN modules, brings
# up vcan0 (and vcan1, ... with --vcan N), runs the command as the guest's workload in the same
# directory with the same exported environment, powers off, and exits with the command's status.
# The host kernel needs no CAN support. See hal/README.md.
#
# Usage: tools/uml-vcan.sh [options] [--] PROGRAM [ARG...]
#        tools/uml-vcan.sh [options] -c 'SHELL COMMAND LINE'
# Options:
#   --vcan N        interfaces vcan0..vcanN-1 (default 1)
#   --timeout S     host-side limit for the whole run, boot included (default 60)
#   --mem SIZE      guest memory (default 256M)
#   --out DIR       also keep the run's files there: status, stdout, stderr, console.log
# Example: tools/uml-vcan.sh --vcan 2 build/release/tests/test_socketcan
# Exit status: the command's; 77 when user-mode Linux cannot start here (not installed, cannot
# boot: ctest's SKIP_RETURN_CODE); 124 when the time ran out; 125 when the guest could not set up
# the bus or the harness was misused.
set -euo pipefail

me=uml-vcan
vcan_count=1
timeout_s=60
mem=256M
out_dir=""
shell_line=""

usage() {
  sed -n '/^# Usage:/,/^# the bus or the harness/p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 125
}

while [ $# -gt 0 ]; do
  case "$1" in
    --vcan) vcan_count=${2:?}; shift 2 ;;
    --timeout) timeout_s=${2:?}; shift 2 ;;
    --mem) mem=${2:?}; shift 2 ;;
    --out) out_dir=${2:?}; shift 2 ;;
    -c) shell_line=${2:?}; shift 2 ;;
    -h | --help) usage ;;
    --) shift; break ;;
    -*) echo "$me: unknown option $1" >&2; usage ;;
    *) break ;;
  esac
done
if [ -z "$shell_line" ] && [ $# -eq 0 ]; then usage; fi
case "$vcan_count" in '' | *[!0-9]*) echo "$me: --vcan wants a number" >&2; exit 125 ;; esac

cannot_start() {
  echo "$me: user-mode Linux cannot start here: $*" >&2
  exit 77
}
console_tail() { tail -n 5 "$run_dir/console.log" 2>/dev/null | tr '\n' ' '; }
timed_out() { [ "$uml_status" -eq 124 ] || [ "$uml_status" -eq 137 ]; }

# --- What the guest needs on the host -------------------------------------------------------
kernel=${UML_VCAN_KERNEL:-/usr/bin/linux.uml}  # the override is for testing this script
[ -x "$kernel" ] || cannot_start "$kernel not found (install the package user-mode-linux)"
vcan_modules=(/usr/lib/uml/modules/*/kernel/drivers/net/can/vcan.ko)
[ -e "${vcan_modules[0]}" ] ||
  cannot_start "no vcan.ko under /usr/lib/uml/modules (package user-mode-linux incomplete)"
for tool in insmod ip timeout; do
  PATH="$PATH:/usr/sbin:/sbin" command -v "$tool" >/dev/null ||
    cannot_start "$tool not found (install kmod, iproute2, coreutils: tools/install-deps.sh)"
done

# --- One private folder per run: several runs at once do not meet -----------------------------
run_dir=$(mktemp -d /tmp/uml-vcan.XXXXXX)  # /tmp: no spaces for the kernel command line, and
                                           # not /dev/shm, which the guest's devtmpfs hides
# shellcheck disable=SC2317  # run by the EXIT trap
cleanup() {
  if [ -n "$out_dir" ]; then
    mkdir -p "$out_dir"
    cp -f "$run_dir"/{status,stdout,stderr,console.log} "$out_dir"/ 2>/dev/null || true
  fi
  rm -rf "$run_dir"
}
trap cleanup EXIT

# The command, quoted for the guest's bash.
if [ -n "$shell_line" ]; then
  printf '%q ' bash -c "$shell_line" >"$run_dir/command"
else
  printf '%q ' "$@" >"$run_dir/command"
fi
# The exported environment, minus what belongs to this shell or this machine's session.
export -p | grep -Ev '^declare -x (BASH[A-Z_]*|SHELLOPTS|SHLVL|PWD|OLDPWD|_|TERM|TMPDIR)=' \
  >"$run_dir/environment" || true

cat >"$run_dir/init" <<EOF
#!/bin/bash
# PID 1 of the guest: set up the bus, run the command, always power off.
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
run=$(printf %q "$run_dir")
# Never returns. PATH: the command's environment may have replaced the one above.
finish() { sync; PATH=/usr/sbin:/sbin:\$PATH poweroff -f; echo o >/proc/sysrq-trigger; sleep 3600; }
setup_failed() { echo "\$*" >"\$run/setup-error"; finish; }
echo booted >"\$run/booted"
mount -t proc proc /proc && mount -t sysfs sysfs /sys || setup_failed "mount proc/sysfs failed"
mkdir -p /dev/shm && mount -t tmpfs tmpfs /dev/shm
# No module autoloading: the guest's modprobe would look in the host's /lib/modules and fail,
# slowly (a lookup of a missing interface would wait for it).
echo >/proc/sys/kernel/modprobe
modules=/usr/lib/uml/modules/\$(uname -r)/kernel
# In this order: vcan needs can-dev.
for m in net/can/can net/can/can-raw drivers/net/can/dev/can-dev drivers/net/can/vcan; do
  insmod "\$modules/\$m.ko" 2>>"\$run/setup-log" ||
    setup_failed "insmod \$m.ko failed: \$(cat "\$run/setup-log")"
done
ip link set lo up
for i in \$(seq 0 \$(($vcan_count - 1))); do
  { ip link add dev vcan\$i type vcan && ip link set vcan\$i up; } 2>>"\$run/setup-log" ||
    setup_failed "vcan\$i: \$(cat "\$run/setup-log")"
done
set -a; . "\$run/environment"; set +a
cd $(printf '%q' "$PWD") || setup_failed "cannot cd to the working directory"
$(cat "$run_dir/command") >"\$run/stdout" 2>"\$run/stderr" </dev/null
echo \$? >"\$run/status"
finish
EOF
chmod +x "$run_dir/init"

# --- Boot ---------------------------------------------------------------------------------------
# uml_dir/umid keep UML's pid file and management socket in the run's folder; the console goes
# to a file (the guest command's output is in its own files).
started_ms=$(($(date +%s%N) / 1000000))
set +e
timeout --kill-after=5 "$timeout_s" "$kernel" mem="$mem" root=/dev/root rootfstype=hostfs \
  rootflags=/ rw init="$run_dir/init" uml_dir="$run_dir" umid=uml con=null con0=null,fd:1 \
  </dev/null >"$run_dir/console.log" 2>&1
uml_status=$?
set -e
elapsed_ms=$(($(date +%s%N) / 1000000 - started_ms))

if [ ! -e "$run_dir/booted" ]; then
  timed_out && cannot_start "the guest did not reach its init in ${timeout_s} s: $(console_tail)"
  cannot_start "linux.uml exited with $uml_status before running its init: $(console_tail)"
fi
[ -e "$run_dir/stdout" ] && cat "$run_dir/stdout"
[ -e "$run_dir/stderr" ] && cat "$run_dir/stderr" >&2
if [ -e "$run_dir/setup-error" ]; then
  echo "$me: the guest could not set up the CAN bus: $(cat "$run_dir/setup-error")" >&2
  exit 125
fi
if [ ! -e "$run_dir/status" ]; then
  if timed_out; then
    echo "$me: timed out after ${timeout_s} s (the command was still running)" >&2
    exit 124
  fi
  echo "$me: the guest stopped before the command finished (linux.uml exited with" \
    "$uml_status): $(console_tail)" >&2
  exit 125
fi
status=$(cat "$run_dir/status")
seconds="$((elapsed_ms / 1000)).$(printf %03d $((elapsed_ms % 1000)))"
echo "$me: command exited with $status after $seconds s (boot included)" >&2
exit "$status"
