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

TIMEOUT=()
if command -v timeout >/dev/null 2>&1; then TIMEOUT=(timeout 120); fi
