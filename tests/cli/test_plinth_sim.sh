#!/usr/bin/env bash
# plinth-sim run as a user would: good runs and their output files (docs/output-formats.md),
# then bad inputs, which must end with exit code 1 or 2 and a message on stderr naming the
# problem. Prints "ok - <name>" or "not ok - <name>: <why>" per check, then "N passed, M failed".
#
# Environment: PLINTH_SIM, the plinth-sim binary; PLINTH_SOURCE_DIR, the repository root.
set -u

# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"

ISOLATED=$SCENES/paper-isolated.toml
GROUND=$SCENES/non-isolated.toml

HAVE_PYTHON=0
if command -v python3 >/dev/null 2>&1 && python3 -c 'import json' >/dev/null 2>&1; then
  HAVE_PYTHON=1
fi

# Prints why FILE is not JSON Lines (one JSON object per line), nothing when it is.
json_lines_problem() {
  local file=$1
  if [[ ! -s "$file" ]]; then
    echo "empty"
    return
  fi
  if ((HAVE_PYTHON)); then
    python3 - "$file" <<'EOF' 2>&1 | tail -n 1
import json, sys

def constant(name):  # NaN, Infinity: not JSON
    raise ValueError("not JSON: " + name)

for number, line in enumerate(open(sys.argv[1]), 1):
    try:
        value = json.loads(line, parse_constant=constant)
    except ValueError as error:
        print(f"line {number}: {error}")
        sys.exit(1)
    if not isinstance(value, dict):
        print(f"line {number}: not an object")
        sys.exit(1)
EOF
  else
    # Without python3: every line must look like {"t": number, "event": "name"[, "key": value]...}.
    local number='-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?'
    local value="($number|\"[a-z_]+\")"
    local bad
    bad=$(grep -nvE "^\\{\"t\": $number, \"event\": \"[a-z_]+\"(, \"[a-z_]+\": $value)*\\}\$" "$file" |
      head -n 1)
    [[ -n "$bad" ]] && echo "line ${bad%%:*} is not a JSON object: ${bad#*:}"
  fi
}

# Prints why FILE is not a plinth-sim time history, nothing when it is.
csv_problem() {
  local file=$1
  local header
  header=$(head -n 1 "$file")
  if [[ "$header" != "t,ag,u,u_dot,x,x_dot,theta,theta_dot,phase" ]]; then
    echo "header is '$header'"
    return
  fi
  awk -F, '
    BEGIN { split("full_contact sliding rocking slide_rocking overturned fell", p, " ");
            for (i in p) phase[p[i]] = 1 }
    NR == 1 { next }
    NF != 9 { printf "line %d has %d fields: %s\n", NR, NF, $0; exit }
    !($9 in phase) { printf "line %d: unknown phase \"%s\"\n", NR, $9; exit }
    { rows++ }
    END { if (rows < 2) printf "%d data rows\n", rows }' "$file"
}

# Prints why the last line of FILE is not the end line with OUTCOME, nothing when it is.
end_line_problem() {
  local file=$1 outcome=$2
  local last
  last=$(tail -n 1 "$file")
  local number='-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?'
  if ! grep -qE "^\\{\"t\": $number, \"event\": \"end\", \"outcome\": \"$outcome\"\\}\$" <<<"$last"; then
    echo "last line is '$last'"
  fi
}

# check NAME PROBLEM: passes when PROBLEM (the output of one of the *_problem functions) is empty.
check() {
  if [[ -z "$2" ]]; then pass "$1"; else fail "$1" "$2"; fi
}

has_event() { grep -qE "\"event\": \"$2\"" "$1"; }

# ---------------------------------------------------------------------------------------------
# Good runs.

if expect_success "isolated, Brienza at 0.3g: exit 0" --scene "$ISOLATED" --record "$AT2" \
  --pga 0.3g --out "$TMP/iso.csv" --events "$TMP/iso.jsonl"; then
  check "isolated, Brienza at 0.3g: CSV header and rows" "$(csv_problem "$TMP/iso.csv")"
  check "isolated, Brienza at 0.3g: events end with survived" \
    "$(end_line_problem "$TMP/iso.jsonl" survived)"
  check "isolated, Brienza at 0.3g: events are JSON Lines" "$(json_lines_problem "$TMP/iso.jsonl")"
  if grep -q "phase timeline" "$TMP/stdout"; then
    pass "summary has a phase timeline"
  else
    fail "summary has a phase timeline" "stdout: $(head -c 300 "$TMP/stdout")"
  fi
fi

