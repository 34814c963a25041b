#!/usr/bin/env python3
"""e2e_can.py's judgement of whose loss a bus run's is (rig_losses, `rig`, the checks' verdict),
fed the files a guest leaves: a witness log with candump's DROPCOUNT lines (one written by the
real candump under overflow: tests/data/candump/), fewer frames than plinth-replay sent, the
sensor's silences, plinth-replay's lateness, the regional bridge's gaps. A run the rig spoiled
fails with the rig's losses named and nothing of the box's judged; a run it carried is judged.
Run by ctest e2e_can_rig (no guest needed)."""
import contextlib
import io
import json
import os
import shutil
import sys
import tempfile
import unittest
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import e2e_can  # noqa: E402
import e2e_can_regional  # noqa: E402

SOURCE = HERE.parent.parent
DBC = SOURCE / "hal" / "can_codec" / "plinth.dbc"
REAL_DROPCOUNT_LOG = SOURCE / "tests" / "data" / "candump" / "overflow.log"
T0_US = 1_700_000_000_000_000
PERIOD_US = 2_500  # 200 Hz at --speed 2
SENSOR = "0000000000A00F00"  # any 8 bytes: the classifier looks at identifiers and times


def line(t_us, ident, data):
    return f"({t_us // 1_000_000:010d}.{t_us % 1_000_000:06d}) vcan0 {ident:03X}#{data}\n"


def sensor_log(count, silence_after=None, silence_us=0):
    """`count` SensorAcceleration frames, PERIOD_US apart; after frame `silence_after` a pause
    of `silence_us` more."""
    out, t = [], T0_US
    for k in range(count):
        out.append(line(t, 0x301, SENSOR))
        t += PERIOD_US + (silence_us if k == silence_after else 0)
    return out


class Work:
    """A work folder as the guest leaves it, for run `name`."""

    def __init__(self, test, scenarios=("main",)):
        self.dir = Path(tempfile.mkdtemp(prefix="e2e-can-rig-"))
        test.addCleanup(shutil.rmtree, self.dir)
        self.config = {"timeout_s": 0.05, "dbc": str(DBC), "scenarios": list(scenarios),
                       "rate": 200.0, "lead_in_samples": 250, "short_record_s": 2.0}
        (self.dir / "config.json").write_text(json.dumps(self.config))

    def run(self, name, bus_lines, sent, late_us=1_000, attempts=1, rig="", extra=""):
        (self.dir / f"{name}.bus.log").write_text("".join(bus_lines))
        (self.dir / f"{name}.replay.json").write_text(json.dumps(
            {"acceleration_frames": sent, "heartbeat_frames": 0, "jitter_max_us": late_us,
             "send_errors": 0}) + "\n")
        (self.dir / f"{name}.replay.rc").write_text("0\n")
        summary = {"type": "summary", "t": 1.0, "frames": {}, "sensor": {}}
        (self.dir / f"{name}.monitor.jsonl").write_text(json.dumps(summary) + "\n")
        (self.dir / f"{name}.monitor.rc").write_text("0\n")
        (self.dir / f"{name}.monitor.err").write_text("")
        (self.dir / f"{name}.extra").write_text(f"attempts={attempts}\nstop_signal=SIGINT\n"
                                                 + extra)
        (self.dir / f"{name}.rig").write_text(rig)

    def losses(self, name):
        return e2e_can.rig_losses(self.dir, name, self.config)


