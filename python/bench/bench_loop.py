#!/usr/bin/env python3
# The Python control loop through pyrcb4, side by side in one run with what Python users do today
# over pyserial, on the same paced virtual board (rcb4 serve --pace: replies at the 1.25 Mbaud line
# rate, plus a USB adapter's latency of 0 and 1,000 us):
#   pyrcb4      ControlLoop: every joint read (the planner's reads), every target written (one CONST)
#   iory        pyserial, iory/rcb4's scheme: five 126-byte reads of the servo area, each reply read
#               length-first, and one CONST of the 35 servo slots
#   planned     pyserial sending the same frames pyrcb4 plans (its reads, its CONST)
#   C++ client  rcb4 bench's control cycle (the C++ client's own rate on the same board)
# Nothing moves: pyrcb4 writes every joint where it is, the pyserial loops HOLD (the same bytes).
#   bench_loop.py RCB4 [SECONDS]      (PYTHONPATH: build/<preset>/python)
# SPDX-License-Identifier: BSL-1.0
import json
import subprocess
import sys
import time

import numpy
import serial

import pyrcb4

RCB4 = sys.argv[1]
SECONDS = float(sys.argv[2]) if len(sys.argv) > 2 else 2.0
HOLD = 0x7FFF


def frame(*body):
    """A request: SIZE first, the checksum (sum of the bytes, low 8 bits) last."""
    b = bytes([len(body) + 2, *body])
    return b + bytes([sum(b) & 0xFF])


def read_ram(address, n):
    return frame(0x00, 0x20, 0x00, 0x00, 0x00, address & 0xFF, address >> 8, n)


def const(slots, frames=1):
    mask = sum(1 << s for s in slots)
    body = [0x10, *mask.to_bytes(5, "little"), frames]
    for _ in slots:
        body += [HOLD & 0xFF, HOLD >> 8]
    return frame(*body)


def exchange(port, request, reply_size):
    port.write(request)
    reply = port.read(reply_size)
    if len(reply) != reply_size or (sum(reply[:-1]) & 0xFF) != reply[-1]:
        raise RuntimeError(f"bad reply {reply.hex(' ')}")
    return reply


def exchange_length_first(port, request):
    """iory/rcb4's way: the SIZE byte, then the rest."""
    port.write(request)
    head = port.read(1)
    rest = port.read(head[0] - 1) if head else b""
    if not head or len(rest) != head[0] - 1:
        raise RuntimeError("no reply")
    return head + rest


def rate(body):
    n, start = 0, time.perf_counter()
    while time.perf_counter() - start < SECONDS:
        body()
        n += 1
    return n / (time.perf_counter() - start)


def measure(latency_us):
    srv = subprocess.Popen([RCB4, "serve", "--pty", "--pace", "--latency", str(latency_us)], stdout=subprocess.PIPE,
                           text=True)
    dev = srv.stdout.readline().strip()
    out = {}
    try:
        with pyrcb4.Board(dev, baud=1250000) as b:
            loop = b.control_loop()
            q = numpy.empty(loop.size)

            def py_cycle():
                loop.read(out=q)
                loop.write(q)  # every joint to where it is: nothing moves, 20 targets written
            out["pyrcb4"] = rate(py_cycle)
            plan, slots = loop.plan, loop.slots
        with serial.Serial(dev, 1250000, parity=serial.PARITY_EVEN, timeout=0.5) as port:
            iory_reads = [read_ram(0x0090 + 126 * k, 126) for k in range(5)]
            iory_const = const(range(35))

            def iory_cycle():
                for r in iory_reads:
                    exchange_length_first(port, r)
                exchange_length_first(port, iory_const)
            out["iory"] = rate(iory_cycle)
            planned_reads = [(read_ram(a, n), n + 3) for a, n in plan]
            planned_const = const(slots)

            def planned_cycle():
                for r, size in planned_reads:
                    exchange(port, r, size)
                exchange(port, planned_const, 4)
            out["planned"] = rate(planned_cycle)
        r = subprocess.run([RCB4, "--json", "--device", dev, "--baud", "1250000", "bench", "--count", "300"],
                           capture_output=True, text=True, timeout=120)
        out["cpp"] = json.loads(r.stdout)["cycle_hz"] if r.returncode == 0 else float("nan")
        out["plan"] = plan
    finally:
        srv.terminate()
        srv.wait(timeout=10)
    return out


print(f"control cycles per second: 20 joints read + targets written, rcb4 serve --pace at 1.25 Mbaud, {SECONDS:g} s each")
print(f"{'adapter latency':>16} {'pyrcb4':>9} {'iory (pyserial)':>16} {'planned (pyserial)':>19} {'C++ client':>11}"
      f" {'pyrcb4/iory':>12} {'pyrcb4/C++':>11}")
for latency in (0, 1000):
    m = measure(latency)
    print(f"{latency:>13} us {m['pyrcb4']:>9.1f} {m['iory']:>16.1f} {m['planned']:>19.1f} {m['cpp']:>11.1f}"
          f" {m['pyrcb4'] / m['iory']:>11.2f}x {m['pyrcb4'] / m['cpp']:>10.2f}x   reads {m['plan']}")
