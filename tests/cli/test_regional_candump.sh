#!/usr/bin/env bash
# Regional alerts over CAN, replayed from a candump log (docs/regional.md, "CAN"): plinth-replay
# writes a quiet record's sensor frames, the test inserts the bridge's frames (hex from the DBC,
# worked out in the comments), plinth-monitor replays the log. Checks: an alert frame without its
# origin frame is a malformed alert; the pair is accepted and raises warning, cause
# regional_alert, on the JSON lines and on the bus (AlarmEvent Cause 15); the status shows the
# alert and its S arrival; with the bridge's key, only a pair followed by its tag is taken, and a
# replayed tag is refused.
#
# Environment: PLINTH_MONITOR, PLINTH_REPLAY, PLINTH_SIM, PLINTH_SOURCE_DIR.
set -u
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/harness.sh"
BIN=${PLINTH_MONITOR:?}
REPLAY=${PLINTH_REPLAY:?}

cp "$SCENES/paper-isolated.toml" "$TMP/statue.toml"
printf '\n[fragility]\nmedian_g = 0.6\nbeta = 0.5\n' >>"$TMP/statue.toml"
"$REPLAY" --record "$AT2" --pga 0.05g --rate 200 --speed max --log "$TMP/quiet.log" >/dev/null
# Event 0x0042, version 1. RegionalAlertOrigin (0x361): EventId 42 00, Version 01, Magnitude
# 7.1 / 0.05 = 142 = 8E, OriginAge 5 s / 0.02 = 250 = FA 00, Distance 80 km = 0x050 and
# Cancelled 0 -> 50 00. RegionalAlert (0x360): EventId 42 00, Version 01, Pga 1.5 g / 0.0001 =
# 15000 = 98 3A, SigmaLn 0.6 / 0.01 = 60 = 3C, SArrivalIn 10 s / 0.01 = 1000 = E8 03.
ORIGIN=361#4200018EFA005000
ALERT=360#420001983A3CE803
# The alert frame alone at 15 s; the pair at 20 s (timestamps between their neighbours').
awk -v origin="$ORIGIN" -v alert="$ALERT" '
  NR == 1 { t0 = substr($1, 2, 17) + 0 }
  { t = substr($1, 2, 17) + 0 }
  !lone && t >= t0 + 15 { printf "(%.6f) %s %s\n", t - 0.0003, $2, alert; lone = 1 }
  !pair && t >= t0 + 20 {
    printf "(%.6f) %s %s\n(%.6f) %s %s\n", t - 0.0004, $2, origin, t - 0.0002, $2, alert; pair = 1
  }
  1' "$TMP/quiet.log" >"$TMP/alerts.log"

if expect_success "a log with regional alert frames replays" --scene "$TMP/statue.toml" \
  --replay "$TMP/alerts.log" --no-events --frames-out "$TMP/frames.log"; then
  if grep -q '"type": "regional", "result": "refused", "reason": "malformed", "field": "RegionalAlertOrigin"' "$TMP/stdout"; then
    pass "an alert frame without its origin frame is a malformed alert"
  else
    fail "lone alert frame" "$(grep '"type": "regional"' "$TMP/stdout" | head -n 1)"
  fi
  # P = Phi(ln(1.5 / 0.6) / sqrt(0.5^2 + 0.6^2)) = 0.8796
  if grep -q '"type": "regional", "result": "accepted".*"probability": 0.8796' "$TMP/stdout" &&
    grep -qE '"type": "alarm", "t": 19\.99[0-9]*, "level": "warning", "previous": "normal", "cause": "regional_alert"' "$TMP/stdout"; then
    pass "the pair is accepted and raises warning at 20 s, cause regional_alert"
  else
    fail "the pair" "$(grep -E '"type": "(regional|alarm)"' "$TMP/stdout" | tail -n 3)"
  fi
  # AlarmEvent: Level warning (2), PreviousLevel normal (0) -> byte 0 02; Cause 15 -> byte 1 0F.
  if grep -qE ' 330#020F' "$TMP/frames.log"; then
    pass "the bus's AlarmEvent says warning, cause 15 (regional_alert)"
  else
    fail "AlarmEvent on the bus" "$(grep ' 330#' "$TMP/frames.log" | head -n 3)"
  fi
  status=$(grep '"type": "status"' "$TMP/stdout" | grep '"held": 1' | head -n 1)
  if [[ "$status" == *'"event_id": 66, "version": 1, "magnitude": 7.10, "distance_km": 80.0, "pga_g": 1.5000, "sigma_ln": 0.60'* &&
    "$status" == *'"s_arrival_t": 30.000'* && "$status" == *'"malformed": 1'* ]]; then
    pass "the status shows the alert, its S arrival at 30 s and the malformed one counted"
  else
    fail "status" "$(grep -o '"regional": {[^}]*' <<<"$status")"
  fi
