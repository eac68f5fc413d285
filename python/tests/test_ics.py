# pyrcb4.IcsServo and pyrcb4.ics_scan: one ICS servo on its own line, with the rules and refusals
# of `rcb4 ics` (rcb4/robot/services/ics.hpp), on the in-process virtual servo and on
# `rcb4 ics serve --pty` (virtual servos on a pseudo-terminal: several, silent, corrupt, ICS 3.5,
# another seed's factory bytes).
# SPDX-License-Identifier: BSL-1.0
import subprocess
import threading
import time

import pytest

import pyrcb4

# 1-based bytes of the servo's factory correction: never written (ics.md §4.2).
FACTORY = [n for n in range(1, 65) if 25 <= n <= 26 or 33 <= n <= 50 or 55 <= n <= 56]


def factory_bytes(image):
    return bytes(image[n - 1] for n in FACTORY)


def backups(directory):
    return sorted(directory.glob("ics-id*.bin"))


@pytest.fixture
def ics_serve(rcb4_tool):
    """Starts `rcb4 ics serve --pty OPTIONS...` and returns the pty's path; stopped after the test."""
    started = []

    def start(*options):
        srv = subprocess.Popen([rcb4_tool, "ics", "serve", "--pty", *options], stdout=subprocess.PIPE, text=True)
        started.append(srv)
        path = srv.stdout.readline().strip()
        assert path.startswith("/dev/"), f"rcb4 ics serve printed {path!r}"
        return path

    yield start
    for srv in started:
        srv.terminate()
        srv.wait(timeout=10)


@pytest.fixture(params=["in-process", "served"])
def servo(request, ics_serve):
    """Every API test runs twice: on the in-process virtual servo, and on `rcb4 ics serve --pty` by its path."""
    device = None if request.param == "in-process" else ics_serve()
    with pyrcb4.IcsServo(device) as s:
        yield s


def arrive(read, target, tolerance=1.0, deadline_s=5.0, every_s=0.01):
    """read() (degrees) polled every every_s until it is within tolerance of target (returned), or the test
    fails after deadline_s."""
    end = time.monotonic() + deadline_s
    while True:
        v = read()
        if abs(v - target) <= tolerance:
            return v
        assert time.monotonic() < end, f"at {v} degrees, not {target}, after {deadline_s} s"
        time.sleep(every_s)


def test_finds_the_one_servo(servo):
    assert servo.id == 0 and servo.baud == 115200 and servo.read_id() == 0
    assert not servo.closed and "IcsServo ID 0 at 115200 baud" in repr(servo)


def test_set_id_then_read_id(servo):
    assert servo.set_id(7) == 7
    assert servo.id == 7 and servo.read_id() == 7
    assert servo.eeprom()["id"] == 7 and servo.stretch() == 60  # it answers as 7 now
    assert servo.set_id(0) == 0 and servo.read_id() == 0
    for bad in (32, -1):
        with pytest.raises(pyrcb4.UsageError, match="0..31"):
            servo.set_id(bad)
    assert servo.read_id() == 0


def test_eeprom_fields(servo):
    e = servo.eeprom()
    raw = servo.eeprom_bytes()
    assert len(raw) == 64 and e["raw"] == raw and raw[:2] == b"\x05\x0a" and max(raw) <= 0x0F
    assert e["stretch"] == 60 and e["speed"] == 127 and e["baud"] == 115200 and e["id"] == 0
    assert e["max_limit"] == 11500 and e["min_limit"] == 3500
    assert e["reverse"] is False and e["pwm_inhibit"] is True
    assert e["free"] is True  # the virtual servo powers on limp, and its FREE status bit says so
    servo.move(degrees=10)
    assert servo.eeprom()["free"] is False  # holding now
    servo.free()
    assert servo.eeprom()["free"] is True
    assert [k for k in e if k != "raw"] == ["stretch", "speed", "punch", "dead_band", "damping", "safe_timer", "slave",
                                           "rotation", "pwm_inhibit", "free", "reverse", "max_limit", "min_limit",
                                           "baud", "temperature_limit", "current_limit", "response", "user_offset",
                                           "id", "stretch_1", "stretch_2", "stretch_3"]


