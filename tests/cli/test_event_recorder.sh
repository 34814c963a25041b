#!/usr/bin/env bash
# The event recorder's folder as a box that restarts uses it (docs/monitor.md, "Event
# recorder"): what runs is named (version, SHA-256 of the scene and box files, as sha256sum
# says) in the first status line and each capture's JSON; a restart numbers its captures after
# the highest present and leaves the earlier ones byte for byte; a process killed with SIGKILL
# while writing leaves no file under a final name but whole ones (its partial file is removed at
# the next start); the retention limit deletes the oldest captures below alarm first and never
# the newest alarm capture. Each run replays the quick start (paper-eccentric.toml, Buia x6.5):
# one capture, which rises through warning to alarm.
# Usage: test_event_recorder.sh PLINTH_MONITOR SOURCE_DIR
set -u
monitor=${1:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
src=${2:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
# shellcheck source=tests/cli/recorder_checks.sh
source "$src/tests/cli/recorder_checks.sh"

# 1. What runs, named: the build's version and the files' SHA-256.
box=$tmp/box.toml
printf '[recorder]\nmax_captures = 0\n' >"$box"
dir=$tmp/events
run "$dir" --config "$box"
check "a replay with the recorder runs" $? "$(head -c 300 "$tmp/err")"
version=$("$monitor" --version | sed 's/^plinth-monitor //')
scene_sum=$(sha256sum "$scene" | cut -d' ' -f1)
box_sum=$(sha256sum "$box" | cut -d' ' -f1)
got=$(json "$tmp/out.jsonl" '(status[0]["version"], status[0]["scene_sha256"], status[0]["config_sha256"])')
[ "$got" = "('$version', '$scene_sum', '$box_sum')" ]
check "first status line: version and sha256sum of scene and box file" $? "$got"
got=$(json "$tmp/out.jsonl" 'sum("version" in s for s in status[1:])')
[ "$got" = 0 ]
check "only the first status line carries them" $? "$got later lines"
got=$(json "$dir/event-001.json" '(d["version"], d["scene_sha256"], d["config_sha256"], d["highest_level"])')
[ "$got" = "('$version', '$scene_sum', '$box_sum', 'alarm')" ]
check "capture JSON: version, digests, highest level alarm" $? "$got"

# 2. A restart continues the numbers; the earlier capture is kept byte for byte.
before=$(sha256sum "$dir/event-001.log" "$dir/event-001.json")
run "$dir"
check "second run" $? "$(head -c 300 "$tmp/err")"
after=$(sha256sum "$dir/event-001.log" "$dir/event-001.json")
[ "$before" = "$after" ] && [ -s "$dir/event-002.log" ] && [ -s "$dir/event-002.json" ]
check "restart: event-002 written, event-001 unchanged" $? "$(ls "$dir")"
got=$(json "$tmp/out.jsonl" 'summary["recorder"]["first_index"]')
[ "$got" = 2 ]
check "summary: first index 2" $? "$got"
# After the highest present, gaps and foreign numbers included.
cp "$dir/event-002.json" "$dir/event-041.json"
run "$dir"
[ -s "$dir/event-042.log" ] && [ ! -e "$dir/event-003.log" ]
check "numbers continue after the highest present (041 -> 042)" $? "$(ls "$dir" | tr '\n' ' ')"
rm "$dir/event-041.json" "$dir/event-042."*

# 3. SIGKILL while a capture is being written: the writer is held halfway through the log
#    (recorder.test_pause_mid_write_s), the process killed there.
printf '[recorder]\ntest_pause_mid_write_s = 60\n' >"$tmp/pause.toml"
"$monitor" "${replay[@]}" --pre-trigger 5 --post-trigger 2 --record-dir "$dir" --config "$tmp/pause.toml" \
  >"$tmp/killed.jsonl" 2>"$tmp/killed.err" &
pid=$!
pids+=("$pid")
partial=""
for ((i = 0; i < 300; i++)); do
  partial=$(find "$dir" -name '.event-*.log.partial' -size +0 | head -1)
  [ -n "$partial" ] && break
  sleep 0.1
done
[ -n "$partial" ]
check "a partial file appears while the capture is written" $? "$(ls -a "$dir")"
kill -9 "$pid"
wait "$pid" 2>/dev/null
partial_lines=$(wc -l <"$partial" 2>/dev/null || echo 0)
[ ! -e "$dir/event-003.log" ] && [ ! -e "$dir/event-003.json" ] && [ "$partial_lines" -gt 0 ]
check "killed mid-write: nothing under a final name ($partial_lines lines in the partial file)" \
  $? "$(ls -a "$dir" | tr '\n' ' ')"
problems=$(whole "$dir")
[ -z "$problems" ]
check "killed mid-write: every capture under a final name is whole" $? "$problems"
run "$dir"
got=$(json "$tmp/out.jsonl" '(summary["recorder"]["partial_files_removed"], summary["recorder"]["first_index"])')
[ "$got" = "(1, 3)" ] && [ -z "$(find "$dir" -name '*.partial')" ] && [ -s "$dir/event-003.log" ]
check "next start: the partial file removed, capture 3 written" $? "$got; $(ls -a "$dir" | tr '\n' ' ')"

# SIGKILL at other moments (random, 0-0.6 s into the run): whatever is under a final name is
# whole.
for ((k = 0; k < 6; k++)); do
  "$monitor" "${replay[@]}" --pre-trigger 5 --post-trigger 2 --record-dir "$dir" >/dev/null 2>&1 &
  pid=$!
  sleep "0.$((RANDOM % 6))$((RANDOM % 10))"
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
done
problems=$(whole "$dir")
[ -z "$problems" ]
check "6 runs killed at random moments: every capture under a final name is whole" $? "$problems"

# 4. Retention. A folder of four captures: 1 alarm, 2 warning, 3 alarm, 4 warning (copies of a
#    real one with its levels set), then the run's capture 5 (alarm).
ret=$tmp/retention
mkdir -p "$ret"
# fake FROM TO LEVEL: capture TO (a stem) as a copy of FROM with its levels set to LEVEL.
fake() {
  cp "$1.log" "$2.log"
  sed -e "s/\"level\":\"[a-z]*\"/\"level\":\"$3\"/" \
      -e "s/\"highest_level\":\"[a-z]*\"/\"highest_level\":\"$3\"/" "$1.json" >"$2.json"
}
for i in 1 2 3 4; do
  level=alarm
  [ $((i % 2)) -eq 0 ] && level=warning
  fake "$dir/event-001" "$ret/event-00$i" "$level"
done
# limited NAME KEY=VALUE EXPECTED: a run with the retention limit [recorder] KEY=VALUE leaves the
# captures EXPECTED ("1 3 5 ").
limited() {
  printf '[recorder]\n%s\n' "$2" >"$tmp/limit.toml"
  run "$ret" --config "$tmp/limit.toml"
  local got
  got=$(listing "$ret")
  [ "$got" = "$3" ]
  check "$1" $? "left: $got"
}
limited "max_captures = 3: the warnings (2, 4) go first" "max_captures = 3" "1 3 5 "
got=$(json "$tmp/out.jsonl" 'summary["recorder"]["captures_deleted"]')
[ "$got" = 2 ]
check "summary: 2 captures deleted" $? "$got"
limited "max_captures = 1: only the newest alarm capture (6) stays" "max_captures = 1" "6 "
# A byte limit below one capture: the newest alarm capture is kept all the same.
limited "max_bytes = 1000: 6 deleted, the newest alarm capture (7) kept over the limit" \
  "max_bytes = 1000" "7 "
# A warning capture newer than an alarm capture still goes first: 7 alarm, 8 warning, then 9.
fake "$ret/event-007" "$ret/event-008" warning
limited "max_captures = 2: the newer warning (8) goes before the older alarm (7)" \
  "max_captures = 2" "7 9 "

# 5. Bad [recorder] values are refused with the key named.
printf '[recorder]\nmax_captures = -1\n' >"$tmp/bad.toml"
run "$tmp/bad" --config "$tmp/bad.toml"
rc=$?
[ $rc -eq 1 ] && grep -q "recorder.max_captures" "$tmp/err"
check "max_captures = -1 refused, the key named" $? "exit $rc: $(head -c 200 "$tmp/err")"

finish
