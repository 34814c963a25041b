# Shared by the CLI tests: a temporary working folder, TAP-like pass/fail counters and a
# timeout. Source it after checking PLINTH_SIM and PLINTH_SOURCE_DIR.
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

TIMEOUT=()
if command -v timeout >/dev/null 2>&1; then TIMEOUT=(timeout 120); fi