fi

# Signed alerts (regional_alert.key_file): each pair must be followed by its RegionalAlertTag
# (0x362: Counter, then the first 4 bytes of HMAC-SHA256(key, origin data, alert data, Counter
# bytes)). An unsigned pair at 15 s (refused when the next origin comes), the signed triple at
# 20 s (taken), the same triple replayed at 25 s (its Counter not above the last: refused).
KEY=000102030405060708090a0b0c0d0e0f101112131415161718191a1b1c1d1e1f
echo "$KEY" >"$TMP/bridge.key"
printf '[regional_alert]\nkey_file = "bridge.key"\n' >"$TMP/signed.toml"
TAG=$(python3 -c 'import hmac, hashlib, sys
key, origin, alert = (bytes.fromhex(a) for a in sys.argv[1:4])
counter = (7).to_bytes(4, "little")
tag = hmac.new(key, origin + alert + counter, hashlib.sha256).digest()[:4]
print("362#" + (counter + tag).hex().upper())' \
  "$KEY" "${ORIGIN#*#}" "${ALERT#*#}")
awk -v origin="$ORIGIN" -v alert="$ALERT" -v tag="$TAG" '
  NR == 1 { t0 = substr($1, 2, 17) + 0 }
  { t = substr($1, 2, 17) + 0 }
  function triple(signed) {
    printf "(%.6f) %s %s\n(%.6f) %s %s\n", t - 0.0004, $2, origin, t - 0.0003, $2, alert
    if (signed) printf "(%.6f) %s %s\n", t - 0.0002, $2, tag
  }
  !a && t >= t0 + 15 { triple(0); a = 1 }
  !b && t >= t0 + 20 { triple(1); b = 1 }
  !c && t >= t0 + 25 { triple(1); c = 1 }
  1' "$TMP/quiet.log" >"$TMP/signed.log"
if expect_success "a log with signed regional alerts replays" --scene "$TMP/statue.toml" \
  --replay "$TMP/signed.log" --no-events --config "$TMP/signed.toml"; then
  problem=$(python3 - "$TMP/stdout" 2>&1 <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
got = [(l["result"], l.get("reason"), l.get("field")) for l in lines if l["type"] == "regional"]
assert got == [("refused", "unauthenticated", "RegionalAlertTag"), ("accepted", None, None),
               ("refused", "unauthenticated", "Counter")], got
warning = [l for l in lines if l["type"] == "alarm" and l["level"] == "warning"]
assert warning and warning[0]["cause"] == "regional_alert", warning
assert 19.9 < warning[0]["t"] < 20.1, warning
frames = lines[-1]["frames"]
assert frames["regional_tags"] == 2 and frames["regional_unauthenticated"] == 2, frames
PY
)
  if [[ -z "$problem" ]]; then
    pass "with a key: an unsigned pair refused, the signed triple taken, its replay refused"
  else
    fail "signed alerts" "$problem"
  fi
fi

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
