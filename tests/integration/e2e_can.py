#!/usr/bin/env python3
"""End-to-end test on a real CAN bus: the input before, every check and measurement after.

tools/e2e-can.sh runs this twice around the bus runs in the guest kernel (its guest part):

    e2e_can.py prepare --work DIR --record R.AT2 --scale 20 ...   # DIR/input.csv, DIR/config.*
    e2e_can.py check --work DIR                                   # exit 1 on a failed check

prepare writes the sensor input: a quiet lead-in (the monitor's start-up window, with a 1 LSB
dither as a real sensor's noise, so the stuck-sensor check stays quiet), then the record
resampled to the sensor rate and scaled, in m/s2 (so that plinth-sim and plinth-replay read the
same numbers whatever a scene's g). check reads what the guest left in DIR (candump logs of the
bus, the monitor's JSON lines, plinth-replay's reports), decodes every frame with its own
decoder built from hal/can_codec/plinth.dbc, runs plinth-sim and plinth-monitor --replay on the
host, and compares. Python 3 standard library only.
"""
import argparse
import json
import math
import re
import resource
import statistics
import subprocess
import sys
from pathlib import Path

G0 = 9.80665  # m/s2: the DBC's 1 g
RESOLUTION_G = 0.00025  # the acceleration signals' factor
DITHER = (0, 1, 0, -1)  # lead-in, in LSB: zero mean over any 4 samples
PLINTH_FIRST, PLINTH_LAST = 0x300, 0x37F
# The guest's markers to candump (tools/e2e-can.sh): 0x37F, a plinth identifier no message uses;
# the end marker goes after the monitor stopped, so it is not part of the run.
END_MARKER = (0x37F, b"\xe3")
SENSOR_NODE = 1
ACCEL_ID = 0x300 + SENSOR_NODE
HEARTBEAT_ID = 0x310 + SENSOR_NODE
STATUS_IDS = (0x320, 0x321)
ALARM_ID = 0x330
FORECAST_IDS = (0x350, 0x351)  # CollapseForecast, with each status while forecasting
NO_COLLAPSE_MS = 65535  # CollapseIn: none forecast
PHASES = ["full_contact", "sliding", "rocking", "slide_rocking", "overturned", "fell", "lifted_off"]
LEVELS = ["normal", "advisory", "warning", "alarm", "fault"]
CAUSES = ["none", "risk_threshold", "phase_change", "overturn_detected", "sensor_timeout",
          "sensor_fault", "sensor_disagreement", "acknowledged", "bus_error", "internal_fault",
          "collapse_forecast", "not_calibrated", "outside_model", "p_wave", "statue_unexplained",
          "regional_alert", "statue_sensor_fault", "restored", "statue_stands"]
SCENARIOS = ("main", "stop", "garbage", "burst", "regional")  # regional: e2e_can_regional.py
# Sent by canplayer in the garbage case, each one refused by the DBC (or not for the monitor).
GARBAGE = (
    "301#", "301#00", "301#00112233445566",  # SensorAcceleration, lengths 0, 1, 7
    "301#00000000A00F00F0",  # its Status bits 4-7 (reserved)
    "311#00", "311#0000000010F00000",  # SensorHeartbeat: short; Status bits 4-7
    "320#00F0000000000000", "320#0700000000000000",  # MonitorStatus: bits 12-15; phase 7
    "320#0000112700000000", "320#0000000000000001",  # risk 10001 (> 1); bits 56-63
    "330#0000FE0000000000", "330#0500000000000000",  # AlarmEvent: bits 17-23; level 5
    "330#00FF000000000000",  # cause 255 (beyond the table)
    "350#1127000100000000", "351#E803050364002800",  # CollapseForecast: probability 10001;
    "350#0000110100000000",  # worst member 5 of 3 members; worst member 17
    "340#F000000000000000", "340#00",  # Acknowledge: bits 4-7; short
    "300#0000000000000000", "322#0000000000000000", "35A#11", "331#00", "341#00",  # unknown
    "37F#",  # node 15's StatueRotation, length 0 (refused; not the monitor's node)
    "301#R", "00000301#00000000A00F0000",  # RTR, extended: the kernel filter keeps them away
)


# ---- The record ------------------------------------------------------------------------------

def read_at2(path):
    """(dt, values in g) of a PEER NGA AT2 file."""
    lines = Path(path).read_text().splitlines()
    match = re.search(r"NPTS\s*=\s*(\d+)\s*,\s*DT\s*=\s*([-+.0-9Ee]+)", lines[3])
    values = [float(x) for line in lines[4:] for x in line.split()]
    return float(match.group(2)), values[: int(match.group(1))]


def value_at(dt, values, t):
    """lib/core SampledSignal::at: linear interpolation, 0 before 0 and after the last sample."""
    position = t / dt
    last = len(values) - 1
    if abs(position - last) <= 1e-9 * max(1.0, last):
        return values[-1]
    if t < 0 or position > last:
        return 0.0
    i = math.floor(position)
    return values[i] + (position - i) * (values[i + 1] - values[i])


def write_csv(path, name, rate, values_m_s2):
    with open(path, "w") as out:
        out.write(f"t,{name} [m/s2]\n")
        for k, a in enumerate(values_m_s2):
            out.write(f"{k / rate:.6f},{a:.10g}\n")


def read_csv(path):
    rows = [line.split(",") for line in Path(path).read_text().splitlines()[1:] if line.strip()]
    return [float(row[1]) for row in rows]


