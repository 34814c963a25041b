#!/usr/bin/env bash
# The paper's Fig. 14: the four kinds of response under the Brienza record (Irpinia 1980,
# Brienza 000), one scene each in sim/scenes/fig14*.toml (docs/fig14.md). Each scene is run at
# its PGA and at PGA x 0.95 and x 1.05, and the kind is read from the event log and the CSV:
#   (a) pure sliding held by the sliding stops: slide_stop_hit, max |x| <= x_hat, no rocking_start;
#   (b) the block slides out of the base: out_of_base, max |x| > x_hat;
#   (c) slide-rocking with base stop impacts: base_stop_hit, sliding_start, rocking_start,
#       out_of_base, and a slide_rocking row in the CSV;
#   (d) pure rocking: rocking_start and impact, no sliding_start.
# Prints "ok - <name>" or "not ok - <name>: <why>" per check, then "N passed, M failed".
#
# Environment: PLINTH_SIM, the plinth-sim binary; PLINTH_SOURCE_DIR, the repository root.
set -u

# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

if ! command -v python3 >/dev/null 2>&1; then
  echo "python3 is needed to read the event log and the CSV" >&2
  exit 2
fi

# Prints why the run (EVENTS, CSV) is not of KIND (a, b, c or d) with clearance XHAT; nothing
# when it is.
kind_problem() {
  python3 - "$1" "$2" "$3" "$4" <<'EOF'
import csv, json, math, sys

kind, events_file, csv_file, x_hat = sys.argv[1], sys.argv[2], sys.argv[3], float(sys.argv[4])
problems = []

events = []
for number, line in enumerate(open(events_file), 1):
    try:
        events.append(json.loads(line))
    except ValueError as error:
        print(f"{events_file}:{number}: {error}")
        sys.exit(0)
if not events or events[-1].get("event") != "end":
    problems.append("the event log has no end line")
count = {}
for e in events:
    count[e.get("event")] = count.get(e.get("event"), 0) + 1

max_x = 0.0
phases = set()
with open(csv_file) as f:
    for row in csv.DictReader(f):
        values = [float(row[k]) for k in ("u", "u_dot", "x", "x_dot", "theta", "theta_dot")]
        if not all(math.isfinite(v) for v in values):
            problems.append(f"non-finite value at t = {row['t']}")
            break
        max_x = max(max_x, abs(float(row["x"])))
        phases.add(row["phase"])

def need(name):
    if not count.get(name):
        problems.append(f"no {name} event")

def refuse(name):
    if count.get(name):
        problems.append(f"{count[name]} {name} events")

if kind == "a":
    need("slide_stop_hit")
    refuse("rocking_start")
    if max_x > x_hat + 1e-9:
        problems.append(f"max |x| = {max_x:.9g} m passes x_hat = {x_hat} m")
elif kind == "b":
    need("out_of_base")
    if not max_x > x_hat:
        problems.append(f"max |x| = {max_x:.9g} m does not pass x_hat = {x_hat} m")
elif kind == "c":
    for name in ("base_stop_hit", "sliding_start", "rocking_start", "out_of_base"):
        need(name)
    if "slide_rocking" not in phases:
        problems.append("no slide_rocking row in the CSV")
elif kind == "d":
    need("rocking_start")
    need("impact")
    refuse("sliding_start")
else:
    problems.append(f"unknown kind {kind}")

if problems:
    seen = ", ".join(f"{n} {k}" for k, n in sorted(count.items()))
    print("; ".join(problems) + f" (events: {seen}; max |x| {max_x:.4g} m; outcome "
          f"{events[-1].get('outcome') if events else '?'})")
EOF
}

# check_kind KIND TITLE SCENE PGA FACTOR...: runs SCENE under the Brienza record at PGA x FACTOR
# (PGA in g) for each FACTOR and checks that each run is of KIND.
check_kind() {
  local kind=$1 title=$2 scene=$3 pga=$4
  shift 4
  local x_hat
  x_hat=$(sed -n 's/^clearance *= *\([0-9.eE+-]*\).*/\1/p' "$scene")
  if [[ -z "$x_hat" ]]; then
    fail "($kind) $title: scene" "$scene has no [support] clearance"
    return
  fi
  local factor
  for factor in "$@"; do
    local g
    g=$(awk -v p="$pga" -v f="$factor" 'BEGIN { printf "%.6g", p * f }')
    local name
    name="($kind) $title, $(basename "$scene") at ${g}g (PGA x $factor)"
    local events=$TMP/$kind-$factor.jsonl csv=$TMP/$kind-$factor.csv
    "${TIMEOUT[@]}" "$SIM" --scene "$scene" --record "$AT2" --pga "${g}g" --events "$events" \
      --out "$csv" >"$TMP/stdout" 2>"$TMP/stderr"
    local rc=$?
    if ((rc != 0)); then
      fail "$name" "exit $rc; stderr: $(head -n 1 "$TMP/stderr" | cut -c 1-200)"
      continue
    fi
    local why
    why=$(kind_problem "$kind" "$events" "$csv" "$x_hat")
    if [[ -z "$why" ]]; then pass "$name"; else fail "$name" "$why"; fi
  done
}

check_kind a "pure sliding held by the sliding stops" \
  "$SCENES/fig14a-sliding-held-by-stops.toml" 1.5 1 0.95 1.05
check_kind b "the block slides out of the base" \
  "$SCENES/fig14b-leaves-the-base.toml" 1.5 1 0.95 1.05
check_kind c "slide-rocking with base stop impacts" \
  "$SCENES/fig14c-slide-rocking-base-stops.toml" 2.3 1 0.95 1.05
check_kind d "pure rocking" \
  "$SCENES/fig14d-pure-rocking.toml" 1.8 1 0.95 1.05

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
