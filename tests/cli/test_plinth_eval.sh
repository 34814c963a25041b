#!/usr/bin/env bash
# plinth-eval run as a user would (docs/forecast.md), kept short: a small run writes one row
# per case and scale up to each case's first collapse, shards merged hold the same rows, the
# report counts what the rows say (recounted here from the CSV, collapse margins too), the
# fragility's fits are maxima of the likelihood (recomputed here), files of an earlier
# plinth-eval are read or refused with what to do, the ROC and the fragility are drawn (or a
# missing gnuplot is named), and bad inputs end with exit code 1 or 2 and a
# message naming the problem. Prints "ok - <name>" or "not ok - <name>: <why>" per check, then
# "N passed, M failed".
#
# Environment: PLINTH_EVAL, the plinth-eval binary; PLINTH_SOURCE_DIR, the repository root.
set -u

PLINTH_SIM=${PLINTH_EVAL:-}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
EVAL=$SIM
EVAL_SCENES=$SRC/sim/scenes/eval
RECORDS=(--record "$AT2" --record "$SRC/sim/data/records/eval/RSN1605_DUZCE_DZC270.AT2")
CASES=(--scene "$EVAL_SCENES/isolated.toml" --scene "$EVAL_SCENES/ground-slender.toml"
  "${RECORDS[@]}" --pga-steps 4 --jobs 2)
SMALL=("${CASES[@]}" --statues 2 --pga-from 0.3g --pga-to 1.5g)

expect_success "a small run" run "${SMALL[@]}" --out all.csv
mv "$TMP/stdout" run.txt
# Each case (2 records x 2 scenes x 2 statues) has rows up to its first collapse only.
ok_if "rows stop at each case's first collapse" python3 - all.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
cases = {}
for r in rows:
    cases.setdefault((r["record"], r["scene"], r["statue"]), []).append(r)
assert len(cases) == 8, len(cases)
for key, rs in cases.items():
    scales = [float(r["scale_g"]) for r in rs]
    assert scales == sorted(scales) and scales[0] == 0.3, scales
    collapsed = [r["collapsed"] == "1" for r in rs]
    assert all(not c for c in collapsed[:-1]), key
    assert collapsed[-1] or len(rs) == 4, key
    for r in rs:
        if r["collapsed"] == "1":
            assert float(r["collapse_time_s"]) > 0 and float(r["peak_ratio"]) >= 1
PY

# A box given the true statue: one member, so its worst member is its nominal statue in every
# row, where the scene file's ensemble differs in some; the truth is the same run for run.
expect_success "a box that knows the statue" run "${SMALL[@]}" --box-knows-statue --out knows.csv
ok_if "the box that knows the statue runs it alone, on the same truth" \
  python3 - all.csv knows.csv <<'PY'
import csv, sys
ensemble = list(csv.DictReader(open(sys.argv[1])))
knows = list(csv.DictReader(open(sys.argv[2])))
truth = ["record", "scene", "statue", "scale_g", "collapsed", "collapse_time_s", "peak_ratio"]
assert [[r[c] for c in truth] for r in ensemble] == [[r[c] for c in truth] for r in knows]
risk = [c for c in knows[0] if c.startswith("risk_ge_")]
def alone(r): return all(r[c] == r["nominal_" + c] for c in risk)
assert all(alone(r) for r in knows)
assert not all(alone(r) for r in ensemble)
PY

# Without the policy's raise hold the box's alarm is a rule of the runs file's columns: one pair
# of thresholds "risk >= a or probability >= b" gives every row's first alarm (up to a sample).
expect_success "a box without a raise hold" run "${SMALL[@]}" --raise-hold 0 --out hold0.csv
ok_if "without a hold the alarm is the first crossing of one rule" python3 - hold0.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
risk = [c for c in rows[0] if c.startswith("risk_ge_")]
probability = [c for c in rows[0] if c.startswith("probability_ge_")]
def first(r, a, b):
    ts = [float(r[c]) for c in (a, b) if float(r[c]) >= 0]
    return min(ts) if ts else -1.0
def fits(a, b):
    return all(abs(first(r, a, b) - float(r["first_alarm_s"])) <= 0.006 for r in rows
               if float(r["first_alarm_s"]) >= 0 or r["collapsed"] == "0")
