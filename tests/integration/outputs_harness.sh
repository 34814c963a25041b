# Shared by the tests of plinth-monitor's outputs (test_modbus.sh, test_mqtt*.sh): the CLI
# harness (tests/cli/harness.sh), then BIN (PLINTH_MONITOR) and helpers for servers on loopback.
# shellcheck source=tests/cli/harness.sh
source "$(dirname "${BASH_SOURCE[0]}")/../cli/harness.sh"
BIN=${PLINTH_MONITOR:-}
if [[ ! -x "$BIN" ]]; then
  echo "PLINTH_MONITOR=$BIN: not an executable" >&2
  exit 2
fi

# require_tools TOOL...: each on PATH (or in /usr/sbin); otherwise exit 77 (skip), or 1 under
# CI=true, which must have them.
require_tools() {
  local tool
  for tool in "$@"; do
    command -v "$tool" >/dev/null || [[ -x /usr/sbin/$tool ]] && continue
    if [[ "${CI:-}" == "true" ]]; then
      echo "$tool is missing (tools/install-deps.sh installs it)" >&2
      exit 1
    fi
    echo "skipped: $tool is missing (tools/install-deps.sh installs it)"
    exit 77
  done
}

# A TCP port free on 127.0.0.1 now.
free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

# fresh FILE...: each FILE emptied now, by this shell. A job started with `>FILE &` opens FILE
# only once it runs; until then a wait_for on FILE would match the lines of the run before it.
fresh() {
  local f
  for f in "$@"; do : >"$f"; done
}

# wait_for FILE PATTERN SECONDS: until a line of FILE matches PATTERN (grep -E); 1 on timeout.
# FILE written by a job started just before: `fresh FILE` first.
wait_for() {
  local i
  for ((i = 0; i < $3 * 10; i++)); do
    grep -qE "$2" "$1" 2>/dev/null && return 0
    sleep 0.1
  done
  return 1
}

# broker_cleanup_at_exit: at exit, kill the box (BOX, a pid) and the broker (BROKER_PID), which
# the caller sets once it has started them, and every background job, then remove $TMP (the MQTT
# tests).
broker_cleanup() {
  [[ -n "$BOX" ]] && kill -9 "$BOX" 2>/dev/null
  [[ -n "$BROKER_PID" ]] && kill "$BROKER_PID" 2>/dev/null
  jobs -p | xargs -r kill 2>/dev/null
  rm -rf "$TMP"
}
broker_cleanup_at_exit() {
  BROKER_PID=
  BOX=
  trap broker_cleanup EXIT
}
