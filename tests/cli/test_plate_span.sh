#!/usr/bin/env bash
# tools/plate-span.py (docs/statue-filter.md, "A correct sensor refused on an isolated scene"):
# the eval's isolated scene under Calitri 000 at 0.2 g has bases inside its box that leave the
# members' span (the finding the tool exists for), a scene without base uncertainty is refused
# by name, and an odd grid is a usage error.
set -euo pipefail
src=${PLINTH_SOURCE_DIR:?}
sim=${PLINTH_SIM:?}
tool=$src/tools/plate-span.py
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "not ok - $*"; exit 1; }

python3 "$tool" --sim "$sim" --scene "$src/sim/scenes/eval/isolated.toml" \
  --record "$src/sim/data/records/irpinia1980_calitri_000.AT2" --pga 0.2g --steps 2 \
  --work "$work/runs" >"$work/out" || fail "plate-span on the isolated scene exited $?"
rows=$(grep -c '^| [0-9]' "$work/out") || true
[ "$rows" -eq 4 ] ||
  fail "4 grid points besides the members expected, $rows rows: $(cat "$work/out")"
# The nominal period at the lowest damping: outside the span by more than 0.1 m/s2 somewhere.
worst=$(awk -F'|' '$2 ~ /^ 1 $/ && $3 ~ /0.075/ {gsub(/ /, "", $6); print $6}' "$work/out")
awk -v w="$worst" 'BEGIN { exit !(w > 0.1) }' ||
  fail "T = 1 s, xi = 0.075 expected beyond the span by more than 0.1 m/s2, got '$worst'"
echo "ok - a base inside the box leaves the members' span by $worst m/s2"

status=0
python3 "$tool" --sim "$sim" --scene "$src/sim/scenes/paper-eccentric.toml" \
  --record "$src/sim/data/records/irpinia1980_calitri_000.AT2" --pga 0.2g \
  >"$work/out" 2>"$work/err" || status=$?
[ "$status" -eq 2 ] && grep -q 'no \[uncertainty.base\]' "$work/err" ||
  fail "a scene without base uncertainty: exit 2 naming it expected, got $status:" \
    "$(cat "$work/err")"
echo "ok - a scene without [uncertainty.base] is refused by name"

status=0
python3 "$tool" --sim "$sim" --scene "$src/sim/scenes/eval/isolated.toml" \
  --record "$src/sim/data/records/irpinia1980_calitri_000.AT2" --pga 0.2g --steps 3 \
  >"$work/out" 2>"$work/err" || status=$?
[ "$status" -eq 2 ] || fail "--steps 3: a usage error (2) expected, got $status"
echo "ok - an odd grid is a usage error"