assert any(float(r["first_alarm_s"]) >= 0 for r in rows)
assert any(fits(a, b) for a in risk for b in probability)
PY
expect_failure "a negative raise hold" "--raise-hold" -- run "${SMALL[@]}" --raise-hold -1 \
  --out x.csv

expect_success "shard 1/2" run "${SMALL[@]}" --shard 1/2 --out s1.csv
expect_success "shard 2/2" run "${SMALL[@]}" --shard 2/2 --out s2.csv
expect_success "merge" merge --out merged.csv s1.csv s2.csv
ok_if "the shards hold the runs of the whole" \
  bash -c 'diff <(tail -n +2 all.csv | sort) <(tail -n +2 merged.csv | sort) >/dev/null'

expect_success "report" report all.csv --json report.json
mv "$TMP/stdout" report.txt
ok_if "the report's alarm counts are the rows'" python3 - all.csv report.json <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
report = json.load(open(sys.argv[2]))
assert report["runs"] == len(rows)
alarm = [l for l in report["levels"] if l["level"] == "alarm"][0]["shown"]
collapses = [r for r in rows if r["collapsed"] == "1"]
quiet = [r for r in rows if r["collapsed"] == "0" and float(r["peak_ratio"]) < 0.5]
hits = [r for r in collapses
        if 0 <= float(r["first_alarm_s"]) < float(r["collapse_time_s"])]
false_alarms = [r for r in quiet if float(r["first_alarm_s"]) >= 0]
assert alarm["collapses"] == len(collapses), (alarm, len(collapses))
assert alarm["hits"] == len(hits) and alarm["misses"] == len(collapses) - len(hits)
assert alarm["quiet_runs"] == len(quiet) and alarm["false_alarms"] == len(false_alarms)
PY
# report --frontier: the best rule each of the alarm's constraints allows. Its "no miss" rule is the
# fewest false alarms of every rule that misses nothing (a brute force over the file's columns
# here), at least as good as the report's choice, and that choice's rate when the report found
# no rule within the alarm's target (safety first picks the same rule).
expect_success "report with the frontier" report all.csv --frontier --json frontier.json
ok_if "the frontier is in the text" grep -q "^frontier: the fewest false alarms of the rules on \
nominal_risk and probability" "$TMP/stdout"
ok_if "the frontier's no-miss rule is the best one" python3 - all.csv frontier.json <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
report = json.load(open(sys.argv[2]))
collapses = [r for r in rows if r["collapsed"] == "1"]
quiet = [r for r in rows if r["collapsed"] == "0" and float(r["peak_ratio"]) < 0.5]
def first(r, columns):
    ts = [float(r[c]) for c in columns if float(r[c]) >= 0]
    return min(ts) if ts else -1.0
def misses(columns):
    return sum(1 for r in collapses
               if not 0 <= first(r, columns) < float(r["collapse_time_s"]))
def rate(columns):
    return sum(1 for r in quiet if first(r, columns) >= 0) / len(quiet)
for signal in ("risk", "nominal_risk"):
    risk = [c for c in rows[0] if c.startswith(signal + "_ge_")] + [None]
    probability = [c for c in rows[0] if c.startswith("probability_ge_")] + [None]
    rules = [[c for c in (a, b) if c] for a in risk for b in probability if a or b]
    best = min(rate(r) for r in rules if misses(r) == 0)
    row = [x for x in report["frontier"][signal] if x["constraint"] == "no miss"][0]
    assert row["outcome"]["misses"] == 0, row
    assert abs(row["outcome"]["false_alarm_rate"] - best) < 1e-4, (signal, row, best)
alarm = [l for l in report["levels"] if l["level"] == "alarm"][0]["all_records"]
frontier = [x for x in report["frontier"]["risk"] if x["constraint"] == "no miss"][0]["outcome"]
if alarm["outcome"]["misses"] == 0:
    assert frontier["false_alarm_rate"] <= alarm["outcome"]["false_alarm_rate"], (frontier, alarm)
if not alarm["meets_target"]:
    assert frontier["false_alarm_rate"] == alarm["outcome"]["false_alarm_rate"], (frontier, alarm)