class RigLosses(unittest.TestCase):
    def test_a_clean_run_is_the_box_s_to_judge(self):
        w = Work(self)
        w.run("main", sensor_log(400), sent=400)
        self.assertEqual(w.losses("main"), [])

    def test_dropcount_lines_are_the_witness_s_losses_with_the_count_and_the_line(self):
        w = Work(self)
        log = sensor_log(400)
        log.insert(100, "DROPCOUNT: dropped 410 CAN frames on 'vcan0' socket (total drops 410)\n")
        log.insert(300, "DROPCOUNT: dropped 3 CAN frames on 'vcan0' socket (total drops 413)\n")
        w.run("main", log, sent=400)
        losses = w.losses("main")
        self.assertEqual(len(losses), 1, losses)
        self.assertEqual(losses[0], "candump, the witness, lost 413 frames (2 DROPCOUNT lines; "
                         "the first, main.bus.log:101: DROPCOUNT: dropped 410 CAN frames on "
                         "'vcan0' socket (total drops 410))")

    def test_a_log_written_by_the_real_candump_under_overflow(self):
        # tests/data/candump/README.md: candump -L -d with a small buffer, stopped while
        # plinth-replay sent; every DROPCOUNT line is read, none taken for a frame.
        frames, drops = e2e_can.read_candump(REAL_DROPCOUNT_LOG)
        self.assertGreater(len(drops), 0)
        self.assertTrue(all(d.frames > 0 and d.text.startswith("DROPCOUNT: dropped ")
                            for d in drops))
        w = Work(self, ("stop",))
        w.run("stop", REAL_DROPCOUNT_LOG.read_text().splitlines(keepends=True),
              sent=sum(1 for f in frames if f.ident == 0x301))
        losses = w.losses("stop")
        self.assertTrue(losses and losses[0].startswith(
            f"candump, the witness, lost {sum(d.frames for d in drops)} frames"), losses)

    def test_frames_the_witness_never_logged(self):
        # Lost at the end, with no later frame to carry the DROPCOUNT report.
        w = Work(self, ("garbage",))
        w.run("garbage", sensor_log(390), sent=400)
        self.assertEqual(w.losses("garbage"), [
            "candump, the witness, logged 390 of the 400 SensorAcceleration frames "
            "plinth-replay sent"])

    def test_a_silence_of_the_sensor_spoils_main_stop_and_regional_not_garbage(self):
        w = Work(self, ("main", "stop", "garbage"))
        for name in ("main", "stop", "garbage"):
            w.run(name, sensor_log(400, silence_after=200, silence_us=60_000), sent=400)
        for name in ("main", "stop"):
            self.assertEqual(w.losses(name), [
                "the guest was starved: the sensor (plinth-replay) fell silent on the bus for "
                "62.5 ms, longer than the monitor's 50 ms sensor timeout"])
        self.assertEqual(w.losses("garbage"), [], "garbage judges the box through silences")
        w.run("main", sensor_log(400, silence_after=200, silence_us=40_000), sent=400)
        self.assertEqual(w.losses("main"), [], "42.5 ms: within the timeout")

    def test_plinth_replay_late_spoils_main_and_regional(self):
        # Seen at host load 18: no silence over 30 ms, plinth-replay 236 ms late at worst, the
        # monitor 9 s behind and 536 frames dropped from its socket.
        w = Work(self, ("main",))
        w.run("main", sensor_log(400), sent=400, late_us=235_838.9)
        self.assertEqual(w.losses("main"), [
            "the guest was starved: plinth-replay (the sensor) was up to 236 ms late, 45 ms "
            "allowed (the monitor beside it falls behind)"])
        w.run("main", sensor_log(400), sent=400, late_us=e2e_can.STARVED_LATE_US - 1)
        self.assertEqual(w.losses("main"), [])

    def test_a_guest_without_idle_cpu_spoils_main_stop_and_regional_not_burst(self):
        # Seen at host load 13-19: 0-6 % idle.
        w = Work(self, ("stop", "burst"))
        w.run("stop", sensor_log(400), sent=400, extra="guest_idle_percent=6\n")
        self.assertEqual(w.losses("stop"), [
            "the guest was starved: its CPU was idle 6% of the stream, less than the 10% it "
            "needs to carry the monitor, candump and plinth-replay"])
        w.run("stop", sensor_log(400), sent=400,
              extra=f"guest_idle_percent={e2e_can.MIN_IDLE_PERCENT}\n")
        self.assertEqual(w.losses("stop"), [])
        w.run("burst", sensor_log(400), sent=400, extra="guest_idle_percent=0\n")
        self.assertEqual(w.losses("burst"), [], "the floods keep the guest busy on purpose")

    def test_plinth_replay_late_spoils_garbage_and_burst(self):
        w = Work(self, ("burst",))
        w.run("burst", sensor_log(400), sent=400, late_us=e2e_can.BACKLOG_LATE_US)
        self.assertEqual(w.losses("burst"), [
            "the guest was starved: plinth-replay was up to 300 ms late (its backlog could "
            "overflow the monitor's socket)"])
        w.run("burst", sensor_log(400), sent=400, late_us=e2e_can.BACKLOG_LATE_US - 1)
        self.assertEqual(w.losses("burst"), [])

    def test_the_regional_bridge_off_its_gaps(self):
        w = Work(self, ("regional",))
        dbc = e2e_can.Dbc(DBC)
        plan = [(ident, data, gap) for _, sent, _ in e2e_can_regional.cases(dbc)
                for ident, data, gap in sent]
        w.config["regional_gaps_us"] = " ".join(str(round(gap * 1e6)) for _, _, gap in plan)

        def bridge(late_frame=None):
            out, t = sensor_log(40), T0_US + 100_000
            for k, (ident, data, gap) in enumerate(plan):
                t += round(gap * 1e6) + (60_000 if k == late_frame else 0)
                out.append(line(t, ident, data.hex().upper()))
            return out

        w.run("regional", bridge(), sent=40)
        self.assertEqual(w.losses("regional"), [])
        w.run("regional", bridge(late_frame=5), sent=40)
        self.assertEqual(w.losses("regional"), [
            "the guest was starved: the bridge's frame 5 (canplayer) came +60.0 ms off its gap "
            "in regional.in.log"])

    def test_a_line_neither_frame_nor_dropcount_is_the_witness_s_named(self):
        w = Work(self)
        w.run("main", sensor_log(4) + ["DROPCOUNT: dropped many frames\n"], sent=4)
        self.assertEqual(w.losses("main"), [
            "candump, the witness, wrote a line that is neither a frame nor a DROPCOUNT report: "
            "main.bus.log:5: DROPCOUNT: dropped many frames"])