def prepare(args):
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    dt, values_g = read_at2(args.record)
    lead = round(args.lead_in * args.rate)
    count = math.floor(args.record_end * args.rate + 1e-6) + 1
    samples = [DITHER[k % 4] * RESOLUTION_G * G0 for k in range(lead)]
    samples += [args.scale * value_at(dt, values_g, k / args.rate) * G0 for k in range(count)]
    write_csv(work / "input.csv", Path(args.record).stem, args.rate, samples)
    # The monitor's estimator starts (t = 0, at rest) with the first sample after its health
    # tracker's recovery (10 clean samples, the 10th fed) and its start-up window: sample
    # round(window * rate) + 10 - 1, as plinth-monitor's own file replay counts its lead-in.
    start_index = round(args.startup_window * args.rate) + 10 - 1
    if start_index >= lead:
        sys.exit("e2e_can.py: --lead-in must be longer than the monitor's start-up window")
    config = {
        "record": str(Path(args.record).resolve()), "scale": args.scale, "rate": args.rate,
        "speed": args.speed, "lead_in_samples": lead, "record_samples": count,
        "record_end_s": args.record_end, "startup_window_s": args.startup_window,
        "estimator_start_index": start_index, "steps": args.steps,
        "status_interval_s": args.status_interval, "timeout_s": 0.05,
        "short_record_s": args.short,
        "scene": str(Path(args.scene).resolve()), "dbc": str(Path(args.dbc).resolve()),
        "monitor": args.monitor, "replay": args.replay, "sim": args.sim,
    }
    # For the guest (bash): the values it needs, already in its units.
    env = {
        "MONITOR": args.monitor, "REPLAY": args.replay, "SCENE": config["scene"],
        "RATE": f"{args.rate:g}", "SPEED": f"{args.speed:g}", "STEPS": str(args.steps),
        "STARTUP_WINDOW": f"{args.startup_window:g}",
        "STATUS_INTERVAL": f"{args.status_interval:g}",
        # the stop case: plinth-replay is killed this long after the monitor's level is back to
        # normal (its start-up fault is held 2 s of wall clock)
        "KILL_AFTER_NORMAL": f"{args.kill_after:g}",
        "LEAD_IN_WALL_S": f"{args.lead_in / args.speed:.3f}",  # the lead-in's wall time
        # ... waiting for that at most until 1 s before the input ends (10 ms polls)
        "STOP_WAIT_POLLS": str(max(1, round(((lead + count - 1) / args.rate / args.speed - 1.0)
                                            * 100))),
        # the garbage and burst cases send the lead-in and this much of the record
        "SHORT_T_END": f"{args.lead_in + args.short:.3f}",
        # the stall and the garbage come once the record is on (the monitor estimating)
        "GARBAGE_AFTER": f"{(args.lead_in + 0.2) / args.speed:.3f}",
        # after each run: whether the rig carried it (rig_losses), and how often to try
        "RIG_LOSSES_AWK": str(RIG_LOSSES_AWK), "MAX_ATTEMPTS": str(MAX_ATTEMPTS),
        "MAX_SLOWDOWN": str(MAX_SLOWDOWN),
        "TIMEOUT_US": str(round(config["timeout_s"] * 1e6)),
        "STARVED_LATE_US": str(STARVED_LATE_US), "BACKLOG_LATE_US": str(BACKLOG_LATE_US),
        "MIN_IDLE_PERCENT": str(MIN_IDLE_PERCENT),
        "WITNESS_RCVBUF": str(WITNESS_RCVBUF),
    }
    scenarios = args.scenarios.split(",")
    unknown = [name for name in scenarios if name not in SCENARIOS]
    if unknown or not scenarios:
        sys.exit(f"e2e_can.py: --scenarios: unknown {unknown}; the runs: {', '.join(SCENARIOS)}")
    config["scenarios"] = scenarios
    if "regional" in scenarios:
        import e2e_can_regional
        if not args.regional_scene:
            sys.exit("e2e_can.py: the regional run needs --regional-scene (a scene with "
                     "[fragility])")
        config["regional_scene"] = str(Path(args.regional_scene).resolve())
        env.update(e2e_can_regional.prepare(work, Dbc(args.dbc), args.regional_scene, args.rate,
                                            args.lead_in))
        config["regional_gaps_us"] = env["REGIONAL_GAPS_US"]
    env["SCENARIOS"] = " ".join(scenarios)
    (work / "config.json").write_text(json.dumps(config, indent=1) + "\n")
    (work / "config.env").write_text("".join(f"{k}='{v}'\n" for k, v in env.items()))
    # Garbage that the DBC accepts would be counted as a valid frame (seen when a cause was
    # added to the table a garbage frame had used as "beyond" it): refuse to run on such a list.
    dbc = Dbc(args.dbc)
    standard = [frame.split("#") for frame in GARBAGE
                if not frame.endswith("#R") and len(frame.split("#")[0]) == 3]
    valid = [f"{ident}#{data}" for ident, data in standard
             if dbc.decode(int(ident, 16), bytes.fromhex(data))[0] is not None]
    if valid:
        sys.exit(f"e2e_can.py: GARBAGE frames that {args.dbc} decodes as valid: {valid}")
    (work / "garbage.in.log").write_text("".join(f"(0.000000) vcan0 {frame}\n"
                                                 for frame in GARBAGE))
    print(f"e2e_can.py: {work / 'input.csv'}: {lead} lead-in + {count} record samples at "
          f"{args.rate:g} Hz ({(lead + count - 1) / args.rate:.3f} s), scale {args.scale:g}")
    return 0


# ---- The DBC ---------------------------------------------------------------------------------

class Signal:
    def __init__(self, name, start, length, signed, factor, offset, minimum, maximum):
        self.name, self.start, self.length, self.signed = name, start, length, signed
        self.factor, self.offset = factor, offset
        self.raw_min = round((minimum - offset) / factor)
        self.raw_max = round((maximum - offset) / factor)
        # The VAL_ table's raw values: an enumeration's (within its range), or a quantity's
        # special value outside its range (255 "none")
        self.values = None
        self.reserved_mask = 0  # flag bits the comment reserves ("bits 4-7 reserved, must be 0")


class Dbc:
    """The messages of plinth.dbc, read from the file itself, and a decoder that refuses what
    the DBC makes invalid: a length other than the message's, raw values outside [min|max] and
    missing from the signal's VAL_ table (an enumeration's table lies in its range; a quantity's
    names a special value outside it), bits no signal covers, flag bits a comment reserves."""

    def __init__(self, path):
        self.messages = {}  # id -> (name, length, [Signal])
        current = None
        for line in Path(path).read_text().splitlines():
            m = re.match(r"^BO_ (\d+) (\w+): (\d+) ", line)
            if m:
                current = (m.group(2), int(m.group(3)), [])
                self.messages[int(m.group(1))] = current
                continue
            m = re.match(r"^ SG_ (\w+) : (\d+)\|(\d+)@1([+-]) \(([^,]+),([^)]+)\) "
                         r"\[([^|]+)\|([^\]]+)\]", line)
            if m and current is not None:
                current[2].append(Signal(m.group(1), int(m.group(2)), int(m.group(3)),
                                         m.group(4) == "-", float(m.group(5)), float(m.group(6)),
                                         float(m.group(7)), float(m.group(8))))
                continue
            m = re.match(r"^VAL_ (\d+) (\w+) (.*);", line)
            if m:
                self.signal(int(m.group(1)), m.group(2)).values = {
                    int(v) for v in re.findall(r'(\d+) "[^"]*"', m.group(3))}
                continue
            m = re.match(r'^CM_ SG_ (\d+) (\w+) "(.*)";', line)
            if m:
                r = re.search(r"bits (\d+)-(\d+) reserved, must be 0", m.group(3))
                if r:
                    low, high = int(r.group(1)), int(r.group(2))
                    self.signal(int(m.group(1)), m.group(2)).reserved_mask = \
                        ((1 << (high + 1)) - 1) & ~((1 << low) - 1)
        if ACCEL_ID not in self.messages or ALARM_ID not in self.messages:
            raise ValueError(f"{path}: not the plinth DBC")

    def signal(self, ident, name):
        return next(s for s in self.messages[ident][2] if s.name == name)

    def ident(self, name):
        return next(i for i, message in self.messages.items() if message[0] == name)

    def encode(self, name, physical, raw=None):
        """The 8 bytes of message `name` (every signal given, in its unit), as the DBC lays
        them out: raw = round((value - offset) / factor), two's complement for a signed one.
        A value outside the signal's range is an error; `raw` gives raw values as they are
        (a hostile frame's, outside the range on purpose)."""
        ident = self.ident(name)
        _, length, signals = self.messages[ident]
        raw = dict(raw or {})
        if set(physical) | set(raw) != {s.name for s in signals}:
            raise ValueError(f"{name}: signals {sorted(physical) + sorted(raw)}, the DBC has "
                             f"{sorted(s.name for s in signals)}")
        word = 0
        for s in signals:
            if s.name not in raw:
                value = round((physical[s.name] - s.offset) / s.factor)
                if not s.raw_min <= value <= s.raw_max:
                    raise ValueError(f"{name}.{s.name} {physical[s.name]} outside its range")
                raw[s.name] = value
            word |= (raw[s.name] & ((1 << s.length) - 1)) << s.start
        return word.to_bytes(length, "little")

    def decode(self, ident, data):
        """({signal: raw}, "") or (None, why not)."""
        if ident not in self.messages:
            return None, "unknown identifier"
        name, length, signals = self.messages[ident]
        if len(data) != length:
            return None, f"length {len(data)}"
        word = int.from_bytes(data, "little")
        used = 0
        raw_values = {}
        for s in signals:
            mask = (1 << s.length) - 1
            used |= mask << s.start
            raw = (word >> s.start) & mask
            if s.signed and raw >> (s.length - 1):
                raw -= 1 << s.length
            # an enumeration's names lie in its range (a table may skip reserved values)
            enumeration = s.values is not None and \
                all(s.raw_min <= v <= s.raw_max for v in s.values)
            if enumeration and raw not in s.values:
                return None, f"{s.name} {raw} not in its VAL_ table"
            if not s.raw_min <= raw <= s.raw_max and not (s.values and raw in s.values):
                return None, f"{s.name} {raw} out of range"
            if raw & s.reserved_mask:
                return None, f"{s.name} reserved flags {raw:#x}"
            raw_values[s.name] = raw
        if word & ~used:
            return None, "reserved bits set"
        if name.startswith("CollapseForecast"):
            # Its comment: the worst member is one of the members, and "none collapses" is said
            # by all of Probability (0), WorstMember (255) and CollapseIn (65535) or by none.
            r = raw_values
            none = r["WorstMember"] == 255
            if not none and r["WorstMember"] >= r["Members"]:
                return None, "WorstMember not below Members"
            if none != (r["CollapseIn"] == NO_COLLAPSE_MS) or none != (r["Probability"] == 0):
                return None, "contradicting none"
        return raw_values, ""


