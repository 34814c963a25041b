#!/usr/bin/env python3
"""Checks a candump log written by plinth-replay against the records it came from.

Rebuilds, independently of the C++ code, every frame plinth-replay must send: per sample time
k / rate (the solver's linear interpolation), the SensorHeartbeat of every node at each whole
second and the SensorAcceleration of every node (ax, ay from the horizontal records, az = 1 g +
the vertical record, all times the scale, clamped to +-8.192 g with the saturated flag), with
sequence counters wrapping 255 -> 0; then compares the log line by line: order, identifiers,
decoded values within half the codec's resolution (0.125 mg), sequence, status, and times
relative to the first line (to 1 us; --time-tolerance-us for candump's receive times on a bus).

    replay_log_check.py LOG --rate HZ (--scale S | --pga G) [--loops N] [--t-end S]
                        [--interface NAME] --axis NODE:AXIS:FILE[:v] ...
    replay_log_check.py LOG --same-as OTHER.log      # same frames at the same relative times

AXIS is x, y or z; ":v" takes the file's vertical column (a three-column CSV) instead of its
horizontal one. Prints "ok: ..." and exits 0, or prints the first difference and exits 1.
"""
import argparse
import math
import re
import sys

RESOLUTION_G = 0.00025
FULL_SCALE_G = (-8.192, 8.19175)
SATURATED = 0x01
FIRMWARE_BYTE = 0x10  # major 0 in bits 32-35, minor 1 in bits 36-39
LINE = re.compile(r"^\((\d+)\.(\d{6})\) (\S+) ([0-9A-F]{3})#((?:[0-9A-F]{2})*)$")


def read_record(path):
    """(dt, horizontal, vertical) in g."""
    if path.lower().endswith(".at2"):
        lines = open(path).read().splitlines()
        match = re.search(r"NPTS\s*=\s*(\d+)\s*,\s*DT\s*=\s*([-+.0-9Ee]+)", lines[3])
        values = [float(x) for line in lines[4:] for x in line.split()]
        return float(match.group(2)), values[: int(match.group(1))], []
    rows = [line.split(",") for line in open(path).read().splitlines()[1:] if line.strip()]
    times = [float(row[0]) for row in rows]
    vertical = [float(row[2]) for row in rows] if len(rows[0]) > 2 else []
    return times[1] - times[0], [float(row[1]) for row in rows], vertical


def value_at(dt, values, t):
    """lib/core SampledSignal::at, a time within rounding of the last sample reading it."""
    if not values or t < 0:
        return 0.0
    position = t / dt
    last = len(values) - 1
    if abs(position - last) <= 1e-9 * max(1.0, last):
        return values[-1]
    if position > last:
        return 0.0
    i = math.floor(position)
    return values[i] + (position - i) * (values[i + 1] - values[i])


def expected_frames(args):
    """[(offset_ns, id, fields)] in send order."""
    nodes = {}
    records = {}
    for spec in args.axis:
        parts = spec.split(":")
        node, axis, path = int(parts[0]), parts[1], parts[2]
        column = parts[3] if len(parts) > 3 else "h"
        if path not in records:
            records[path] = read_record(path)
        dt, horizontal, vertical = records[path]
        nodes.setdefault(node, {})[axis] = (dt, vertical if column == "v" else horizontal)
    scale = args.scale
    if args.pga is not None:
        first = args.axis[0].split(":")[2]
        scale = args.pga / max(abs(v) for v in records[first][1])
    duration = max((len(v) - 1) * dt for axes in nodes.values() for dt, v in axes.values())
    if args.t_end is not None:
        duration = min(duration, args.t_end)
    per_loop = math.floor(duration * args.rate + 1e-6) + 1
    samples = {}
    for node, axes in nodes.items():
        rows = []
        for k in range(per_loop):
            t = k / args.rate
            reading = []
            status = 0
            for axis, rest in (("x", 0.0), ("y", 0.0), ("z", 1.0)):
                dt, values = axes.get(axis, (1.0, []))
                value = rest + scale * value_at(dt, values, t)
                if not FULL_SCALE_G[0] <= value <= FULL_SCALE_G[1]:
                    status |= SATURATED
                    value = min(max(value, FULL_SCALE_G[0]), FULL_SCALE_G[1])
                reading.append(value)
            rows.append((reading, status))
        samples[node] = rows
    frames = []
    sequence = {node: 0 for node in nodes}
    since_heartbeat = {node: 0 for node in nodes}
    next_heartbeat = 0
    for n in range(per_loop * args.loops):
        offset_ns = round(n * 1e9 / args.rate)
        if n + 1e-6 >= next_heartbeat * args.rate:
            for node in sorted(nodes):
                fields = ("heartbeat", next_heartbeat, since_heartbeat[node])
                frames.append((offset_ns, 0x310 + node, fields))
                since_heartbeat[node] = 0
            next_heartbeat += 1
        for node in sorted(nodes):
            reading, status = samples[node][n % per_loop]
            fields = ("acceleration", reading, sequence[node], status)
            frames.append((offset_ns, 0x300 + node, fields))
            sequence[node] = (sequence[node] + 1) % 256
            since_heartbeat[node] |= status
    return frames


