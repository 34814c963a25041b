#!/usr/bin/env bash
# The event recorder's folder taken as written by an attacker (issue 33; docs/monitor.md,
# "Event recorder"), with real plinth-monitor processes and real files: symlinks planted under
# the names it writes are never followed and nothing is written over; a second box on the same
# folder is refused, said and shown live while the first keeps it; a capture numbered
# event-999999999 leaves no number after it, which is said and shown; a folder deleted while the
# box runs is recreated; a busy bus, and the statue sensor's frames, are kept whole or the
# capture says what it misses. The full disk and a read-only folder:
# test_recorder_full_disk.sh.
# Usage: test_recorder_hostile.sh PLINTH_MONITOR SOURCE_DIR
set -u
monitor=${1:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
src=${2:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
# shellcheck source=tests/cli/recorder_checks.sh
source "$src/tests/cli/recorder_checks.sh"
# start NAME DIR [ARGS...]: a paced replay (twice real time) recording into DIR in the
# background, its output in $tmp/NAME.jsonl and $tmp/NAME.err, its pid in $pid; waits for its
# first status line (the recorder has opened its folder by then).
start() {
  local name=$1 dir=$2
  shift 2
  "$monitor" "${replay[@]}" --pre-trigger 5 --post-trigger 2 --speed 2 --record-dir "$dir" "$@" \
    >"$tmp/$name.jsonl" 2>"$tmp/$name.err" &
  pid=$!
  pids+=("$pid")
  wait_for "$tmp/$name.jsonl" '"type": "status"' ||
    echo "the paced replay $name did not start: $(head -c 300 "$tmp/$name.err")" >&2
}
# stop_when FILE: once FILE exists (a capture written; at most 120 s), SIGINT to $pid (it writes
# its summary), then waits for it.
stop_when() {
  local deadline=$((SECONDS + 120))
  until [ -e "$1" ] || ((SECONDS >= deadline)); do sleep 0.05; done
  kill -INT "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
}
echo precious >"$tmp/target"

# 1. Symlinks and other files under the recorder's names. At start: a symlink at the first
#    capture's partial name (removed, not followed), one under the second capture's final name
#    (a name taken: that capture takes the next number), a folder and a FIFO under capture names,
#    a file with a name the recorder never writes. Two captures (--post-trigger 0).
dir=$tmp/symlinks
mkdir -p "$dir"
ln -s "$tmp/target" "$dir/.event-001.log.partial"
ln -s "$tmp/target" "$dir/event-002.log"
mkdir "$dir/event-003.json"
mkfifo "$dir/event-004.log"
echo '{"highest_level": "alarm"}' >"$dir/event-0005.json"
post=0 run "$dir"
check "a folder of planted files: the run ends" $? "$(head -c 300 "$tmp/err")"
[ "$(cat "$tmp/target")" = precious ] && [ -L "$dir/event-002.log" ] && [ -d "$dir/event-003.json" ] &&
  [ -p "$dir/event-004.log" ] && [ -s "$dir/event-0005.json" ]
check "no symlink followed, no planted file written over or removed" $? "$(ls -la "$dir")"
got="$(listing "$dir")$(json "$tmp/out.jsonl" '(rec["captures_written"], rec["health"])')"
[ "$got" = "1 5 (2, 'ok')" ]
check "the captures take the free numbers (1, then 5 after the names taken)" $? "$got"
problems=$(whole "$dir")
[ -z "$problems" ]
check "both captures whole" $? "$problems"
# While the box runs: symlinks at the partial names of the numbers it may take next (removed,
# not followed: the partial file is created, never opened).
dir=$tmp/symlinks-live
mkdir -p "$dir"
start live "$dir"
for n in 001 002 003; do
  ln -s "$tmp/target" "$dir/.event-$n.log.partial"
  ln -s "$tmp/target" "$dir/.event-$n.json.partial"
done
stop_when "$dir/event-001.json"
got="$(cat "$tmp/target") $(listing "$dir")$(json "$tmp/live.jsonl" 'rec["health"]')"
[ "$got" = "precious 1 ok" ] && [ -z "$(whole "$dir")" ]
check "symlinks planted at the partial names while the box runs: not followed" $? "$got"

# 2. A second box on the same folder: refused (the first holds the lock), said with the first's
#    pid, shown failed from its first status line, its capture counted lost; the first box's
#    captures untouched. Once the first has gone, the folder is a third box's.
dir=$tmp/shared
start first "$dir"
first_pid=$pid
run "$dir"
check "a second box runs all the same" $? "$(head -c 300 "$tmp/err")"
grep -q "is in use by another plinth-monitor (pid $first_pid, holding .*\.plinth-monitor\.lock)" \
  "$tmp/err"
check "the second box says the folder is the first's, with its pid" $? "$(head -c 300 "$tmp/err")"
got=$(json "$tmp/out.jsonl" '(status[0]["recorder"]["health"], status[0]["recorder"]["problem"], all(s["recorder"]["health"] == "failed" for s in status), rec["captures_lost"], rec["captures_written"])')
[ "$got" = "('failed', 'folder_in_use', True, 1, 0)" ]
check "shown failed (folder_in_use) in every status line, its capture lost" $? "$got"
grep -q "capture at t = 2.820 s (.*) is lost: .*(folder_in_use); 1 lost so far" "$tmp/err"
check "its loss is said" $? "$(tail -n 2 "$tmp/err")"
stop_when "$dir/event-001.json"
got="$(listing "$dir")$(json "$tmp/first.jsonl" '(rec["captures_written"], rec["health"])')"
[ "$got" = "1 (1, 'ok')" ]
check "the first box keeps the folder: its capture written" $? "$got"
run "$dir"
got="$(listing "$dir")$(json "$tmp/out.jsonl" 'rec["health"]')"
[ "$got" = "1 2 ok" ]
check "after the first box, a third box takes the folder" $? "$got"

# 3. The numbering: a capture numbered 999999999 leaves no number after it (nothing written as
#    event-1000000000, nothing over the file); said at start and shown in every status line.
#    At 999999998, the first capture takes 999999999 and the second is lost, said.
dir=$tmp/numbers
mkdir -p "$dir"
echo '{"level": "warning"}' >"$dir/event-999999999.json"
run "$dir"
got=$(json "$tmp/out.jsonl" '(all(s["recorder"]["problem"] == "numbering_exhausted" for s in status), rec["health"], rec["captures_lost"])')
[ "$got" = "(True, 'failed', 1)" ] && [ "$(ls "$dir")" = event-999999999.json ] &&
  [ "$(cat "$dir/event-999999999.json")" = '{"level": "warning"}' ]
check "event-999999999 present: nothing written, shown failed (numbering_exhausted)" $? \
  "$got; $(ls "$dir" | tr '\n' ' ')"
grep -q "holds event-999999999 (a .log or .json), the highest number" "$tmp/err" &&
  grep -q "is lost: no capture number after event-999999999" "$tmp/err"
check "said at start and at the loss" $? "$(head -c 400 "$tmp/err")"
rm "$dir/event-999999999.json"
echo '{"level": "warning"}' >"$dir/event-999999998.json"
post=0 run "$dir"
got="$(listing "$dir")$(json "$tmp/out.jsonl" '(rec["captures_written"], rec["captures_lost"], rec["problem"])')"
[ "$got" = "999999998 999999999 (1, 1, 'numbering_exhausted')" ]
check "from 999999998: the first capture is 999999999, the second lost" $? "$got"

# 4. The folder deleted while the box runs: recreated (the check every 2 s, or the capture's),
#    said, the capture written in it.
dir=$tmp/deleted
start deleted "$dir"
rm -rf "$dir"
stop_when "$dir/event-001.json"
got="$(listing "$dir")$(json "$tmp/deleted.jsonl" '(rec["captures_written"], rec["health"])')"
[ "$got" = "1 (1, 'ok')" ] && grep -q "$dir disappeared: recreated" "$tmp/deleted.err" &&
  [ -z "$(whole "$dir")" ]
check "a folder deleted while the box runs is recreated and gets the capture" $? \
  "$got; $(head -c 300 "$tmp/deleted.err")"

# 5. A busy bus. The quick start's ground frames as a candump log (its first 7.5 s: 1,501
#    frames at 200 Hz), and the same with 2,000 frames/s of another node's traffic between them.
base=$tmp/base
pre=60 post=60 run "$base"
python3 - "$base/event-001.log" "$tmp/ground.log" "$tmp/busy.log" <<'PY'
import sys
ground, busy, previous = open(sys.argv[2], "w"), open(sys.argv[3], "w"), None
for line in open(sys.argv[1]):
    us = round(float(line[1:18]) * 1e6)
    if us > 7_500_000:
        break
    if previous is not None:  # ten frames of node 0x123 in each 5 ms gap
        for k in range(1, 11):
            u = previous + k * (us - previous) // 11
            busy.write("(%010d.%06d) can0 123#%016X\n" % (u // 10**6, u % 10**6, u))
    ground.write(line)
    busy.write(line)
    previous = us
PY
# in_window CAPTURES LOG: "frames in the captures / frames of LOG within their window".
in_window() {
  python3 - "$1" "$2" <<'PY'
import glob, json, os, sys
pieces = [json.load(open(j)) for j in sorted(glob.glob(os.path.join(sys.argv[1], "event-*.json")))]
first = min(p["first_frame_time"] for p in pieces)
last = max(p["last_frame_time"] for p in pieces)
held = sum(p["frames"] for p in pieces)
log = sum(1 for l in open(sys.argv[2]) if first - 1e-7 <= float(l[1:18]) <= last + 1e-7)
print("%d/%d" % (held, log))
PY
}
# log_replay LOG DIR [ARGS...]: LOG replayed recording into DIR (output in $tmp/out.jsonl).
log_replay() {
  local log=$1 dir=$2
  shift 2
  "$monitor" --scene "$scene" --replay "$log" --startup-window 1 --pre-trigger 5 \
    --post-trigger 2 --no-events --status-interval 1 --record-dir "$dir" "$@" \
    >"$tmp/out.jsonl" 2>"$tmp/err"
}
# (a) The default buffers (recorder.bus_frames_hz = 2000) hold the window whole (from the log's
#     start, 5 s before the warning, to 2 s after the alarm).
log_replay "$tmp/busy.log" "$tmp/busy-a"
got="$(listing "$tmp/busy-a")$(json "$tmp/busy-a/event-001.json" '(d["truncated"], d["first_frame_time"], d["last_frame_time"])')"
frames=$(in_window "$tmp/busy-a" "$tmp/busy.log")
[ "$got" = "1 (False, 0.0, 7.03)" ] && [ "${frames%/*}" = "${frames#*/}" ]
check "2,000 other frames/s: the window whole in one capture" $? "$got; $frames frames"
# (b) Buffers for 100 other frames/s: the window goes on in pieces, each continuing the one
#     before, no frame lost after the first piece's start; the pre-trigger window the ring
#     could not hold is marked (truncated, pre_trigger_cut_s), counted and said.
printf '[recorder]\nbus_frames_hz = 100\n' >"$tmp/small.toml"
log_replay "$tmp/busy.log" "$tmp/busy-b" --speed 1 --config "$tmp/small.toml"
got=$(python3 - "$tmp/busy-b" <<'PY'
import glob, json, os, sys
pieces = [json.load(open(j)) for j in sorted(glob.glob(os.path.join(sys.argv[1], "event-*.json")))]
chained = all(p.get("continues") == q["event"] and q.get("continued") for q, p in zip(pieces, pieces[1:]))
print(len(pieces) >= 3, chained, "continued" not in pieces[-1], pieces[0]["truncated"],
      pieces[0]["pre_trigger_cut_s"] > 1, all(not p["truncated"] for p in pieces[1:]),
      all(p["highest_level"] == "alarm" for p in pieces))
PY
)
frames=$(in_window "$tmp/busy-b" "$tmp/busy.log")
[ "$got" = "True True True True True True True" ] && [ "${frames%/*}" = "${frames#*/}" ]
check "100 other frames/s in the buffers: the window in chained pieces, none lost" $? \
  "$got; $frames frames"
got=$(json "$tmp/out.jsonl" '(rec["health"], rec["problem"], rec["captures_truncated"], rec["frames_lost"], status[-1]["recorder"]["health"])')
[ "$got" = "('degraded', 'truncated', 1, 0, 'degraded')" ] &&
  grep -q "event-001 misses frames of its window: 0 dropped before it, .* s of its pre-trigger window no longer held" "$tmp/err"
check "the cut pre-trigger window: degraded (truncated) live and at the end, said" $? \
  "$got; $(head -c 300 "$tmp/err")"
# (c) The writer held halfway through the first piece (test_pause_mid_write_s): the window
#     finds no buffer for a while; the frames it misses are counted, marked and said.
printf '[recorder]\nbus_frames_hz = 100\ntest_pause_mid_write_s = 1\n' >"$tmp/held.toml"
log_replay "$tmp/busy.log" "$tmp/busy-c" --config "$tmp/held.toml"
got=$(json "$tmp/out.jsonl" '(rec["frames_lost"] > 0, rec["captures_truncated"] >= 2, rec["health"])')
[ "$got" = "(True, True, 'degraded')" ] &&
  grep -q "frame(s) of a capture window found no buffer (the writer is behind)" "$tmp/err" &&
  [ -z "$(whole "$tmp/busy-c")" ]
check "the writer behind: the frames missed counted and said, every piece whole" $? \
  "$got; $(head -c 300 "$tmp/err")"

# 6. The statue sensor: three frames a sample (the ground's, the IMU's acceleration and
#    rotation). With [statue_sensor] and no allowance for other traffic, the buffers still hold
#    the window whole: they are sized for every configured sensor.
python3 "$src/tests/cli/statue_frames.py" "$tmp/ground.log" "$tmp/statue.log" >/dev/null
printf '[statue_sensor]\nnode = 2\n[recorder]\nbus_frames_hz = 0\n' >"$tmp/statue.toml"
log_replay "$tmp/statue.log" "$tmp/statue" --config "$tmp/statue.toml"
got="$(json "$tmp/out.jsonl" '(rec["captures_written"], rec["captures_truncated"], rec["frames_lost"])') $(json "$tmp/statue/event-001.json" 'd["truncated"]')"
frames=$(in_window "$tmp/statue" "$tmp/statue.log")
[ "$got" = "(1, 0, 0) False" ] && [ "${frames%/*}" = "${frames#*/}" ]
check "the statue sensor's frames: the window whole" $? "$got; $frames frames; $(head -c 300 "$tmp/err")"

finish
