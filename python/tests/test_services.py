# pyrcb4's robot services as a Python user calls them: motion slots (show, pull, push, erase), the
# remote's buttons, the whole ROM; the same refusals as the rcb4 tool (rcb4/robot/services/), on
# the in-process virtual board and on `rcb4 serve --pty`.
# SPDX-License-Identifier: BSL-1.0
import time
import zlib

import pytest

import pyrcb4

SLOT = 0x0B80  # HTH4 2.2+: motion N at 0x0B80 + (N-1) * 0x800


def slot(n):
    return SLOT + (n - 1) * 0x800


KNEE = """robot: KHR-3HV
period_ms: 10
steps:
  - set_counter: 2
  - label: again
  - pose: {left_knee: 30}
    time_ms: 300
  - pose: {left_knee: 0}
    time_ms: 300
  - loop: again
  - end
"""


def test_push_pull_erase_round_trip(board, tmp_path):
    f = tmp_path / "knee.yaml"
    f.write_text(KNEE)
    backup = tmp_path / "ten.bin"
    r = board.push_motion(f, 10, backup=backup)
    assert r["motion"] == 10 and r["address"] == slot(10) and not r["unchanged"] and r["backup"] == str(backup)
    assert backup.read_bytes() == b"\xff" * 2048  # the slot was empty
    assert board.read(slot(10), r["bytes"], memory="rom").hex(" ") == r["hex"].lower()
    pulled = board.pull_motion(10)
    assert pulled["robot"] == "KHR-3HV" and pulled["period_ms"] == 10 and pulled["file"] is None
    poses = [s for s in pulled["steps"] if "pose" in s]
    assert [p["pose"] for p in poses] == [{"left_knee": 30}, {"left_knee": 0}]
    assert [p["time_ms"] for p in poses] == [300, 300]
    # The steps pushed back give the same bytes (the slot is unchanged), and pull the same again;
    # into another slot, the same code but for its jumps (labels are named by their address).
    assert board.push_motion(pulled, 10)["unchanged"]
    assert board.pull_motion(10)["steps"] == pulled["steps"]
    again = board.push_motion(pulled, 11, backup=tmp_path / "eleven.bin")
    assert again["bytes"] == r["bytes"] and len(board.pull_motion(11)["steps"]) == len(pulled["steps"])
    # A list of steps, its times in the board's period.
    listed = board.push_motion([{"pose": {"head_yaw": 20}, "time_ms": 200}, "end"], 12, backup=tmp_path / "12.bin")
    assert listed["bytes"] > 0 and board.pull_motion(12)["steps"][0] == {"pose": {"head_yaw": 20}, "time_ms": 200}
    # Written to a file, then refused over it without force.
    out = tmp_path / "pulled.yaml"
    assert board.pull_motion(10, out)["file"] == str(out) and "left_knee: 30" in out.read_text()
    with pytest.raises(pyrcb4.UsageError, match="exists"):
        board.pull_motion(10, out)
    # Erase, then the backup puts it back.
    e = board.erase_motion(10, backup=tmp_path / "erased10.bin")
    assert not e["unchanged"] and board.read(slot(10), 4, memory="rom") == b"\xff" * 4
    board.push_motion(tmp_path / "erased10.bin", 10)
    assert board.read(slot(10), r["bytes"], memory="rom").hex(" ") == r["hex"].lower()
    shown = board.show_motion(10)
    assert not shown["empty"] and not shown["problems"] and shown["code"][0]["address"] == slot(10)
    assert board.show_motion(100)["empty"]


