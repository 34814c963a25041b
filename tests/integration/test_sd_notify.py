#!/usr/bin/env python3
"""plinth-monitor under a stand-in for systemd: this test binds its own NOTIFY_SOCKET (an AF_UNIX
datagram socket, as systemd does for Type=notify), sets WATCHDOG_USEC, replays a record in real
time and reads what the monitor says (docs/relays-and-supervision.md):

  1. READY=1 first, then WATCHDOG=1 at half WATCHDOG_USEC while the loop runs, STOPPING=1 at
     SIGTERM, exit 0;
  2. a loop made to hang (watchdog.test_stall_after_s, the documented test-only hook): the
     pings stop, as systemd would see before it kills the service;
  3. watchdog.notify = false: nothing at all on the socket.

Usage: test_sd_notify.py PLINTH_MONITOR SOURCE_DIR
"""
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

WATCHDOG_USEC = 1_000_000  # the service's WatchdogSec=1 s: pings every 0.5 s
FAILURES = []
PASSED = []


def check(condition, what):
    print(("ok - " if condition else "not ok - ") + what)
    (PASSED if condition else FAILURES).append(what)


def run_monitor(monitor, source, folder, config_text, seconds):
    """Runs the monitor for `seconds` under our NOTIFY_SOCKET, then SIGTERM; returns its exit
    status, its stderr, and the messages received as (time since start, text)."""
    sock_path = os.path.join(folder, "notify.sock")
    if os.path.exists(sock_path):
        os.unlink(sock_path)
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    listener.bind(sock_path)
    listener.settimeout(0.05)
    config = os.path.join(folder, "box.toml")
    with open(config, "w") as f:
        f.write(config_text)
    env = dict(os.environ, NOTIFY_SOCKET=sock_path, WATCHDOG_USEC=str(WATCHDOG_USEC))
    env.pop("WATCHDOG_PID", None)
    record = os.path.join(source, "sim/data/records/irpinia1980_brienza_000.AT2")
    scene = os.path.join(source, "sim/scenes/paper-isolated.toml")
    start = time.monotonic()
    proc = subprocess.Popen(
        [monitor, "--scene", scene, "--replay", record, "--speed", "1", "--config", config,
         "--status-interval", "1", "--no-events"],
        env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    messages = []

    def drain(until):
        while time.monotonic() < until:
            try:
                data = listener.recv(4096)
            except socket.timeout:
                continue
            messages.append((time.monotonic() - start, data.decode()))

    drain(start + seconds)
    proc.send_signal(signal.SIGTERM)
    try:
        _, err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
        err += b"\n(did not exit within 30 s of SIGTERM)"
    drain(time.monotonic() + 0.2)
    listener.close()
    return proc.returncode, err.decode(), messages


def ping_times(messages):
    return [t for t, m in messages if "WATCHDOG=1" in m.split("\n")]


def main():
    monitor, source = sys.argv[1], sys.argv[2]
    with tempfile.TemporaryDirectory() as folder:
        # 1. A healthy loop.
        rc, err, messages = run_monitor(monitor, source, folder, "", 4.0)
        check(rc == 0, "healthy loop: exit 0 at SIGTERM (got %s: %s)" % (rc, err.strip()))
        check(bool(messages) and messages[0][1].startswith("READY=1\nSTATUS=monitoring "),
              "READY=1 with a STATUS comes first: %r" % messages[:1])
        pings = ping_times(messages)
        # From READY=1 (late under a sanitizer or load) to SIGTERM at 4 s: a ping per 0.5 s.
        span = 4.0 - (messages[0][0] if messages else 4.0)
        check(len(pings) >= 3 and len(pings) >= int(span / 0.5),
              "WATCHDOG=1 every 0.5 s from READY=1 to SIGTERM (%.2f s): %d pings" % (span, len(pings)))
        gaps = [b - a for a, b in zip(pings, pings[1:])]
        check(all(g >= 0.45 for g in gaps), "no ping sooner than half WATCHDOG_USEC: %s" % gaps)
        check(all(g < WATCHDOG_USEC / 1e6 for g in gaps),
              "every gap shorter than WatchdogSec (systemd would not kill it): max %.3f s"
              % max(gaps or [0]))
        check(messages[-1][1] == "STOPPING=1", "STOPPING=1 last: %r" % messages[-1:])

        # 2. The loop hangs 2 s after it started: the pings stop.
        rc, err, messages = run_monitor(monitor, source, folder,
                                        "[watchdog]\ntest_stall_after_s = 2.0\n", 6.0)
        check(rc == 0, "hung loop: exit 0 at SIGTERM (got %s: %s)" % (rc, err.strip()))
        ready = [t for t, m in messages if m.startswith("READY=1")]
        pings = ping_times(messages)
        check(len(ready) == 1 and len(pings) >= 3,
              "hung loop: READY=1 and pings before the stall: %d pings" % len(pings))
        if ready and pings:
            check(pings[-1] - ready[0] < 2.0 + 0.2,
                  "no WATCHDOG=1 after the stall (2 s after READY=1): last at %.3f s"
                  % (pings[-1] - ready[0]))
            check(6.0 - pings[-1] > WATCHDOG_USEC / 1e6 * 1.5,
                  "silence longer than WatchdogSec before SIGTERM: %.3f s" % (6.0 - pings[-1]))

        # 3. notify = false: silent, even under systemd.
        rc, err, messages = run_monitor(monitor, source, folder,
                                        "[watchdog]\nnotify = false\n", 1.5)
        check(rc == 0 and not messages, "watchdog.notify = false: nothing sent: %r" % messages)

    print("%d passed, %d failed" % (len(PASSED), len(FAILURES)))
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
