#!/usr/bin/env python3
# The refusals a real robot needs before a motion slot is written or played (issue 30 item 2), as
# a user meets them through the rcb4 tool on rcb4 serve --pty:
#  - a slot a stopped or running program would return into (a CALL of it pending on the board's
#    stack), or the slot its program counter is in, is not written over or erased; other slots are,
#    running or stopped alike;
#  - calls across slots that nest deeper than the board's 16-deep stack, or come back round, are
#    refused before anything is written; the deepest chain that fits plays to its end;
#  - a slot motion list marks broken is not played, by the host or by a button;
#  - a file far too large for a motion is refused by its size, at once.
#   motion_safety_test.py RCB4
# SPDX-License-Identifier: BSL-1.0
import json
import os
import sys
import tempfile
import time
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish, tool

RCB4 = sys.argv[1]
run, serve = tool(RCB4)
work = tempfile.mkdtemp(prefix="rcb4-motion-safety-")
os.chdir(work)

SLOT = 0x0B80  # HTH4 2.2+: motion N at 0x0B80 + (N-1) * 0x800 (motions.md §2)


def slot(n):
    return SLOT + (n - 1) * 0x800


def write(name, text):
    with open(name, "w") as f:
        f.write(text)


def rom(on, address, n):
    rc, out, err = run("--json", *on, "read", "rom", hex(address), str(n))
    return bytes(json.loads(out)["bytes"]) if rc == 0 else b""


def status(on):
    rc, out, err = run("--json", *on, "motion", "status")
    return json.loads(out) if rc == 0 else {}


def wait_for(on, cond, seconds=5):
    until = time.monotonic() + seconds
    st = status(on)
    while not cond(st) and time.monotonic() < until:
        time.sleep(0.05)
        st = status(on)
    return st


HEAD = "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n"
write("forever.yaml", HEAD + "  - label: top\n  - pose: {head_yaw: 10}\n    time_ms: 300\n"
      "  - pose: {head_yaw: -10}\n    time_ms: 300\n  - goto: top\n")
write("call31.yaml", HEAD + "  - pose: {head_yaw: 5}\n    time_ms: 150\n  - call: 31\n  - end\n")
write("nod.yaml", HEAD + "  - pose: {head_yaw: 15}\n    time_ms: 150\n  - end\n")

