#!/usr/bin/env bash
# plinth-eval run --fault and fault-report as a user would (docs/safety.md, "Fault injection"),
# kept short: every class parsed and bad ones refused naming what is wrong; a short run per class
# on one bundled record, its truth the fault-free run's and its box changed by the fault only
# through the box's inputs (identity faults change nothing, a statue sensor on the plinth of a
# statue that never moves reads what the statue reads, stuck from the start is at rest, the
# onsets land where --fault-at says); the fault columns read back, older files read or refused
# naming why; and fault-report's arithmetic recounted from a hand-made runs file. Prints
# "ok - <name>" or "not ok - <name>: <why>" per check, then "N passed, M failed".
#
# Environment: PLINTH_EVAL, the plinth-eval binary; PLINTH_SOURCE_DIR, the repository root.
set -u

PLINTH_SIM=${PLINTH_EVAL:-}
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
EVAL_SCENES=$SRC/sim/scenes/eval
CASES=(--scene "$EVAL_SCENES/ground-slender.toml" --scene "$EVAL_SCENES/isolated.toml"
  --record "$SRC/sim/data/records/eval/RSN1605_DUZCE_DZC270.AT2" --statues 2
  --pga-from 0.2g --pga-to 0.6g --pga-steps 3 --jobs 2)

# --- The option: bad faults refused, naming what is wrong ---
bad_fault() {  # NAME PATTERN ARGS...
  local name=$1 pattern=$2
  shift 2
  expect_failure "$name" "$pattern" -- run "${CASES[@]}" --out x.csv "$@"
}
bad_fault "an unknown kind" "--fault: unknown kind .statue_asleep. \\(plinth-eval run --help" \
  --statue-sensor --fault statue_asleep
bad_fault "a parameter missing" "--fault: statue_gain needs its parameter" \
  --statue-sensor --fault statue_gain
bad_fault "a parameter where none is taken" "--fault: statue_at_rest takes no parameter, got .1." \
  --statue-sensor --fault statue_at_rest:1
bad_fault "an empty parameter" "--fault: statue_delay: an empty parameter" \
  --statue-sensor --fault statue_delay:
bad_fault "a gain of 0" "--fault: statue_gain: a gain above 0" --statue-sensor --fault statue_gain:0
bad_fault "a gain that is no number" "--fault: statue_gain: expected a number, got .half." \
  --statue-sensor --fault statue_gain:half
bad_fault "a delay out of range" "--fault: statue_delay \\(s\\): expected 0 to 10, got .20." \
  --statue-sensor --fault statue_delay:20
bad_fault "a bias out of range" "--fault: statue_bias \\(deg/s\\): expected -2000 to 2000" \
  --statue-sensor --fault statue_bias:1e4
bad_fault "an axis that is none" "--fault: statue_sign: expected the axis x, y or z, got .w." \
  --statue-sensor --fault statue_sign:w
bad_fault "a ground gain on no axis" "--fault: ground_gain gain: expected the axis x, y or z" \
  --fault ground_gain:q=0.5
bad_fault "a heading out of range" "--fault: ground_heading heading \\(deg\\): expected -360 to" \
  --fault ground_heading:400
bad_fault "a pair's unknown fault" "--fault: ground_pair_primary: expected gain:... or heading:" \
  --fault ground_pair_primary:tilt:3
bad_fault "a pair without its fault" "--fault: ground_pair_second: expected gain:G" \
  --fault ground_pair_second:gain
bad_fault "a statue sensor's fault without one" \
  "statue_at_rest: a fault of the statue sensor needs --statue-sensor" \
  --fault statue_at_rest
bad_fault "a restart without a time" "--fault restart: needs --fault-at" --fault restart
bad_fault "a restart's downtime out of range" "--fault: restart downtime \\(s\\): expected 0 to" \
  --fault restart:-1 --fault-at 3
bad_fault "--fault-at without a fault" "--fault-at: says when the fault begins, and no --fault" \
  --fault-at motion
bad_fault "an onset before the alarm that times it" "--fault-at: alarm-1: a fault cannot begin" \
  --fault reset --fault-at alarm-1
