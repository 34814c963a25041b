#!/usr/bin/env python3
"""When the unneeded alarms are raised, against when the statue first moves (docs/forecast.md,
"The statue sensor"): a statue sensor measures nothing while the statue stands in full contact,
so an alarm raised before the statue's first motion is one its weights can only take away by
ruling out members that predict a motion that does not come.

    statue-alarm-timing.py RUNS.csv MOTION.csv [--level alarm]

RUNS.csv is a plinth-eval runs file (with its grid columns), MOTION.csv the same run's
--motion-out. An unneeded alarm is one raised in a run of collapse margin >= 2 (plinth-eval
report's definition: the case's lowest collapsing PGA over the run's; a case that never
collapsed has the lower bound grid top / PGA, and a run whose bound is below 2 is left out).
Prints the runs, the unneeded alarms, and how many of them were raised while the statue was
still in full contact (it never moved, or moved later), with the lead of the alarm over the
first motion.
"""
import argparse
import csv
import statistics
import sys


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("runs")
    p.add_argument("motion")
    p.add_argument("--level", default="alarm", choices=("advisory", "warning", "alarm"))
    args = p.parse_args()
    key = lambda r: (r["record"], r["scene"], r["statue"], r["seed"])  # noqa: E731
    runs = list(csv.DictReader(open(args.runs)))
    if not runs or "pga_to_g" not in runs[0]:
        sys.exit(f"{args.runs}: not a plinth-eval runs file with its grid columns")
    collapse = {}
    for r in runs:
        if r["collapsed"] == "1":
            g = float(r["scale_g"])
            collapse[key(r)] = min(g, collapse.get(key(r), g))
    motion = {(key(m), round(float(m["scale_g"]), 5)): m for m in csv.DictReader(open(args.motion))}
    column = f"first_{args.level}_s"
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
        t_alarm = float(r[column])
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
    print(f"{eligible} runs of margin >= 2; {unneeded} unneeded {args.level}s "
          f"({100.0 * unneeded / max(eligible, 1):.1f} %); {standing} of them ({share:.1f} %) "
          f"raised while the statue stood in full contact "
          f"({standing - len(leads)} never moved; the others moved a median "
          f"{statistics.median(leads) if leads else 0:.2f} s later)")


if __name__ == "__main__":
    main()