# ---- Files the guest wrote -------------------------------------------------------------------

class Frame:
    __slots__ = ("t_us", "ident", "extended", "rtr", "data")

    def __init__(self, t_us, ident, extended, rtr, data):
        self.t_us, self.ident, self.extended, self.rtr, self.data = t_us, ident, extended, rtr, data

    def plinth(self):
        """What plinth-monitor's socket passes: standard data frames 0x300-0x37F."""
        return not self.extended and not self.rtr and PLINTH_FIRST <= self.ident <= PLINTH_LAST


CANDUMP_LINE = re.compile(r"^\((\d+)\.(\d{6})\) (\S+) ([0-9A-Fa-f]{3}|[0-9A-Fa-f]{8})#"
                          r"(R\d?|(?:[0-9A-Fa-f]{2})*)$")
# candump -d, when its socket overflowed (can-utils' candump.c)
DROPCOUNT_LINE = re.compile(r"^DROPCOUNT: dropped (\d+) CAN frames? on '([^']+)' socket "
                            r"\(total drops (\d+)\)$")


class Drop:
    """A DROPCOUNT line of candump's: `frames` lost before line `line` of its log."""
    __slots__ = ("line", "frames", "text")

    def __init__(self, line, frames, text):
        self.line, self.frames, self.text = line, frames, text


def read_candump(path):
    """(frames, [Drop]) of a candump -L -d log; ValueError for a line that is neither."""
    frames, drops = [], []
    path = Path(path)
    for number, line in enumerate(path.read_text().splitlines(), 1):
        m = CANDUMP_LINE.match(line)
        if m is None:
            d = DROPCOUNT_LINE.match(line)
            if d is not None:
                drops.append(Drop(number, int(d.group(1)), line))
            elif line.strip():
                raise ValueError(f"{path.name}:{number}: not a candump -L line: {line[:80]!r}")
            continue
        seconds, micros, _, ident, data = m.groups()
        rtr = data.startswith("R")
        frames.append(Frame(int(seconds) * 1_000_000 + int(micros), int(ident, 16), len(ident) == 8,
                            rtr, b"" if rtr else bytes.fromhex(data)))
    return frames, drops


def read_jsonl(path):
    out = []
    for line in Path(path).read_text().splitlines():
        if line.strip():
            out.append(json.loads(line))
    return out


def read_keys(path):
    """key=value lines."""
    out = {}
    if path.exists():
        for line in path.read_text().splitlines():
            if "=" in line:
                key, value = line.split("=", 1)
                out[key.strip()] = value.strip()
    return out


def ms(seconds):
    return "none" if seconds is None else f"{seconds * 1e3:.1f} ms"


def percentile(values, fraction):
    """Nearest rank, as plinth-replay's report."""
    ordered = sorted(values)
    return ordered[max(0, math.ceil(fraction * len(ordered)) - 1)]


# ---- Whose loss: the rig's or the box's ------------------------------------------------------
# The rig is the guest kernel and its CPU, candump (the witness) and plinth-replay (the sensor);
# the box is plinth-monitor. A run the rig spoiled proves nothing about the box: the guest runs
# it again (tools/e2e-can.sh, `attempt`, after `e2e_can.py rig`), MAX_ATTEMPTS times at most; if
# the last run is spoiled too, the checks fail naming the rig's losses and judge nothing else.

MAX_ATTEMPTS = 5
# After a run the guest was starved in, the next runs stream at half the speed, then a quarter:
# the box's logic is judged at any speed, and a guest that shares a busy host's CPU (stress-ng
# --cpu 2 beside the tests: idle 0-5 % of the stream at --speed 2) carries a slower stream.
MAX_SLOWDOWN = 4


def run_speed(s, config):
    """The speed a run streamed at (the guest's note; slower after a starved run)."""
    return float(s.extra.get("speed", config["speed"]))

# The witness's receive buffer, bytes (candump -r; the kernel doubles it): room for about 11 000
# frames (measured in the guest: docs/can-e2e.md), 20 s of the main run's traffic, where the
# kernel's default (rmem_default 212 992) holds 278.
WITNESS_RCVBUF = 4 << 20
# plinth-replay this late (its report's jitter_max_us): the guest was starved. In main and
# regional: its pacing jitter on a calm host is at most 27 ms (docs/can-e2e.md); in garbage and
# burst, which load the guest on purpose, a backlog that could overflow the monitor's socket (278
# frames with the kernel's default buffer).
STARVED_LATE_US = 45_000
BACKLOG_LATE_US = 300_000
# The guest's CPU idle less than this share of the stream (main, stop, regional): it could not
# carry the monitor, candump and plinth-replay (docs/can-e2e.md, "A run the rig spoiled"). Seen
# at host load 13-19: 0-6 %; on a calm host about 85 % (the three cost ~150 us a frame together
# in user-mode Linux, 550 frames a second, and plinth-replay's start).
MIN_IDLE_PERCENT = 10


RIG_LOSSES_AWK = Path(__file__).resolve().parent / "rig_losses.awk"


def rig_losses(work, name, config):
    """Why the rig spoiled run `name`, from the files it left in `work`: a list of reasons, []
    when it carried the run (rig_losses.awk, which the guest runs after each run: the witness's
    DROPCOUNT lines and missing frames, the sensor's silences, plinth-replay's lateness, the
    regional bridge's gaps). Nothing here reads what the box said."""
    work = Path(work)
    done = subprocess.run(
        ["awk", "-f", str(RIG_LOSSES_AWK), "-v", f"run={name}",
         "-v", f"report={work / f'{name}.replay.json'}",
         "-v", f"timeout_us={round(config['timeout_s'] * 1e6)}",
         "-v", f"starved_late_us={STARVED_LATE_US}", "-v", f"backlog_late_us={BACKLOG_LATE_US}",
         "-v", f"extra={work / f'{name}.extra'}", "-v", f"min_idle_percent={MIN_IDLE_PERCENT}",
         "-v", f"gaps_us={config.get('regional_gaps_us', '')}", str(work / f"{name}.bus.log")],
        capture_output=True, text=True)
    if done.returncode != 0:
        raise ValueError(f"rig_losses.awk on {name}.bus.log: {done.stderr.strip()}")
    return [line for line in done.stdout.splitlines() if line]