def test_backup_set_restore(servo, tmp_path):
    original = servo.eeprom_bytes()
    kept = tmp_path / "kept.bin"
    assert servo.backup(kept) == {"file": str(kept), "id": 0, "baud": 115200}
    assert kept.read_bytes() == original

    r = servo.set(stretch=40, speed=100)
    assert r["written"] and r["changed"] == {"stretch": 40, "speed": 100} and r["notes"] == []
    # The old image is saved first, as `rcb4 ics set` names it, in backup_dir (".": the test's directory).
    first = backups(tmp_path)
    assert len(first) == 1 and r["backup"] == f"./{first[0].name}" and first[0].read_bytes() == original
    e = servo.eeprom()
    assert e["stretch"] == 40 and e["speed"] == 100
    assert servo.stretch() == 40 and servo.speed() == 100  # an EEPROM write reloads the live values
    changed = servo.eeprom_bytes()
    assert changed != original and factory_bytes(changed) == factory_bytes(original)
    assert [n for n in range(1, 65) if changed[n - 1] != original[n - 1]] == [3, 4, 5, 6]  # stretch ×2, speed

    r = servo.restore(kept)
    assert r["written"] and r["changed"] == {"stretch": 60, "speed": 127}
    assert servo.eeprom_bytes() == original  # byte for byte
    # Its own backup, not over the first even within the same second.
    assert len(backups(tmp_path)) == 2 and (tmp_path / r["backup"]).read_bytes() == changed
    assert first[0].read_bytes() == original

    again = servo.restore(kept)
    assert again == {"written": False, "changed": {}, "backup": None, "notes": []}
    assert len(backups(tmp_path)) == 2


def test_set_flags_and_backup_dir(servo, tmp_path):
    where = tmp_path / "olds"
    where.mkdir()
    r = servo.set(backup_dir=where, reverse=True, punch=3, user_offset=-5)
    assert r["changed"] == {"punch": 3, "reverse": True, "user_offset": -5} and r["backup"].startswith(str(where))
    e = servo.eeprom()
    assert e["reverse"] is True and e["punch"] == 3 and e["user_offset"] == -5
    assert servo.set(reverse=False)["changed"] == {"reverse": False}
    assert servo.set(reverse="on")["changed"] == {"reverse": True}  # the tool's words, as `rcb4 ics set` takes
    assert servo.set(reverse="no")["changed"] == {"reverse": False}
    with pytest.raises(pyrcb4.UsageError, match="give on or off"):
        servo.set(reverse="maybe")
    with pytest.raises(pyrcb4.UsageError, match="a number, not True or False"):
        servo.set(stretch=True)
    assert servo.set(punch=3)["written"] is False  # already so: nothing written, no backup


def test_set_refused_before_anything_is_written(servo, tmp_path):
    before = servo.eeprom_bytes()
    for fields, match in [({"stretch": 0}, "stretch=0: out of range 1..127"), ({"speed": 128}, "out of range"),
                          ({"baud": 9600}, "115200, 625000 or 1250000"), ({"id": 3}, r"set_id\(n\)"),
                          ({"free": True}, "cannot be set"), ({"stretchiness": 3}, "stretchiness: no such field"),
                          ({"stretch": 40.5}, "whole number"), ({"stretch": "40"}, "number"),
                          ({"stretch": None}, "number"), ({}, "give fields")]:
        with pytest.raises(pyrcb4.UsageError, match=match):
            servo.set(**fields)
    with pytest.raises(pyrcb4.UsageError, match="cannot write"):  # the backup fails: nothing written
        servo.set(backup_dir=tmp_path / "no" / "such", stretch=40)
    assert servo.eeprom_bytes() == before and backups(tmp_path) == []


def test_move_and_position(servo):
    was = servo.move(degrees=30)
    assert was["counts"] == 7500 and was["degrees"] == 0  # it powered on limp at neutral
    assert was["target"]["counts"] == 8389 and abs(was["target"]["degrees"] - 30) < 0.05
    arrive(servo.position, 30)
    assert abs(servo.position() - 30) <= 1  # and it stays there
    assert abs(servo.position_counts() - 8389) <= 30
    assert servo.temperature() in range(1, 128) and servo.current() in range(0, 128)
    back = servo.move(counts=7500)
    assert abs(back["degrees"] - 30) <= 1
    arrive(servo.position, 0)
    stopped = servo.free()
    assert abs(stopped["degrees"]) <= 1 and stopped["counts"] == servo.position_counts()
    for kwargs, match in [({}, "degrees=... .* or counts="), ({"degrees": 10, "counts": 8000}, "degrees=..."),
                          ({"degrees": 136}, "-135..135"), ({"counts": 3000}, "3500..11500"),
                          ({"counts": 70000}, "3500..11500"), ({"counts": 8000.5}, "whole number"),
                          ({"degrees": "x"}, "number")]:
        with pytest.raises(pyrcb4.UsageError, match=match):
            servo.move(**kwargs)


def test_stretch_and_speed(servo):
    assert servo.stretch() == 60 and servo.speed() == 127
    assert servo.stretch(50) == 50 and servo.stretch() == 50
    assert servo.speed(90) == 90 and servo.speed() == 90
    assert servo.eeprom()["stretch"] == 60  # set live: the EEPROM keeps its own
    for bad in (0, 128, 5000):
        with pytest.raises(pyrcb4.UsageError, match="out of range 1..127"):
            servo.stretch(bad)
    with pytest.raises(pyrcb4.UsageError):
        servo.speed(True)
    assert servo.stretch() == 50


