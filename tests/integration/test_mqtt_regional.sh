#!/usr/bin/env bash
# Regional alerts over MQTT (docs/regional.md): a bridge's alerts published to a real mosquitto
# broker that this test starts on loopback, taken by plinth-monitor replaying a quiet record in
# real time for a statue whose scene gives its [fragility]. Checks: a malformed payload, values
# out of range, a future-dated and a stale alert are refused with their reason and counted; a
# dangerous alert raises `warning` with cause regional_alert (never alarm) and the state shows
# its time to the S arrival counting down; a duplicate and an older version are refused, a later
# version replaces it; a short alert expires; a box without mqtt.regional_alerts ignores the
# topic; the summary counts what came. Hostile (docs/regional.md, "Who may send an alert"): a
# burst of 5,000 messages (malformed ones, harmless alerts, four spoofed events at version 255)
# with the bridge's real alert of a spoofed event inside: the real alert is taken and raises
# warning, the lines about the burst stay few; with regional_alert.key_file, an alert without
# the bridge's HMAC or with a wrong one is refused as unauthenticated, a signed one taken and its
# replay refused.
#
# Environment: PLINTH_MONITOR, PLINTH_SIM, PLINTH_SOURCE_DIR. Exit 77 (skip) when mosquitto or
# its clients are missing, unless CI=true.
set -u

# shellcheck source=tests/integration/outputs_harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/outputs_harness.sh"
require_tools mosquitto mosquitto_sub mosquitto_pub
MOSQUITTO=$(command -v mosquitto || echo /usr/sbin/mosquitto)
broker_cleanup_at_exit

PORT=$(free_port)
# The broker queues the whole burst for a box that falls behind (mosquitto drops beyond 1,000
# by default: the rig's loss, not the box's).
printf 'listener %s 127.0.0.1\nallow_anonymous true\nmax_queued_messages 10000\n' "$PORT" \
  >"$TMP/broker.conf"
"$MOSQUITTO" -c "$TMP/broker.conf" >"$TMP/broker.log" 2>&1 &
BROKER_PID=$!
for ((i = 0; i < 100; i++)); do
  mosquitto_pub -h 127.0.0.1 -p "$PORT" -t ping -m x 2>/dev/null && break
  sleep 0.1
done

# The statue: the paper's isolated block, fragile at 0.6 g median (beta 0.5).
cp "$SCENES/paper-isolated.toml" "$TMP/statue.toml"
printf '\n[fragility]\nmedian_g = 0.6\nbeta = 0.5\n' >>"$TMP/statue.toml"
TOPIC=plinth/regional_alert
PUB=(mosquitto_pub -h 127.0.0.1 -p "$PORT" -q 1 -t "$TOPIC")

# alert ID VERSION PGA ORIGIN_IN S_ARRIVAL_IN [EXTRA]: the JSON of an M 7.1 at 80 km, times from now.
alert() {
  python3 - "$@" <<'EOF'
import json, sys, time
now = time.time()
a = {"event_id": int(sys.argv[1]), "version": int(sys.argv[2]), "magnitude": 7.1,
     "origin_time": now + float(sys.argv[4]), "distance_km": 80.0, "pga_g": float(sys.argv[3]),
     "sigma_ln": 0.6, "s_arrival_time": now + float(sys.argv[5])}
a.update(json.loads(sys.argv[6]) if len(sys.argv) > 6 else {})
print(json.dumps(a))
EOF
}

# box NAME [KEY = VALUE lines]: the box on the broker, Brienza unscaled (quiet for this statue)
# at 0.7 x real time (50 s: the checks on a loaded machine end before the record does); its
# lines in $TMP/NAME.out.
box() {
  local name=$1
  shift
  printf '[mqtt]\nbroker = "127.0.0.1:%s"\nbox_id = "%s"\nstate_interval_s = 0.2\n' "$PORT" \
    "$name" >"$TMP/$name.toml"
  printf '%s\n' "$@" >>"$TMP/$name.toml"
  "$BIN" --scene "$TMP/statue.toml" --replay "$AT2" --speed 0.7 --no-events \
    --config "$TMP/$name.toml" >"$TMP/$name.out" 2>"$TMP/$name.err" &
  BOX=$!
  wait_for "$TMP/$name.out" '"calibrated": true' 30  # else the fault level hides a warning
}

