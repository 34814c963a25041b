"""Regional alerts on the live vcan bus (docs/regional.md, "CAN"; issue 26, item 2): the bridge's
frames for tools/e2e-can.sh's regional run, and its checks. Imported by e2e_can.py.

The guest runs plinth-monitor on a scene with a [fragility] (--regional-scene) and a box file
that shortens the expiry margin, fed quiet ground by plinth-replay in real time; once the
monitor's level is normal, canplayer puts regional.in.log on the bus, timed as written: hostile
frames (each refused, counted by reason), then a dangerous alert (warning, cause
regional_alert), its duplicate and an older version (refused), a harmless alert and its
cancellation (accepted). The guest waits until the dangerous alert has expired. Every frame is
encoded here from hal/can_codec/plinth.dbc (e2e_can.Dbc.encode); each one's expected outcome is
worked out from docs/regional.md's rules, never taken from a run.
"""
import math
import tomllib
from pathlib import Path

import e2e_can as e2e

EXPIRY_MARGIN_S = 1.0  # the box file's regional_alert.expiry_margin_s (default 30 s)
STRESS_DROP_BAR = 100.0  # regional_alert's defaults: the shaking's duration (Boore 2003)
SHEAR_WAVE_SPEED_KM_S = 3.5
PATH_DURATION_S_PER_KM = 0.05
PAIR_WINDOW_S = 0.1  # the RegionalAlert frame follows its origin within this (the DBC's comment)
WARNING_ON = 0.7  # alarm_policy.warning_regional.on (default)
WARNING = 2  # AlarmLevel
REGIONAL_CAUSE = e2e.CAUSES.index("regional_alert")  # 15
FRAME_GAP_S = 0.002  # between the frames of regional.in.log
HOSTILE_TO_ALERTS_S = 0.3  # from the last hostile frame to the dangerous alert
BOX_FILE = f"[regional_alert]\nexpiry_margin_s = {EXPIRY_MARGIN_S}\n"

# The dangerous alert (event 0x0101): S waves 2 s after its frame, M 5 at 10 km, 1.5 g expected.
DANGEROUS = dict(EventId=0x0101, Version=1, Magnitude=5.0, OriginAge=1.0, Distance=10,
                 Cancelled=0, Pga=1.5, SigmaLn=0.6, SArrivalIn=2.0)
HARMLESS = dict(DANGEROUS, EventId=0x0202, Pga=0.1, SigmaLn=0.5, SArrivalIn=3.0)
ORIGIN_SIGNALS = ("EventId", "Version", "Magnitude", "OriginAge", "Distance", "Cancelled")
ALERT_SIGNALS = ("EventId", "Version", "Pga", "SigmaLn", "SArrivalIn")


def origin(dbc, alert, raw=None):
    """The RegionalAlertOrigin frame of `alert` (its signals by DBC name)."""
    physical = {k: alert[k] for k in ORIGIN_SIGNALS if k not in (raw or {})}
    return dbc.ident("RegionalAlertOrigin"), dbc.encode("RegionalAlertOrigin", physical, raw)


def intensity(dbc, alert):
    """The RegionalAlert frame of `alert`."""
    return dbc.ident("RegionalAlert"), dbc.encode("RegionalAlert",
                                                   {k: alert[k] for k in ALERT_SIGNALS})


def pair(dbc, alert):
    return [origin(dbc, alert), intensity(dbc, alert)]


