#!/usr/bin/python3
"""Extra calibration records for a test of the P-wave predictor's tau_c term (docs/pwave.md, "Why
the first target is missed"): three-component stations of the earthquakes that are neither
bundled (sim/data/records/pwave) nor held out (tools/pwave-heldout.sh), copied out of a clone of
github.com/vacalderon/GroundmotionSelection at commit 4575a07afb90e2a254291c19a0518df52a87846d
(PEER NGA-West2 records; cite Ancheta et al. 2014, Earthquake Spectra 30(3)), each file checked
against its git blob SHA-1. Not in the repository: they were used to measure, not to fit the box.

    tools/pwave-extra.py CLONE /tmp/extra && tools/pwave-records.sh /tmp/extra

The rule, fixed before any run of the stage on them: the earthquake is the file name's tag
(RSN<number>_<tag>_...); every tag of a bundled or held-out file is left out (with it the other
earthquakes of those sequences that share a tag). A station is an RSN with one vertical (a name
ending in UP, V, DWN or Z) and two horizontals, the first path of each file name kept. Per
earthquake, sorted by RSN: all its stations up to 4, else every k-th from the first, k =
ceil(n / 4). Then a station with a file plinth-eval cannot read (header line 3 without 'UNITS OF
G': one, RSN12806, whose file has no header) is left out. CLONE is a clone or its bare git
directory. Prints per earthquake its stations and what was chosen.
"""
import collections
import math
import pathlib
import re
import sys

from pwave_clone import COMMIT, fail, git  # tools/pwave_clone.py

HERE = pathlib.Path(__file__).resolve().parent
PER_EARTHQUAKE = 4
NAME = re.compile(r"RSN(\d+)_([^_]+)_.*\.AT2$")
VERTICAL = re.compile(r"(UP|V|DWN|Z)\.AT2$")


def excluded_tags():
    heldout = (HERE / "pwave-heldout.sh").read_text()
    bundled = [f.name for f in (HERE.parent / "sim/data/records/pwave").glob("RSN*.AT2")]
    names = re.findall(r"/(RSN\d+_[^/\s]+\.AT2)$", heldout, re.M) + bundled
    if not names:
        fail("no held-out or bundled file found")
    return {NAME.match(n).group(2) for n in names}


def main():
    if len(sys.argv) != 3:
        print("usage: pwave-extra.py CLONE OUT", file=sys.stderr)
        sys.exit(2)
    clone, out = sys.argv[1], pathlib.Path(sys.argv[2])
    excluded = excluded_tags()
    files = {}
    for line in git(clone, "ls-tree", "-r", COMMIT).decode().splitlines():
        meta, path = line.split("\t", 1)
        name = pathlib.PurePosixPath(path).name
        if NAME.match(name):
            files.setdefault(name, (meta.split()[2], path))
    stations = collections.defaultdict(list)
    for name in files:
        m = NAME.match(name)
        stations[(m.group(2), int(m.group(1)))].append(name)
    by_earthquake = collections.defaultdict(list)
    for (tag, rsn), names in stations.items():
        verticals = [n for n in names if VERTICAL.search(n)]
        if tag not in excluded and len(verticals) == 1 and len(names) == 3:
            by_earthquake[tag].append(rsn)
    out.mkdir(parents=True, exist_ok=True)
    copied = 0
    earthquakes = 0
    for tag in sorted(by_earthquake):
        rsns = sorted(by_earthquake[tag])
        k = math.ceil(len(rsns) / PER_EARTHQUAKE)
        kept = []
        for rsn in rsns[::k]:
            texts = {n: git(clone, "show", f"{COMMIT}:{files[n][1]}")
                     for n in sorted(stations[(tag, rsn)])}
            if any(b"UNITS OF G" not in (t.split(b"\n") + [b""] * 3)[2] for t in texts.values()):
                print(f"# {tag}: RSN{rsn} left out: a file without the PEER header",
                      file=sys.stderr)
                continue
            for n, text in texts.items():
                (out / n).write_bytes(text)
                blob = git(clone, "hash-object", str((out / n).resolve())).decode().strip()
                if blob != files[n][0]:
                    fail(f"{files[n][1]}: not the blob {files[n][0]}")
                copied += 1
            kept.append(rsn)
        earthquakes += 1 if kept else 0
        print(f"# {tag}: {len(rsns)} stations, every {k}-th: {kept}", file=sys.stderr)
    print(f"pwave-extra.py: {copied} files of {earthquakes} earthquakes in {out}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