bad_fault "an onset that is none" "--fault-at: expected start, a time in s, or strong, motion" \
  --fault reset --fault-at soon
bad_fault "a negative onset" "--fault-at: a time from the record's start, s, expected 0 to 1e6" \
  --fault reset --fault-at -3
bad_fault "an anchor's offset that is no number" "--fault-at: motion: expected \\+S or -S" \
  --fault restart --fault-at motion+x

# --- A short run per class ---
expect_success "the box without the statue sensor" run "${CASES[@]}" --out base.csv
expect_success "the box with the statue sensor" run "${CASES[@]}" --statue-sensor \
  --out base-s.csv --motion-out motion.csv
# Each class: a run, then its truth is the fault-free run's, its fault columns say which, and its
# box (levels, crossings, trouble) differs from the fault-free box's in some run.
check_class() {  # NAME BASE ARGS...
  local name=$1 base=$2
  shift 2
  expect_success "$name runs" run "${CASES[@]}" --out "$name.csv" "$@"
  ok_if "$name: the same truth, its fault named, its box changed" \
    python3 - "$base" "$name.csv" "$@" <<'PY'
import csv, sys
base = list(csv.DictReader(open(sys.argv[1])))
runs = list(csv.DictReader(open(sys.argv[2])))
args = sys.argv[3:]
kind, _, param = args[args.index("--fault") + 1].partition(":")
at = args[args.index("--fault-at") + 1] if "--fault-at" in args else "start"
truth = ["record", "scene", "statue", "scale_g", "collapsed", "collapse_time_s", "peak_ratio"]
assert [[r[c] for c in truth] for r in runs] == [[r[c] for c in truth] for r in base]
assert all((r["fault"], r["fault_param"], r["fault_at"], r["runs_written"]) ==
           (kind, param, at, "all") for r in runs), runs[0]
box = [c for c in base[0] if c not in truth and not c.startswith("fault")
       and c != "first_fault_trouble_s"]
assert any(r[c] != b[c] for r, b in zip(runs, base) for c in box), "the fault changed nothing"
PY
}
for fault in statue_at_rest statue_gain:0.5 statue_gain:57.3 statue_axes_swapped statue_sign:y \
  statue_delay:0.1 statue_neighbour statue_on_plinth; do
  check_class "${fault//:/_}" base-s.csv --statue-sensor --fault "$fault"
done
check_class statue_stuck base-s.csv --statue-sensor --fault statue_stuck --fault-at motion
check_class statue_bias base-s.csv --statue-sensor --fault statue_bias:10 --fault-at motion
check_class statue_dropout base-s.csv --statue-sensor --fault statue_dropout:2 --fault-at motion
for fault in ground_gain:0.5 ground_gain:z=0.5 ground_heading:90 ground_pair_primary:heading:90; do
  check_class "${fault//:/_}" base.csv --fault "$fault"
done
check_class restart base.csv --fault restart:1 --fault-at motion
check_class reset base.csv --fault reset --fault-at motion

# What the fault does, from outside: it begins where --fault-at says (one sample after its
# anchor at most); a restart's box is not calibrated at once, and says so (not_calibrated or
# restored) from the restart on; a silent statue sensor is named.
ok_if "the onsets: motion, alarm+0.1, 3 s and the box's start" \
  python3 - motion.csv statue_stuck.csv restart.csv <<'PY'
import csv, sys
motion = {(r["scene"], r["statue"], r["scale_g"]): float(r["first_motion_s"])
          for r in csv.DictReader(open(sys.argv[1]))}
for name in sys.argv[2:]:
    for r in csv.DictReader(open(name)):
        m = motion[(r["scene"], r["statue"], r["scale_g"])]
        if m < 0:
            assert r["fault_began_s"] == "", r
        else:
            assert 0 <= float(r["fault_began_s"]) - m <= 0.005 + 1e-9, (m, r)
PY
expect_success "a reset after the alarm" run "${CASES[@]}" --fault reset --fault-at alarm+0.1 \
  --out reset-alarm.csv
