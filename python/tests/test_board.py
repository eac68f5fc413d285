# pyrcb4 as a Python user calls it: the in-process virtual board and `rcb4 serve --pty`, every
# call of the API, and the exceptions bad boards raise (before their timeout, never a hang).
# SPDX-License-Identifier: BSL-1.0
import math
import os
import re
import signal
import subprocess
import threading
import time

import numpy
import pytest

import pyrcb4
from standin import StandIn


def test_version_is_the_projects(rcb4_tool):
    out = subprocess.run([rcb4_tool, "--version"], capture_output=True, text=True).stdout
    assert re.fullmatch(r"\d+\.\d+\.\d+", pyrcb4.__version__)
    assert pyrcb4.__version__ in out


def test_exceptions_are_one_hierarchy():
    for e in (pyrcb4.BoardRefused, pyrcb4.Timeout, pyrcb4.DeviceError, pyrcb4.BadReply, pyrcb4.LimitError,
              pyrcb4.UsageError):
        assert issubclass(e, pyrcb4.Error)
    assert issubclass(pyrcb4.Timeout, TimeoutError) and issubclass(pyrcb4.DeviceError, OSError)
    assert issubclass(pyrcb4.LimitError, ValueError) and issubclass(pyrcb4.UsageError, ValueError)


def test_raw_level(board):
    assert 0 < board.ping() < 1
    assert board.version().startswith("CB-4")
    c = board.config
    assert c["ics"] and c["period_ms"] == 10 and c["baud"] in (115200, 625000, 1250000)
    board.write(0x0460, b"\x12\x34")
    assert board.read(0x0460, 2) == b"\x12\x34"
    assert len(board.read(0x0000, 1000, memory="rom")) == 1000
    with pytest.raises(pyrcb4.UsageError, match="'ram' or 'rom'"):
        board.read(0, 2, memory="eeprom")
    with pytest.raises(pyrcb4.UsageError):
        board.read(0x0480, 100)  # past the end of RAM: refused before anything is sent


def test_joints_in_degrees_and_numpy(board):
    j = board.joints()
    assert list(j) == board.joint_names and len(j) == 20
    assert all(abs(v) < 0.1 for v in j.values())
    v = board.angle_vector()
    assert isinstance(v, numpy.ndarray) and v.shape == (20,) and v.dtype == numpy.float64


def test_move_within_limits_and_refused_beyond(board):
    took = board.move({"left_knee": 40, "head_yaw": -20.5}, time=0.3)
    assert 0.25 <= took <= 0.35
    j = board.joints()
    assert abs(j["left_knee"] - 40) < 0.1 and abs(j["head_yaw"] + 20.5) < 0.1
    with pytest.raises(pyrcb4.LimitError, match=r"left_knee: 131 degrees is beyond its upper limit 130"):
        board.move({"left_knee": 131, "head_yaw": 0})
    assert abs(board.joints()["head_yaw"] + 20.5) < 0.1  # nothing moved: not even the joint within its limit
    with pytest.raises(pyrcb4.UsageError, match="no joint of KHR-3HV is called 'left_kneee'"):
        board.move({"left_kneee": 3})
    with pytest.raises(pyrcb4.UsageError, match="degrees must be a number"):
        board.move({"left_knee": "ten"})
    assert numpy.isclose(board.angle_vector()[board.joint_names.index("left_knee")], 40, atol=0.1)


def test_free_and_hold(board):
    assert board.free("left_arm") == ["left_shoulder_pitch", "left_shoulder_roll", "left_elbow_yaw",
                                       "left_elbow_pitch"]
    assert len(board.hold()) == 20
    assert board.free(["head", "right_knee"]) == ["head_yaw", "right_knee"]
    with pytest.raises(pyrcb4.UsageError):
        board.free("tail")


def test_motions(board):
    ms = board.motions()
    assert [(m["slot"], m["name"]) for m in ms] == [(1, "home"), (2, "wave"), (3, "bow")]
    start = time.monotonic()
    st = board.play_motion(2)
    assert 0.5 < time.monotonic() - start < 5 and not st["running"]
    assert board.play_motion(3, wait=False) is None
    assert board.motion_status()["motion"] == 3
    board.stop_motion()
    assert board.motion_status()["suspended"]
    with pytest.raises(pyrcb4.UsageError):
        board.play_motion(121)


def test_sensors(board):
    s = board.sensors()
    assert 5 < s["battery_volts"] < 20 and len(s["ad"]) == 11 and s["button_names"] == [] and len(s["pa"]) == 4
    assert abs(s["ad_volts"][0] * 5 - s["battery_volts"]) < 0.02  # AD0 is the supply / 5 (protocol.md §6)
    board.write(0x0350, b"\x02\x01")  # UP + S1 as a KRR receiver leaves them (protocol.md §6: 02 01)
    assert board.sensors()["button_names"] == ["up", "s1"]


def test_closed_board_and_context_manager():
    with pyrcb4.Board() as b:
        assert not b.closed and "virtual" in repr(b)
    assert b.closed and "closed" in repr(b)
    with pytest.raises(pyrcb4.UsageError, match="closed"):
        b.ping()
    b.close()  # twice is fine