def read_notes(path):
    """The non-empty lines of a note file of the guest's, [] when there is none."""
    try:
        return [line for line in Path(path).read_text().splitlines() if line.strip()]
    except OSError:
        return []


def rig_cut_short(work, name, finished):
    """Why the guest has no run of `name` to judge, "" when it has one: its time ran out during
    the run (NAME.running), before the run began (no guest.done, no files), or it started none
    because the runs before it, spoiled and run again, had spent the time (NAME.rig)."""
    work = Path(work)
    notes = read_notes(work / f"{name}.rig")
    running = read_notes(work / f"{name}.running")
    earlier = f" (each run before: {' | '.join(notes)})" if notes else ""
    if running:
        return f"run {running[0]}{earlier}"
    if notes and notes[-1].split(": ", 1)[-1].startswith("not run") and \
            not (work / f"{name}.bus.log").exists():
        return notes[-1].split(": ", 1)[1]
    if not finished and not (work / f"{name}.bus.log").exists():
        return "not run: the guest's time ran out before it began"
    return ""


def rig_command(args):
    """`rig --work DIR --run NAME --attempt N`, in the guest after each run: exit 0 when the rig
    carried the run; else 1, with the reasons on stderr and in NAME.rig ("N: reason; ...")."""
    work = Path(args.work)
    config = json.loads((work / "config.json").read_text())
    try:
        losses = rig_losses(work, args.run, config)
    except ValueError as error:  # the run left no log: the checks say so
        print(f"e2e-can (guest): {args.run}, run {args.attempt}: {error}", file=sys.stderr)
        return 0
    if not losses:
        return 0
    with open(work / f"{args.run}.rig", "a") as out:
        out.write(f"{args.attempt}: {'; '.join(losses)}\n")
    print(f"e2e-can (guest): {args.run}, run {args.attempt}: {'; '.join(losses)}", file=sys.stderr)
    return 1


# ---- Checks ----------------------------------------------------------------------------------

class Checks:
    def __init__(self):
        self.failed = 0
        self.passed = 0

    def __call__(self, ok, what):
        if ok:
            self.passed += 1
            print(f"  ok    {what}")
        else:
            self.failed += 1
            print(f"  FAIL  {what}")
        return ok


class Scenario:
    """One bus run: what candump logged, what plinth-monitor printed, plinth-replay's report."""

    def __init__(self, work, name, dbc):
        self.name = name
        self.dbc = dbc
        frames, self.drops = read_candump(work / f"{name}.bus.log")
        self.frames = [f for f in frames if (f.ident, f.data) != END_MARKER]
        self.lines = read_jsonl(work / f"{name}.monitor.jsonl")
        self.monitor_rc = (work / f"{name}.monitor.rc").read_text().strip()
        self.monitor_err = (work / f"{name}.monitor.err").read_text().strip()
        self.summary = next((x for x in self.lines if x.get("type") == "summary"), None)
        self.status_lines = [x for x in self.lines if x.get("type") == "status"]
        self.alarm_lines = [x for x in self.lines if x.get("type") == "alarm"]
        self.event_lines = [x for x in self.lines if x.get("type") == "event"]
        report = (work / f"{name}.replay.json").read_text().strip()
        self.report = json.loads(report.splitlines()[-1]) if report else None
        self.replay_rc = (work / f"{name}.replay.rc").read_text().strip()
        self.extra = read_keys(work / f"{name}.extra")
        self.decoded = [dbc.decode(f.ident, f.data) if f.plinth() else (None, "not plinth")
                        for f in self.frames]
        # The monitor listens from before its first frame (a status, its start-up fault
        # alarm); every frame on the bus after that one reached its socket, or should have.
        self.ready = next((i for i in range(len(self.frames)) if self.own(i)), None)
        self.sensor = [(f, d) for f, (d, _) in zip(self.frames, self.decoded)
                       if f.plinth() and f.ident == ACCEL_ID and d is not None]
        self.epoch_us = self.sensor[0][0].t_us if self.sensor else 0

    def own(self, index):
        """A frame plinth-monitor sent: a valid MonitorStatus, CollapseForecast or AlarmEvent
        (the tests never inject valid ones)."""
        f = self.frames[index]
        return f.plinth() and (f.ident in STATUS_IDS or f.ident in FORECAST_IDS
                               or f.ident == ALARM_ID) \
            and self.decoded[index][0] is not None

    def expected_counters(self):
        """The summary's frame counters, from the bus, as the DBC says (frames after ready)."""
        c = dict(received=0, sensor_samples=0, other_nodes=0, heartbeats=0, acknowledgements=0,
                 monitor_frames=0, rejected=0, unknown_identifiers=0)
        for i in range(self.ready + 1, len(self.frames)):
            f = self.frames[i]
            if not f.plinth() or self.own(i):
                continue
            c["received"] += 1
            raw, why = self.decoded[i]
            if why == "unknown identifier":
                c["unknown_identifiers"] += 1
            elif raw is None:
                c["rejected"] += 1
            elif f.ident == ACCEL_ID:
                c["sensor_samples"] += 1
            elif 0x301 <= f.ident <= 0x30F:
                c["other_nodes"] += 1
            elif 0x311 <= f.ident <= 0x31F:
                c["heartbeats"] += 1
            elif f.ident == 0x340:
                c["acknowledgements"] += 1
            elif f.ident in STATUS_IDS or f.ident in FORECAST_IDS or f.ident == ALARM_ID:
                c["monitor_frames"] += 1
        return c

    def streaming(self, index):
        """Whether frame `index` lies between the first and the last sensor frame."""
        t = self.frames[index].t_us
        return bool(self.sensor) and self.sensor[0][0].t_us <= t <= self.sensor[-1][0].t_us

    def latency_us(self):
        """Each MonitorStatus frame's time minus the newest SensorAcceleration before it, while
        the sensor sends."""
        out = []
        last = None
        for i, f in enumerate(self.frames):
            if f.plinth() and f.ident == ACCEL_ID:
                last = f.t_us
            elif f.plinth() and f.ident in STATUS_IDS and self.own(i) and last is not None \
                    and self.streaming(i):
                out.append(f.t_us - last)
        return out


def rig_verdict(check, work, s, config):
    """The run's header; False (one failed check naming the rig's losses, nothing of the box's)
    when the rig spoiled the last run too, True when the box is to be judged on it."""
    runs = s.extra.get("attempts", "1")
    earlier = [line for line in (work / f"{s.name}.rig").read_text().splitlines()
               if line.strip()] if (work / f"{s.name}.rig").exists() else []
    losses = rig_losses(work, s.name, config)
    if not losses:
        print(f"[{s.name}]" + ("" if runs == "1" else f" (the last of {runs} runs: the rig "
                                                      f"spoiled the others: {'; '.join(earlier)})"))
        return True
    print(f"[{s.name}]")
    check(False, f"the rig could not carry the {s.name} run in {runs} attempt"
          f"{'' if runs == '1' else 's'} (at most {MAX_ATTEMPTS}): {'; '.join(losses)}"
          + (f" (each run: {' | '.join(earlier)})" if earlier else "") +
          ". The rig's losses, not the box's: the box is not judged on this run; run the test "
          "again on a less loaded host")
    return False


