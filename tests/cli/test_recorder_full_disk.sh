#!/usr/bin/env bash
# The event recorder on a full disk and a read-only folder (issue 33; docs/monitor.md, "Event
# recorder"), real plinth-monitor processes on a real file system: a 1 MiB tmpfs mounted in a
# user and mount namespace of its own (unshare -rm: no root needed where unprivileged user
# namespaces are allowed; exit 77, skipped, where they are not). A full disk gives an alarm
# capture the room of older captures below alarm (the retention order), never the newest alarm
# capture's; where no capture can make room, every loss is said and shown live. A folder
# read-only at start, or made read-only while the box runs, is said, shown failed in the status
# lines, then degraded once it can be written again.
# Usage: test_recorder_full_disk.sh PLINTH_MONITOR SOURCE_DIR
set -u
monitor=${1:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
src=${2:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
if [[ ${PLINTH_IN_NAMESPACE:-} != 1 ]]; then
  if ! unshare -rm true 2>/dev/null; then
    echo "SKIPPED: unshare -rm cannot make a user and mount namespace here (the full disk needs" \
      "a tmpfs of its own)" >&2
    exit 77
  fi
  PLINTH_IN_NAMESPACE=1 exec unshare -rm bash "$0" "$@"
fi
# shellcheck source=tests/cli/recorder_checks.sh
source "$src/tests/cli/recorder_checks.sh"
disk=$tmp/disk
mkdir -p "$disk"
at_exit() { umount "$disk" 2>/dev/null; }
if ! mount -t tmpfs -o size=1m tmpfs "$disk"; then
  echo "SKIPPED: no tmpfs can be mounted in the namespace" >&2
  exit 77
fi
dir=$disk/events

# A capture of the quick start (about 76 KB) to copy, written outside the small disk.
run "$tmp/model"
model=$tmp/model/event-001
# fake N LEVEL: capture N (its stem) in $dir, a copy of the model with its levels set to LEVEL.
fake() {
  cp "$model.log" "$dir/$1.log"
  sed -e "s/\"level\":\"[a-z]*\"/\"level\":\"$2\"/" \
      -e "s/\"highest_level\":\"[a-z]*\"/\"highest_level\":\"$2\"/" "$model.json" >"$dir/$1.json"
}
# fill: the disk's free space taken by a file that is no capture (retention leaves it).
fill() { cat /dev/zero >"$disk/filler-$RANDOM" 2>/dev/null; }

# 1. Full of captures: 1 alarm, 2-6 warnings, then no byte free. The run's capture (alarm) takes
#    the room of the oldest warnings, said; capture 1 (alarm) stays.
mkdir -p "$dir"
fake event-001 alarm
for n in 2 3 4 5 6; do fake "event-00$n" warning; done
fill
run "$dir"
check "a full disk: the run ends" $? "$(head -c 300 "$tmp/err")"
got="$(listing "$dir")$(json "$tmp/out.jsonl" '(rec["captures_written"], rec["captures_deleted"] >= 1, rec["health"])')"
[[ "$got" == "1 "*" 7 (1, True, 'ok')" && "$got" != "1 2 "* ]]
check "the alarm capture written in the room of the oldest warnings, alarm capture 1 kept" $? \
  "$got"
grep -q "the disk is full: .* older capture(s) deleted to make room (event-002" "$tmp/err"
check "the room made is said" $? "$(head -c 300 "$tmp/err")"
problems=$(whole "$dir")
[ -z "$problems" ]
check "every capture left whole" $? "$problems"

# 2. Full, and the newest alarm capture (7) the only capture: it is never deleted for another,
#    so both captures of the run (--post-trigger 0: the warning's, the alarm's) are lost; each
#    loss is said. (The status lines show such a loss live: section 4.)
rm -f "$dir"/event-00[1-6].*
fill
post=0 run "$dir"
got="$(listing "$dir")$(json "$tmp/out.jsonl" '(rec["captures_lost"], rec["health"], rec["problem"])')"
[ "$got" = "7 (2, 'failed', 'disk_full')" ]
check "no room to make: the newest alarm capture kept, both captures lost, failed (disk_full)" \
  $? "$got"
[ "$(grep -c "capture at t = .* is lost: .*No space left on device (disk_full)" "$tmp/err")" = 2 ] &&
  grep -q "2 lost so far" "$tmp/err"
check "each loss said, not only the first" $? "$(head -c 400 "$tmp/err")"

# 3. Read-only at start: said at once, failed (not_writable) from the first status line, the
#    capture lost; the box runs all the same.
rm -f "$disk"/filler-*
mount -o remount,ro "$disk"
run "$dir"
check "a read-only folder: the box runs" $? "$(head -c 300 "$tmp/err")"
got=$(json "$tmp/out.jsonl" '(status[0]["recorder"]["problem"], rec["health"], rec["captures_lost"])')
[ "$got" = "('not_writable', 'failed', 1)" ] &&
  grep -q "cannot create files in $dir: Read-only file system (not_writable)" "$tmp/err"
check "read-only at start: said, shown failed from the first status line, the capture lost" $? \
  "$got; $(head -c 300 "$tmp/err")"
mount -o remount,rw "$disk"

# 4. Made read-only while the box runs (a paced replay): shown failed within the check period
#    (2 s), the capture lost and said; writable again: degraded (a capture was lost), said.
"$monitor" "${replay[@]}" --pre-trigger 5 --post-trigger 2 --speed 2 --record-dir "$dir" \
  >"$tmp/live.jsonl" 2>"$tmp/live.err" &
pid=$!
pids+=("$pid")
wait_for "$tmp/live.jsonl" '"type": "status"'
mount -o remount,ro "$disk"
wait_for "$tmp/live.jsonl" '"problem": "not_writable"' &&
  wait_for "$tmp/live.err" "is lost: .*not_writable"
check "made read-only: shown failed (not_writable) live, the capture's loss said" $? \
  "$(head -c 300 "$tmp/live.err")"
mount -o remount,rw "$disk"
wait_for "$tmp/live.jsonl" '"recorder": \{"health": "degraded", "problem": "not_writable"' &&
  wait_for "$tmp/live.err" "can be used again"
check "writable again: degraded (the capture lost), said" $? "$(tail -n 2 "$tmp/live.err")"
kill -INT "$pid"
wait "$pid"

finish
