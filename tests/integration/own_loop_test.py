#!/usr/bin/env python3
# examples/own_loop.cpp, the operations over plain POSIX read/write/poll through the library's
# public link (rcb4/link/device_link.hpp), as its user runs it:
# against `rcb4 serve --pty` (the virtual board), then against stand-in boards that misbehave
# (tests/integration/standin.py: silent, NACK, bad checksums, dying mid-transfer) and against
# things that are not boards. Each ends in its documented exit status and a message naming it.
#   own_loop_test.py RCB4_OWN_LOOP RCB4
# SPDX-License-Identifier: BSL-1.0
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish
from standin import StandIn

LOOP, RCB4 = sys.argv[1], sys.argv[2]


def own_loop(device):
    start = time.monotonic()
    p = subprocess.run([LOOP, device], capture_output=True, text=True, timeout=30)
    return p.returncode, p.stdout, p.stderr, time.monotonic() - start


srv = subprocess.Popen([RCB4, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
try:
    dev = srv.stdout.readline().strip()
    rc, out, err, _ = own_loop(dev)
    print(out.rstrip())
    check(rc == 0, f"own_loop on rcb4 serve --pty: exit 0 ({rc}, {err.strip()!r})")
    check("config word 0x" in out and "COM 1250000 baud, output period 10 ms" in out, "it read the config word")
    check("20 servos in " in out and "ICS 19  position  7500" in out, "it read the KHR-3HV's 20 servos, planned")
finally:
    srv.terminate()
    srv.wait(timeout=10)

for kwargs, status, words in [
        ({"silent": True}, 4, "read config: no reply from the board before the deadline"),
        ({"mode": "nack"}, 1, "read config: board answered NACK"),
        ({"mode": "badsum"}, 1, "read config: checksum mismatch"),
        ({"mode": "short"}, 1, "read config: reply status byte neither ACK (06) nor NACK (15)"),
        ({"mode": "cut"}, 1, "read config: the board's reply stopped short of its length before the deadline"),
        ({"mode": "die", "die_after": 2}, 4, "read servos: no reply from the board before the deadline")]:
    board = StandIn(**kwargs)
    rc, out, err, took = own_loop(board.path)
    name = kwargs.get("mode", "silent")
    check(rc == status and words in err and took < 10,
          f"a {name} board: exit {status}, '{words}' in {took:.1f} s (got {rc}: {err.strip().splitlines()[-1:]})")
    if name in ("badsum", "silent"):
        # The link's policy (rcb4/link/exchange_machine.hpp): a read is tried three times in all,
        # each failed attempt named (a resync's ping before the second and third).
        why = "checksum mismatch" if name == "badsum" else "no reply from the board before the deadline"
        check(err.count(f"attempt failed: {why}") == 3 and err.count("retrying") == 2,
              f"a {name} board: each of the three attempts named, two retries ({err.strip().splitlines()})")
        check(took < 1.5 * 3 + 1, f"three attempts of 500 ms and the wire time each ({took:.2f} s)")

rc, out, err, _ = own_loop("/dev/null")
check(rc == 3 and "/dev/null: not a serial port" in err, f"/dev/null: exit 3, not a serial port ({err.strip()!r})")
rc, out, err, _ = own_loop("/dev/ttyNOPE9")
check(rc == 3 and "No such file or directory" in err, f"a missing device: exit 3 ({err.strip()!r})")
finish()
