#!/usr/bin/env bash
# plinth-monitor's MQTT publisher against a real mosquitto broker that this test starts on
# loopback with its own configuration (docs/integration.md): a password file, a plain and a TLS
# listener (a CA and a server certificate made here with openssl), persistence. Checks: every
# alarm line arrives on the events topic, in order, across a broker restart in the middle of a
# replay; the retained state and availability; the acknowledge command (an ACL lets only the
# operator publish it; replies accepted or refused with the reason); Home Assistant discovery,
# on and off; the state's forecast, counters, version and the digests of the scene and box files
# (as sha256sum prints them; null for a file not given); the Last Will when the box is killed
# (-9); a wrong password refused with a clear message; bad settings refused naming the key or
# flag. What each surface trusts (docs/integration.md): a retained acknowledgement is never
# carried out (neither one stored on the broker before the box connects nor one published
# retained while it runs), duplicate members and forged log lines are refused and escaped, a
# client that takes the box's client id (read from the broker's log) is noticed and counted,
# and topics that would mix with the box's own are refused.
#
# Environment: PLINTH_MONITOR, PLINTH_SIM, PLINTH_SOURCE_DIR. Exit 77 (skip) when mosquitto,
# its clients or openssl are missing, unless CI=true.
set -u

# shellcheck source=tests/integration/outputs_harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/outputs_harness.sh"
require_tools mosquitto mosquitto_sub mosquitto_pub mosquitto_passwd openssl
MOSQUITTO=$(command -v mosquitto || echo /usr/sbin/mosquitto)
ISOLATED=$SCENES/paper-isolated.toml
ECCENTRIC=$SCENES/paper-eccentric.toml
sha() { sha256sum "$1" | cut -d' ' -f1; }
broker_cleanup_at_exit

# The broker: users "box" and "watcher", a plain listener and a TLS one.
PLAIN=$(free_port)
TLS=$(free_port)
mkdir -p "$TMP/db"
openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2 \
  -subj "/CN=plinth test CA" -keyout "$TMP/ca.key" -out "$TMP/ca.crt" 2>/dev/null
openssl req -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -subj "/CN=localhost" \
  -keyout "$TMP/server.key" -out "$TMP/server.csr" 2>/dev/null
printf 'subjectAltName=IP:127.0.0.1,DNS:localhost\n' >"$TMP/server.ext"
openssl x509 -req -in "$TMP/server.csr" -CA "$TMP/ca.crt" -CAkey "$TMP/ca.key" -CAcreateserial \
  -days 2 -extfile "$TMP/server.ext" -out "$TMP/server.crt" 2>/dev/null
mosquitto_passwd -c -b "$TMP/passwd" box box-secret 2>/dev/null
mosquitto_passwd -b "$TMP/passwd" watcher watcher-secret 2>/dev/null
mosquitto_passwd -b "$TMP/passwd" operator operator-secret 2>/dev/null
# Who may do what: the box publishes its topics and reads its commands; the watcher only reads;
# the operator alone may publish a command (MQTT does not tell the box who published).
cat >"$TMP/acl" <<EOF
user box
topic readwrite plinth/#
topic write homeassistant/#
user watcher
topic read plinth/#
topic read homeassistant/#
user operator
topic write plinth/+/command
topic read plinth/+/command/reply
EOF
echo box-secret >"$TMP/box.pw"
echo wrong >"$TMP/wrong.pw"
cat >"$TMP/broker.conf" <<EOF
user root
persistence true
persistence_location $TMP/db/
allow_anonymous false
password_file $TMP/passwd
acl_file $TMP/acl
listener $PLAIN 127.0.0.1
listener $TLS 127.0.0.1
cafile $TMP/ca.crt
certfile $TMP/server.crt
keyfile $TMP/server.key
EOF
start_broker() {
  "$MOSQUITTO" -c "$TMP/broker.conf" >>"$TMP/broker.log" 2>&1 &
  BROKER_PID=$!
  local i
  for ((i = 0; i < 100; i++)); do
    mosquitto_pub -h 127.0.0.1 -p "$PLAIN" -u watcher -P watcher-secret -t ping -m x \
      2>/dev/null && return 0
    sleep 0.1
  done
  return 1
}
stop_broker() {
  kill "$BROKER_PID" 2>/dev/null
  wait "$BROKER_PID" 2>/dev/null
  BROKER_PID=
}
WATCH=(-h 127.0.0.1 -p "$PLAIN" -u watcher -P watcher-secret)
if ! start_broker; then
  fail "mqtt: the broker starts" "$(tail -n 3 "$TMP/broker.log")"
  echo "$PASSED passed, $FAILED failed"
  exit 1
