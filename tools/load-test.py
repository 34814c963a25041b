#!/usr/bin/env python3
"""plinth-monitor under load, on a real CAN bus, with real clients (docs/load.md).

In one guest kernel (tools/vcan-bus.sh: user-mode Linux, else QEMU), two runs of the box on
vcan0 at 1000 Hz, fed the same input by plinth-replay (the sensor node):

  idle    the box with its Modbus server and MQTT publisher on, nobody connected but the
          MQTT witness, the broker up
  loaded  the same, and at once: CLIENTS Modbus TCP clients (real connections, each reading
          the 32 input registers POLL_HZ times a second), cangen filling the bus to BUS_LOAD of
          a 500 kbit/s bus (the computation: docs/load.md), and the broker (mosquitto) stalled
          with SIGSTOP for STALL s, then killed (SIGKILL: the connection dropped, nothing sent
          during the stall acknowledged) and away for DROP s, then started again; the quake's
          alarm events happen while it is stalled

Then it prints, from this one run: samples sent and lost, the sample-to-status latency
(plinth-monitor --latency: a sensor frame's arrival in the loop to its status ready) median
and p99 idle and loaded and their ratios, the alarm events the box printed and those the
witness (mosquitto_sub, a persistent QoS 1 session on a broker saving it every second, so
it outlives the kill) received after the broker came back, the
queue's high-water mark and overflow counter, the Modbus answers and the bus load reached, the
box's file descriptors and memory. --check exits 1 when a sample or an alarm event was lost,
an answer was wrong, or the box's descriptors grew (above the first count at the last three
samples); --max-p99-ratio R also when the loaded p99 exceeds R times the idle one.

Usage: tools/load-test.py [--build DIR] [--work DIR] [--clients 50] [--poll-hz 100]
                          [--bus-load 0.9] [--lead S] [--stall S] [--drop S] [--tail S]
                          [--route auto|uml|qemu] [--if-chosen FILE] [--check]
                          [--max-p99-ratio R] [--json FILE]
Exit: 0 done (and the checks passed), 1 a check failed or the run failed, 2 usage, 77 no
route to a CAN bus can start here (tools/vcan-bus.sh; with CI=true it fails instead).
Python 3 standard library only; in the guest also: mosquitto, mosquitto_sub, cangen, chrt.
"""
import argparse
import json
import os
import selectors
import shutil
import signal
import socket
import struct
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "integration"))
import e2e_can  # noqa: E402  the sensor input (quiet lead-in with dither, the record in m/s2)

RATE_HZ = 1000.0          # the sensor rate the box runs at
BUS_BITRATE = 500_000     # bit/s: the bus the load is a share of
FRAME_BITS = 111          # a standard 8-byte data frame without stuff bits, interframe space in
REGISTERS = 32            # read by each poll: input registers 0-31
LOAD_ID = "2FF"           # cangen's identifier: outside plinth's 0x300-0x37F, above them all in
                          # arbitration on a real bus
BOX_ID = "load"
FIFO_BOX = 50             # the packaged unit's CPUSchedulingPriority (docs/install.md)
FIFO_NODES = 60           # the sensor node and the other bus nodes: hardware of their own


# ---- Modbus TCP clients (a process of their own in the guest) -------------------------------

