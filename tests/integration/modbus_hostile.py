#!/usr/bin/env python3
"""Raw Modbus TCP clients against plinth-monitor's server (docs/integration.md, "What each
surface trusts"), for tests/integration/test_modbus.sh.

  modbus_hostile.py frames PORT
      Each hostile frame on a connection of its own; prints one JSON line per frame: what came
      back (an exception code, a closed connection) and in how many ms.
  modbus_hostile.py exceptions PORT COUNT
      COUNT requests the box answers with an exception (quantity 0), back to back on one
      connection; prints one JSON line: how many were answered and the time they took in all.
  modbus_hostile.py silent PORT
      A client that connects and sends nothing, and one that sends 3 bytes of a frame and stops;
      prints one JSON line: after how many s the server closed each (null: not within 10 s).
  modbus_hostile.py write PORT SOURCE
      Writes 1 to coil 0 (acknowledge) from the loopback address SOURCE; prints the outcome.
  modbus_hostile.py siege PORT SECONDS IDLE MALFORMED
      IDLE clients that connect and send nothing (connecting again when closed) and MALFORMED
      clients that send the hostile frames in turn, back to back, each on a new connection, for
      SECONDS (each kind from a loopback address of its own, as other hosts), while a building
      management system polls registers 0-31 every 50 ms on one connection (connecting again
      when closed, its lost polls counted). Prints one JSON line: the BMS's polls, answers,
      answer times (median, 95th percentile, max, how many within 100 ms) and what the hostile
      clients saw.
"""
import json
import socket
import struct
import sys
import threading
import time

POLL_PERIOD_S = 0.05
ANSWER_TIMEOUT_S = 2.0


def frame(pdu, protocol=0, length=None, transaction=0x0101, unit=1):
    """An MBAP frame around `pdu`; `length` overrides the header's length field."""
    n = len(pdu) + 1 if length is None else length
    return struct.pack(">HHHB", transaction, protocol, n, unit) + pdu


# Each hostile frame and what a Modbus server must do with it: "close" (not Modbus: no answer)
# or an exception code.
HOSTILE = [
    ("protocol id 1", frame(b"\x03\x00\x00\x00\x01", protocol=1), "close"),
    ("protocol id 0xFFFF", frame(b"\x03\x00\x00\x00\x01", protocol=0xFFFF), "close"),
    ("length field 0", frame(b"\x03\x00\x00\x00\x01", length=0), "close"),
    ("length field 300", frame(b"\x03\x00\x00\x00\x01", length=300), "close"),
    ("length 1 more than function 03's request", frame(b"\x03\x00\x00\x00\x01\x00"), "close"),
    ("function 0x11 (report server id)", frame(b"\x11"), 1),
    ("function 0x07 (read exception status)", frame(b"\x07"), 1),
    ("function 0x2B (device identification)", frame(b"\x2b\x0e\x01\x00"), 1),
    ("function 06 (register write)", frame(b"\x06\x00\x00\x00\x07"), 1),
    ("function 15 with 2000 coils", frame(b"\x0f\x00\x00\x07\xd0\x01\xff"), 1),
    ("function 15 with 2000 coils and their 250 bytes (a frame longer than Modbus allows)",
     frame(b"\x0f\x00\x00\x07\xd0\xfa" + b"\xff" * 250), "close"),
    ("function 03 quantity 0", frame(b"\x03\x00\x00\x00\x00"), 3),
    ("function 03 quantity 126", frame(b"\x03\x00\x00\x00\x7e"), 3),
    ("function 04 past the map", frame(b"\x04\x00\xff\x00\x02"), 2),
]


def read_exactly(sock, n):
    data = b""
    while len(data) < n:
        chunk = sock.recv(n - len(data))
        if not chunk:
            return None
        data += chunk
    return data


def read_answer(sock):
    """One MBAP answer: (function, payload), or None when the connection closed."""
    header = read_exactly(sock, 7)
    if header is None:
        return None
    _, _, length, _ = struct.unpack(">HHHB", header)
    body = read_exactly(sock, length - 1)
    return None if body is None else (body[0], body[1:])


# Each kind of client from a host of its own (every 127.x.y.z is this machine's loopback): the
# BMS from 127.0.0.1, the idle clients from 127.0.0.2, the malformed ones from 127.0.0.3.
BMS_HOST, IDLE_HOST, MALFORMED_HOST = "127.0.0.1", "127.0.0.2", "127.0.0.3"


def connect(port, source=BMS_HOST):
    s = socket.create_connection(("127.0.0.1", port), timeout=ANSWER_TIMEOUT_S,
                                 source_address=(source, 0))
    s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
    return s


def ask(port, request, sock=None, source=BMS_HOST):
    """(outcome, ms): "close", an exception code, or "answer"."""
    own = sock is None
    sock = sock or connect(port, source)
    try:
        start = time.monotonic()
        sock.sendall(request)
        try:
            got = read_answer(sock)
        except (ConnectionResetError, socket.timeout):
            got = None
        ms = (time.monotonic() - start) * 1e3
        if got is None:
            return "close", ms
        function, payload = got
        return (payload[0] if function & 0x80 else "answer"), ms
    finally:
        if own:
            sock.close()


def frames(port):
    for name, request, expected in HOSTILE:
        outcome, ms = ask(port, request)
        print(json.dumps({"frame": name, "expected": expected, "outcome": outcome,
                          "ms": round(ms, 2)}))