def test_restore_refuses_bad_files(servo, tmp_path):
    short = tmp_path / "short.bin"
    short.write_bytes(b"\x05\x0a" * 5)
    with pytest.raises(pyrcb4.UsageError, match="holds 10 bytes"):
        servo.restore(short)
    wrong = tmp_path / "wrong.bin"
    wrong.write_bytes(b"\x00" * 64)
    with pytest.raises(pyrcb4.UsageError, match="no ICS EEPROM image"):
        servo.restore(wrong)
    with pytest.raises(pyrcb4.UsageError, match="cannot read"):
        servo.restore(tmp_path / "missing.bin")
    assert backups(tmp_path) == []


def test_closed(servo):
    servo.close()
    assert servo.closed and "(closed)" in repr(servo)
    with pytest.raises(pyrcb4.UsageError, match="closed"):
        servo.read_id()
    with pytest.raises(pyrcb4.UsageError, match="closed"):
        servo.id


def test_scan_in_process():
    assert pyrcb4.ics_scan() == [{"id": 0, "baud": 115200, "ics": "3.6", "stretch": 60, "speed": 127,
                                  "problem": None}]
    assert pyrcb4.ics_scan(bauds=[625000]) == []
    with pytest.raises(pyrcb4.UsageError, match="115200, 625000 or 1250000"):
        pyrcb4.ics_scan(bauds=[9600])
    with pytest.raises(pyrcb4.UsageError, match="bauds"):
        pyrcb4.ics_scan(bauds="115200")


def test_set_id_persists_on_the_line(ics_serve):
    path = ics_serve()
    with pyrcb4.IcsServo(path) as s:
        assert s.set_id(12) == 12
    with pyrcb4.IcsServo(path) as s:  # found again by the ID command
        assert s.id == 12 and s.read_id() == 12
    with pyrcb4.IcsServo(path, id=12, baud=115200) as s:
        assert s.stretch() == 60
    with pytest.raises(pyrcb4.Timeout, match="ICS servo 3 does not answer"):
        pyrcb4.IcsServo(path, id=3, baud=115200)


def test_two_servos_refuse_an_id_write(ics_serve, tmp_path):
    path = ics_serve("--servos", "2")
    with pytest.raises(pyrcb4.BoardRefused, match="more than one device"):
        pyrcb4.IcsServo(path)  # finding the one servo needs it alone
    with pyrcb4.IcsServo(path, id=1) as s:
        before = s.eeprom_bytes()
        with pytest.raises(pyrcb4.BoardRefused, match="more than one device answers the ID read"):
            s.set_id(5)
        with pytest.raises(pyrcb4.BoardRefused, match="more than one device"):
            s.read_id()
        assert s.id == 1 and s.eeprom_bytes() == before and s.eeprom()["id"] == 1
    # Nothing changed: both still answer as they did.
    found = pyrcb4.ics_scan(path)
    assert [(f["id"], f["baud"], f["problem"]) for f in found] == [(0, 115200, None), (1, 115200, None)]
    assert backups(tmp_path) == []


def test_silent_line_times_out(ics_serve):
    path = ics_serve("--silent")
    with pytest.raises(pyrcb4.Timeout, match="no ICS servo answers the ID read") as e:
        pyrcb4.IcsServo(path)
    assert isinstance(e.value, TimeoutError)
    with pytest.raises(pyrcb4.Timeout):
        pyrcb4.IcsServo(path, id=0, baud=115200)
    assert pyrcb4.ics_scan(path) == []


def test_the_gil_is_released_while_the_line_waits(ics_serve):
    path = ics_serve("--silent")
    raised = []

    def find():
        try:
            pyrcb4.IcsServo(path, timeout=0.5)  # three rates, half a second each, in one call
        except pyrcb4.Error as e:
            raised.append(e)

    t = threading.Thread(target=find)
    t.start()
    gap, last = 0.0, time.monotonic()
    while t.is_alive():  # Python runs here while the other thread waits on the line
        now = time.monotonic()
        gap, last = max(gap, now - last), now
    t.join()
    assert len(raised) == 1 and isinstance(raised[0], pyrcb4.Timeout)
    assert gap < 0.25, f"this thread stood still {gap:.3f} s"


def test_corrupt_line_is_refused(ics_serve):
    path = ics_serve("--corrupt")
    with pytest.raises(pyrcb4.BoardRefused, match="not an ID reply"):
        pyrcb4.IcsServo(path)
    with pytest.raises(pyrcb4.BoardRefused, match="bad answer to the stretch read"):
        pyrcb4.IcsServo(path, id=0, baud=115200)
    found = pyrcb4.ics_scan(path, bauds=[115200])
    assert found and all(f["problem"] and f["ics"] is None and f["stretch"] is None for f in found)