def test_served_board_by_path(served):
    with pyrcb4.Board(served) as b:
        assert b.where == served and b.baud in (115200, 625000, 1250000)
        b.move({"left_knee": 20}, time=0.1)
        assert abs(b.joints()["left_knee"] - 20) < 0.1


def test_device_errors():
    with pytest.raises(pyrcb4.DeviceError, match="No such file"):
        pyrcb4.Board("/dev/rcb4-no-such-port")
    with pytest.raises(pyrcb4.DeviceError, match="not a serial port"):
        pyrcb4.Board("/dev/null", baud=115200)
    with pytest.raises(pyrcb4.UsageError):
        pyrcb4.Board("")
    with pytest.raises(pyrcb4.UsageError, match="115200, 625000 or 1250000"):
        pyrcb4.Board(baud=9600)
    with pytest.raises(pyrcb4.UsageError, match="robot"):
        pyrcb4.Board(robot="no-such-robot")


def test_bad_boards_raise_before_their_timeout():
    start = time.monotonic()
    with pytest.raises(pyrcb4.Timeout):
        pyrcb4.Board(StandIn(silent=True).path, baud=115200)
    assert time.monotonic() - start < 2
    with pytest.raises(pyrcb4.BoardRefused):
        pyrcb4.Board(StandIn(mode="nack").path, baud=115200)
    with pytest.raises(pyrcb4.BadReply):
        pyrcb4.Board(StandIn(mode="badsum").path, baud=115200)
    with pytest.raises(pyrcb4.BadReply):
        pyrcb4.Board(StandIn(mode="short").path, baud=115200).read(0x0000, 2)
    b = pyrcb4.Board(StandIn(mode="die", die_after=3).path, baud=115200)
    with pytest.raises((pyrcb4.Timeout, pyrcb4.DeviceError)):
        for _ in range(10):
            b.version()


def test_ctrl_c_interrupts_a_wait_within_100_ms(board):
    board.play_motion(2, wait=False)
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        board.wait_motion(timeout=10)
    assert time.monotonic() - start < 0.3 + 0.2
    board.wait_motion(timeout=10)


def test_the_gil_is_released_and_two_threads_share_a_board(board):
    counted = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            counted[0] += 1

    def reads(errors):
        try:
            for _ in range(40):
                assert len(board.joints()) == 20
                board.ping()
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    t = threading.Thread(target=count)
    t.start()
    errors = []
    workers = [threading.Thread(target=reads, args=(errors,)) for _ in range(2)]
    for w in workers:
        w.start()
    board.play_motion(2)  # this thread waits in C++ meanwhile
    for w in workers:
        w.join()
    stop.set()
    t.join()
    assert not errors and counted[0] > 1000


def test_poses_capture_play_and_files(board, tmp_path, rcb4_tool):
    board.move({"left_knee": 30, "head_yaw": 15}, time=0.1)
    pose = board.capture()
    assert len(pose) == 20 and abs(pose["left_knee"] - 30) < 0.1
    path = tmp_path / "bent.yaml"
    pyrcb4.save_pose(path, pose, time=0.2)
    r = subprocess.run([rcb4_tool, "pose", "show", str(path)], capture_output=True, text=True)
    assert r.returncode == 0 and "left_knee" in r.stdout  # the tool reads what Python wrote
    loaded = pyrcb4.load_pose(path)
    assert loaded["robot"] == "KHR-3HV" and loaded["time"] == 0.2 and abs(loaded["joints"]["head_yaw"] - 15) < 0.1
    board.move({"left_knee": 0, "head_yaw": 0}, time=0.1)
    assert 0.15 < board.play(path) < 0.25  # the file's 200 ms
    assert abs(board.joints()["left_knee"] - 30) < 0.1
    board.play({"left_knee": -10}, time=0.1)
    assert abs(board.joints()["left_knee"] + 10) < 0.1
    with pytest.raises(pyrcb4.LimitError, match="head_yaw: 95 degrees is beyond its upper limit 90"):
        board.play({"head_yaw": 95})
    with pytest.raises(pyrcb4.UsageError, match="missing.yaml"):
        board.play(tmp_path / "missing.yaml")
    with pytest.raises(pyrcb4.UsageError, match="no joint of KHR-3HV"):
        pyrcb4.save_pose(tmp_path / "x.yaml", {"tail": 3})


def test_trims_servos_and_scan(board):
    board.set_trims({"left_knee": 2.5})
    assert abs(board.trims()["left_knee"] - 2.5) < 0.05
    with pytest.raises(pyrcb4.LimitError, match="within ±30 degrees"):
        board.set_trims({"left_knee": 31})
    s = board.servos()
    assert sorted(s) == [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21]
    assert s[16]["joint"] == "left_knee" and s[16]["answered"] and s[16]["trim"] > 0
    scan = board.scan()
    assert len(scan) == 20 and all(p["answers"] for p in scan) and scan[0]["joint"] == "head_yaw"