with serve("--period", "15") as dev:
    on = ["--device", dev]
    # Motion 30 calls motion 31, which never ends; stopped inside 31, motion 30's CALL is on the stack.
    for f, n in (("forever.yaml", "31"), ("call31.yaml", "30"), ("nod.yaml", "32")):
        rc, out, err = run(*on, "motion", "push", f, n, "--backup", f"old{n}.bin")
        check(rc == 0, f"push {f} into motion {n} ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "30")
    st = wait_for(on, lambda s: s.get("motion") == 31)
    check(rc == 0 and st.get("running") and st.get("motion") == 31, f"motion 30 plays and runs inside motion 31 ({st})")
    # Running: the slot it would return into, and its own, are refused; an unrelated slot is not.
    before30 = rom(on, slot(30), 64)
    rc, out, err = run(*on, "motion", "push", "nod.yaml", "30", "--backup", "r30.bin")
    check(rc == 1 and "return into motion 30" in err and "call stack" in err and rom(on, slot(30), 64) == before30
          and not os.path.exists("r30.bin"),
          f"running inside 31: a push over 30 (its caller) refused, ROM unchanged, no backup ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "erase", "31", "--backup", "r31.bin")
    check(rc == 1 and "motion 31 is running" in err, f"running: erase of its own slot refused ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "nod.yaml", "33", "--backup", "r33.bin")
    check(rc == 0, f"running: a push to a slot it neither runs, calls nor returns into is written ({rc}: {err.strip()!r})")
    # Stopped part way inside 31: the same refusals, in the words of a resume.
    run(*on, "motion", "stop")
    st = status(on)
    check(not st.get("running") and st.get("motion") == 31, f"stopped part way inside motion 31 ({st})")
    rc, out, err = run(*on, "motion", "push", "nod.yaml", "30", "--backup", "s30.bin")
    check(rc == 1 and "motion resume would return into the bytes being written" in err
          and rom(on, slot(30), 64) == before30 and not os.path.exists("s30.bin"),
          f"stopped inside 31: a push over its caller 30 refused, ROM unchanged ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "erase", "30", "--backup", "s30.bin")
    check(rc == 1 and "return into" in err and rom(on, slot(30), 64) == before30,
          f"stopped inside 31: erase of 30 refused ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "erase", "31", "--backup", "s31.bin")
    check(rc == 1 and "stopped part way" in err and "motion resume would continue" in err,
          f"stopped inside 31: erase of 31 refused ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "forever.yaml", "34", "--backup", "s34.bin")
    check(rc == 0, f"stopped: a push to an unrelated slot is written, as while running ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "32", "--wait", "--timeout", "5")
    check(rc == 0, f"motion play 32 starts afresh ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "nod.yaml", "30", "--backup", "f30.bin")
    check(rc == 0, f"after a fresh play, motion 30 is written ({rc}: {err.strip()!r})")

    # A chain of calls: motion 60 a pose, each of 59..44 calls the next. Motion 45 (play + 15
    # calls = 16 levels) fits the stack and plays to its end; motion 44 would need 17: refused.
    run(*on, "motion", "push", "nod.yaml", "60", "--backup", "c60.bin")
    ok = True
    for n in range(59, 44, -1):
        write(f"c{n}.yaml", HEAD + f"  - call: {n + 1}\n  - end\n")
        rc, out, err = run(*on, "motion", "push", f"c{n}.yaml", str(n), "--backup", f"c{n}.bin")
        ok = ok and rc == 0
    check(ok, "a chain of 15 calls across motions 45..60 pushed")
    rc, out, err = run(*on, "motion", "play", "45", "--wait", "--timeout", "10")
    rc2, cfg, _ = run("--json", *on, "config")
    check(rc == 0 and not json.loads(cfg).get("program_error", True) if rc2 == 0 else False,
          f"motion 45 (16 levels of the stack) plays to its end, no program error ({rc}: {err.strip()!r} {cfg.strip()!r})")
    write("c44.yaml", HEAD + "  - call: 45\n  - end\n")
    before44 = rom(on, slot(44), 16)
    rc, out, err = run(*on, "motion", "push", "c44.yaml", "44", "--backup", "c44.bin")
    check(rc == 1 and "nest 16 deep" in err and "17 levels of the board's 16-deep call stack" in err
          and f"motion 45 (0x{slot(45):06X}) -> motion 46" in err and rom(on, slot(44), 16) == before44
          and not os.path.exists("c44.bin"),
          f"a chain of 16 calls (17 levels) refused at push, nothing written ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "c44.yaml", "44", "--dry-run")
    check(rc == 1 and "17 levels" in err, f"--dry-run refuses it too ({rc}: {err.strip()!r})")
    # The chain deepened from its end: the callers are checked again. Motion 60 calling 61 would
    # make motion 45 (which reaches 60 through 46..59) need 17 levels: refused, nothing written.
    run(*on, "motion", "push", "nod.yaml", "61", "--backup", "c61.bin")
    write("c60deep.yaml", HEAD + "  - call: 61\n  - end\n")
    before60 = rom(on, slot(60), 16)
    rc, out, err = run(*on, "motion", "push", "c60deep.yaml", "60", "--backup", "c60d.bin")
    check(rc == 1 and f"motion 45 (0x{slot(45):06X}) calls it" in err and "17 levels" in err
          and rom(on, slot(60), 16) == before60 and not os.path.exists("c60d.bin"),
          f"a push that deepens a chain from its end: refused for its caller, nothing written ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "c60deep.yaml", "60", "--dry-run")
    check(rc == 1 and "calls it" in err, f"--dry-run refuses it too ({rc}: {err.strip()!r})")
    # Mutual recursion: 70 calls 71, then 71 calling 70 is refused.
    run(*on, "motion", "push", "nod.yaml", "71", "--backup", "m71.bin")
    write("c70.yaml", HEAD + "  - call: 71\n  - end\n")
    write("c71.yaml", HEAD + "  - pose: {head_yaw: 3}\n    time_ms: 150\n  - call: 70\n  - end\n")
    run(*on, "motion", "push", "c70.yaml", "70", "--backup", "m70.bin")
    before71 = rom(on, slot(71), 32)
    rc, out, err = run(*on, "motion", "push", "c71.yaml", "71", "--backup", "m71b.bin")
    check(rc == 1 and "come back round" in err and f"motion 71 (0x{slot(71):06X}) -> motion 70 (0x{slot(70):06X}) -> motion 71" in err
          and "step 2 (c71.yaml:6) calls" not in err and rom(on, slot(71), 32) == before71,
          f"mutual recursion 71 -> 70 -> 71 refused, nothing written ({rc}: {err.strip()!r})")

    # A half-written slot (its second frame fails its checksum, as motion list marks it broken):
    # refused by motion play and by a button, as an empty slot is.
    run(*on, "motion", "push", "nod.yaml", "80", "--backup", "b80.bin")
    rc, out, err = run(*on, "motion", "buttons", "set", "s1+up", "80")
    check(rc == 0, f"a button set to play motion 80 ({rc}: {err.strip()!r})")
    first = rom(on, slot(80), 1)  # the pose's frame; its RETURN follows
    after = slot(80) + (first[0] if first else 11)
    run(*on, "write", "rom", hex(after), "07 0B 00 00 00 00 00")  # a JUMP whose checksum is wrong
    rc, out, err = run("--json", *on, "motion", "list")
    listed = [m for m in json.loads(out)["motions"] if m.get("slot") == 80] if rc == 0 else []
    check(len(listed) == 1 and not listed[0].get("ends", True), f"motion list marks motion 80 broken ({listed})")
    rc, out, err = run(*on, "motion", "play", "80")
    st = status(on)
    check(rc == 1 and f"rcb4 motion play: motion 80 (0x{slot(80):06X}) is broken" in err and "checksum" in err
          and not st.get("running"), f"motion play of a broken slot refused, nothing started ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "set", "s2+up", "80")
    check(rc == 1 and "is broken" in err, f"a button is not set to play a broken slot ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "press", "s1+up")
    check(rc == 1 and "is broken" in err and not status(on).get("running"),
          f"a button playing a broken slot: press refused ({rc}: {err.strip()!r})")
    # Buttons with no entry are held as a receiver holds them (a motion's if_buttons sees them).
    rc, out, err = run(*on, "motion", "buttons", "press", "triangle+square", "--hold")
    rc2, ram, _ = run("--json", *on, "read", "ram", "0x0350", "2")
    held = bytes(json.loads(ram)["bytes"]) if rc2 == 0 else b""
    check(rc == 0 and "held" in out and held != b"\x00\x00",
          f"press --hold of buttons without an entry holds them ({rc}: {out.strip()!r} {err.strip()!r} {held.hex()})")
    rc, out, err = run(*on, "motion", "buttons", "press", "triangle+square")
    check(rc == 1 and "no entry of the table plays anything" in err and "--hold" in err,
          f"press without --hold and no entry: refused, saying --hold ({rc}: {err.strip()!r})")
    # An entry for the buttons held now would start its motion the moment it is written.
    rc, out, err = run(*on, "motion", "buttons", "set", "triangle+square", "1")
    check(rc == 1 and "are held now" in err and "release" in err and not status(on).get("running"),
          f"buttons set of the buttons held now: refused, nothing played ({rc}: {err.strip()!r})")
    run(*on, "motion", "buttons", "release")
    rc, out, err = run(*on, "motion", "buttons", "set", "triangle+square", "1")
    check(rc == 0 and not status(on).get("running"), f"released, the entry is set and nothing plays ({rc}: {err.strip()!r})")
    run(*on, "motion", "buttons", "clear", "triangle+square")

    # A loop with no way out (goto, no RETURN) plays until stopped: listed as endless, not broken.
    write("loop.yaml", HEAD + "  - label: top\n  - pose: {head_yaw: 20}\n    time_ms: 150\n"
                              "  - pose: {head_yaw: -20}\n    time_ms: 150\n  - goto: top\n")
    write("calls_loop.yaml", HEAD + "  - pose: {left_knee: 40}\n    time_ms: 900\n  - call: 93\n  - end\n")
    run(*on, "motion", "push", "loop.yaml", "93")
    run(*on, "motion", "push", "calls_loop.yaml", "94")

    def listed(n):
        rc, out, _ = run("--json", *on, "motion", "list")
        return next((m for m in json.loads(out)["motions"] if m["slot"] == n), {}) if rc == 0 else {}
    m93, m94 = listed(93), listed(94)
    check(m93.get("endless") is True and m93.get("broken") is False and m94.get("broken") is False,
          f"motion list: a goto loop is endless, not broken, and so is its caller ({m93}, {m94})")
    rc, out, err = run(*on, "motion", "list")
    line = next((x for x in out.splitlines() if x.strip().startswith("93 ")), "")
    check(rc == 0 and "for ever" in line and "broken" not in line, f"motion list's line for 93: for ever ({line!r})")
    # Its callee erased: the erase says who calls it, the caller is listed broken and not played.
    rc, out, err = run(*on, "motion", "erase", "93")
    check(rc == 0 and "note: motion 94 calls it" in err, f"erase of a called slot names its caller ({rc}: {err.strip()!r})")
    m94 = listed(94)
    check(m94.get("broken") is True and "calls motion 93, which holds no motion" in (m94.get("problem") or ""),
          f"motion list: the caller of an empty slot is broken ({m94})")
    rc, out, _ = run("--json", *on, "joint", "list")
    before = {j["name"]: j["degrees"] for j in json.loads(out)} if rc == 0 else {}
    rc, out, err = run(*on, "motion", "play", "94")
    time.sleep(0.3)
    rc2, out2, _ = run("--json", *on, "joint", "list")
    after = {j["name"]: j["degrees"] for j in json.loads(out2)} if rc2 == 0 else {}
    check(rc == 1 and "motion 94 calls motion 93 (0x" in err and "holds no motion" in err and not status(on).get("running")
          and before.get("left_knee") == after.get("left_knee"),
          f"motion play of a caller of an empty slot: refused before anything moves ({rc}: {err.strip()!r}; knee {before.get('left_knee')} -> {after.get('left_knee')})")
    rc, out, err = run(*on, "motion", "buttons", "set", "s4", "94")
    check(rc == 1 and "holds no motion" in err, f"nor is a button set to play it ({rc}: {err.strip()!r})")
    run(*on, "motion", "erase", "94")

    # A file far larger than any motion: refused by its size, at once, nothing written.
    with open("huge.yaml", "w") as f:
        f.write(HEAD)
        f.seek(50 * 1024 * 1024)
        f.write("\n")
    t0 = time.monotonic()
    rc, out, err = run(*on, "motion", "push", "huge.yaml", "90")
    took = time.monotonic() - t0
    check(rc == 2 and "more than 4 MiB" in err and took < 5, f"a 50 MB motion file refused by its size in {took:.2f} s ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "huge.yaml")
    check(rc == 2 and "more than 4 MiB" in err, f"motion play of it too ({rc}: {err.strip()!r})")

# The ROM restored: the button table the board compares (RAM) follows it, so what `buttons` lists
# is what a press does and what `buttons clear` removes; an image that is no RCB-4 program is
# refused unless forced, even with --no-check.

def with_crc(name, data):
    with open(name, "wb") as f:
        f.write(data)
    with open(name + ".crc32", "w") as f:
        f.write(f"{zlib.crc32(data):08x}  {name}\n")


with serve() as dev:
    on = ["--device", dev]
    rc, out, err = run(*on, "motion", "buttons", "set", "s2+down", "2")
    rc2, out2, err2 = run(*on, "rom", "backup", "with-s2.bin")
    check(rc == 0 and rc2 == 0, f"s2+down plays motion 2; ROM backed up ({rc} {rc2}: {err.strip()!r} {err2.strip()!r})")
    run(*on, "motion", "buttons", "reset")
    rc, out, err = run(*on, "rom", "restore", "with-s2.bin")
    rc2, b, _ = run("--json", *on, "motion", "buttons")
    b = json.loads(b) if rc2 == 0 else {}
    ram = [e["buttons"] for e in b.get("ram", {}).get("entries", [])]
    check(rc == 0 and "the button table the board compares (RAM) now is the restored one" in out
          and b.get("same") is True and "down+s2" in ram,
          f"rom restore: RAM's table is the restored one, RAM and ROM the same ({rc}: {out.strip()!r} {ram} {b.get('same')})")
    # A restore leaves the ROM program off: status says so (buttons would play nothing).
    rc, out, err = run(*on, "motion", "status")
    check(rc == 0 and "the ROM program is off" in out and status(on).get("program_on") is False,
          f"motion status after a restore: the ROM program is off ({rc}: {out.strip()!r})")
    run(*on, "motion", "resume")
    check(status(on).get("program_on") is True, "motion resume lets it run")
    rc, out, err = run(*on, "motion", "buttons", "clear", "s2+down")
    rc2, b, _ = run("--json", *on, "motion", "buttons")
    b = json.loads(b) if rc2 == 0 else {}
    lists = [e["buttons"] for t in ("ram", "rom") for e in b.get(t, {}).get("entries", [])]
    check(rc == 0 and "down+s2" not in lists and b.get("same") is True,
          f"buttons clear after a restore removes what buttons lists ({rc}: {err.strip()!r})")
    # An entry only RAM holds (ROM's table erased by hand): listed, and cleared.
    run(*on, "motion", "buttons", "set", "s3", "1")
    run(*on, "write", "rom", "0x091B", "FF " * 16)
    rc2, b, _ = run("--json", *on, "motion", "buttons")
    b = json.loads(b) if rc2 == 0 else {}
    listed = [e["buttons"] for e in b.get("ram", {}).get("entries", [])]
    rc, out, err = run(*on, "motion", "buttons", "clear", "s3")
    rc3, b2, _ = run("--json", *on, "motion", "buttons")
    b2 = json.loads(b2) if rc3 == 0 else {}
    check("s3" in listed and rc == 0 and "s3" not in [e["buttons"] for e in b2.get("ram", {}).get("entries", [])],
          f"an entry only RAM holds is cleared ({listed} {rc}: {err.strip()!r} {b2.get('ram')})")
    # ROM's table damaged after its first entry: the listing shows the entry and then the problem.
    run(*on, "motion", "buttons", "set", "s3", "1")
    run(*on, "motion", "buttons", "set", "s4", "2")
    run(*on, "write", "rom", "0x0923", "FF " * 8)
    rc, out, err = run(*on, "motion", "buttons")
    rom_part = out.split("ROM (what the board loads at power-on) differs:")[-1]
    check(rc == 0 and "then: " in rom_part and "buttons reset" in rom_part,
          f"motion buttons shows a ROM table's problem after its entries ({rc}: {out.strip()!r})")
    run(*on, "motion", "buttons", "reset")
    # Images that are no RCB-4 program.
    good = open("with-s2.bin", "rb").read()
    with_crc("erased.bin", b"\xff" * len(good))
    no_motion1 = bytearray(good)
    no_motion1[0x0B80:0x0B80 + 0x800] = b"\xff" * 0x800
    with_crc("nomotion1.bin", bytes(no_motion1))
    no_boot = bytearray(good)
    no_boot[0:16] = b"\xff" * 16
    with_crc("noboot.bin", bytes(no_boot))
    rc0, before, _ = run("--json", *on, "read", "rom", "0", "16")
    for name, words in (("erased.bin", "no boot code at 0x000000"), ("nomotion1.bin", "its HTH4 layout cannot be told"),
                        ("noboot.bin", "no boot code")):
        for extra in ([], ["--no-check"]):
            rc, out, err = run(*on, "rom", "restore", name, *extra)
            check(rc == 2 and "not a plausible RCB-4 ROM" in err and words in err and "--force" in err,
                  f"rom restore {name} {' '.join(extra)}: refused, exit 2 ({rc}: {err.strip()!r})")
    rc1, after, _ = run("--json", *on, "read", "rom", "0", "16")
    check(rc0 == 0 and before == after, "nothing was written")
    rc, out, err = run(*on, "rom", "restore", "nomotion1.bin", "--force")
    check(rc == 0 and "wrote" in out and rom(on, SLOT, 4) == b"\xff" * 4,
          f"--force writes it all the same ({rc}: {out.strip()!r} {err.strip()!r})")

finish()