def common_checks(check, s, config):
    """What every run must show: the monitor stopped cleanly, nothing lost or dropped (the
    witness lost nothing: rig_verdict said so)."""
    check(s.monitor_rc == "0" and s.summary is not None,
          f"plinth-monitor stopped cleanly on {s.extra.get('stop_signal', '?')} (exit "
          f"{s.monitor_rc}, summary line written){': ' + s.monitor_err if s.monitor_err else ''}")
    check(s.ready is not None, "the monitor's first frames (status, start-up fault) are on the bus")
    if s.summary is None or s.ready is None:
        return False
    sensor = s.summary["sensor"]
    frames = s.summary["frames"]
    want = s.expected_counters()
    got = {k: frames[k] for k in want}
    check(got == want, f"the summary's frame counters match the bus as the DBC decodes it: {got}"
          + ("" if got == want else f", expected {want}"))
    on_bus = sum(1 for i in range(s.ready + 1, len(s.frames))
                 if s.frames[i].plinth() and s.frames[i].ident == ACCEL_ID
                 and s.decoded[i][0] is not None)
    check(frames["sensor_samples"] == on_bus and sensor["missing"] == 0 and
          sensor["long_gaps"] == 0 and sensor["bridged"] == 0 and sensor["duplicates"] == 0 and
          sensor["out_of_order"] == 0,
          f"no sensor frame lost: {frames['sensor_samples']} received of {on_bus} on the bus; "
          f"missing {sensor['missing']}, long gaps {sensor['long_gaps']}, bridged "
          f"{sensor['bridged']}, duplicates {sensor['duplicates']}, out of order "
          f"{sensor['out_of_order']}")
    check(s.summary["bus_send_errors"] == 0, f"bus send errors {s.summary['bus_send_errors']}")
    # A sensor timeout is right only where the bus had no sensor frame for longer than the
    # timeout: between two frames, or after the last one (the monitor runs on 0.2 s at least).
    timeout_us = config["timeout_s"] * 1e6
    stream = [f.t_us for i, f in enumerate(s.frames) if i > s.ready and f.plinth()
              and f.ident == ACCEL_ID and s.decoded[i][0] is not None]
    gaps = [b - a for a, b in zip(stream, stream[1:])]
    silent = sum(1 for g in gaps if g > timeout_us)
    trailing = 1 if stream and s.epoch_us + s.summary["t"] * 1e6 - stream[-1] > timeout_us else 0
    check(sensor["timeouts"] == silent + trailing,
          f"sensor timeouts counted {sensor['timeouts']}: the bus was silent for more than "
          f"{timeout_us / 1e3:.0f} ms {silent} times between sensor frames (longest gap "
          f"{max(gaps, default=0) / 1e3:.1f} ms) and {trailing} time at the end")
    bus_faults = [a for a in s.alarm_lines if a["cause"] == "bus_error"]
    check(not bus_faults, "no bus fault (kernel drop or error frame) reported" +
          (f": {bus_faults[0]}" if bus_faults else ""))
    return True


def replay_checks(check, s, samples):
    r = s.report
    if not check(s.replay_rc == "0" and r is not None and r["send_errors"] == 0 and
                 r["acceleration_frames"] == samples,
                 f"plinth-replay sent {r and r['acceleration_frames']} SensorAcceleration + "
                 f"{r and r['heartbeat_frames']} SensorHeartbeat frames, {samples} expected, "
                 f"send errors {r and r['send_errors']} (exit {s.replay_rc})"):
        return
    sensor_on_bus = sum(1 for f in s.frames if f.plinth() and f.ident == ACCEL_ID
                        and s.dbc.decode(f.ident, f.data)[0] is not None)
    # plinth-replay's heartbeats: firmware 0.1, error counters 0 (not the garbage case's
    # random frames that happen to decode)
    heartbeats = 0
    for f in s.frames:
        raw = s.dbc.decode(f.ident, f.data)[0] if f.plinth() and f.ident == HEARTBEAT_ID else None
        if raw and (raw["FirmwareMajor"], raw["FirmwareMinor"], raw["CanTxErrors"],
                    raw["CanRxErrors"]) == (0, 1, 0, 0):
            heartbeats += 1
    check(sensor_on_bus == r["acceleration_frames"] and heartbeats == r["heartbeat_frames"],
          f"candump logged every frame plinth-replay sent ({sensor_on_bus} + {heartbeats})")
    check(s.summary is not None and
          s.summary["frames"]["sensor_samples"] == r["acceleration_frames"],
          f"the monitor received every SensorAcceleration frame plinth-replay sent (sensor_samples "
          f"{s.summary and s.summary['frames']['sensor_samples']})")


def samples_checks(check, s, config, expected_m_s2):
    """candump's SensorAcceleration frames decode to the input, within the resolution."""
    rate, speed = config["rate"], run_speed(s, config)
    worst = 0.0
    problems = []
    for k, (f, raw) in enumerate(s.sensor):
        if k >= len(expected_m_s2):
            problems.append(f"frame {k}: more frames than samples")
            break
        want_g = expected_m_s2[k] / G0
        ax = raw["Ax"] * RESOLUTION_G
        worst = max(worst, abs(ax - want_g))
        if abs(ax - want_g) > RESOLUTION_G / 2 + 1e-9:
            problems.append(f"frame {k}: ax {ax:.5f} g, expected {want_g:.5f} g")
        if raw["Ay"] != 0 or raw["Az"] != 4000 or raw["Sequence"] != k % 256 or raw["Status"] != 0:
            problems.append(f"frame {k}: ay {raw['Ay']}, az {raw['Az']} LSB, sequence "
                            f"{raw['Sequence']}, status {raw['Status']}; expected 0, 4000, "
                            f"{k % 256}, 0")
    if len(s.sensor) != len(expected_m_s2):
        problems.append(f"{len(s.sensor)} frames, {len(expected_m_s2)} samples")
    check(not problems, f"candump's {len(s.sensor)} SensorAcceleration frames decode (per the DBC) "
          f"to the record resampled at {rate:g} Hz: |ax - input| <= {worst * 1e3:.4f} mg (half "
          f"the resolution: 0.125 mg), ay 0, az 1 g, sequence k mod 256, status 0"
          + (f": {problems[:3]}" if problems else ""))
    # Heartbeats: one per whole second of virtual time, uptime 0, 1, 2, ...
    beats = [(i, s.dbc.decode(f.ident, f.data)[0]) for i, f in enumerate(s.frames)
             if f.plinth() and f.ident == HEARTBEAT_ID]
    check(all(raw is not None and raw["Uptime"] == n for n, (_, raw) in enumerate(beats)) and
          len(beats) == math.floor((len(expected_m_s2) - 1) / rate) + 1,
          f"{len(beats)} SensorHeartbeat frames decode, uptime 0, 1, 2, ... s")
    # Send times on the bus (kernel receive times) against k / (rate * speed).
    t0 = s.sensor[0][0].t_us
    deviation = [(f.t_us - t0) - k * 1e6 / (rate * speed) for k, (f, _) in enumerate(s.sensor)]
    return deviation