fi

# restart_replay BOX_ID [KEY = VALUE lines]: Brienza x20 at --speed 2 through a box on the TLS
# listener with a password; the broker stops once the normal event reached the subscriber and
# starts again after the alarm, so the advisory, warning and alarm events happen while it is
# away. On a loaded machine the subscriber can run seconds behind the box (whose replay keeps
# to the wall clock), and the advisory may reach the broker before it stops: the scenario did
# not happen, and is run again (up to 3 times) rather than judged. A persistent subscriber
# takes the events topic. Sets rc; leaves $TMP/box.out, box.err and events.out.
restart_replay() {
  local box=$1 attempt
  shift
  printf '[mqtt]\nbroker = "127.0.0.1:%s"\nbox_id = "%s"\nusername = "box"\n' "$TLS" "$box" \
    >"$TMP/box.toml"
  printf '%s\n' 'password_file = "box.pw"' 'tls_ca_file = "ca.crt"' 'reconnect_min_s = 0.1' \
    'reconnect_max_s = 0.5' 'state_interval_s = 0.2' "$@" >>"$TMP/box.toml"
  for attempt in 1 2 3; do
    fresh "$TMP/events.out" "$TMP/box.out"
    mosquitto_sub "${WATCH[@]}" -c -i "watcher-$box-$attempt" -q 1 -v -t "plinth/$box/events" \
      >"$TMP/events.out" 2>"$TMP/events.err" &
    local watcher=$!
    sleep 1
    "$BIN" --scene "$ISOLATED" --replay "$AT2" --scale 20 --speed 2 --no-events \
      --config "$TMP/box.toml" --record-dir "$TMP/captures-$box" >"$TMP/box.out" \
      2>"$TMP/box.err" &
    BOX=$!
    local happened=1
    if wait_for "$TMP/events.out" '"level": "normal"' 30; then
      stop_broker
      grep -qE '"level": "(advisory|warning|alarm)"' "$TMP/events.out" && happened=0
      wait_for "$TMP/box.out" '"level": "alarm", "previous"' 30
      sleep 1
      start_broker || fail "mqtt: the broker starts again" "$(tail -n 3 "$TMP/broker.log")"
    else
      fail "mqtt: replay" "no normal level within 30 s"
    fi
    wait "$BOX"
    rc=$?
    BOX=
    sleep 2
    kill "$watcher" 2>/dev/null
    wait "$watcher" 2>/dev/null
    ((happened)) && return
    echo "# mqtt: $box: the advisory reached the broker before it stopped (attempt $attempt)"
  done
}

# check_events PYTHON: the alarm lines of box.out (alarms), the payloads received (received,
# an event repeated at once counted once: QoS 1 delivers at least once, and an event whose
# acknowledgement the broker's stop cut off is sent again) and the summary's mqtt object
# (mqtt); prints the failed assertion.
check_events() {
  python3 - "$TMP/box.out" "$TMP/events.out" "$1" 2>&1 <<'PY'
import json, sys
lines = open(sys.argv[1]).read().splitlines()
alarms = [l for l in lines if l.startswith('{"type": "alarm"')]
payloads = [l.split(" ", 1)[1] for l in open(sys.argv[2]).read().splitlines()]
received = [p for i, p in enumerate(payloads) if i == 0 or p != payloads[i - 1]]
mqtt = json.loads(lines[-1])["mqtt"]
seq = lambda ls: [json.loads(l)["sequence"] for l in ls]
try:
    assert len(alarms) >= 4, "the replay gave %d alarm lines" % len(alarms)
    exec(sys.argv[3])
except AssertionError as e:
    print(str(e) or "an assertion without a message failed")
PY
}

