# Shared by the CLI tests: checks the environment (PLINTH_SIM, the plinth-sim binary;
# PLINTH_SOURCE_DIR, the repository root) and sets SIM, SRC, SCENES and AT2 (the Brienza
# record); then a temporary working folder, TAP-like pass/fail counters and a timeout.
if [[ -z "${PLINTH_SIM:-}" || -z "${PLINTH_SOURCE_DIR:-}" ]]; then
  echo "usage: PLINTH_SIM=path/to/plinth-sim PLINTH_SOURCE_DIR=repo/root bash $0" >&2
  exit 2
fi
SIM=$PLINTH_SIM
SRC=$PLINTH_SOURCE_DIR
if [[ ! -x "$SIM" ]]; then
  echo "$SIM: not an executable" >&2
  exit 2
fi
SCENES=$SRC/sim/scenes
AT2=$SRC/sim/data/records/irpinia1980_brienza_000.AT2

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cd "$TMP" || exit 2

PASSED=0
FAILED=0
pass() {
  echo "ok - $1"
  PASSED=$((PASSED + 1))
}
fail() {
  echo "not ok - $1: $2"
  FAILED=$((FAILED + 1))
}
# ok_if NAME COMMAND...: passes NAME when COMMAND succeeds; else fails it with the start of
# the last run's stderr.
ok_if() {
  local name=$1
  shift
  if "$@"; then pass "$name"; else fail "$name" "$(head -c 300 "$TMP/stderr")"; fi
}

TIMEOUT=()
if command -v timeout >/dev/null 2>&1; then TIMEOUT=(timeout 120); fi

BIN=$SIM

# run ARGS...: runs the binary under test, $BIN (plinth-sim unless the script sets it); sets RC, and leaves its output in $TMP/stdout and $TMP/stderr.
RC=0
run() {
  "${TIMEOUT[@]}" "$BIN" "$@" >"$TMP/stdout" 2>"$TMP/stderr"
  RC=$?
}

# Why an exit code is wrong for a bad input ("" when it is 1 or 2).
bad_exit_reason() {
  if ((RC == 0)); then
    echo "exit 0 on bad input"
  elif ((RC == 124)) && ((${#TIMEOUT[@]} > 0)); then
    echo "timed out"
  elif ((RC >= 128)); then
    echo "crashed (exit $RC, signal $((RC - 128)))"
  elif ((RC != 1 && RC != 2)); then
    echo "exit code $RC, expected 1 or 2"
  fi
}

first_stderr_line() { head -n 1 "$TMP/stderr" | cut -c 1-200; }

# expect_failure NAME PATTERN... -- ARGS...: $BIN ARGS must exit with 1 or 2 and print
# to stderr a readable message matching every PATTERN (extended regex, case-insensitive).
expect_failure() {
  local name=$1
  shift
  local patterns=()
  while (($# > 0)) && [[ "$1" != "--" ]]; do
    patterns+=("$1")
    shift
  done
  shift
  run "$@"
  local why
  why=$(bad_exit_reason)
  if [[ -n "$why" ]]; then
    fail "$name" "$why; stderr: $(first_stderr_line)"
    return
  fi
  if [[ ! -s "$TMP/stderr" ]]; then
    fail "$name" "nothing on stderr"
    return
  fi
  local pattern
  for pattern in "${patterns[@]}"; do
    if ! grep -qiE -- "$pattern" "$TMP/stderr"; then
      fail "$name" "stderr does not match /$pattern/: $(first_stderr_line)"
      return
    fi
  done
  local longest
  longest=$(awk '{ if (length($0) > n) n = length($0) } END { print n + 0 }' "$TMP/stderr")
  if ((longest > 300)); then
    fail "$name" "unreadable message ($longest characters on one line): $(first_stderr_line)..."
    return
  fi
  pass "$name"
}

# expect_success NAME ARGS...: $BIN ARGS must exit 0. Returns non-zero otherwise.
expect_success() {
  local name=$1
  shift
  run "$@"
  if ((RC != 0)); then
    fail "$name" "exit code $RC; stderr: $(first_stderr_line)"
    return 1
  fi
  pass "$name"
}
