#!/usr/bin/env bash
# tools/vcan-bus.sh's choice of route on a host where user-mode Linux cannot start, simulated with
# UML_VCAN_XSTATE_SIZE=11008 (the XSAVE state of a Xeon with AMX, docs/can-e2e.md):
#  1. the uml route (tools/uml-vcan.sh) refuses before it boots, says why, exits 77, and the
#     command does not run;
#  2. the auto route runs the command on qemu instead, in the same directory with the same
#     environment, and its exit status comes back;
#  3. a route that does not exist is a usage error (125).
# Exit 0 when all of that holds; 77 when the qemu route cannot start here.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
work=$(mktemp -d /tmp/test-vcan-fallback.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() { echo "test_vcan_fallback: $*" >&2; exit 1; }
cd "$work"
unset PLINTH_VCAN_ROUTE
# This test is about the choice of route, not about CI's rule that some route must run (vcan_route
# enforces that): under CI=true the refused uml route would exit 1, not the 77 checked here.
unset CI
export UML_VCAN_XSTATE_SIZE=11008

status=0
bash "$root/tools/uml-vcan.sh" -c 'touch ran' >uml.out 2>uml.err || status=$?
[ "$status" -eq 77 ] || fail "uml route on an AMX host: exit $status, not 77: $(cat uml.err)"
[ ! -e ran ] || fail "uml route on an AMX host: the command ran"
grep -q "route uml cannot start here: this host's XSAVE state is 11008 bytes" uml.err ||
  fail "uml route on an AMX host: no reason given: $(cat uml.err)"

export VCAN_FALLBACK_MARK=$RANDOM
status=0
# shellcheck disable=SC2016  # expanded in the guest
bash "$root/tools/vcan-bus.sh" --timeout 240 -c \
  'test "$PWD" = "'"$work"'" && test "$VCAN_FALLBACK_MARK" = '"$VCAN_FALLBACK_MARK"' &&
   touch ran && exit 3' >auto.out 2>auto.err || status=$?
cat auto.err >&2
if grep -q "route qemu cannot start here" auto.err; then  # 77, or 1 under CI=true
  [ "$status" -eq 77 ] || fail "the qemu route cannot start here (above)"
  exit 77
fi
grep -q "route uml cannot start here" auto.err || fail "auto route: uml was not refused first"
grep -q "route qemu (\(kvm\|tcg\)): command exited with 3" auto.err ||
  fail "auto route: the command did not run on qemu"
[ -e ran ] || fail "auto route: another directory or environment in the guest"
[ "$status" -eq 3 ] || fail "auto route: exit $status, not the command's 3"

status=0
PLINTH_VCAN_ROUTE=bogus bash "$root/tools/vcan-bus.sh" true 2>bogus.err || status=$?
if [ "$status" -ne 125 ] || ! grep -q "must be auto, uml or qemu" bogus.err; then
  fail "PLINTH_VCAN_ROUTE=bogus: exit $status: $(cat bogus.err)"
fi
echo "test_vcan_fallback: uml refused before booting, qemu ran the command, status 3 came back"