PY
# Issue 24's row: the longest median lead of the rules that miss nothing within 9 % unneeded
# alarms (margin >= 2, or a bound >= 2 where the case stood; a brute force over the columns), or
# none when no rule is within.
ok_if "the frontier's 9 % row is the longest lead within it" python3 - all.csv frontier.json <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
report = json.load(open(sys.argv[2]))
assert report["false_alarm"] == "margin"
collapse = {}
for r in rows:
    key = (r["record"], r["scene"], r["statue"], r["seed"])
    if r["collapsed"] == "1":
        collapse[key] = min(collapse.get(key, 9.0), float(r["scale_g"]))
def margin(r):
    key = (r["record"], r["scene"], r["statue"], r["seed"])
    return collapse.get(key, float(r["pga_to_g"])) / float(r["scale_g"])
collapses = [r for r in rows if r["collapsed"] == "1"]
unneeded = [r for r in rows if r["collapsed"] == "0" and margin(r) >= 2 * (1 - 1e-9)]
def first(r, columns):
    ts = [float(r[c]) for c in columns if float(r[c]) >= 0]
    return min(ts) if ts else -1.0
def median(values):  # type 7, as the report's
    v = sorted(values)
    p = 0.5 * (len(v) - 1)
    k = int(p)
    return v[k] + (p - k) * (v[min(k + 1, len(v) - 1)] - v[k])
risk = [c for c in rows[0] if c.startswith("risk_ge_")] + [None]
probability = [c for c in rows[0] if c.startswith("probability_ge_")] + [None]
best = None
for rule in ([c for c in (a, b) if c] for a in risk for b in probability if a or b):
    t = [first(r, rule) for r in collapses]
    if not all(0 <= x < float(r["collapse_time_s"]) for x, r in zip(t, collapses)):
        continue
    if sum(1 for r in unneeded if first(r, rule) >= 0) > 0.09 * len(unneeded):
        continue
    lead = median([float(r["collapse_time_s"]) - x for x, r in zip(t, collapses)])
    best = lead if best is None else max(best, lead)
row = [x for x in report["frontier"]["risk"]
       if x["constraint"] == "no miss, false alarms <= 9 %: longest lead"][0]
if best is None:
    assert row["rule"] is None, row
else:
    assert row["outcome"]["misses"] == 0 and row["outcome"]["unneeded_rate"] <= 0.09, row
    assert abs(row["outcome"]["lead_median_s"] - best) < 1e-3, (row, best)
PY
ok_if "the report names the two folds" grep -q "fold 2: chosen" report.txt

# The collapse margin (docs/forecast.md): each row names its case's seed and grid, and the report's
# unneeded alarms and margin bands are recounted here from the rows: a case's lowest collapsing
# PGA over the run's PGA, or the grid's top over it (a bound from below) when the case stood.
ok_if "each row names its case's seed and grid" python3 - all.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
columns = ("seed", "pga_from_g", "pga_to_g", "pga_steps")
assert all(tuple(r[c] for c in columns) == ("2026", "0.3", "1.5", "4") for r in rows), rows[0]
PY
ok_if "the report's margins are the rows'" python3 - all.csv report.json <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
report = json.load(open(sys.argv[2]))
assert report["false_alarm"] == "margin" and report["margins_known"]
collapse = {}
for r in rows:
    key = (r["record"], r["scene"], r["statue"], r["seed"])
    if r["collapsed"] == "1":
        collapse[key] = min(collapse.get(key, 9.0), float(r["scale_g"]))
floors = [1.0, 1.25, 1.5, 2.0, 3.0]
known = [[0, 0, 0] for _ in floors]
lower = [[0, 0, 0] for _ in floors[:-1]]
for r in rows:
    if r["collapsed"] == "1":
        continue
    key = (r["record"], r["scene"], r["statue"], r["seed"])
    bounded = key not in collapse
    margin = (float(r["pga_to_g"]) if bounded else collapse[key]) / float(r["scale_g"])
    band = max(i for i, f in enumerate(floors) if margin >= f * (1 - 1e-9))
    count = lower[band] if bounded and band < 4 else known[band]
    count[0] += 1
    count[1] += float(r["first_alarm_s"]) >= 0
    count[2] += float(r["peak_ratio"]) < 0.5
