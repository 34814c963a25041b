#!/usr/bin/env python3
"""The microcontroller image's replay against plinth-monitor's on the same case.

    mcu_replay_check.py MCU.log HOST.jsonl HOST_FRAMES.log [--time-tolerance S]

MCU.log is what the image printed under QEMU: a candump log of the status and alarm frames it
sent, with '#' comment lines for its phase events ("# event axis=x t=4.841192906
event=rocking_start corner=right"), its summary and "# end: ok". HOST.jsonl and HOST_FRAMES.log
are plinth-monitor --replay's JSON lines and --frames-out log. Checks that the frames are the
same lines (every status and alarm: time, phase, corner, alarm level, risk to 1e-4, sequence),
and that the phase events are the same events (axis, kind, corner) at the same times: within half a unit of
the host's 10th significant digit (it prints %.10g) plus the image's 1 ns, plus
--time-tolerance (default 0). Prints "ok: ..." and the largest time difference, or the first
difference, and exits 0 or 1."""
import argparse
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import monitor_frames  # noqa: E402

EVENT = re.compile(r"^# event axis=(\w) t=(-?\d+\.\d+) event=(\w+)(?: corner=(\w+))?$")


def describe(line):
    try:
        frame = monitor_frames.decode(line)
    except ValueError:
        return line
    return "%s -> %s" % (line, frame[2] if frame else "comment")


def printed_resolution(t):
    """Half a unit of the 10th significant digit of t, plus 1 ns."""
    digits = math.floor(math.log10(abs(t))) if t != 0 else -10
    return 0.5 * 10.0 ** (digits - 9) + 1e-9


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mcu")
    parser.add_argument("host_json")
    parser.add_argument("host_frames")
    parser.add_argument("--time-tolerance", type=float, default=0.0)
    args = parser.parse_args()
    mcu = open(args.mcu).read().splitlines()
    if "# end: ok" not in mcu:
        ends = [l for l in mcu if l.startswith("# end")] or ["no '# end' line (did it crash?)"]
        print("%s: the image did not finish: %s" % (args.mcu, ends[0]))
        return 1
    mcu_frames = [l for l in mcu if l and not l.startswith("#")]
    host_frames = [l for l in open(args.host_frames).read().splitlines() if l]
    for n, (a, b) in enumerate(zip(mcu_frames, host_frames)):
        if a != b:
            print("frame %d differs:\n  image: %s\n  host:  %s" % (n + 1, describe(a), describe(b)))
            return 1
    if len(mcu_frames) != len(host_frames):
        print("the image sent %d frames, plinth-monitor %d" % (len(mcu_frames), len(host_frames)))
        return 1

    mcu_events = []
    for line in mcu:
        if line.startswith("# event"):
            m = EVENT.match(line)
            if not m:
                print("unreadable event line: %s" % line)
                return 1
            mcu_events.append((m.group(1), float(m.group(2)), m.group(3), m.group(4)))
    host_events = []
    for line in open(args.host_json):
        e = json.loads(line)
        if e["type"] == "event":
            corner = e.get("corner") if e["event"] in ("rocking_start", "overturned", "impact") else None
            host_events.append((e["axis"], e["t"], e["event"], corner))
    if len(mcu_events) != len(host_events):
        print("the image found %d phase events, plinth-monitor %d" % (len(mcu_events),
                                                                       len(host_events)))
    largest = 0.0
    for n, (a, b) in enumerate(zip(mcu_events, host_events)):
        allowed = printed_resolution(b[1]) + args.time_tolerance
        if (a[0], a[2], a[3]) != (b[0], b[2], b[3]) or abs(a[1] - b[1]) > allowed:
            print("event %d differs:\n  image: %s\n  host:  %s" % (n + 1, a, b))
            return 1
        largest = max(largest, abs(a[1] - b[1]))
    if len(mcu_events) != len(host_events):
        return 1
    print("ok: %d frames identical, %d phase events equal (largest time difference %.3g s)" % (
        len(mcu_frames), len(mcu_events), largest))
    return 0


if __name__ == "__main__":
    sys.exit(main())