def cases(dbc):
    """[(what, [(ident, data, delay before it in s)], expected)]: one alert each, and the
    (result, reason, field) its {"type": "regional"} line must say (None: an accepted one's)."""
    def frames(*items, gap=FRAME_GAP_S):
        return [(ident, data, gap) for ident, data in items]

    a = DANGEROUS
    lone = dict(a, EventId=0x0301)
    origin_frame = origin(dbc, a)
    alert_frame = intensity(dbc, a)
    reserved = origin_frame[1][:7] + bytes([origin_frame[1][7] | 0x20])  # bit 61
    return [
        ("an alert frame without its origin frame", frames(intensity(dbc, lone)),
         ("refused", "malformed", "RegionalAlertOrigin")),
        ("an origin frame cut to 7 bytes", frames((origin_frame[0], origin_frame[1][:7])),
         ("refused", "malformed", "RegionalAlertOrigin")),
        ("an alert frame cut to 5 bytes, after its origin",
         frames(origin(dbc, lone), (alert_frame[0], alert_frame[1][:5])),
         ("refused", "malformed", "RegionalAlert")),
        ("an origin frame with Magnitude raw 201 (10.05, above the DBC's 10)",
         frames(origin(dbc, lone, raw={"Magnitude": 201})),
         ("refused", "malformed", "Magnitude")),
        ("an origin frame with reserved bit 61 set", frames((origin_frame[0], reserved)),
         ("refused", "malformed", "RegionalAlertOrigin")),
        ("an alert frame after another event's origin",
         frames(origin(dbc, dict(a, EventId=0x0302)), intensity(dbc, dict(a, EventId=0x0303))),
         ("refused", "malformed", "RegionalAlertOrigin")),
        (f"an alert frame {2 * PAIR_WINDOW_S:g} s after its origin (the window: "
         f"{PAIR_WINDOW_S:g} s)", frames(origin(dbc, dict(a, EventId=0x0304))) +
         [(*intensity(dbc, dict(a, EventId=0x0304)), 2 * PAIR_WINDOW_S)],
         ("refused", "malformed", "RegionalAlertOrigin")),
        ("an origin 5 s after the frame (S waves 10 s after it)",
         frames(*pair(dbc, dict(a, EventId=0x0305, OriginAge=-5.0, SArrivalIn=10.0))),
         ("refused", "future-dated", "origin_age_s")),
        ("an origin 650 s back (max_origin_age_s 600)",
         frames(*pair(dbc, dict(a, EventId=0x0306, OriginAge=650.0))),
         ("refused", "stale", "origin_age_s")),
        ("S waves 5 s before the frame, the origin 1 s before",
         frames(*pair(dbc, dict(a, EventId=0x0307, SArrivalIn=-5.0))),
         ("refused", "S arrival before origin", "s_arrival_in_s")),
        # The alerts: the dangerous one after a pause (the bus shows what raised the level).
        ("the dangerous alert", [(*origin_frame, HOSTILE_TO_ALERTS_S), (*alert_frame,
                                                                        FRAME_GAP_S)],
         ("accepted", None, None)),
        ("the dangerous alert again", frames(*pair(dbc, a)), ("refused", "duplicate", "version")),
        ("its version 0", frames(*pair(dbc, dict(a, Version=0))),
         ("refused", "out of order", "version")),
        ("a harmless alert", frames(*pair(dbc, HARMLESS)), ("accepted", None, None)),
        ("its cancellation (version 2)",
         frames(*pair(dbc, dict(HARMLESS, Version=2, Cancelled=1))), ("accepted", None, None)),
    ]


def shaking_duration_s(magnitude, distance_km):
    """docs/regional.md: 1 / f0, f0 = 4.906e6 beta (stress_drop / M0)^(1/3), M0 = 10^(1.5 M +
    16.05) dyne cm, plus 0.05 s/km."""
    m0 = 10 ** (1.5 * magnitude + 16.05)
    f0 = 4.906e6 * SHEAR_WAVE_SPEED_KM_S * (STRESS_DROP_BAR / m0) ** (1 / 3)
    return 1 / f0 + PATH_DURATION_S_PER_KM * distance_km


def collapse_probability(scene, pga_g, sigma_ln):
    """docs/regional.md: Phi(ln(PGA / median_g) / sqrt(beta^2 + sigma_ln^2))."""
    fragility = tomllib.loads(Path(scene).read_text())["fragility"]
    z = math.log(pga_g / fragility["median_g"]) / math.hypot(fragility["beta"], sigma_ln)
    return 0.5 * math.erfc(-z / math.sqrt(2))