expect_success "a drop-out from 3 s" run "${CASES[@]}" --statue-sensor --fault statue_dropout:1000 \
  --fault-at 3 --out dropout3.csv
expect_success "a gain from the box's start" run "${CASES[@]}" --fault ground_gain:0.5 --out g.csv
ok_if "the onsets where they were asked for" python3 - reset-alarm.csv dropout3.csv g.csv <<'PY'
import csv, sys
for r in csv.DictReader(open(sys.argv[1])):
    alarm = float(r["first_alarm_s"])
    if alarm < 0:
        assert r["fault_began_s"] == "", r
    else:
        assert 0 <= float(r["fault_began_s"]) - (alarm + 0.1) <= 0.005 + 1e-9, r
for r in csv.DictReader(open(sys.argv[2])):
    assert abs(float(r["fault_began_s"]) - 3) <= 0.005, r
    assert float(r["first_statue_fault_s"]) >= 3, r  # the box names the silent sensor
    assert float(r["first_fault_trouble_s"]) >= 3 and r["fault_trouble_at_end"] == "1", r
starts = {r["fault_began_s"] for r in csv.DictReader(open(sys.argv[3]))}
assert len(starts) == 1 and float(starts.pop()) < -2, starts  # in the box's quiet lead-in
PY
ok_if "a restart's box says it is not calibrated from the restart on" python3 - restart.csv <<'PY'
import csv, sys
began = 0
for r in csv.DictReader(open(sys.argv[1])):
    if r["fault_began_s"] == "":
        continue
    began += 1
    assert float(r["first_fault_trouble_s"]) >= float(r["fault_began_s"]), r
    assert r["first_fault_trouble_s"] != "-1", r
assert began >= 4, began
PY

# Identity faults, and a fault that begins after the run, change nothing of the box; a sensor
# stuck from the box's start is one at rest; a statue sensor on the plinth of a statue that never
# left full contact reads what the statue reads (the base's motion, on the ground and on an
# isolated base).
same_box() {  # A B [only runs that never moved]
  python3 - "$1" "$2" "${3:-}" motion.csv <<'PY'
import csv, sys
a = list(csv.DictReader(open(sys.argv[1])))
b = list(csv.DictReader(open(sys.argv[2])))
still = {(r["scene"], r["statue"], r["scale_g"]) for r in csv.DictReader(open(sys.argv[4]))
         if r["first_motion_s"] == "-1"}
assert len(a) == len(b)
skip = {"fault", "fault_param", "fault_at", "fault_began_s", "first_fault_trouble_s",
        "fault_trouble_at_end"}
compared = 0
for x, y in zip(a, b):
    if sys.argv[3] and (x["scene"], x["statue"], x["scale_g"]) not in still:
        continue
    compared += 1
    differ = [c for c in x if c not in skip and x[c] != y[c]]
    assert not differ, (x["scene"], x["statue"], x["scale_g"], differ)
assert compared >= 4, compared
PY
}
for identity in "statue_gain:1" "statue_bias:0 --fault-at motion" "statue_delay:0" \
  "statue_stuck --fault-at 1000"; do
  name=identity_$(echo "$identity" | cut -d' ' -f1 | tr ':' '_')
  # shellcheck disable=SC2086  # the fault and its onset, split
  expect_success "$identity runs" run "${CASES[@]}" --statue-sensor --fault $identity \
    --out "$name.csv"
  ok_if "$identity changes nothing of the box" same_box base-s.csv "$name.csv"
done
for identity in "ground_gain:1" "ground_heading:0" "ground_pair_second:gain:1" \
  "ground_pair_primary:heading:0" "restart --fault-at 1000"; do
  name=identity_$(echo "$identity" | cut -d' ' -f1 | tr ':' '_')
  # shellcheck disable=SC2086
  expect_success "$identity runs" run "${CASES[@]}" --fault $identity --out "$name.csv"
  ok_if "$identity changes nothing of the box" same_box base.csv "$name.csv"