# --- A box that takes regional alerts.
mosquitto_sub -h 127.0.0.1 -p "$PORT" -v -t 'plinth/regional/state' >"$TMP/state.out" 2>&1 &
box regional 'regional_alerts = true' '[regional_alert]' 'expiry_margin_s = 1.0'
sleep 1  # subscribed

"${PUB[@]}" -m 'not json'
"${PUB[@]}" -m "$(alert 1 1 12.0 -5 20)"                          # PGA 12 g
"${PUB[@]}" -m "$(alert 2 1 0.5 60 80)"                           # origin a minute ahead
"${PUB[@]}" -m "$(alert 3 1 0.5 -1000 -970)"                      # long past
"${PUB[@]}" -m "$(alert 4 1 0.5 -5 20 '{"depth_km": 10}')"        # unknown member
if wait_for "$TMP/regional.out" '"reason": "stale"' 10; then
  sleep 1  # the unknown member's, published after
  refused=$(grep -c '"type": "regional", "result": "refused"' "$TMP/regional.out")
  if ((refused == 5)) &&
    grep -q '"reason": "malformed", "field": "payload"' "$TMP/regional.out" &&
    grep -q '"reason": "out of range", "field": "pga_g"' "$TMP/regional.out" &&
    grep -q '"reason": "future-dated", "field": "origin_age_s"' "$TMP/regional.out" &&
    grep -q '"reason": "stale", "field": "origin_age_s"' "$TMP/regional.out"; then
    pass "regional: malformed, out of range, future-dated, stale and unknown-member alerts refused with their reason"
  else
    fail "regional: refusals" "$(grep '"type": "regional"' "$TMP/regional.out" | head -n 6)"
  fi
else
  fail "regional: refusals" "no refusal line; $(tail -n 3 "$TMP/regional.err")"
fi
RISEN='"type": "alarm".*"level": "(advisory|warning|alarm)"'  # not the start-up fault
if grep -qE "$RISEN" "$TMP/regional.out"; then
  fail "regional: a refused alert raises nothing" "$(grep -E "$RISEN" "$TMP/regional.out")"
else
  pass "regional: a refused alert raises nothing"
fi

# A dangerous alert: 1.5 g expected, S in 20 s: P = Phi(ln(1.5/0.6)/sqrt(0.25 + 0.36)) = 0.88.
"${PUB[@]}" -m "$(alert 42 1 1.5 -5 20)"
if wait_for "$TMP/regional.out" '"type": "alarm".*"level": "warning".*"cause": "regional_alert"' 10; then
  pass "regional: a dangerous alert raises warning, cause regional_alert"
else
  fail "regional: warning" "$(grep -E '"type": "(alarm|regional)"' "$TMP/regional.out" | tail -n 3)"
fi
if grep -q '"level": "alarm"' "$TMP/regional.out"; then
  fail "regional: never alarm" "$(grep '"level": "alarm"' "$TMP/regional.out" | head -n 1)"
else
  pass "regional: never alarm"
fi
sleep 1.5
# The state: the alert and its time to the S arrival, counting down.
python3 - "$TMP/state.out" <<'EOF' && pass "regional: the MQTT state shows the alert and its time to arrival, counting down" || fail "regional: state" "$(tail -n 1 "$TMP/state.out" | cut -c 1-300)"
import json, sys
times = []
for line in open(sys.argv[1]):
    topic, _, payload = line.partition(" ")
    r = json.loads(payload).get("regional")
    if r and r["alert"] and r["alert"]["event_id"] == 42:
        a = r["alert"]
        assert a["pga_g"] == 1.5 and abs(a["probability"] - 0.8797) < 1e-3, a
        times.append(a["time_to_s_arrival_s"])
assert len(times) >= 3 and times[-1] < times[0] and 10 < times[-1] < 20, times
EOF

"${PUB[@]}" -m "$(alert 42 1 1.5 -5 20)"  # the same version again
"${PUB[@]}" -m "$(alert 42 0 1.5 -5 20)"  # an older one
"${PUB[@]}" -m "$(alert 42 2 0.05 -6 19)"  # the update: smaller
if wait_for "$TMP/regional.out" '"result": "accepted", "replaced": true' 10 &&
  grep -q '"reason": "duplicate", "field": "version"' "$TMP/regional.out" &&
  grep -q '"reason": "out of order", "field": "version"' "$TMP/regional.out"; then
  pass "regional: a duplicate and an older version refused, a later version replaces"