def decoded_alert(dbc, alert):
    """The alert as the frames carry it (quantised by the DBC's factors)."""
    out = {}
    for name, signals in (("RegionalAlertOrigin", ORIGIN_SIGNALS), ("RegionalAlert",
                                                                    ALERT_SIGNALS)):
        ident = dbc.ident(name)
        raw, _ = dbc.decode(ident, dbc.encode(name, {k: alert[k] for k in signals}))
        for k in signals:
            s = dbc.signal(ident, k)
            out[k] = raw[k] * s.factor + s.offset
    return out


def prepare(work, dbc, scene, rate, lead_in_s):
    """regional.in.log (canplayer's input), regional.toml (the box file), quiet.csv (the quiet
    ground plinth-replay sends); returns config.env's values for the guest."""
    lines, gaps, t = [], [], 0.0
    for _, frames, _ in cases(dbc):
        for ident, data, gap in frames:
            t += gap
            gaps.append(str(round(gap * 1e6)))
            lines.append(f"({t:.6f}) vcan0 {ident:03X}#{data.hex().upper()}\n")
    (work / "regional.in.log").write_text("".join(lines))
    (work / "regional.toml").write_text(BOX_FILE)
    a = decoded_alert(dbc, DANGEROUS)
    probability = collapse_probability(scene, a["Pga"], a["SigmaLn"])
    if probability < WARNING_ON:
        raise ValueError(f"{scene}: the dangerous alert's probability {probability:.3f} is "
                         f"below warning_regional.on {WARNING_ON}: no warning to check")
    expires_after_s = a["SArrivalIn"] + shaking_duration_s(a["Magnitude"], a["Distance"]) + \
        EXPIRY_MARGIN_S
    # The guest waits this long after canplayer: the alert's expiry and 0.5 s of status after it.
    wait_s = expires_after_s + 0.5
    # Quiet ground (the lead-in's 1 LSB dither) for the monitor's start-up (fault held 2 s), the
    # frames and the wait, and 5 s more than that: plinth-replay is stopped before it ends.
    seconds = lead_in_s + 2.5 + t + wait_s + 5.0
    samples = [e2e.DITHER[k % 4] * e2e.RESOLUTION_G * e2e.G0 for k in range(round(seconds * rate))]
    e2e.write_csv(work / "quiet.csv", "quiet", rate, samples)
    return {"REGIONAL_SCENE": str(Path(scene).resolve()),
            "REGIONAL_CONFIG": str(work / "regional.toml"),
            "REGIONAL_WAIT": f"{wait_s:.3f}",
            # the gap before each frame, us (rig_losses.awk: the bus kept them)
            "REGIONAL_GAPS_US": " ".join(gaps)}



def bus_index(s, ident, data, after=-1):
    return next((i for i, f in enumerate(s.frames) if i > after and f.plinth()
                 and f.ident == ident and f.data == data), None)