class RigCommand(unittest.TestCase):
    """`e2e_can.py rig`, as the guest runs it after each run."""

    def rig(self, w, attempt):
        err = io.StringIO()
        args = type("Args", (), {"work": str(w.dir), "run": "main", "attempt": attempt})
        with contextlib.redirect_stderr(err):
            status = e2e_can.rig_command(args)
        return status, err.getvalue()

    def test_spoiled_runs_are_noted_and_a_carried_one_ends_the_attempts(self):
        w = Work(self)
        dropped = sensor_log(400)
        dropped.insert(9, "DROPCOUNT: dropped 2 CAN frames on 'vcan0' socket (total drops 2)\n")
        w.run("main", dropped, sent=400)
        status, err = self.rig(w, 1)
        self.assertEqual(status, 1)
        self.assertIn("main, run 1: candump, the witness, lost 2 frames", err)
        w.run("main", sensor_log(400, silence_after=3, silence_us=80_000), sent=400, rig=(
            w.dir / "main.rig").read_text())
        self.assertEqual(self.rig(w, 2)[0], 1)
        w.run("main", sensor_log(400), sent=400, rig=(w.dir / "main.rig").read_text())
        self.assertEqual(self.rig(w, 3)[0], 0)
        notes = (w.dir / "main.rig").read_text().splitlines()
        self.assertEqual(len(notes), 2, notes)
        self.assertTrue(notes[0].startswith("1: candump, the witness, lost 2 frames"))
        self.assertTrue(notes[1].startswith("2: the guest was starved: the sensor"))