def monitor_frames_checks(check, s, config):
    """MonitorStatus and AlarmEvent frames on the bus: valid per the DBC, one per JSON line."""
    status_frames = [(i, f) for i, f in enumerate(s.frames) if f.plinth() and f.ident in STATUS_IDS]
    alarm_frames = [(i, f) for i, f in enumerate(s.frames) if f.plinth() and f.ident == ALARM_ID]
    bad = [f"{f.ident:03X}#{f.data.hex()}: {s.decoded[i][1]}"
           for i, f in status_frames + alarm_frames if s.decoded[i][0] is None]
    check(not bad, f"{len(status_frames)} MonitorStatus and {len(alarm_frames)} AlarmEvent frames "
          f"decode per the DBC (phase, corner, level, cause in their VAL_ tables, risk <= 1, "
          f"reserved bits 0)" + (f": {bad[:3]}" if bad else ""))
    if bad:
        return
    raw_status = [s.decoded[i][0] for i, _ in status_frames]
    raw_alarm = [s.decoded[i][0] for i, _ in alarm_frames]
    sequences_ok = all((b["Sequence"] - a["Sequence"]) % 256 == 1
                       for a, b in zip(raw_status, raw_status[1:]))
    mismatch = []
    if len(raw_status) != len(s.status_lines):
        mismatch.append(f"{len(raw_status)} frames, {len(s.status_lines)} status lines")
    for n, (raw, line) in enumerate(zip(raw_status, s.status_lines)):
        if (PHASES[raw["Phase"]] != line["phase"] or LEVELS[raw["AlarmLevel"]] != line["alarm"] or
                ["none", "left", "right"][raw["Corner"]] != line["corner"] or
                abs(raw["Risk"] * 1e-4 - line["risk"]) > 1.5e-4):
            mismatch.append(f"status {n}: frame {raw}, line {line['phase']} {line['corner']} "
                            f"{line['alarm']} {line['risk']}")
    check(not mismatch and sequences_ok,
          "each MonitorStatus frame matches its JSON status line (phase, corner, alarm level, "
          "risk), sequence +1 per frame" + (f": {mismatch[:3]}" if mismatch else ""))
    mismatch = []
    if len(raw_alarm) != len(s.alarm_lines):
        mismatch.append(f"{len(raw_alarm)} frames, {len(s.alarm_lines)} alarm lines")
    for raw, line in zip(raw_alarm, s.alarm_lines):
        if (LEVELS[raw["Level"]] != line["level"]
                or LEVELS[raw["PreviousLevel"]] != line["previous"]
                or CAUSES[raw["Cause"]] != line["cause"] or bool(raw["Latched"]) != line["latched"]
                or raw["Sequence"] != line["sequence"]
                # the frame floors the time to the ms, the line rounds it: 1 ms apart at most,
                # with room for the product's rounding (2.023 * 1000 - 2022 is 1.0000000000002)
                or abs(raw["TimeSinceStart"] - line["t"] * 1000) > 1.0 + 1e-6):
            mismatch.append(f"frame {raw} vs line {line}")
    check(not mismatch, "each AlarmEvent frame matches its JSON alarm line (level, previous, "
          "cause, latched, sequence, time in ms): " +
          ", ".join(f"{a['level']}/{a['cause']}@{a['t']:.3f}" for a in s.alarm_lines)
          + (f": {mismatch[:3]}" if mismatch else ""))
    forecast_frames_checks(check, s, raw_status)
    return raw_status


def forecast_frames_checks(check, s, raw_status):
    """CollapseForecast frames (one axis): each valid per the DBC, its signals consistent, and
    the same as the status line it goes with (the MonitorStatus of the same sequence)."""
    frames = [(i, f) for i, f in enumerate(s.frames) if f.plinth() and f.ident in FORECAST_IDS]
    bad = [f"{f.ident:03X}#{f.data.hex()}: {s.decoded[i][1]}" for i, f in frames
           if s.decoded[i][0] is None]
    # The n-th status line goes with the n-th MonitorStatus frame; its forecast frame follows
    # that frame on the bus, with the same sequence.
    mismatch = []
    statuses = 0
    for i, f in enumerate(s.frames):
        if f.plinth() and f.ident in STATUS_IDS and s.decoded[i][0] is not None:
            statuses += 1
        if not (f.plinth() and f.ident in FORECAST_IDS) or s.decoded[i][0] is None:
            continue
        r = s.decoded[i][0]
        if statuses == 0 or statuses > min(len(raw_status), len(s.status_lines)):
            mismatch.append(f"no status before frame {r}")
            continue
        line = s.status_lines[statuses - 1]
        if r["Sequence"] != raw_status[statuses - 1]["Sequence"]:
            mismatch.append(f"sequence {r['Sequence']}, its status's "
                            f"{raw_status[statuses - 1]['Sequence']}")
        state = line["state"]
        if "members" not in state:  # two axes: the line's values are over both
            continue
        at = line["collapse_forecast_t"]
        if (abs(r["Probability"] * 1e-4 - line["probability"]) > 1.5e-4
                or r["Members"] != state["members"]
                or (at is None) != (r["CollapseIn"] == NO_COLLAPSE_MS)
                or (at is not None and abs(line["t"] + r["CollapseIn"] * 1e-3 - max(at, line["t"]))
                    > 1.5e-3)):
            mismatch.append(f"frame {r} vs line t {line['t']} probability {line['probability']} "
                            f"collapse_forecast_t {at} members {state['members']}")
    check(not bad and not mismatch,
          f"{len(frames)} CollapseForecast frames decode per the DBC (probability <= 1, worst "
          f"member below the members or none, none said by all of probability, worst member and "
          f"collapse time or by none) and match their status lines (probability, members, "
          f"collapse time = t + CollapseIn, sequence)"
          + (f": {(bad + mismatch)[:3]}" if bad or mismatch else ""))


def monitor_events(lines, frames_sensor, start_index, rate):
    """The monitor's phase events on the record's time axis: an event line's t is monitor time
    (since the first sample's receive time) = the estimator's time + its start's receive time."""
    start_s = (frames_sensor[start_index][0].t_us - frames_sensor[0][0].t_us) * 1e-6
    return [dict(e, t=e["t"] - start_s + start_index / rate) for e in lines
            if e.get("type", "event") == "event"]


def run_tool(command):
    """A tool's stdout; raises ValueError with its stderr when it fails."""
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        raise ValueError(f"{Path(command[0]).name} exited with {done.returncode}: "
                         f"{done.stderr.strip()}")
    return done.stdout


def run_sim(config, csv, out):
    dt = 1.0 / (config["rate"] * config["steps"])
    run_tool([config["sim"], "--scene", config["scene"], "--record", str(csv), "--dt", repr(dt),
              "--events", str(out)])
    return [e for e in read_jsonl(out) if e["event"] != "end"]


def compare_events(check, name, ours, theirs, tolerance_s):
    worst = 0.0
    same = len(ours) == len(theirs)
    for a, b in zip(ours, theirs):
        if a["event"] != b["event"] or a.get("corner") != b.get("corner"):
            same = False
        worst = max(worst, abs(a["t"] - b["t"]))
    timeline = ", ".join(f"{e['event']} {e.get('corner', '')} {e['t']:.4f} s" for e in ours)
    check(same and worst <= tolerance_s,
          f"{name}: same {len(ours)} events in the same order, |dt| <= {worst * 1e6:.1f} us "
          f"(tolerance {tolerance_s * 1e6:.0f} us)" +
          ("" if same else f": monitor [{timeline}] vs "
           f"[{', '.join(e['event'] + ' ' + str(e['t']) for e in theirs)}]"))
    return worst


