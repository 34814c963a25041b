#!/usr/bin/env python3
"""The microcontroller image's replay against plinth-monitor's on the same case.

    mcu_replay_check.py MCU.log HOST.jsonl HOST_FRAMES.log [--rule auto|identical|timeline]
                        [--time-tolerance S] [--alarm-samples N]

MCU.log is what the image printed under QEMU: a candump log of the status and alarm frames it
sent, with '#' comment lines for its scalar ("# real=float"), its phase events ("# event axis=x
t=4.841192906 event=rocking_start corner=right"), its summary (with sample_period_ns) and
"# end: ok". HOST.jsonl and HOST_FRAMES.log are plinth-monitor --replay's JSON lines and
--frames-out log (the host's double precision).

--rule identical (auto for a double image): the frames are the same lines (every status and
alarm: time, phase, corner, alarm level, risk to 1e-4, sequence), and the phase events are the
same events (axis, kind, corner) at the same times: within half a unit of the host's 10th
significant digit (it prints %.10g) plus the image's 1 ns, plus --time-tolerance (default 0).

--rule timeline (auto for a float image, docs/microcontroller.md): the alarm timeline agrees:
the same alarm frames (level, previous level, cause, latched, sequence) in the same order, each
sent within --alarm-samples sample periods (default 1) of the host's. Single precision rounds
the risk and the located event times differently (1e-7 relative): a threshold or a phase change
that the host crosses in one sample the image may cross in the next. The phase events (count,
kinds, largest time difference) and the status frames (count, largest risk difference at equal
times, to the frames' 1e-4) are reported, not required equal.

Prints "ok: ..." with what it compared, or the first difference, and exits 0 or 1."""
import argparse
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import monitor_frames  # noqa: E402
from monitor_frames import ALARM_ID, STATUS_ID  # noqa: E402

SUMMARY_PERIOD = re.compile(r"^# summary .*\bsample_period_ns=(\d+)")
REAL = re.compile(r"^# real=(\w+)$")
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


def read_events(mcu, host_json_path):
    """(image events, host events) as (axis, t, kind, corner); raises ValueError on a bad line."""
    mcu_events = []
    for line in mcu:
        if line.startswith("# event"):
            m = EVENT.match(line)
            if not m:
                raise ValueError("unreadable event line: %s" % line)
            mcu_events.append((m.group(1), float(m.group(2)), m.group(3), m.group(4)))
    host_events = []
    for line in open(host_json_path):
        e = json.loads(line)
        if e["type"] == "event":
            corner = e.get("corner") if e["event"] in ("rocking_start", "overturned", "impact") else None
            host_events.append((e["axis"], e["t"], e["event"], corner))
    return mcu_events, host_events


def check_identical(mcu, mcu_frames, host_frames, host_json, time_tolerance):
    for n, (a, b) in enumerate(zip(mcu_frames, host_frames)):
        if a != b:
            print("frame %d differs:\n  image: %s\n  host:  %s" % (n + 1, describe(a), describe(b)))
            return 1
    if len(mcu_frames) != len(host_frames):
        print("the image sent %d frames, plinth-monitor %d" % (len(mcu_frames), len(host_frames)))
        return 1
    mcu_events, host_events = read_events(mcu, host_json)
    if len(mcu_events) != len(host_events):
        print("the image found %d phase events, plinth-monitor %d" % (len(mcu_events),
                                                                       len(host_events)))
    largest = 0.0
    for n, (a, b) in enumerate(zip(mcu_events, host_events)):
        allowed = printed_resolution(b[1]) + time_tolerance
        if (a[0], a[2], a[3]) != (b[0], b[2], b[3]) or abs(a[1] - b[1]) > allowed:
            print("event %d differs:\n  image: %s\n  host:  %s" % (n + 1, a, b))
            return 1
        largest = max(largest, abs(a[1] - b[1]))
    if len(mcu_events) != len(host_events):
        return 1
    print("ok: %d frames identical, %d phase events equal (largest time difference %.3g s)" % (
        len(mcu_frames), len(mcu_events), largest))
    return 0


def alarm_key(fields):
    return (fields["level"], fields["previous"], fields["cause"], fields["latched"],
            fields["sequence"])


def event_report(mcu_events, host_events):
    """The phase events compared: count, whether the kinds agree in order, largest time shift."""
    same_kinds = [(e[0], e[2], e[3]) for e in mcu_events] == [(e[0], e[2], e[3])
                                                              for e in host_events]
    text = "phase events %d, host %d" % (len(mcu_events), len(host_events))
    if same_kinds and mcu_events:
        largest = max(abs(a[1] - b[1]) for a, b in zip(mcu_events, host_events))
        return text + " (same kinds in order, largest time difference %.3g s)" % largest
    if same_kinds:
        return text
    first = next((n for n, (a, b) in enumerate(zip(mcu_events, host_events))
                  if (a[0], a[2], a[3]) != (b[0], b[2], b[3])), min(len(mcu_events),
                                                                  len(host_events)))
    return text + " (kinds differ from event %d)" % (first + 1)


