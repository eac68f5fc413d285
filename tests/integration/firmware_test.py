#!/usr/bin/env python3
# The example firmware (examples/firmware) in Debian's qemu-system-arm: a Cortex-M4 (MPS2 AN386)
# whose UART0 is connected to `rcb4 serve --tcp`. The firmware pings, reads the config word,
# reads every servo through the planner and moves two servos with one CONST; the test checks its
# semihosting exit status and output, then asks the board itself (through the rcb4 tool) where
# the two servos went. Then the same firmware against boards that misbehave (tests/integration/
# standin.py over TCP): silent, NACK, bad checksums; each must end in its documented exit status.
#   firmware_test.py FIRMWARE.elf RCB4 [arm-none-eabi-size]
# SPDX-License-Identifier: BSL-1.0
import glob
import json
import os
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish
from standin import StandIn

ELF, RCB4 = sys.argv[1], sys.argv[2]
SIZE = sys.argv[3] if len(sys.argv) > 3 and os.path.exists(sys.argv[3]) else shutil.which("arm-none-eabi-size")
QEMU = shutil.which("qemu-system-arm")
DEADLINE = 60  # QEMU may hold the first byte ~1 s; a firmware stuck on the UART never exits

if QEMU is None:
    print("SKIPPED: qemu-system-arm is not installed (cmake/install-deps.sh installs it)")
    sys.exit(77)

# Budgets (docs/firmware.md), set from the figures measured on 2026-11-28 with a little room: a
# change that grows the image or its stack past them must say why, here and in the docs.
#   11,360 bytes of code, 0 of data, 260 of bss, a worst stack of 3,848 bytes: the firmware's own
#          exchange loop (retry a read after draining the line);
#   15,852 / 0 / 16 / 4,672: the library's link (rcb4/link/: a resync by ping after any error,
#          reads tried three times, a loopback named, damaged bytes refused, a stop) in place of
#          that loop, and a clock widened to 64 bits.
BUDGET_TEXT, BUDGET_DATA, BUDGET_BSS, BUDGET_STACK = 16500, 0, 288, 4800

if SIZE:
    out = subprocess.run([SIZE, ELF], capture_output=True, text=True).stdout.split("\n")
    text, data, bss = out[1].split()[:3]
    print(f"firmware image: {text} bytes of code, {data} of data, {bss} of bss ({os.path.basename(ELF)})")
    check(int(text) <= BUDGET_TEXT and int(data) <= BUDGET_DATA and int(bss) <= BUDGET_BSS,
          f"the image within its budget: code {text} <= {BUDGET_TEXT}, data {data} <= {BUDGET_DATA}, "
          f"bss {bss} <= {BUDGET_BSS}")
    # No heap: nothing in the image allocates (malloc, operator new) or grows one (_sbrk).
    nm = subprocess.run([SIZE[:-len("size")] + "nm", ELF], capture_output=True, text=True).stdout.split()
    heap = sorted({s for s in nm if s in ("malloc", "_malloc_r", "calloc", "realloc", "_sbrk", "_sbrk_r", "_Znwj", "_Znaj",
                                          "_ZnwjRKSt9nothrow_t", "_ZnajRKSt9nothrow_t", "free")})
    check(nm and not heap, f"the image has no heap: no malloc, operator new or _sbrk ({heap})")


# The worst stack, from GCC's call graph (-fcallgraph-info=su): the deepest path from the reset
# handler plus the interrupts on top (tests/support/stack_usage.py).
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
import stack_usage  # noqa: E402

graphs = sorted(glob.glob(ELF + "-*.ci"))
check(len(graphs) == 2, f"the build wrote the firmware's call graphs ({[os.path.basename(g) for g in graphs]})")
if graphs:
    stack, main_bytes, path, handlers, problems, indirect = stack_usage.analyse(graphs)
    print(f"firmware worst stack: {stack} bytes ({main_bytes} on the deepest path from reset, then the interrupts); the path:")
    for step in path:
        print("    " + step)
    check(not problems, f"every path's stack is bounded: no recursion, no dynamic frame ({problems})")
    check(stack <= BUDGET_STACK, f"the worst stack within its budget: {stack} <= {BUDGET_STACK} bytes")


def firmware(address):
    """Runs the firmware with its UART on TCP ADDRESS; returns (exit status, output). QEMU is
    killed at the deadline: a firmware that hangs fails clearly instead of hanging the suite."""
    cmd = [QEMU, "-M", "mps2-an386", "-display", "none", "-monitor", "none", "-nodefaults", "-nic", "none",
           "-serial", f"tcp:{address}", "-semihosting-config", "enable=on,target=native", "-kernel", ELF]
    start = time.monotonic()
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=DEADLINE)
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode() if isinstance(e.stdout, bytes) else (e.stdout or "")
        return None, out + f"\n(killed after {DEADLINE} s: the firmware did not exit)"
    print(f"  (QEMU ran {time.monotonic() - start:.1f} s, exit status {p.returncode})")
    return p.returncode, p.stdout + p.stderr


# --- against the virtual board ------------------------------------------------------------------
srv = subprocess.Popen([RCB4, "serve", "--tcp", "127.0.0.1:0"], stdout=subprocess.PIPE, text=True)
try:
    address = srv.stdout.readline().strip()
    rc, out = firmware(address)
    print(out.rstrip())
    check(rc == 0, f"the firmware ends with exit status 0 on rcb4 serve (got {rc})")
    check("ping: ACK" in out, "it pinged the board")
    check("config: 0x" in out and "baud 1250000" in out, "it read and decoded the config word")
    check("servos: 20 allocated, read in" in out, "it read the 20 servos of the KHR-3HV through the planner")
    check("  ICS 0: position 7500" in out, "ICS 0 is at the centre (7500) before the move")
    check("move: ICS 0 -> 8500, ICS 1 -> 6500, 10 frames: ACK" in out, "one CONST frame moved two servos")
    check("arrived: ICS 0 at 8500, ICS 1 at 6500" in out, "the firmware read them back at their targets")
    # The board, asked by another program after the firmware has gone: the two servos are there.
    p = subprocess.run([RCB4, "--json", "--device", f"tcp:{address}", "servo", "get", "0", "1", "2"],
                       capture_output=True, text=True, timeout=30)
    states = {s["ics"]: s for s in json.loads(p.stdout)} if p.returncode == 0 else {}
    check(p.returncode == 0 and states.get(0, {}).get("target") == 8500 and states.get(1, {}).get("target") == 6500
          and states.get(2, {}).get("target") == 7500,
          f"rcb4 servo get: ICS 0 and 1 hold 8500 and 6500, ICS 2 did not move ({p.returncode}, {p.stderr.strip()!r})")
finally:
    srv.terminate()
    srv.wait(timeout=10)

# --- against boards that misbehave ---------------------------------------------------------------
for mode, silent, status, words in [
        (None, True, 1, "the board did not answer in time"),
        ("nack", False, 3, "ping: NACK"),
        ("badsum", False, 2, "ping: checksum mismatch"),
        ("short", False, 2, "read config: reply status byte neither ACK (06) nor NACK (15)")]:
    board = StandIn(silent=silent, mode=mode, tcp=True)
    rc, out = firmware(board.path)
    name = mode or "silent"
    check(rc == status and words in out,
          f"a {name} board: exit status {status} and '{words}' (got {rc}: {out.strip().splitlines()[-1:]})")
    if name == "badsum":  # the link's policy: a read (a ping) is tried three times, each failure named
        check(out.count("attempt failed: checksum mismatch") == 3,
              f"a badsum board: each of the ping's three attempts named ({out.count('attempt failed')} lines)")

finish()
