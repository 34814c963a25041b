#!/usr/bin/env python3
"""Inside the qemu route's guest with a gpio-sim chip (tools/vcan-bus.sh --gpio-sim N, N >= 4):
plinth-monitor drives its relays on the simulated chip (libgpiod backend) while it replays a
candump log in real time, and this script reads the lines' levels on the simulator's side
(GPIO_SIM_SYSFS/sim_gpioK/value) each time the monitor reports a status:

  advisory, warning, alarm: lines 0, 1, 2, active-high (the simulator pulls them down);
  fault: line 3, active-low (the simulator pulls it up, as an opto-isolated board's input).

The log: 3 s quiet, a 0.5 s gap (sensor timeout: fault), 3 s quiet, then Brienza x20 (advisory,
warning, alarm, latched; the block overturns). Checked: every relay released (contact open) in
fault, energised when normal, the level relays open at the alarm and held (latched), all
released when the process ends at the end of its input, and when it is killed (SIGKILL) while
every relay is energised. Exit 0 when all of that holds.
Environment: GPIO_SIM_CHIP, GPIO_SIM_LINES, GPIO_SIM_SYSFS (from vcan-bus.sh), PLINTH_MONITOR,
PLINTH_REPLAY; run from the repository's root.
"""
import json
import os
import random
import select
import signal
import subprocess
import sys
import tempfile
import time

CHIP = os.environ.get("GPIO_SIM_CHIP", "")
SYSFS = os.environ.get("GPIO_SIM_SYSFS", "")
MONITOR = os.environ.get("PLINTH_MONITOR", "")
REPLAY = os.environ.get("PLINTH_REPLAY", "")
RELAYS = ("advisory", "warning", "alarm", "fault")
ACTIVE_LOW = (False, False, False, True)
LEVELS = ("normal", "advisory", "warning", "alarm", "fault")
PASSED, FAILED = [], []


def check(ok, what):
    print(("ok - " if ok else "not ok - ") + what, flush=True)
    (PASSED if ok else FAILED).append(what)


def sim_levels():
    """The physical level of lines 0..3 as the simulator reads them."""
    out = []
    for k in range(4):
        with open(os.path.join(SYSFS, "sim_gpio%d" % k, "value")) as f:
            out.append(int(f.read().strip()))
    return tuple(out)


def physical(energised):
    return tuple(int(e != low) for e, low in zip(energised, ACTIVE_LOW))


RELEASED = physical((False,) * 4)  # every contact open: (0, 0, 0, 1)


def expected(alarm, latched, fault):
    """relay_energised (firmware/linux/relay_outputs.cpp) as the physical line levels."""
    if alarm == "fault":
        return RELEASED
    reached = max(LEVELS.index(alarm), 0 if latched == "fault" else LEVELS.index(latched))
    energised = [reached < level for level in (1, 2, 3)] + [not fault]
    return physical(energised)