else
  fail "regional: versions" "$(grep '"type": "regional"' "$TMP/regional.out" | tail -n 3)"
fi
# The warning stays latched (acknowledged by an operator); the status shows version 2.
if wait_for "$TMP/regional.out" '"regional": \{"held": 1, "event_id": 42, "version": 2' 5; then
  pass "regional: the status line shows the replacing version"
else
  fail "regional: status line" "$(grep -o '"regional": {[^}]*' "$TMP/regional.out" | tail -n 1)"
fi

# A short alert expires after its S arrival, the shaking (M 4: 0.3 s at 80 km + 4 s) and the
# box's 1 s margin; event 42 (S in ~17 s) is still held meanwhile.
"${PUB[@]}" -m "$(alert 43 1 0.01 -2 1 '{"magnitude": 4.0}')"
if wait_for "$TMP/regional.out" '"held": 1, .*"expired": 1' 25; then
  pass "regional: a short alert expires after its S arrival and shaking"
else
  fail "regional: expiry" "$(grep -o '"regional": {.*' "$TMP/regional.out" | tail -n 1 | cut -c 1-300)"
fi
kill -INT "$BOX"
wait "$BOX" 2>/dev/null
BOX=
summary=$(grep '"type": "summary"' "$TMP/regional.out")
if [[ "$summary" == *'"regional_received": 10'* && "$summary" == *'"regional_malformed": 2'* ]]; then
  pass "regional: the summary counts the messages (10, 2 malformed)"
else
  fail "regional: summary" "$(grep -o '"mqtt": {[^}]*}' <<<"$summary")"
fi

# --- A burst: 5,000 messages at once (mosquitto_pub -l, one a line): a fifth not JSON, four
#     spoofed events at version 255 (ids 700-703, harmless), harmless alerts, and in the middle
#     the bridge's real alert of event 701, version 1, dangerous.
python3 - >"$TMP/burst.txt" <<'EOF'
import json, time
now = time.time()
def alert(event, version, pga):
    return json.dumps({"event_id": event, "version": version, "magnitude": 7.1,
                       "origin_time": now - 5, "distance_km": 80.0, "pga_g": pga,
                       "sigma_ln": 0.6, "s_arrival_time": now + 25})
lines = [alert(700 + k, 255, 0.01) for k in range(4)]
for i in range(4996):
    if i == 2501:
        lines.append(alert(701, 1, 1.5))
    elif i % 5 == 0:
        lines.append("not json %d \x1b[31m" % i)
    else:
        lines.append(alert(1000 + i, 1, 0.01))
print("\n".join(lines))
EOF
box burst 'regional_alerts = true'
sleep 1
mosquitto_pub -h 127.0.0.1 -p "$PORT" -q 1 -t "$TOPIC" -l <"$TMP/burst.txt"
wait_for "$TMP/burst.out" '"type": "alarm".*"level": "warning".*"cause": "regional_alert"' 20
# The broker may still be delivering the burst (QoS 1) on a loaded machine: stop once the
# alerts the loop has taken stop growing for 3 s (at most 60 s).
last=-1 still=0
for _ in $(seq 60); do
  now=$(grep -o '"regional": {[^}]*"received": [0-9]*' "$TMP/burst.out" | tail -n 1 |
    grep -o '[0-9]*$' || echo 0)
  if [[ "$now" == "$last" ]]; then still=$((still + 1)); else still=0; fi
  ((still >= 3)) && break
  last=$now
  sleep 1