alarm = [l for l in report["levels"] if l["level"] == "alarm"][0]
bands = alarm["shown_by_margin"]
assert [[b["runs"], b["alarms"], b["quiet"]] for b in bands["bands"]] == known, (bands, known)
assert [[b["runs"], b["alarms"], b["quiet"]] for b in bands["lower_bound_only"]] == lower, lower
unneeded = [known[3][i] + known[4][i] + lower[3][i] for i in (0, 1)]
shown = alarm["shown"]
assert [shown["unneeded_runs"], shown["unneeded_alarms"]] == unneeded, (shown, unneeded)
assert shown["margin_unknown_runs"] == sum(c[0] for c in lower[:3])
assert sum(c[0] for c in known) + sum(c[0] for c in lower) == \
    sum(1 for r in rows if r["collapsed"] == "0")  # every run that stood, counted once
PY
ok_if "the text names the bands" grep -q "by collapse margin (runs that stood): 1-1.25: " report.txt
expect_success "report counting alarms in quiet runs" report all.csv --false-alarm peak \
  --json peak.json
ok_if "the peak report says so" python3 -c '
import json, sys
r = json.load(open("peak.json"))
assert r["false_alarm"] == "peak" and r["margins_known"], r["false_alarm"]'
expect_failure "an unknown false alarm" "--false-alarm: expected margin or peak" -- report \
  all.csv --false-alarm loud

# report --calibrate-on: each level's rule chosen on another file (here shard 1, as its own report
# chooses it on all its records), and that rule on this file's rows (shard 2, recounted here).
expect_success "report on shard 1" report s1.csv --json s1.json
expect_success "report on shard 2 calibrated on shard 1" report s2.csv --calibrate-on s1.csv \
  --json s2-cal.json
ok_if "the rule chosen on one file is scored on the other" \
  python3 - s1.json s2-cal.json s2.csv <<'PY'
import csv, json, sys
own = json.load(open(sys.argv[1]))
report = json.load(open(sys.argv[2]))
rows = list(csv.DictReader(open(sys.argv[3])))
for mine, theirs in zip(own["levels"], report["levels"]):
    elsewhere = theirs["calibrated_elsewhere"]
    assert elsewhere["rule"] == mine["all_records"]["rule"], (elsewhere, mine["all_records"])
    assert elsewhere["calibration"] == mine["all_records"]["outcome"]
columns = []
for part in report["levels"][2]["calibrated_elsewhere"]["rule"].split(" or "):
    signal, value = part.split(" >= ")
    columns += [c for c in rows[0] if c.startswith(signal + "_ge_")
                and abs(float(c.split("_ge_")[1]) - float(value)) < 1e-3]
def first(r):
    ts = [float(r[c]) for c in columns if float(r[c]) >= 0]
    return min(ts) if ts else -1.0
held_out = report["levels"][2]["calibrated_elsewhere"]["held_out"]
collapses = [r for r in rows if r["collapsed"] == "1"]
assert held_out["misses"] == sum(1 for r in collapses
                                 if not 0 <= first(r) < float(r["collapse_time_s"]))
quiet = [r for r in rows if r["collapsed"] == "0" and float(r["peak_ratio"]) < 0.5]
assert held_out["false_alarms"] == sum(1 for r in quiet if first(r) >= 0)
PY

# A runs file of a plinth-eval before the margin (no seed and grid columns): reported with the
# peak alone, refused for the margin and the fragility with what to do.
python3 - all.csv old.csv <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
with open(sys.argv[2], "w", newline="") as out:
    csv.writer(out, lineterminator="\n").writerows([r[:10] + r[15:] for r in rows])  # neither model_valid_until_s nor the grid
PY
expect_failure "an earlier file is refused for the margin" "old.csv" "no seed and pga grid" \
  "--false-alarm peak" -- report old.csv
expect_success "an earlier file reported with the peak" report old.csv --false-alarm peak
ok_if "without margins, says so" grep -q "collapse margins: not in this file" "$TMP/stdout"
expect_failure "an earlier file has no fragility" "old.csv" "no seed and pga grid" -- \
  fragility old.csv
