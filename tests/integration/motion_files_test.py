#!/usr/bin/env python3
# Motion files and ROM images through the rcb4 tool as a robot owner uses them: pull a motion into
# YAML, write one by hand and push it (the bytes checked against ones written by hand from
# protocol.md), play it, pull it back, erase it and put the backup back, a whole ROM backed up and
# restored; and what must be refused: poses beyond limits, another output period, a running
# motion, damaged images, boards that do not keep what is written, die mid-transfer or are silent.
#   motion_files_test.py RCB4
# SPDX-License-Identifier: BSL-1.0
import glob
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish, tool
from standin import StandIn

RCB4 = sys.argv[1]
run, serve = tool(RCB4)
work = tempfile.mkdtemp(prefix="rcb4-motion-files-")
os.chdir(work)  # backups land in the working directory, as they would for a user


def write(name, text):
    with open(name, "w") as f:
        f.write(text)


def joints_deg(on):
    rc, out, err = run("--json", *on, "joint", "list")
    return {x["name"]: x["degrees"] for x in json.loads(out)} if rc == 0 else {}


def status(on):
    rc, out, err = run("--json", *on, "motion", "status")
    return json.loads(out) if rc == 0 else {}


def rom(on, address, n):
    rc, out, err = run("--json", *on, "read", "rom", hex(address), str(n))
    return bytes(json.loads(out)["bytes"]) if rc == 0 else b""


# Counter 3, left_knee to +30 degrees in 300 ms, three times; again while UP is held.
write("knee.yaml", """# three knee bends
robot: KHR-3HV
period_ms: 15
steps:
  - set_counter: 3
  - label: again
  - pose: {left_knee: 30}
    time_ms: 300
  - loop: again
  - if_buttons: up
    goto: again
  - end
""")
# The same at motion 5 (0x002B80), written by hand from protocol.md §4-§5 and motions.md §1.
knee_at_5 = bytes.fromhex(
    "08 00 02 57 04 00 03 68"            # MOV 3 -> RAM 0x0457
    "0B 10 00 00 01 00 00 14 C5 20 15"   # CONST ICS 16 = 8389 (+30 deg), 20 frames, flags set
    "08 07 02 57 04 00 01 6D"            # SUB 1 from 0x0457
    "07 0B 88 2B 00 04 C9"               # JUMP 0x002B88 when Z = 0
    "09 07 82 50 03 00 00 01 E6"         # SUB S of 0x0350 with UP as it lies there: 00 01 (§6)
    "07 0B 88 2B 00 05 CA"               # JUMP 0x002B88 when Z = 1
    "03 0D 10")                          # RETURN

