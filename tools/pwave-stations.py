#!/usr/bin/python3
"""Each station's magnitude, distances and Vs30, for plinth-eval run --regional on --record-info.

Reads the NGA-West2 flatfile that the public repository github.com/vacalderon/GroundmotionSelection
holds at commit 4575a07afb90e2a254291c19a0518df52a87846d (Mainshock_DB.xlsx and
Aftershock_DB.xlsx; PEER NGA-West2, cite Ancheta et al. 2014, Earthquake Spectra 30(3)) and
writes one CSV row per station (the RSN<number>_ prefix) of the .AT2 files in FOLDER:

    rsn,earthquake,station,magnitude,rrup_km,rjb_km,rhyp_km,vs30_m_s

the columns earthquake_name, station_name, earthquake_magnitude, clstd_km (Rrup),
joyner_booredist_km (Rjb), hypd_km (Rhyp) and vs30_m_s_selectedforanalysis, as the flatfile gives
them (rounded to 0.01). docs/regional.md, "Evaluation":

    tools/pwave-stations.py CLONE sim/data/records/pwave > sim/data/records/pwave/stations.csv
    tools/pwave-stations.py CLONE /work/pw/heldout > /work/pw/heldout/stations.csv

CLONE is a clone of the repository or its bare git directory. Needs python3-openpyxl (Debian;
tools/install-deps.sh). Exit 1 naming the station when one is not in the flatfile or a value is
missing.
"""
import csv
import io
import math
import pathlib
import re
import sys

from pwave_clone import COMMIT, fail, git  # tools/pwave_clone.py

WORKBOOKS = ("Mainshock_DB.xlsx", "Aftershock_DB.xlsx")
COLUMNS = {
    "earthquake": "earthquake_name",
    "station": "station_name",
    "magnitude": "earthquake_magnitude",
    "rrup_km": "clstd_km",
    "rjb_km": "joyner_booredist_km",
    "rhyp_km": "hypd_km",
    "vs30_m_s": "vs30_m_s_selectedforanalysis",
}


def flatfile(clone):
    try:
        import openpyxl  # Debian's python3-openpyxl
    except ImportError:
        fail("needs openpyxl (apt-get install python3-openpyxl; tools/install-deps.sh)")
    rows = {}
    paths = git(clone, "ls-tree", "-r", "--name-only", COMMIT).decode().splitlines()
    for name in WORKBOOKS:
        path = next((p for p in paths if pathlib.PurePosixPath(p).name == name), None)
        if path is None:
            fail(f"{clone}: no {name} at {COMMIT}")
        book = openpyxl.load_workbook(io.BytesIO(git(clone, "show", f"{COMMIT}:{path}")),
                                      read_only=True)
        lines = book.worksheets[0].iter_rows(values_only=True)
        header = list(next(lines))
        try:
            rsn_at = header.index("record_sequence_number")
            at = {key: header.index(column) for key, column in COLUMNS.items()}
        except ValueError as e:
            fail(f"{name}: {e}")
        for line in lines:
            if line[rsn_at] is None:
                continue
            rows.setdefault(int(line[rsn_at]), {k: line[i] for k, i in at.items()})
    return rows


def main():
    if len(sys.argv) != 3:
        print("usage: pwave-stations.py CLONE FOLDER > stations.csv", file=sys.stderr)
        sys.exit(2)
    clone, folder = sys.argv[1], pathlib.Path(sys.argv[2])
    rsns = sorted({int(m.group(1)) for f in folder.glob("RSN*.AT2")
                   if (m := re.match(r"RSN(\d+)_", f.name))})
    if not rsns:
        fail(f"{folder}: no RSN<number>_*.AT2 file")
    table = flatfile(clone)
    out = csv.writer(sys.stdout, lineterminator="\n")
    out.writerow(["rsn"] + list(COLUMNS))
    for rsn in rsns:
        row = table.get(rsn)
        if row is None:
            fail(f"RSN{rsn}: not in {' or '.join(WORKBOOKS)}")
        values = []
        for key in COLUMNS:
            v = row[key]
            if key in ("earthquake", "station"):
                values.append(str(v).strip())
                continue
            if not isinstance(v, (int, float)) or not math.isfinite(v) or v < 0:
                fail(f"RSN{rsn}: {COLUMNS[key]}: not a number >= 0 ({v!r})")
            values.append(f"{v:.2f}")
        out.writerow([rsn] + values)


if __name__ == "__main__":
    main()