def exceptions(port, count):
    sock = connect(port)
    start = time.monotonic()
    answered = 0
    for _ in range(count):
        if ask(port, frame(b"\x03\x00\x00\x00\x00"), sock)[0] == 3:
            answered += 1
    total_ms = round((time.monotonic() - start) * 1e3, 1)
    print(json.dumps({"answered": answered, "total_ms": total_ms}))
    sock.close()


def closed_after(sock, limit_s=10.0):
    """s until the server closes `sock`, None when it does not within limit_s."""
    start = time.monotonic()
    sock.settimeout(0.05)
    while time.monotonic() - start < limit_s:
        try:
            if sock.recv(1) == b"":
                return round(time.monotonic() - start, 2)
        except socket.timeout:
            continue
        except ConnectionResetError:
            return round(time.monotonic() - start, 2)
    return None


def silent(port):
    idle = connect(port, IDLE_HOST)
    partial = connect(port, MALFORMED_HOST)
    partial.sendall(frame(b"\x03\x00\x00\x00\x01")[:3])
    result = {}
    threads = [threading.Thread(target=lambda k=k, c=c: result.__setitem__(k, closed_after(c)))
               for k, c in (("idle_s", idle), ("partial_frame_s", partial))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    print(json.dumps(result))


def write(port, source):
    outcome, _ = ask(port, frame(b"\x05\x00\x00\xff\x00"), source=source)
    print(json.dumps({"source": source, "outcome": outcome}))


class Stop:
    def __init__(self, seconds):
        self.deadline = time.monotonic() + seconds

    def __bool__(self):
        return time.monotonic() >= self.deadline


def idle_client(port, stop, seen):
    while not stop:
        try:
            s = connect(port, IDLE_HOST)
            seen["idle_connections"] += 1
            s.settimeout(0.2)
            while not stop:
                try:
                    if s.recv(1) == b"":
                        seen["idle_closed_by_server"] += 1
                        break
                except socket.timeout:
                    continue
            s.close()
        except OSError:
            seen["idle_errors"] += 1
            time.sleep(0.01)


def malformed_client(port, stop, seen, first):
    """The hostile frames in turn, each on a new connection (under siege a connection may be
    closed for a newer one before its answer: what came back is counted, not checked)."""
    i = first
    while not stop:
        _, request, _ = HOSTILE[i % len(HOSTILE)]
        i += 1
        try:
            outcome, _ = ask(port, request, source=MALFORMED_HOST)
            seen["hostile_frames"] += 1
            seen["hostile_closed" if outcome == "close" else "hostile_exceptions"] += 1
        except OSError:
            seen["hostile_errors"] += 1


def bms(port, stop, result):
    """Registers 0-31 every POLL_PERIOD_S on one connection; a poll that fails is lost."""
    request_pdu = b"\x03\x00\x00\x00\x20"
    sock = None
    transaction = 0
    next_poll = time.monotonic()
    while not stop:
        time.sleep(max(0.0, next_poll - time.monotonic()))
        next_poll += POLL_PERIOD_S
        result["polls"] += 1
        transaction = (transaction + 1) & 0xFFFF
        try:
            if sock is None:
                start = time.monotonic()
                sock = connect(port)
                result["connects"] += 1
            else:
                start = time.monotonic()
            sock.sendall(frame(request_pdu, transaction=transaction))
            got = read_answer(sock)
            if got is None or got[0] != 0x03 or len(got[1]) != 65:
                raise OSError("no answer")
            result["times_ms"].append((time.monotonic() - start) * 1e3)
        except OSError:
            result["lost"] += 1
            if sock is not None:
                sock.close()
            sock = None
    if sock is not None:
        sock.close()


def siege(port, seconds, idle, malformed):
    stop = Stop(seconds)
    seen = {"idle_connections": 0, "idle_closed_by_server": 0, "idle_errors": 0,
            "hostile_frames": 0, "hostile_closed": 0, "hostile_exceptions": 0,
            "hostile_errors": 0}
    result = {"polls": 0, "lost": 0, "connects": 0, "times_ms": []}
    threads = [threading.Thread(target=idle_client, args=(port, stop, seen)) for _ in range(idle)]
    threads += [threading.Thread(target=malformed_client, args=(port, stop, seen, k))
                for k in range(malformed)]
    for t in threads:
        t.start()
    time.sleep(0.5)  # the hostile clients hold their slots first
    bms(port, stop, result)
    for t in threads:
        t.join()
    times = sorted(result.pop("times_ms"))
    answered = len(times)

    def quantile(q):
        return round(times[min(answered - 1, int(q * answered))], 2) if answered else None

    print(json.dumps({
        "polls": result["polls"], "answered": answered, "lost": result["lost"],
        "bms_connects": result["connects"],
        "answered_fraction": round(answered / max(result["polls"], 1), 4),
        "median_ms": quantile(0.5), "p95_ms": quantile(0.95),
        "max_ms": round(times[-1], 2) if times else None,
        "within_100_ms": sum(1 for t in times if t <= 100.0),
        "hostile": seen,
    }))


def main():
    if len(sys.argv) == 3 and sys.argv[1] == "frames":
        frames(int(sys.argv[2]))
    elif len(sys.argv) == 4 and sys.argv[1] == "exceptions":
        exceptions(int(sys.argv[2]), int(sys.argv[3]))
    elif len(sys.argv) == 3 and sys.argv[1] == "silent":
        silent(int(sys.argv[2]))
    elif len(sys.argv) == 4 and sys.argv[1] == "write":
        write(int(sys.argv[2]), sys.argv[3])
    elif len(sys.argv) == 6 and sys.argv[1] == "siege":
        siege(int(sys.argv[2]), float(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5]))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
