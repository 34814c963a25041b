"""The warning reports' figures recounted from a runs file's rows, apart from plinth-eval's own
code (used by tests/cli/test_plinth_eval_pwave.sh and test_plinth_eval_regional.sh, and by
tools/warning-inputs.py): each run's collapse margin from its case's rows, and for a rule giving
each run's warning time, the median lead over the collapses and the share of runs at margin >= 2
that warned. Runs that left the model count in no outcome, as in plinth-eval report."""
import statistics


def margins(rows):
    """Each row's collapse margin: its case's lowest collapsing PGA (the grid's top for a case
    that never collapsed) over the row's PGA, keyed by the row's index."""
    cases = {}
    for r in rows:
        cases.setdefault((r["record"], r["scene"], r["statue"]), []).append(r)
    out = {}
    for i, r in enumerate(rows):
        rs = cases[(r["record"], r["scene"], r["statue"])]
        col = [float(x["scale_g"]) for x in rs if x["collapsed"] == "1"]
        out[i] = (min(col) if col else float(r["pga_to_g"])) / float(r["scale_g"])
    return out


def score(rows, warning_time, keep=lambda r: True):
    """(median lead in s, unneeded warnings in %) for `warning_time(row)` (< 0: never warned)
    over the rows `keep` accepts."""
    margin = margins(rows)
    leads, unneeded, warned = [], 0, 0
    for i, r in enumerate(rows):
        if float(r.get("model_valid_until_s", "-1")) >= 0 or not keep(r):
            continue
        t = warning_time(r)
        if r["collapsed"] == "1":
            c = float(r["collapse_time_s"])
            leads.append(c - t if 0 <= t < c else 0.0)
        elif margin[i] >= 2.0 - 1e-9:
            unneeded += 1
            warned += t >= 0
    median = statistics.median(leads) if leads else 0.0
    return median, 100.0 * warned / unneeded if unneeded else 0.0
