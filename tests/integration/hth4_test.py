#!/usr/bin/env python3
# HeartToHeart4 projects and trim files through the rcb4 tool as an HTH4 user moving to Linux uses
# them (issue 32), on `rcb4 serve --pty`: a project written in HTH4's schema (tests/data/hth4, not
# by rcb4's writer) dry-run (nothing written), imported (motions at their addresses, the button,
# the trims, the motions play), exported and imported again (the ROM unchanged), a 2.0-layout
# project moved to the board's layout, and what must be refused with nothing written: a damaged
# file, a board whose motion runs, an existing export file; a trim file by ICS number.
#   hth4_test.py RCB4 DATA_DIR
# SPDX-License-Identifier: BSL-1.0
import json
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish, tool

RCB4, DATA = sys.argv[1], sys.argv[2]
run, serve = tool(RCB4)
work = tempfile.mkdtemp(prefix="rcb4-hth4-")
os.chdir(work)  # the ROM backups land in the working directory
os.environ["RCB4_SLOT_NAMES"] = os.path.join(work, "slot-names.yaml")
PROJECT, OLD_PROJECT, TRIMS = (os.path.join(DATA, n) for n in ("three_motions.h4p", "three_motions_2_0.h4p", "trims.h4t"))


def rom(on, address, n):
    rc, out, err = run("--json", *on, "read", "rom", hex(address), str(n))
    return bytes(json.loads(out)["bytes"]) if rc == 0 else b""


def backup(on, name):
    rc, out, err = run(*on, "rom", "backup", name, "--force")
    with open(name, "rb") as f:
        return f.read() if rc == 0 else b""


