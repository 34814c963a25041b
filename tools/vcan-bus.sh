#!/usr/bin/env bash
# Runs a command on a real SocketCAN bus in a guest kernel, whatever the host kernel has: boots
# the guest on the host's root filesystem, loads the CAN modules, brings up vcan0 (and vcan1, ...
# with --vcan N), runs the command as the guest's workload in the same directory with the same
# exported environment, powers off, and exits with the command's status. Two routes:
#   uml   Debian's user-mode Linux kernel (linux.uml, an ordinary process), the host's root
#         through hostfs. Does not start on a host whose XSAVE state is larger than 2696 bytes
#         (AMX): checked before it boots (tools/host-xstate-size.py, docs/can-e2e.md).
#   qemu  Debian's kernel (linux-image-amd64) in qemu-system-x86_64, KVM where /dev/kvm is
#         usable, TCG emulation otherwise; an initramfs built per run from busybox-static and the
#         kernel's modules mounts the host's root through virtio-9p and sets up the bus. It can
#         also give the guest a gpio-sim chip (--gpio-sim; module: tools/build-gpio-sim.sh).
# auto (the default) takes uml when it starts here, else qemu. See hal/README.md.
#
# Usage: tools/vcan-bus.sh [options] [--] PROGRAM [ARG...]
#        tools/vcan-bus.sh [options] -c 'SHELL COMMAND LINE'
#        tools/vcan-bus.sh [--route R] --which        the route that would run, without booting
#        tools/vcan-bus.sh --qemu-kernel              the kernel version the qemu route boots
#        tools/vcan-bus.sh [options] --choose FILE    send a frame on the route that runs here,
#                                                     write its name (uml, qemu) to FILE
# Options:
#   --route R         auto, uml or qemu (default: $PLINTH_VCAN_ROUTE, else auto)
#   --vcan N          interfaces vcan0..vcanN-1 (default 1)
#   --timeout S       host-side limit for each boot and its command (default 60)
#   --mem SIZE        guest memory (default 256M)
#   --cpus N          qemu's virtual CPUs (default 1; uml has one)
#   --gpio-sim N      qemu only: a gpio-sim chip with N lines (1-64); the command gets
#                     GPIO_SIM_CHIP (gpiochipX), GPIO_SIM_LINES and GPIO_SIM_SYSFS (its sim_gpioK
#                     folders: pull, value)
#   --out DIR         also keep the run's files there: status, stdout, stderr, console.log
#   --if-chosen FILE  run only if FILE (from --choose) names the route given with --route; else
#                     exit 77 (ctest: the tests of the other route)
# Example: tools/vcan-bus.sh --vcan 2 build/release/tests/test_socketcan
# Exit status: the command's; 77 when no route can start here (ctest's SKIP_RETURN_CODE: the
# reasons are printed; with CI=true 1 instead: CI must run the real-bus tests) or, with
# --if-chosen, when FILE names another route; 124 when the time ran out; 125 when the guest could
# not set up the bus or the harness was misused.
# Environment: PLINTH_VCAN_ROUTE (above); PLINTH_QEMU_ACCEL=kvm|tcg|auto; PLINTH_QEMU_KERNEL (a
# version in /boot, default the newest with vcan); PLINTH_GPIO_SIM_MODULE (default
# /usr/local/lib/plinth/modules/VERSION/gpio-sim.ko); PLINTH_CACHE_DIR (default
# ~/.cache/plinth: the kernel's uncompressed image); for testing this script, UML_VCAN_KERNEL
# (default /usr/bin/linux.uml) and UML_VCAN_XSTATE_SIZE (the host's XSAVE size, bytes).
# shellcheck disable=SC2317  # functions run by traps and through "route_$name"
set -euo pipefail

me=vcan-bus
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

# --- Inside a guest: the frame --choose sends -------------------------------------------------
if [ "${1:-}" = "--smoke-guest" ]; then
  log=$(mktemp /dev/shm/vcan-smoke.XXXXXX)
  candump -L -n 1 vcan0,123:7FF >"$log" 2>&1 &
  dump=$!
  for _ in $(seq 100); do  # until candump has bound its socket and logged the frame
    cansend vcan0 123#C0FFEE
    sleep 0.05
    kill -0 "$dump" 2>/dev/null || break
  done
  kill "$dump" 2>/dev/null || true
  wait "$dump" || true
  if ! grep -q ' vcan0 123#C0FFEE$' "$log"; then
    echo "$me (guest): candump did not receive 123#C0FFEE on vcan0: $(cat "$log")" >&2
    exit 1
  fi
  echo "$me (guest): vcan0 carried 123#C0FFEE from cansend to candump"
  exit 0
