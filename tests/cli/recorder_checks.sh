# Shared by the event recorder's CLI tests (test_event_recorder.sh, test_recorder_hostile.sh,
# test_recorder_full_disk.sh): the quick start replayed with the recorder on, and what to read in
# its output and its folder. Needs $monitor and $src; sources checks.sh. Makes $tmp, removed at
# exit after the processes in $pids are killed and the script's own at_exit has run.
# shellcheck source=tests/cli/checks.sh
source "$src/tests/cli/checks.sh"
tmp=$(mktemp -d)
pids=()
at_exit() { :; }
cleanup() {
  for pid in "${pids[@]}"; do kill -9 "$pid" 2>/dev/null; done
  at_exit
  rm -rf "$tmp"
}
trap cleanup EXIT
scene=$src/sim/scenes/paper-eccentric.toml
record=$src/sim/data/records/friuli1976-09-15_buia_000.AT2
# The quick start (paper-eccentric.toml, Buia x6.5): one capture, which rises through warning
# (record time 2.82 s) to alarm (3.00 s); with --post-trigger 0, two (the warning's, the
# alarm's).
replay=(--scene "$scene" --replay "$record" --scale 6.5 --no-events --status-interval 1)

# [pre=S] [post=S] run DIR [ARGS...]: one replay recording into DIR, 5 s before the trigger and
# 2 s after unless pre or post say otherwise; its JSON lines in $tmp/out.jsonl, its stderr in
# $tmp/err.
run() {
  local dir=$1
  shift
  "$monitor" "${replay[@]}" --pre-trigger "${pre:-5}" --post-trigger "${post:-2}" \
    --record-dir "$dir" "$@" >"$tmp/out.jsonl" 2>"$tmp/err"
}
# json FILE EXPR: a Python expression over the JSON document `d` of FILE (one object), or over
# the JSON lines `lines` of FILE (status lines `status`, the summary `summary`, the summary's
# recorder `rec`).
json() {
  python3 - "$1" "$2" <<'PY'
import json, sys
text = open(sys.argv[1]).read()
try:
    d = json.loads(text)
except ValueError:
    d = None
lines = [json.loads(l) for l in text.splitlines() if l.startswith("{")]
status = [l for l in lines if l.get("type") == "status"]
summary = next((l for l in lines if l.get("type") == "summary"), {})
rec = summary.get("recorder", {})
print(eval(sys.argv[2]))
PY
}
# The names the recorder writes: event-NNN.log and .json, three digits or more, no other
# leading zero (capture_store.h); regular files only (what is planted under them aside).
captures_py='
import os, re
def captures(folder, extension):
    name = re.compile(r"event-(\d{3}|[1-9]\d{3,8})\." + extension + "$")
    return sorted((os.path.join(folder, f) for f in os.listdir(folder) if name.match(f) and
                   os.path.isfile(os.path.join(folder, f)) and
                   not os.path.islink(os.path.join(folder, f))),
                  key=lambda p: int(re.search(r"(\d+)\.[a-z]+$", p).group(1)))
'
# whole DIR: every capture under a final name is complete (its log has the frames its JSON
# counts, the JSON parses); prints what is not.
whole() {
  python3 - "$1" <<PY
$captures_py
import json, sys
for j in captures(sys.argv[1], "json"):
    log = j[:-5] + ".log"
    try:
        d = json.load(open(j))
    except ValueError as e:
        print("%s: %s" % (j, e)); continue
    lines = sum(1 for _ in open(log)) if os.path.exists(log) else -1
    if lines != d["frames"]:
        print("%s: %d lines, its JSON says %d frames" % (log, lines, d["frames"]))
for log in captures(sys.argv[1], "log"):
    if not os.path.exists(log[:-4] + ".json"):
        print("%s without its JSON" % log)
PY
}
# listing DIR: the numbers of the captures' summaries in DIR, "1 3 5 ".
listing() {
  python3 - "$1" <<PY
$captures_py
import sys
print("".join("%d " % int(re.search(r"(\d+)\.json$", j).group(1))
              for j in captures(sys.argv[1], "json")), end="")
PY
}
# wait_for FILE PATTERN [SECONDS]: until FILE holds PATTERN (grep -E), at most SECONDS (60).
wait_for() {
  local deadline=$((SECONDS + ${3:-60}))
  until grep -qE "$2" "$1" 2>/dev/null; do
    ((SECONDS < deadline)) || return 1
    sleep 0.05
  done
}