rom_file = os.path.join(work, "robot.rom")
with serve("--rom", rom_file, "--period", "15") as dev:
    on = ["--device", dev]
    # Pull: the demo's motion 2 in joints and milliseconds.
    rc, out, err = run(*on, "motion", "pull", "2", "wave.yaml")
    text = open("wave.yaml").read() if os.path.exists("wave.yaml") else ""
    check(rc == 0 and "motion 2 (0x001380, HTH4 2.2+ layout): 62 bytes, 6 steps, 5 poses" in out and "-> wave.yaml" in out,
          f"motion pull 2 ({rc}: {out.strip()!r} {err.strip()!r})")
    check('name: "wave"' in text and "period_ms: 15" in text
          and "- pose: {right_shoulder_pitch: 67.5, right_shoulder_roll: 94.5}\n    time_ms: 300" in text,
          f"the pulled file in degrees and ms ({text[:300]!r})")
    check("would not push back" not in err, f"the demo's wave lies inside the profile's limits ({err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "wave.yaml", "2")
    check(rc == 0 and "already holds these" in out, f"the pulled wave pushes back as it is, unchanged ({rc}: {out.strip()!r} {err.strip()!r})")
    # A slot whose pose lies beyond a limit (written raw: CONST ICS 5 = 10500, +101.25 deg, 20
    # frames, then RETURN; protocol.md §4-§5): pulled as it is, with the note.
    run(*on, "write", "rom", "0x4380", "0B 10 20 00 00 00 00 14 04 29 7C 03 0D 10")
    rc, out, err = run(*on, "motion", "pull", "8", "beyond.yaml")
    check(rc == 0 and "would not push back" in err and "right_shoulder_roll: 101.25 degrees is beyond its upper limit 100" in err,
          f"pull says a pose lies beyond the profile's limit ({rc}: {err.strip()!r})")
    run(*on, "motion", "erase", "8", "--backup", "beyond8.bin")
    rc, out, err = run(*on, "motion", "pull", "2", "wave.yaml")
    check(rc == 2 and "exists (--force replaces it)" in err, f"pull does not overwrite a file ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "pull", "9", "empty.yaml")
    check(rc == 1 and "is empty" in err and not os.path.exists("empty.yaml"), f"pull of an empty slot: exit 1 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "pull", "2", "wave.txt")
    check(rc == 2 and ".yaml" in err, f"pull to a .txt: exit 2 ({rc}: {err.strip()!r})")

    # A pose beyond a limit: refused, nothing written, no backup made.
    rc, out, err = run(*on, "motion", "push", "beyond.yaml", "5")
    check(rc == 2 and "step 1 (beyond.yaml:" in err and "beyond its upper limit 100" in err and "nothing was written" in err,
          f"push of a pose beyond a limit: exit 2 ({rc}: {err.strip()!r})")
    check(rom(on, 0x2B80, 4) == b"\xff" * 4 and not glob.glob("motion-5-*.bin"), "nothing written, no backup made")

    # Push the hand-written file: the bytes by hand, the old (erased) slot backed up.
    rc, out, err = run(*on, "motion", "push", "knee.yaml", "5")
    check(rc == 0 and "wrote 53 bytes to motion 5 (0x002B80..0x002BB4" in out and "read them back" in out
          and "6 steps, 1 pose (plays 0.90 s, no button held)" in out, f"motion push knee.yaml 5 ({rc}: {out.strip()!r} {err.strip()!r})")
    check(rom(on, 0x2B80, len(knee_at_5)) == knee_at_5, "ROM 0x002B80 holds the bytes written by hand")
    backups = glob.glob("motion-5-*.bin")
    check(len(backups) == 1 and open(backups[0], "rb").read() == b"\xff" * 2048,
          f"the old slot (2,048 bytes of erased ROM) backed up ({backups})")
    rc, out, err = run(*on, "motion", "push", "knee.yaml", "5")
    check(rc == 0 and "already holds these 53 bytes: nothing written" in out, f"the same again: nothing written ({rc}: {out.strip()!r})")
    rc, out, err = run("--json", *on, "motion", "push", "knee.yaml", "6", "--dry-run")
    j = json.loads(out) if rc == 0 else {}
    check(rc == 0 and j.get("bytes") == 53 and rom(on, 0x3380, 1) == b"\xff", f"--dry-run writes nothing ({rc}: {out.strip()[:120]!r})")

    # Play it: the knee ends at +30 degrees.
    rc, out, err = run(*on, "motion", "play", "5", "--wait", "--timeout", "10")
    check(rc == 0 and "done after" in out, f"motion play 5 --wait ({rc}: {out.strip()!r} {err.strip()!r})")
    rc, out, err = run("--json", *on, "joint", "list")
    knee = [x for x in json.loads(out) if x["name"] == "left_knee"][0] if rc == 0 else {}
    check(abs(knee.get("degrees", 99) - 30) < 0.1, f"left_knee at +30 deg after the motion ({knee.get('degrees')})")

    # Pulled back: the same steps, pushed again: the same bytes.
    rc, out, err = run(*on, "motion", "pull", "5", "knee-back.yaml")
    back = open("knee-back.yaml").read() if rc == 0 else ""
    check(rc == 0 and "- pose: {left_knee: 30}\n    time_ms: 300" in back and "- loop: L2B88" in back
          and '- if_buttons: "up"\n    goto: L2B88' in back and err == "", f"pull 5: the file written by hand, back ({back[-200:]!r} {err!r})")
    rc, out, err = run(*on, "motion", "push", "knee-back.yaml", "5")
    check(rc == 0 and "nothing written" in out, f"the pulled file assembles to the same bytes ({rc}: {out.strip()!r})")

    # A motion file's name names its slot (the board keeps no names): motion list, show and pull
    # say it, pyrcb4 and rcb4 ui read the same file; an erase forgets it.
    os.environ["RCB4_SLOT_NAMES"] = os.path.join(work, "slot-names.yaml")
    write("named.yaml", open("knee.yaml").read().replace("robot: KHR-3HV", "robot: KHR-3HV\nname: knee bends"))
    rc, out, err = run(*on, "motion", "push", "named.yaml", "6", "--backup", "six-named.bin")
    check(rc == 0 and "motion 6 'knee bends'" in out, f"push of a named file names the slot ({rc}: {out.strip()!r})")
    rc, out, err = run("--json", *on, "motion", "list")
    names = {m["slot"]: m["name"] for m in json.loads(out)["motions"]} if rc == 0 else {}
    check(names.get(6) == "knee bends", f"motion list shows the slot's name ({names})")
    rc, out, err = run(*on, "motion", "show", "6")
    check(rc == 0 and "motion 6 (knee bends)" in out, f"motion show names it ({out[:80]!r})")
    rc, out, err = run(*on, "motion", "pull", "6", "named-back.yaml")
    check(rc == 0 and "knee bends" in open("named-back.yaml").read(), "a pull keeps the name")
    rc, out, err = run(*on, "motion", "erase", "6", "--backup", "six-erased.bin")
    rc, out, err = run("--json", *on, "motion", "list")
    names = {m["slot"]: m["name"] for m in json.loads(out)["motions"]} if rc == 0 else {}
    check(rc == 0 and 6 not in names and "knee bends" not in open("slot-names.yaml").read(),
          "an erase forgets the slot's name")
    # Play time as the board plays it: the loop counted (3 passes of 300 ms), no button held.
    rc, out, err = run("--json", *on, "motion", "list")
    times = {m["slot"]: m["seconds"] for m in json.loads(out)["motions"]} if rc == 0 else {}
    check(times.get(5) == 0.9, f"motion list: motion 5 plays 0.9 s, its loop counted ({times.get(5)})")

    # Another output period: refused, or rescaled on request.
    write("knee10.yaml", open("knee.yaml").read().replace("period_ms: 15", "period_ms: 10"))
    rc, out, err = run(*on, "motion", "push", "knee10.yaml", "6")
    check(rc == 2 and "made for 10 ms frames" in err and "--rescale" in err, f"a file of 10 ms frames on a 15 ms board ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "knee10.yaml", "6", "--rescale", "--backup", "six.bin")
    check(rc == 0 and "times kept in milliseconds" in err and "300 ms is 20 frames" not in err,
          f"--rescale: 300 ms stays 300 ms ({rc}: {err.strip()!r})")
    check(rom(on, 0x3380 + 8 + 7, 1) == bytes([20]) and os.path.exists("six.bin"), "20 frames of 15 ms, the backup where --backup says")

    # A running motion is not written over; a slot it neither runs, calls nor returns into is
    # (motion_safety_test.py has the rest of these rules).
    # (A motion that never ends, so that it still runs however slow the machine.)
    write("loop12.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - label: top\n  - pose: {head_yaw: 10}\n"
          "    time_ms: 300\n  - pose: {head_yaw: -10}\n    time_ms: 300\n  - goto: top\n")
    run(*on, "motion", "push", "loop12.yaml", "12", "--backup", "twelve.bin")
    run(*on, "motion", "play", "12")
    before12 = rom(on, 0x6380, 16)
    rc, out, err = run(*on, "motion", "push", "knee.yaml", "12")
    check(rc == 1 and "motion 12 is running" in err and rom(on, 0x6380, 16) == before12, f"push over motion 12 while it runs: exit 1 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "knee.yaml", "7", "--backup", "seven.bin")
    check(rc == 0 and rom(on, 0x3B80, 1) == b"\x08", f"push into motion 7 while motion 12 runs: written ({rc}: {err.strip()!r})")
    run(*on, "motion", "stop")
    run(*on, "motion", "play", "1", "--wait", "--timeout", "10")  # the program afresh
    run(*on, "motion", "push", "seven.bin", "7")
    run(*on, "motion", "push", "twelve.bin", "12")
    run(*on, "motion", "wait", "--timeout", "5")

    # Erase, with a button on the slot; then the backup put back.
    run(*on, "motion", "buttons", "set", "left", "5")
    rc, out, err = run(*on, "motion", "erase", "5", "--backup", "five.bin")
    check(rc == 0 and "erased motion 5" in out and "left plays motion 5" in err and rom(on, 0x2B80, 8) == b"\xff" * 8,
          f"motion erase 5 ({rc}: {out.strip()!r} {err.strip()!r})")
    rc, out, err = run(*on, "motion", "list")
    check(rc == 0 and "0x02B80" not in out, "motion list no longer shows 5")
    rc, out, err = run(*on, "motion", "buttons", "press", "left")
    check(rc == 1 and "motion 5 (0x002B80) holds no motion: a play would stop the board's program there" in err,
          f"press of a button on an erased slot: refused ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "five.bin", "5")
    check(rc == 0 and rom(on, 0x2B80, len(knee_at_5)) == knee_at_5, f"the backup put back ({rc}: {out.strip()!r} {err.strip()!r})")
    run(*on, "motion", "buttons", "clear", "left")
    rc, out, err = run(*on, "motion", "erase", "5", "--backup", "five.bin")
    check(rc == 2 and "a backup never replaces a file" in err, f"--backup over an existing file: exit 2 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "erase", "5", "--backup", "five.yaml")
    check(rc == 2 and ".bin" in err, f"--backup not .bin: exit 2 ({rc}: {err.strip()!r})")
    write("calls9.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - call: 9\n  - end\n")
    rc, out, err = run(*on, "motion", "push", "calls9.yaml", "6")
    check(rc == 1 and "step 1 (calls9.yaml:4) calls motion 9 (0x004B80), which holds no motion" in err, f"push of a call of an empty slot: exit 1 ({rc}: {err.strip()!r})")
    # A ROM motion that calls an empty slot (written raw): not played, nothing moves.
    run(*on, "write", "rom", "0x3B80", "07 0C 80 4B 00 00 DE 03 0D 10")
    rc, out, err = run(*on, "motion", "play", "7", "--wait", "--timeout", "5")
    check(rc == 1 and "motion 7 calls motion 9 (0x004B80), which holds no motion" in err and not status(on).get("running"),
          f"a play of a motion that calls an erased slot: refused ({rc}: {err.strip()!r})")
    # Its callee overwritten while it runs (another program's raw write): the board's program
    # stops on an error, and the tool says so.
    write("slow9.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - pose: {left_knee: 5}\n    time_ms: 1500\n  - end\n")
    run(*on, "motion", "push", "slow9.yaml", "9")
    nine = rom(on, 0x4B80, 64)
    rc, out, err = run(*on, "motion", "play", "7")
    run(*on, "write", "rom", hex(0x4B80 + nine[0]), *(["FF"] * (len(nine.rstrip(b"\xff")) - nine[0])))
    rc, out, err = run(*on, "motion", "wait", "--timeout", "5")
    check(rc == 1 and "on an error of the board's program" in err and "motion play N" in err,
          f"a callee overwritten under way stops the program: exit 1, saying so ({rc}: {err.strip()!r})")
    rc, out, err = run("--json", *on, "motion", "status")
    check(rc == 0 and json.loads(out).get("program_error") is True, f"status says program_error ({out.strip()!r})")
    rc, out, err = run(*on, "motion", "resume")
    check(rc == 1 and "resuming would stop it again" in err, f"resume after a program error: refused ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "1", "--wait", "--timeout", "5")
    check(rc == 0, f"motion play 1 starts the program afresh ({rc}: {err.strip()!r})")
    rc, out, err = run("--json", *on, "config")
    check(rc == 0 and json.loads(out)["program_error"] is False, "and clears the old program error")
    run(*on, "write", "rom", "0x3B80", "FF FF FF FF FF FF FF FF FF FF")
    run(*on, "write", "rom", "0x4B80", *(["FF"] * nine[0]))
    rc, out, err = run(*on, "motion", "erase", "9")
    check(rc == 0 and "already empty" in out, f"erase of an empty slot writes nothing ({rc}: {out.strip()!r})")

    # Played from the host, nothing written: 3 poses of 300 ms, the knee at +30 at the end.
    run(*on, "joint", "move", "left_knee=0@15")
    before_rom = rom(on, 0x0B80, 2048 * 10)
    rc, out, err = run("--json", *on, "motion", "play", "knee.yaml")
    j = json.loads(out) if rc == 0 else {}
    check(rc == 0 and j.get("poses") == 3 and j.get("calls") == 0 and 0.85 <= j.get("seconds", 0) < 2.5,
          f"motion play knee.yaml: 3 poses in about 0.9 s ({rc}: {out.strip()!r} {err.strip()!r})")
    rc, out, err = run("--json", *on, "joint", "list")
    knee = [x for x in json.loads(out) if x["name"] == "left_knee"][0] if rc == 0 else {}
    check(abs(knee.get("degrees", 99) - 30) < 0.1 and rom(on, 0x0B80, 2048 * 10) == before_rom,
          f"the knee at +30 deg, the ROM untouched ({knee.get('degrees')})")
    write("calls.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - pose: {head_yaw: 20}\n    time_ms: 150\n"
                        "  - call: 1\n  - end\n")
    rc, out, err = run(*on, "motion", "play", "calls.yaml")
    check(rc == 0 and "1 pose, 1 ROM motion in" in out, f"a file that calls ROM motion 1 ({rc}: {out.strip()!r} {err.strip()!r})")
    # A button test sees the buttons as a receiver leaves them (0x0350 high byte first, protocol.md
    # §6): TRIANGLE (0x0010) is 00 10 there; SQUARE (0x0100), 01 00, is another button. From the
    # host and from ROM.
    write("branch.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - if_buttons: triangle\n    goto: yes\n"
                         "  - pose: {head_yaw: 10}\n    time_ms: 150\n  - end\n  - label: yes\n"
                         "  - pose: {head_yaw: -10}\n    time_ms: 150\n  - end\n")
    run(*on, "motion", "push", "branch.yaml", "8", "--backup", "eight.bin")
    for held, want in (("00 10", -10), ("01 00", 10)):
        run(*on, "write", "ram", "0x0350", held)
        rc1, _, err1 = run(*on, "motion", "play", "branch.yaml")
        host = joints_deg(on)["head_yaw"]
        run(*on, "joint", "move", "head_yaw=0@15")
        rc2, _, err2 = run(*on, "motion", "play", "8", "--wait", "--timeout", "5")
        rom_played = joints_deg(on)["head_yaw"]
        check(rc1 == 0 and rc2 == 0 and abs(host - want) < 0.1 and abs(rom_played - want) < 0.1,
              f"if_buttons triangle with {held} at 0x0350: head_yaw {want:+} from the host and from ROM ({host}, {rom_played}; {err1.strip()!r} {err2.strip()!r})")
    run(*on, "write", "ram", "0x0350", "00 00")
    write("unslotted.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - pose: {\"ics 30\": 7500}\n    time_ms: 150\n  - end\n")
    rc, out, err = run(*on, "motion", "play", "unslotted.yaml")
    check(rc == 1 and "(ICS 30) has no slot on the board" in err, f"a servo without a slot: exit 1, nothing sent ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "unslotted.yaml", "37")
    check(rc == 1 and "(ICS 30) has no slot on the board" in err and "nothing was written" in err,
          f"and a push of it: exit 1, nothing written ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "knee10.yaml")
    check(rc == 2 and "--rescale" in err, f"play of a file for another period: exit 2 ({rc}: {err.strip()!r})")
    # A motion that never ends, stopped with Ctrl-C.
    write("forever.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - label: a\n  - pose: {left_knee: 10}\n    time_ms: 150\n"
                          "  - pose: {left_knee: -10}\n    time_ms: 150\n  - goto: a\n")
    proc = subprocess.Popen([RCB4, *on, "motion", "play", "forever.yaml"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=10)
    check(proc.returncode == 130 and "interrupted at step" in err and time.monotonic() - sent < 1.0,
          f"Ctrl-C stops a motion played from the host within 1 s ({proc.returncode}: {err.strip()!r})")

    # Ctrl-C while a called ROM motion's pose is under way: every servo holds where it is, the
    # ones the called motion moves too (not only those the file's own poses moved).
    write("slow.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - label: a\n  - pose: {head_yaw: 40}\n    time_ms: 2700\n"
                       "  - pose: {head_yaw: -40}\n    time_ms: 2700\n  - goto: a\n")
    run(*on, "motion", "push", "slow.yaml", "11", "--backup", "eleven.bin")
    write("call11.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - pose: {left_knee: 5}\n    time_ms: 150\n"
                         "  - call: 11\n  - end\n")
    proc = subprocess.Popen([RCB4, *on, "--trace", "motion", "play", "call11.yaml"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    # Not a fixed time from the start (a loaded machine starts a sanitized tool late): from its first
    # exchange (--trace), 1.2 s is inside motion 11's first pose (0.15 s, the call, 2.7 s towards +40).
    trace = proc.stderr.readline()
    time.sleep(1.2)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=10)
    first = joints_deg(on)["head_yaw"]
    time.sleep(0.5)
    then = joints_deg(on)["head_yaw"]
    check(proc.returncode == 130 and abs(first - then) < 0.5 and abs(then) < 39,
          f"Ctrl-C inside a called motion's pose: head_yaw (moved only by the called motion) holds ({first} then {then}; "
          f"{trace.strip()[:60]!r} {err.strip()[-300:]!r})")
    run(*on, "motion", "play", "1", "--wait", "--timeout", "5")

    # Ctrl-C while a file waits for a ROM motion it called (one that never ends): within 1 s, and
    # the motion stopped on the board too.
    run(*on, "motion", "push", "forever.yaml", "10", "--backup", "ten.bin")
    write("call10.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - call: 10\n  - end\n")
    proc = subprocess.Popen([RCB4, *on, "motion", "play", "call10.yaml"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(1.0)
    sent = time.monotonic()
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=10)
    rc, st, _ = run("--json", *on, "motion", "status")
    st = json.loads(st) if rc == 0 else {}
    check(proc.returncode == 130 and time.monotonic() - sent < 1.0 and "was stopped" in err and not st.get("running"),
          f"Ctrl-C during a called ROM motion: exit 130 within 1 s, the motion stopped ({proc.returncode}: {err.strip()!r} {st})")
    # Stopped part way in motion 10: its slot is not written over, resume would land in new bytes.
    rc, out, err = run(*on, "motion", "erase", "10")
    check(rc == 1 and "stopped part way" in err, f"erase of a slot stopped part way: exit 1 ({rc}: {err.strip()!r})")
    run(*on, "--timeout", "1000", "rom", "backup", "pre10.bin")
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", "pre10.bin")
    check(rc == 1 and "stopped part way" in err, f"rom restore with a motion stopped part way: exit 1 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "1", "--wait", "--timeout", "5")
    check(rc == 0, f"motion play 1 starts afresh ({rc}: {err.strip()!r})")
    # A named layout the ROM contradicts is refused before anything is read or written with it.
    rc, out, err = run(*on, "motion", "push", "knee.yaml", "2", "--layout", "2.0")
    check(rc == 1 and "another layout than this board's ROM has" in err, f"--layout 2.0 on a 2.2 board: exit 1 ({rc}: {err.strip()!r})")

    # Motion 1 tells the layout: erased, the hint to put it back names --layout.
    rc, out, err = run(*on, "motion", "erase", "1", "--backup", "one.bin")
    check(rc == 0 and "from now on give it: --layout 2.2" in err and "rcb4 motion push one.bin 1 --layout 2.2" in out,
          f"erase 1 says the layout must be given ({rc}: {out.strip()!r} {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "one.bin", "1", "--layout", "2.2")
    check(rc == 0, f"the hint's command puts motion 1 back ({rc}: {err.strip()!r})")

    # Mistakes in files: named with file and line, exit 2.
    write("bad.yaml", "robot: KHR-3HV\nperiod_ms: 15\nsteps:\n  - pose: {left_kneee: 3}\n    time_ms: 10\n")
    rc, out, err = run(*on, "motion", "push", "bad.yaml", "8")
    check(rc == 2 and "bad.yaml:4:12: no joint of KHR-3HV is called 'left_kneee'" in err, f"an unknown joint ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "missing.yaml", "8")
    check(rc == 2 and "missing.yaml" in err, f"a missing file ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "push", "knee.yaml", "121")
    check(rc == 2, f"motion 121 ({rc}: {err.strip()!r})")

    # The whole ROM: backed up with a CRC-32 (checked here with zlib, not the tool), restored.
    rc, out, err = run(*on, "--timeout", "1000", "rom", "backup", "all.bin")
    image = open("all.bin", "rb").read() if rc == 0 else b""
    crc = open("all.bin.crc32").read().split() if os.path.exists("all.bin.crc32") else [""]
    check(rc == 0 and len(image) == 262144 and crc[0] == "%08x" % zlib.crc32(image) and image[0x2B80:0x2B80 + 53] == knee_at_5,
          f"rom backup: 262,144 bytes and their CRC-32 ({rc}: {out.strip()!r} {err.strip()!r} {crc})")
    run(*on, "motion", "erase", "5")
    run(*on, "motion", "push", "knee.yaml", "9")
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", "all.bin")
    check(rc == 0 and "wrote 2 pieces of 128 bytes" in out and "each read back" in out,
          f"rom restore: only the pieces that differ ({rc}: {out.strip()!r} {err.strip()!r})")
    check(rom(on, 0x2B80, 53) == knee_at_5 and rom(on, 0x4B80, 1) == b"\xff", "motion 5 back, motion 9 gone")
    before = glob.glob("rom-before-restore-*.bin")
    old = open(before[0], "rb").read() if len(before) == 1 else b""
    check(len(old) == 262144 and old[0x2B80] == 0xFF and old[0x4B80:0x4B88] == knee_at_5[:8]
          and os.path.exists(before[0] + ".crc32"), f"the ROM it replaced saved first, beside the image ({before})")
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", "all.bin")
    check(rc == 0 and "nothing written" in out, f"restore of the same image writes nothing ({rc}: {out.strip()!r})")
    damaged = bytearray(image)
    damaged[100] ^= 0xFF
    open("damaged.bin", "wb").write(damaged)
    os.link("all.bin.crc32", "damaged.bin.crc32")
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", "damaged.bin")
    check(rc == 2 and "the file changed or is damaged" in err, f"a damaged image: exit 2 ({rc}: {err.strip()!r})")
    open("short.bin", "wb").write(image[:1000])
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", "short.bin", "--no-check")
    check(rc == 2 and "a ROM image is 262144" in err, f"an image of the wrong size: exit 2 ({rc}: {err.strip()!r})")
    os.remove("damaged.bin.crc32")
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", "damaged.bin")
    check(rc == 2 and ".crc32 is missing" in err, f"no .crc32: exit 2 unless --no-check ({rc}: {err.strip()!r})")
    # rcb4 ui's one-file backup: the CRC-32 in the file's name (issue 41, M7), no .crc32 beside it.
    named = "rcb4-rom-20261128-101010-crc32-%08x.bin" % zlib.crc32(image)
    open(named, "wb").write(image)
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", named)
    check(rc == 0 and "nothing written" in out, f"a CRC in the file's name checks it ({rc}: {out.strip()!r} {err.strip()!r})")
    wrong = "rcb4-rom-20261128-101010-crc32-%08x.bin" % (zlib.crc32(image) ^ 1)
    open(wrong, "wb").write(image)
    rc, out, err = run(*on, "--timeout", "1000", "rom", "restore", wrong)
    check(rc == 2 and "the file changed or is damaged" in err, f"and a name whose CRC differs: exit 2 ({rc}: {err.strip()!r})")

# The served ROM is saved when it changes, not only at a clean exit.
rom2 = os.path.join(work, "hup.rom")
srv = subprocess.Popen([RCB4, "serve", "--pty", "--rom", rom2, "--period", "15"], stdout=subprocess.PIPE, text=True)
dev = srv.stdout.readline().strip()
rc, out, err = run("--device", dev, "motion", "push", "knee.yaml", "5", "--backup", "hup5.bin")
time.sleep(1.6)
srv.kill()  # SIGKILL: no chance to save at exit
srv.wait(timeout=10)
image = open(rom2, "rb").read() if os.path.exists(rom2) else b""
check(rc == 0 and image[0x2B80:0x2B80 + 53] == knee_at_5, f"serve --rom saved the change within a second, before a kill ({rc})")
srv = subprocess.Popen([RCB4, "serve", "--pty", "--rom", rom2], stdout=subprocess.PIPE, text=True)
dev = srv.stdout.readline().strip()
run("--device", dev, "motion", "erase", "5", "--backup", "hup5b.bin")
srv.send_signal(signal.SIGHUP)  # a closed terminal
srv.wait(timeout=10)
image = open(rom2, "rb").read()
check(srv.returncode == 0 and image[0x2B80:0x2B88] == b"\xff" * 8, f"SIGHUP saves the ROM too ({srv.returncode})")

# Teaching by demonstration, against a board of our own whose servo a "hand" turns (the stand-in's
# RAM, changed by this script while the tool samples): still, to +40 deg, still, back to 0.
hand = StandIn()
def head_at(deg):
    hand.ram[0x90 + 4:0x90 + 6] = int(round(7500 + deg * 8000 / 270)).to_bytes(2, "little")
head_at(0)
rec = subprocess.Popen([RCB4, "--device", hand.path, "motion", "record", "taught.yaml", "--joints", "head_yaw",
                        "--every", "50", "--free", "--for", "3"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
t0 = time.monotonic()
def at(t):
    while time.monotonic() - t0 < t:
        time.sleep(0.005)
at(0.7)
for k in range(1, 41):   # +40 deg over 0.5 s, in steps of 1 deg (finer than the 2 deg threshold)
    head_at(k)
    at(0.7 + 0.0125 * k)
at(1.8)
for k in range(1, 41):   # back over 0.5 s
    head_at(40 - k)
    at(1.8 + 0.0125 * k)
out, err = rec.communicate(timeout=20)
taught = open("taught.yaml").read() if os.path.exists("taught.yaml") else ""
poses = [l for l in taught.splitlines() if l.strip().startswith("- pose:")]
times = [int(l.split(":")[1]) for l in taught.splitlines() if l.strip().startswith("time_ms:")]
peak = max((float(l.split("head_yaw:")[1].strip(" }")) for l in poses), default=0)
check(rec.returncode == 0 and 4 <= len(poses) <= 8 and abs(peak - 40) <= 2 and "period_ms: 10" in taught,
      f"motion record: a few poses, the turn at +40 deg ({rec.returncode}: {len(poses)} poses, peak {peak}, {err.strip()[-200:]!r})")
check(2.8 <= sum(times[1:]) / 1000 <= 3.3 and all(t % 10 == 0 for t in times), f"the poses' times add up to the 3 s recorded ({times})")
consts = [f for f in hand.frames if f[1] == 0x10]
check(len(consts) >= 2 and b"\x00\x80" in bytes(consts[0]) and b"\xff\x7f" in bytes(consts[-1]),
      "--free: the joint freed first (0x8000) and held at the end (0x7FFF)")
rc, out, err = run("--device", StandIn().path, "motion", "record", "legs.yaml", "--joints", "legs", "--for", "1")
check(rc == 1 and "no servo allocated for left_hip_roll" in err and not os.path.exists("legs.yaml"),
      f"record of joints the board has no servo for: exit 1 ({rc}: {err.strip()!r})")
rc, out, err = run("--device", StandIn().path, "motion", "record", "/nonexistent-dir/x.yaml", "--free", "--for", "2")
check(rc == 3 and "cannot be written" in err and "nothing recorded" in err, f"record to a place it cannot write: exit 3 at once ({rc}: {err.strip()!r})")
dying = StandIn(mode="die", die_after=40)
rc, out, err = run("--device", dying.path, "motion", "record", "died.yaml", "--joints", "head_yaw", "--every", "20", "--for", "5")
check(rc == 4 and os.path.exists("died.yaml") and "recorded before the board stopped answering are in died.yaml" in err,
      f"a board that dies mid-recording: exit 4, what was recorded kept ({rc}: {err.strip()[-200:]!r})")
rec = subprocess.Popen([RCB4, "--device", StandIn().path, "motion", "record", "stopped.yaml", "--joints", "head_yaw"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
time.sleep(1.0)
rec.send_signal(signal.SIGINT)
out, err = rec.communicate(timeout=10)
check(rec.returncode == 0 and os.path.exists("stopped.yaml") and "recorded 2 poses" in out,
      f"Ctrl-C ends a recording and saves it ({rec.returncode}: {out.strip()!r} {err.strip()[-200:]!r})")
run("--device", StandIn().path, "motion", "record", "stopped.yaml", "--joints", "head_yaw", "--for", "0.2")
rc, out, err = run("--device", StandIn().path, "motion", "record", "stopped.yaml", "--for", "0.2")
check(rc == 2 and "exists" in err, f"record does not replace a file ({rc}: {err.strip()!r})")

# Boards that are not ours (the stand-in has slots for ICS 0-2 only: head_yaw, waist_yaw, left_shoulder_pitch).
write("knee10.yaml", "robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - pose: {head_yaw: 10, waist_yaw: -5}\n    time_ms: 300\n  - end\n")
board = StandIn()  # acknowledges ROM writes and keeps nothing
rc, out, err = run("--device", board.path, "motion", "push", "knee10.yaml", "1", "--layout", "2.2", "--backup", "x.bin")
check(rc == 1 and "ROM 0x000B80 reads back 0xFF, 0x0D was written" in err and "rcb4 motion push x.bin 1 puts them back" in err,
      f"a board that does not keep ROM writes: exit 1, the backup and the command that puts it back named ({rc}: {err.strip()!r})")
# A board that dies at every point of a push: once the backup exists, the failure (in the write or
# the read-back) names it and the command that puts the slot back.
seen = set()
for k in range(22, 29):  # around the write (the exchanges before it: layout, config, backup reads, state)
    rc, out, err = run("--device", StandIn(mode="die", die_after=k).path, "--timeout", "50", "motion", "push",
                       "knee10.yaml", "1", "--layout", "2.2", "--backup", f"die{k}.bin")
    if os.path.exists(f"die{k}.bin"):
        where = ("write" if "writing ROM" in err else "read-back" if "reading back ROM" in err
                 else "compare" if "reads back 0xFF" in err else "?")
        seen.add(where)
        check(rc == (1 if where == "compare" else 4) and where != "?"
              and f"rcb4 motion push die{k}.bin 1 puts them back" in err,
              f"dies after {k} frames, after the backup ({where}): the way back named ({rc}: {err.strip()[-200:]!r})")
check({"write", "read-back"} <= seen, f"the board died in the write and in the read-back at least once each ({seen})")
rc, out, err = run("--device", StandIn(mode="die", die_after=200).path, "rom", "backup", "die.bin")
check(rc == 4 and "reading ROM stopped at 0x" in err and not os.path.exists("die.bin"), f"a board that dies mid-backup: exit 4, no file ({rc}: {err.strip()!r})")
rc, out, err = run("--device", StandIn(silent=True).path, "motion", "pull", "1", "s.yaml", "--layout", "2.2")
check(rc == 4 and not os.path.exists("s.yaml"), f"a silent board: exit 4 ({rc}: {err.strip()!r})")
rc, out, err = run("--device", StandIn(mode="nack").path, "motion", "erase", "1", "--layout", "2.2")
check(rc == 1, f"a board that NACKs: exit 1 ({rc}: {err.strip()!r})")
rc, out, err = run("--device", "/dev/rcb4-no-such-port", "rom", "backup", "n.bin")
check(rc == 3 and not os.path.exists("n.bin"), f"no such device: exit 3 ({rc}: {err.strip()!r})")

os.chdir("/")
shutil.rmtree(work, ignore_errors=True)
finish()
