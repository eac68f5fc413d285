#!/usr/bin/env python3
# Motions on Linux through the rcb4 tool, as a robot owner uses them: `rcb4 motion show` reads a
# slot back as the board runs it (the virtual board's demo motions, and a motion written here by
# hand in HeartToHeart4's patterns of motions.md §1: a loop, a button test, a call of another
# motion, leftovers of an older motion after its RETURN), with exit codes and JSON checked.
#   motion_test.py RCB4
# SPDX-License-Identifier: BSL-1.0
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish, tool

RCB4 = sys.argv[1]
run, serve = tool(RCB4)  # run(*args) -> (exit code, stdout, stderr); with serve(*args) as device: ...


# Written by hand (the checksums summed by hand): motion 10 of the 2.2 layout at 0x005380.
# CONST ICS 0 = 7500 in 28 frames; C1 = 3; loop: ICS 0 = 8500, ICS 0 = 6500 (10 frames each);
# SUB 1 from C1, JUMP back if Z = 0; CALL motion 2 (0x001380); while any button is held (SUB S
# 0x0350 - 0, JUMP if Z = 0) back into the loop; RETURN. Then an older motion's leftovers.
base = 0x005380
loop = base + 19
motion = bytes([0x0B, 0x10, 0x01, 0, 0, 0, 0, 0x1C, 0x4C, 0x1D, 0xA1,
                0x08, 0x00, 0x02, 0x57, 0x04, 0x00, 0x03, 0x68,
                0x0B, 0x10, 0x01, 0, 0, 0, 0, 0x0A, 0x34, 0x21, 0x7B,
                0x0B, 0x10, 0x01, 0, 0, 0, 0, 0x0A, 0x64, 0x19, 0xA3,
                0x08, 0x07, 0x02, 0x57, 0x04, 0x00, 0x01, 0x6D,
                0x07, 0x0B, 0x93, 0x53, 0x00, 0x04, 0x07 + 0x0B + 0x93 + 0x53 + 0x04,
                0x07, 0x0C, 0x80, 0x13, 0x00, 0x00, (0x07 + 0x0C + 0x80 + 0x13) & 0xFF,
                0x09, 0x07, 0x82, 0x50, 0x03, 0x00, 0x00, 0x00, 0xE5,
                0x07, 0x0B, 0x93, 0x53, 0x00, 0x04, 0x07 + 0x0B + 0x93 + 0x53 + 0x04,
                0x03, 0x0D, 0x10,
                0x0B, 0x10, 0x01, 0, 0, 0, 0, 0x0A, 0x34, 0x21, 0x7B])  # leftovers: not code
assert motion[51] == loop & 0xFF and motion[52] == loop >> 8  # the JUMP at +49 goes to the loop

