#!/usr/bin/env bash
# Acknowledge frames from the bus are unauthenticated (docs/monitor.md, "Who may acknowledge"):
# the sweep issue 33 met, one Acknowledge for each of the 256 sequence numbers (the right one
# last), after the statue overturned and latched the alarm. Checks: the latch holds (4 refused,
# then the bus locked out while the alarm stays latched), the refused ones leave command lines,
# at most 5 of them in the burst, the next saying how many were not shown, a line on stderr at
# the lockout, and the summary's frame counters.
#
# Environment: PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_SIM, PLINTH_SOURCE_DIR.
set -u
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
BIN=${PLINTH_MONITOR:?}
REPLAY=${PLINTH_REPLAY:?}

# The non-isolated block (b/h = 1/3) pushed by 0.6 g for 1 s after 4 s of quiet: it overturns,
# the alarm latched. The sweep from 20 s, one frame between two sensor frames (1.3 s in all),
# sequence 255 first: the alarm events' sequences are small, the right one comes last.
# Acknowledge (0x340): Level alarm 3, SourceId 9, EventSequence -> 03 09 SS.
python3 -c 'print("t,a [g]")
for n in range(30 * 200):
    print("%.3f,%s" % (n * 0.005, "0.6" if 800 <= n < 1000 else "0"))' >"$TMP/push.csv"
"$REPLAY" --record "$TMP/push.csv" --rate 200 --speed max --log "$TMP/quake.log" >/dev/null
awk '
  NR == 1 { t0 = substr($1, 2, 17) + 0 }
  { t = substr($1, 2, 17) + 0 }
  t >= t0 + 20 && k < 256 && t > previous + 0.0002 {
    printf "(%.6f) %s 340#0309%02X0000000000\n", (previous + t) / 2, $2, 255 - k++
  }
  { previous = t }
  1' "$TMP/quake.log" >"$TMP/sweep.log"
if expect_success "a log with an acknowledgement sweep replays" \
  --scene "$SCENES/non-isolated.toml" --replay "$TMP/sweep.log" --no-events --stuck-samples 0; then
  problem=$(python3 - "$TMP/stdout" "$TMP/stderr" 2>&1 <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
alarms = [l for l in lines if l["type"] == "alarm"]
assert any(a["level"] == "alarm" and a["latched"] for a in alarms), "no latched alarm"
assert not any(a["cause"] == "acknowledged" for a in alarms), "the sweep released the latch"
last = [l for l in lines if l["type"] == "status"][-1]
assert last["latched"] == "alarm", last["latched"]
commands = [l for l in lines if l["type"] == "command"]
assert all(c["source"] == "can" and c["source_id"] == 9 for c in commands), commands[:2]
assert 1 <= len(commands) <= 5, "%d command lines for the sweep" % len(commands)
assert [c["outcome"] for c in commands[:4]] == ["stale sequence"] * 4, commands[:4]
assert commands[3].get("locks_out_the_bus") is True, commands[3]
frames = lines[-1]["frames"]
assert frames["acknowledgements"] == 256 and frames["acknowledgements_refused"] == 4, frames
assert frames["acknowledgements_ignored"] == 252 and frames["acknowledgement_lockouts"] == 1, frames
err = open(sys.argv[2]).read()
assert "4 acknowledgements refused within 60 s: the bus's are ignored while alarm stays latched" \
    in err, err
PY
)
  if [[ -z "$problem" ]]; then
    pass "a sweep of the 256 sequences leaves the alarm latched: 4 refused, 252 ignored"
  else
    fail "acknowledgement sweep" "$problem"
  fi
fi

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