expect_failure "merging an earlier file with a new one" "pga grid columns" -- merge --out m.csv \
  all.csv old.csv
expect_failure "calibrating on an earlier file" \
  "old.csv \\(--calibrate-on\\): no seed and pga grid" -- \
  report all.csv --calibrate-on old.csv
# A case with a row missing: its rows must run up the grid from its first point.
python3 - all.csv short.csv <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
standing = [i for i, r in enumerate(rows[1:], 1) if r[4] == "0" and r[3] == "0.3"]
del rows[standing[0]]
with open(sys.argv[2], "w", newline="") as out:
    csv.writer(out, lineterminator="\n").writerows(rows)
PY
expect_failure "a case with a row missing" \
  "short.csv: case .*no row at 0.3 g, below its rows at higher PGA" -- report short.csv
mkdir -p a b
cp "$AT2" a/r.AT2
cp "$SRC/sim/data/records/eval/RSN1605_DUZCE_DZC270.AT2" b/r.AT2
expect_failure "two records of one name" "--record: two files named r.AT2" -- run \
  --scene "$EVAL_SCENES/isolated.toml" --record a/r.AT2 --record b/r.AT2 --out x.csv

# plinth-eval fragility: per scene its cases and collapses, as the rows count them, and each
# fitted curve a maximum of the likelihood (recomputed here, interval-censored on the grid).
expect_success "fragility" fragility all.csv --json fragility.json
ok_if "the fragility's counts are the rows', its fits maxima" \
  python3 - all.csv fragility.json <<'PY'
import csv, json, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
fits = json.load(open(sys.argv[2]))
cases = {}
for r in rows:
    key = (r["record"], r["scene"], r["statue"], r["seed"])
    c = cases.setdefault(key, [r["scene"], None, float(r["pga_from_g"]), float(r["pga_to_g"]),
                               int(r["pga_steps"])])
    if r["collapsed"] == "1" and (c[1] is None or float(r["scale_g"]) < c[1]):
        c[1] = float(r["scale_g"])
assert sorted(f["scene"] for f in fits) == sorted({c[0] for c in cases.values()})
assert any(f["median_g"] is not None for f in fits)  # these runs allow a fit (else no check)
def cdf(z): return 0.5 * math.erfc(-z / math.sqrt(2))
for f in fits:
    mine = [c for c in cases.values() if c[0] == f["scene"]]
    assert f["cases"] == len(mine) and f["collapsed"] == sum(c[1] is not None for c in mine), f
    assert f["censored_at_g"] == 1.5
    if f["median_g"] is None:
        assert f["no_fit"], f
        continue
    def ll(median, beta):
        total = 0.0
        for _, at, lo, top, steps in mine:
            step = (top - lo) / (steps - 1)
            if at is None:
                total += math.log(1 - cdf(math.log(top / median) / beta))
            else:
                below = at - step
                p = cdf(math.log(at / median) / beta) - (
                    cdf(math.log(below / median) / beta) if below > 1e-9 else 0.0)
                total += math.log(p)
        return total
    best = ll(f["median_g"], f["beta"])
    assert abs(best - f["log_likelihood"]) < 1e-3, (best, f)
    for dm, db in ((1.02, 1), (0.98, 1), (1, 1.02), (1, 0.98)):
        assert ll(f["median_g"] * dm, f["beta"] * db) < best, (f, dm, db)
PY
ok_if "the fragility text names every scene" bash -c \
  'grep -q "^isolated.toml: " "$0" && grep -q "^ground-slender.toml: " "$0"' "$TMP/stdout"
expect_failure "an unknown collapse intensity" "--collapse-intensity: expected interval or grid" \
  -- fragility all.csv --collapse-intensity midpoint

if command -v gnuplot >/dev/null 2>&1; then
  expect_success "the ROC as a PNG" report all.csv --plot roc.png
  ok_if "the PNG is a PNG" bash -c '[[ "$(head -c 4 roc.png | tail -c 3)" == PNG ]]'
  # A file name that would be gnuplot code if it reached gnuplot: it does not.
  hostile=$'x\'\nsystem "touch pwned"\n#.png'
  expect_success "a hostile plot name is only a name" report all.csv --plot "$hostile"
  ok_if "no command ran" test ! -e pwned
  ok_if "the hostile name holds the PNG" test -s "$hostile"
  expect_success "the fragility as a PNG" fragility all.csv --plot fragility.png
  ok_if "the fragility PNG is a PNG" bash -c '[[ "$(head -c 4 fragility.png | tail -c 3)" == PNG ]]'
  # A scene whose file name would be gnuplot code reaches the legend as plain characters.
  python3 - all.csv hostile.csv <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