fi

# --- Options --------------------------------------------------------------------------------
route=${PLINTH_VCAN_ROUTE:-auto}
vcan_count=1
timeout_s=60
mem=256M
cpus=1
gpio_lines=0
out_dir=""
shell_line=""
mode=run
choose_file=""
chosen_file=""

usage() {
  sed -n '/^# Usage:/,/^# not set up the bus/p' "$0" | sed 's/^# \{0,1\}//' >&2
  exit 125
}
while [ $# -gt 0 ]; do
  case "$1" in
    --route) route=${2:?}; shift 2 ;;
    --vcan) vcan_count=${2:?}; shift 2 ;;
    --timeout) timeout_s=${2:?}; shift 2 ;;
    --mem) mem=${2:?}; shift 2 ;;
    --cpus) cpus=${2:?}; shift 2 ;;
    --gpio-sim) gpio_lines=${2:?}; shift 2 ;;
    --out) out_dir=${2:?}; shift 2 ;;
    --if-chosen) chosen_file=${2:?}; shift 2 ;;
    --which) mode=which; shift ;;
    --qemu-kernel) mode=qemu-kernel; shift ;;
    --choose) mode=choose; choose_file=${2:?}; shift 2 ;;
    -c) shell_line=${2:?}; shift 2 ;;
    -h | --help) usage ;;
    --) shift; break ;;
    -*) echo "$me: unknown option $1" >&2; usage ;;
    *) break ;;
  esac
done
misuse() { echo "$me: $*" >&2; exit 125; }
case "$route" in auto | uml | qemu) ;; *)
  misuse "the route must be auto, uml or qemu (--route or PLINTH_VCAN_ROUTE), got '$route'" ;;
