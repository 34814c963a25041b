#!/usr/bin/env python3
"""When the unneeded alarms are raised, against when the statue first moves (docs/forecast.md,
"The statue sensor"): a statue sensor measures nothing while the statue stands in full contact,
so an alarm raised before the statue's first motion is one its weights can only take away by
ruling out members that predict a motion that does not come.

    statue-alarm-timing.py RUNS.csv MOTION.csv [--level alarm] [--rule COLUMN ...]

RUNS.csv is a plinth-eval runs file (with its grid columns), MOTION.csv the same run's
--motion-out. An unneeded alarm is one raised in a run of collapse margin >= 2 (plinth-eval
report's definition: the case's lowest collapsing PGA over the run's; a case that never
collapsed has the lower bound grid top / PGA, and a run whose bound is below 2 is left out).
Prints the runs, the unneeded alarms, and how many of them were raised while the statue was
still in full contact (it never moved, or moved later), with the lead of the alarm over the
first motion. With --rule, the alarm is not the box's first_<level>_s but the earliest of the
named crossing columns (e.g. --rule risk_ge_1 probability_ge_0.0625: "risk >= 1 or probability
>= 0.0625", a rule of plinth-eval report --frontier, re-scored from the same runs); it also
prints the rule's missed collapses and median lead (misses as 0, the report's quantile). Runs
whose true statue lifted off (model_valid_until_s >= 0) count in no outcome, as in the report.
"""
import argparse
import csv
import statistics
import sys


def median_type7(values):
    """plinth-eval report's quantile (linear between order statistics) at one half."""
    v = sorted(values)
    if not v:
        return -1.0
    p = 0.5 * (len(v) - 1)
    k = int(p)
    return v[k] + (p - k) * (v[min(k + 1, len(v) - 1)] - v[k])


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs")
    p.add_argument("motion")
    p.add_argument("--level", default="alarm", choices=("advisory", "warning", "alarm"))
    p.add_argument("--rule", nargs="+", metavar="COLUMN",
                   help="crossing columns (risk_ge_*, probability_ge_*): alarm at the earliest")
    args = p.parse_args()
    key = lambda r: (r["record"], r["scene"], r["statue"], r["seed"])  # noqa: E731
    runs = list(csv.DictReader(open(args.runs)))
    if not runs or "pga_to_g" not in runs[0]:
        sys.exit(f"{args.runs}: not a plinth-eval runs file with its grid columns")
    columns = args.rule or [f"first_{args.level}_s"]
    for c in columns:
        if c not in runs[0]:
            sys.exit(f"{args.runs}: no column {c}")
    runs = [r for r in runs if float(r.get("model_valid_until_s", "-1")) < 0]

    def alarm_at(r):
        times = [float(r[c]) for c in columns if float(r[c]) >= 0]
        return min(times) if times else -1.0
    collapse = {}
    for r in runs:
        if r["collapsed"] == "1":
            g = float(r["scale_g"])
            collapse[key(r)] = min(g, collapse.get(key(r), g))
    motion = {(key(m), round(float(m["scale_g"]), 5)): m for m in csv.DictReader(open(args.motion))}
    eligible = unneeded = standing = 0
    leads = []
    for r in runs:
        if r["collapsed"] == "1":
            continue
        scale = float(r["scale_g"])
        if key(r) in collapse:
            margin = collapse[key(r)] / scale
        else:
            margin = float(r["pga_to_g"]) / scale
            if margin < 2:
                continue  # the grid cannot bound it
        if margin < 2:
            continue
        eligible += 1
        t_alarm = alarm_at(r)
        if t_alarm < 0:
            continue
        unneeded += 1
        m = motion.get((key(r), round(scale, 5)))
        if m is None:
            sys.exit(f"{args.motion}: no row for {key(r)} at {scale} g")
        t_move = float(m["first_motion_s"])
        if t_move < 0 or t_move > t_alarm:
            standing += 1
            if t_move >= 0:
                leads.append(t_move - t_alarm)
    share = 100.0 * standing / unneeded if unneeded else 0.0
    lead_s = []
    for r in runs:
        if r["collapsed"] == "1":
            t, t_collapse = alarm_at(r), float(r["collapse_time_s"])
            lead_s.append(t_collapse - t if 0 <= t < t_collapse else None)
    if args.rule:
        print(f"rule {' or '.join(columns)}: {lead_s.count(None)} of {len(lead_s)} collapses "
              f"missed, median lead {median_type7([x or 0.0 for x in lead_s]):.2f} s")
    print(f"{eligible} runs of margin >= 2; {unneeded} unneeded {args.level}s "
          f"({100.0 * unneeded / max(eligible, 1):.1f} %); {standing} of them ({share:.1f} %) "
          f"raised while the statue stood in full contact "
          f"({standing - len(leads)} never moved; the others moved a median "
          f"{statistics.median(leads) if leads else 0:.2f} s later)")


if __name__ == "__main__":
    main()
