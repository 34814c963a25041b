#!/usr/bin/env python3
"""Does the span of the members' plate accelerations bound a base inside the box?

The statue filter's does_not_follow_base test (docs/statue-filter.md, "Corroboration") asks the
statue's accelerometer, while the statue stands, to follow one member's base. The members' bases
are the centre and the corners of the scene's [uncertainty.base] box (period, damping ratio; the
two-level design, ensemble_design.cpp). This runs plinth-sim on the scene with its base on a grid
over that box (the statue and its stops as the scene has them, its uncertainty dropped), and
reports, per other grid point, at how many of the instants where every run is in full contact
the plate's absolute acceleration (the ground's plus u'') lies outside the span of the members'
bases, and by how much at worst.

Usage: tools/plate-span.py --sim PLINTH_SIM --scene SCENE --record RECORD --pga PGA
                           [--steps N] [--work DIR]
Exit status: 0 reported, 1 a run failed, 2 usage or a scene without [uncertainty.base].
"""
import argparse
import csv
import re
import subprocess
import sys
import tempfile
from pathlib import Path


def section(text, name):
    """The body of the TOML table [name] in a scene's text (group 1), or None."""
    return re.search(rf"^\[{re.escape(name)}\]\s*$(.*?)(?=^\[|\Z)", text, re.M | re.S)


def base_ranges(text):
    """The [uncertainty.base] period and damping_ratio ranges of a scene's text."""
    table = section(text, "uncertainty.base")
    if not table:
        return None
    ranges = {}
    for key in ("period", "damping_ratio"):
        number = r"([-0-9.eE+]+)"
        m = re.search(rf"^{key}\s*=\s*\[\s*{number}\s*,\s*{number}\s*\]", table.group(1),
                      re.M)
        if not m:
            return None
        ranges[key] = (float(m.group(1)), float(m.group(2)))
    return ranges


def with_base(text, period, damping):
    """The scene's text with its [base] period and damping ratio set, its uncertainty dropped."""
    text = re.split(r"^\[uncertainty", text, maxsplit=1, flags=re.M)[0]
    table = section(text, "base")
    base = re.sub(r"^period\s*=.*$", f"period = {period!r}", table.group(1), count=1, flags=re.M)
    base = re.sub(r"^damping_ratio\s*=.*$", f"damping_ratio = {damping!r}", base, count=1,
                  flags=re.M)
    return text[:table.start(1)] + base + text[table.end(1):]


def plate_acceleration(path):
    """A run's plate accelerations (ag + u'', u'' by central differences) and phases."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    t = [float(r["t"]) for r in rows]
    u_dot = [float(r["u_dot"]) for r in rows]
    ag = [float(r["ag"]) for r in rows]
    dt = t[1] - t[0]
    last = len(t) - 1
    acc = [ag[i] + (u_dot[min(i + 1, last)] - u_dot[max(i - 1, 0)]) / (2 * dt)
           for i in range(len(t))]
    return acc, [r["phase"] for r in rows]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sim", required=True)
    p.add_argument("--scene", required=True)
    p.add_argument("--record", required=True)
    p.add_argument("--pga", required=True, help="e.g. 0.15g")
    p.add_argument("--steps", type=int, default=4, help="grid intervals per range (default 4)")
    p.add_argument("--work", help="keep the runs here (default: a temporary folder)")
    a = p.parse_args()
    if a.steps < 2 or a.steps % 2:
        p.error("--steps: even, at least 2 (the centre a grid point)")
    try:
        text = Path(a.scene).read_text()
    except OSError as e:
        print(f"plate-span: {a.scene}: cannot read the scene ({e.strerror})", file=sys.stderr)
        return 2
    ranges = base_ranges(text)
    if ranges is None or section(text, "base") is None:
        print(f"plate-span: {a.scene}: no [base] section, or no [uncertainty.base] with period "
              "and damping_ratio ranges", file=sys.stderr)
        return 2
    if a.work:
        work = Path(a.work)
        work.mkdir(parents=True, exist_ok=True)
        return report(a, text, ranges, work)
    with tempfile.TemporaryDirectory(prefix="plate-span.") as folder:
        return report(a, text, ranges, Path(folder))


def report(a, text, ranges, work):
    """Runs the grid in `work` and prints the table; the exit status."""
    grid = {}
    for key, (lo, hi) in ranges.items():
        grid[key] = [lo + (hi - lo) * k / a.steps for k in range(a.steps + 1)]
    runs = {}
    for i, period in enumerate(grid["period"]):
        for j, damping in enumerate(grid["damping_ratio"]):
            scene = work / f"base-{i}-{j}.toml"
            scene.write_text(with_base(text, period, damping))
            out = work / f"base-{i}-{j}.csv"
            try:
                done = subprocess.run([a.sim, "--scene", str(scene), "--record", a.record,
                                       "--pga", a.pga, "--out", str(out), "--out-interval",
                                       "0.005"], capture_output=True, text=True)
            except OSError as e:
                print(f"plate-span: cannot run {a.sim} ({e.strerror})", file=sys.stderr)
                return 1
            if done.returncode != 0:
                print(f"plate-span: plinth-sim failed for T = {period}, xi = {damping}:\n"
                      f"{done.stderr}", file=sys.stderr)
                return 1
            runs[(i, j)] = plate_acceleration(out)
    last, mid = a.steps, a.steps // 2
    members = [(i, j) for i in (0, last) for j in (0, last)] + [(mid, mid)]
    # Per instant, once: whether every run is in full contact, and the members' span.
    n = len(runs[members[0]][0])
    in_contact = [all(r[1][k] == "full_contact" for r in runs.values()) for k in range(n)]
    span = [(min(runs[m][0][k] for m in members), max(runs[m][0][k] for m in members))
            for k in range(n)]
    print(f"{a.scene} under {a.record} at {a.pga}: period {ranges['period']} s, damping ratio "
          f"{ranges['damping_ratio']}; instants where every run is in full contact, every 5 ms")
    print("| period (s) | damping ratio | outside the members' span | beyond 0.1 m/s2 "
          "| worst (m/s2) |")
    print("|---|---|---|---|---|")
    for (i, j), (acc, _) in sorted(runs.items()):
        if (i, j) in members:
            continue
        count = outside = beyond = 0
        worst = 0.0
        for k in range(n):
            if not in_contact[k]:
                continue
            lo, hi = span[k]
            excess = max(lo - acc[k], acc[k] - hi, 0.0)
            count += 1
            outside += excess > 0
            beyond += excess > 0.1
            worst = max(worst, excess)
        print(f"| {grid['period'][i]:.4g} | {grid['damping_ratio'][j]:.4g} | {outside} of {count} "
              f"| {beyond} | {worst:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
