#!/usr/bin/env bash
# plinth-eval's P-wave parts as a user runs them (docs/pwave.md), kept short: pwave-fit prints
# its table from two bundled stations; run --pwave on with three-component records writes the
# stage's columns (the record's phases, its trigger, its crossings, monotone in the threshold);
# the report's P-wave section is recounted here from the CSV (the warning with the stage is the
# earlier of the box's and the stage's crossing); and bad inputs end with exit code 1 or 2 and a
# message naming the problem. Prints "ok - <name>" or "not ok - <name>: <why>" per check, then
# "N passed, M failed".
#
# Environment: PLINTH_EVAL, the plinth-eval binary; PLINTH_SOURCE_DIR, the repository root.
set -u

PLINTH_SIM=${PLINTH_EVAL:-}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
# shellcheck source=tests/cli/eval_two_stations.sh
source "$SRC/tests/cli/eval_two_stations.sh"
CASES=("${GRID[@]}" --jobs 2)

expect_success "pwave-fit on two stations" pwave-fit "${STATIONS[@]}"
ok_if "pwave-fit prints a line per record and scale, and its table" python3 - "$TMP/stdout" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
records = [l for l in lines if l.startswith("RSN")]
assert len(records) == 6, records  # 2 stations x 3 scales
table = lines[lines.index(next(l for l in lines if l.startswith("# window_s"))) + 1:][:8]
windows = [float(l.split(",")[0]) for l in table]
assert windows == [0.5 * i for i in range(1, 9)], windows
assert any("predictor = [" == l for l in lines)
PY

# --cross-validate: two stations of Northridge and two of Coalinga; each earthquake's residuals
# under the fit on the other, pooled per window as the per-earthquake lines give them.
CV=("${STATIONS[@]:0:4}" --record "$PW/RSN963_NORTHR_ORR090.AT2" --vertical "$PW/RSN963_NORTHR_ORR-UP.AT2"
  --record "$PW/RSN410_COALINGA_D-PLM270.AT2" --vertical "$PW/RSN410_COALINGA_D-PLM-UP.AT2"
  --record "$PW/RSN412_COALINGA_D-PVY045.AT2" --vertical "$PW/RSN412_COALINGA_D-PVY-UP.AT2"
  --pga 0.3g --pga 0.6g --pga 1.2g --pga 2g --fit-tau-c)
expect_success "pwave-fit --cross-validate" pwave-fit "${CV[@]}" --cross-validate
ok_if "leave one earthquake out: pooled from the two earthquakes' residuals" python3 - "$TMP/stdout" <<'PY'
import math, sys
lines = open(sys.argv[1]).read().splitlines()
def block(prefix, n):
    at = lines.index(next(l for l in lines if l.startswith(prefix)))
    return [l.split(", ") for l in lines[at + 1:at + 1 + n]]
fit = block("# window_s", 8)
assert lines[lines.index(next(l for l in lines if l.startswith("# leave one")))].count(
    ", 2 earthquakes:") == 1
pooled = block("# leave one", 8)
per = {p[0]: [c.split(":") for c in p[1:]] for p in block("# per earthquake", 2)}
assert sorted(per) == ["COALINGA", "NORTHR"], per
for w in range(8):
    n = sum(int(per[q][w][0]) for q in per)
    assert int(pooled[w][1]) == n == int(fit[w][1]), (w, pooled[w], fit[w], n)
    ss = sum(int(per[q][w][0]) * float(per[q][w][1]) ** 2 for q in per)
    assert abs(float(pooled[w][2]) - math.sqrt(ss / n)) < 2e-3, (w, pooled[w], ss, n)
# A line of all four stations fits them better than the other earthquake's line does.
assert all(float(pooled[w][2]) > float(fit[w][4]) for w in range(3)), (pooled, fit)
PY
expect_failure "--cross-validate needs two earthquakes" "two earthquakes or more" \
  -- pwave-fit "${STATIONS[@]}" --cross-validate
cp "$PW/RSN990_NORTHR_LAC090.AT2" lac.AT2
expect_failure "--cross-validate needs the earthquake in the file name" "lac.AT2: not named" \
  -- pwave-fit --record lac.AT2 --vertical "$PW/RSN990_NORTHR_LAC-UP.AT2" --cross-validate

# --trace on Kagel Canyon at 0.2 g: its first candidates are rejected again and again in its
# strong motion; the S-wave guard refuses the excitation 2 s after its first candidate, and
# without it (--max-retry-s 60) a candidate 10 s in, long after the strong motion, triggers.
KAT=(--record "$PW/RSN1080_NORTHR_KAT000.AT2" --vertical "$PW/RSN1080_NORTHR_KAT-UP.AT2" --pga 0.2g)
expect_success "pwave-fit --trace" pwave-fit "${KAT[@]}" --trace
ok_if "the trace shows the candidates and the excitation refused, and no trigger" python3 - "$TMP/stdout" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
candidates = [l for l in lines if l.startswith("#   candidate")]
refused = [l for l in lines if "excitation refused (not after quiet)" in l]
assert len(candidates) == 4 and all("rejected" in l for l in candidates), candidates
assert len(refused) == 1 and " 2.060 s after its first candidate" in refused[0], refused
assert not any(l.startswith("#   window_s") for l in lines)  # a trace, not a fit
record = [l for l in lines if l.startswith("RSN1080")]
assert len(record) == 1 and record[0].split(", ")[4] == "none", record
PY
expect_success "pwave-fit --trace without the guard" pwave-fit "${KAT[@]}" --trace --max-retry-s 60
ok_if "without the guard a candidate in the S waves triggers" python3 - "$TMP/stdout" <<'PY'
import sys
lines = open(sys.argv[1]).read().splitlines()
assert not any("excitation refused" in l for l in lines)
triggers = [l for l in lines if l.startswith("#   candidate") and ": trigger" in l]
assert len(triggers) == 1 and triggers[0].startswith("#   candidate 10.100 s"), triggers
record = [l for l in lines if l.startswith("RSN1080")][0].split(", ")
assert float(record[4]) > float(record[3]), record  # after the strong motion
PY