def test_control_loop(board):
    loop = board.control_loop()
    assert loop.size == 20
    q = loop.read()
    assert q.shape == (20,) and numpy.all(numpy.abs(q) < 0.1)
    k = board.joint_names.index("left_knee")
    target = numpy.full(20, numpy.nan)
    target[k] = 25.0
    loop.write(target, frames=1)
    time.sleep(0.05)
    same = loop.read(out=q)
    assert same is q and abs(q[k] - 25) < 0.1
    target[k] = 131.0
    with pytest.raises(pyrcb4.LimitError, match="left_knee: 131 degrees is beyond its upper limit 130"):
        loop.write(target)
    time.sleep(0.05)
    assert abs(loop.read()[k] - 25) < 0.1  # nothing was sent
    with pytest.raises(pyrcb4.UsageError):
        loop.write(numpy.zeros(3))
    # A write names only its joints: one still on its way elsewhere goes on at its own pace.
    h = board.joint_names.index("head_yaw")
    board.move({"head_yaw": 60}, time=2.0, wait=False)
    target[:] = numpy.nan
    target[k] = 20.0
    loop.write(target, frames=1)
    time.sleep(0.3)
    q = loop.read()
    assert abs(q[k] - 20) < 0.1 and 0 < q[h] < 30, f"head_yaw must still be on its 2 s way ({q[h]})"
    loop.write(numpy.full(20, numpy.nan))  # nothing named: nothing sent


def test_config_fields_and_servos_by_ics(board):
    board.set_config(led=True, period_ms=15)
    c = board.config
    assert c["led"] and c["period_ms"] == 15
    with pytest.raises(pyrcb4.UsageError, match="not a field it writes"):
        board.set_config(baud=625000)
    with pytest.raises(pyrcb4.UsageError, match="10, 15, 20 or 25"):
        board.set_config(period_ms=12)
    board.set_config(period_ms=10)
    board.move_servos({16: 8389, 0: "hold"}, frames=1)
    time.sleep(0.05)
    assert board.servos()[16]["position"] == 8389 and abs(board.joints()["left_knee"] - 30) < 0.1
    board.move_servos({16: "free"})
    assert board.servos()[16]["target"] == 0x8000
    with pytest.raises(pyrcb4.BoardRefused, match="ICS 30 has no servo block"):
        board.move_servos({30: 7500})
    with pytest.raises(pyrcb4.UsageError):
        board.move_servos({16: 20000})


def test_what_a_newcomer_found(board, tmp_path):
    # No crash on a closed board, whatever is called.
    b = pyrcb4.Board()
    b.close()
    for call in (b.scan, b.joints, b.servos, b.trims, b.capture, b.control_loop, b.version):
        with pytest.raises(pyrcb4.UsageError, match="closed"):
            call()
    with pytest.raises(pyrcb4.UsageError, match="closed"):
        with b:
            pass
    # read(out=...) fills the array given, or refuses: never a silent copy.
    loop = board.control_loop()
    for bad in (numpy.zeros(20, numpy.float32), numpy.zeros(40)[::2], [0.0] * 20):
        with pytest.raises(pyrcb4.UsageError, match="contiguous float64"):
            loop.read(out=bad)
    # No move while a ROM motion runs (it would overwrite it); the reason is said.
    board.play_motion(2, wait=False)
    with pytest.raises(pyrcb4.BoardRefused, match="motion 2 is running"):
        board.move({"left_knee": 10})
    with pytest.raises(pyrcb4.BoardRefused, match="motion 2 is running"):
        board.move_servos({16: 7600})
    board.wait_motion()
    # Too long a move is a limit, an empty slot the board lacking it.
    with pytest.raises(pyrcb4.LimitError, match="255 output periods"):
        board.move({"left_knee": 5}, time=3.0)
    with pytest.raises(pyrcb4.BoardRefused, match="holds no motion"):
        board.play_motion(7)
    # load_pose's result plays as it is; numpy integers are numbers; bytes-likes write.
    pyrcb4.save_pose(tmp_path / "p.json", {"left_knee": 12}, time=0.1)
    board.play(pyrcb4.load_pose(tmp_path / "p.json"))
    assert abs(board.joints()["left_knee"] - 12) < 0.1
    board.move_servos({numpy.int64(16): numpy.uint16(7600)}, frames=1)
    with pytest.raises(pyrcb4.UsageError, match="ICS number"):
        board.move_servos({"16": 7500})
    board.write(0x0460, bytearray(b"\x01\x02"))
    board.write(0x0462, numpy.array([3, 4], dtype=numpy.uint8))
    board.write(0x0464, memoryview(b"\x05"))
    assert board.read(0x0460, 5) == b"\x01\x02\x03\x04\x05" and board.read(0x0460, 0) == b""


def test_device_errors_carry_errno():
    import errno
    with pytest.raises(pyrcb4.DeviceError) as e:
        pyrcb4.Board("/dev/rcb4-no-such-port")
    assert e.value.errno == errno.ENOENT and "rcb4-no-such-port" in str(e.value)
