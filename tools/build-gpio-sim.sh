#!/usr/bin/env bash
# Builds gpio-sim, the kernel's simulated GPIO chip (configfs, Documentation/admin-guide/gpio/
# gpio-sim.rst), as an out-of-tree module for the Debian kernel that the qemu route of
# tools/vcan-bus.sh boots (--gpio-sim): Debian's kernels ship neither gpio-sim nor gpio-mockup.
# From Debian packages only: the sources in linux-source-6.1 (drivers/gpio/gpio-sim.c and its
# drivers/gpio/gpiolib.h; kernel/irq/irq_sim.c, the interrupt simulator gpio-sim needs, which
# Debian's kernel does not build in: CONFIG_IRQ_SIM is not set) and the kernel's headers
# (linux-headers-VERSION). irq_sim goes into the same module, with one change: it calls
# irq_to_desc(), which modules cannot (not exported), to run handle_simple_irq(); it calls
# generic_handle_irq() instead, which runs the same handler (irq_sim sets it on each interrupt).
#
# Usage: tools/build-gpio-sim.sh [--kernel VERSION] [--out DIR] [--force | --check]
#   --kernel VERSION  default: the kernel the qemu route boots (tools/vcan-bus.sh --qemu-kernel)
#   --out DIR         default /usr/local/lib/plinth/modules/VERSION, where vcan-bus.sh looks
#   --force           build even if DIR/gpio-sim.ko is there for VERSION
#   --check           build nothing: exit 0 if it is there, 1 if not
# Exit status: 0 built or already there; 1 failed (why on stderr); 2 usage.
set -euo pipefail

me="build-gpio-sim"
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
kernel=""
out=""
force=0
check=0
usage() { sed -n '/^# Usage:/,/^# Exit status/p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }
while [ $# -gt 0 ]; do
  case "$1" in
    --kernel) kernel=${2:?}; shift 2 ;;
    --out) out=${2:?}; shift 2 ;;
    --force) force=1; shift ;;
    --check) check=1; shift ;;
    -h | --help) usage ;;
    *) echo "$me: unknown argument $1" >&2; usage ;;
  esac
done
fail() { echo "$me: $*" >&2; exit 1; }
[ -n "$kernel" ] || kernel=$(bash "$root/tools/vcan-bus.sh" --qemu-kernel) ||
  fail "no kernel for the qemu route (install linux-image-amd64)"
out=${out:-/usr/local/lib/plinth/modules/$kernel}
module=$out/gpio-sim.ko
PATH="$PATH:/usr/sbin:/sbin"
if [ "$force" -eq 0 ] && [ -e "$module" ] &&
  [ "$(modinfo -F vermagic "$module" 2>/dev/null | cut -d' ' -f1)" = "$kernel" ]; then
  echo "$me: $module is there for $kernel"
  exit 0
fi
[ "$check" -eq 0 ] || { echo "$me: no $module for $kernel" >&2; exit 1; }
headers=/lib/modules/$kernel/build
[ -e "$headers/Makefile" ] || fail "no $headers (install linux-headers-$kernel)"
sources=(/usr/src/linux-source-*.tar.xz)
[ -e "${sources[0]}" ] || fail "no /usr/src/linux-source-*.tar.xz (install linux-source-6.1)"
source=${sources[-1]}

work=$(mktemp -d /tmp/build-gpio-sim.XXXXXX)
trap 'rm -rf "$work"' EXIT
top=$(basename "$source" .tar.xz)
echo "$me: taking gpio-sim and irq_sim from $source (xz: about a minute)"
tar -xJf "$source" -C "$work" "$top/drivers/gpio/gpio-sim.c" "$top/drivers/gpio/gpiolib.h" \
  "$top/kernel/irq/irq_sim.c" || fail "cannot extract the sources from $source"
build=$work/build
mkdir "$build"
cp "$work/$top/drivers/gpio/gpio-sim.c" "$build/gpio-sim-main.c"
cp "$work/$top/drivers/gpio/gpiolib.h" "$work/$top/kernel/irq/irq_sim.c" "$build/"
sed -i 's/handle_simple_irq(irq_to_desc(irqnum));/generic_handle_irq(irqnum);/' "$build/irq_sim.c"
grep -q 'irq_to_desc' "$build/irq_sim.c" &&
  fail "irq_sim.c in $source still calls irq_to_desc() elsewhere: the change above needs updating"
printf 'obj-m := gpio-sim.o\ngpio-sim-y := gpio-sim-main.o irq_sim.o\n' >"$build/Kbuild"
make -C "$headers" M="$build" modules >"$work/make.log" 2>&1 ||
  fail "the module did not build against $headers: $(tail -n 5 "$work/make.log")"
strip --strip-debug "$build/gpio-sim.ko"
mkdir -p "$out"
install -m 0644 "$build/gpio-sim.ko" "$module.new"
mv -f "$module.new" "$module"
echo "$me: built $module ($(modinfo -F vermagic "$module" | cut -d' ' -f1))"
