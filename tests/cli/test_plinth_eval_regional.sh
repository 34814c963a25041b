#!/usr/bin/env bash
# plinth-eval's simulated regional alerts as a user runs them (docs/regional.md, "Evaluation"),
# kept short: run --regional on --record-info writes the alert's columns (recomputed here from
# the record's strong motion, its row of stations.csv and the box's fragility rule); the alert
# changes nothing else of the run; the report's "Regional alerts" section is recounted from the
# CSV (the warning with the alert is the earlier of the box's and the alert's, when the alert's
# probability passes the threshold); and bad inputs end with exit code 1 or 2 and a message
# naming the problem. Prints "ok - <name>" or "not ok - <name>: <why>" per check, then
# "N passed, M failed".
#
# Environment: PLINTH_EVAL, the plinth-eval binary; PLINTH_SOURCE_DIR, the repository root.
set -u

PLINTH_SIM=${PLINTH_EVAL:-}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
# shellcheck source=tests/cli/eval_two_stations.sh
source "$SRC/tests/cli/eval_two_stations.sh"
INFO=$PW/stations.csv
CASES=("${GRID[@]}" --jobs 2)

# With the P-wave stage too: its strong_motion_s column is the S arrival the alert is built on.
expect_success "a run with regional alerts" run "${CASES[@]}" --pwave on --regional on \
  --record-info "$INFO" --out reg.csv
ok_if "the alert's columns: its times, its PGA and the room's probability recomputed" \
  python3 - reg.csv "$INFO" <<'PY'
import csv, math, sys
rows = list(csv.DictReader(open(sys.argv[1])))
info = {r["rsn"]: r for r in csv.DictReader(open(sys.argv[2]))}
assert rows and "regional_probability" in rows[0], list(rows[0])
phi = lambda z: 0.5 * math.erfc(-z / math.sqrt(2.0))
blind = {}
eps = set()
for r in rows:
    g = {k[len("regional_"):]: float(v) for k, v in r.items() if k.startswith("regional_")}
    station = info[r["record"][3:r["record"].index("_")]]
    assert g["magnitude"] == float(station["magnitude"]) and g["rhyp_km"] == float(station["rhyp_km"]), g
    # The S arrival is the record's strong motion; the origin Rhyp / 3.5 km/s before it.
    assert abs(g["s_arrival_s"] - float(r["strong_motion_s"])) < 1e-4, (g, r["strong_motion_s"])
    assert abs(g["s_arrival_s"] - g["origin_s"] - g["rhyp_km"] / 3.5) < 1e-4, g
    assert g["alert_s"] - g["origin_s"] >= 3.0 - 1e-9, g   # the latency's floor
    assert abs(g["sigma_ln"] - math.log(2.0)) < 1e-5, g
    eps.add(round(math.log(g["pga_g"] / float(r["scale_g"])), 4))
    # The box's rule: Phi(ln(PGA / median) / sqrt(beta^2 + sigma^2)), median 0.8 g, beta 0.3.
    p = phi(math.log(g["pga_g"] / 0.8) / math.sqrt(0.09 + g["sigma_ln"] ** 2))
    assert abs(p - g["probability"]) < 1e-4, (p, g)
    blind.setdefault(r["record"], set()).add(g["alert_s"] >= g["s_arrival_s"])
assert len(eps) > 5, eps  # drawn per run
assert blind["RSN990_NORTHR_LAC090.AT2"] == {False}, blind   # 42.9 km: 12.3 s of S travel
PY

expect_success "the same run without them" run "${CASES[@]}" --pwave on --out off.csv
ok_if "the alert changes nothing else: the same truth, box and stage" python3 - reg.csv off.csv <<'PY'
import csv, sys
a = list(csv.DictReader(open(sys.argv[1])))
b = list(csv.DictReader(open(sys.argv[2])))
assert len(a) == len(b)
assert not any(k.startswith("regional_") for k in b[0])
for x, y in zip(a, b):
    for k in y:
        assert x[k] == y[k], (k, x[k], y[k])
PY
expect_success "the same run again" run "${GRID[@]}" --jobs 1 --pwave on --regional on \
  --record-info "$INFO" --out again.csv
ok_if "the alerts are drawn the same in another run (seeded per run)" cmp -s reg.csv again.csv

expect_success "the report of a run with regional alerts" report reg.csv
cp "$TMP/stdout" report.txt
ok_if "the report's regional section, recounted from the rows" \
  env PYTHONPATH="$SRC/tools" python3 - reg.csv report.txt <<'PY'
import csv, re, sys
from warning_recount import score as recount
rows = list(csv.DictReader(open(sys.argv[1])))
text = open(sys.argv[2]).read()
section = text[text.index("Regional alerts (warning"):]
def warning_time(r, p):
    t = float(r["first_warning_s"])
    if p is not None and float(r["regional_probability"]) >= p:
        a = max(0.0, float(r["regional_alert_s"]))
        t = a if t < 0 else min(t, a)
    return t
def score(p, rhyp=None):
    keep = lambda r: not rhyp or rhyp[0] <= float(r["regional_rhyp_km"]) < rhyp[1]
    return recount(rows, lambda r: warning_time(r, p), keep)
