#!/usr/bin/env python3
"""plinth-monitor's alarm changes as systemd sees them (docs/relays-and-supervision.md): in a
private mount namespace this test lays a tmpfs over /run/systemd and binds its own journal socket
at /run/systemd/journal/socket (the native protocol journald reads, systemd.journal-fields(7)),
and its own NOTIFY_SOCKET; with INVOCATION_ID set, as systemd sets it for a service, the box
replays the quick start (Buia x6.5 on the eccentric block). Checked against the run's JSON alarm
lines, one for one:

  1. one journal entry per alarm change, PRIORITY alert (1) for alarm, crit (2) for warning and
     fault, warning (4) for advisory, notice (5) for normal; fields PLINTH_ALARM_LEVEL,
     PLINTH_ALARM_PREVIOUS, PLINTH_ALARM_CAUSE, PLINTH_ALARM_T (the line's t),
     SYSLOG_IDENTIFIER=plinth-monitor and a MESSAGE; and one for the commissioning's verdict at
     start (PLINTH_COMMISSIONING=none: no report, a warning);
  2. a STATUS= after each change naming the level (what `systemctl status` shows), the last one
     the final level;
  3. without INVOCATION_ID (not a service) nothing reaches the journal socket.

Skips (77) where no mount namespace can be made.
Usage: test_journal.py PLINTH_MONITOR SOURCE_DIR
"""
import json
import os
import socket
import struct
import subprocess
import sys
import tempfile

PASSED, FAILED = [], []
PRIORITY = {"alarm": 1, "warning": 2, "fault": 2, "advisory": 4, "normal": 5}


def check(ok, what):
    print(("ok - " if ok else "not ok - ") + what)
    (PASSED if ok else FAILED).append(what)


def fields(datagram):
    """The native protocol: KEY=value lines, or KEY\\n<64-bit little-endian size><value>\\n."""
    out, i = {}, 0
    while i < len(datagram):
        end = datagram.index(b"\n", i)
        line = datagram[i:end]
        if b"=" in line:
            key, value = line.split(b"=", 1)
            i = end + 1
        else:
            key = line
            (size,) = struct.unpack("<Q", datagram[end + 1:end + 9])
            value = datagram[end + 9:end + 9 + size]
            i = end + 9 + size + 1
        out[key.decode()] = value.decode()
    return out


def run(monitor, source, folder, service):
    journal = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    journal.bind("/run/systemd/journal/socket")
    notify_path = os.path.join(folder, "notify.sock")
    notify = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    notify.bind(notify_path)
    env = {k: v for k, v in os.environ.items()
           if k not in ("INVOCATION_ID", "WATCHDOG_USEC", "WATCHDOG_PID", "JOURNAL_STREAM")}
    env["NOTIFY_SOCKET"] = notify_path
    if service:
        env["INVOCATION_ID"] = "0123456789abcdef0123456789abcdef"
    result = subprocess.run(
        [monitor, "--scene", os.path.join(source, "sim/scenes/paper-eccentric.toml"),
         "--replay", os.path.join(source, "sim/data/records/friuli1976-09-15_buia_000.AT2"),
         "--scale", "6.5", "--no-events"], env=env, capture_output=True, timeout=120)
    entries, statuses = [], []
    for sock, out, parse in ((journal, entries, fields),
                             (notify, statuses, lambda d: d.decode())):
        sock.setblocking(False)
        while True:
            try:
                out.append(parse(sock.recv(65536)))
            except BlockingIOError:
                break
        sock.close()
    os.unlink("/run/systemd/journal/socket")
    os.unlink(notify_path)
    alarms = [json.loads(l) for l in result.stdout.decode().splitlines()
              if l.startswith('{"type": "alarm"')]
    return result, alarms, entries, statuses


def main():
    monitor, source = sys.argv[1], sys.argv[2]
    if os.environ.get("PLINTH_JOURNAL_TEST_NAMESPACE") != "1":
        try:
            probe = subprocess.run(["unshare", "-m", "true"], capture_output=True)
        except OSError:
            probe = None
        if probe is None or probe.returncode != 0:
            print("skipped: cannot make a mount namespace here (unshare -m: needs root)")
            return 77
        env = dict(os.environ, PLINTH_JOURNAL_TEST_NAMESPACE="1")
        return subprocess.run(["unshare", "-m", sys.executable, __file__] + sys.argv[1:],
                              env=env).returncode
    os.makedirs("/run/systemd", exist_ok=True)
    subprocess.run(["mount", "-t", "tmpfs", "plinth-journal-test", "/run/systemd"], check=True)
    os.makedirs("/run/systemd/journal")
    with tempfile.TemporaryDirectory() as folder:
        result, alarms, entries, statuses = run(monitor, source, folder, service=True)
        check(result.returncode == 0 and len(alarms) >= 4,
              "the quick start runs under INVOCATION_ID (%d alarm lines; exit %d: %s)"
              % (len(alarms), result.returncode, result.stderr.decode().strip()[:200]))
        alarm_entries = [e for e in entries if "PLINTH_ALARM_LEVEL" in e]
        # Besides them, the commissioning's verdict at start (docs/commissioning.md): no report
        # in the recorder's folder, none required, a warning.
        verdicts = [e for e in entries if "PLINTH_COMMISSIONING" in e]
        check(len(alarm_entries) == len(alarms) == len(entries) - 1,
              "one journal entry per alarm change: %d entries, %d alarm lines"
              % (len(entries), len(alarms)))
        check(len(verdicts) == 1 and verdicts[0].get("PLINTH_COMMISSIONING") == "none" and
              verdicts[0].get("PRIORITY") == "4" and
              "no commissioning report" in verdicts[0].get("MESSAGE", ""),
              "the commissioning's verdict once at start, a warning: %s" % verdicts)
        for line, entry in zip(alarms, alarm_entries):
            want = {"PRIORITY": str(PRIORITY[line["level"]]),
                    "PLINTH_ALARM_LEVEL": line["level"],
                    "PLINTH_ALARM_PREVIOUS": line["previous"],
                    "PLINTH_ALARM_CAUSE": line["cause"],
                    "SYSLOG_IDENTIFIER": "plinth-monitor"}
            got = {k: entry.get(k) for k in want}
            same_t = abs(float(entry.get("PLINTH_ALARM_T", "nan")) - line["t"]) < 5e-6
            check(got == want and same_t and line["level"] in entry.get("MESSAGE", ""),
                  "t = %.3f %s: priority %s, level, previous, cause, t: %s"
                  % (line["t"], line["level"], want["PRIORITY"],
                     {k: v for k, v in entry.items() if k.startswith(("PRIORITY", "PLINTH"))}))
        changes = [s for s in statuses if s.startswith("STATUS=alarm level")]
        check(len(changes) == len(alarms) and
              all(s.startswith("STATUS=alarm level %s" % a["level"])
                  for s, a in zip(changes, alarms)),
              "STATUS= at each change, naming the level: %s" % [s[:40] for s in changes])
        check(bool(statuses) and statuses[-1] == "STOPPING=1" and changes and
              changes[-1].startswith("STATUS=alarm level alarm, latched"),
              "the last STATUS= shows the final level, latched: %r" % (changes[-1:]))

        result, alarms, entries, statuses = run(monitor, source, folder, service=False)
        check(result.returncode == 0 and alarms and not entries,
              "without INVOCATION_ID: nothing in the journal (%d entries)" % len(entries))
    print("%d passed, %d failed" % (len(PASSED), len(FAILED)))
    return 1 if FAILED else 0


if __name__ == "__main__":
    sys.exit(main())
