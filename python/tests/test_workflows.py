# pyrcb4's workflows that step with the clock (play a motion file from the host, record by
# demonstration), trims in RAM and ROM, stretch/speed/resume, and what the 2026-11-25 trial as an
# iory/rcb4 user found: Board.baud over TCP, one-line argument errors, close() from another thread,
# terminal settings another program changed. On the in-process board and `rcb4 serve --pty`.
# SPDX-License-Identifier: BSL-1.0
import os
import subprocess
import termios
import threading
import time

import pytest

import pyrcb4

FOREVER = [{"label": "top"}, {"pose": {"head_yaw": 10}, "time_ms": 300}, {"pose": {"head_yaw": -10}, "time_ms": 300},
           {"goto": "top"}]


def test_play_motion_file_at_the_authored_timing(board, tmp_path):
    steps = [{"pose": {"left_knee": 30}, "time_ms": 300}, {"pose": {"left_knee": -20, "head_yaw": 15}, "time_ms": 300},
             "end"]
    start = time.monotonic()
    r = board.play_motion_file(steps)
    took = time.monotonic() - start
    assert r["poses"] == 2 and r["calls"] == 0 and not r["interrupted"]
    assert 0.55 <= took < 2.0, took  # two poses of 300 ms, waited as the board plays them
    j = board.joints()
    assert abs(j["left_knee"] + 20) < 1 and abs(j["head_yaw"] - 15) < 1
    # The same from a file, and the tool's refusals.
    f = tmp_path / "k.yaml"
    f.write_text("robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - pose: {left_knee: 5}\n    time_ms: 100\n  - end\n")
    assert board.play_motion_file(f, rescale=True)["poses"] == 1
    with pytest.raises(pyrcb4.UsageError, match="nothing was sent"):
        board.play_motion_file([{"pose": {"left_knee": 300}, "time_ms": 100}, "end"])
    with pytest.raises(pyrcb4.UsageError, match="push it, then play"):
        board.play_motion_file(tmp_path / "slot.bin")


def test_play_motion_file_refused_while_a_motion_runs_and_a_callee_timed_out(board):
    board.push_motion(FOREVER, 31, backup="31.bin")
    board.play_motion(31, wait=False)
    with pytest.raises(pyrcb4.BoardRefused, match="motion 31 is running on the board: it would overwrite the move"):
        board.play_motion_file([{"pose": {"left_knee": 10}, "time_ms": 100}, "end"])
    board.stop_motion()
    with pytest.raises(pyrcb4.Timeout, match="motion 31, called at step 1, still ran after 0.3 s: stopped"):
        board.play_motion_file([{"call": 31}, "end"], timeout=0.3)
    assert not board.motion_status()["running"]


def test_record_then_push_and_play(board, tmp_path):
    out = tmp_path / "taught.yaml"
    r = board.record(out, joints=["left_leg"], every=0.05, seconds=0.4, free=True)
    assert r["held"] and r["samples"] >= 5 and r["file"] == str(out) and out.exists()
    poses = [s for s in r["steps"] if isinstance(s, dict) and "pose" in s]
    assert poses and set(poses[0]["pose"]) == {"left_hip_roll", "left_hip_pitch", "left_knee", "left_ankle_pitch",
                                               "left_ankle_roll"}
    assert all(s["target"] != 0x8000 for i, s in board.servos().items() if s["joint"].startswith("left_"))  # held
    assert board.push_motion(out, 12, backup="12.bin")["bytes"] > 0
    with pytest.raises(pyrcb4.UsageError, match="exists"):
        board.record(out, seconds=0.1)
    with pytest.raises(pyrcb4.UsageError, match="every"):
        board.record(every=5, seconds=0.1)
    board.push_motion(FOREVER, 31, backup="31.bin")
    board.play_motion(31, wait=False)
    with pytest.raises(pyrcb4.BoardRefused, match="not yours to move"):
        board.record(seconds=0.1, free=True)
    board.stop_motion()


def test_trims_in_ram_and_rom(board):
    counts = board.set_trims({"left_knee": 1.5, "head_yaw": -2}, persistent=True)
    assert set(counts) == {"left_knee", "head_yaw"} and 30 < abs(counts["left_knee"]) < 60
    board.set_trims({"left_knee": 3})
    assert abs(board.trims()["left_knee"] - 3) < 0.05
    assert abs(board.trims(rom=True)["left_knee"] - 1.5) < 0.05  # power-on still loads the one kept in ROM
    with pytest.raises(pyrcb4.LimitError, match="within ±30 degrees"):
        board.set_trims({"left_knee": 31})
    with pytest.raises(pyrcb4.UsageError, match="must be a number"):
        board.set_trims({"left_knee": "3"})


def test_stretch_speed_and_resume(board):
    assert board.stretch(60, "left_leg") == ["left_hip_roll", "left_hip_pitch", "left_knee", "left_ankle_pitch",
                                            "left_ankle_roll"]
    assert len(board.speed(127)) == 20
    for bad in (0, 128, 2.5):
        with pytest.raises(pyrcb4.UsageError, match="stretch"):
            board.stretch(bad)
    board.push_motion(FOREVER, 31, backup="31.bin")
    board.play_motion(31, wait=False)
    board.stop_motion()
    assert not board.motion_status()["running"]
    board.resume_motion()
    assert board.motion_status()["running"] and board.motion_status()["motion"] == 31
    board.stop_motion()


