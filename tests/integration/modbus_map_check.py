#!/usr/bin/env python3
"""Checks what mbpoll read from plinth-monitor's Modbus server against the shipped map
(firmware/linux/modbus-map.csv), row by row: each register, discrete input and coil of the map
has the value that the box's JSON lines (status, alarm, command, summary; the first status line
for the files' digests) and --version say.
A row the map gains without a rule here fails, so the map and this check cannot drift apart.

usage: modbus_map_check.py MAP READS AT_READ BOX_OUT VERSION_TEXT HEARTBEAT_BEFORE
         HEARTBEAT_AFTER ELAPSED_S
  READS     "table address value" lines (table: input, holding, discrete, coil), two reads:
            the first marked "first", then the full read checked here
  AT_READ   the box's stdout as it was right after the full read
  BOX_OUT   the box's whole stdout, ended by its summary line
Prints one line per failed row; nothing when every row holds.
"""
import csv
import json
import math
import sys


def main():
    map_path, reads_path, at_read, box_out, version_text = sys.argv[1:6]
    before, after, elapsed = int(sys.argv[6]), int(sys.argv[7]), float(sys.argv[8])
    rows = list(csv.DictReader(open(map_path, newline="")))
    first, reads = {}, {}
    for line in open(reads_path):
        parts = line.split()
        if len(parts) == 4 and parts[0] == "first":
            first[(parts[1], int(parts[2]))] = int(parts[3])
        elif len(parts) == 3:
            reads[(parts[0], int(parts[1]))] = int(parts[2])
    lines = [json.loads(l) for l in open(at_read) if l.startswith("{")]
    statuses = [l for l in lines if l["type"] == "status"]
    status, first_status = statuses[-1], statuses[0]
    alarms = [l for l in lines if l["type"] == "alarm"]
    commands = [l for l in lines if l["type"] == "command" and l["command"] == "acknowledge"]
    summary = json.loads(open(box_out).read().splitlines()[-1])
    assert summary["type"] == "summary", "the box's output ends without its summary"
    # "plinth-monitor 0.1.0 (v0.1.0-3-gabc)"
    number, git = version_text.split(" ", 1)[1].split(" ", 1)
    version = dict(zip(("major", "minor", "patch"), (int(n) for n in number.split("."))))
    version["git"] = git.strip("()")
    problems = []

    def fail(row, message):
        problems.append("%s %s (%s): %s" % (row["table"], row["address"], row["name"], message))

    def codes(row):
        return {name: int(code) for code, name in
                (c.split("=", 1) for c in row["codes"].split(";"))} if row["codes"] else {}

    def field(source):
        kind, _, key = source.partition(".")
        if kind == "status":
            return status[key]
        if kind == "alarm":
            return alarms[-1][key]
        if kind == "command":
            return commands[-1][key] if commands else "none"
        if kind == "version":
            return version[key]
        if kind == "first_status":
            return first_status.get(key)  # None: the member is left out
        raise KeyError(source)

    for row in rows:
        table = {"register": "input", "discrete_input": "discrete", "coil": "coil"}[row["table"]]
        address, words = int(row["address"]), int(row["words"])
        if row["table"] == "register":
            # The holding registers were read after the input registers: a count may have gone
            # on in between, everything else is the same.
            held = [reads.get(("holding", address + i)) for i in range(words)]
            read = [reads.get(("input", address + i)) for i in range(words)]
            counts = row["name"] in ("heartbeat", "uptime") or row["json"].startswith("summary.")
            if None not in held + read and counts and held >= read:
                pass
            elif held != read:
                fail(row, "holding registers %s, input registers %s" % (held, read))
        raw = [reads.get((table, address + i)) for i in range(words)]
        if None in raw:
            fail(row, "not read")
            continue
        value = raw[0]
        if row["type"] in ("uint32", "uint64"):  # the high word first
            value = 0
            for w in raw:
                value = value << 16 | w
        source, name = row["json"], row["name"]
        if row["type"] == "bit" and row["table"] == "discrete_input":
            bit, level = row["codes"].split("=", 1)
            expected = 1 if field(source) == level else 0
        elif row["table"] == "coil":
            expected = 0
        elif row["type"] == "ascii":
            text = "".join(chr(w >> 8) + chr(w & 0xFF) for w in raw).rstrip("\0")
            if text != field(source)[:2 * words]:
                fail(row, "reads %r, --version says %r" % (text, field(source)))
            continue
        elif source.startswith("summary."):
            # A counter: it only counts up, to the summary's total at the end.
            total = summary
            for key in source.split(".")[1:]:
                total = total[key]
            earlier = first.get((table, address), 0) << 16 | first.get((table, address + 1), 0)
            if not earlier <= value <= total:
                fail(row, "%d, not between the first read's %d and the summary's %d" % (
                    value, earlier, total))
            continue
        elif name.startswith("regional_") and "regional" not in status:
            # No regional alert received: none held, nothing counted.
            expected = {"regional_held": 0, "regional_probability": 0, "regional_event_id": 0,
                        "regional_received": 0, "regional_accepted": 0, "regional_refused": 0,
                        "regional_last_refusal": 0}.get(name, 65535)
        elif name.startswith("regional_"):
            fail(row, "no rule in tests/integration/modbus_map_check.py for a run with alerts")
            continue
        elif row["type"] == "uint64" and source.startswith("first_status."):
            # A file's digest: sha256sum's first 16 hex digits; the none value without the file.
            digest = field(source)
            expected = int(digest[:16], 16) if digest else int(row["none"])
            if value != expected:
                fail(row, "reads %016x, the first status line says %s" % (value, digest))
            continue
        elif name.startswith("statue_"):
            # The statue sensor's: none without one; else its streams' health, ready, and per
            # axis the weights' code and effective members (one axis here: y is none).
            sensor = status.get("statue_sensor")
            axis = name[-1] if name[-2:] in ("_x", "_y") else ""
            if sensor is None or axis == "y":
                expected = int(row["none"])
            elif name.startswith("statue_weights_"):
                w = sensor["weights"]
                code = ("not_measured" if not w["measured"] else "unexplained"
                        if not w["explained"] else "weighted" if w["weighted"] else
                        "uninformative")
                expected = codes(row)[code]
            elif name.startswith("statue_effective_members_"):
                expected = round(sensor["weights"]["effective_members"] * 100)
            elif name == "statue_ready":
                expected = int(sensor["ready"])
            else:  # statue_rate_health, statue_acceleration_health
                stream = name[len("statue_"):-len("_health")]
                expected = codes(row)[sensor[stream]["health"]]
        elif name.startswith(("recorder_", "captures_")):
            # The event recorder's: none (counts 0) without one; its health and problem as the
            # status line's; its counts only count up, from that line's to the summary's.
            recorder = status.get("recorder")
            if recorder is None:
                expected = 0 if name.startswith("captures_") else int(row["none"])
            elif name.startswith("captures_"):
                total = summary["recorder"][name]
                if not recorder[name] <= value <= total:
                    fail(row, "%d, not between the status line's %d and the summary's %d" % (
                        value, recorder[name], total))
                continue
            else:
                expected = codes(row)[recorder[name[len("recorder_"):]]]
        elif name.endswith("_given"):  # 1 while the digest that follows is the file's
            expected = 1 if name[:-len("given")] + "sha256" in first_status else 0
        elif name == "collapse_in":
            t = status["collapse_forecast_t"]
            expected = 65535 if t is None else max(0, math.ceil((t - status["t"]) * 1000))
        elif source:
            v = field(source)
            c = codes(row)
            if c:
                expected = c[v]
            elif isinstance(v, bool):
                expected = int(v)
            else:
                expected = round(v / float(row["scale"]))
        elif name == "heartbeat":
            if not before <= value <= after:
                fail(row, "%d, not within the status lines %d .. %d" % (value, before, after))
            continue
        elif name == "uptime":
            if not 1 <= value <= elapsed + 1:
                fail(row, "%d s, the box ran %.1f s" % (value, elapsed))
            continue
        elif name == "axis_count":
            expected = 1
        elif name == "phase_y":
            expected = 65535
        elif name == "commands":
            expected = len([l for l in lines if l["type"] == "command"])
        elif name == "alarm_events":
            expected = len(alarms)
        elif name == "map_version":
            expected = 8  # map 8: regional 86-101, statue 102-108, recorder 109-116, 117-118
        elif name == "collapse_held":
            expected = 1 if "collapse" in status else 0
        elif name == "forecast_axis":  # one axis: x once a forecast ran
            expected = 0 if status["collapse_forecast_t"] is not None else value
        elif name == "forecast_worst_member":  # one member: member 0 is the first to collapse
            expected = 0 if status["collapse_forecast_t"] is not None else 65535
        else:
            fail(row, "no rule in tests/integration/modbus_map_check.py for this row")
            continue
        if value != expected:
            fail(row, "reads %d, the box's lines say %d" % (value, expected))
    if not rows:
        problems.append("the map has no rows")
    print("\n".join(problems))


if __name__ == "__main__":
    main()