def make_log(folder):
    """3 s of quiet noise, a 0.5 s gap, 3 s of quiet, then 12 s of Brienza x20, as candump."""
    rng = random.Random(1)
    quiet_csv = os.path.join(folder, "quiet.csv")
    with open(quiet_csv, "w") as f:
        f.write("t,quiet [g]\n")
        for k in range(600):
            f.write("%.3f,%.5f\n" % (k / 200.0, rng.gauss(0.0, 0.002)))
    logs = []
    for name, args in (("quiet", ["--record", quiet_csv]),
                       ("quake", ["--record", "sim/data/records/irpinia1980_brienza_000.AT2",
                                  "--scale", "20", "--t-end", "12"])):
        path = os.path.join(folder, name + ".log")
        subprocess.run([REPLAY] + args + ["--speed", "max", "--log", path], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        frames = []
        for line in open(path):
            stamp, rest = line.split(")", 1)
            frames.append((float(stamp[1:]), rest))
        logs.append([(t - frames[0][0], rest) for t, rest in frames])
    quiet, quake = logs
    out = os.path.join(folder, "relays.log")
    with open(out, "w") as f:
        for start, frames in ((0.0, quiet), (3.5, quiet), (6.505, quake)):
            for t, rest in frames:
                f.write("(%.6f)%s" % (1000.0 + start + t, rest))
    return out


def start_monitor(folder, log):
    config = os.path.join(folder, "box.toml")
    with open(config, "w") as f:
        f.write('[relays]\nchip = "%s"\nadvisory = 0\nwarning = 1\nalarm = 2\n'
                "fault = { line = 3, active_low = true }\n" % CHIP)
    return subprocess.Popen(
        ["stdbuf", "-oL", MONITOR, "--scene", "sim/scenes/paper-isolated.toml", "--replay", log,
         "--speed", "1", "--config", config, "--status-interval", "0.25", "--no-events"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def process_state(pid):
    """The state letter of /proc/PID/stat (R, S, T stopped, Z exited), or None when gone."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return f.read().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return None


def statuses(proc):
    """(newest status line, the lines' levels) each time the monitor prints a status: the monitor
    is stopped (SIGSTOP) while its pipe is drained to its newest status and the levels are read,
    so a loaded guest's slow reader compares like with like; then it goes on (SIGCONT). Its
    pacing is by absolute deadlines, its sensor timeouts by the log's clock: the pauses change
    neither. Nothing is read once it has exited (its lines are released then)."""
    fd = proc.stdout.fileno()
    pending = b""
    while True:
        chunk = os.read(fd, 65536)
        if not chunk:
            return
        pending += chunk
        if b'"type": "status"' not in pending:
            continue
        proc.send_signal(signal.SIGSTOP)
        while process_state(proc.pid) not in ("T", "Z", None):
            time.sleep(0.001)
        while select.select([fd], [], [], 0)[0]:
            more = os.read(fd, 65536)
            if not more:
                break
            pending += more
        complete, _, pending = pending.rpartition(b"\n")
        newest = None
        for line in complete.split(b"\n"):
            if line.startswith(b"{") and b'"type": "status"' in line:
                newest = json.loads(line)
        if newest is not None and process_state(proc.pid) == "T":
            yield newest, sim_levels()
        proc.send_signal(signal.SIGCONT)


def run_to_the_end(folder, log):
    proc = start_monitor(folder, log)
    seen = {}  # the state each read checked: (alarm, latched, fault)
    pending = None  # a mismatch, excused only if the state changed right after it
    mismatches = []
    consumer_ok = None
    for status, levels in statuses(proc):
        # The fault relay: a sensor at fault, a disagreement, or any trouble beside the level
        # (docs/safety.md).
        fault = (status["sensors_state"] == "fault" or status["disagreement"] or
                 status["trouble"] != "none")
        state = (status["alarm"], status["latched"], fault)
        if pending is not None and pending[0] == state:
            mismatches.append(pending)  # the same state still: the read was wrong
        pending = None
        if levels == expected(*state):
            seen[state] = seen.get(state, 0) + 1
        else:
            pending = (state, status["t"], levels)
        if consumer_ok is None and state == ("normal", "normal", False):
            info = subprocess.run(["gpioinfo", CHIP], capture_output=True, text=True).stdout
            held = [l.split() for l in info.splitlines() if '"plinth-monitor"' in l]
            consumer_ok = (len(held) == 4 and all("output" in h for h in held) and
                           ["active-low" in h for h in held] == list(ACTIVE_LOW)) or info
    rc = proc.wait(timeout=60)
    err = proc.stderr.read().decode()
    after = sim_levels()
    check(rc == 0, "the replay ran to its end (exit %s): %s" % (rc, err.strip()))
    check(not mismatches, "every status read back as its relays: mismatches %s" % mismatches)
    check(consumer_ok is True, "gpioinfo shows plinth-monitor holding 4 output lines, the last "
          "active-low: %s" % ("" if consumer_ok is True else consumer_ok))
    in_fault = sum(n for state, n in seen.items() if state[0] == "fault")
    check(in_fault >= 3, "fault (start, the gap, the new start-up window): every relay released, "
          "%d reads" % in_fault)
    check(seen.get(("normal", "normal", False), 0) >= 3,  # a loaded host's guest reads fewer
          "normal: every relay energised, %d reads" % seen.get(("normal", "normal", False), 0))
    # The quake begins without a quiet window: the alarm comes with the trouble not_calibrated
    # beside it, so the fault relay is released too.
    alarmed = sum(n for state, n in seen.items() if state[:2] == ("alarm", "alarm"))
    check(alarmed >= 3, "alarm, latched: the three level relays open, the fault relay as the "
          "trouble says, %d reads" % alarmed)
    check(after == RELEASED, "process ended: every line back to its pull (released): %s" % (after,))


def killed_while_healthy(folder, log):
    proc = start_monitor(folder, log)
    energised = None
    for status, levels in statuses(proc):
        if status["alarm"] == "normal" and levels == physical((True,) * 4):
            energised = levels
            break
    if energised is not None:
        proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=60)
    proc.stdout.close()
    proc.stderr.close()
    after = sim_levels()
    check(energised is not None, "every relay energised before the kill: %s" % (energised,))
    check(after == RELEASED, "SIGKILL: every contact open at once: %s" % (after,))


def main():
    if not (CHIP and SYSFS and MONITOR and REPLAY):
        print("relays (guest): needs GPIO_SIM_CHIP, GPIO_SIM_SYSFS (tools/vcan-bus.sh --gpio-sim "
              "4), PLINTH_MONITOR and PLINTH_REPLAY", file=sys.stderr)
        return 2
    for k, low in enumerate(ACTIVE_LOW):
        with open(os.path.join(SYSFS, "sim_gpio%d" % k, "pull"), "w") as f:
            f.write("pull-up" if low else "pull-down")
    check(sim_levels() == RELEASED, "before the monitor: the board's pulls, every relay off")
    with tempfile.TemporaryDirectory(dir="/dev/shm" if os.path.isdir("/dev/shm") else None) as d:
        log = make_log(d)
        run_to_the_end(d, log)
        killed_while_healthy(d, log)
    print("%d passed, %d failed" % (len(PASSED), len(FAILED)))
    return 1 if FAILED else 0


if __name__ == "__main__":
    sys.exit(main())