done
kill -INT "$BOX"
wait "$BOX" 2>/dev/null
BOX=
problem=$(python3 - "$TMP/burst.out" "$TMP/burst.err" 2>&1 <<'EOF'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
warnings = [l for l in lines if l["type"] == "alarm" and l["level"] == "warning"]
assert warnings and warnings[0]["cause"] == "regional_alert", "no warning"
regional = [l for l in lines if l["type"] == "status" and "regional" in l][-1]["regional"]
assert regional["event_id"] == 701 and regional["version"] == 1, regional
mqtt = lines[-1]["mqtt"]
assert mqtt["regional_received"] == 5000, mqtt
assert mqtt["regional_malformed"] == 1000, mqtt
err = open(sys.argv[2], "rb").read()
said = [l for l in err.splitlines() if b"regional alert" in l]
assert 1 <= len(said) <= 20, "%d lines about the burst" % len(said)
assert b"\x1b" not in err, "an escape reached stderr"
print("burst: %d received, %d dropped in the burst, %d lines about it" %
      (mqtt["regional_received"], mqtt["regional_lost"], len(said)), file=sys.stderr)
EOF
)
if [[ "$problem" == burst:* || -z "$problem" ]]; then
  pass "regional: in a burst of 5,000 the bridge's real alert of a spoofed event raises\
 warning (${problem#burst: })"
else
  fail "regional: burst" "$problem"
fi

# --- Authenticated alerts: the box holds the bridge's key (regional_alert.key_file); an alert
#     must carry the HMAC-SHA256 of its payload in the MQTT 5 user property hmac-sha256.
KEY=000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f
echo "$KEY" >"$TMP/bridge.key"
hmac() { python3 -c 'import hmac, hashlib, sys
print(hmac.new(bytes.fromhex(sys.argv[1]), sys.argv[2].encode(), hashlib.sha256).hexdigest())' \
  "$1" "$2"; }
box signed 'regional_alerts = true' '[regional_alert]' "key_file = \"$TMP/bridge.key\""
sleep 1
SIGNED=(mosquitto_pub -h 127.0.0.1 -p "$PORT" -V mqttv5 -q 1 -t "$TOPIC")
unsigned=$(alert 60 1 1.5 -5 20)
"${PUB[@]}" -m "$unsigned"
"${SIGNED[@]}" -D publish user-property hmac-sha256 "$(hmac "ff${KEY:2}" "$unsigned")" \
  -m "$unsigned"
for ((i = 0; i < 100; i++)); do
  (($(grep -c '"reason": "unauthenticated"' "$TMP/signed.out") >= 2)) && break
  sleep 0.1
done
good=$(alert 61 1 1.5 -5 20)
"${SIGNED[@]}" -D publish user-property hmac-sha256 "$(hmac "$KEY" "$good")" -m "$good"
wait_for "$TMP/signed.out" '"type": "alarm".*"level": "warning".*"cause": "regional_alert"' 10
"${SIGNED[@]}" -D publish user-property hmac-sha256 "$(hmac "$KEY" "$good")" -m "$good"  # replayed
sleep 1.5
kill -INT "$BOX"
wait "$BOX" 2>/dev/null
BOX=
problem=$(python3 - "$TMP/signed.out" 2>&1 <<'EOF'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
regional = [l for l in lines if l["type"] == "regional"]
outcomes = [(r["result"], r.get("reason"), r.get("field")) for r in regional]
assert outcomes == [("refused", "unauthenticated", "hmac-sha256")] * 2 + [
    ("accepted", None, None), ("refused", "duplicate", "version")], outcomes
warnings = [l for l in lines if l["type"] == "alarm" and l["level"] == "warning"]
assert len(warnings) == 1 and warnings[0]["cause"] == "regional_alert", warnings
mqtt = lines[-1]["mqtt"]
assert mqtt["regional_unauthenticated"] == 2, mqtt
EOF
)
if [[ -z "$problem" ]]; then
  pass "regional: with a key, unsigned and wrongly signed alerts refused as unauthenticated,\
 a signed one taken, its replay a duplicate"
else
  fail "regional: authenticated" "$problem"
fi

# --- A box without mqtt.regional_alerts ignores the topic.
box quiet
sleep 1
"${PUB[@]}" -m "$(alert 50 1 1.5 -5 20)"
sleep 2
kill -INT "$BOX"
wait "$BOX" 2>/dev/null
BOX=
if grep -qE "\"type\": \"regional\"|$RISEN" "$TMP/quiet.out"; then
  fail "regional: off by default" "$(grep -E "\"type\": \"regional\"|$RISEN" "$TMP/quiet.out" | head -n 1)"
else
  pass "regional: a box without mqtt.regional_alerts ignores the topic"
fi

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
