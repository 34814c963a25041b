#!/usr/bin/env python3
"""mcu_replay_check.py's two rules on doctored logs: the identical rule refuses any changed
frame, the timeline rule passes an alarm change moved by up to --alarm-samples sample periods
and refuses one moved further, a changed cause, level or order, and a missing change. Run by
ctest mcu_replay_check_rules (no cross tools needed)."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

CHECK = os.path.join(os.path.dirname(os.path.abspath(__file__)), "mcu_replay_check.py")
PERIOD_NS = 5_000_000  # 200 Hz
LEVELS = ["normal", "advisory", "warning", "alarm", "fault"]
CAUSES = ["none", "risk_threshold", "phase_change", "overturn_detected", "sensor_timeout"]


def alarm_frame(time_us, level, previous, cause, sequence, latched=False):
    """A candump line of an AlarmEvent (0x330, hal/can_codec/plinth.dbc)."""
    value = (LEVELS.index(level) | LEVELS.index(previous) << 4 | CAUSES.index(cause) << 8 |
             int(latched) << 16 | (time_us // 1000) << 24 | sequence << 56)
    return "(%010d.%06d) can0 330#%s" % (time_us // 1_000_000, time_us % 1_000_000,
                                         value.to_bytes(8, "little").hex().upper())


def status_frame(time_us, risk, sequence):
    """A candump line of a MonitorStatus (0x320), full contact, normal."""
    value = round(risk * 1e4) << 16 | sequence << 32
    return "(%010d.%06d) can0 320#%s" % (time_us // 1_000_000, time_us % 1_000_000,
                                         value.to_bytes(8, "little").hex().upper())


# The host's timeline: an advisory by risk at 4.495 s, a warning by phase change at 4.965 s,
# an alarm at 7.110 s; status frames every 0.1 s; one phase event.
HOST_ALARMS = [(4_495_000, "advisory", "normal", "risk_threshold", 1),
               (4_965_000, "warning", "advisory", "phase_change", 2),
               (7_110_000, "alarm", "warning", "overturn_detected", 3)]


def frames(alarms, risk_offset=0.0):
    status = [(t * 100_000, status_frame(t * 100_000, min(1.0, 0.01 * t + risk_offset), t % 256))
              for t in range(80)]
    lines = status + [(a[0], alarm_frame(*a)) for a in alarms]
    return [line for _, line in sorted(lines, key=lambda x: x[0])]


class Rules(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.host_log = self.write("host.log", frames(HOST_ALARMS))
        self.host_json = self.write("host.jsonl", [json.dumps(
            {"type": "event", "axis": "x", "t": 4.841192906, "event": "rocking_start",
             "corner": "right"})])

    def tearDown(self):
        self.dir.cleanup()

    def write(self, name, lines):
        path = os.path.join(self.dir.name, name)
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        return path

    def check(self, alarms, real="float", rule=None, event_t=4.841194633, risk_offset=0.0,
              extra=()):
        log = ["# plinth box on mps2-an386: case", "# real=" + real,
               "# event axis=x t=%.9f event=rocking_start corner=right" % event_t]
        log += frames(alarms, risk_offset) + list(extra)
        log += ["# summary samples=10 record_samples=10 sample_period_ns=%d" % PERIOD_NS,
                "# end: ok"]
        args = [sys.executable, CHECK, self.write("mcu.log", log), self.host_json,
                self.host_log]
        if rule:
            args += ["--rule", rule]
        run = subprocess.run(args, capture_output=True, text=True)
        return run.returncode, run.stdout

    def moved(self, index, by_us=0, **change):
        alarms = [list(a) for a in HOST_ALARMS]
        alarms[index][0] += by_us
        for key, value in change.items():
            alarms[index][("level", "previous", "cause").index(key) + 1] = value
        return [tuple(a) for a in alarms]

    def test_identical_rule_passes_the_same_log_only(self):
        self.assertEqual(self.check(HOST_ALARMS, real="double", event_t=4.841192906)[0], 0)
        self.assertEqual(self.check(self.moved(0, 5000), real="double", event_t=4.841192906)[0], 1)
        self.assertEqual(self.check(HOST_ALARMS, real="double", risk_offset=1e-4,
                                    event_t=4.841192906)[0], 1)

    def test_auto_picks_the_rule_from_the_images_scalar(self):
        code, out = self.check(self.moved(0, 5000))
        self.assertEqual(code, 0, out)
        self.assertIn("ok (timeline)", out)
        self.assertEqual(self.check(self.moved(0, 5000), real="double")[0], 1)

    def test_timeline_passes_a_shift_within_the_allowed_samples_and_reports(self):
        code, out = self.check(self.moved(1, -5000), risk_offset=2e-4)
        self.assertEqual(code, 0, out)
        self.assertIn("largest shift 5000 us (1 samples, allowed 1)", out)
        self.assertIn("risk max abs difference 0.0002", out)
        self.assertIn("largest time difference 1.73e-06 s", out)

    def test_timeline_refuses_a_shift_beyond_the_allowed_samples(self):
        code, out = self.check(self.moved(2, 10000))
        self.assertEqual(code, 1, out)
        self.assertIn("alarm change 3", out)
        self.assertEqual(self.check(self.moved(2, 10000), rule="timeline")[0], 1)
        run = subprocess.run([sys.executable, CHECK, self.write("m.log", ["# end: ok"]),
                              self.host_json, self.host_log], capture_output=True, text=True)
        self.assertEqual(run.returncode, 1)

    def test_timeline_refuses_a_changed_cause_or_level(self):
        self.assertEqual(self.check(self.moved(1, cause="risk_threshold"))[0], 1)
        self.assertEqual(self.check(self.moved(2, level="fault"))[0], 1)

    def test_timeline_refuses_a_missing_extra_or_reordered_change(self):
        self.assertEqual(self.check(HOST_ALARMS[:2])[0], 1)
        extra = HOST_ALARMS + [(7_500_000, "normal", "alarm", "none", 4)]
        self.assertEqual(self.check(extra)[0], 1)
        swapped = [HOST_ALARMS[1][:1] + HOST_ALARMS[0][1:], HOST_ALARMS[0][:1] + HOST_ALARMS[1][1:],
                   HOST_ALARMS[2]]
        self.assertEqual(self.check(swapped)[0], 1)


if __name__ == "__main__":
    unittest.main()
