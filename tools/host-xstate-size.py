#!/usr/bin/env python3
"""Prints the size in bytes of this host's x86 XSAVE register state, as ptrace's NT_X86_XSTATE
register set has it: the one buffer size PTRACE_SETREGSET accepts for it (Linux >= 5.16:
fpu_user_cfg.max_size, which counts AMX's 8 KiB of tile data where the CPU has AMX).

tools/vcan-bus.sh asks before it boots user-mode Linux: Debian 12's linux.uml (6.1) always sets
2696 bytes, so on a host whose size is larger every guest process dies (docs/can-e2e.md).

Usage: tools/host-xstate-size.py
Exit status: 0 and the size on stdout; 2 when this host lets no process trace its child (the
reason on stderr: user-mode Linux cannot run either); 3 not an x86-64 Linux host.
"""
import ctypes
import os
import platform
import signal
import sys

PTRACE_TRACEME = 0
PTRACE_GETREGSET = 0x4204
NT_X86_XSTATE = 0x202
BUFFER_BYTES = 1 << 20  # far above any XSAVE size (AMX: 11008)


class IoVec(ctypes.Structure):
    _fields_ = [("base", ctypes.c_void_p), ("length", ctypes.c_size_t)]


def main():
    if platform.system() != "Linux" or platform.machine() != "x86_64":
        print(f"host-xstate-size: not an x86-64 Linux host ({platform.machine()})", file=sys.stderr)
        return 3
    libc = ctypes.CDLL(None, use_errno=True)
    libc.ptrace.argtypes = [ctypes.c_long, ctypes.c_long, ctypes.c_void_p, ctypes.c_void_p]
    libc.ptrace.restype = ctypes.c_long
    child = os.fork()
    if child == 0:  # stops at once, traced by the parent
        if libc.ptrace(PTRACE_TRACEME, 0, None, None) != 0:
            os._exit(1)
        os.kill(os.getpid(), signal.SIGSTOP)
        os._exit(0)
    _, status = os.waitpid(child, 0)
    if not os.WIFSTOPPED(status):
        print("host-xstate-size: ptrace(PTRACE_TRACEME) was refused here", file=sys.stderr)
        return 2
    buffer = ctypes.create_string_buffer(BUFFER_BYTES)
    iov = IoVec(ctypes.cast(buffer, ctypes.c_void_p), BUFFER_BYTES)
    result = libc.ptrace(PTRACE_GETREGSET, child, NT_X86_XSTATE, ctypes.byref(iov))
    error = ctypes.get_errno()
    os.kill(child, signal.SIGKILL)
    os.waitpid(child, 0)
    if result != 0:
        print(f"host-xstate-size: PTRACE_GETREGSET NT_X86_XSTATE failed: {os.strerror(error)}",
              file=sys.stderr)
        return 2
    print(iov.length)
    return 0


if __name__ == "__main__":
    sys.exit(main())