def test_push_refusals(board, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(KNEE.replace("left_knee: 30", "left_knee: 300"))
    with pytest.raises(pyrcb4.UsageError, match="beyond its upper limit"):
        board.push_motion(bad, 10)
    with pytest.raises(pyrcb4.UsageError, match="outside 1..120"):
        board.push_motion(bad, 121)
    calls = tmp_path / "calls.yaml"
    calls.write_text("robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - call: 9\n  - end\n")
    with pytest.raises(pyrcb4.BoardRefused, match="holds no motion"):
        board.push_motion(calls, 6)
    assert board.read(slot(6), 1, memory="rom") == b"\xff"
    huge = tmp_path / "huge.yaml"
    with open(huge, "wb") as f:
        f.seek(50 * 1024 * 1024)
        f.write(b"\n")
    with pytest.raises(pyrcb4.UsageError, match="more than 4 MiB"):
        board.push_motion(huge, 6)
    with pytest.raises(pyrcb4.UsageError, match=".bin"):
        board.push_motion(calls, 6, backup=tmp_path / "x.yaml")


def test_push_refused_over_a_caller_stopped_part_way(board, tmp_path):
    forever = tmp_path / "forever.yaml"
    forever.write_text("robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - label: top\n  - pose: {head_yaw: 10}\n"
                       "    time_ms: 300\n  - pose: {head_yaw: -10}\n    time_ms: 300\n  - goto: top\n")
    board.push_motion(forever, 31, backup=tmp_path / "31.bin")
    board.push_motion([{"call": 31}, "end"], 30, backup=tmp_path / "30.bin")
    board.play_motion(30, wait=False)
    until = time.monotonic() + 5
    while board.motion_status()["motion"] != 31 and time.monotonic() < until:
        time.sleep(0.02)
    board.stop_motion()
    before = board.read(slot(30), 16, memory="rom")
    with pytest.raises(pyrcb4.BoardRefused, match="return into motion 30"):
        board.push_motion([{"pose": {"head_yaw": 5}, "time_ms": 100}, "end"], 30, backup=tmp_path / "r30.bin")
    assert board.read(slot(30), 16, memory="rom") == before and not (tmp_path / "r30.bin").exists()
    with pytest.raises(pyrcb4.BoardRefused, match="stopped part way"):
        board.erase_motion(31, backup=tmp_path / "r31.bin")


def test_play_refuses_a_broken_slot(board, tmp_path):
    board.push_motion([{"pose": {"head_yaw": 15}, "time_ms": 150}, "end"], 80, backup=tmp_path / "80.bin")
    first = board.read(slot(80), 1, memory="rom")[0]
    board.write(slot(80) + first, bytes.fromhex("07 0B 00 00 00 00 00"), memory="rom")  # a bad checksum
    with pytest.raises(pyrcb4.BoardRefused, match="is broken") as e:
        board.play_motion(80)
    assert "show_motion(80) lists its code" in str(e.value) and "rcb4" not in str(e.value)
    assert not board.motion_status()["running"]


def test_rom_restore_without_its_crc_says_what_to_do(board, tmp_path):
    image = tmp_path / "image.bin"
    image.write_bytes(b"\xff" * 262144)
    with pytest.raises(pyrcb4.UsageError) as e:
        board.rom_restore(image)
    text = str(e.value)
    assert text.startswith("rom_restore: ") and "image.bin.crc32 is missing" in text and "no_check=True" in text
    assert "FILE" not in text and "--" not in text


def test_a_loop_plays_and_a_caller_of_an_erased_slot_does_not(board, tmp_path):
    loop = [{"label": "top"}, {"pose": {"head_yaw": 20}, "time_ms": 150}, {"pose": {"head_yaw": -20}, "time_ms": 150},
            {"goto": "top"}]
    board.push_motion(loop, 93, backup=tmp_path / "93.bin")
    board.push_motion([{"pose": {"left_knee": 40}, "time_ms": 900}, {"call": 93}, "end"], 94, backup=tmp_path / "94.bin")
    listed = {m["slot"]: m for m in board.motions()}
    assert listed[93]["endless"] and listed[93]["seconds"] == float("inf") and not listed[93]["broken"]
    assert not listed[94]["broken"] and listed[94]["problem"] is None
    assert board.erase_motion(93, backup=tmp_path / "93b.bin")["callers"] == [94]
    listed = {m["slot"]: m for m in board.motions()}
    assert listed[94]["broken"] and "calls motion 93, which holds no motion" in listed[94]["problem"]
    knee = board.joints()["left_knee"]
    with pytest.raises(pyrcb4.BoardRefused, match="motion 94 calls motion 93 .* holds no motion"):
        board.play_motion(94)
    assert not board.motion_status()["running"] and board.joints()["left_knee"] == knee
    board.erase_motion(94, backup=tmp_path / "94b.bin")


def test_buttons(board):
    t = board.buttons()
    assert t["same"] and [e["buttons"] for e in t["ram"]] == ["up", "down"]
    r = board.set_button("s1+up", 3)
    assert r["done"] == "up+s1 plays motion 3"
    assert [(e["motion"], e["action"]) for e in r["entries"] if e["buttons"] == "up+s1"] == [(3, "call")]
    p = board.press("s1+up")
    assert p["entry"] and p["motion"] == 3 and not p["held"]
    board.wait_motion(5)
    r = board.clear_button("s1+up")
    assert "up+s1" not in [e["buttons"] for e in r["entries"]]
    with pytest.raises(pyrcb4.BoardRefused, match="no entry plays anything"):
        board.clear_button("s1+up")
    with pytest.raises(pyrcb4.BoardRefused, match="hold=True"):
        board.press("triangle+square")
    held = board.press("triangle+square", hold=True)
    assert held["held"] and not held["entry"] and board.read(0x0350, 2) != b"\x00\x00"
    board.release()
    assert board.read(0x0350, 2) == b"\x00\x00"
    with pytest.raises(pyrcb4.UsageError, match="buttons"):
        board.set_button("s9", 3)
    with pytest.raises(pyrcb4.BoardRefused, match="holds no motion"):
        board.set_button("s2", 7)


def test_rom_backup_and_restore(board, tmp_path):
    image = tmp_path / "all.bin"
    r = board.rom_backup(image)
    data = image.read_bytes()
    assert r["bytes"] == 262144 == len(data) and r["crc32"] == f"{zlib.crc32(data):08x}"
    assert (tmp_path / "all.bin.crc32").read_text().split()[0] == r["crc32"]
    with pytest.raises(pyrcb4.UsageError, match="exists"):
        board.rom_backup(image)
    board.set_button("s3", 1)
    assert board.rom_restore(image)["pieces_written"] >= 1
    t = board.buttons()
    assert t["same"] and "s3" not in [e["buttons"] for e in t["ram"]]  # RAM follows the restored ROM
    assert board.rom_restore(image)["unchanged"]
    erased = tmp_path / "erased.bin"
    erased.write_bytes(b"\xff" * 262144)
    with pytest.raises(pyrcb4.UsageError, match="not a plausible RCB-4 ROM"):
        board.rom_restore(erased, no_check=True)
    with pytest.raises(pyrcb4.UsageError, match="crc32 is missing"):
        board.rom_restore(erased)


def test_move_refusal_is_the_one_rule():
    assert pyrcb4.move_refusal({"running": True, "motion": 3}) == (
        "motion 3 is running on the board: it would overwrite the move, so nothing was sent")
    assert pyrcb4.move_refusal({"running": True, "motion": None}) is None
    assert pyrcb4.move_refusal({"running": False, "motion": 3}) is None


def test_board_takes_rcb4_device_as_the_tool_does(served, monkeypatch):
    monkeypatch.setenv("RCB4_DEVICE", served)
    with pyrcb4.Board() as b:
        assert served in b.where and b.ping() > 0
    monkeypatch.setenv("RCB4_DEVICE", "")
    with pytest.raises(pyrcb4.UsageError, match="RCB4_DEVICE is set but empty"):
        pyrcb4.Board()


def test_a_simulation_says_so_once():
    import os
    import subprocess
    import sys
    from conftest import PRELOAD
    env = {k: v for k, v in os.environ.items() if k != "RCB4_DEVICE"}
    if PRELOAD:  # a sanitized module needs its runtime in that Python too
        env["LD_PRELOAD"] = PRELOAD
    p = subprocess.run([sys.executable, "-c", "import pyrcb4\nb = pyrcb4.Board(); print(b.where); b.close()\n"
                        "pyrcb4.Board().close()"], capture_output=True, text=True, env=env, timeout=60)
    assert p.returncode == 0 and "a simulation" in p.stdout
    assert p.stderr.count("an in-process virtual board, a simulation") == 1