def status_report(mcu_frames, host_frames):
    """Status frames: counts, and the largest risk difference between frames of the same time
    and axis."""
    mcu_status = {(f[0], f[1]): f[2] for f in mcu_frames if f[1] in (STATUS_ID, STATUS_ID + 1)}
    host_status = {(f[0], f[1]): f[2] for f in host_frames if f[1] in (STATUS_ID, STATUS_ID + 1)}
    paired = sorted(set(mcu_status) & set(host_status))
    largest, at = 0.0, None
    for key in paired:
        difference = abs(mcu_status[key]["risk"] - host_status[key]["risk"])
        if difference > largest + 1e-9:
            largest, at = difference, key
    text = "status frames %d, host %d, %d at equal times: risk max abs difference %.4f" % (
        len(mcu_status), len(host_status), len(paired), largest)
    if at is not None:
        text += " (t=%.6f s, axis %d)" % (at[0] * 1e-6, at[1] - STATUS_ID)
    return text


def check_timeline(mcu, mcu_lines, host_lines, host_json, alarm_samples):
    period_ns = next((int(m.group(1)) for m in map(SUMMARY_PERIOD.match, mcu) if m), None)
    if period_ns is None:
        print("the image's summary gives no sample_period_ns: the timeline rule needs it")
        return 1
    allowed_us = alarm_samples * period_ns / 1000.0
    mcu_frames = [monitor_frames.decode(l) for l in mcu_lines]
    host_frames = [monitor_frames.decode(l) for l in host_lines]
    mcu_alarms = [f for f in mcu_frames if f[1] == ALARM_ID]
    host_alarms = [f for f in host_frames if f[1] == ALARM_ID]
    largest_us = 0
    for n, (a, b) in enumerate(zip(mcu_alarms, host_alarms)):
        if alarm_key(a[2]) != alarm_key(b[2]):
            print("alarm change %d differs:\n  image: %s\n  host:  %s" % (n + 1, a[2], b[2]))
            return 1
        if abs(a[0] - b[0]) > allowed_us:
            print("alarm change %d (%s, %s) is %d us from the host's, more than %d sample(s) "
                  "(%g us):\n  image: t=%.6f s\n  host:  t=%.6f s" % (
                      n + 1, a[2]["level"], a[2]["cause"], abs(a[0] - b[0]), alarm_samples,
                      allowed_us, a[0] * 1e-6, b[0] * 1e-6))
            return 1
        largest_us = max(largest_us, abs(a[0] - b[0]))
    if len(mcu_alarms) != len(host_alarms):
        extra = (mcu_alarms if len(mcu_alarms) > len(host_alarms) else host_alarms)[
            min(len(mcu_alarms), len(host_alarms))]
        print("the image sent %d alarm changes, plinth-monitor %d; the first unmatched: %s" % (
            len(mcu_alarms), len(host_alarms), extra[2]))
        return 1
    mcu_events, host_events = read_events(mcu, host_json)
    print("ok (timeline): %d alarm changes agree, largest shift %d us (%g samples, allowed %d); "
          "%s; %s" % (len(mcu_alarms), largest_us, largest_us * 1000.0 / period_ns, alarm_samples,
                      event_report(mcu_events, host_events),
                      status_report(mcu_frames, host_frames)))
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mcu")
    parser.add_argument("host_json")
    parser.add_argument("host_frames")
    parser.add_argument("--rule", choices=("auto", "identical", "timeline"), default="auto")
    parser.add_argument("--time-tolerance", type=float, default=0.0)
    parser.add_argument("--alarm-samples", type=int, default=1)
    args = parser.parse_args()
    mcu = open(args.mcu).read().splitlines()
    if "# end: ok" not in mcu:
        ends = [l for l in mcu if l.startswith("# end")] or ["no '# end' line (did it crash?)"]
        print("%s: the image did not finish: %s" % (args.mcu, ends[0]))
        return 1
    rule = args.rule
    if rule == "auto":
        real = next((m.group(1) for m in map(REAL.match, mcu) if m), "double")
        rule = "identical" if real == "double" else "timeline"
    mcu_frames = [l for l in mcu if l and not l.startswith("#")]
    host_frames = [l for l in open(args.host_frames).read().splitlines() if l]
    try:
        if rule == "identical":
            return check_identical(mcu, mcu_frames, host_frames, args.host_json,
                                   args.time_tolerance)
        return check_timeline(mcu, mcu_frames, host_frames, args.host_json, args.alarm_samples)
    except ValueError as e:
        print(e)
        return 1


if __name__ == "__main__":
    sys.exit(main())