def test_argument_errors_are_one_line(board):
    for call in (lambda: board.play_motion("two"), lambda: board.read("ram", 3), lambda: pyrcb4.Board(robot=3)):
        with pytest.raises(pyrcb4.UsageError) as e:
            call()
        assert isinstance(e.value, TypeError) and isinstance(e.value, pyrcb4.ArgumentError)
        assert "\n" not in str(e.value) and "called with" in str(e.value), str(e.value)
    with pytest.raises(pyrcb4.ArgumentError, match=r"^play_motion\(n: int"):
        board.play_motion("two")


def test_close_from_another_thread_ends_a_wait(board):
    board.push_motion(FOREVER, 31, backup="31.bin")
    board.play_motion(31, wait=False)
    failed = []

    def waiter():
        try:
            board.wait_motion(timeout=30)
        except pyrcb4.Error as e:
            failed.append(e)

    t = threading.Thread(target=waiter)
    t.start()
    time.sleep(0.2)
    start = time.monotonic()
    board.close()
    t.join(5)
    assert time.monotonic() - start < 0.5 and not t.is_alive()
    assert failed and "closed" in str(failed[0])


def test_baud_over_tcp_is_unknown(rcb4_tool):
    srv = subprocess.Popen([rcb4_tool, "serve", "--tcp", "127.0.0.1:0"], stdout=subprocess.PIPE, text=True)
    try:
        where = "tcp:" + srv.stdout.readline().strip()
        with pyrcb4.Board(where) as b:
            assert b.baud is None
        with pyrcb4.Board(where, baud=1250000) as b:
            assert b.baud == 1250000
    finally:
        srv.terminate()
        srv.wait(timeout=10)
    with pyrcb4.Board() as b:
        assert b.baud in (115200, 625000, 1250000)


def test_terminal_settings_changed_by_another_program(served):
    with pyrcb4.Board(served) as b:
        try:
            fd = os.open(served, os.O_RDWR | os.O_NOCTTY)  # as root, past TIOCEXCL (what pyserial as root does)
        except OSError:
            pytest.skip("the port is exclusive here (not root)")
        try:
            attrs = termios.tcgetattr(fd)
            attrs[3] |= termios.ICANON | termios.ECHO  # stty sane: a cooked line
            attrs[4] = attrs[5] = termios.B9600
            termios.tcsetattr(fd, termios.TCSANOW, attrs)
        finally:
            os.close(fd)
        # The first call fails (how depends on what the cooked line did to the reply); when it is
        # the line's fault it names the change, never "unplugged" for ever; then the line is set again.
        with pytest.raises(pyrcb4.Error) as e:
            b.ping()
        if isinstance(e.value, pyrcb4.DeviceError):
            assert "another program changed" in str(e.value) and "set again" in str(e.value), str(e.value)
        # Set again: it answers. (The echoing line fed the board's replies back into the board,
        # whose parser resyncs only once that stops: on a loaded machine calls may time out for a
        # while. Within 10 s it must answer again, with no other call made.)
        deadline = time.monotonic() + 10
        while True:
            try:
                assert b.ping() < 1
                break
            except (pyrcb4.Timeout, pyrcb4.BadReply):  # the echoed bytes still draining
                if time.monotonic() > deadline:
                    raise


def test_a_slot_name_belongs_to_the_code_not_to_the_slot_number(board):
    # Two boards of one robot model share the names file (issue 41, H5): another board's push to
    # slot 14 must never rename this board's slot 14, which holds other code.
    other = pyrcb4.Board()
    try:
        board.push_motion({"name": "wave", "steps": [{"pose": {"head_yaw": 20}, "time_ms": 200}, "end"]}, 14,
                          backup="14a.bin")
        other.push_motion({"name": "bow", "steps": [{"pose": {"left_knee": 30}, "time_ms": 300}, "end"]}, 14,
                          backup="14b.bin")
        assert {m["slot"]: m["name"] for m in other.motions()}[14] == "bow"
        assert {m["slot"]: m["name"] for m in board.motions()}[14] is None  # not "bow": its code is not bow's
        assert board.pull_motion(14).get("name") in (None, "")
        # the same code on both boards: the name shows on both
        other.push_motion({"name": "wave", "steps": [{"pose": {"head_yaw": 20}, "time_ms": 200}, "end"]}, 14,
                          backup="14c.bin")
        assert {m["slot"]: m["name"] for m in board.motions()}[14] == "wave"
    finally:
        other.close()


def test_slot_names_kept_with_the_code(board):
    r = board.push_motion({"name": "wave", "steps": [{"pose": {"head_yaw": 20}, "time_ms": 200}, "end"]}, 14,
                          backup="14.bin")
    assert r["name"] == "wave"
    assert {m["slot"]: m["name"] for m in board.motions()}[14] == "wave"
    assert board.pull_motion(14)["name"] == "wave"
    board.erase_motion(14, backup="14e.bin")
    assert 14 not in {m["slot"] for m in board.motions()}
    board.push_motion([{"pose": {"head_yaw": 20}, "time_ms": 200}, "end"], 14, backup="14b.bin")
    assert {m["slot"]: m["name"] for m in board.motions()}[14] is None