esac
whole_number() { case "$1" in '' | *[!0-9]*) misuse "$2 wants a whole number, got '$1'" ;; esac; }
whole_number "$vcan_count" --vcan
whole_number "$timeout_s" --timeout
whole_number "$cpus" --cpus
whole_number "$gpio_lines" --gpio-sim
[ "$gpio_lines" -le 64 ] || misuse "--gpio-sim wants at most 64 lines"
[ "$cpus" -ge 1 ] || misuse "--cpus wants at least 1"
if [ "$mode" = run ] && [ -z "$shell_line" ] && [ $# -eq 0 ]; then usage; fi
if [ -n "$chosen_file" ] && [ "$route" = auto ]; then
  misuse "--if-chosen needs --route uml|qemu"
fi
on_ci() { [ "${CI:-}" = true ]; }

# --- What every guest does: its init on the host's root --------------------------------------
# The route's BUS_SETUP (code for the guest's bash) runs first, unless the route set the bus up
# before (qemu: in its initramfs, with busybox: no dynamic program to load over 9p).
write_guest_init() {  # RUN_DIR BUS_SETUP
  local run=$1
  cat >"$run/init" <<EOF
#!/bin/bash
# PID 1 of the guest on the host's root: set up the bus, run the command, always power off.
export PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin
run=$(printf %q "$run")
# Never returns. PATH: the command's environment may have replaced the one above.
finish() { sync; PATH=/usr/sbin:/sbin:\$PATH poweroff -f; echo o >/proc/sysrq-trigger; sleep 3600; }
setup_failed() { echo "\$*" >"\$run/setup-error"; finish; }
[ -e "\$run/booted" ] || echo booted >"\$run/booted"
$2
set -a
. "\$run/environment"
[ ! -e "\$run/gpio-sim.env" ] || . "\$run/gpio-sim.env"
set +a
cd $(printf '%q' "$PWD") || setup_failed "cannot cd to the working directory"
read -r uptime _ </proc/uptime && echo "\$uptime" >"\$run/started"  # the guest's clock
$(cat "$run/command") >"\$run/stdout" 2>"\$run/stderr" </dev/null
echo \$? >"\$run/status"
finish
EOF
  chmod +x "$run/init"
}

new_run_dir() {  # ROUTE: one private folder per boot (several runs at once do not meet)
  # /tmp: no spaces for a kernel command line, and not /dev/shm, which the guest's hides.
  run=$(mktemp -d "/tmp/vcan-bus-$1.XXXXXX") || misuse "cannot create a folder in /tmp"
  runs+=("$run")
  if [ -n "$shell_line" ]; then
    printf '%q ' bash -c "$shell_line" >"$run/command"
  else
    printf '%q ' "${command[@]}" >"$run/command"
  fi
  # The exported environment, minus what belongs to this shell or this machine's session.
  export -p | grep -Ev '^declare -x (BASH[A-Z_]*|SHELLOPTS|SHLVL|PWD|OLDPWD|_|TERM|TMPDIR)=' \
    >"$run/environment" || true
}
runs=()
# shellcheck disable=SC2329  # run by the EXIT trap
cleanup() {
  [ -z "${guest_pid:-}" ] || kill -TERM "$guest_pid" 2>/dev/null || true
  if [ -n "$out_dir" ] && [ -n "${run:-}" ]; then
    mkdir -p "$out_dir"
    cp -f "$run"/{status,stdout,stderr,console.log} "$out_dir"/ 2>/dev/null || true
  fi
  [ ${#runs[@]} -eq 0 ] || rm -rf "${runs[@]}"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

now_ms() { echo $(($(date +%s%N) / 1000000)); }
seconds() { echo "$(($1 / 1000)).$(printf %03d $(($1 % 1000)))"; }  # MS -> s.mmm
console_tail() { tail -q -n 5 "$run/console.log" "$run/qemu.log" 2>/dev/null | tr -s '\n' ' '; }

# Runs the guest's process under the time limit, notes when the command started (boot_ms).
boot_guest() {  # LOG COMMAND...
  boot_ms=""
  local started_ms log=$1
  shift
  started_ms=$(now_ms)
  timeout --kill-after=5 "$timeout_s" "$@" </dev/null >"$log" 2>&1 &
  guest_pid=$!
  while kill -0 "$guest_pid" 2>/dev/null; do
    if [ -z "$boot_ms" ] && [ -e "$run/started" ]; then boot_ms=$(($(now_ms) - started_ms)); fi
    sleep 0.02
  done
  guest_status=0
  wait "$guest_pid" || guest_status=$?
  guest_pid=""
  elapsed_ms=$(($(now_ms) - started_ms))
  [ -n "$boot_ms" ] || boot_ms=$elapsed_ms
}
timed_out() { [ "$guest_status" -eq 124 ] || [ "$guest_status" -eq 137 ]; }

# After the guest: 77 (why set) when it never reached its init, else the command's status.
collect() {  # ROUTE
  if [ ! -e "$run/booted" ]; then
    if timed_out; then
      why="the guest did not reach its init in ${timeout_s} s: $(console_tail)"
    else
      why="the guest stopped (status $guest_status) before its init: $(console_tail)"
    fi
    return 77
  fi
  [ -e "$run/stdout" ] && cat "$run/stdout"
  [ -e "$run/stderr" ] && cat "$run/stderr" >&2
  if [ -e "$run/setup-error" ]; then
    echo "$me: route $1: the guest could not set up the bus: $(cat "$run/setup-error")" >&2
    return 125
  fi
  if [ ! -e "$run/status" ]; then
    if timed_out; then
      if [ -e "$run/started" ]; then
        echo "$me: route $1: timed out after ${timeout_s} s (the command, started after" \
          "$(seconds "$boot_ms") s of boot, was still running)" >&2
      else
        echo "$me: route $1: timed out after ${timeout_s} s, before the command started:" \
          "$(console_tail)" >&2
      fi
      return 124
    fi
    echo "$me: route $1: the guest stopped before the command finished (status" \
      "$guest_status): $(console_tail)" >&2
    return 125
  fi
  local status
  status=$(cat "$run/status")
  echo "$me: route $1${accel:+ ($accel)}: command exited with $status after" \
    "$(seconds "$elapsed_ms") s (boot to command $(seconds "$boot_ms") s)" >&2
  return "$status"
}

# --- Route uml ------------------------------------------------------------------------------
uml_kernel=${UML_VCAN_KERNEL:-/usr/bin/linux.uml}  # the overrides are for testing this script
uml_fp_bytes=2696  # linux.uml < 6.13: arch/x86/um/user-offsets.c, HOST_FP_SIZE

version_at_least() { [ "$(printf '%s\n%s\n' "$2" "$1" | sort -V | head -n 1)" = "$2" ]; }

# Sets why and fails when the host's ptrace would refuse the guest's FPU state.
uml_xstate_fits() {
  [ "$(uname -m)" = x86_64 ] || return 0
  local version size
  version=$("$uml_kernel" --version 2>/dev/null | head -n 1) || version=""
  # Linux 6.13 (commit 3f17fed21491) sizes the state from the host.
  if [ -n "$version" ] && version_at_least "$version" 6.13; then return 0; fi
  size=${UML_VCAN_XSTATE_SIZE:-}
  if [ -z "$size" ]; then
    if command -v python3 >/dev/null; then
      size=$(python3 "$root/tools/host-xstate-size.py" 2>&1) || {
        [ $? -ne 2 ] || { why="$size (user-mode Linux runs its guest's processes under ptrace)"
                          return 1; }
        return 0  # not x86-64 Linux: nothing known against booting
      }
    elif grep -qw amx_tile /proc/cpuinfo; then
      size="more than $uml_fp_bytes (amx_tile in /proc/cpuinfo)"
    else
      return 0
    fi
  fi
  case "$size" in *[!0-9]*) ;; *) [ "$size" -gt "$uml_fp_bytes" ] || return 0 ;; esac
  why="this host's XSAVE state is $size bytes (AMX) and linux.uml ${version:-?} hands ptrace"
  why+=" $uml_fp_bytes: the host refuses it (PTRACE_SETREGSET: EFAULT), every guest process"
  why+=" would die with SIGSEGV (docs/can-e2e.md)"
  return 1
}

uml_can_start() {  # sets why when it cannot
  [ -x "$uml_kernel" ] || { why="$uml_kernel not found (install user-mode-linux)"; return 1; }
  local modules=(/usr/lib/uml/modules/*/kernel/drivers/net/can/vcan.ko)
  [ -e "${modules[0]}" ] ||
    { why="no vcan.ko under /usr/lib/uml/modules (package user-mode-linux incomplete)"; return 1; }
  if [ "$gpio_lines" -gt 0 ]; then
    why="no gpio-sim for user-mode Linux (--gpio-sim needs the qemu route)"
    return 1
  fi
  uml_xstate_fits
}

# shellcheck disable=SC2016  # the snippet is code for the guest
route_uml() {
  uml_can_start || return 77
  accel=""
  new_run_dir uml
  # No module autoloading: the guest's modprobe would look in the host's /lib/modules and fail,
  # slowly. In this order: vcan needs can-dev. Few programs: each exec costs 40-300 ms here.
  write_guest_init "$run" '
mount -t proc proc /proc && mount -t sysfs sysfs /sys || setup_failed "mount proc/sysfs failed"
mkdir -p /dev/shm && mount -t tmpfs tmpfs /dev/shm
echo >/proc/sys/kernel/modprobe
read -r release </proc/sys/kernel/osrelease
for m in net/can/can net/can/can-raw drivers/net/can/dev/can-dev drivers/net/can/vcan; do
  insmod "/usr/lib/uml/modules/$release/kernel/$m.ko" 2>>"$run/setup-log" ||
    setup_failed "insmod $m.ko failed: $(cat "$run/setup-log")"
done
{ echo link set lo up
  for ((i = 0; i < '"$vcan_count"'; i++)); do
    echo "link add dev vcan$i type vcan"; echo "link set vcan$i up"
  done; } | ip -batch - 2>>"$run/setup-log" || setup_failed "vcan: $(cat "$run/setup-log")"'
  # uml_dir/umid keep UML's pid file and management socket in the run's folder.
  boot_guest "$run/console.log" "$uml_kernel" mem="$mem" root=/dev/root rootfstype=hostfs \
    rootflags=/ rw init="$run/init" uml_dir="$run" umid=uml con=null con0=null,fd:1
  collect uml
}

# --- Route qemu -----------------------------------------------------------------------------
# The newest installed Debian kernel that has vcan (linux-image-amd64), or PLINTH_QEMU_KERNEL.
qemu_kernel_version() {
  if [ -n "${PLINTH_QEMU_KERNEL:-}" ]; then echo "$PLINTH_QEMU_KERNEL"; return; fi
  local image version
  for image in /boot/vmlinuz-*; do
    version=${image#/boot/vmlinuz-}
    [ -e "/lib/modules/$version/kernel/drivers/net/can/vcan.ko" ] && echo "$version"
  done | sort -V | tail -n 1
}
gpio_sim_module() {  # KERNEL_VERSION
  echo "${PLINTH_GPIO_SIM_MODULE:-/usr/local/lib/plinth/modules/$1/gpio-sim.ko}"
}

qemu_can_start() {  # sets why when it cannot; kernel_version, accel
  command -v qemu-system-x86_64 >/dev/null ||
    { why="qemu-system-x86_64 not found (install qemu-system-x86)"; return 1; }
  kernel_version=$(qemu_kernel_version)
  if [ -z "$kernel_version" ] || [ ! -r "/boot/vmlinuz-$kernel_version" ]; then
    why="no readable /boot/vmlinuz-* with vcan.ko in /lib/modules (install linux-image-amd64)"
    return 1
  fi
  case "$(LC_ALL=C ldd /bin/busybox 2>&1 || true)" in
    *"not a dynamic executable"*) ;;
    *) why="no static /bin/busybox (install busybox-static)"; return 1 ;;
  esac
  if [ "$gpio_lines" -gt 0 ] && [ ! -r "$(gpio_sim_module "$kernel_version")" ]; then
    why="$(gpio_sim_module "$kernel_version") not built (tools/build-gpio-sim.sh, run by"
    why+=" tools/install-deps.sh)"
    return 1
  fi
  case "${PLINTH_QEMU_ACCEL:-auto}" in
    kvm | tcg) accel=$PLINTH_QEMU_ACCEL ;;
    auto) if [ -r /dev/kvm ] && [ -w /dev/kvm ]; then accel=kvm; else accel=tcg; fi ;;
    *) misuse "PLINTH_QEMU_ACCEL must be kvm, tcg or auto" ;;
  esac
}

# The kernel as an uncompressed ELF (its PVH entry): under TCG, decompressing the bzImage takes
# seconds; natively once, then cached. The bzImage when that fails (it still boots).
qemu_kernel_image() {
  local image=/boot/vmlinuz-$kernel_version cache offset elf
  cache=${PLINTH_CACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/plinth}/qemu
  elf=$cache/vmlinux-$kernel_version-$(stat -c %s-%Y "$image")
  if [ ! -s "$elf" ]; then
    offset=$(LC_ALL=C grep -abo -P '\xfd7zXZ\x00' "$image" 2>/dev/null | head -n 1 | cut -d: -f1)
    if [ -n "$offset" ] && mkdir -p "$cache" 2>/dev/null &&
      { tail -c +$((offset + 1)) "$image" || true; } |  # SIGPIPE: xz stops after its stream
      xz -dc --single-stream >"$elf.$$" 2>/dev/null &&
      [ "$(head -c 4 "$elf.$$" | od -An -c | tr -d ' ')" = 177ELF ]; then
      mv -f "$elf.$$" "$elf"
    else
      rm -f "$elf.$$"
      elf=$image
    fi
  fi
  echo "$elf"
}

# The initramfs: busybox and the modules of each GROUP (virtio and 9p; CAN; configfs with
# --gpio-sim), in the order insmod needs, in modules/GROUP.order.
qemu_initramfs_modules() {  # DIR GROUP MODULE...
  local dir=$1 group=$2 listing module
  shift 2
  listing=$(PATH="$PATH:/usr/sbin:/sbin" modprobe -S "$kernel_version" --show-depends -a "$@") ||
    return 1
  awk '$1 == "insmod" { print $2 }' <<<"$listing" | while read -r module; do
    [ -e "$dir/modules/$(basename "$module")" ] && continue  # in an earlier group
    cp "$module" "$dir/modules/" && basename "$module"
  done >"$dir/modules/$group.order"
}

# Its /init mounts the host's root through virtio-9p, sets up the bus (and gpio-sim) with
# busybox, and hands over to the run's init there. Setup errors go to the run's folder.
qemu_initramfs() {
  local dir=$run/initramfs gpio_ko=""
  mkdir -p "$dir"/{bin,modules,proc,sys,dev,root}
  cp /bin/busybox "$dir/bin/"
  qemu_initramfs_modules "$dir" base virtio_pci 9pnet_virtio 9p &&
    qemu_initramfs_modules "$dir" can can-raw vcan || return 1
  if [ "$gpio_lines" -gt 0 ]; then
    qemu_initramfs_modules "$dir" gpio configfs || return 1
    gpio_ko=$(gpio_sim_module "$kernel_version")
  fi
  cat >"$dir/init" <<EOF
#!/bin/busybox sh
# First stage of the qemu route's guest: virtio and 9p, the host's root, the bus, the run's init.
b=/bin/busybox
run=/root$run  # the run's folder, before switch_root
fail() { echo "vcan-bus (qemu guest): \$*"; \$b poweroff -f; \$b sleep 3600; }
setup_failed() { echo "\$*" >"\$run/setup-error"; \$b sync; \$b poweroff -f; \$b sleep 3600; }
load() {  # GROUP
  for module in \$(\$b cat "/modules/\$1.order"); do
    \$b insmod "/modules/\$module" 2>>/setup-log || return 1
  done
}
\$b mount -t proc proc /proc && \$b mount -t sysfs sysfs /sys &&
  \$b mount -t devtmpfs devtmpfs /dev || fail "cannot mount proc, sysfs, devtmpfs"
load base || fail "insmod: \$(\$b cat /setup-log)"
\$b mount -t 9p -o trans=virtio,version=9p2000.L,msize=262144,cache=loose hostroot /root ||
  fail "cannot mount the host's root filesystem through virtio-9p"
echo booted >"\$run/booted"
\$b cat /proc/uptime >>"\$run/booted"  # the guest's clock, for diagnosis
# kvm-clock: the accelerator that ran (QEMU falls back from KVM to TCG when KVM fails).
\$b grep -qw kvm-clock /sys/devices/system/clocksource/clocksource0/available_clocksource &&
  echo kvm >"\$run/accel" || echo tcg >"\$run/accel"
load can || setup_failed "insmod: \$(\$b cat /setup-log)"
{ \$b ip link set lo up && for i in \$(\$b seq 0 $((vcan_count - 1))); do
    \$b ip link add dev "vcan\$i" type vcan && \$b ip link set "vcan\$i" up || exit 1
  done; } 2>>/setup-log || setup_failed "vcan: \$(\$b cat /setup-log)"
EOF
  if [ "$gpio_lines" -gt 0 ]; then
    # One bank of N lines (configfs: the kernel's Documentation/admin-guide/gpio/gpio-sim.rst).
    cat >>"$dir/init" <<EOF
sim=/sys/kernel/config/gpio-sim/plinth
{ load gpio && \$b mount -t configfs configfs /sys/kernel/config &&
  \$b insmod "/root$gpio_ko" && \$b mkdir "\$sim" "\$sim/bank0" &&
  echo $gpio_lines >"\$sim/bank0/num_lines" && echo plinth >"\$sim/bank0/label" &&
  echo 1 >"\$sim/live"; } 2>>/setup-log || setup_failed "gpio-sim: \$(\$b cat /setup-log)"
chip=\$(\$b cat "\$sim/bank0/chip_name")
{ echo "GPIO_SIM_CHIP=\$chip"
  echo "GPIO_SIM_LINES=$gpio_lines"
  echo "GPIO_SIM_SYSFS=/sys/devices/platform/\$(\$b cat "\$sim/dev_name")/\$chip"
} >"\$run/gpio-sim.env"
EOF
  fi
  cat >>"$dir/init" <<EOF
for d in proc sys dev; do \$b mount --move "/\$d" "/root/\$d" || fail "cannot move /\$d"; done
\$b mkdir -p /root/dev/shm && \$b mount -t tmpfs tmpfs /root/dev/shm
exec \$b switch_root /root "$run/init"
EOF
  chmod +x "$dir/init"
  (cd "$dir" && find . | busybox cpio -o -H newc 2>/dev/null) >"$run/initramfs.cpio"
}

# A throwaway guest: no crypto self-tests (1.2 s of an emulated boot in crypto_algapi_init), no
# speculation mitigations (their cost under emulation). On a loaded host an emulated CPU misses
# timer ticks: no_timer_check keeps the boot's test of the 8254 timer (4 ticks in 10) from
# failing and panicking ("IO-APIC + timer doesn't work!", seen at load 15), tsc=reliable keeps
# the TSC (QEMU derives it from the host's clock) as the clock source.
qemu_kernel_options="cryptomgr.notests mitigations=off no_timer_check tsc=reliable"

route_qemu() {
  qemu_can_start || return 77
  new_run_dir qemu
  local kernel_image
  kernel_image=$(qemu_kernel_image)
  qemu_initramfs || { why="cannot build the initramfs for $kernel_version"; return 77; }
  write_guest_init "$run" ""
  local accelerators=(-accel tcg)
  [ "$accel" = tcg ] || accelerators=(-accel kvm)
  [ "${PLINTH_QEMU_ACCEL:-auto}" != auto ] || [ "$accel" = tcg ] || accelerators+=(-accel tcg)
  qemu_boot "${accelerators[@]}"
  local status=0
  collect qemu || status=$?
  # QEMU's own fallback covers a KVM that cannot open, not one that aborts after (seen on an
  # AMD host: "failed to set MSR 0x10a", an assertion in kvm_buf_set_msrs): in auto, a KVM
  # guest that stopped before its init boots again under TCG.
  if [ "$status" -eq 77 ] && [ "$accel" = kvm ] && [ "${PLINTH_QEMU_ACCEL:-auto}" = auto ]; then
    echo "$me: route qemu: KVM stopped the guest before its init ($why); booting under TCG" >&2
    why=""
    accel=tcg
    rm -f "$run"/{booted,started,status,stdout,stderr,setup-error,accel,console.log}
    qemu_boot -accel tcg
    status=0
    collect qemu || status=$?
  fi
  return "$status"
}

qemu_boot() {  # ACCELERATOR OPTIONS...
  boot_guest "$run/qemu.log" qemu-system-x86_64 -nodefaults -no-user-config -machine pc \
    "$@" -cpu max -m "$mem" -smp "$cpus" -kernel "$kernel_image" \
    -initrd "$run/initramfs.cpio" -append "console=ttyS0 panic=-1 quiet $qemu_kernel_options" \
    -virtfs local,path=/,mount_tag=hostroot,security_model=none,multidevs=remap \
    -chardev "file,id=console,path=$run/console.log" -serial chardev:console \
    -display none -monitor none -no-reboot
  [ ! -s "$run/accel" ] || accel=$(cat "$run/accel")
}

# --- Choosing -------------------------------------------------------------------------------
candidates() {
  case "$route" in
    auto) echo uml qemu ;;
    *) echo "$route" ;;
  esac
}

if [ "$mode" = qemu-kernel ]; then
  kernel_version=$(qemu_kernel_version)
  [ -n "$kernel_version" ] || { echo "$me: no /boot/vmlinuz-* with vcan.ko" >&2; exit 1; }
  echo "$kernel_version"
  exit 0
fi
no_route() {  # a skip (77); with CI=true a failure: the real-bus tests must run in CI
  echo "$me: no route can start here${1:-" (the reasons above)"}" >&2
  if on_ci; then
    echo "$me: CI=true: the real-bus tests must run in CI, failing" >&2
    exit 1
  fi
  exit 77
}

if [ -n "$chosen_file" ]; then
  chosen=$(cat "$chosen_file" 2>/dev/null) || chosen=""
  if [ "$chosen" != "$route" ]; then
    echo "$me: skipped: the real-bus tests run on route '${chosen:-none}' here (from" \
      "$chosen_file, written by the vcan_route test)" >&2
    exit 77
  fi
fi

if [ "$mode" = which ]; then
  reasons=""
  for candidate in $(candidates); do
    why=""
    if "${candidate}_can_start"; then
      echo "$candidate${accel:+ ($accel)}"
      exit 0
    fi
    reasons+="; $candidate: $why"
  done
  no_route ": ${reasons#; }"
fi

if [ "$mode" = choose ]; then
  command=(bash "$root/tools/vcan-bus.sh" --smoke-guest)
  rm -f "$choose_file"
else
  command=("$@")
fi
reasons=""
for candidate in $(candidates); do
  why=""
  status=0
  "route_$candidate" || status=$?
  if [ "$status" -ne 77 ] || [ -z "$why" ]; then  # ran (a command's own 77 has no why)
    if [ "$mode" = choose ] && [ "$status" -eq 0 ]; then
      echo "$candidate" >"$choose_file"
      echo "$me: the real-bus tests run on route $candidate here${reasons:+; before it:}"
      printf '%s' "$reasons"
    fi
    exit "$status"
  fi
  echo "$me: route $candidate cannot start here: $why" >&2
  reasons+="  $candidate: $why"$'\n'
done
no_route ""