if expect_success "on the ground, Brienza at 1g: exit 0" --scene "$GROUND" --record "$AT2" \
  --pga 1g --out "$TMP/ground.csv" --events "$TMP/ground.jsonl"; then
  check "on the ground, Brienza at 1g: CSV header and rows" "$(csv_problem "$TMP/ground.csv")"
  if has_event "$TMP/ground.jsonl" rocking_start && has_event "$TMP/ground.jsonl" impact; then
    pass "on the ground, Brienza at 1g: rocking_start and impact events"
  else
    fail "on the ground, Brienza at 1g: rocking_start and impact events" \
      "events: $(cut -d, -f2 "$TMP/ground.jsonl" | sort | uniq -c | tr -s ' \n' ' ')"
  fi
  check "on the ground, Brienza at 1g: events are JSON Lines" \
    "$(json_lines_problem "$TMP/ground.jsonl")"
  check "on the ground, Brienza at 1g: events end with survived" \
    "$(end_line_problem "$TMP/ground.jsonl" survived)"
fi

if expect_success "on the ground, impulse -3 m/s: exit 0" --scene "$GROUND" --impulse -3 \
  --out "$TMP/over.csv" --events "$TMP/over.jsonl"; then
  check "impulse -3 m/s overturns: events end with overturned" \
    "$(end_line_problem "$TMP/over.jsonl" overturned)"
  if grep -qE '"event": "overturned", "corner": "left"' "$TMP/over.jsonl"; then
    pass "impulse -3 m/s overturns: overturned event about the left corner"
  else
    fail "impulse -3 m/s overturns: overturned event about the left corner" \
      "events: $(tr '\n' ' ' <"$TMP/over.jsonl" | cut -c 1-300)"
  fi
  check "impulse -3 m/s overturns: events are JSON Lines" "$(json_lines_problem "$TMP/over.jsonl")"
  check "impulse -3 m/s overturns: CSV header and rows" "$(csv_problem "$TMP/over.csv")"
fi

# A ground that falls faster than gravity (vertical column to -1.5 g) lifts the block off: the
# run ends there, outside the model, said in the events, the end line and the summary.
{
  echo "t,ag [g],v [g]"
  for i in $(seq 0 200); do
    printf '%s,0.05,%s\n' "$(awk "BEGIN{print $i * 0.01}")" "$(awk "BEGIN{v = -1.5 * ($i * 0.01 - 1); print ($i < 100) ? 0 : v}")"
  done
} >"$TMP/falling.csv"
if expect_success "a falling ground: exit 0" --scene "$ISOLATED" --record "$TMP/falling.csv" \
  --out "$TMP/lift.csv" --events "$TMP/lift.jsonl"; then
  check "a falling ground: events are JSON Lines" "$(json_lines_problem "$TMP/lift.jsonl")"
  lift_t=$(grep -oE '^\{"t": [0-9.]+, "event": "lift_off", "from": "[a-z_]+"' "$TMP/lift.jsonl" |
    grep -oE '[0-9]+\.[0-9]+' | head -n 1)
  if [[ -n "$lift_t" ]] &&
    grep -qxE "\\{\"t\": [0-9.]+, \"event\": \"end\", \"outcome\": \"lifted_off\", \"model_valid_until\": $lift_t\\}" \
      "$TMP/lift.jsonl"; then
    pass "a falling ground: a lift_off event, and the end line says lifted_off and when"
  else
    fail "a falling ground: a lift_off event, and the end line says lifted_off and when" \
      "events: $(tail -n 2 "$TMP/lift.jsonl" | tr '\n' ' ' | cut -c 1-300)"
  fi
  if [[ "$(tail -n 1 "$TMP/lift.csv" | cut -d, -f9)" == lifted_off ]] &&
    grep -q "^outcome:    lifted_off" "$TMP/stdout" && grep -q "^outside the model: " "$TMP/stdout"; then
    pass "a falling ground: the CSV's last phase and the summary say lifted_off"
  else
    fail "a falling ground: the CSV's last phase and the summary say lifted_off" \
      "$(tail -n 1 "$TMP/lift.csv"); $(grep -E '^(outcome|outside)' "$TMP/stdout" | cut -c 1-200)"
  fi
fi

if expect_success "on the ground, Brienza at 3g: exit 0" --scene "$GROUND" --record "$AT2" \
  --pga 3g --events "$TMP/over3g.jsonl"; then
  if has_event "$TMP/over3g.jsonl" overturned &&
    [[ -z "$(end_line_problem "$TMP/over3g.jsonl" overturned)" ]]; then
    pass "Brienza at 3g overturns the block on the ground"
  else
    fail "Brienza at 3g overturns the block on the ground" "$(tail -n 2 "$TMP/over3g.jsonl" | tr '\n' ' ')"
  fi