for r in rows[1:]:
    r[1] = r[1].replace("isolated.toml", "x'; system \"touch pwned2\"; print '.toml")
with open(sys.argv[2], "w", newline="") as out:
    csv.writer(out, lineterminator="\n").writerows(rows)
PY
  expect_success "a hostile scene name in the fragility plot" fragility hostile.csv \
    --plot hostile.png
  ok_if "no command ran from the scene name" test ! -e pwned2
else
  expect_failure "a missing gnuplot is named" "gnuplot" -- report all.csv --plot roc.png
fi

# The statue sensor's accelerometer on a statue that slides (ground-slender with [friction]
# 0.2 / 0.16: it slides, never rocks): the measured phase leaves full contact (advisory) in
# runs whose truth moved, never before the truth's first motion, never in a run that stayed.
{ cat "$EVAL_SCENES/ground-slender.toml"; printf '\n[friction]\nstatic = 0.2\nkinetic = 0.16\n'; } \
  >ground-sliding.toml
expect_success "a sliding statue with the statue sensor" run --scene ground-sliding.toml \
  "${RECORDS[@]}" --statues 2 --pga-from 0.3g --pga-to 1.5g --pga-steps 4 --jobs 2 \
  --statue-sensor --out sliding.csv --motion-out sliding-motion.csv
ok_if "the accelerometer's sliding: advisories after the truth's first motion only" \
  python3 - sliding-motion.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
raised = [r for r in rows if float(r["first_advisory_s"]) >= 0]
assert len(rows) == 16 and len(raised) >= 4, (len(rows), len(raised))
for r in raised:
    assert 0 <= float(r["first_motion_s"]) <= float(r["first_advisory_s"]), r
assert all(float(r["first_alarm_s"]) < 0 for r in rows)
PY

expect_failure "no scene" "--scene" -- run --record "$AT2" --out x.csv
expect_failure "a scene that is not there" "nothing.toml" -- run --scene nothing.toml \
  "${RECORDS[@]}" --out x.csv
expect_failure "a PGA grid upside down" "--pga-to.*below --pga-from" -- run "${CASES[@]}" \
  --statues 2 --pga-from 1g --pga-to 0.5g --out x.csv
expect_failure "a PGA of zero" "--pga-from: must be above 0" -- run "${CASES[@]}" \
  --statues 2 --pga-from 0g --out x.csv
expect_failure "a grid of one point in steps" "--pga-steps: a grid from 1g to 1g has one point" \
  -- run "${CASES[@]}" --statues 2 --pga-from 1g --pga-to 1g --out x.csv
expect_failure "merging a file with itself" "merge \\(a case in two inputs\\?\\): case .*two rows" \
  -- merge --out m.csv all.csv all.csv
expect_failure "a PGA without a unit" "--pga-from" -- run "${CASES[@]}" --statues 2 \
  --pga-from 0.3 --out x.csv
expect_failure "too many statues" "--statues: expected 1 to 1000" -- run "${CASES[@]}" \
  --statues 0 --out x.csv
expect_failure "an unknown forecaster" "--forecast: expected" -- run "${SMALL[@]}" \
  --forecast crystal_ball --out x.csv
expect_failure "a bad shard" "--shard" -- run "${SMALL[@]}" --shard 3/2 --out x.csv
expect_failure "an output folder that does not exist" "cannot write" -- run "${SMALL[@]}" \
  --out /nonexistent/x.csv
printf 'record,scene\n' >bad.csv
expect_failure "a runs file that is not one" "bad.csv:1" -- report bad.csv
expect_failure "merging files of other grids" "threshold columns differ" -- merge --out m.csv \
  all.csv <(head -1 all.csv | sed 's/risk_ge_0.05,//; s/nominal_risk_ge_0.05,//')

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
