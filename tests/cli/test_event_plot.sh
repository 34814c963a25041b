#!/usr/bin/env bash
# tools/plinth-event-plot as a custodian runs it on the event recorder's captures
# (docs/relays-and-supervision.md): a collapse and an all-clear marked where the monitor says,
# a PNG of the expected size, hostile file names (quotes, a newline, gnuplot and shell code)
# kept as data, and bad inputs refused with a message.
# Usage: test_event_plot.sh PLINTH_MONITOR SOURCE_DIR
set -u
monitor=${1:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
src=${2:?usage: $0 PLINTH_MONITOR SOURCE_DIR}
plot=$src/tools/plinth-event-plot
scene=$src/sim/scenes/paper-eccentric.toml
record=$src/sim/data/records/friuli1976-09-15_buia_000.AT2
export PLINTH_MONITOR=$monitor
if ! command -v gnuplot >/dev/null; then
  echo "skipped: no gnuplot (package gnuplot-nox)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
# shellcheck source=tests/cli/checks.sh
source "$src/tests/cli/checks.sh"
# png_size FILE: "WIDTHxHEIGHT" of a PNG, or nothing when FILE is not one.
png_size() {
  python3 -c 'import struct, sys
d = open(sys.argv[1], "rb").read(24)
if d[:8] == b"\x89PNG\r\n\x1a\n" and d[12:16] == b"IHDR":
    print("%dx%d" % struct.unpack(">II", d[16:24]))' "$1" 2>/dev/null
}
# capture NAME SCALE: the recorder's capture of the record at SCALE, and the overturn's time in
# the capture (the record's time plus the replay's lead-in) in NAME.overturned, if any.
capture() {
  "$monitor" --scene "$scene" --replay "$record" --scale "$2" --record-dir "$1" \
    --status-interval 100 >"$1.jsonl" 2>"$1.err"
  python3 -c 'import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
lead = -min(l["t"] for l in lines if l["type"] == "alarm")
for l in lines:
    if l["type"] == "event" and l["event"] == "overturned":
        print("%.3f" % (l["t"] + lead)); break' "$1.jsonl" >"$1.overturned"
}

# 1. A collapse: Fig. 8 case H (the quick start's). The capture starts with the replay's
#    noise-free lead-in: --stuck-samples 0 for the monitor, as docs/monitor.md says.
capture collapse 6.5
out=$("$plot" --scene "$scene" collapse/event-001.log -- --stuck-samples 0 2>&1)
rc=$?
check "collapse: exit 0" $rc "$out"
want=$(cat collapse.overturned)
got=$(printf '%s\n' "$out" | sed -n 's/.*collapse: overturned at t = \([0-9.]*\) s.*/\1/p')
awk -v a="$got" -v b="$want" 'BEGIN { exit !(a != "" && b != "" && (a - b) ^ 2 < 0.01 ^ 2) }'
check "collapse marked at the overturn ($want s in the capture): $got s" $?
[ "$(png_size collapse/event-001.png)" = 1100x1000 ]
check "collapse: collapse/event-001.png, 1100x1000" $? "$(png_size collapse/event-001.png)"

# 2. No collapse: the risk falls back, the all-clear is marked.
capture calm 4.5
out=$("$plot" --scene "$scene" calm/event-001.log --out calm.png -- --stuck-samples 0 2>&1)
rc=$?
[ $rc -eq 0 ] && [ -s calm.png ] && printf '%s\n' "$out" | grep -q "all clear at t = "
check "no collapse: the all-clear marked, calm.png written" $? "$out"
[ ! -s calm/collapse.overturned ] && ! printf '%s\n' "$out" | grep -q collapse
check "no collapse: none marked" $?

# 3. Hostile names: quotes, a newline, gnuplot's system() and shell substitutions, in the
#    folder, the capture's name and the output's name. They stay names.
#    Each payload, if run by a shell or gnuplot, would create $HIT-something in $tmp (no slash
#    in a file name: the path comes from the environment).
export HIT=$tmp/hit
evil_dir=$tmp/$'dir \' " `touch $HIT-dir`'
mkdir -p "$evil_dir"
evil=$evil_dir/$'a\'b"c\nsystem("touch $HIT-gp")\n!touch $HIT-bang\n$(touch $HIT-sh)\';x.log'
cp collapse/event-001.log "$evil"
evil_out=$evil_dir/$'out\'"\nset output "hit.png"\n!touch $HIT-out\n.png'
out=$("$plot" --scene "$scene" "$evil" --out "$evil_out" -- --stuck-samples 0 2>&1)
rc=$?
check "hostile names: exit 0" $rc "$out"
[ "$(png_size "$evil_out")" = 1100x1000 ]
check "hostile names: the PNG is at the hostile output path" $?
found=$(find "$tmp" -name 'hit*' 2>/dev/null)
[ -z "$found" ]
check "hostile names: no command ran (no hit* file)" $? "$found"

# 4. Bad inputs: a message naming the problem, exit 1 (2 for usage).
"$plot" --scene "$scene" missing/event-009.log >out.txt 2>&1
rc=$?
[ $rc -eq 1 ] && grep -q "capture 'missing/event-009.log': no such file" out.txt
check "a missing capture: exit 1, named" $? "exit $rc: $(cat out.txt)"
head -n 200 collapse/event-001.log >short.log
"$plot" --scene "$scene" short.log >out.txt 2>&1
rc=$?
[ $rc -eq 1 ] && grep -qE "never started|never ran" out.txt
check "a capture too short to start the estimators: exit 1, said" $? "exit $rc: $(cat out.txt)"
"$plot" collapse/event-001.log >out.txt 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q -- "--scene" out.txt
check "no --scene: usage, exit 2" $? "exit $rc: $(cat out.txt)"
"$monitor" --scene "$scene" --replay collapse/event-001.log --trace "$tmp/no/such/dir/t.tsv" \
  >/dev/null 2>out.txt
rc=$?
[ $rc -eq 1 ] && grep -q -- "--trace $tmp/no/such/dir/t.tsv: cannot create it" out.txt
check "plinth-monitor --trace into a missing folder: exit 1, named" $? "exit $rc: $(cat out.txt)"

finish