fi

if expect_success "sine pulse 0.5g, 0.5 s: exit 0" --scene "$ISOLATED" --pulse sine \
  --amplitude 0.5g --period 0.5 --out "$TMP/pulse.csv" --events "$TMP/pulse.jsonl"; then
  check "sine pulse: CSV header and rows" "$(csv_problem "$TMP/pulse.csv")"
  check "sine pulse: events end with survived" "$(end_line_problem "$TMP/pulse.jsonl" survived)"
fi

if expect_success "isolated, impulse 0.4 m/s: exit 0" --scene "$ISOLATED" --impulse 0.4 \
  --out "$TMP/impulse.csv" --events "$TMP/impulse.jsonl"; then
  check "isolated, impulse 0.4 m/s: CSV header and rows" "$(csv_problem "$TMP/impulse.csv")"
  # The base starts with u' = I, to the right (docs/output-formats.md).
  first_row=$(sed -n 2p "$TMP/impulse.csv")
  if awk -F, '{ exit !($1 == 0 && $3 == 0 && $4 == 0.4) }' <<<"$first_row"; then
    pass "isolated, impulse 0.4 m/s: first row has t = 0, u = 0, u_dot = 0.4"
  else
    fail "isolated, impulse 0.4 m/s: first row has t = 0, u = 0, u_dot = 0.4" "first row: $first_row"
  fi
fi

if expect_success "--scale 2.5: exit 0" --scene "$ISOLATED" --record "$AT2" --scale 2.5 \
  --out "$TMP/scale.csv"; then
  check "--scale 2.5: CSV header and rows" "$(csv_problem "$TMP/scale.csv")"
fi

if expect_success "--out-interval 0.01 --t-end 1: exit 0" --scene "$ISOLATED" --impulse 0.4 \
  --t-end 1 --out-interval 0.01 --out "$TMP/interval.csv"; then
  rows=$(($(wc -l <"$TMP/interval.csv") - 1))
  last_t=$(tail -n 1 "$TMP/interval.csv" | cut -d, -f1)
  if ((rows == 101)) && [[ "$last_t" == "1.000000" ]]; then
    pass "--out-interval 0.01 --t-end 1: 101 rows, the last at t = 1"
  else
    fail "--out-interval 0.01 --t-end 1: 101 rows, the last at t = 1" "$rows rows, last t = $last_t"
  fi
fi

# ---------------------------------------------------------------------------------------------
# Bad inputs. Files written here live in $TMP.

{
  echo "THIS IS NOT A PEER RECORD"
  echo "just some text"
  echo "more text"
  echo "and no NPTS or DT anywhere"
  sed -n '5,$p' "$AT2"
} >"$TMP/garbage.AT2"
head -n 20 "$AT2" >"$TMP/truncated.AT2"
# The first value of line 10 replaced by NaN: the value count stays right.
sed '10s/^\( *\)[-+.0-9Ee]*/\1NaN/' "$AT2" >"$TMP/poisoned.AT2"
printf 't,a [g]\n0,0\n0.01,0.1\n0.02,nan\n0.03,0\n' >"$TMP/poisoned.csv"
printf 't,a [g]\n0,0\n0.01,0.1\n0.02,-0.05\n0.03,0\n' >"$TMP/good.csv"

sed 's/^half_width = 0.3 /half_width = 0.3\nwidht = 0.3 /' "$ISOLATED" >"$TMP/unknown-key.toml"
sed 's/^eccentricity_ratio = 0.0/eccentricity_ratio = 1.2/' "$ISOLATED" >"$TMP/eccentric.toml"
sed 's/^damping_ratio = 0.2/damping_ratio = 1.0/' "$ISOLATED" >"$TMP/damped.toml"
sed 's/^half_width = 0.3/half_width = -0.3/' "$ISOLATED" >"$TMP/negative.toml"
{
  cat "$ISOLATED"
  printf '\n[friction]\nstatic = 0.6\nkinetic = 0.7\n'
} >"$TMP/friction.toml"
{
  cat "$ISOLATED"
  printf '\n[friction]\nstatic = 0.1\n'
} >"$TMP/slides.toml"

# The scenes above must differ from the bundled one, or the checks below prove nothing.
for f in unknown-key eccentric damped negative; do
  if cmp -s "$ISOLATED" "$TMP/$f.toml"; then fail "test setup: $f.toml" "sed did not change the scene"; fi
done
if cmp -s "$AT2" "$TMP/poisoned.AT2"; then fail "test setup: poisoned.AT2" "sed did not change the record"; fi

