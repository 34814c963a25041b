#!/usr/bin/env bash
# Inside the qemu route's guest with a gpio-sim chip (tools/vcan-bus.sh --gpio-sim N, N >= 2):
# libgpiod's tools (package gpiod) find the chip, read the levels the simulator puts on an input
# line, and drive an output line whose level the simulator reads back, as relays on gpio-sim
# will be tested (issue 15). Exit 0 when all of that holds.
set -euo pipefail
fail() { echo "gpio-sim (guest): $*" >&2; exit 1; }
[ -n "${GPIO_SIM_CHIP:-}" ] || fail "no GPIO_SIM_CHIP: run under tools/vcan-bus.sh --gpio-sim N"
[ "${GPIO_SIM_LINES:-0}" -ge 2 ] || fail "needs at least 2 lines, got ${GPIO_SIM_LINES:-none}"
line() { echo "$GPIO_SIM_SYSFS/sim_gpio$1"; }  # the simulator's side of line N

# The chip, as libgpiod lists it: its label and its number of lines.
gpiodetect | grep -qx "$GPIO_SIM_CHIP \[plinth\] ($GPIO_SIM_LINES lines)" ||
  fail "gpiodetect does not list $GPIO_SIM_CHIP [plinth] ($GPIO_SIM_LINES lines): $(gpiodetect)"

# Line 0 as an input: the simulator pulls it up, then down; gpioget reads each level.
for pull in pull-up:1 pull-down:0; do
  level=${pull#*:}
  pull=${pull%:*}
  echo "$pull" >"$(line 0)/pull"
  got=$(gpioget "$GPIO_SIM_CHIP" 0)
  [ "$got" = "$level" ] || fail "line 0 pulled $pull: gpioget read $got"
done

# Line 1 as an output (a relay's coil): gpioset drives it high while it holds the line, the
# simulator reads 1; released, the line falls back to the simulator's pull (down: 0).
gpioset --mode=signal "$GPIO_SIM_CHIP" 1=1 &
holder=$!
value=""
for _ in $(seq 100); do
  read -r value <"$(line 1)/value"
  [ "$value" = 1 ] && break
  sleep 0.02
done
kill "$holder"
wait "$holder" || true
[ "$value" = 1 ] || fail "gpioset drove line 1 high: the simulator read ${value:-nothing}"
read -r value <"$(line 1)/value"
[ "$value" = 0 ] || fail "line 1 released: the simulator read $value, not its pull-down 0"
echo "gpio-sim (guest): $GPIO_SIM_CHIP: gpioget read both pulls of line 0, gpioset drove line 1"
