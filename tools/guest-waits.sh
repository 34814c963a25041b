# shellcheck shell=bash disable=SC2034  # now: the caller's
# Waits for a guest of tools/vcan-bus.sh, in bash builtins only (sourced by tools/e2e-can.sh
# and tests/integration/candump_overflow.sh): every process started in a guest costs tens of ms
# (exec through hostfs), so EPOCHREALTIME for the time, read -t for sleeping, reading the new
# lines of a log for watching the bus.
#
# Usage (in the guest, the work folder its cwd): . tools/guest-waits.sh
# A FIFO nobody writes to (in the guest's own tmpfs): read -t on it is a sleep.
nap_fifo=$(mktemp -u /dev/shm/guest-nap.XXXXXX)
mkfifo "$nap_fifo"
exec {nap_fd}<>"$nap_fifo"
nap() { read -r -t "$1" -u "$nap_fd" || true; }  # sleep S, without a process
us() { now=${EPOCHREALTIME/./}; }                 # now: us since the epoch
# Waits until a line of FILE matches the glob PATTERN, at most POLLS x 10 ms.
wait_line() {  # FILE PATTERN POLLS
  local fd line rest="" i
  for ((i = 0; i < $3; i++)); do
    [ -e "$1" ] && break  # a background job's redirection may not have run yet
    nap 0.01
  done
  exec {fd}<"$1" || return 1
  for ((; i < $3; i++)); do
    while IFS= read -r -u "$fd" line; do
      line=$rest$line
      rest=""
      # shellcheck disable=SC2053  # a glob on purpose
      if [[ $line == $2 ]]; then exec {fd}<&-; return 0; fi
    done
    rest=$rest$line
    nap 0.01
  done
  exec {fd}<&-
  return 1
}
