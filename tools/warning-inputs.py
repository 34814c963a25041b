#!/usr/bin/env python3
"""The warning with both of the box's early inputs: the on-site P-wave stage and the regional
alerts (docs/pwave.md, docs/regional.md), from one runs file of
`plinth-eval run --pwave on --regional on --record-info ...`.

plinth-eval report scores each input alone, its threshold chosen on its own. The box ORs them
(alarm_policy.h: warning_pwave, warning_regional), so a box with both warns at the earliest of its
own warning, the stage's crossing and the alert (counted at 0 s when it comes before the record,
as the regional report counts it). This prints, per record class of the P-wave report, the median
lead over the collapses and the unneeded warnings (margin >= 2) without either input, with each
alone and with both, at the thresholds given (default: the box's, 0.75 and 0.7).

--calibrate-on CAL.csv first chooses the pair on CAL.csv by the P-wave report's rule, applied to
both: the longest median lead on the records whose P wave comes >= 3 s before the strong motion,
the unneeded warnings of all records at most 5 points more than without either input (ties: the
fewer unneeded); then scores RUNS.csv at that pair.

    tools/warning-inputs.py held_both.csv --calibrate-on cal_both.csv
"""
import argparse
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from warning_recount import score  # noqa: E402

# The P-wave report's thresholds (the runs file's pwave_ge_* columns).
THRESHOLDS = ["0.01", "0.02", "0.05", "0.1", "0.15", "0.2", "0.25", "0.3", "0.35", "0.4", "0.45",
              "0.5", "0.55", "0.6", "0.65", "0.7", "0.75", "0.8", "0.85", "0.9", "0.95", "0.99"]
MAX_EXTRA_UNNEEDED_POINTS = 5.0  # issue 26's allowance, as the reports choose
CLASSES = [("all records", lambda r: True),
           ("P >= 3 s before the strong motion", lambda r: pwave_class(r) == 0),
           ("P < 3 s before it (near the source)", lambda r: pwave_class(r) == 1),
           ("no P before it", lambda r: pwave_class(r) == 2)]


def fail(message):
    sys.exit(f"warning-inputs.py: {message}")


def pwave_class(r):
    """The P-wave report's classes (eval_pwave_report.cpp): 0 P >= 3 s, 1 P < 3 s, 2 no P."""
    pick = float(r["p_pick_s"])
    if pick < 0.0:
        return 2
    return 0 if float(r["strong_motion_s"]) - pick >= 3.0 else 1


def read(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    if not rows:
        fail(f"{path}: no runs")
    missing = [c for c in ("first_warning_s", "p_pick_s", "strong_motion_s",
                           "regional_alert_s", "regional_probability",
                           *("pwave_ge_" + t for t in THRESHOLDS)) if c not in rows[0]]
    if missing:
        fail(f"{path}: no column {missing[0]} (a run with --pwave on and --regional on?)")
    return rows


def earliest(*times):
    shown = [t for t in times if t >= 0.0]
    return min(shown) if shown else -1.0


def warning_time(r, pwave, regional):
    """The box's warning with the stage at p >= pwave and alerts at p >= regional (None: off)."""
    box = float(r["first_warning_s"])
    stage = float(r["pwave_ge_" + pwave]) if pwave is not None else -1.0
    alert = -1.0
    if regional is not None and float(r["regional_probability"]) >= float(regional):
        alert = max(0.0, float(r["regional_alert_s"]))
    return earliest(box, stage, alert)


def choose(rows):
    _, base = score(rows, lambda r: warning_time(r, None, None))
    early = CLASSES[1][1]
    best = None
    for p in THRESHOLDS:
        for q in THRESHOLDS:
            lead, _ = score(rows, lambda r: warning_time(r, p, q), early)
            _, unneeded = score(rows, lambda r: warning_time(r, p, q))
            if unneeded > base + MAX_EXTRA_UNNEEDED_POINTS:
                continue
            key = (lead, -unneeded)
            if best is None or key > best[0]:
                best = (key, p, q)
    if best is None:
        fail("no pair of thresholds keeps the unneeded warnings within 5 points")
    return best[1], best[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs")
    parser.add_argument("--pwave", default="0.75", choices=THRESHOLDS,
                        help="the stage's threshold (default 0.75, the box's)")
    parser.add_argument("--regional", default="0.7", choices=THRESHOLDS,
                        help="the alerts' threshold (default 0.7, the box's)")
    parser.add_argument("--calibrate-on", metavar="CAL.csv",
                        help="choose both thresholds on this file instead")
    args = parser.parse_args()
    rows = read(args.runs)
    p, q = args.pwave, args.regional
    if args.calibrate_on:
        p, q = choose(read(args.calibrate_on))
        print(f"chosen on {args.calibrate_on}: P-wave p >= {p}, regional p >= {q}")
    print(f"{args.runs}: {len(rows)} runs; median lead (s) / unneeded warnings (margin >= 2, %)")
    rules = [("without", None, None), (f"P-wave {p}", p, None), (f"regional {q}", None, q),
             ("both", p, q)]
    print(f"{'records':38s}" + "".join(f"{name:>20s}" for name, _, _ in rules))
    for label, keep in CLASSES:
        cells = []
        for _, pw, rg in rules:
            lead, unneeded = score(rows, lambda r: warning_time(r, pw, rg), keep)
            cells.append(f"{lead:6.2f} / {unneeded:5.1f} %")
        print(f"{label:38s}" + "".join(f"{c:>20s}" for c in cells))


if __name__ == "__main__":
    main()
