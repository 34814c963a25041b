#!/usr/bin/env python3
"""A statue sensor's frames added to a candump log of ground sensor frames (hal/can_codec/
plinth.dbc, encoded here independently of the C++ codec): at each SensorAcceleration of the
ground node, the IMU's SensorAcceleration (0x300 + node) and StatueRotation (0x370 + node) of the
same sample, one Sequence for both, counting from 0.

    statue_frames.py IN.log OUT.log [--node 2] [--ground-node 1] [--offset-rad-s 0.01]
        [--noise-rad-s 0.003] [--rock-rad-s 0] [--silent-after-s S] [--garble-every K]
        [--accelerometer ground|rest]

The statue stands (rates: the offset about y plus noise; the accelerometer reads what the ground
sensor reads, plus noise: a statue in full contact moves with the ground) unless
--rock-rad-s gives a 3 Hz swing of that amplitude about y from the log's fifth second (a loose
sensor: no member explains it). --silent-after-s: no IMU frame after S seconds of the log.
--garble-every K: every K-th StatueRotation is cut to 7 bytes (the box refuses and counts it).
--accelerometer rest: the accelerometer reads 1 g up and nothing else (a sensor come off the
statue, frozen at rest: the ground sensor does not corroborate it).
Prints the frames added.
"""
import argparse
import math
import random
import re
import sys

LINE = re.compile(r"^\((\d+)\.(\d{6})\) (\S+) ([0-9A-F]{3})#((?:[0-9A-F]{2})*)$")
RATE_STEP = 0.0005  # rad/s per bit (StatueRotation.Wx..Wz)
G_STEP = 0.00025  # g per bit (SensorAcceleration.Ax..Az)


def signed16(value, step):
    raw = round(value / step)
    if not -32768 <= raw <= 32767:
        raise ValueError(f"{value} beyond the signal's range")
    return raw & 0xFFFF


def unframe(data_hex, step):
    """The three signed 16-bit values of a frame's first six bytes, in units of `step`."""
    word = int.from_bytes(bytes.fromhex(data_hex), "little")
    values = []
    for i in range(3):
        raw = (word >> (16 * i)) & 0xFFFF
        values.append((raw - 0x10000 if raw & 0x8000 else raw) * step)
    return values


def frame(values, step, sequence):
    word = 0
    for i, v in enumerate(values):
        word |= signed16(v, step) << (16 * i)
    word |= sequence << 48
    return word.to_bytes(8, "little").hex().upper()


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("log_in")
    p.add_argument("log_out")
    p.add_argument("--node", type=int, default=2)
    p.add_argument("--ground-node", type=int, default=1)
    p.add_argument("--offset-rad-s", type=float, default=0.01)
    p.add_argument("--noise-rad-s", type=float, default=0.003)
    p.add_argument("--rock-rad-s", type=float, default=0.0)
    p.add_argument("--silent-after-s", type=float, default=-1.0)
    p.add_argument("--garble-every", type=int, default=0)
    p.add_argument("--accelerometer", choices=("ground", "rest"), default="ground")
    args = p.parse_args()
    noise = random.Random(24)
    out = []
    first_us = None
    added = 0
    sequence = 0
    with open(args.log_in) as f:
        for line in f:
            out.append(line)
            m = LINE.match(line.rstrip("\n"))
            if not m or int(m.group(4), 16) != 0x300 + args.ground_node:
                continue
            stamp, interface = f"({m.group(1)}.{m.group(2)})", m.group(3)
            t_us = int(m.group(1)) * 1_000_000 + int(m.group(2))
            first_us = t_us if first_us is None else first_us
            t = (t_us - first_us) * 1e-6
            if 0 <= args.silent_after_s < t:
                continue
            swing = args.rock_rad_s * math.sin(2 * math.pi * 3 * t) if t > 5 else 0.0
            rates = [noise.gauss(0, args.noise_rad_s),
                     args.offset_rad_s + swing + noise.gauss(0, args.noise_rad_s),
                     noise.gauss(0, args.noise_rad_s)]
            ground = unframe(m.group(5), G_STEP) if args.accelerometer == "ground" else [0, 0, 1]
            accel = [g + noise.gauss(0, 0.0005) for g in ground]
            rotation = frame(rates, RATE_STEP, sequence)
            added += 1
            if args.garble_every > 0 and added % args.garble_every == 0:
                rotation = rotation[:14]
            out.append(f"{stamp} {interface} {0x300 + args.node:03X}#{frame(accel, G_STEP, sequence)}\n")
            out.append(f"{stamp} {interface} {0x370 + args.node:03X}#{rotation}\n")
            sequence = (sequence + 1) % 256
    with open(args.log_out, "w") as f:
        f.writelines(out)
    print(f"{added} samples of node {args.node} added")
    return 0


if __name__ == "__main__":
    sys.exit(main())