with serve() as dev:
    on = ["--device", dev]
    before = backup(on, "before.bin")
    rc, out, err = run(*on, "project", "import", PROJECT, "--dry-run")
    check(rc == 0 and "change 0x000B80  motion 1 'wave_twice' (63 bytes)" in out and "button table (1 entries)" in out
          and "servo ICS 16 'left_knee' trim -1980" in out and "not written: priority motions" in out
          and "nothing written" in out, f"--dry-run lists every area ({rc}: {out[-400:]!r} {err!r})")
    check(backup(on, "after-dry.bin") == before and not [f for f in os.listdir(".") if f.startswith("rom-before-import")],
          "--dry-run writes nothing (the ROM the same, no backup made)")

    rc, out, err = run(*on, "project", "import", PROJECT)
    saved = [f for f in os.listdir(".") if f.startswith("rom-before-import") and f.endswith(".bin")]
    check(rc == 0 and "wrote  0x000B80  motion 1 'wave_twice'" in out and len(saved) == 1
          and "output period is now 15 ms" in out,
          f"import: written, the ROM saved first ({rc}: {out[-300:]!r} {err!r})")
    with open(saved[0], "rb") as f:
        check(f.read() == before, "the saved ROM is the board's ROM before the import")
    rc, out, err = run(*on, "motion", "list")
    check(rc == 0 and all(s in out for s in ("1  wave_twice           0x00B80", "2  bow                  0x01380",
                                             "3  bow and home         0x01B80")) and "3 of 120 slots used" in out,
          f"motion list: the three motions at their addresses, named ({out!r})")
    # The bytes of motion 1 as hth4-files.md §2.6 prints them (the loop's JUMP to 0x000BAB).
    check(rom(on, 0x0B80, 8) == bytes.fromhex("0800025704000267") and rom(on, 0x0B9D, 7) == bytes.fromhex("070BAB0B0005CD"),
          "motion 1's frames are the project's, byte for byte")
    rc, out, err = run(*on, "motion", "buttons")
    check(rc == 0 and "right+s1" in out and "plays motion 1" in out, f"motion buttons: the assignment ({out!r})")
    rc, out, err = run("--json", *on, "trim", "get", "left_knee", "right_shoulder_roll")
    t = {x["name"]: x for x in json.loads(out)} if rc == 0 else {}
    check(t.get("left_knee", {}).get("counts") == -1980 and t["left_knee"].get("rom_counts") == -1980
          and t.get("right_shoulder_roll", {}).get("counts") == 12, f"trim get: the project's trims, RAM and ROM ({out!r})")
    run(*on, "motion", "resume")
    rc, out, err = run(*on, "motion", "play", "3", "--wait", "--timeout", "10")
    check(rc == 0 and "done after" in out, f"motion 3 (a call of 2, then home) plays and ends ({rc}: {out!r} {err!r})")
    rc, out, err = run("--json", *on, "servo", "get", "2", "3")
    pos = [x.get("position") for x in json.loads(out)] if rc == 0 else []
    check(pos == [7500, 7500], f"after motion 3 ICS 2 and 3 are home ({out.strip()!r})")

    # Export, then import the export: nothing changes.
    rc, out, err = run(*on, "project", "export", "board.h4p")
    check(rc == 0 and "3 motions" in out and os.path.exists("board.h4p"), f"project export ({rc}: {out!r} {err!r})")
    rc, out, err = run(*on, "project", "export", "board.h4p")
    check(rc == 2 and "exists" in err, f"export over an existing file: exit 2 ({rc}: {err.strip()!r})")
    exported = backup(on, "exported.bin")
    rc, out, err = run(*on, "project", "import", "board.h4p")
    check(rc == 0 and "already held all of it" in out and backup(on, "again.bin") == exported,
          f"importing the export leaves the ROM unchanged ({rc}: {out[-200:]!r})")
    with open("board.h4p", encoding="utf-8", newline="") as f:
        text = f.read()
    check(text.startswith('<?xml version="1.0"?>\r\n<Rcb4 ') and "<Name>wave_twice</Name>" in text
          and "<Key xsi:type=\"xsd:string\">left_knee</Key>" in text, "the export is HTH4's schema, joints and slots named")

    # A damaged file: refused with its line, nothing written.
    with open(PROJECT, encoding="utf-8", newline="") as f:
        good = f.read()
    with open("bad.h4p", "w", encoding="utf-8", newline="") as f:
        f.write(good.replace("07 0B AB 0B 00 05 CD", "07 0B AB 0B 00 05 CE"))
    now = backup(on, "now.bin")
    rc, out, err = run(*on, "project", "import", "bad.h4p")
    check(rc == 2 and "bad.h4p:61" in err and "SUM" in err and backup(on, "now2.bin") == now,
          f"a frame with a bad SUM: exit 2 with its line, nothing written ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "project", "import", "missing.h4p")
    check(rc == 2 and "missing.h4p" in err, f"a missing file: exit 2 ({rc}: {err.strip()!r})")

    # A running motion is not written over.
    with open("loop.yaml", "w") as f:
        f.write("robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - label: top\n  - pose: {head_yaw: 10}\n    time_ms: 300\n"
                "  - pose: {head_yaw: -10}\n    time_ms: 300\n  - goto: top\n")
    rc, out, err = run(*on, "motion", "push", "loop.yaml", "12", "--backup", "twelve.bin")
    rc2, out2, err2 = run(*on, "motion", "play", "12")
    check(rc == 0 and rc2 == 0, f"a never-ending motion pushed and played ({rc}, {rc2}: {err.strip()!r} {err2.strip()!r})")
    now = backup(on, "now3.bin")
    rc, out, err = run(*on, "project", "import", OLD_PROJECT)
    check(rc == 1 and "running" in err and backup(on, "now4.bin") == now,
          f"import while a motion runs: exit 1, nothing written ({rc}: {err.strip()!r})")
    run(*on, "motion", "stop")
    rc, out, err = run(*on, "project", "import", OLD_PROJECT)
    check(rc == 1 and "stopped part way" in err and "then import" in err and backup(on, "now5.bin") == now,
          f"import while a motion is stopped part way: exit 1, nothing written ({rc}: {err.strip()!r})")
    run(*on, "motion", "play", "1", "--wait", "--timeout", "10")  # the program afresh

    # A 2.0-2.1 project (slots from 0x0BB8) onto this 2.2 board: moved, its JUMP targets with it.
    rc, out, err = run(*on, "project", "import", OLD_PROJECT)
    check(rc == 0 and "moved to the board's HTH4 2.2+" in out and rom(on, 0x0B9D, 7) == bytes.fromhex("070BAB0B0005CD"),
          f"a 2.0 project is relocated to 0x0B80 ({rc}: {out[:200]!r} {err.strip()!r})")

    # --json: one object.
    rc, out, err = run("--json", *on, "project", "import", PROJECT, "--dry-run")
    j = json.loads(out) if rc == 0 else {}
    check(j.get("dry_run") is True and any(a["what"].startswith("motion 1") for a in j.get("areas", [])),
          f"--json project import: areas ({out[:200]!r})")

    # A trim file by ICS number; an entry for a servo the board does not allocate is listed, not written.
    with open(TRIMS, encoding="utf-8", newline="") as f:
        trims = f.read()
    with open("t.h4t", "w", encoding="utf-8", newline="") as f:
        f.write(trims.replace("<DeviceNumber>30</DeviceNumber>\r\n      <Trim>0</Trim>",
                              "<DeviceNumber>30</DeviceNumber>\r\n      <Trim>77</Trim>"))
    rc, out, err = run(*on, "trim", "import", "t.h4t", "--persist")
    check(rc == 0 and "left_knee" in out and "-3960" in out and "ICS 30 (+77)" in out,
          f"trim import --persist: by ICS, the unallocated one named ({rc}: {out[-300:]!r} {err!r})")
    rc, out, err = run("--json", *on, "trim", "get", "left_knee")
    t = json.loads(out)[0] if rc == 0 else {}
    check(t.get("counts") == -3960 and t.get("rom_counts") == -3960, f"trim get after trim import ({out!r})")
    rc, out, err = run(*on, "trim", "import", PROJECT)
    check(rc == 2 and "not <ArrayOfDictionaryEntry>" in err, f"a project is not a trim file: exit 2 ({err.strip()!r})")

    # Flowcharts (.xml): into a motion file (either schema, the same steps), or compiled into a slot.
    for name in ("wave_twice.xml", "wave_twice_old.xml"):
        rc, out, err = run("motion", "import", os.path.join(DATA, name), name + ".yaml", "--period", "15")
        with open(name + ".yaml") as f:
            y = f.read() if rc == 0 else ""
        check(rc == 0 and "set_counter: 2" in y and "count_down:" in y and "period_ms: 15" in y,
              f"motion import {name}: a motion file ({rc}: {err.strip()!r} {y[:200]!r})")
        # Each block's place on HTH4's canvas and its name ride on the step its code starts with.
        check('name: "Pos2"\n    at: [8, 96]' in y and 'name: "SetCounter1"\n    at: [8, 16]' in y
              and 'name: "Pos4"\n    at: [8, 256]' in y,
              f"motion import {name}: the blocks' names and places kept ({y!r})")
    rc, out, err = run(*on, "motion", "push", "wave_twice.xml.yaml", "20", "--backup", "twenty.bin")
    rc2, out2, err2 = run(*on, "motion", "import", os.path.join(DATA, "wave_twice.xml"), "--push", "21", "--backup", "t1.bin")
    # The same motion at slots 20 and 21: the same bytes but for the jump targets (slot 20 vs 21).
    a, b = rom(on, 0x0B80 + 19 * 2048, 59), rom(on, 0x0B80 + 20 * 2048, 59)
    def offsets(code, base):  # the two JUMPs' targets (at 29 and 36) from the slot's start
        return [int.from_bytes(code[j + 2:j + 5], "little") - base for j in (29, 36)] if len(code) == 59 else []
    check(rc == 0 and rc2 == 0 and a[:29] == b[:29] and a[43:] == b[43:] and b[-3:] == bytes([3, 13, 16])
          and offsets(a, 0x0B80 + 19 * 2048) == offsets(b, 0x0B80 + 20 * 2048) == [0x2B, 0x08],
          f"the imported file pushes to the bytes --push writes ({rc}, {rc2}: {err.strip()!r} {err2.strip()!r})")
    rc, out, err = run("motion", "import", os.path.join(DATA, "wait_and_call.xml"), "w.yaml")
    check(rc == 2 and "cannot express it" in err and "--push N" in err, f"a Wait block: no motion file, says --push ({err.strip()!r})")
    rc, out, err = run(*on, "motion", "import", os.path.join(DATA, "wait_and_call.xml"), "--push", "22", "--backup", "t2.bin")
    check(rc == 0 and "moved to 0x001380" in err and rom(on, 0x0B80 + 21 * 2048 + 0x26, 7) == bytes.fromhex("070C80130000A6"),
          f"motion import --push: compiled into slot 22, its call moved to this layout ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "22", "--wait", "--timeout", "10")
    check(rc == 0 and "done after" in out, f"the imported motion plays (a Wait of 0.8 s, a call) ({rc}: {out!r} {err!r})")

    # --to DIR: the project as rcb4's files (no board), and its push.sh puts the same bytes back.
    rc, out, err = run("project", "import", PROJECT, "--to", "asfiles")
    files = sorted(os.listdir("asfiles")) if rc == 0 else []
    check(rc == 0 and files == ["001-wave_twice.yaml", "002-bow.yaml", "003-bow_and_home.yaml", "buttons.yaml",
                                "profile.yaml", "push.sh", "trims.h4t"], f"project import --to: a profile, motion files, trims, push.sh ({rc}: {files} {err!r})")
    rc, out, err = run("project", "import", PROJECT, "--to", "asfiles")
    check(rc == 2 and "not empty" in err, f"--to into a directory that is not empty: exit 2 ({err.strip()!r})")
    # (Slot 1 gets other code: erased, the board's layout could no longer be told.)
    rcs = [run(*on, "motion", "push", "loop.yaml", "1", "--backup", "e1.bin")[0],
           run(*on, "motion", "erase", "3", "--backup", "e3.bin")[0], run(*on, "motion", "erase", "2", "--backup", "e2.bin")[0]]
    check(rcs == [0, 0, 0] and rom(on, 0x1380, 1) == b"\xff", f"slots 1-3 changed before push.sh ({rcs})")
    p = subprocess.run(["sh", "asfiles/push.sh"], capture_output=True, text=True, timeout=120,
                       env=dict(os.environ, RCB4=f"{RCB4} --device {dev}"))
    want = {1: "0800025704000267 0D100C000000001478 1E201C0F 080702570400016D 070BAB0B0005CD 070B880B0000A5 "
               "0D100C000000001E4C1D4C1D19 030D10",
            3: "070C80130000A6"}
    check(p.returncode == 0 and rom(on, 0x0B80, 59) == bytes.fromhex(want[1].replace(" ", ""))
          and rom(on, 0x1B80, 7) == bytes.fromhex(want[3]),
          f"push.sh writes the project's bytes back (callee first) ({p.returncode}: {p.stderr[-300:]!r})")
    rc, out, err = run(*on, "motion", "buttons")
    check("right+s1" in out and "plays motion 1" in out, f"push.sh set the button ({out!r})")
    # And the directory back as a project (no board): the same motions, frame for frame.
    rc, out, err = run("project", "export", "fromdir.h4p", "--from", "asfiles")
    run(*on, "project", "import", PROJECT)
    rc2, out2, err2 = run(*on, "project", "import", "fromdir.h4p", "--dry-run")
    changed = [l for l in out2.splitlines() if l.startswith("  change")]
    check(rc == 0 and rc2 == 0 and changed == ["  change 0x0008F6  AD references"],
          f"project export --from DIR: the project's motions, buttons and trims again (only the AD references, which "
          f"a directory does not hold, differ) ({rc}, {rc2}: {changed} {err.strip()!r} {err2.strip()!r})")

    # Power-on: the start-up motion (HTH4's CALL at 0x0444) and the boot config word.
    # (The import wrote the project's StartupMotionAddress, 2944: motion 1.)
    rc, out, err = run(*on, "motion", "startup")
    check(rc == 0 and out.startswith("motion 1 ") and "(0x000B80) plays at power-on" in out,
          f"motion startup: the project's ({out!r})")
    rc, out, err = run(*on, "motion", "startup", "none")
    check(rc == 0 and "no start-up motion" in out and rom(on, 0x0444, 7) == bytes.fromhex("070C80CB030061"),
          f"motion startup none: DefaultStartup, 07 0C 80 CB 03 00 61 ({out!r})")
    rc, out, err = run(*on, "motion", "startup", "30")
    check(rc == 1 and "holds no motion" in err and rom(on, 0x0444, 7) == bytes.fromhex("070C80CB030061"),
          f"motion startup 30 (empty): exit 1, nothing written ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "startup", "3")
    check(rc == 0 and "motion 3" in out and rom(on, 0x0444, 7) == bytes.fromhex("070C801B0000AE"),
          f"motion startup 3: the CALL at 0x0444 (07 0C 80 1B 00 00 AE) ({rc}: {out!r} {err!r})")
    run(*on, "motion", "stop")
    boot_before = rom(on, 0x05DC, 2)
    rc, out, err = run(*on, "config", "set", "led=on", "--persist")
    boot_after = rom(on, 0x05DC, 2)
    check(rc == 0 and boot_after[1] == boot_before[1] | 0x80 and boot_after[0] == boot_before[0],
          f"config set led=on --persist: only the LED bit added to ROM's word, the stopped program not kept "
          f"({rc}: {boot_before.hex()} -> {boot_after.hex()} {err!r})")
    backup(on, "startup.bin")

# The board powered on from that ROM plays motion 3 by itself (a call of motion 2: ICS 2 to 7000).
with serve("--rom", "startup.bin") as dev:
    seen, t0 = [], time.monotonic()
    while time.monotonic() - t0 < 5 and not (seen and min(seen) <= 7200):
        rc, out, err = run("--json", "--device", dev, "servo", "get", "2")
        if rc == 0:
            seen.append(json.loads(out)[0]["position"])
    check(seen and min(seen) <= 7200, f"at power-on the start-up motion plays (ICS 2 on its way to 7000: {seen[-5:]})")

finish()