expect_success "a run with the stage" run "${CASES[@]}" --pwave on --out pw.csv
ok_if "the runs carry the stage's columns, its crossings monotone in the threshold" \
  python3 - pw.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
grid = [c for c in rows[0] if c.startswith("pwave_ge_")]
assert len(grid) >= 10, grid
for r in rows:
    t = [float(r[c]) for c in grid]
    # A higher threshold is crossed no sooner (never, -1, counts as last).
    key = [x if x >= 0 else float("inf") for x in t]
    assert key == sorted(key), (r["record"], t)
    assert float(r["strong_motion_s"]) > 0
by_record = {r["record"]: r for r in rows}
lac = by_record["RSN990_NORTHR_LAC090.AT2"]
assert float(lac["strong_motion_s"]) - float(lac["p_pick_s"]) >= 3.0, lac
assert 0 <= float(lac["pwave_trigger_s"]) < float(lac["strong_motion_s"]), lac
PY

expect_success "a run without it" run "${CASES[@]}" --out off.csv
ok_if "the stage changes nothing else: the same truth and box" python3 - pw.csv off.csv <<'PY'
import csv, sys
a = list(csv.DictReader(open(sys.argv[1])))
b = list(csv.DictReader(open(sys.argv[2])))
assert len(a) == len(b)
assert "pwave_ge_0.5" not in b[0] and "p_pick_s" not in b[0]
for x, y in zip(a, b):
    for k in y:
        assert x[k] == y[k], (k, x[k], y[k])
PY

expect_success "the report of a run with the stage" report pw.csv
cp "$TMP/stdout" report.txt
ok_if "the report's P-wave section, recounted from the rows" \
  env PYTHONPATH="$SRC/tools" python3 - pw.csv report.txt <<'PY'
import csv, re, sys
from warning_recount import score as recount
rows = list(csv.DictReader(open(sys.argv[1])))
text = open(sys.argv[2]).read()
assert "P-wave stage (warning" in text, text[-500:]
def warning_time(r, p):
    box = float(r["first_warning_s"])
    if p is None:
        return box
    s = float(r["pwave_ge_" + p])
    return box if s < 0 else s if box < 0 else min(box, s)
def score(p):
    return recount(rows, lambda r: warning_time(r, p))
lines = {l.split()[0]: l for l in text.splitlines() if re.match(r"^    (without|\d)", l)}
for key, line in lines.items():
    p = None if key == "without" else key
    median, unneeded = score(p)
    fields = line.split()
    got_all = float(fields[3])
    got_unneeded = float(fields[4])
    assert abs(got_all - median) < 0.006, (key, got_all, median)
    assert abs(got_unneeded - unneeded) < 0.06, (key, got_unneeded, unneeded)
PY

expect_success "a report calibrated on another file" report pw.csv --pwave-calibrate-on pw.csv
ok_if "it says where the threshold was chosen" grep -q "chosen on the calibration file" \
  "$TMP/stdout"

expect_failure "as many --vertical as --record" "i-th --vertical belongs to the i-th --record" \
  -- run --scene isolated.toml --record "$PW/RSN990_NORTHR_LAC090.AT2" \
  --vertical "$PW/RSN990_NORTHR_LAC-UP.AT2" --record "$PW/RSN1063_NORTHR_RRS228.AT2" --out x.csv
expect_failure "the stage needs the scene's fragility" "needs the scene's \[fragility\]" \
  -- run --scene no-fragility.toml "${STATIONS[@]}" --statues 1 \
  --pga-steps 1 --pwave on --out x.csv
expect_failure "--pwave is on or off" "--pwave: expected on or off" \
  -- run "${CASES[@]}" --pwave yes --out x.csv
expect_failure "a vertical at another rate" "sampling interval .* differs" \
  -- run --scene isolated.toml --record "$PW/RSN990_NORTHR_LAC090.AT2" \
  --vertical "$PW/RSN2622_CHICHI.03_TCU071V.AT2" --out x.csv
expect_failure "pwave-fit needs the verticals" "--vertical" \
  -- pwave-fit --record "$PW/RSN990_NORTHR_LAC090.AT2"
expect_failure "a report without the stage's columns asked to calibrate them" "P-wave columns" \
  -- report off.csv --pwave-calibrate-on off.csv

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