done
expect_success "stuck from the box's start" run "${CASES[@]}" --statue-sensor --fault statue_stuck \
  --out stuck-start.csv
ok_if "stuck from the start is at rest" same_box statue_at_rest.csv stuck-start.csv
ok_if "on the plinth of a statue that never moved: what the statue reads" \
  same_box base-s.csv statue_on_plinth.csv still

# Collapses only: the box's rows where the truth collapsed, the same as in the full run; from a
# fault-free file's collapses, the same rows again.
expect_success "collapses only" run "${CASES[@]}" --statue-sensor --fault statue_neighbour \
  --collapses-only --out nb-collapses.csv
expect_success "collapses of a fault-free file" run "${CASES[@]}" --statue-sensor \
  --fault statue_neighbour --collapses-of base.csv --out nb-of.csv
ok_if "collapses only: the full run's collapse rows" \
  python3 - statue_neighbour.csv nb-collapses.csv nb-of.csv <<'PY'
import csv, sys
full = [r for r in csv.DictReader(open(sys.argv[1])) if r["collapsed"] == "1"]
only = list(csv.DictReader(open(sys.argv[2])))
assert len(only) == len(full) >= 3
for r, f in zip(only, full):
    assert r["runs_written"] == "collapses"
    assert {**r, "runs_written": "all"} == f, r
assert open(sys.argv[2]).read() == open(sys.argv[3]).read()
PY
expect_failure "report refuses collapses only" \
  "nb-collapses.csv: holds only the runs whose truth collapsed" \
  -- report nb-collapses.csv
expect_failure "fragility refuses collapses only" "holds only the runs whose truth collapsed" \
  -- fragility nb-collapses.csv
expect_failure "collapses of another seed" "base.csv: .* ran with --seed 2026 on another grid" \
  -- run "${CASES[@]}" --seed 3 --collapses-of base.csv --out x.csv
expect_success "shards of a fault run" run "${CASES[@]}" --statue-sensor --fault statue_on_plinth \
  --collapses-only --shard 1/2 --out p1.csv
expect_success "shard 2" run "${CASES[@]}" --statue-sensor --fault statue_on_plinth \
  --collapses-only --shard 2/2 --out p2.csv
expect_success "merged" merge --out p.csv p1.csv p2.csv
expect_failure "merging two faults" "merge: .*fault statue_neighbour.*not shards of one run" \
  -- merge --out m.csv p.csv nb-collapses.csv
expect_failure "merging a fault run with itself" "merge \\(a run in two inputs\\?\\)" \
  -- merge --out m.csv p1.csv p1.csv

# --- Older runs files: read by report without the fault block; fault-report names why not ---
python3 - base.csv old.csv <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
n = rows[0].index("fault")
with open(sys.argv[2], "w", newline="") as out:
    csv.writer(out, lineterminator="\n").writerows([r[:n] for r in rows])
PY
expect_success "a file without the fault block is reported" report old.csv
expect_failure "fault-report names a file without the fault block" \
  "old.csv: no fault columns .*before fault injection; run it again with this one \\(plinth [0-9]" \
  -- fault-report old.csv
expect_success "merging it with a new one" merge --out x.csv old.csv
expect_failure "merging it with a new one is refused" "fault columns" -- merge --out m.csv \
  base.csv old.csv

# --- fault-report's arithmetic on a hand-made file ---
python3 - <<'PY'
import csv
fixed = ["record", "scene", "statue", "scale_g", "collapsed", "collapse_time_s", "peak_ratio",
         "first_advisory_s", "first_warning_s", "first_alarm_s", "model_valid_until_s"]
block = ["fault", "fault_param", "fault_at", "fault_began_s", "first_fault_trouble_s",
         "fault_trouble_at_end", "first_statue_fault_s", "first_statue_unexplained_s",
         "level_at_end", "trouble_at_end", "runs_written"]