expect_success "a CSV record runs" --scene "$ISOLATED" --record "$TMP/good.csv" --pga 0.3g

NOFILE='cannot open|cannot read|no such file|not found|does not exist'

expect_failure "missing scene file" 'no-such-scene\.toml' "$NOFILE" -- \
  --scene "$TMP/no-such-scene.toml" --record "$AT2" --pga 0.3g
expect_failure "missing record file" 'no-such-record\.AT2' "$NOFILE" -- \
  --scene "$ISOLATED" --record "$TMP/no-such-record.AT2" --pga 0.3g
expect_failure "malformed AT2 (garbage header)" 'garbage\.AT2' 'header|NPTS|DT|units' -- \
  --scene "$ISOLATED" --record "$TMP/garbage.AT2" --pga 0.3g
expect_failure "truncated AT2 (fewer values than NPTS)" 'truncated\.AT2' \
  'truncated|fewer|NPTS|expected' -- \
  --scene "$ISOLATED" --record "$TMP/truncated.AT2" --pga 0.3g
expect_failure "NaN in a CSV record" 'poisoned\.csv:4' 'finite|not a number|nan' -- \
  --scene "$ISOLATED" --record "$TMP/poisoned.csv" --pga 0.3g
expect_failure "NaN in an AT2 record" 'poisoned\.AT2:10' 'finite|not a number|nan' -- \
  --scene "$ISOLATED" --record "$TMP/poisoned.AT2" --pga 0.3g

expect_failure "unknown scene key" 'widht' 'unknown' -- \
  --scene "$TMP/unknown-key.toml" --record "$AT2" --pga 0.3g
expect_failure "eccentricity_ratio = 1.2" 'eccentric\.toml' 'eccentricity' -- \
  --scene "$TMP/eccentric.toml" --record "$AT2" --pga 0.3g
expect_failure "damping_ratio = 1.0" 'damped\.toml' 'damping_ratio' -- \
  --scene "$TMP/damped.toml" --record "$AT2" --pga 0.3g
expect_failure "negative half_width" 'negative\.toml' 'half_width' -- \
  --scene "$TMP/negative.toml" --record "$AT2" --pga 0.3g
expect_failure "[friction] kinetic above static" 'friction\.kinetic' 'static' -- \
  --scene "$TMP/friction.toml" --record "$AT2" --pga 0.3g
if expect_success "a low-friction block slides" --scene "$TMP/slides.toml" --record "$AT2" \
  --pga 1g --events "$TMP/slides.jsonl"; then
  if grep -q '"event": "sliding_start"' "$TMP/slides.jsonl"; then
    pass "sliding shows in the event log"
  else
    fail "sliding shows in the event log" "no sliding_start event"
  fi
fi

expect_failure "--pga without a unit" '--pga' 'unit' -- \
  --scene "$ISOLATED" --record "$AT2" --pga 0.3
expect_failure "--pga with an unknown unit" '--pga' 'furlongs' 'unit' -- \
  --scene "$ISOLATED" --record "$AT2" --pga 0.3furlongs
expect_failure "--dt 0" '--dt' -- --scene "$ISOLATED" --record "$AT2" --pga 0.3g --dt 0
expect_failure "--dt negative" '--dt' -- --scene "$ISOLATED" --record "$AT2" --pga 0.3g --dt -1e-4
expect_failure "--pulse without --amplitude" '--amplitude' -- \
  --scene "$ISOLATED" --pulse sine --period 0.5
expect_failure "unwritable --out" '/nonexistent/dir/x\.csv' 'cannot open|cannot write|no such|does not exist' -- \
  --scene "$ISOLATED" --record "$AT2" --pga 0.3g --out /nonexistent/dir/x.csv
expect_failure "unwritable --events" '/nonexistent/dir/x\.jsonl' \
  'cannot open|cannot write|no such|does not exist' -- \
  --scene "$ISOLATED" --record "$AT2" --pga 0.3g --events /nonexistent/dir/x.jsonl
expect_failure "--scale together with --pga" '--scale' '--pga' -- \
  --scene "$ISOLATED" --record "$AT2" --pga 0.3g --scale 2

# Numbers that are not finite must be refused, not simulated into NaN output.
expect_failure "--scale nan" '--scale' -- --scene "$ISOLATED" --record "$AT2" --scale nan
expect_failure "--impulse nan" '--impulse' -- --scene "$GROUND" --impulse nan
expect_failure "--period nan" '--period' -- \
  --scene "$ISOLATED" --pulse sine --amplitude 0.5g --period nan
expect_failure "--t-end nan" '--t-end' -- --scene "$ISOLATED" --impulse 0.4 --t-end nan

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
