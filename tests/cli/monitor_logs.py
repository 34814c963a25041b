#!/usr/bin/env python3
"""Candump logs for plinth-monitor made from a recorder's capture (one sensor, node 1, id 0x301):
the cases tests/cli/test_plinth_monitor.sh and tools/monitor-snapshot.sh replay.

  monitor_logs.py forecast-frames CAPTURE OUT   another box's CollapseForecast frames (0x350 +
      axis) half way through: two valid, a probability above 1, a worst member beyond the members
  monitor_logs.py failover CAPTURE OUT          node 2 sends node 1's frames 0.5 ms later; node 1
      falls silent at 60 % of the log
  monitor_logs.py plate CAPTURE OUT             node 3 (a plate sensor) sends node 1's frames
      0.5 ms later
  monitor_logs.py step CAPTURE OUT              node 2 sends node 1's frames 0.5 ms later, its x
      0.1 g higher from its 1500th frame on (a disagreement)
"""
import sys

# Each a microsecond apart: a log's time never stands still for one identifier (docs/limits.md).
FORECAST_FRAMES = ["351#C90D0C11290928FE", "350#0000FF09FFFF6400", "350#1127000100000000",
                   "351#E803050364002800"]
LATER_S = 0.0005  # the second node's frames after the first's
STEP_RAW = 400  # 0.1 g at the DBC's 0.25 mg


def frames(lines):
    """(time s, interface, identifier, data) of each line."""
    for line in lines:
        stamp, iface, frame = line.split()
        ident, data = frame.split("#")
        yield float(stamp.strip("()")), iface, ident, data


def line(t, iface, ident, data):
    return "(%.6f) %s %s#%s" % (t, iface, ident, data)


def forecast_frames(lines):
    iface = lines[0].split()[1]
    half = len(lines) // 2
    t = float(lines[half].split()[0].strip("()"))
    extra = [line(t + 1e-6 * k, iface, *f.split("#")) for k, f in enumerate(FORECAST_FRAMES)]
    return lines[: half + 1] + extra + lines[half + 1:]


def second_node(lines, ident, first_until=None, shift_x=None):
    rows = []
    for k, (t, iface, frame_id, data) in enumerate(frames(lines)):
        if frame_id != "301":
            continue
        if first_until is None or t < first_until:
            rows.append((t, line(t, iface, "301", data)))
        if shift_x is not None:
            data = shift_x(k, data)
        rows.append((t + LATER_S, line(t + LATER_S, iface, ident, data)))
    return [row for _, row in sorted(rows)]


def failover(lines):
    times = [t for t, _, _, _ in frames(lines)]
    return second_node(lines, "302", first_until=times[0] + 0.6 * (times[-1] - times[0]))


def step(lines):
    def shifted(k, data):
        raw = bytearray.fromhex(data)
        ax = int.from_bytes(raw[0:2], "little", signed=True) + (STEP_RAW if k > 1500 else 0)
        raw[0:2] = max(-32768, min(32767, ax)).to_bytes(2, "little", signed=True)
        return raw.hex().upper()
    return second_node(lines, "302", shift_x=shifted)


CASES = {"forecast-frames": forecast_frames, "failover": failover,
         "plate": lambda lines: second_node(lines, "303"), "step": step}


def main(argv):
    if len(argv) != 4 or argv[1] not in CASES:
        sys.exit("usage: monitor_logs.py {%s} CAPTURE OUT" % ",".join(CASES))
    lines = [l for l in open(argv[2]).read().splitlines() if l.strip()]
    with open(argv[3], "w") as out:
        out.write("\n".join(CASES[argv[1]](lines)) + "\n")


if __name__ == "__main__":
    main(sys.argv)