def row(name, collapse, alarm, trouble=0, level="alarm", cause="none", statue=(-1, -1),
        fault="statue_stuck", written="all", began=1.5):
    return [name, "s.toml", 0, 0.5, 1 if collapse >= 0 else 0, collapse,
            1 if collapse >= 0 else 0.1, -1, -1, alarm, -1,
            fault, "", "motion" if fault != "none" else "", began if fault != "none" else "",
            2 if trouble else -1, trouble, statue[0], statue[1], level, cause, written]
# With the fault: (collapse time, alarm time): a lost 0.2 s, b lost 1.0 s, c no alarm but the
# input named at the collapse, d silenced (a warning), e silenced (its alarm after the collapse),
# f alarmed where the other box did not; g and h stood, h with the statue's trouble.
faulted = [row("a", 8, 5), row("b", 8, 6), row("c", 8, -1, 1, "fault", "statue_sensor_fault"),
           row("d", 8, -1, 0, "warning"), row("e", 8, 9, 0, "warning"), row("f", 8, 4),
           row("g", -1, -1, level="normal"), row("h", -1, -1, level="normal", statue=(3, 4))]
against = [row("a", 8, 4.8, fault="none"), row("b", 8, 5, fault="none"),
           row("c", 8, 3, fault="none"), row("d", 8, 2, fault="none"),
           row("e", 8, -1, fault="none"), row("f", 8, -1, fault="none"),
           row("g", -1, -1, fault="none"), row("h", -1, -1, fault="none")]
for name, rows in (("faulted.csv", faulted), ("against.csv", against)):
    with open(name, "w", newline="") as out:
        w = csv.writer(out, lineterminator="\n")
        w.writerow(fixed + block)
        w.writerows(rows)
with open("other-truth.csv", "w", newline="") as out:
    w = csv.writer(out, lineterminator="\n")
    w.writerow(fixed + block)
    w.writerows(against[:1] + [row("b", 7.5, 5, fault="none")] + against[2:])
with open("mixed.csv", "w", newline="") as out:
    w = csv.writer(out, lineterminator="\n")
    w.writerow(fixed + block)
    w.writerows(faulted[:2] + [row("x", 8, 5, fault="statue_at_rest")])
PY
expect_success "fault-report" fault-report faulted.csv --against against.csv --json report.json
ok_if "fault-report's counts and lost lead" python3 - report.json "$TMP/stdout" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["classes"][0]
text = open(sys.argv[2]).read()
assert (r["fault"], r["at"], r["runs"], r["collapses"]) == ("statue_stuck", "motion", 8, 6), r
assert (r["alarmed"], r["named"], r["fault_began"]) == (3, 1, 6), r
assert [s["record"] for s in r["silenced"]] == ["d", "e"], r["silenced"]
assert r["level_at_collapse"] == {"alarm": 3, "fault": 1, "warning": 2}, r
assert (r["statue_trouble_runs"], r["statue_fault_runs"], r["statue_unexplained_runs"]) == (1, 1, 1)
a = r["against"]
assert (a["matched"], a["within"], a["both_alarmed"]) == (6, 3, 2), a
assert (a["only_other_alarmed"], a["only_this_alarmed"], a["neither_alarmed"]) == (2, 1, 1), a
assert abs(a["within_share"] - 0.5) < 1e-9 and abs(a["lost_median_s"] - 0.6) < 1e-9, a
assert abs(a["lost_max_s"] - 1.0) < 1e-9, a
assert "silenced: 2" in text and "within +0.5 s: 3 (50.0 %)" in text, text
assert "lost median 0.60 s" in text and "worst 1.00 s" in text, text
assert "silenced: d, s.toml, statue 0, 0.5 g: collapse at 8.000 s" in text, text
PY
expect_failure "another truth is refused" \
  "other-truth.csv: b, s.toml, statue 0, 0.5 g collapses at 7.5 s, in faulted.csv at 8 s" \
  -- fault-report faulted.csv --against other-truth.csv
expect_failure "a collapse the other file lacks" "base.csv: has no collapse at a, s.toml" \
  -- fault-report faulted.csv --against base.csv
expect_failure "two classes in one file" "mixed.csv: x, s.toml.*one class per file" \
  -- fault-report mixed.csv

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
