#!/usr/bin/env python3
# `rcb4 ics` on a line that lies (issue 40): a relay pty between the tool and `rcb4 ics serve --pty`
# delivers 0x00 in place of one byte of an EEPROM read, the way Linux delivers a byte that failed
# its parity check (termios INPCK without PARMRK). The servo's EEPROM and the backup stay exactly as
# they were or as the user asked; a line that garbles every read is refused, nothing written. Also:
# a backup of values outside rcb4's ranges (written by another tool) goes back with --force.
# SPDX-License-Identifier: BSL-1.0
import contextlib
import glob
import json
import os
import pty
import re
import select
import sys
import tempfile
import threading
import tty

sys.path.insert(0, os.path.dirname(__file__))
from checks import check, finish, ics_server, tool  # noqa: E402

RCB4 = sys.argv[1]
run, _ = tool(RCB4)


def ics_serve(*args):
    return ics_server(RCB4, *args)


@contextlib.contextmanager
def relay(server, zero_reads, image_byte=6):
    """A pty whose bytes go to @p server and back; in the EEPROM reads numbered in @p zero_reads
    (0: the first; "all": every one, a different byte each time) image byte @p image_byte is 0x00."""
    master, slave = pty.openpty()
    tty.setraw(slave)
    path = os.ttyname(slave)
    far = os.open(server, os.O_RDWR | os.O_NOCTTY)
    tty.setraw(far)
    stop = threading.Event()
    state = {"reads": 0, "left": 0, "at": 0}

    def pump():
        while not stop.is_set():
            ready, _, _ = select.select([master, far], [], [], 0.05)
            if master in ready:
                try:
                    data = os.read(master, 4096)
                except OSError:
                    data = b""
                if data:
                    # an EEPROM read: 2 bytes, 0xA0 | ID, sub-command 0 (ics.md §2.3)
                    if len(data) == 2 and data[0] & 0xE0 == 0xA0 and data[1] == 0:
                        n = state["reads"]
                        state["reads"] += 1
                        if zero_reads == "all" or n in zero_reads:
                            state["left"] = 68  # echo 2, header 2, image 64
                            state["at"] = 4 + image_byte - 1 + (n if zero_reads == "all" else 0)
                    os.write(far, data)
            if far in ready:
                try:
                    data = bytearray(os.read(far, 4096))
                except OSError:
                    data = bytearray()
                if data and state["left"]:
                    done = 68 - state["left"]
                    i = state["at"] - done
                    if 0 <= i < len(data):
                        data[i] = 0
                    state["left"] = max(0, state["left"] - len(data))
                if data:
                    os.write(master, bytes(data))

    t = threading.Thread(target=pump, daemon=True)
    t.start()
    try:
        yield path, state
    finally:
        stop.set()
        t.join(timeout=2)
        for fd in (master, slave, far):
            os.close(fd)


def ics(device, *args, json_out=False):
    return run("--device", device, "--baud", "115200", *(["--json"] if json_out else []), "ics", *args)


def raw(device):
    rc, out, _ = ics(device, "eeprom", "show", json_out=True)
    return bytes(int(b, 16) for b in json.loads(out)["raw"].split()) if rc == 0 else None


work = tempfile.mkdtemp(prefix="rcb4-ics-line-")
os.chdir(work)