def check(check, s, config):
    """The regional run's checks (after e2e_can.common_checks: counters, no sensor frame lost,
    timeouts only where the bus was silent)."""
    dbc = s.dbc
    scene = config["regional_scene"]
    plan = cases(dbc)
    sent = [(ident, data) for _, frames, _ in plan for ident, data, _ in frames]
    # canplayer's frames, all on the bus in order, after the monitor listened
    position, missing = s.ready, []
    for ident, data in sent:
        found = bus_index(s, ident, data, position)
        if found is None:
            missing.append(f"{ident:03X}#{data.hex().upper()}")
        else:
            position = found
    check(not missing, f"candump logged the bridge's {len(sent)} frames in order after the "
          f"monitor's first frame" + (f": missing {missing[:3]}" if missing else ""))

    # One {"type": "regional"} line per alert, each with the outcome docs/regional.md gives.
    lines = [x for x in s.lines if x.get("type") == "regional"]
    wrong = []
    for (what, _, (result, reason, field)), line in zip(plan, lines):
        got = (line.get("result"), line.get("reason"), line.get("field"))
        if got != (result, reason, field):
            wrong.append(f"{what}: {got}, expected {(result, reason, field)}")
    # the cancellation drops the harmless alert: the dangerous one alone is held
    if lines and (lines[-1].get("cancelled") is not True or lines[-1].get("held") != 1):
        wrong.append(f"the cancellation: {lines[-1]}")
    check(len(lines) == len(plan) and not wrong,
          f"{len(lines)} regional lines, one per alert sent ({len(plan)}), each refused with its "
          f"reason and field or accepted: " + "; ".join(
              f"{what} -> {reason or result}" for what, _, (result, reason, _) in plan)
          + (f"; WRONG: {wrong[:3]}" if wrong else ""))

    a = decoded_alert(dbc, DANGEROUS)
    probability = collapse_probability(scene, a["Pga"], a["SigmaLn"])
    accepted = next((x for x in lines if x.get("result") == "accepted"), None)
    check(accepted is not None and abs(accepted["probability"] - probability) <= 2e-4,
          f"the dangerous alert (PGA {a['Pga']:g} g, sigma_ln {a['SigmaLn']:g}) accepted with "
          f"P(collapse) {accepted and accepted['probability']}: Phi(ln(PGA / median) / "
          f"sqrt(beta^2 + sigma_ln^2)) = {probability:.4f} from the scene's [fragility] "
          f"(warning_regional.on {WARNING_ON})")

    # The bus: one AlarmEvent while the sensor sent after the start-up's normal: warning,
    # cause 15, latched, after the dangerous alert's frames.
    alert_frame = intensity(dbc, DANGEROUS)
    alert_at = bus_index(s, *alert_frame, s.ready)
    first_hostile = bus_index(s, *sent[0], s.ready)
    last_sensor = s.sensor[-1][0].t_us if s.sensor else 0
    events = [(i, s.decoded[i][0]) for i, f in enumerate(s.frames)
              if f.plinth() and f.ident == e2e.ALARM_ID and s.decoded[i][0] is not None
              and first_hostile is not None and i > first_hostile and f.t_us <= last_sensor]
    rise = events[0] if len(events) == 1 else None
    latency_ms = None
    if rise is not None and alert_at is not None and rise[0] > alert_at:
        latency_ms = (s.frames[rise[0]].t_us - s.frames[alert_at].t_us) / 1e3
    check(rise is not None and rise[1]["Level"] == WARNING and rise[1]["PreviousLevel"] == 0 and
          rise[1]["Cause"] == REGIONAL_CAUSE and rise[1]["Latched"] == 1 and
          latency_ms is not None and latency_ms < 100,
          f"the bus's only AlarmEvent from the first hostile frame to the sensor's last: "
          f"{rise and rise[1]} (warning from normal, cause {REGIONAL_CAUSE} regional_alert, "
          f"latched), {latency_ms if latency_ms is None else f'{latency_ms:.1f}'} ms after the "
          f"dangerous alert's RegionalAlert frame" + (f"; all: {events}" if rise is None else ""))
    warnings = [x for x in s.alarm_lines if x["cause"] == "regional_alert"]
    check(len(warnings) == 1 and warnings[0]["level"] == "warning" and
          not any(x["level"] == "alarm" for x in s.alarm_lines),
          f"the JSON alarm lines: one warning, cause regional_alert, never alarm: {warnings}")

    # The status lines: the alert held, its time to the S arrival counting down (negative while
    # the S waves pass), its expiry, the level latched after it.
    # (until the sensor's stop: its timeout's fault, after the last warning, ends the run)
    stopped_t = next((x["t"] for x in s.alarm_lines if x["cause"] == "sensor_timeout" and
                      warnings and x["t"] > warnings[-1]["t"]), math.inf)
    status = [x for x in s.status_lines if "regional" in x and x["t"] < stopped_t]
    held = [x for x in status if x["regional"]["held"] >= 1 and
            x["regional"]["event_id"] == DANGEROUS["EventId"]]
    raised_t = warnings[0]["t"] if warnings else None
    duration = shaking_duration_s(a["Magnitude"], a["Distance"])
    problems = []
    if not held or raised_t is None:
        problems.append("no status line holds the alert")
    else:
        r = held[0]["regional"]
        if abs(r["s_arrival_t"] - raised_t - a["SArrivalIn"]) > 0.005:
            problems.append(f"s_arrival_t {r['s_arrival_t']} is not the warning's t {raised_t} "
                            f"+ {a['SArrivalIn']} s")
        if abs(r["expires_t"] - r["s_arrival_t"] - duration - EXPIRY_MARGIN_S) > 0.002:
            problems.append(f"expires_t - s_arrival_t = {r['expires_t'] - r['s_arrival_t']:.3f}"
                            f" s, not {duration:.3f} + {EXPIRY_MARGIN_S}")
        for x in held:
            g = x["regional"]
            if abs(g["time_to_s_arrival_s"] - (g["s_arrival_t"] - x["t"])) > 0.0015:
                problems.append(f"t {x['t']}: time_to_s_arrival_s {g['time_to_s_arrival_s']}")
                break
        if not 0 < held[0]["regional"]["time_to_s_arrival_s"] <= a["SArrivalIn"]:
            problems.append(f"first time to arrival {held[0]['regional']['time_to_s_arrival_s']}")
        if not any(x["regional"]["time_to_s_arrival_s"] < 0 for x in held):
            problems.append("never negative while the S waves pass")
    shown = [x["regional"]["time_to_s_arrival_s"] for x in held]
    check(not problems, f"{len(held)} status lines show the dangerous alert: time to the S "
          f"arrival from {max(shown, default=0):.3f} s down to {min(shown, default=0):.3f} s, "
          f"s_arrival_t = warning t + {a['SArrivalIn']:g} s, expires_t = s_arrival_t + shaking "
          f"{duration:.3f} s (M {a['Magnitude']:g}, {a['Distance']:g} km) + margin "
          f"{EXPIRY_MARGIN_S:g} s" + (f": {problems}" if problems else ""))

    expired = [x for x in status if x["regional"]["expired"] >= 1]
    expires_t = held[0]["regional"]["expires_t"] if held else None
    last = status[-1]["regional"] if status else None
    refused = {}
    for _, _, (result, reason, _) in plan:
        if result == "refused":
            refused[reason] = refused.get(reason, 0) + 1
    want = dict(received=len(plan), accepted=len(plan) - sum(refused.values()), cancelled=1,
                expired=1, held=0, refused=refused)
    got = last and {k: last[k] for k in want}
    if got:
        got["refused"] = {k: v for k, v in got["refused"].items() if v}
    summary = s.summary.get("regional")
    final = summary and {k: summary[k] for k in want}
    if final:
        final["refused"] = {k: v for k, v in final["refused"].items() if v}
    # expired at expires_t: the first status line after it (status interval 0.02 s) says so
    on_time = bool(expired) and expires_t is not None and \
        expires_t <= expired[0]["t"] <= expires_t + 2 * config["status_interval_s"] + 0.005
    check(on_time and got == want and final == want and
          all(x["alarm"] == "warning" and x["latched"] == "warning" for x in expired),
          f"the alert expired at expires_t {expires_t} (first status line saying so at "
          f"{expired[0]['t'] if expired else None}); in the {len(expired)} status lines after, "
          f"the level still warning and latched (until acknowledged); the counters of the last "
          f"status line and of the summary: {got}" +
          ("" if got == want and final == want else f", summary {final}, expected {want}"))

    # The sensor stream went on: every SensorAcceleration frame on the bus was a sample (the
    # common checks), and none was refused.
    check(s.summary["sensor"]["rejected"] == 0 and s.summary["frames"]["sensor_samples"] > 0,
          f"the sensor stream went on undisturbed: {s.summary['frames']['sensor_samples']} "
          f"samples, none rejected; frames rejected by the codec "
          f"{s.summary['frames']['rejected']} (the truncated and garbled regional frames)")
    return latency_ms