def check_main(check, work, s, config, figures):
    expected = read_csv(work / "input.csv")
    replay_checks(check, s, len(expected))
    deviation = samples_checks(check, s, config, expected)
    figures["bus_send_time_deviation_us"] = (min(deviation), max(deviation))
    raw_status = monitor_frames_checks(check, s, config)
    rate, start = config["rate"], config["estimator_start_index"]
    step = 1.0 / (rate * config["steps"])
    lead_s = config["lead_in_samples"] / rate
    if len(s.sensor) <= start:
        check(False, "the monitor's estimator never started")
        return
    live = monitor_events(s.event_lines, s.sensor, start, rate)
    # plinth-sim on the very samples the monitor received (candump's frames, decoded): the
    # same solver with the same input, so the same events at the same times but for rounding
    # and the monitor's offset estimate (zero over the dithered lead-in) and its slow offset
    # tracking while quiet (600 s time constant): 10 us.
    quantised = [raw["Ax"] * RESOLUTION_G * G0 for _, raw in s.sensor]
    write_csv(work / "bus-samples.csv", "bus", rate, quantised)
    sim_bus = run_sim(config, work / "bus-samples.csv", work / "sim-bus.jsonl")
    compare_events(check, "monitor on the bus vs plinth-sim on the bus's samples", live, sim_bus,
                   10e-6)
    # plinth-sim on the input itself (before the codec's 0.25 mg quantisation): one solver step.
    sim = run_sim(config, work / "input.csv", work / "sim.jsonl")
    worst = compare_events(check, f"monitor on the bus vs plinth-sim on the record "
                           f"(--dt {step:g})", live, sim, step)
    figures["timeline_vs_sim_us"] = worst * 1e6
    figures["timeline"] = ", ".join(f"{e['event']} {e.get('corner', '')} at {e['t'] - lead_s:.4f} s"
                                    for e in sim)
    # plinth-monitor --replay of candump's log: the same frames at the same times.
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    replayed = run_tool(
        [config["monitor"], "--scene", config["scene"], "--replay", str(work / "main.bus.log"),
         "--rate", f"{rate:g}", "--startup-window", f"{config['startup_window_s']:g}",
         "--status-interval", f"{config['status_interval_s']:g}"])
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu_s = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    figures["host_cpu_us_per_frame"] = cpu_s * 1e6 / max(1, len(s.frames))
    (work / "main.monitor-replay.jsonl").write_text(replayed)
    lines = [json.loads(x) for x in replayed.splitlines() if x.strip()]
    compare_events(check, "monitor on the bus vs plinth-monitor --replay main.bus.log",
                   live, monitor_events(lines, s.sensor, start, rate), 2e-6)
    phases = [PHASES[r["Phase"]] for r in raw_status or []]
    check(phases and phases[-1] == "overturned" and "rocking" in phases,
          "the MonitorStatus frames on the bus show the block rocking, then overturned")
    check(s.summary["final_phase"] == "overturned" and s.summary["max_alarm"] == "alarm" and
          s.summary["estimator_restarts"] == 1,
          f"summary: final phase {s.summary['final_phase']}, max alarm {s.summary['max_alarm']}, "
          f"estimator started {s.summary['estimator_restarts']} time(s)")
    latency = s.latency_us()
    figures["latency_us"] = latency
    figures["jitter"] = s.report
    figures["main_wall_s"] = s.report["wall_time_s"]
    figures["main_attempts"] = s.extra.get("attempts", "?")
    figures["main_speed"] = run_speed(s, config)
    status_index = [i for i, f in enumerate(s.frames) if f.plinth() and f.ident in STATUS_IDS]
    ages = [r["SampleAge"] for i, r in zip(status_index, raw_status or [])
            if s.streaming(i) and s.frames[i].t_us > s.sensor[start][0].t_us]
    figures["sample_age_ms_max"] = max(ages, default=None)


def fault_delay(s):
    """The first sensor_timeout fault line after the last sensor frame, and its delays after
    that frame: in monitor time (JSON) and on the bus (its AlarmEvent frame), s."""
    last = s.sensor[-1][0].t_us
    line = next((a for a in s.alarm_lines
                 if a["level"] == "fault" and a["cause"] == "sensor_timeout"
                 and a["t"] * 1e6 + s.epoch_us > last - 1), None)
    frame = next((f for i, f in enumerate(s.frames) if f.plinth() and f.ident == ALARM_ID
                  and f.t_us > last and s.decoded[i][0] is not None
                  and s.decoded[i][0]["Level"] == 4 and s.decoded[i][0]["Cause"] == 4), None)
    json_delay = None if line is None else (line["t"] * 1e6 + s.epoch_us - last) * 1e-6
    bus_delay = None if frame is None else (frame.t_us - last) * 1e-6
    return line, json_delay, bus_delay


def check_stop(check, s, config, figures):
    rate = config["rate"]
    killed_at = (len(s.sensor) - 1) / rate - config["lead_in_samples"] / rate
    check(s.replay_rc == "137" and 0 < killed_at < config["record_end_s"] - 0.5,
          f"plinth-replay killed (SIGKILL, exit {s.replay_rc}) mid-record, after the sample at "
          f"{killed_at:.3f} s of the record")
    timeout = config["timeout_s"]
    line, json_delay, bus_delay = fault_delay(s)
    figures["fault_delay_s"] = (json_delay, bus_delay)
    # The health tracker declares the timeout at the first tick at least timeout_s after the
    # last sample; plinth-monitor ticks after every receive() (10 ms poll): timeout + 10 ms,
    # plus scheduling in the guest (bounded at 100 ms in all, so that a loaded host passes).
    ok = line is not None and bus_delay is not None and \
        timeout <= json_delay <= bus_delay <= timeout + 0.1 and line["previous"] != "fault"
    check(ok, f"fault (sensor_timeout) raised {ms(json_delay)} after the last sensor frame "
          f"(monitor time; from {line and line['previous']}), its AlarmEvent on the bus "
          f"{ms(bus_delay)} after it (timeout {timeout * 1e3:.0f} ms, allowed up to "
          f"{(timeout + 0.1) * 1e3:.0f} ms)")
    check("no_normal_level" not in s.extra, "the monitor's level was back to normal (start-up "
          "fault over) before the sensor was killed")
    check(s.summary["sensor"]["timeouts"] == 1 and s.summary["alarm"] == "fault",
          f"summary: sensor timeouts {s.summary['sensor']['timeouts']}, alarm {s.summary['alarm']}")


def check_garbage(check, s, config, expected_samples):
    replay_checks(check, s, expected_samples)
    c = s.summary["frames"]
    check(c["rejected"] > 0 and c["unknown_identifiers"] > 0,
          f"garbage counted: rejected {c['rejected']} (last error: {c['last_error']}), unknown "
          f"identifiers {c['unknown_identifiers']}, other nodes {c['other_nodes']}")
    # A silence longer than the timeout after the estimator started may restart it (the generic
    # check above counts the silences; two close ones make one restart); nothing else may.
    start_us = s.sensor[config["estimator_start_index"]][0].t_us if len(s.sensor) > \
        config["estimator_start_index"] else float("inf")
    restarts = 1 + sum(1 for (a, _), (b, _) in zip(s.sensor, s.sensor[1:])
                       if b.t_us - a.t_us > config["timeout_s"] * 1e6 and a.t_us >= start_us)
    check(s.summary["sensor"]["rejected"] == 0 and s.summary["estimator_restarts"] <= restarts,
          f"the sensor stream went on undisturbed by the garbage and by the monitor's "
          f"{s.extra.get('stalled_s', '?')} s stall (SIGSTOP): sensor samples rejected "
          f"{s.summary['sensor']['rejected']}, estimator started "
          f"{s.summary['estimator_restarts']} time(s), at most {restarts} expected")