# 1. Every alarm line arrives, in order, across the broker restart.
restart_replay b1
problem=$(check_events '
assert received == alarms, "received events %s, the box wrote %s" % (seq(received), seq(alarms))
assert mqtt["connects"] >= 2 and mqtt["connections_lost"] >= 1, mqtt
assert mqtt["events_published"] == len(alarms) and mqtt["events_dropped"] == 0, mqtt
assert mqtt["most_queued"] >= 2, mqtt
')
if ((rc == 0)) && [[ -z "$problem" ]]; then
  pass "mqtt: TLS, password; every alarm line arrives in order across a broker restart"
else
  fail "mqtt: broker restart" "exit $rc; $problem; stderr: $(head -c 300 "$TMP/box.err")"
fi
if grep -q "lost" "$TMP/box.err" && grep -q "connected to 127.0.0.1:$TLS" "$TMP/box.err"; then
  pass "mqtt: the lost connection and the reconnection are reported"
else
  fail "mqtt: reconnect messages" "$(head -c 300 "$TMP/box.err")"
fi
mosquitto_sub "${WATCH[@]}" -C 2 -W 5 -v -t plinth/b1/state -t plinth/b1/availability \
  >"$TMP/retained.out" 2>&1
problem=$(python3 - "$TMP/retained.out" "$TMP/box.out" 2>&1 <<'PY'
import json, sys
got = dict(l.split(" ", 1) for l in open(sys.argv[1]).read().splitlines())
assert got.get("plinth/b1/availability") == "offline", got
state = json.loads(got["plinth/b1/state"])
status = [json.loads(l) for l in open(sys.argv[2]) if l.startswith('{"type": "status"')][-1]
alarm = [json.loads(l) for l in open(sys.argv[2]) if l.startswith('{"type": "alarm"')][-1]
assert state["box"] == "b1" and state["level"] == status["alarm"] == "alarm", state
assert state["latched"] == "alarm" and state["cause"] == alarm["cause"], (state, alarm)
assert state["phase"] == {"x": status["phase"]} and state["risk"] == status["risk"], state
assert state["time"].endswith("Z") and abs(state["t"] - status["t"]) < 0.2, state
recorder = state["recorder"]  # the event recorder's health, as the status lines'
assert (recorder["health"], recorder["problem"]) == ("ok", "none"), state
assert set(recorder) == set(status["recorder"]), (recorder, status["recorder"])
PY
)
if [[ -z "$problem" ]]; then pass "mqtt: the retained state is the last status; offline after a clean stop"
else fail "mqtt: retained state" "$problem"; fi

# 1b. A queue of 1: of the events held while the broker is away (two: the warning may be skipped
#     on the way to the alarm), the oldest is dropped and counted; the others arrive in order.
#     The start-up's two faults (sensor_timeout, not_calibrated) may come before the first
#     connection: the first of them is then dropped too.
restart_replay b4 'event_queue = 1'
problem=$(check_events '
s = seq(alarms)
normal = next(i for i, l in enumerate(alarms) if "\"level\": \"normal\"" in l)
startup = s[:normal + 1] if seq(received)[0] == s[0] else s[1:normal + 1]
assert seq(received) == startup + s[normal + 2:], "received %s of %s" % (seq(received), s)
dropped = len(alarms) - len(received)
assert mqtt["events_dropped"] == dropped and mqtt["events_published"] == len(received), mqtt
assert mqtt["most_queued"] == 1, mqtt
')
if ! grep -q 'alarm event queue full (mqtt.event_queue = 1, .*): the oldest waiting event dropped, 1 so far' \
  "$TMP/box.err"; then
  problem="${problem}the overflow was not said on stderr: $(head -c 300 "$TMP/box.err")"
fi
if ((rc == 0)) && [[ -z "$problem" ]]; then
  pass "mqtt: a full queue drops its oldest event, counts it and says so"
else
  fail "mqtt: bounded queue" "exit $rc; $problem"
fi

# 1c. A broker certificate the box's CA did not sign: refused, with OpenSSL's reason.
openssl req -x509 -newkey ec -pkeyopt ec_paramgen_curve:prime256v1 -nodes -days 2 \
  -subj "/CN=another CA" -keyout "$TMP/other.key" -out "$TMP/other.crt" 2>/dev/null
expect_success "mqtt: a broker certificate from another CA does not stop the box" \
  --scene "$ISOLATED" --replay "$AT2" --no-events --mqtt "127.0.0.1:$TLS" --mqtt-box-id b5 \
  --mqtt-username box --mqtt-password-file "$TMP/box.pw" --mqtt-ca "$TMP/other.crt" && true
if grep -qi "certificate verify failed" "$TMP/stderr"; then
  pass "mqtt: the certificate is refused with OpenSSL's reason"
else
  fail "mqtt: wrong CA" "stderr: $(head -c 300 "$TMP/stderr")"
fi

# 1d. Commands and Home Assistant discovery (plain listener): after the overturn the watcher's
#     acknowledgement is refused by the broker's ACL (MQTT v5 tells the publisher: Not
#     authorized) and never reaches the box; the operator's malformed, wrong-level and stale
#     ones are refused with the reason, the last one accepted (the latch released); the
#     discovery configs are retained, the state carries the forecast, counters, version and
#     digests (the scene's and the box file's; no second scene: null). An acknowledgement
#     stored retained before the box starts never reaches it; one published retained while it
#     runs, one with a member given twice and one forging log lines are refused, and none of
#     them releases the latch.
OPERATOR=(-h 127.0.0.1 -p "$PLAIN" -u operator -P operator-secret)
printf '[mqtt]\nbroker = "127.0.0.1:%s"\nbox_id = "b6"\nusername = "box"\n' "$PLAIN" >"$TMP/box.toml"
printf '%s\n' 'password_file = "box.pw"' 'state_interval_s = 0.2' 'commands = true' >>"$TMP/box.toml"
DIGESTS=("$(sha "$ISOLATED")" "$(sha "$TMP/box.toml")")
# The section before left an overturn in box.out: a wait on it must see this run's lines only.
fresh "$TMP/replies.out" "$TMP/box.out"
# A retained acknowledgement waits on the broker before the box connects.
mosquitto_pub "${OPERATOR[@]}" -q 1 -r -t plinth/b6/command \
  -m '{"command": "acknowledge", "id": "stored-retained"}'
mosquitto_sub "${OPERATOR[@]}" -q 1 -t plinth/b6/command/reply >"$TMP/replies.out" 2>&1 &
REPLIES=$!
sleep 0.5
# --speed 1: the 24 s after the overturn leave time for the commands on a loaded machine.
"$BIN" --scene "$ISOLATED" --replay "$AT2" --scale 20 --speed 1 --no-events \
  --config "$TMP/box.toml" >"$TMP/box.out" 2>"$TMP/box.err" &
BOX=$!
ack() { mosquitto_pub "${OPERATOR[@]}" -q 1 -t plinth/b6/command -m "$1"; }
if wait_for "$TMP/box.out" '"phase": "overturned"' 30; then
  mosquitto_pub "${WATCH[@]}" -V mqttv5 -q 1 -t plinth/b6/command \
    -m '{"command": "acknowledge", "id": "watcher"}' >"$TMP/denied.out" 2>&1
  sleep 0.5
  mosquitto_pub "${OPERATOR[@]}" -q 1 -r -t plinth/b6/command \
    -m '{"command": "acknowledge", "id": "live-retained"}'
  ack '{"command": "acknowledge", "command": "acknowledge", "id": "twice"}'
  ack $'forged\nplinth-monitor: mqtt: connected to the real broker\x1b[2K\xff\xfe'
  ack 'acknowledge'
  ack '{"command": "acknowledge", "level": "warning", "id": "op-1"}'
  ack '{"command": "acknowledge", "sequence": 0, "id": 2}'
  ack '{"command": "acknowledge", "id": "op-3"}'
  wait_for "$TMP/replies.out" '"op-3"' 10
  sleep 0.5
  mosquitto_sub "${WATCH[@]}" -W 2 -v -t 'homeassistant/+/plinth_b6/#' >"$TMP/discovery.out" 2>&1
  mosquitto_sub "${WATCH[@]}" -C 1 -W 2 -t plinth/b6/state >"$TMP/state.out" 2>&1
else
  fail "mqtt: commands" "no overturn within 30 s; stderr: $(head -c 300 "$TMP/box.err")"
fi
wait "$BOX"
rc=$?
BOX=
kill "$REPLIES" 2>/dev/null
wait "$REPLIES" 2>/dev/null
mosquitto_pub "${OPERATOR[@]}" -q 1 -r -n -t plinth/b6/command  # the retained one cleared
problem=$(python3 - "$TMP/box.out" "$TMP/replies.out" "$TMP/denied.out" "$TMP/box.err" 2>&1 <<'PY'
import json, sys
lines = [json.loads(l) for l in open(sys.argv[1])]
replies = [json.loads(l) for l in open(sys.argv[2]) if l.startswith("{")]
assert len(replies) == 7, "7 replies expected, got %s" % open(sys.argv[2]).read()[:900]
assert "Not authorized" in open(sys.argv[3]).read(), "the watcher's publish was not refused"
commands = [l for l in lines if l["type"] == "command"]
assert [c["source"] for c in commands] == ["mqtt"] * 3, commands  # not the watcher's
raised = [l for l in lines if l["type"] == "alarm" and l["level"] == "alarm"][0]
assert [r["id"] for r in replies] == [None, None, None, None, "op-1", 2, "op-3"], replies
assert [r["result"] for r in replies] == ["refused"] * 6 + ["accepted"], replies
assert replies[0]["reason"].startswith("retained"), replies[0]
assert replies[1]["reason"] == 'member "command" given twice', replies[1]
assert replies[2]["reason"] == "not JSON" and replies[3]["reason"] == "not JSON", replies[2:4]
replies = replies[3:]
assert replies[1]["reason"] == "wrong level" and replies[1]["level"] == "warning", replies[1]
assert replies[2]["reason"] == "stale sequence" and replies[2]["sequence"] == 0, replies[2]
last = replies[3]
assert last["outcome"] == "released, condition holds" and "reason" not in last, last
assert last["level"] == "alarm" and last["sequence"] == raised["sequence"], (last, raised)
assert commands[-1]["outcome"] == last["outcome"], commands[-1]
ack = [l for l in lines if l["type"] == "alarm"][-1]
assert ack["cause"] == "acknowledged" and ack["latched"] is False, ack
mqtt = lines[-1]["mqtt"]
assert mqtt["commands_received"] == 7 and mqtt["commands_accepted"] == 1, mqtt
assert mqtt["commands_refused"] == 6 and mqtt["discovery_configs"] >= 8, mqtt
assert mqtt["commands_retained"] == 1, mqtt
# What the forged payload logged: one line, its bytes escaped.
err = open(sys.argv[4], "rb").read()
assert b"\x1b" not in err and b"\xff" not in err, err[-400:]
assert not any(l.startswith(b"plinth-monitor: mqtt: connected to the real broker")
               for l in err.splitlines()), err[-400:]
assert b"forged\\x0Aplinth-monitor: mqtt: connected to the real broker\\x1B[2K\\xFF\\xFE" in err, \
    err[-400:]
PY
)
if ((rc == 0)) && [[ -z "$problem" ]]; then
  pass "mqtt: operator's acknowledgement accepted, bad ones refused with reasons, ACL keeps others out"
else
  fail "mqtt: commands" "exit $rc; $problem; replies: $(head -c 600 "$TMP/replies.out")"
fi
problem=$(python3 - "$TMP/discovery.out" "$TMP/state.out" "$("$BIN" --version)" "${DIGESTS[@]}" 2>&1 <<'PY'
import json, sys
configs = dict(l.split(" ", 1) for l in open(sys.argv[1]).read().splitlines()
               if l.startswith("homeassistant/"))
configs = {topic: json.loads(payload) for topic, payload in configs.items()}
prefix = "homeassistant/%s/plinth_b6/%s/config"
expected = {prefix % ("sensor", "level"): "{{ value_json.level }}",
            prefix % ("sensor", "latched"): "{{ value_json.latched }}",
            prefix % ("sensor", "risk"): "{{ value_json.risk }}",
            prefix % ("sensor", "probability"): "{{ value_json.forecast.probability }}"}
digests = {prefix % ("sensor", "scene_sha256"): "{{ value_json.scene_sha256 }}",
           prefix % ("sensor", "config_sha256"): "{{ value_json.config_sha256 }}"}
expected.update(digests)  # no second scene: no sensor for its digest
others = {prefix % ("binary_sensor", "availability"), prefix % ("button", "acknowledge")}
assert set(configs) == set(expected) | others, sorted(configs)
for topic in digests:
    assert configs[topic]["entity_category"] == "diagnostic", configs[topic]
version = sys.argv[3].split(" ", 1)[1]
for topic, config in configs.items():
    assert config["unique_id"].startswith("plinth_b6_"), config
    assert config["device"]["identifiers"] == ["plinth_b6"], config
    assert config["device"]["sw_version"] == version, config
for topic, template in expected.items():
    c = configs[topic]
    assert c["state_topic"] == "plinth/b6/state" and c["value_template"] == template, c
    assert c["availability_topic"] == "plinth/b6/availability", c
assert configs[prefix % ("sensor", "level")]["options"][-1] == "fault"
online = configs[prefix % ("binary_sensor", "availability")]
assert online["state_topic"] == "plinth/b6/availability" and online["payload_on"] == "online"
button = configs[prefix % ("button", "acknowledge")]
assert button["command_topic"] == "plinth/b6/command", button
assert json.loads(button["payload_press"])["command"] == "acknowledge", button
state = json.loads(open(sys.argv[2]).read())
assert state["forecast"]["probability"] == 1.0 and state["forecast"]["axis"] == "x", state
assert state["forecast"]["worst_member"] == 0 and state["forecast"]["collapse_in_s"] == 0, state
assert state["sensor_counters"]["fed"] > 1000 and state["sensor_counters"]["missing"] == 0, state
assert state["sensors_state"] == "ok" and state["estimator_restarts"] == 1, state
assert "%s (%s)" % (state["version"]["project"], state["version"]["git"]) == version, state
scene, config = sys.argv[4:6]  # sha256sum's
assert state["scene_sha256"] == scene and state["config_sha256"] == config, (state, scene, config)
assert "scene_y_sha256" in state and state["scene_y_sha256"] is None, state
PY
)
if [[ -z "$problem" ]]; then
  pass "mqtt: discovery configs retained; the state: forecast, counters, version, digests"
else
  fail "mqtt: discovery and state" "$problem"
fi

# 1e. Commands off (the default) and discovery off: the reply says why, no config published. Two
#     axes: the state carries the second scene's digest too.
printf '[mqtt]\nbroker = "127.0.0.1:%s"\nbox_id = "b7"\nusername = "box"\n' "$PLAIN" >"$TMP/box.toml"
printf '%s\n' 'password_file = "box.pw"' 'discovery = false' >>"$TMP/box.toml"
DIGESTS=("$(sha "$ISOLATED")" "$(sha "$ECCENTRIC")" "$(sha "$TMP/box.toml")")
mosquitto_sub "${OPERATOR[@]}" -C 1 -W 30 -t plinth/b7/command/reply >"$TMP/replies.out" 2>&1 &
REPLIES=$!
"$BIN" --scene "$ISOLATED" --scene-y "$ECCENTRIC" --replay "$AT2" --speed 4 --no-events \
  --config "$TMP/box.toml" >"$TMP/box.out" 2>"$TMP/box.err" &
BOX=$!
for ((i = 0; i < 100; i++)); do
  [[ "$(mosquitto_sub "${WATCH[@]}" -C 1 -W 1 -t plinth/b7/availability 2>/dev/null)" == online ]] &&
    break
done
mosquitto_pub "${OPERATOR[@]}" -q 1 -t plinth/b7/command -m '{"command": "acknowledge", "id": 7}'
wait "$REPLIES"
discovered=$(mosquitto_sub "${WATCH[@]}" -W 2 -v -t 'homeassistant/+/plinth_b7/#' 2>/dev/null | wc -l)
kill -INT "$BOX" 2>/dev/null
wait "$BOX" 2>/dev/null
BOX=
reply='"id": 7, "command": "acknowledge", "result": "refused", '
reply+='"reason": "commands are off (mqtt.commands = false)"'
if grep -qF "$reply" "$TMP/replies.out" && ((discovered == 0)) &&
  ! grep -q '"type": "command"' "$TMP/box.out"; then
  pass "mqtt: with commands off the reply says so; discovery off publishes no config"
else
  fail "mqtt: commands and discovery off" "reply: $(cat "$TMP/replies.out"); $discovered configs"
fi
mosquitto_sub "${WATCH[@]}" -C 1 -W 2 -t plinth/b7/state >"$TMP/state.out" 2>&1
problem=$(python3 - "$TMP/state.out" "$TMP/box.out" "${DIGESTS[@]}" 2>&1 <<'PY'
import json, sys
state = json.loads(open(sys.argv[1]).read())
first = [json.loads(l) for l in open(sys.argv[2]) if l.startswith('{"type": "status"')][0]
got = [state[k] for k in ("scene_sha256", "scene_y_sha256", "config_sha256")]
assert got == sys.argv[3:6], "state %s, sha256sum %s" % (got, sys.argv[3:6])
assert got == [first[k] for k in ("scene_sha256", "scene_y_sha256", "config_sha256")], first
PY
)
if [[ -z "$problem" ]]; then
  pass "mqtt: two axes: the state's three digests are sha256sum's and the first status line's"
else
  fail "mqtt: digests, two axes" "$problem"
fi

# 2. The Last Will: the box killed (-9) while connected on the plain listener.
"$BIN" --scene "$ISOLATED" --replay "$AT2" --speed 1 --no-events --mqtt "127.0.0.1:$PLAIN" \
  --mqtt-box-id b2 --mqtt-username box --mqtt-password-file "$TMP/box.pw" \
  >"$TMP/box2.out" 2>"$TMP/box2.err" &
BOX=$!
online=""
for ((i = 0; i < 100; i++)); do
  online=$(mosquitto_sub "${WATCH[@]}" -C 1 -W 1 -t plinth/b2/availability 2>/dev/null)
  [[ "$online" == online ]] && break
  sleep 0.1
done
kill -9 "$BOX"
wait "$BOX" 2>/dev/null
BOX=
sleep 0.5
will=$(mosquitto_sub "${WATCH[@]}" -C 1 -W 5 -t plinth/b2/availability 2>/dev/null)
if [[ "$online" == online && "$will" == offline ]]; then
  pass "mqtt: availability online, then the Last Will says offline after kill -9"
else
  fail "mqtt: Last Will" "availability '$online' while running, '$will' after kill -9"
fi

# 2b. Another client takes the box's client id: the broker closes the box's session and
#     publishes its Last Will (mosquitto 2.0.11 sends no DISCONNECT reason 0x8E); the box finds
#     its Will retained when it connects again, says so, counts it. The id has 64 random bits:
#     this client reads it off the broker's log, as only the broker's administrator can.
printf '[mqtt]\nbroker = "127.0.0.1:%s"\nbox_id = "taken"\nusername = "box"\n' "$PLAIN" \
  >"$TMP/taker.toml"
printf '%s\n' 'password_file = "box.pw"' 'reconnect_min_s = 0.1' 'reconnect_max_s = 0.5' \
  >>"$TMP/taker.toml"
fresh "$TMP/taker-box.out"
"$BIN" --scene "$ISOLATED" --replay "$AT2" --speed 1 --no-events --config "$TMP/taker.toml" \
  >"$TMP/taker-box.out" 2>"$TMP/taker-box.err" &
BOX=$!
id=""
for ((i = 0; i < 100; i++)); do
  id=$(grep -o 'as plinth-taken-[0-9a-f]\{16\}' "$TMP/broker.log" | tail -n 1 | cut -d' ' -f2)
  [[ -n "$id" ]] && break
  sleep 0.1
done
if [[ -n "$id" ]]; then
  mosquitto_sub -h 127.0.0.1 -p "$PLAIN" -u box -P box-secret -i "$id" -t plinth/taken/x -W 2 \
    >"$TMP/taker.out" 2>&1
  wait_for "$TMP/taker-box.err" "another client connected with its client id" 10
fi
sleep 1
online=$(mosquitto_sub "${WATCH[@]}" -C 1 -W 5 -t plinth/taken/availability 2>/dev/null)
kill -INT "$BOX" 2>/dev/null
wait "$BOX" 2>/dev/null
BOX=
problem=$(python3 - "$TMP/taker-box.out" "$TMP/taker-box.err" "$id" "$online" 2>&1 <<'PY'
import json, sys
mqtt = json.loads(open(sys.argv[1]).read().splitlines()[-1])["mqtt"]
err = open(sys.argv[2]).read()
assert sys.argv[3], "the box's client id is not in the broker's log"
assert mqtt["session_takeovers"] + mqtt["wills_while_running"] >= 1, mqtt
assert mqtt["connects"] >= 2, mqtt
assert "another client connected with its client id (%s" % sys.argv[3] in err, err[-500:]
assert sys.argv[4] == "online", "availability after the takeover: %r" % sys.argv[4]
PY
)
if [[ -z "$problem" ]]; then
  pass "mqtt: a session takeover is said and counted, the box connects again"
else
  fail "mqtt: takeover" "$problem; the taker: $(head -c 200 "$TMP/taker.out"); the broker:\
 $(grep -E "taken-|$id" "$TMP/broker.log" | tail -n 4)"
fi

# 3. A wrong password: refused with a clear message; the box goes on with its work.
expect_success "mqtt: a wrong password does not stop the box" --scene "$ISOLATED" \
  --replay "$AT2" --no-events --mqtt "127.0.0.1:$PLAIN" --mqtt-box-id b3 \
  --mqtt-username box --mqtt-password-file "$TMP/wrong.pw" && true
if grep -qE "refused the connection: (bad user name or password|not authorised)" "$TMP/stderr" &&
  grep -q -- "--mqtt" "$TMP/stderr"; then
  pass "mqtt: the wrong password is refused with a clear message"
else
  fail "mqtt: wrong password" "stderr: $(head -c 300 "$TMP/stderr")"
fi
stop_broker

# 3c. A broker that never answers the TCP handshake (a listener whose accept queue is full:
#     the kernel drops the SYNs, as a firewall would): the box goes on, says so once, and stops
#     within its flush bound after the input, not after the kernel's ~130 s of SYN retries per
#     blocked connect (it took 270 s when the connect blocked).
SILENT=$(free_port)
python3 - "$SILENT" >"$TMP/silent.out" 2>&1 <<'PY' &
import socket, sys, time
port = int(sys.argv[1])
server = socket.socket()
server.bind(("127.0.0.1", port))
server.listen(0)
fillers = []
for _ in range(3):  # fill the accept queue; later SYNs are dropped
    c = socket.socket()
    c.setblocking(False)
    c.connect_ex(("127.0.0.1", port))
    fillers.append(c)
print("ready", flush=True)
time.sleep(120)
PY
SILENT_PID=$!
for _ in $(seq 50); do grep -q ready "$TMP/silent.out" && break; sleep 0.1; done
started=$(date +%s)
rc=0
timeout 100 "$BIN" --scene "$ISOLATED" --replay "$AT2" --scale 20 --speed 4 --no-events \
  --mqtt "127.0.0.1:$SILENT" --mqtt-box-id silent >"$TMP/silent.jsonl" 2>"$TMP/silent.err" || rc=$?
took=$(($(date +%s) - started))
kill "$SILENT_PID" 2>/dev/null
problem=$(python3 - "$TMP/silent.jsonl" "$TMP/silent.err" "$took" <<'PY' 2>&1
import json, sys
summary = json.loads(open(sys.argv[1]).read().splitlines()[-1])
mqtt = summary["mqtt"]
err = open(sys.argv[2]).read()
took = int(sys.argv[3])
assert mqtt["connects"] == 0 and mqtt["connect_failures"] >= 2, mqtt
assert mqtt["events_undelivered"] == summary["alarm_events"] and mqtt["events_dropped"] == 0, mqtt
assert err.count("the connection attempt was not answered") == 1, err
# 9 s of input at --speed 4, then at most the 10 s flush: far below one blocked connect.
assert took <= 45, "stopped %d s after its start" % took
PY
)
if ((rc == 0)) && [[ -z "$problem" ]]; then
  pass "mqtt: a broker that never answers: said once, the events kept, stopped within the flush bound"
else
  fail "mqtt: unanswered broker" "exit $rc; $problem"
fi

# 4. Bad settings.
run_args=(--scene "$ISOLATED" --replay "$AT2")
expect_failure "mqtt: broker without a port" "--mqtt" "HOST:PORT" -- \
  "${run_args[@]}" --mqtt localhost
expect_failure "mqtt: a CA file that does not exist" "mqtt.tls_ca_file" "--mqtt-ca" \
  "no-such-ca.crt" -- "${run_args[@]}" --mqtt 127.0.0.1:1883 --mqtt-ca "$TMP/no-such-ca.crt"
expect_failure "mqtt: a password file that does not exist" "mqtt.password_file" \
  "--mqtt-password-file" -- "${run_args[@]}" --mqtt 127.0.0.1:1883 --mqtt-username box \
  --mqtt-password-file "$TMP/no-such.pw"
expect_failure "mqtt: a box id with a slash" "--mqtt-box-id" "topic level" -- \
  "${run_args[@]}" --mqtt 127.0.0.1:1883 --mqtt-box-id a/b
printf '[mqtt]\nbroker = "127.0.0.1:1883"\nevent_queue = 0\n' >"$TMP/bad.toml"
expect_failure "mqtt: event_queue out of range" "bad.toml:3" "mqtt.event_queue" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\ndiscovery_prefix = "ha/#"\n' >"$TMP/bad.toml"
expect_failure "mqtt: a discovery prefix with a wildcard" "bad.toml:3" "mqtt.discovery_prefix" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\ncommands = "yes"\n' >"$TMP/bad.toml"
expect_failure "mqtt: commands not a boolean" "bad.toml:2" "mqtt.commands" "true or false" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1"\n' >"$TMP/bad.toml"
expect_failure "mqtt: broker without a port in the file" "bad.toml:2" "mqtt.broker" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\nbox_id = "b\\u0000other"\n' >"$TMP/bad.toml"
expect_failure "mqtt: a box id with a NUL" "bad.toml:3" "mqtt.box_id" "control character" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\nbox_id = "%s"\n' "$(printf 'x%.0s' $(seq 70000))" \
  >"$TMP/bad.toml"
expect_failure "mqtt: a box id of 70,000 characters" "bad.toml:3" "mqtt.box_id" \
  "longer than 64 bytes" -- "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\nregional_topic = "site/eew"\n' >"$TMP/bad.toml"
expect_failure "mqtt: regional_topic without regional_alerts" "bad.toml:3" \
  "mqtt.regional_topic" "regional_alerts is false" -- "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\nregional_alerts = true\nregional_topic = "site/#"\n' \
  >"$TMP/bad.toml"
expect_failure "mqtt: a wildcard regional_topic" "bad.toml:4" "mqtt.regional_topic" "wildcard" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\nbox_id = "b8"\nregional_alerts = true\n%s\n' \
  'regional_topic = "plinth/b8/command"' >"$TMP/bad.toml"
expect_failure "mqtt: regional_topic on the command topic" "mqtt.regional_topic" \
  "a box's command topic" -- "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\nregional_alerts = true\n%s\n' \
  'regional_topic = "plinth/hall-4/state"' >"$TMP/bad.toml"
expect_failure "mqtt: regional_topic on another box's state" "mqtt.regional_topic" \
  "a box's state" -- "${run_args[@]}" --config "$TMP/bad.toml"
printf '[mqtt]\nbroker = "127.0.0.1:1883"\ntls_cert_file = "c.pem"\n' >"$TMP/bad.toml"
expect_failure "mqtt: a certificate that does not exist" "mqtt.tls_cert_file" "c.pem" -- \
  "${run_args[@]}" --config "$TMP/bad.toml"

echo "$PASSED passed, $FAILED failed"
((FAILED == 0))