with ics_serve() as server:
    truth = raw(server)
    check(truth is not None and truth[5] != 0, "the servo's image, read directly (byte 6 is not 0 already)")
    # set stretch=50 through a line that zeroes byte 6 (speed's low nibble) of the first EEPROM read
    with relay(server, [0]) as (line, state):
        rc, out, err = ics(line, "--backup-dir", work, "set", "stretch=50")
        reads = state["reads"]
    check(rc == 0 and "stretch" in out and "speed" not in out, f"set stretch=50 through the lying line: only stretch "
                                                                 f"changes (rc {rc}: {out.strip()} {err.strip()})")
    check(reads >= 3, f"the image was read until two reads agreed, then read back ({reads} EEPROM reads)")
    after = raw(server)
    want = bytearray(truth)
    want[2], want[3] = 100 >> 4, 100 & 0xF  # stretch 50, stored doubled (bytes 3-4)
    check(after == bytes(want), f"the servo holds its old image but the stretch (speed byte 6 {after[5]:X}, "
                                f"was {truth[5]:X})")
    backups = glob.glob(os.path.join(work, "ics-id0-*.bin"))
    check(len(backups) == 1 and open(backups[0], "rb").read() == truth,
          f"the automatic backup is the servo's true image, byte for byte ({backups})")

    # the same through `eeprom backup` and `eeprom show`
    with relay(server, [0]) as (line, _):
        rc, _, err = ics(line, "eeprom", "backup", "b.bin")
    check(rc == 0 and open("b.bin", "rb").read() == after, f"eeprom backup through the lying line is true ({err.strip()})")
    with relay(server, [0]) as (line, _):
        shown = raw(line)
    check(shown == after, "eeprom show through the lying line shows the true image")

    # a line that garbles every read: refused with both images, nothing written, no backup
    for f in glob.glob(os.path.join(work, "ics-id0-*.bin")):
        os.remove(f)
    with relay(server, "all", image_byte=3) as (line, state):  # bytes 3-6: stretch 50, speed 127, none 0
        rc, out, err = ics(line, "--backup-dir", work, "set", "stretch=40")
    check(rc == 1 and "never agreed" in err and "read 1:" in err and "read 2:" in err,
          f"a line whose reads never agree: exit 1, both images shown ({err.strip()[:300]})")
    check(raw(server) == after and not glob.glob(os.path.join(work, "ics-id0-*.bin")),
          "nothing written, no backup saved")

    # another tool wrote dead band 15 and an odd stretch_1: the user's backup of that goes back with --force
    theirs = bytearray(after)
    theirs[8], theirs[9] = 0x0, 0xF  # dead band 15 (bytes 9-10)
    theirs[58], theirs[59] = 0x6, 0x5  # stretch_1 stored 0x65, odd (bytes 59-60)
    with open("theirs.bin", "wb") as f:
        f.write(bytes(theirs))
    rc, _, err = ics(server, "eeprom", "restore", "theirs.bin")
    check(rc == 2 and "dead_band 15" in err and "stretch_1 stored odd" in err and "--force" in err
          and raw(server) == after, f"restore of values outside rcb4's ranges: exit 2, named, nothing written "
                                    f"({err.strip()[:300]})")
    rc, out, err = ics(server, "eeprom", "show", "theirs.bin")
    check(rc == 0 and "15" in out and "50.5 (stored odd)" in out, f"eeprom show FILE shows the odd stretch ({err.strip()})")
    rc, out, err = ics(server, "eeprom", "restore", "theirs.bin", "--force")
    check(rc == 0 and "dead_band" in out and raw(server) == bytes(theirs),
          f"restore --force writes it byte for byte, after showing the fields (rc {rc}: {out.strip()} {err.strip()})")
    rc, out, err = ics(server, "--backup-dir", work, "set", "dead_band=4")
    named = re.search(r"the old image is in (\S+\.bin)", out)
    saved = named.group(1) if named else "none"
    check(rc == 0 and os.path.exists(saved) and open(saved, "rb").read() == bytes(theirs),
          f"set dead_band=4 saves that image ({out.strip()} {err.strip()})")
    rc, out, err = ics(server, "eeprom", "restore", saved, "--force")
    check(rc == 0 and raw(server) == bytes(theirs), f"and its own backup goes back with --force ({err.strip()})")
    rc, out, err = ics(server, "set", "stretch_1=50")
    check(rc == 0 and "nothing to change" not in out and raw(server)[58:60] == bytes([0x6, 0x4]),
          f"set stretch_1=50 on an odd stored 50.5 rewrites it ({out.strip()} {err.strip()})")
    rc, out, _ = ics(server, "position", "free")
    rc, out, _ = ics(server, "eeprom", "show", json_out=True)
    check(rc == 0 and json.loads(out)["free"] is True, "the FREE status bit shows a limp servo")
    rc, out, _ = ics(server, "position", "10")
    rc, out, _ = ics(server, "eeprom", "show", json_out=True)
    check(rc == 0 and json.loads(out)["free"] is False, "and a holding one")

finish()