class Verdict(unittest.TestCase):
    """The checks on a work folder whose last main run the rig spoiled: one failure, naming the
    rig's losses; none of the box's checks, which would blame the box for the witness's loss
    (seen: "no sensor frame lost: 2451 received of 2041 on the bus")."""

    def test_the_rig_s_losses_fail_the_test_and_the_box_is_not_judged(self):
        w = Work(self)
        log = sensor_log(2451)
        log.insert(2037, "DROPCOUNT: dropped 410 CAN frames on 'vcan0' socket (total drops 410)\n")
        notes = "".join(f"{n}: candump, the witness, lost {n} frames\n" for n in range(1, 6))
        w.run("main", log, sent=2451, attempts=e2e_can.MAX_ATTEMPTS, rig=notes)
        out = io.StringIO()
        args = type("Args", (), {"work": str(w.dir)})
        with contextlib.redirect_stdout(out):
            status = e2e_can.run_checks(args)
        text = out.getvalue()
        self.assertEqual(status, 1, text)
        failed = [x for x in text.splitlines() if x.strip().startswith("FAIL")]
        self.assertEqual(len(failed), 1, text)
        self.assertIn("the rig could not carry the main run in 5 attempts (at most 5): "
                      "candump, the witness, lost 410 frames", failed[0])
        self.assertIn("main.bus.log:2038", failed[0])
        self.assertIn("1: candump, the witness, lost 1 frames | 2:", failed[0])
        self.assertIn("not the box's", failed[0])
        self.assertNotIn("no sensor frame lost", text)
        self.assertIn("0 checks passed, 1 failed", text)

    def test_a_run_the_guest_had_no_time_left_for_names_the_rig(self):
        w = Work(self, ("main", "stop"))
        w.run("main", sensor_log(40), sent=40, attempts=5,
              rig="".join(f"{n}: the guest was starved: ...\n" for n in range(1, 6)))
        (w.dir / "stop.rig").write_text("1: not run: the guest's time (420 s, boot included) was "
                                        "spent, and the longest run so far took 27 s\n")
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            status = e2e_can.run_checks(type("Args", (), {"work": str(w.dir)}))
        text = out.getvalue()
        self.assertEqual(status, 1, text)
        self.assertIn("FAIL  the rig could not carry the stop run: not run: the guest's time (420 "
                      "s, boot included) was spent", text)
        self.assertNotIn("left no usable output", text)

    def test_a_guest_whose_time_ran_out_names_the_run_it_was_in_and_those_never_begun(self):
        w = Work(self, ("main", "stop", "garbage"))
        w.run("main", sensor_log(40), sent=40)
        w.run("stop", sensor_log(40), sent=40, attempts=2,
              rig="1: the guest was starved: the sensor (plinth-replay) fell silent ...\n")
        (w.dir / "stop.running").write_text("2: not finished: the guest's time (420 s, boot "
                                            "included) ran out during this run\n")
        self.assertEqual(e2e_can.rig_cut_short(w.dir, "main", False), "")
        self.assertEqual(e2e_can.rig_cut_short(w.dir, "stop", False),
                         "run 2: not finished: the guest's time (420 s, boot included) ran out "
                         "during this run (each run before: 1: the guest was starved: the sensor "
                         "(plinth-replay) fell silent ...)")
        self.assertEqual(e2e_can.rig_cut_short(w.dir, "garbage", False),
                         "not run: the guest's time ran out before it began")
        self.assertEqual(e2e_can.rig_cut_short(w.dir, "garbage", True), "",
                         "a guest that finished: missing files are the checks' to report")

    def test_a_run_the_rig_carried_after_spoiled_ones_is_judged(self):
        w = Work(self)
        w.run("main", sensor_log(40), sent=40, attempts=2,
              rig="1: candump, the witness, lost 7 frames\n")
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            e2e_can.rig_verdict(lambda ok, what: ok, w.dir,
                                e2e_can.Scenario(w.dir, "main", e2e_can.Dbc(DBC)), w.config)
        self.assertEqual(out.getvalue(), "[main] (the last of 2 runs: the rig spoiled the "
                         "others: 1: candump, the witness, lost 7 frames)\n")


if __name__ == "__main__":
    os.chdir(HERE)
    unittest.main()