lines = [l for l in section.splitlines() if re.match(r"^    (without|0\.\d)\s", l)]
assert len(lines) == 10, lines
for line in lines:
    key = line.split()[0]
    p = None if key == "without" else float(key)
    fields = line.split()
    got = [float(x) for x in fields[1:] if x != "/"]
    want_all, want_unneeded = score(p)
    assert abs(got[0] - want_all) < 0.006, (key, got, want_all)
    near, _ = score(p, (0, 25))
    mid, _ = score(p, (25, 50))
    assert abs(got[1] - near) < 0.006 and abs(got[2] - mid) < 0.006, (key, got, near, mid)
    assert abs(got[4] - want_unneeded) < 0.06, (key, got, want_unneeded)
blind = sum(float(r["regional_alert_s"]) >= float(r["regional_s_arrival_s"]) for r in rows)
m = re.search(r"blind zone \(at or after the S arrival\): (\d+)", section)
assert m and int(m.group(1)) == blind, (m and m.group(0), blind)
PY

expect_success "a report calibrated on another file" report reg.csv --regional-calibrate-on reg.csv
ok_if "it says where the threshold was chosen" grep -Eq "(chosen |\()on the calibration file" \
  "$TMP/stdout"

# tools/warning-inputs.py: the box with both early inputs warns at the earliest of its own
# warning, the stage's crossing and the alert (at 0 s when before the record).
python3 "$SRC/tools/warning-inputs.py" reg.csv --pwave 0.5 --regional 0.5 > inputs.txt 2> inputs.err
ok_if "warning-inputs.py: each input alone and both, recounted from the rows" \
  env PYTHONPATH="$SRC/tools" python3 - reg.csv inputs.txt <<'PY'
import csv, re, sys
from warning_recount import score
rows = list(csv.DictReader(open(sys.argv[1])))
text = open(sys.argv[2]).read()
def when(r, stage, alert):
    t = [float(r["first_warning_s"])]
    if stage:
        t.append(float(r["pwave_ge_0.5"]))
    if alert and float(r["regional_probability"]) >= 0.5:
        t.append(max(0.0, float(r["regional_alert_s"])))
    t = [x for x in t if x >= 0.0]
    return min(t) if t else -1.0
line = next(l for l in text.splitlines() if l.startswith("all records"))
cells = [tuple(map(float, c)) for c in re.findall(r"([\d.]+) /\s+([\d.]+) %", line)]
assert len(cells) == 4, line
for cell, (stage, alert) in zip(cells, [(0, 0), (1, 0), (0, 1), (1, 1)]):
    lead, unneeded = score(rows, lambda r: when(r, stage, alert))
    assert abs(cell[0] - lead) < 0.006 and abs(cell[1] - unneeded) < 0.06, (cell, lead, unneeded)
assert cells[3][0] >= max(cells[1][0], cells[2][0]) and cells[3][1] >= max(cells[1][1], cells[2][1])
assert cells[1] != cells[0] and cells[2] != cells[0], cells   # each input changes something here
PY
ok_if "warning-inputs.py refuses a file without the alerts' columns, naming one" \
  bash -c '! python3 "$0/tools/warning-inputs.py" off.csv 2> err.txt && grep -q "off.csv: no column regional_alert_s" err.txt' "$SRC"

printf 'rsn,earthquake,station,magnitude,rrup_km,rjb_km,rhyp_km,vs30_m_s\n990,N,LAC,6.69,36.62,35.03,42.88,365\n' \
  > one.csv
printf 'rsn,earthquake,station,magnitude,rrup_km,rjb_km,rhyp_km,vs30_m_s\n990,N,LAC,6.69,36.62,35.03,inf,365\n' \
  > bad.csv
expect_failure "--regional on needs --record-info" "--regional on needs --record-info" \
  -- run "${CASES[@]}" --regional on --out x.csv
expect_failure "a record without its row is named" "RSN1063_NORTHR_RRS228.AT2: no row for RSN 1063" \
  -- run "${CASES[@]}" --regional on --record-info one.csv --out x.csv
expect_failure "a bad row names file, line and field" "bad.csv:2: rhyp_km: not finite" \
  -- run "${CASES[@]}" --regional on --record-info bad.csv --out x.csv
expect_failure "--record-info without --regional on" "--record-info: .*--regional is off" \
  -- run "${CASES[@]}" --record-info "$INFO" --out x.csv
expect_failure "--regional is on or off" "--regional: expected on or off" \
  -- run "${CASES[@]}" --regional yes --record-info "$INFO" --out x.csv
expect_failure "a negative sigma" "--regional-sigma" \
  -- run "${CASES[@]}" --regional on --record-info "$INFO" --regional-sigma -1 --out x.csv
expect_failure "the alert needs the scene's fragility" "needs the scene's \[fragility\]" \
  -- run --scene no-fragility.toml "${STATIONS[@]}" --statues 1 --pga-steps 1 --regional on \
  --record-info "$INFO" --out x.csv
expect_failure "a calibration file without regional columns" "no regional columns" \
  -- report reg.csv --regional-calibrate-on off.csv

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