def modbus_clients(port, clients, poll_hz, duration_s, out_path):
    """CLIENTS connections, each sending a read of the input registers every 1/POLL_HZ s
    (function 04, 0-31) and checking the answer's framing; counts per client."""
    period = 1.0 / poll_hz
    sel = selectors.DefaultSelector()
    state = []
    start = time.monotonic()
    for i in range(clients):
        s = socket.create_connection(("127.0.0.1", port), timeout=10)
        s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        s.setblocking(False)
        c = {"sock": s, "next": start + i * period / clients, "tid": 0, "sent_at": None,
             "buf": b"", "answers": 0, "bad": 0, "late": 0, "rtt": []}
        state.append(c)
        sel.register(s, selectors.EVENT_READ, c)
    answer_len = 9 + 2 * REGISTERS
    end = start + duration_s
    closed = 0
    while True:
        now = time.monotonic()
        if now >= end:
            break
        for c in state:
            if c["sent_at"] is None and c["sock"] is not None and now >= c["next"]:
                c["tid"] = (c["tid"] + 1) & 0xFFFF
                c["sock"].send(struct.pack(">HHHBBHH", c["tid"], 0, 6, 1, 4, 0, REGISTERS))
                c["sent_at"] = now
                if now - c["next"] > period:
                    c["late"] += 1
                c["next"] += period
                if c["next"] < now:  # fell behind: no burst to catch up
                    c["next"] = now + period
        wake = min([c["next"] for c in state if c["sent_at"] is None] + [end])
        for key, _ in sel.select(timeout=max(0.0, wake - time.monotonic())):
            c = key.data
            try:
                data = c["sock"].recv(4096)
            except ConnectionError:
                data = b""
            if not data:
                sel.unregister(c["sock"])
                c["sock"].close()
                c["sock"] = None
                closed += 1
                continue
            c["buf"] += data
            if len(c["buf"]) >= answer_len:
                tid, proto, length, _unit, function, count = struct.unpack(
                    ">HHHBBB", c["buf"][:9])
                ok = (tid == c["tid"] and proto == 0 and length == 3 + 2 * REGISTERS and
                      function == 4 and count == 2 * REGISTERS)
                c["answers" if ok else "bad"] += 1
                c["rtt"].append(time.monotonic() - c["sent_at"])
                c["buf"] = c["buf"][answer_len:]
                c["sent_at"] = None
    rtt = sorted(x for c in state for x in c["rtt"])
    result = {
        "clients": clients, "poll_hz": poll_hz, "duration_s": time.monotonic() - start,
        "answers": sum(c["answers"] for c in state), "bad": sum(c["bad"] for c in state),
        "late": sum(c["late"] for c in state), "closed_by_server": closed,
        "fewest_answers": min(c["answers"] for c in state),
        "rtt_p50_ms": 1e3 * rtt[len(rtt) // 2] if rtt else None,
        "rtt_p99_ms": 1e3 * rtt[min(len(rtt) - 1, int(0.99 * len(rtt)))] if rtt else None,
    }
    Path(out_path).write_text(json.dumps(result) + "\n")
    return 0


# ---- The guest: both runs ----------------------------------------------------------------------

class Scenario:
    """Both runs, in the guest (the box on vcan0 fed by plinth-replay) or on the host (the box
    replaying the same input itself, paced: no bus)."""

    def __init__(self, work):
        self.work = Path(work)
        self.cfg = json.loads((self.work / "config.json").read_text())
        self.on_bus = self.cfg["where"] == "guest"
        self.broker_port = self.cfg["broker_port"]
        self.modbus_port = self.cfg["modbus_port"]
        self.procs = []

    def log(self, text):
        with open(self.work / "guest.log", "a") as f:
            f.write(f"{time.monotonic():.3f} {text}\n")

    def start(self, name, argv, **kw):
        out = open(self.work / f"{name}.out", "w")
        err = open(self.work / f"{name}.err", "w")
        p = subprocess.Popen(argv, stdout=out, stderr=err, **kw)
        self.procs.append(p)
        self.log(f"started {name} ({p.pid}): {' '.join(map(str, argv))}")
        return p

    def wait_port(self, port, seconds):
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                return True
            except OSError:
                time.sleep(0.05)
        return False

    def broker(self):
        conf = self.work / "broker.conf"
        conf.write_text(f"listener {self.broker_port} 127.0.0.1\nallow_anonymous true\n"
                        # The witness's session survives the broker's kill: saved every
                        # second (as root, mosquitto would switch to its own user, who cannot
                        # write the run's folder).
                        + ("user root\n" if os.geteuid() == 0 else "") +
                        f"persistence true\npersistence_location {self.work}/\n"
                        "autosave_interval 1\nmax_queued_messages 100000\n")
        p = self.start("broker", [shutil.which("mosquitto") or "/usr/sbin/mosquitto", "-c",
                                  str(conf)])
        if not self.wait_port(self.broker_port, 20):
            raise SystemExit("load-test (guest): mosquitto did not start: "
                             + (self.work / "broker.err").read_text()[-300:])
        return p

    def tx_packets(self):
        if not self.on_bus:
            return 0
        return int(Path("/sys/class/net/vcan0/statistics/tx_packets").read_text())

    def box_usage(self, pid):
        fds = len(os.listdir(f"/proc/{pid}/fd"))
        rss = 0
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                rss = int(line.split()[1])
        return fds, rss

    def run(self, name, loaded):
        cfg = self.cfg
        box_toml = self.work / "box.toml"
        box_toml.write_text(
            f'[modbus]\nlisten = "127.0.0.1:{self.modbus_port}"\nmax_clients = 64\n'
            f'[mqtt]\nbroker = "127.0.0.1:{self.broker_port}"\nbox_id = "{BOX_ID}"\n'
            f"state_interval_s = 0.1\n")
        broker = self.broker()
        for db in self.work.glob("*.db"):
            db.unlink()
        witness = self.start(f"{name}.witness", [
            "mosquitto_sub", "-h", "127.0.0.1", "-p", str(self.broker_port), "-c", "-i",
            f"witness-{name}", "-q", "1", "-t", f"plinth/{BOX_ID}/events"])
        time.sleep(1.0)  # the witness's session exists before the box publishes
        record_dir = self.work / f"{name}.captures"
        source = (["--can", "vcan0"] if self.on_bus else
                  ["--replay", str(self.work / "input.csv"), "--speed", "1"])
        box = self.start(f"{name}.box", [
            "chrt", "--fifo", "--reset-on-fork", str(FIFO_BOX), cfg["monitor"],
            "--scene", cfg["scene"], *source, "--rate", f"{RATE_HZ:g}",
            "--latency", "--no-events", "--config", str(box_toml),
            "--record-dir", str(record_dir)])
        if not self.wait_port(self.modbus_port, 30):
            raise SystemExit(f"load-test (guest): {name}: the box did not start: "
                             + (self.work / f"{name}.box.err").read_text()[-300:])
        time.sleep(1.0)  # connected to the broker: the descriptors it holds from now on
        usage = [self.box_usage(box.pid)]
        extra = {}
        clients = cangen = None
        duration = cfg["input_s"]
        if loaded:
            clients = self.start(f"{name}.modbus", [
                sys.executable, str(ROOT / "tools" / "load-test.py"), "--modbus-clients",
                str(cfg["clients"]), "--poll-hz", str(cfg["poll_hz"]),
                "--port", str(self.modbus_port),
                "--duration", f"{duration - 4:g}", "--out", str(self.work / f"{name}.modbus.json")])
            if self.on_bus:
                burst, gap_ms = cfg["cangen_burst"], cfg["cangen_gap_ms"]
                cangen = self.start(f"{name}.cangen", [
                    "chrt", "--fifo", str(FIFO_NODES), "cangen", "vcan0", "-I", LOAD_ID, "-L",
                    "8", "-D", "r", "-g", f"{gap_ms:g}", "-c", str(burst), "-i"])
            time.sleep(1.0)
        tx0, t0 = self.tx_packets(), time.monotonic()
        # The input's end: plinth-replay's (on the bus), the box's own (its replay).
        replay = box
        if self.on_bus:
            replay = self.start(f"{name}.replay", [
                "chrt", "--fifo", str(FIFO_NODES), cfg["replay"], "--record",
                str(self.work / "input.csv"), "--can", "vcan0", "--rate", f"{RATE_HZ:g}",
                "--speed", "1", "--report-json"])
        timeline = []
        if loaded:
            timeline = [(cfg["stall_at_s"], "stall"),
                        (cfg["stall_at_s"] + cfg["stall_s"], "drop"),
                        (cfg["stall_at_s"] + cfg["stall_s"] + cfg["drop_s"], "restart")]
        ticks = 0
        while replay.poll() is None:
            now = time.monotonic() - t0
            while timeline and now >= timeline[0][0]:
                _, what = timeline.pop(0)
                self.log(f"{name}: broker {what} at {now:.1f} s")
                extra[f"broker_{what}_s"] = now
                if what == "stall":
                    broker.send_signal(signal.SIGSTOP)
                elif what == "drop":
                    # Killed while stopped: it never runs again (a crash, a power cut), so
                    # nothing sent to it during the stall was acknowledged.
                    broker.send_signal(signal.SIGKILL)
                    broker.wait(20)
                else:
                    broker = self.broker()
            time.sleep(0.5)
            ticks += 1
            if ticks % 4 == 0 and box.poll() is None:
                usage.append(self.box_usage(box.pid))
        tx1, t1 = self.tx_packets(), time.monotonic()
        if cangen is not None:
            cangen.send_signal(signal.SIGINT)
            cangen.wait(10)
        if clients is not None:
            clients.wait(duration + 60)
        if self.on_bus:
            time.sleep(1.0)  # the server has closed the clients' connections
            usage.append(self.box_usage(box.pid))
            box.send_signal(signal.SIGTERM)
        box.wait(60)
        # The witness takes what the box delivered last (it may reconnect after the box did).
        alarms = sum('"type": "alarm"' in x
                     for x in (self.work / f"{name}.box.out").read_text().splitlines())
        for _ in range(120):
            got = sum(x.startswith("{") for x in
                      (self.work / f"{name}.witness.out").read_text().splitlines())
            if got >= alarms:
                break
            time.sleep(0.5)
        witness.send_signal(signal.SIGTERM)
        witness.wait(10)
        broker.send_signal(signal.SIGTERM)
        broker.wait(20)
        extra.update({
            "box_exit": box.returncode, "replay_exit": replay.returncode,
            "bus_frames": tx1 - tx0, "bus_seconds": t1 - t0,
            "box_fds": [u[0] for u in usage], "box_rss_kib": [u[1] for u in usage]})
        (self.work / f"{name}.extra.json").write_text(json.dumps(extra) + "\n")

    def syscall_cost(self):
        """Wall time of one system call here, s: dd copying 20000 single bytes (40000 calls);
        in user-mode Linux each is a round of ptrace stops on the host."""
        began = time.monotonic()
        subprocess.run(["dd", "if=/dev/zero", "of=/dev/null", "bs=1", "count=20000"],
                       stderr=subprocess.DEVNULL, check=True)
        return (time.monotonic() - began) / 40000

    def main(self):
        try:
            probe = {"syscall_us_before": 1e6 * self.syscall_cost()}
            self.run("idle", loaded=False)
            self.run("loaded", loaded=True)
            probe["syscall_us_after"] = 1e6 * self.syscall_cost()
            (self.work / "probe.json").write_text(json.dumps(probe) + "\n")
        finally:
            for p in self.procs:
                if p.poll() is None:
                    p.kill()
        return 0


# ---- The host: the input before, the figures after ---------------------------------------------

def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def write_input(path, seconds, quake_at, record, scale):
    """The sensor's input at RATE_HZ: quiet (a 1 LSB dither, as a real sensor's noise: the
    stuck-sensor check stays quiet) but for the record scaled from quake_at on, CSV in g with
    few digits (an hour at 1000 Hz is 51 MB, under the 64 MiB a record may have)."""
    dt, values_g = e2e_can.read_at2(record)
    n_total = round(seconds * RATE_HZ)
    first = round(quake_at * RATE_HZ)
    last = min(n_total, first + round(len(values_g) * dt * RATE_HZ))
    quiet = ["0", f"{e2e_can.RESOLUTION_G:g}", "0", f"{-e2e_can.RESOLUTION_G:g}"]
    with open(path, "w") as out:
        out.write(f"t,{Path(record).stem} [g]\n")
        for k in range(n_total):
            if first <= k < last:
                a = f"{scale * e2e_can.value_at(dt, values_g, (k - first) / RATE_HZ):.6g}"
            else:
                a = quiet[k % 4]
            out.write(f"{k / RATE_HZ:.3f},{a}\n")
    return n_total


def prepare(args, work):
    quake_at = args.lead + min(5.0, args.stall / 2)  # while the broker is stalled
    input_s = args.lead + args.stall + args.drop + args.tail
    n_samples = write_input(work / "input.csv", input_s, quake_at, args.record, args.scale)
    # cangen's share: 90 % of the bus in frames per second, less the sensor's frames.
    total_fps = args.bus_load * BUS_BITRATE / FRAME_BITS
    cangen_fps = total_fps - RATE_HZ
    gap_ms = 10.0
    burst = max(1, round(cangen_fps * gap_ms / 1000.0))
    config = {
        "monitor": str(Path(args.monitor).resolve()), "replay": str(Path(args.replay).resolve()),
        "scene": str(ROOT / "sim/scenes/paper-isolated.toml"), "record": str(args.record),
        "scale": args.scale, "input_s": input_s, "quake_at_s": quake_at,
        "clients": args.clients, "poll_hz": args.poll_hz, "bus_load": args.bus_load,
        "target_fps": total_fps, "cangen_burst": burst, "cangen_gap_ms": gap_ms,
        "stall_at_s": args.lead, "stall_s": args.stall, "drop_s": args.drop,
        "where": args.where, "broker_port": free_port(), "modbus_port": free_port(),
        "input_samples": n_samples,
    }
    (work / "config.json").write_text(json.dumps(config, indent=1) + "\n")
    return config


def last_json(path, kind=None):
    found = None
    for line in Path(path).read_text().splitlines():
        if line.startswith("{"):
            obj = json.loads(line)
            if kind is None or obj.get("type") == kind:
                found = obj
    return found


def percent(a, b):
    return 100.0 * a / b if b else float("nan")


def report(work, cfg, args):
    failures = []
    out = {"config": cfg}
    for name in ("idle", "loaded"):
        box_lines = [json.loads(x) for x in (work / f"{name}.box.out").read_text().splitlines()
                     if x.startswith("{")]
        summary = box_lines[-1] if box_lines and box_lines[-1].get("type") == "summary" else None
        if summary is None:
            failures.append(f"{name}: the box wrote no summary: "
                            + (work / f"{name}.box.err").read_text()[-300:])
            continue
        replay_out = work / f"{name}.replay.out"
        replay = last_json(replay_out) if replay_out.exists() else None
        extra = json.loads((work / f"{name}.extra.json").read_text())
        alarms = [x for x in box_lines if x.get("type") == "alarm"]
        witnessed = {}
        for line in (work / f"{name}.witness.out").read_text().splitlines():
            if line.startswith("{"):
                e = json.loads(line)
                witnessed[(e.get("sequence"), e.get("level"), e.get("t"))] = e
        missing = [a for a in alarms if (a.get("sequence"), a.get("level"), a.get("t"))
                   not in witnessed]
        sensor = summary["sensors"][0]
        mqtt = summary.get("mqtt", {})
        on_bus = cfg["where"] == "guest"
        run = {
            # on the bus, what plinth-replay sent; the box's own replay adds its lead-in
            "sent": (replay.get("acceleration_frames") if replay else None) if on_bus
            else cfg["input_samples"],
            "received": sensor["received"], "missing": sensor["missing"],
            "bridged": sensor["bridged"], "timeouts": sensor["timeouts"],
            "bus_dropped_frames": summary["bus_dropped_frames"],
            "latency": summary["latency"], "alarm_events": len(alarms),
            "latency_from_due": summary.get("latency_from_due"),
            "witnessed": len(alarms) - len(missing), "mqtt": mqtt,
            "modbus": summary.get("modbus", {}), "extra": extra,
            "bus_fps": extra["bus_frames"] / extra["bus_seconds"],
            "replay_late_max_us": replay.get("jitter_max_us") if replay and on_bus else None,
            "captures": sorted(p.name for p in (work / f"{name}.captures").glob("event-*.log")),
        }
        if name == "loaded" and (work / "loaded.modbus.json").exists():
            run["clients"] = json.loads((work / "loaded.modbus.json").read_text())
        out[name] = run
        lost = max(0, (run["sent"] or 0) - run["received"])
        run["lost"] = lost
        if run["sent"] is None or lost != 0 or run["missing"] or run["bridged"] or \
                run["timeouts"] or run["bus_dropped_frames"]:
            failures.append(f"{name}: samples lost: sent {run['sent']}, received "
                            f"{run['received']}, missing {run['missing']}, bridged "
                            f"{run['bridged']}, timeouts {run['timeouts']}, dropped by the "
                            f"socket {run['bus_dropped_frames']}")
        if missing or mqtt.get("events_dropped") or mqtt.get("events_undelivered"):
            failures.append(f"{name}: alarm events lost: {len(missing)} of {len(alarms)} not "
                            f"received by the witness, dropped {mqtt.get('events_dropped')}, "
                            f"undelivered {mqtt.get('events_undelivered')}")
        # Grown: above the first count at each of the last three samples. One sample above it is
        # a descriptor open at that instant (seen under ASan: 9 at 17 samples, then 10 at the
        # last; which descriptor was not identified); a leak stays.
        if min(extra["box_fds"][-3:]) > extra["box_fds"][0]:
            failures.append(f"{name}: the box's descriptors grew: {extra['box_fds']}")
        if extra["box_exit"] != 0:
            failures.append(f"{name}: the box exited with {extra['box_exit']}")
    if "idle" in out and "loaded" in out:
        loaded, idle = out["loaded"], out["idle"]
        c = loaded.get("clients", {})
        if not c or c["bad"] or c["closed_by_server"] or c["fewest_answers"] == 0:
            failures.append(f"loaded: Modbus clients: {c}")
        if not loaded["mqtt"].get("connections_lost") and not loaded["mqtt"].get(
                "connect_failures"):
            failures.append("loaded: the box never saw the broker go (no connection lost)")
        ratio = {k: loaded["latency"][k] / idle["latency"][k] for k in ("median_us", "p99_us")}
        out["ratio"] = ratio
        if args.max_p99_ratio and ratio["p99_us"] > args.max_p99_ratio:
            failures.append(f"loaded p99 is {ratio['p99_us']:.2f} times the idle one "
                            f"(bound {args.max_p99_ratio:g})")
    if (work / "probe.json").exists():
        out["probe"] = json.loads((work / "probe.json").read_text())
    print_figures(out)
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1) + "\n")
    return out, failures


