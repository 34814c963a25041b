# Why the rig spoiled one bus run of tools/e2e-can.sh: one reason a line, nothing when it carried
# the run. The rig is the guest kernel and its CPU, candump (the witness) and plinth-replay (the
# sensor); nothing here reads what the box (plinth-monitor) said. The guest runs it after each
# run to decide whether to run again; e2e_can.py's checks run it on the last run's files for
# their verdict: one implementation for both. awk, not Python: a process started in a loaded
# user-mode Linux guest reads its files through hostfs, and Python's start took 31 s there at
# host load 15 (awk's: a fraction of a second). docs/can-e2e.md, "A run the rig spoiled".
#
# Usage: awk -f rig_losses.awk -v run=NAME -v report=NAME.replay.json -v timeout_us=50000
#            -v starved_late_us=45000 -v backlog_late_us=300000 -v extra=NAME.extra
#            -v min_idle_percent=10 [-v gaps_us="0 2000 ..."] NAME.bus.log
#   run              main, stop, garbage, burst or regional
#   report           plinth-replay's --report-json output ("" or a missing file: none)
#   extra            the guest's notes of the run (key=value): guest_idle_percent, the share of
#                    the stream the guest's CPU was idle (main, stop, regional)
#   min_idle_percent below it, the guest was starved
#   timeout_us       the monitor's sensor timeout
#   starved_late_us  main and regional: plinth-replay this late spoils the run
#   backlog_late_us  garbage and burst: plinth-replay this late spoils the run
#   gaps_us          regional: the gap before each of the bridge's frames in regional.in.log
#   tolerance_us     regional: how far off its gap a bridge frame may come (default 50000)
#
# The reasons:
# - candump, the witness, lost frames: its DROPCOUNT lines (candump -d), or fewer
#   SensorAcceleration frames (0x301, 8 bytes) in its log than plinth-replay says it sent (a loss
#   at the end, which no later frame reports); a line that is neither a frame nor a DROPCOUNT;
# - the guest was starved: in main, stop and regional the sensor fell silent on the bus for
#   longer than the timeout (the monitor's estimator restarts, the timeline cannot be
#   plinth-sim's, the stop's fault would not be the kill's, the regional warning would hide
#   behind a fault); in main and regional plinth-replay was starved_late_us late (a process that
#   needs little CPU could not keep time: the monitor beside it in the guest, which needs more,
#   falls behind and its socket overflows; seen at host load 18: 536 frames dropped, its clock
#   9 s behind, plinth-replay 236 ms late at worst and no silence over 30 ms); in garbage and
#   burst, which load the guest on purpose (canplayer, cangen, a stopped monitor, floods),
#   plinth-replay was backlog_late_us late; in main, stop and regional the guest's CPU was idle
#   less than min_idle_percent of the stream (it could not carry the monitor, candump and
#   plinth-replay: seen at host load 17, the monitor 1.1 s behind with plinth-replay on time;
#   idle 0-6 % at host load 13-19);
# - regional: a bridge frame (0x360, 0x361, sent by canplayer) came more than tolerance_us off
#   its gap.

function base(path) { sub(/.*\//, "", path); return path }
function us(stamp) { gsub(/[().]/, "", stamp); return stamp + 0 }  # "(s.micros)" -> us

BEGIN {
  if (tolerance_us == "") tolerance_us = 50000
  sent = -1
  late = -1
  if (report != "") {
    while ((getline line < report) > 0) {  # the last JSON line is the report
      if (match(line, /"acceleration_frames": [0-9]+/))
        sent = substr(line, RSTART + 23, RLENGTH - 23) + 0
      if (match(line, /"jitter_max_us": [0-9.]+/))
        late = substr(line, RSTART + 17, RLENGTH - 17) + 0
    }
    close(report)
  }
  idle = -1
  if (extra != "") {
    while ((getline line < extra) > 0)
      if (line ~ /^guest_idle_percent=[0-9]+$/) idle = substr(line, 20) + 0
    close(extra)
  }
  gap_count = split(gaps_us, gap, " ")
}

/^DROPCOUNT: dropped [0-9]+ CAN frames? on '[^']+' socket \(total drops [0-9]+\)$/ {
  drops++
  lost += $3
  if (drops == 1) first_drop = base(FILENAME) ":" FNR ": " $0
  next
}

/^\([0-9]+\.[0-9][0-9][0-9][0-9][0-9][0-9]\) [^ ]+ [0-9A-Fa-f]+#[0-9A-Fa-fR.]*$/ {
  t = us($1)
  if (substr($3, 1, 4) == "301#" && length($3) == 20) {  # SensorAcceleration, 8 bytes
    logged++
    if (logged > 1 && t - last_sensor > silence) silence = t - last_sensor
    last_sensor = t
  } else if (run == "regional" && (substr($3, 1, 4) == "360#" || substr($3, 1, 4) == "361#")) {
    bridge++
    if (bridge > 1 && bridge <= gap_count && miss_at == 0) {
      miss = t - last_bridge - gap[bridge]
      if (miss > tolerance_us || miss < -tolerance_us) miss_at = bridge
    }
    last_bridge = t
  }
  next
}

/./ {
  if (!strange) strange = base(FILENAME) ":" FNR ": " substr($0, 1, 80)
}

END {
  if (drops > 0)
    printf "candump, the witness, lost %d frames (%d DROPCOUNT line%s; the first, %s)\n",
      lost, drops, (drops > 1 ? "s" : ""), first_drop
  if (strange != "")
    printf "candump, the witness, wrote a line that is neither a frame nor a DROPCOUNT " \
      "report: %s\n", strange
  if (sent > logged)
    printf "candump, the witness, logged %d of the %d SensorAcceleration frames " \
      "plinth-replay sent\n", logged, sent
  if ((run == "main" || run == "stop" || run == "regional") && silence > timeout_us)
    printf "the guest was starved: the sensor (plinth-replay) fell silent on the bus for " \
      "%.1f ms, longer than the monitor's %.0f ms sensor timeout\n", silence / 1e3,
      timeout_us / 1e3
  if ((run == "main" || run == "regional") && late >= starved_late_us)
    printf "the guest was starved: plinth-replay (the sensor) was up to %.0f ms late, %.0f ms " \
      "allowed (the monitor beside it falls behind)\n", late / 1e3, starved_late_us / 1e3
  if ((run == "main" || run == "stop" || run == "regional") && idle >= 0 && \
      idle < min_idle_percent)
    printf "the guest was starved: its CPU was idle %d%% of the stream, less than the %d%% " \
      "it needs to carry the monitor, candump and plinth-replay\n", idle, min_idle_percent
  if ((run == "garbage" || run == "burst") && late >= backlog_late_us)
    printf "the guest was starved: plinth-replay was up to %.0f ms late (its backlog could " \
      "overflow the monitor's socket)\n", late / 1e3
  if (miss_at > 0)
    printf "the guest was starved: the bridge's frame %d (canplayer) came %+.1f ms off its " \
      "gap in regional.in.log\n", miss_at - 1, miss / 1e3
}
