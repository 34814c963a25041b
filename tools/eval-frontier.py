#!/usr/bin/env python3
"""The best alarm rule a plinth-eval runs file allows under each of the alarm's targets.

A rule is "risk >= a or probability >= b" (either part may be absent), scored on the runs'
first-crossing columns exactly as `plinth-eval report` scores it (docs/forecast.md): a hit when
the rule fires before the collapse (lead = collapse time - first firing, 0 for a miss), a
false alarm when it fires in a quiet run (no collapse, peak below half the overturning angle).
For each constraint the rule with the fewest false alarms is printed: what the signals of the
file can do at best, whatever thresholds the box ships.

Usage: eval-frontier.py RUNS.csv [--signal risk|nominal_risk]
  --signal nominal_risk scores the nominal statue's risk instead of the worst member's.
"""
import argparse
import csv
import sys

QUIET_PEAK_RATIO = 0.5  # plinth::host::kQuietPeakRatio


def load(path):
    try:
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
    except OSError as e:
        sys.exit("eval-frontier: %s: %s" % (path, e.strerror))
    need = {"collapsed", "collapse_time_s", "peak_ratio"}
    if not rows or not need <= set(rows[0]):
        sys.exit("eval-frontier: %s: not a plinth-eval runs file (no %s)" % (path, sorted(need)))
    for line, row in enumerate(rows, start=2):
        for column, text in row.items():
            if column in ("record", "scene"):
                continue
            try:
                float(text)
            except (TypeError, ValueError):
                sys.exit("eval-frontier: %s:%d: %s: expected a number, got %r"
                         % (path, line, column, text))
    return rows


def score(collapses, quiet, risk, probability):
    def first(r):
        ts = [float(r[c]) for c in (risk, probability) if c and float(r[c]) >= 0.0]
        return min(ts) if ts else -1.0

    leads = []
    for r in collapses:
        t, collapse_s = first(r), float(r["collapse_time_s"])
        leads.append(collapse_s - t if 0.0 <= t < collapse_s else 0.0)
    misses = sum(1 for lead in leads if lead == 0.0)
    false_rate = sum(1 for r in quiet if first(r) >= 0.0) / max(1, len(quiet))
    return {"risk": risk, "probability": probability, "misses": misses,
            "false_rate": false_rate, "median": quantile(leads, 0.5), "p10": quantile(leads, 0.1)}


def quantile(values, q):
    """Linear interpolation between order statistics, as the report's lead_quantile."""
    if not values:
        return 0.0
    ordered = sorted(values)
    position = q * (len(ordered) - 1)
    below = int(position)
    above = min(below + 1, len(ordered) - 1)
    return ordered[below] + (position - below) * (ordered[above] - ordered[below])


def describe(rule):
    parts = [c.replace("_ge_", " >= ") for c in (rule["risk"], rule["probability"]) if c]
    return "%-48s %4d missed  false alarms %5.1f %%  lead median %.2f s, 10th pct %.2f s" % (
        " or ".join(parts), rule["misses"], 100.0 * rule["false_rate"], rule["median"], rule["p10"])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("runs")
    parser.add_argument("--signal", choices=["risk", "nominal_risk"], default="risk")
    args = parser.parse_args()
    rows = load(args.runs)
    risks = [c for c in rows[0] if c.startswith(args.signal + "_ge_")]
    probabilities = [c for c in rows[0] if c.startswith("probability_ge_")]
    collapses = [r for r in rows if r["collapsed"] == "1"]
    quiet = [r for r in rows
             if r["collapsed"] == "0" and float(r["peak_ratio"]) < QUIET_PEAK_RATIO]
    rules = [score(collapses, quiet, a, b) for a in risks + [None]
             for b in probabilities + [None] if a or b]
    print("%s: %d runs, %d collapses, %d quiet runs; %d rules on %s and probability"
          % (args.runs, len(rows), len(collapses), len(quiet), len(rules), args.signal))
    constraints = [
        ("no miss", lambda r: r["misses"] == 0),
        ("no miss, median lead >= 1.5 s", lambda r: r["misses"] == 0 and r["median"] >= 1.5),
        ("no miss, 10th pct lead >= 0.5 s", lambda r: r["misses"] == 0 and r["p10"] >= 0.5),
        ("no miss, median lead >= 3 s", lambda r: r["misses"] == 0 and r["median"] >= 3.0),
        ("false alarms <= 5 %, fewest misses", lambda r: r["false_rate"] <= 0.05),
        ("fewest false alarms, any misses", lambda r: True),
    ]
    for name, allowed in constraints:
        candidates = [r for r in rules if allowed(r)]
        if not candidates:
            print("%-36s none" % name)
            continue
        key = ((lambda r: (r["misses"], r["false_rate"])) if "fewest misses" in name
               else (lambda r: (r["false_rate"], r["misses"], -r["median"])))
        print("%-36s %s" % (name, describe(min(candidates, key=key))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
