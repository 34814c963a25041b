#!/usr/bin/env bash
# Runs a command on a real SocketCAN bus inside Debian's user-mode Linux kernel: the uml route of
# tools/vcan-bus.sh (same options, same exit status; 77 when user-mode Linux cannot start here,
# e.g. on a host with AMX, docs/can-e2e.md). tools/vcan-bus.sh alone takes QEMU where UML does
# not start.
#
# Usage: tools/uml-vcan.sh [options] [--] PROGRAM [ARG...]
#        tools/uml-vcan.sh [options] -c 'SHELL COMMAND LINE'
# Example: tools/uml-vcan.sh --vcan 2 build/release/tests/test_socketcan
exec bash "$(dirname "${BASH_SOURCE[0]}")/vcan-bus.sh" --route uml "$@"