def check_burst(check, s, config, expected_samples, figures):
    replay_checks(check, s, expected_samples)
    sent = int(s.extra.get("tx_after", 0)) - int(s.extra.get("tx_before", 0))
    seconds = (int(s.extra.get("flood_stop_ns", 0)) - int(s.extra.get("flood_start_ns", 0))) * 1e-9
    plinth = sum(1 for f in s.frames if f.plinth())
    foreign = sent - plinth
    rate = foreign / seconds if seconds > 0 else 0.0
    figures["burst"] = (foreign, seconds, rate, s.report, s.latency_us())
    check(foreign > 1000, f"{foreign} unrelated frames (id 0x2FF, random extended ids) "
          f"in {seconds:.2f} s ({rate:.0f} frames/s) alongside {plinth} plinth frames")


def describe(values, unit="us"):
    if not values:
        return "none"
    return (f"median {statistics.median(values):.0f} {unit}, p99 {percentile(values, 0.99):.0f} "
            f"{unit}, max {max(values):.0f} {unit} ({len(values)} frames)")


def run_checks(args):
    work = Path(args.work)
    config = json.loads((work / "config.json").read_text())
    dbc = Dbc(config["dbc"])
    checks = Checks()
    figures = {}
    timing = read_keys(work / "guest.times")
    runs = {}
    finished = (work / "guest.done").exists()
    for name in config["scenarios"]:
        cut_short = rig_cut_short(work, name, finished)
        if cut_short:
            print(f"[{name}]")
            checks(False, f"the rig could not carry the {name} run: {cut_short}. The rig's "
                   f"losses, not the box's: run the test again on a less loaded host")
            continue
        try:
            runs[name] = Scenario(work, name, dbc)
        except (OSError, ValueError) as error:
            print(f"[{name}]")
            checks(False, f"the {name} run left no usable output: {error}")
    short_samples = round((config["lead_in_samples"] / config["rate"] + config["short_record_s"])
                          * config["rate"]) + 1

    def judged(name):  # the run is there, the rig carried it, and the common checks ran
        return name in runs and rig_verdict(checks, work, runs[name], config) and \
            common_checks(checks, runs[name], config)

    if judged("main"):
        try:
            check_main(checks, work, runs["main"], config, figures)
        except ValueError as error:  # plinth-sim or plinth-monitor --replay failed
            checks(False, str(error))
    if judged("stop"):
        check_stop(checks, runs["stop"], config, figures)
    if judged("garbage"):
        check_garbage(checks, runs["garbage"], config, short_samples)
    if judged("burst"):
        check_burst(checks, runs["burst"], config, short_samples, figures)
    if judged("regional"):
        import e2e_can_regional
        figures["regional_ms"] = e2e_can_regional.check(checks, runs["regional"], config)

    print("measured:")
    if "latency_us" in figures:
        print(f"  record: {figures['timeline']} (record time; plinth-sim on the same input)")
        print(f"  sensor frame -> MonitorStatus frame latency on the bus: "
              f"{describe(figures['latency_us'])}")
        j = figures["jitter"]
        print(f"  plinth-replay pacing jitter (send - deadline): median "
              f"{j['jitter_median_us']:.0f} us, p99 {j['jitter_p99_us']:.0f} us, max "
              f"{j['jitter_max_us']:.0f} us over {j['frames_sent']} frames at --speed "
              f"{figures['main_speed']:g} ({config['rate'] * figures['main_speed']:g} frames/s)")
        print(f"  the record run took {figures['main_wall_s']:.2f} s (run "
              f"{figures['main_attempts']} of at most {MAX_ATTEMPTS})")
        lo, hi = figures["bus_send_time_deviation_us"]
        print(f"  sensor frames on the bus vs k / (rate x speed): {lo:.0f} to {hi:.0f} us")
        print(f"  monitor timeline vs plinth-sim: {figures['timeline_vs_sim_us']:.1f} us "
              f"(solver step {1e6 / (config['rate'] * config['steps']):.0f} us)")
        print(f"  newest-sample age in the MonitorStatus frames (estimating, sensor sending): at "
              f"most {figures['sample_age_ms_max']} ms")
    if "host_cpu_us_per_frame" in figures:
        print(f"  plinth-monitor's own work: {figures['host_cpu_us_per_frame']:.1f} us of CPU per "
              f"frame (plinth-monitor --replay main.bus.log on the host, start-up included); "
              f"inside user-mode Linux add its system calls (poll, recvmsg, clock_gettime, "
              f"sendmsg) at ~16 us each (not measured on the qemu route)")
    if "fault_delay_s" in figures:
        json_delay, bus_delay = figures["fault_delay_s"]
        print(f"  sensor stop -> fault: {ms(json_delay)} (monitor time), AlarmEvent on the bus "
              f"after {ms(bus_delay)}")
    if "burst" in figures:
        foreign, seconds, rate, report, latency = figures["burst"]
        print(f"  burst: {foreign} unrelated frames in {seconds:.2f} s ({rate:.0f} frames/s); "
              f"latency {describe(latency)}; jitter median {report['jitter_median_us']:.0f} us, "
              f"p99 {report['jitter_p99_us']:.0f} us, max {report['jitter_max_us']:.0f} us")
    if figures.get("regional_ms") is not None:
        print(f"  regional: the dangerous alert's RegionalAlert frame -> the AlarmEvent (warning, "
              f"cause regional_alert) on the bus: {figures['regional_ms']:.1f} ms")
    if timing:
        print("  guest wall time: " + ", ".join(f"{k} {float(v):.2f} s" for k, v in timing.items()))
    print(f"e2e-can: {checks.passed} checks passed, {checks.failed} failed")
    return 1 if checks.failed else 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("prepare")
    p.add_argument("--work", required=True)
    p.add_argument("--record", required=True)
    p.add_argument("--scene", required=True)
    p.add_argument("--dbc", required=True)
    p.add_argument("--monitor", required=True)
    p.add_argument("--replay", required=True)
    p.add_argument("--sim", required=True)
    p.add_argument("--scale", type=float, default=20.0)
    p.add_argument("--rate", type=float, default=200.0)
    p.add_argument("--speed", type=float, default=2.0)
    p.add_argument("--steps", type=int, default=4)
    p.add_argument("--lead-in", type=float, default=1.25, help="s of quiet input before the record")
    p.add_argument("--record-end", type=float, default=11.0, help="s of the record sent")
    p.add_argument("--startup-window", type=float, default=1.0)
    p.add_argument("--status-interval", type=float, default=0.02)
    p.add_argument("--kill-after", type=float, default=0.1,
                   help="s after the monitor's level is normal again: the stop case")
    p.add_argument("--short", type=float, default=2.0, help="record s: the garbage and burst cases")
    p.add_argument("--scenarios", default="main,stop,garbage,burst",
                   help="the runs, comma-separated: " + ", ".join(SCENARIOS))
    p.add_argument("--regional-scene", help="the regional run's scene (with [fragility])")
    c = sub.add_parser("check")
    c.add_argument("--work", required=True)
    r = sub.add_parser("rig", help="in the guest after a run: did the rig carry it (exit 0)?")
    r.add_argument("--work", required=True)
    r.add_argument("--run", required=True, choices=SCENARIOS)
    r.add_argument("--attempt", required=True, type=int)
    args = parser.parse_args()
    if args.command == "rig":
        return rig_command(args)
    return prepare(args) if args.command == "prepare" else run_checks(args)


if __name__ == "__main__":
    sys.exit(main())
