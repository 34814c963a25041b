#!/usr/bin/env bash
# Flash, RAM and instruction counts of a cross build's images (docs/microcontroller.md): runs
# every replay image and the step bench in QEMU under -icount shift=0 (one instruction per ns
# of virtual time) and prints their '# cost', '# step' and '# stack' lines, then each image's
# flash and RAM from its link map (tools/image-size-by-object.py; the compiled-in record apart).
# Usage: tools/cortex-m-costs.sh [BUILD_DIR] [QEMU_MACHINE]
#   BUILD_DIR      a cortex-m4f build tree (default build/cortex-m4f)
#   QEMU_MACHINE   mps2-an386 (Cortex-M4F, default) or mps2-an500 (Cortex-M7, for a build with
#                  -DPLINTH_MCU_CPU_FLAGS="-mcpu=cortex-m7 -mthumb -mfloat-abi=hard -mfpu=fpv5-d16")
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
build=${1:-build/cortex-m4f}
machine=${2:-mps2-an386}
images=$build/firmware/cortex_m
[ -s "$images/replay_cases.txt" ] || { echo "cortex-m-costs: no $images/replay_cases.txt: build $build first" >&2; exit 2; }
run() {  # IMAGE
  timeout 600 qemu-system-arm -M "$machine" -nographic -monitor none -serial none \
    -semihosting-config enable=on,target=native -icount shift=0 -kernel "$1"
}
names=$(cut -f 1 "$images/replay_cases.txt")
# Images that no plinth-monitor replay compares with (the statue sensor's load case).
if [ -s "$images/cost_cases.txt" ]; then names="$names $(cat "$images/cost_cases.txt")"; fi
for name in $names step-bench; do
  echo "== $name"
  run "$images/$name.elf" | grep -E '^# (cost|step|stack|end)' | sed 's/^# /   /'
done
for name in $names step-bench; do
  echo "== $name: $(python3 "$here/image-size-by-object.py" "$images/$name.map" --summary)"
done