def test_restore_of_another_servos_backup(ics_serve, tmp_path):
    # A backup of the in-process servo (seed 1), its settings changed first ...
    with pyrcb4.IcsServo() as mine:
        mine.set(backup_dir=tmp_path, stretch=20, reverse=True)
        mine.backup(tmp_path / "seed1.bin")
        theirs = mine.eeprom_bytes()
    for old in backups(tmp_path):
        old.unlink()
    # ... onto a served servo with other factory bytes.
    with pyrcb4.IcsServo(ics_serve("--seed", "7")) as s:
        before = s.eeprom_bytes()
        assert factory_bytes(before) != factory_bytes(theirs)
        with pytest.raises(pyrcb4.BoardRefused, match="another servo") as e:
            s.restore(tmp_path / "seed1.bin")
        assert "force=True" in str(e.value)
        assert s.eeprom_bytes() == before and backups(tmp_path) == []
        r = s.restore(tmp_path / "seed1.bin", force=True)
        assert r["written"] and r["changed"] == {"stretch": 20, "reverse": True}
        assert any("factory bytes were not written" in n for n in r["notes"])
        after = s.eeprom_bytes()
        assert factory_bytes(after) == factory_bytes(before)  # this servo's own, kept
        assert all(after[n - 1] == theirs[n - 1] for n in range(1, 65) if n not in FACTORY)
        assert len(backups(tmp_path)) == 1 and backups(tmp_path)[0].read_bytes() == before


def test_ics35_servo(ics_serve):
    path = ics_serve("--ics35")
    assert pyrcb4.ics_scan(path, bauds=[115200])[0]["ics"] == "3.5"
    with pyrcb4.IcsServo(path) as s:
        with pytest.raises(pyrcb4.BoardRefused, match="ICS 3.6 position read"):
            s.position()
        assert s.move(degrees=10)["counts"] == 7500
        # A 3.5 servo tells where it stands in reply to a position command: the same target again.
        arrive(lambda: s.move(degrees=10)["degrees"], 10)
        assert abs(s.free()["degrees"] - 10) <= 1


def test_other_rates_and_ids(ics_serve):
    path = ics_serve("--servos", "2", "--servo-baud", "625000", "--servo-id", "3")
    found = pyrcb4.ics_scan(path)
    assert [(f["id"], f["baud"], f["ics"]) for f in found] == [(3, 625000, "3.6"), (4, 625000, "3.6")]
    assert pyrcb4.ics_scan(path, bauds=[115200, 1250000]) == []
    with pyrcb4.IcsServo(path, id=4) as s:  # each rate in turn
        assert s.id == 4 and s.baud == 625000
    with pytest.raises(pyrcb4.Timeout, match="at 115200"):
        pyrcb4.IcsServo(path, id=4, baud=115200)


def test_baud_change_moves_the_line(ics_serve):
    path = ics_serve()
    with pyrcb4.IcsServo(path) as s:
        r = s.set(baud=625000)
        assert r["changed"] == {"baud": 625000} and any("625000" in n for n in r["notes"])
        assert "--baud" not in " ".join(r["notes"])  # the tool's words, as Python's
        assert s.baud == 625000 and s.eeprom()["baud"] == 625000
    with pyrcb4.IcsServo(path) as s:
        assert s.baud == 625000
        s.set(baud=115200)
    assert pyrcb4.ics_scan(path)[0]["baud"] == 115200


def test_opening_is_checked():
    with pytest.raises(pyrcb4.DeviceError) as e:
        pyrcb4.IcsServo("/dev/no-such-adapter")
    assert e.value.errno == 2
    for kwargs, match in [({"id": 32}, "0..31"), ({"baud": 9600}, "115200, 625000 or 1250000"),
                          ({"timeout": 0}, "timeout"), ({"device": ""}, "names no device"),
                          ({"device": 3}, "device")]:
        with pytest.raises(pyrcb4.UsageError, match=match):
            pyrcb4.IcsServo(**kwargs)
    with pytest.raises(pyrcb4.ArgumentError, match="set_id"):
        pyrcb4.IcsServo().set_id()


def test_backup_never_replaces_a_file_unless_forced(servo, tmp_path):
    kept = tmp_path / "a.bin"
    servo.backup(kept)
    with pytest.raises(pyrcb4.UsageError, match="exists"):
        servo.backup(kept)
    assert servo.backup(kept, force=True)["file"] == str(kept)


def test_slave_flag_needs_force(servo, tmp_path):
    before = servo.eeprom_bytes()
    with pytest.raises(pyrcb4.UsageError, match="never answer"):
        servo.set(backup_dir=tmp_path, slave=True)
    assert servo.eeprom_bytes() == before
    assert backups(tmp_path) == []