def read_log(path):
    """[(time_us, interface, id, bytes)]; ValueError on a line plinth-replay would not write."""
    out = []
    for number, line in enumerate(open(path).read().splitlines(), 1):
        match = LINE.match(line)
        if not match:
            raise ValueError(f"{path}:{number}: not a candump -l line: {line!r}")
        seconds, micros, interface, ident, data = match.groups()
        time_us = int(seconds) * 1_000_000 + int(micros)
        out.append((time_us, interface, int(ident, 16), bytes.fromhex(data)))
    return out


def int16(data, at):
    return int.from_bytes(data[at : at + 2], "little", signed=True)


def compare(args):
    lines = read_log(args.log)
    frames = expected_frames(args)
    if len(lines) != len(frames):
        heartbeats = sum(1 for f in frames if f[2][0] == "heartbeat")
        accelerations = len(frames) - heartbeats
        return (f"{len(lines)} lines, expected {len(frames)} "
                f"({accelerations} acceleration + {heartbeats} heartbeat)")
    first_us = lines[0][0]
    for index, (line, frame) in enumerate(zip(lines, frames), 1):
        time_us, interface, ident, data = line
        offset_ns, want_id, fields = frame
        where = f"line {index}"
        if interface != args.interface:
            return f"{where}: interface {interface}, expected {args.interface}"
        if ident != want_id:
            return f"{where}: id {ident:03X}, expected {want_id:03X}"
        if len(data) != 8:
            return f"{where}: {len(data)} data bytes"
        if abs((time_us - first_us) - offset_ns / 1000) > args.time_tolerance_us:
            return (f"{where}: at {time_us - first_us} us after the first line, "
                    f"expected {offset_ns / 1000:.1f}")
        if fields[0] == "heartbeat":
            _, uptime, status = fields
            want = uptime.to_bytes(4, "little") + bytes([FIRMWARE_BYTE, status, 0, 0])
            if data != want:
                return f"{where}: heartbeat {data.hex()}, expected {want.hex()}"
            continue
        _, reading, sequence, status = fields
        for axis, at in (("ax", 0), ("ay", 2), ("az", 4)):
            decoded = int16(data, at) * RESOLUTION_G
            want = reading[at // 2]
            if abs(decoded - want) > RESOLUTION_G / 2 + 1e-9:
                return f"{where}: {axis} {decoded:.5f} g, expected {want:.5f} g"
        if data[6] != sequence:
            return f"{where}: sequence {data[6]}, expected {sequence}"
        if data[7] != status:
            return f"{where}: status {data[7]}, expected {status}"
    accelerations = sum(1 for f in frames if f[2][0] == "acceleration")
    heartbeats = len(lines) - accelerations
    return f"ok: {len(lines)} frames ({accelerations} acceleration, {heartbeats} heartbeat)"


def same_as(args):
    ours, theirs = read_log(args.log), read_log(args.same_as)
    if len(ours) != len(theirs):
        return f"{len(ours)} lines, {args.same_as} has {len(theirs)}"
    for index, (a, b) in enumerate(zip(ours, theirs), 1):
        if a[2:] != b[2:]:
            return f"line {index}: frame {a[2]:03X}#{a[3].hex()}, expected {b[2]:03X}#{b[3].hex()}"
        if abs((a[0] - ours[0][0]) - (b[0] - theirs[0][0])) > 1:
            return (f"line {index}: relative time {a[0] - ours[0][0]} us, "
                    f"expected {b[0] - theirs[0][0]}")
    return f"ok: {len(ours)} frames as in {args.same_as}"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("log")
    parser.add_argument("--same-as")
    parser.add_argument("--rate", type=float)
    parser.add_argument("--scale", type=float, default=1.0)
    parser.add_argument("--pga", type=float, help="g")
    parser.add_argument("--loops", type=int, default=1)
    parser.add_argument("--t-end", type=float)
    parser.add_argument("--interface", default="vcan0")
    parser.add_argument("--axis", action="append", default=[])
    parser.add_argument("--time-tolerance-us", type=float, default=1.0,
                        help="1 us for a log plinth-replay wrote; more for candump on a bus")
    args = parser.parse_args()
    try:
        result = same_as(args) if args.same_as else compare(args)
    except (ValueError, OSError) as error:
        result = str(error)
    print(result)
    return 0 if result.startswith("ok:") else 1


if __name__ == "__main__":
    sys.exit(main())
