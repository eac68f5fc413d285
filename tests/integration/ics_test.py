#!/usr/bin/env python3
# `rcb4 ics` (issue 34) on `rcb4 ics serve --pty`: scan, ID, EEPROM backup/set/restore, position,
# temperature, and the refusals (two servos, silent, corrupt, wrong baud, bad values, another
# servo's backup): exit codes and output, nothing written when refused.
# SPDX-License-Identifier: BSL-1.0
import json
import os
import signal
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from checks import check, finish, ics_server, tool  # noqa: E402

RCB4 = sys.argv[1]
run, _ = tool(RCB4)
FACTORY = [n for n in range(1, 65) if 25 <= n <= 26 or 33 <= n <= 50 or 55 <= n <= 56]


def ics_serve(*args):
    return ics_server(RCB4, *args)


def ics(pty, *args, json_out=False):
    pre = ["--device", pty] + (["--json"] if json_out else [])
    return run(*pre, "ics", *args)


def raw(pty):
    rc, out, _ = ics(pty, "eeprom", "show", json_out=True)
    return [int(b, 16) for b in json.loads(out)["raw"].split()] if rc == 0 else None


work = tempfile.mkdtemp(prefix="rcb4-ics-")
os.chdir(work)

with ics_serve() as pty:
    # (the virtual servo is a process on a pty: under load, or under a sanitizer, its first answer
    # can take longer than a real servo's 30 ms, so the scan waits longer here)
    rc, out, err = ics(pty, "scan", "--scan-timeout", "300", json_out=True)
    servos = json.loads(out)["servos"] if rc == 0 else []
    check(rc == 0 and servos == [{"id": 0, "baud": 115200, "ics": "3.6", "stretch": 60, "speed": 127}],
          f"scan finds the servo: ID 0 at 115200, ICS 3.6 (rc {rc}: {out.strip()} {err.strip()})")
    first = raw(pty)
    rc, out, err = ics(pty, "id", "set", "5")
    check(rc == 0 and "ID 0 -> 5" in out, f"id set 5 (rc {rc}: {out.strip()} {err.strip()})")
    rc, out, _ = ics(pty, "id", json_out=True)
    check(rc == 0 and json.loads(out)["id"] == 5, f"--json ics id says 5 ({out.strip()})")
    rc, out, err = ics(pty, "eeprom", "backup", "a.bin")
    check(rc == 0 and os.path.getsize("a.bin") == 64, f"eeprom backup a.bin: 64 bytes (rc {rc} {err.strip()})")
    before = raw(pty)
    check(before is not None and [before[n - 1] for n in FACTORY] == [first[n - 1] for n in FACTORY],
          "the ID write left the factory bytes alone")
    rc, out, err = ics(pty, "--backup-dir", work, "set", "stretch=40", "speed=100")
    check(rc == 0 and "stretch            60 -> 40" in out and "old image is in" in out,
          f"set stretch=40 speed=100 (rc {rc}: {out.strip()} {err.strip()})")
    saved = [f for f in os.listdir(work) if f.startswith("ics-id5-") and f.endswith(".bin")]
    check(len(saved) == 1 and open(saved[0], "rb").read() == bytes(before),
          f"set saved the old image first, byte for byte ({saved})")
    rc, out, _ = ics(pty, "eeprom", "show", json_out=True)
    shown = json.loads(out) if rc == 0 else {}
    check(shown.get("stretch") == 40 and shown.get("speed") == 100 and shown.get("id") == 5,
          f"--json eeprom show names stretch 40 and speed 100 ({out[:120]})")
    rc, out, _ = ics(pty, "eeprom", "show")
    check(rc == 0 and "stretch            40" in out and "speed              100" in out, "eeprom show shows both")
    after_set = raw(pty)
    check([after_set[n - 1] for n in FACTORY] == [before[n - 1] for n in FACTORY], "set left the factory bytes alone")
    changed = [n for n in range(1, 65) if after_set[n - 1] != before[n - 1]]
    check(changed and all(n in (3, 4, 5, 6) for n in changed), f"set changed only bytes 3-6 ({changed})")
    rc, out, err = ics(pty, "eeprom", "restore", "a.bin")
    check(rc == 0 and raw(pty) == before and open("a.bin", "rb").read() == bytes(before),
          f"eeprom restore a.bin brings the image back byte for byte (rc {rc} {err.strip()})")
    rc, out, _ = ics(pty, "eeprom", "restore", "a.bin", json_out=True)
    check(rc == 0 and json.loads(out)["written"] is False and json.loads(out)["backup"] is None,
          f"restoring the same image again writes nothing, no backup ({out.strip()})")
    rc, out, _ = ics(pty, "set", "reverse=on", json_out=True)
    check(rc == 0 and json.loads(out)["changed"] == {"reverse": True}, f"--json set: a flag is a bool ({out.strip()})")
    check(ics(pty, "eeprom", "restore", "a.bin")[0] == 0, "restore after reverse=on")
    rc, out, _ = ics(pty, "id", "set", "5")
    check(rc == 0 and "already" in out, f"id set 5 on ID 5: nothing written ({out.strip()})")
    rc, _, err = ics(pty, "eeprom", "backup", "a.bin")
    check(rc == 2 and "exists" in err and open("a.bin", "rb").read() == bytes(before),
          f"eeprom backup onto an existing file is refused ({err.strip()})")
    rc, _, err = ics(pty, "eeprom", "backup", "a.bin", "--force")
    check(rc == 0, f"eeprom backup --force replaces it ({err.strip()})")
    # Its CRC-32 beside it (trial L5): a bit flipped inside a field's range is caught, nothing written.
    import zlib
    crc = open("a.bin.crc32").read().split()[0] if os.path.exists("a.bin.crc32") else ""
    check(crc == "%08x" % zlib.crc32(open("a.bin", "rb").read()), f"the backup's CRC-32 is beside it ({crc})")
    flipped = bytearray(open("a.bin", "rb").read())
    flipped[14] ^= 1  # byte 15, bit 0: rotation off -> on, a valid image
    with open("flipped.bin", "wb") as f:
        f.write(flipped)
    with open("flipped.bin.crc32", "w") as f:
        f.write(open("a.bin.crc32").read())
    rc, _, err = ics(pty, "eeprom", "restore", "flipped.bin", "--dry-run")
    check(rc == 2 and "the file changed or is damaged" in err and raw(pty) == before,
          f"a backup whose bytes no longer match its .crc32: exit 2, nothing written ({err.strip()})")
    rc, _, err = run("--device", pty, "--trace", "ics", "temperature")
    check(rc == 0 and "->" in err and "A5 04" in err and "<-" in err and "25 04" in err,
          f"--trace shows the exchanges ({err.strip()[:200]})")
    # byte 16's fixed bit 2 and FREE status bit 1 are never written from a file
    good = open("a.bin", "rb").read()
    with open("bits.bin", "wb") as f:
        f.write(good[:15] + bytes([good[15] | 0x6]) + good[16:])
    rc, out, err = ics(pty, "eeprom", "restore", "bits.bin")
    check(rc == 0 and "nothing to change" in out and raw(pty) == before,
          f"restore of a file with byte 16's bits 1 and 2 set writes neither ({out.strip()} {err.strip()})")
    rc, out, err = ics(pty, "eeprom", "show", "a.bin")
    check(rc == 0 and "a.bin: EEPROM backup" in out and "stretch            60" in out,
          f"eeprom show FILE decodes a backup ({err.strip()})")
    rc, out, err = ics(pty, "set", "stretch=41", "--dry-run", json_out=True)
    check(rc == 0 and json.loads(out)["dry_run"] and json.loads(out)["changed"] == {"stretch": 41}
          and raw(pty) == before, f"set --dry-run shows the change, writes nothing ({out.strip()})")
    # damaged backups: a field beyond its range, an unknown baud code
    with open("stretch0.bin", "wb") as f:
        f.write(good[:2] + bytes([0, 0]) + good[4:])
    with open("baud5.bin", "wb") as f:
        f.write(good[:27] + bytes([5]) + good[28:])
    with open("odd.bin", "wb") as f:
        f.write(good[:2] + bytes([5, 1]) + good[4:])
    for name, words in (("stretch0.bin", "stretch 0 (rcb4's range 1..127)"), ("baud5.bin", "baud code is 5"),
                        ("odd.bin", "stored odd")):
        rc, _, err = ics(pty, "eeprom", "restore", name)
        check(rc == 2 and words in err and raw(pty) == before, f"restore {name}: exit 2, nothing written ({err.strip()})")

    rc, out, err = ics(pty, "position", "30", "--wait", json_out=True)
    pos = json.loads(out) if rc == 0 else {}
    check(rc == 0 and abs(pos.get("degrees", 99) - 30) <= 1, f"position 30 --wait: within 1 degree ({out.strip()})")
    rc, out, _ = ics(pty, "position", json_out=True)
    check(rc == 0 and abs(json.loads(out)["degrees"] - 30) <= 1, f"position reads 30 degrees ({out.strip()})")
    rc, out, _ = ics(pty, "position", "8000", json_out=True)
    check(rc == 0 and json.loads(out)["target"]["counts"] == 8000, "position 8000 is counts")
    rc, out, _ = ics(pty, "position", "free", json_out=True)
    check(rc == 0 and json.loads(out)["free"] is True, f"position free ({out.strip()})")
    rc, out, _ = ics(pty, "temperature", json_out=True)
    check(rc == 0 and 1 <= json.loads(out)["temperature"] <= 127, f"temperature reads ({out.strip()})")
    rc, out, _ = ics(pty, "current", json_out=True)
    check(rc == 0 and "amperes" in json.loads(out), f"current reads ({out.strip()})")
    rc, out, _ = ics(pty, "stretch", "50", json_out=True)
    check(rc == 0 and json.loads(out)["stretch"] == 50, "stretch 50 set live")
    # a slow servo: --wait gives up at --max-wait, says it is still moving, one JSON object
    check(ics(pty, "speed", "3")[0] == 0, "speed 3 set live")
    rc, out, err = ics(pty, "position", "-130", "--wait", "--max-wait", "0.3", json_out=True)
    one = json.loads(out) if rc == 1 and out.count("\n") == 1 else {}
    check(rc == 1 and one.get("arrived") is False and "still moving" in one.get("error", ""),
          f"--wait --max-wait 0.3 on a slow servo: exit 1, one JSON object ({out.strip()} {err.strip()})")
    # Ctrl-C ends a wait at its next read: exit 130, said, promptly
    p = subprocess.Popen([RCB4, "--device", pty, "ics", "position", "130", "--wait", "--max-wait", "30"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.5)
    p.send_signal(signal.SIGINT)
    t0 = time.monotonic()
    out, err = p.communicate(timeout=10)
    check(p.returncode == 130 and "interrupted" in err and time.monotonic() - t0 < 2,
          f"Ctrl-C during position --wait: exit 130 at once ({p.returncode}: {err.strip()})")
    check(ics(pty, "speed", "127")[0] == 0, "speed 127 again")

    # refusals: nothing written
    now = raw(pty)
    for args, code, words in [
        (("set", "stretch=0"), 2, "out of range 1..127"),
        (("set", "stretch=200"), 2, "out of range"),
        (("set", "baud=9600"), 2, "115200, 625000 or 1250000"),
        (("set", "id=3"), 2, "ics id set"),
        (("set", "nonsense=1"), 2, "no EEPROM field is called 'nonsense'"),
        (("set", "stretch"), 2, "expected FIELD=VALUE"),
        (("set", "reverse=maybe"), 2, "give on or off"),
        (("set", "slave=on"), 2, "never answer again"),
        (("set", "stretch=40", "stretch=41"), 2, "given twice"),
        (("position", "200"), 2, "degrees (-135..135) or counts"),
        (("position", "north"), 2, "give degrees"),
        (("--id", "7", "eeprom", "show"), 4, "does not answer"),
        (("eeprom", "restore", "missing.bin"), 2, "cannot read"),
    ]:
        rc, out, err = ics(pty, *args)
        check(rc == code and words in err, f"{' '.join(args)}: exit {code}, says '{words}' (rc {rc}: {err.strip()})")
    with open("short.bin", "wb") as f:
        f.write(bytes(10))
    rc, _, err = ics(pty, "eeprom", "restore", "short.bin")
    check(rc == 2 and "holds 10 bytes" in err, f"a 10-byte file is refused ({err.strip()})")
    check(raw(pty) == now, "nothing was written by the refused commands")
    rc, _, err = ics(pty, "--baud", "625000", "id")
    check(rc == 4 and "no ICS servo answers" in err, f"a wrong --baud: exit 4 ({err.strip()})")

# another servo's backup is refused; --force keeps this servo's factory bytes
with ics_serve("--seed", "7") as pty:
    mine = raw(pty)
    rc, out, err = ics(pty, "eeprom", "restore", "a.bin")
    check(rc == 1 and "another servo" in err and raw(pty) == mine,
          f"another servo's backup: exit 1, nothing written ({err.strip()})")
    rc, out, err = ics(pty, "eeprom", "restore", "a.bin", "--force", json_out=True)
    forced = raw(pty)
    check(rc == 0 and [forced[n - 1] for n in FACTORY] == [mine[n - 1] for n in FACTORY] and forced[56:58] == mine[56:58],
          f"--force writes the settings, keeps its factory bytes and ID ({out.strip()} {err.strip()})")

# two servos on one wire: ID work refused, nothing changes
with ics_serve("--servos", "2") as pty:
    rc, out, _ = ics(pty, "scan", json_out=True)
    check(rc == 0 and [s["id"] for s in json.loads(out)["servos"]] == [0, 1], f"scan finds both ({out.strip()})")
    rc, out, _ = ics(pty, "--id", "1", "scan", json_out=True)
    check(rc == 0 and [s["id"] for s in json.loads(out)["servos"]] == [1], f"scan --id 1 asks ID 1 only ({out.strip()})")
    rc, _, err = ics(pty, "id")
    check(rc == 1 and "leave one servo alone" in err, f"id with two servos: the hint is about ID work ({err.strip()})")
    before0 = ics(pty, "--id", "0", "eeprom", "show", json_out=True)[1]
    rc, out, err = ics(pty, "id", "set", "5")
    check(rc == 1 and "more than one device" in err, f"id set with two servos: exit 1 ({err.strip()})")
    rc, out, _ = ics(pty, "--id", "1", "eeprom", "show", json_out=True)
    check(rc == 0 and json.loads(out)["id"] == 1, "servo 1 keeps its ID")
    check(ics(pty, "--id", "0", "eeprom", "show", json_out=True)[1] == before0, "servo 0 unchanged")
    rc, _, err = ics(pty, "eeprom", "show")
    check(rc == 1 and "--id N" in err, f"eeprom show with two servos and no --id: the hint names --id ({err.strip()})")

with ics_serve("--silent") as pty:
    rc, _, err = ics(pty, "id")
    check(rc == 4 and "no ICS servo answers" in err and "ICS mode" in err, f"silent: exit 4 with a hint ({err.strip()})")
    rc, out, _ = ics(pty, "scan")
    check(rc == 4 and "no ICS servo answered" in out, "silent: scan finds nothing, exit 4")

with ics_serve("--corrupt") as pty:
    rc, _, err = ics(pty, "id")
    check(rc == 1 and "corrupt" in err, f"corrupt ID reply: exit 1 ({err.strip()})")
    rc, _, err = ics(pty, "--id", "0", "set", "stretch=30")
    check(rc in (1, 4) and "ics-id0-" not in " ".join(os.listdir(work)), f"corrupt: set refused, nothing saved ({err.strip()})")

with ics_serve("--servo-baud", "1250000", "--ics35", "--servo-id", "3") as pty:
    rc, out, _ = ics(pty, "scan", json_out=True)
    check(rc == 0 and json.loads(out)["servos"] == [{"id": 3, "baud": 1250000, "ics": "3.5", "stretch": 60, "speed": 127}],
          f"scan finds an ICS 3.5 servo at 1.25 M ({out.strip()})")
    rc, out, err = ics(pty, "eeprom", "show")
    check(rc == 0 and "ICS servo 3 at 1250000 baud" in out, f"the baud is found without --baud ({err.strip()})")
    rc, _, err = ics(pty, "position")
    check(rc == 1 and "ICS 3.5" in err, f"a 3.5 servo's position read is refused with why ({err.strip()})")
    rc, _, err = ics(pty, "position", "40", "--wait")
    rc2, out, _ = ics(pty, "position", "free", json_out=True)
    check(rc == 1 and "ICS 3.5" in err and rc2 == 0 and json.loads(out)["counts"] == 7500,
          f"position --wait on a 3.5 servo is refused before it moves ({err.strip()} {out.strip()})")
    rc, out, err = ics(pty, "--baud", "1250000", "set", "baud=115200")
    check(rc == 0 and "now talks at 115200" in out, f"set baud=115200 follows the servo ({out.strip()} {err.strip()})")
    rc, out, _ = ics(pty, "--baud", "115200", "id", json_out=True)
    check(rc == 0 and json.loads(out) == {"id": 3, "baud": 115200}, f"it answers at 115200 now ({out.strip()})")

# slave=on with --force: written, and the servo never answers again
with ics_serve("--servo-id", "2") as pty:
    rc, out, err = ics(pty, "set", "slave=on", "--force")
    check(rc == 0 and "slave now" in out and "not read back" in out,
          f"set slave=on --force writes it, says it was not read back ({out.strip()} {err.strip()})")
    rc, _, err = ics(pty, "id")
    check(rc == 4, f"then the servo never answers ({err.strip()})")

# unplugged during a wait: the line closes under a position read or its write
srv = subprocess.Popen([RCB4, "ics", "serve", "--pty"], stdout=subprocess.PIPE, text=True)
pty = srv.stdout.readline().strip()
check(run("--device", pty, "ics", "speed", "3")[0] == 0, "speed 3 before the unplug")
p = subprocess.Popen([RCB4, "--device", pty, "ics", "position", "130", "--wait", "--max-wait", "30"],
                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
time.sleep(0.5)
srv.kill()
srv.wait(timeout=10)
t0 = time.monotonic()
out, err = p.communicate(timeout=20)
check(p.returncode == 3 and "line closed" in err and "ser2net" not in err and time.monotonic() - t0 < 3,
      f"unplugged during position --wait: exit 3 at once, in ICS words ({p.returncode}: {err.strip()})")

rc, out, err = run("--device", "/dev/nonexistent-ics", "ics", "id")
check(rc == 3, f"a missing device: exit 3 ({err.strip()})")
rc, out, err = run("--json", "ics", "eeprom", "show")
check(rc == 0 and json.loads(out)["stretch"] == 60 and "virtual servo" in err,
      f"without --device: the in-process virtual servo, and it says so ({err.strip()})")
rc, _, err = run("--device", "tcp:127.0.0.1:9", "ics", "id")
check(rc == 2 and "not TCP" in err, f"a tcp: device is refused for ICS ({err.strip()})")
rc, _, err = run("ics", "eeprom", "restore", "/tmp")
check(rc == 2 and "not a file" in err, f"restore of a directory: exit 2 ({err.strip()})")

finish()