with serve() as dev:
    on = ["--device", dev]
    rc, out, err = run(*on, "motion", "show", "2")
    check(rc == 0 and "motion 2 (wave) at 0x001380" in out and "right_shoulder_roll +94.5" in out and "beyond" not in out
          and "6 steps, assembled back to the same bytes" in out, f"motion show 2: the demo wave, poses in joints ({rc}, {err.strip()!r})")
    # A pose beyond a limit is shown, not hidden (CONST ICS 5 = 10500, +101.25 deg, then RETURN, at motion 9).
    run(*on, "write", "rom", "0x4B80", "0B 10 20 00 00 00 00 14 04 29 7C 03 0D 10")
    rc, out, err = run(*on, "motion", "show", "9")
    check(rc == 0 and "right_shoulder_roll +101.2 (beyond its upper limit 100)" in out,
          f"motion show of a pose beyond a limit says so ({rc}, {out.strip()[-200:]!r})")
    rc, out, err = run(*on, "motion", "show", "5")
    check(rc == 0 and "empty (erased ROM)" in out, f"motion show of an erased slot says so ({out.strip()!r})")
    rc, out, err = run(*on, "write", "rom", hex(base), motion.hex())
    assert rc == 0, err
    rc, out, err = run(*on, "motion", "show", "10")
    lines = out.splitlines()
    check(rc == 0 and "  0x00538B  MOV" in out and "calls motion 2 (0x001380)" in out
          and "10 reachable frames, 82 bytes" in out and "9 steps, assembled back to the same bytes" in out,
          f"motion show 10: a loop, a call and a button test, the leftovers left out ({rc}: {lines[-2:]})")
    check(sum(1 for l in lines if l.startswith("  0x")) == 10, "only the reachable frames are listed")
    rc, out, err = run("--json", *on, "motion", "show", "10")
    j = json.loads(out) if rc == 0 else {}
    check(rc == 0 and len(j.get("code", [])) == 10 and j["code"][0]["joints"] == {"head_yaw": 0.0}
          and j["calls"] == ["motion 2 (0x001380)"] and j["steps"] == 9 and j["problems"] == [] and not j["empty"],
          f"motion show --json ({str(j)[:160]})")
    # A slot whose code jumps out of it: the listing says where the board would go.
    rc, out, err = run(*on, "write", "rom", "0x005B80", "07 0B 00 00 01 00 13")
    rc, out, err = run(*on, "motion", "show", "11")
    check(rc == 0 and "the board stops: 0x005B80: jumps out of the slot, to 0x010000" in out, f"a jump out of the slot is named ({out.strip()[-120:]!r})")
    rc, out, err = run(*on, "motion", "show", "11", "--json")
    check(rc == 2, "global options go before the command here too")
    # A motion stopped part way is not running (motion status said "running" after motion stop).
    rc, out, err = run(*on, "write", "rom", "0x005B80", "07 0B 80 5B 00 00 ED")  # JUMP to itself: never ends
    rc, out, err = run(*on, "motion", "show", "11")
    check("note: 0x005B80: jumps to itself: the motion never ends" in out, f"motion show notes a motion that never ends ({out.strip()[-90:]!r})")
    rc, out, err = run(*on, "motion", "play", "11")
    rc2, out2, err2 = run(*on, "motion", "status")
    check(rc == 0 and rc2 == 0 and out2.startswith("motion 11 running"), f"a motion that loops for ever runs ({out2.strip()!r})")
    rc, out, err = run(*on, "motion", "stop")
    rc, out, err = run(*on, "motion", "status")
    check(rc == 0 and out.startswith("motion 11 stopped part way"), f"after motion stop: stopped part way ({out.strip()!r})")
    rc, out, err = run("--json", *on, "motion", "status")
    st = json.loads(out) if rc == 0 else {}
    check(st.get("running") is False and st.get("suspended") is True and st.get("motion") == 11, f"--json: running false, suspended true ({st})")
    rc, out, err = run(*on, "motion", "wait", "--timeout", "1")
    check(rc == 1 and "motion 11 stopped part way" in err and "motion resume" in err, f"motion wait on it: exit 1, says so ({rc}, {err.strip()!r})")
    rc, out, err = run(*on, "joint", "move", "head_yaw=10")
    check(rc == 0, "a joint moves while the motion is stopped")
    rc, out, err = run(*on, "motion", "resume")
    rc, out, err = run(*on, "motion", "status")
    check(out.startswith("motion 11 running"), f"resumed: running again ({out.strip()!r})")
    rc, out, err = run(*on, "joint", "move", "head_yaw=20")
    check(rc == 1 and "motion 11 is running" in err, f"and a joint move is refused again ({err.strip()!r})")
    run(*on, "motion", "stop")
    rc, out, err = run(*on, "motion", "show", "--layout", "1.3", "60")
    check(rc == 2 and "the HTH4 1.3 layout has motions 1-50" in err, f"a motion the layout does not have: exit 2 ({err.strip()!r})")
    rc, out, err = run(*on, "motion", "show", "0")
    check(rc == 2, "motion 0: exit 2")
finish()