def print_figures(out):
    cfg = out["config"]
    where = ("on vcan0 in the guest, fed by plinth-replay" if cfg["where"] == "guest" else
             "on this host, replaying the input itself (no bus)")
    if "probe" in out:
        print(f"load-test: one system call took {out['probe']['syscall_us_before']:.1f} us "
              f"before the runs, {out['probe']['syscall_us_after']:.1f} us after (dd bs=1)")
    print(f"load-test: the box at {RATE_HZ:g} Hz {where}, {cfg['input_s']:g} s of input per run "
          f"(Brienza x{cfg['scale']:g} from {cfg['quake_at_s']:g} s)")
    print(f"{'run':<7} {'sent':>8} {'received':>8} {'lost':>5} {'median_us':>10} "
          f"{'p99_us':>9} {'max_us':>9} {'alarms':>6} {'witnessed':>9} {'bus_fps':>8} "
          f"{'load_%':>6}")
    for name in ("idle", "loaded"):
        r = out.get(name)
        if not r:
            continue
        lat = r["latency"]
        load = percent(r["bus_fps"] * FRAME_BITS, BUS_BITRATE)
        print(f"{name:<7} {r['sent'] or 0:>8} {r['received']:>8} "
              f"{r['lost']:>5} {lat['median_us']:>10.3f} "
              f"{lat['p99_us']:>9.3f} {lat['max_us']:>9.1f} {r['alarm_events']:>6} "
              f"{r['witnessed']:>9} {r['bus_fps']:>8.0f} {load:>6.1f}")
    for name in ("idle", "loaded"):
        lat = (out.get(name) or {}).get("latency_from_due")
        if lat:
            print(f"{name}: from each sample's deadline (the replay's pacing): median "
                  f"{lat['median_us']:.3f} us, p99 {lat['p99_us']:.3f} us, max {lat['max_us']:.1f} us")
    if "ratio" in out:
        print(f"ratio loaded/idle: median {out['ratio']['median_us']:.2f}, "
              f"p99 {out['ratio']['p99_us']:.2f}")
    r = out.get("loaded")
    if r:
        c = r.get("clients", {})
        m, q = r["modbus"], r["mqtt"]
        e = r["extra"]
        print(f"loaded: Modbus {c.get('clients')} clients at {c.get('poll_hz')} Hz: "
              f"{c.get('answers')} answers in {c.get('duration_s', 0):.0f} s "
              f"({c.get('answers', 0) / max(c.get('duration_s', 1), 1):.0f}/s), "
              f"{c.get('bad')} wrong, {c.get('late')} polls sent a period late, "
              f"round trip p50 {c.get('rtt_p50_ms') or 0:.2f} ms p99 {c.get('rtt_p99_ms') or 0:.2f}"
              f" ms; the server: {m.get('requests')} requests, {m.get('most_clients_at_once')} "
              f"clients at once, {m.get('closed_for_room')} closed for a new one")
        print(f"loaded: MQTT broker stalled at {e.get('broker_stall_s', 0):.0f} s, dropped at "
              f"{e.get('broker_drop_s', 0):.0f} s, back at {e.get('broker_restart_s', 0):.0f} s; "
              f"the box: {q.get('connections_lost')} connections lost, "
              f"{q.get('connect_failures')} connect failures, {q.get('connects')} connects, "
              f"events published {q.get('events_published')}, republished "
              f"{q.get('events_republished')}, most queued {q.get('most_queued')}, dropped "
              f"{q.get('events_dropped')}, undelivered {q.get('events_undelivered')}")
    for name in ("idle", "loaded"):
        r = out.get(name)
        if r:
            e = r["extra"]
            print(f"{name}: box descriptors {e['box_fds'][0]} -> max {max(e['box_fds'])} -> "
                  f"{e['box_fds'][-1]}, RSS {e['box_rss_kib'][0]} -> max "
                  f"{max(e['box_rss_kib'])} -> {e['box_rss_kib'][-1]} KiB; captures "
                  f"{len(r['captures'])}; plinth-replay late at most {r['replay_late_max_us']} us")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", default=str(ROOT / "build/release"))
    ap.add_argument("--work")
    ap.add_argument("--clients", type=int, default=50)
    ap.add_argument("--poll-hz", type=float, default=100.0)
    ap.add_argument("--bus-load", type=float, default=0.9)
    ap.add_argument("--lead", type=float, default=20.0, help="s of input before the stall")
    ap.add_argument("--stall", type=float, default=120.0, help="s the broker is stopped")
    ap.add_argument("--drop", type=float, default=60.0, help="s the broker is gone")
    ap.add_argument("--tail", type=float, default=45.0, help="s of input after it is back")
    ap.add_argument("--record", default=str(ROOT / "sim/data/records/irpinia1980_brienza_000.AT2"))
    ap.add_argument("--scale", type=float, default=20.0)
    ap.add_argument("--where", choices=("guest", "host"), default="guest",
                    help="guest: the box on vcan0 in a guest kernel (tools/vcan-bus.sh), the bus "
                    "loaded; host: the box replaying the input itself on this machine, no bus")
    ap.add_argument("--route")
    ap.add_argument("--if-chosen")
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--max-p99-ratio", type=float)
    ap.add_argument("--json")
    ap.add_argument("--keep", action="store_true")
    # internal modes
    ap.add_argument("--guest", help=argparse.SUPPRESS)
    ap.add_argument("--modbus-clients", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--port", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--duration", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--out", help=argparse.SUPPRESS)
    ap.add_argument("--write-input", help=argparse.SUPPRESS)  # FILE: tools/soak.sh's input
    ap.add_argument("--seconds", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--quake-at", type=float, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.write_input:
        print(write_input(args.write_input, args.seconds, args.quake_at, args.record, args.scale))
        return 0
    if args.modbus_clients:
        return modbus_clients(args.port, args.modbus_clients, args.poll_hz, args.duration,
                              args.out)
    if args.guest:
        return Scenario(args.guest).main()

    if os.environ.get("PLINTH_ASAN") == "1" and args.where == "guest":
        print("load-test: skipped: ASan cannot run in user-mode Linux", file=sys.stderr)
        return 77
    if not (1 <= args.clients <= 60 and 0 < args.poll_hz <= 1000 and 0 < args.bus_load < 1 and
            args.lead >= 5 and args.stall > 0 and args.drop > 0 and args.tail >= 10):
        ap.error("--clients 1..60, --poll-hz 0..1000, --bus-load 0..1, --lead >= 5, --stall "
                 "and --drop > 0, --tail >= 10")
    # The build tested: --build's, or PLINTH_MONITOR's and PLINTH_REPLAY's (ctest gives both);
    # plinth-replay and cangen feed the bus, which a run on the host has not.
    on_bus = args.where == "guest"
    args.monitor = os.environ.get("PLINTH_MONITOR", f"{args.build}/firmware/linux/plinth-monitor")
    args.replay = os.environ.get("PLINTH_REPLAY", f"{args.build}/hal/replay/plinth-replay")
    for tool in (args.monitor, args.replay) if on_bus else (args.monitor,):
        if not os.access(tool, os.X_OK):
            print(f"load-test: {tool} not found: build it, or give --build DIR", file=sys.stderr)
            return 1
    for tool in ("mosquitto_sub", "cangen", "chrt") if on_bus else ("mosquitto_sub", "chrt"):
        if shutil.which(tool) is None:
            print(f"load-test: {tool} is missing (tools/install-deps.sh)", file=sys.stderr)
            return 1
    if shutil.which("mosquitto") is None and not os.access("/usr/sbin/mosquitto", os.X_OK):
        print("load-test: mosquitto is missing (tools/install-deps.sh)", file=sys.stderr)
        return 1
    bus = []
    if args.route:
        bus += ["--route", args.route]
    if args.if_chosen:
        bus += ["--if-chosen", args.if_chosen]
    if args.work:
        work = Path(args.work).resolve()
        work.mkdir(parents=True, exist_ok=True)
        for old in [*work.glob("idle.*"), *work.glob("loaded.*"), *work.glob("*.db"),
                    work / "probe.json", work / "guest.log"]:
            shutil.rmtree(old) if old.is_dir() else old.unlink(missing_ok=True)
    else:
        import tempfile
        work = Path(tempfile.mkdtemp(prefix="plinth-load.", dir="/tmp"))
    cfg = prepare(args, work)
    timeout = int(2 * cfg["input_s"] + 200)
    started = time.monotonic()
    guest = [sys.executable, str(Path(__file__).resolve()), "--guest", str(work)]
    if args.where == "host":
        status = subprocess.call(guest)
    else:
        status = subprocess.call(["bash", str(ROOT / "tools/vcan-bus.sh"), *bus, "--timeout",
                                  str(timeout), "--mem", "1024M", "--cpus", "2", "--", *guest])
    if status == 77:
        print("load-test: SKIPPED: no route to a CAN bus can start here (above: why)",
              file=sys.stderr)
        return 77
    if status != 0:
        print(f"load-test: the runs in the guest failed (status {status}); files in {work}",
              file=sys.stderr)
        return 1
    print(f"load-test: the runs took {time.monotonic() - started:.0f} s (boot included)")
    _, failures = report(work, cfg, args)
    for f in failures:
        print(f"load-test: FAILED: {f}", file=sys.stderr)
    if failures and args.check:
        print(f"load-test: the run's files are in {work}", file=sys.stderr)
        return 1
    if not args.work and not args.keep:
        shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())
