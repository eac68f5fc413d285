#!/usr/bin/env python3
# Which remote button plays which motion, through the rcb4 tool as a robot owner uses it: show the
# vector-jump table, press a button, assign one, clear one, reset the table, and the table kept in
# ROM across a power cycle of `rcb4 serve --rom FILE`; the layout told from the ROM; boards that
# are not ours (a stand-in with an erased ROM, a silent one, one that NACKs). Exit codes checked.
#   buttons_test.py RCB4
# SPDX-License-Identifier: BSL-1.0
import json
import os
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish, tool
from standin import StandIn

RCB4 = sys.argv[1]
run, serve = tool(RCB4)  # run(*args) -> (exit code, stdout, stderr); with serve(*args) as device: ...

rom_file = os.path.join(tempfile.mkdtemp(prefix="rcb4-buttons-"), "robot.rom")
with serve("--rom", rom_file) as dev:
    on = ["--device", dev]
    rc, out, err = run(*on, "motion", "buttons")
    check(rc == 0 and 'up             plays motion 2 "wave" (0x001380)' in out and "down           plays motion 3" in out
          and "HTH4 2.2+ layout" in out, f"motion buttons: the virtual board's table ({rc}: {out.strip()!r} {err.strip()!r})")
    rc, out, err = run("--json", *on, "motion", "buttons")
    j = json.loads(out) if rc == 0 else {}
    check(rc == 0 and [(e["buttons"], e["motion"], e["action"]) for e in j["ram"]["entries"]] == [("up", 2, "call"), ("down", 3, "call")]
          and j["same"] and j["vector_switch"] and j["table_address"] == 0x0357, f"motion buttons --json ({str(j)[:200]})")
    check(j.get("ram", {}).get("entries", [{}])[-1].get("hex") == "B5 50 03 00 02 80 1B 00",
          "the last entry's bytes: EOF, a word compare of 0x0350 with DOWN, CALL 0x001B80 (protocol.md §6)")

    rc, out, err = run(*on, "motion", "buttons", "press", "up")
    check(rc == 0 and "up pressed: motion 2 runs (released)" in out, f"press up plays motion 2 ({rc}: {out.strip()!r} {err.strip()!r})")
    rc, out, err = run(*on, "motion", "wait", "--timeout", "5")
    check(rc == 0 and "no motion running" in out, f"the pressed motion ends: nothing held the button ({rc}: {out.strip()!r})")

    rc, out, err = run(*on, "motion", "buttons", "set", "S1+Up", "1")
    check(rc == 0 and "up+s1 plays motion 1" in out and 'up+s1          plays motion 1 "home"' in out,
          f"set s1+up 1 ({rc}: {out.strip()!r} {err.strip()!r})")
    # ROM 0x091B, written by hand from protocol.md §6: UP → 0x001380, DOWN → 0x001B80 (no EOF any
    # more), S1+UP (the word 0x0201 as it lies at 0x0350: 02 01) → 0x000B80 with EOF.
    rc, out, err = run("--json", *on, "read", "rom", "0x091B", "24")
    data = bytes(json.loads(out)["bytes"]) if rc == 0 else b""
    golden = bytes.fromhex("35 50 03 00 01 80 13 00  35 50 03 00 02 80 1B 00  B5 50 03 02 01 80 0B 00")
    check(data == golden, f"the table in ROM byte by byte ({data.hex(' ')})")
    rc, out, err = run(*on, "motion", "buttons", "press", "s1+up")
    check(rc == 0 and "motion 1 runs" in out, f"the new assignment plays at once ({rc}: {out.strip()!r} {err.strip()!r})")
    run(*on, "motion", "wait", "--timeout", "5")

    rc, out, err = run(*on, "motion", "buttons", "set", "up", "7")
    check(rc == 1 and "motion 7 (0x003B80) holds no motion" in err, f"set to an empty slot: exit 1 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "set", "up+jump", "2")
    check(rc == 2 and "'jump' is no button" in err, f"a button that does not exist: exit 2 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "set", "up", "121")
    check(rc == 2, f"motion 121: exit 2 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "clear", "left")
    check(rc == 1 and "no entry plays anything for left" in err, f"clear of an unassigned button: exit 1 ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "clear", "down")
    check(rc == 0 and "down plays nothing" in out and "down " not in out.split("read back):")[-1],
          f"clear down ({rc}: {out.strip()!r})")

# Power off and on: the board loads the table from ROM.
with serve("--rom", rom_file) as dev:
    on = ["--device", dev]
    rc, out, err = run("--json", *on, "motion", "buttons")
    j = json.loads(out) if rc == 0 else {}
    check(rc == 0 and [e["buttons"] for e in j["ram"]["entries"]] == ["up", "up+s1"] and j["same"],
          f"after a power cycle the board has the table written to ROM ({str(j)[:160]})")
    rc, out, err = run(*on, "motion", "buttons", "reset")
    check(rc == 0 and "no button plays anything" in out and "no entries" in out, f"reset ({rc}: {out.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "press", "up")
    check(rc == 1 and "no entry of the table plays anything for up" in err, f"press with an empty table: exit 1 at once ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "press", "down", "--hold")
    rc2, st, _ = run("--json", *on, "motion", "status")
    check(rc == 0 and "down held (no entry of the table plays anything" in out and not json.loads(st).get("running"),
          f"press --hold with an empty table: held as a receiver holds it, nothing plays ({rc}: {out.strip()!r})")
    run(*on, "motion", "buttons", "release")
    run(*on, "motion", "buttons", "release")
    rc, out, err = run(*on, "motion", "buttons", "set", "down", "3")
    check(rc == 0, f"a table can be built again from nothing ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "press", "down", "--hold")
    check(rc == 0 and "still pressed" in out, f"press --hold ({rc}: {out.strip()!r})")
    # Motion 3 takes 0.7 s; held, it starts again each time it ends (between two plays the board is
    # in its main loop for a period or two, so a 50 ms poll may see it idle: sample for 2 s).
    start, late = time.monotonic(), []
    while time.monotonic() - start < 2.0:
        rc, out, err = run("--json", *on, "motion", "status")
        if rc == 0 and json.loads(out)["running"] and time.monotonic() - start > 1.2:
            late.append(json.loads(out)["motion"])
    check(late and set(late) == {3}, f"a held button plays the motion again and again (motion 3 running after 1.2 s: {late[:5]})")
    rc, out, err = run(*on, "motion", "buttons", "release")
    check(rc == 0, "release")
    rc, out, err = run(*on, "motion", "wait", "--timeout", "5")
    check(rc == 0, f"released: the motion ends ({rc}: {err.strip()!r})")
    # No motion 1 where HTH4 2.2 puts it, nor where 2.0 and 1.3 do: the layout is not guessed.
    rc, out, err = run(*on, "write", "rom", "0x000B80", "FF FF FF")
    rc, out, err = run(*on, "motion", "list")
    check(rc == 1 and "cannot tell which HeartToHeart4 layout" in err and "--layout 2.2" in err,
          f"motion list on a ROM that does not tell its layout: exit 1 naming --layout ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "list", "--layout", "2.2")
    check(rc == 0 and "slots used" in out, f"--layout 2.2 says it ({rc}: {err.strip()!r})")
    rc, out, err = run(*on, "motion", "buttons", "--layout", "2.2")
    check(rc == 0, f"motion buttons --layout 2.2 ({rc}: {err.strip()!r})")

# Boards that are not ours: an erased ROM, a silent board, one that NACKs everything.
board = StandIn()
rc, out, err = run("--device", board.path, "motion", "buttons")
check(rc == 1 and "cannot tell which HeartToHeart4 layout" in err, f"a stand-in with an erased ROM: exit 1 ({rc}: {err.strip()!r})")
rc, out, err = run("--device", board.path, "motion", "buttons", "set", "up", "1", "--layout", "2.2")
check(rc == 1 and "holds no motion" in err, f"set on an erased ROM: refused before anything is written ({rc}: {err.strip()!r})")
check(not any(f[1] == 0x00 and f[2] == 0x32 for f in board.frames), "nothing was written to its ROM")
rc, out, err = run("--device", StandIn(silent=True).path, "motion", "buttons", "--layout", "2.2")
check(rc == 4, f"a silent board: exit 4 ({rc}: {err.strip()!r})")
rc, out, err = run("--device", StandIn(mode="nack").path, "motion", "buttons", "press", "up", "--layout", "2.2")
check(rc == 1, f"a board that NACKs: exit 1 ({rc}: {err.strip()!r})")

finish()
