#!/usr/bin/env python3
"""The status and alarm frames the box sends (hal/can_codec/plinth.dbc), read from a candump log
and checked against plinth-monitor's JSON lines, decoded here independently of the C++ codec.

    monitor_frames.py LOG --json MONITOR.jsonl   # the frames say what the JSON lines say

MonitorStatus (0x320 + axis): one frame per axis for every status line, in order: phase, corner,
alarm level, risk (the worst axis's, to the frame's 1e-4), sequence (+1 per status, wrapping). AlarmEvent (0x330):
one per alarm line, in order: level, previous level, cause, latched, sequence, and the time since
start (ms) equal to the line's time on the frame's clock. Every frame is stamped with the time
of the status or alarm it carries: one constant offset from the JSON's t (the record's origin).
Comment lines ('#') are skipped. Prints "ok: ..." and exits 0, or the first problem and exits 1.
"""
import argparse
import json
import re
import sys

LINE = re.compile(r"^\((\d+)\.(\d{6})\) (\S+) ([0-9A-F]{3})#((?:[0-9A-F]{2})*)$")
PHASES = ["full_contact", "sliding", "rocking", "slide_rocking", "overturned", "fell", "lifted_off"]
CORNERS = ["none", "left", "right"]
LEVELS = ["normal", "advisory", "warning", "alarm", "fault"]
CAUSES = ["none", "risk_threshold", "phase_change", "overturn_detected", "sensor_timeout",
          "sensor_fault", "sensor_disagreement", "acknowledged", "bus_error", "internal_fault",
          "collapse_forecast", "not_calibrated", "outside_model", "p_wave", "statue_unexplained",
          "regional_alert"]
STATUS_ID, ALARM_ID = 0x320, 0x330


def bits(data, start, length):
    """An Intel (little-endian) unsigned signal."""
    return (int.from_bytes(data, "little") >> start) & ((1 << length) - 1)


def named(names, value, signal):
    """The value table's name of `value` (plinth.dbc); a value outside it is an error."""
    if value >= len(names) or names[value] is None:
        raise ValueError("%s %d is not in plinth.dbc's value table" % (signal, value))
    return names[value]


def decode(text):
    """(time_us, id, fields) of one log line; None for a comment."""
    if not text.strip() or text.startswith("#"):
        return None
    m = LINE.match(text)
    if not m:
        raise ValueError("not a candump line: %r" % text)
    time_us = int(m.group(1)) * 1_000_000 + int(m.group(2))
    frame_id, data = int(m.group(4), 16), bytes.fromhex(m.group(5))
    if len(data) != 8:
        raise ValueError("not 8 bytes: %r" % text)
    if frame_id in (STATUS_ID, STATUS_ID + 1):
        fields = {"axis": frame_id - STATUS_ID, "phase": named(PHASES, bits(data, 0, 4), "Phase"),
                  "corner": named(CORNERS, bits(data, 4, 4), "Corner"),
                  "alarm": named(LEVELS, bits(data, 8, 4), "AlarmLevel"),
                  "risk": bits(data, 16, 16) * 1e-4, "sequence": bits(data, 32, 8),
                  "sample_age_ms": bits(data, 40, 16)}
    elif frame_id == ALARM_ID:
        fields = {"level": named(LEVELS, bits(data, 0, 4), "Level"),
                  "previous": named(LEVELS, bits(data, 4, 4), "PreviousLevel"),
                  "cause": named(CAUSES, bits(data, 8, 8), "Cause"),
                  "latched": bool(bits(data, 16, 1)),
                  "time_ms": bits(data, 24, 32), "sequence": bits(data, 56, 8)}
    else:
        fields = {}
    return time_us, frame_id, fields


def read_frames(path):
    frames = []
    for number, text in enumerate(open(path).read().splitlines(), 1):
        try:
            frame = decode(text)
        except ValueError as e:
            raise SystemExit("%s:%d: %s" % (path, number, e))
        if frame is not None:
            frames.append(frame)
    return frames


def per_axis(line, key, axis):
    value = line[key]
    return value[("x", "y")[axis]] if isinstance(value, dict) else value


def check_against_json(frames, lines):
    statuses = [l for l in lines if l["type"] == "status"]
    alarms = [l for l in lines if l["type"] == "alarm"]
    axes = 2 if isinstance(statuses[0]["phase"], dict) else 1
    status_frames = [f for f in frames if f[1] in (STATUS_ID, STATUS_ID + 1)]
    alarm_frames = [f for f in frames if f[1] == ALARM_ID]
    if len(alarm_frames) != len(alarms):
        return "%d AlarmEvent frames for %d alarm lines" % (len(alarm_frames), len(alarms))
    if len(status_frames) != axes * len(statuses):
        return "%d MonitorStatus frames for %d status lines of %d axes" % (
            len(status_frames), len(statuses), axes)
    offsets = set()
    for (time_us, _, f), a in zip(alarm_frames, alarms):
        for key in ("level", "previous", "cause", "latched", "sequence"):
            if f[key] != a[key]:
                return "AlarmEvent %s = %r, the alarm line says %r: %s" % (key, f[key], a[key], a)
        if f["time_ms"] != time_us // 1000:
            return "AlarmEvent time since start %d ms, stamped %d us" % (f["time_ms"], time_us)
        offsets.add(round(time_us - a["t"] * 1e6))
    for n, line in enumerate(statuses):
        for axis in range(axes):
            time_us, frame_id, f = status_frames[axes * n + axis]
            if frame_id != STATUS_ID + axis:
                return "status %d: frame %03X where axis %d's was expected" % (n, frame_id, axis)
            expected = {"phase": per_axis(line, "phase", axis),
                        "corner": per_axis(line, "corner", axis), "alarm": line["alarm"],
                        "sequence": n % 256}
            for key, value in expected.items():
                if f[key] != value:
                    return "status %d axis %d: %s = %r, the status line says %r" % (
                        n, axis, key, f[key], value)
            offsets.add(round(time_us - line["t"] * 1e6))
        # The status line's risk is the worst axis's.
        worst = max(status_frames[axes * n + axis][2]["risk"] for axis in range(axes))
        if abs(worst - line["risk"]) > 0.6e-4:
            return "status %d: risk %.4f, the status line says %.4f" % (n, worst, line["risk"])
    if max(offsets) - min(offsets) > 1:
        return "frames stamped at varying offsets from the JSON's t: %s us" % sorted(offsets)[:5]
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("--json", required=True, help="plinth-monitor's JSON lines")
    args = parser.parse_args()
    frames = read_frames(args.log)
    lines = [json.loads(l) for l in open(args.json)]
    problem = check_against_json(frames, lines)
    if problem:
        print("%s: %s" % (args.log, problem))
        return 1
    print("ok: %s: %d frames agree with %s" % (args.log, len(frames), args.json))
    return 0


if __name__ == "__main__":
    sys.exit(main())
