#!/usr/bin/env python3
# The robot layer through the rcb4 tool, as a robot owner uses it: `rcb4 serve --pty` (a virtual
# KHR-3HV) in one process, joint/pose/trim/scan/motion commands from others, checked through
# their exit codes, their JSON and the board's own answers. Expected angles are worked out by hand.
# SPDX-License-Identifier: BSL-1.0
import json
import re
import os
import signal
import subprocess
import sys
import tempfile
import time

RCB4 = sys.argv[1]
PROFILES = sys.argv[2]
README_JOINTS = sys.argv[3] if len(sys.argv) > 3 else None  # the README's joints.cpp, built
from checks import check, finish, tool
from standin import StandIn

run, serve = tool(RCB4)  # run(*args) -> (exit code, stdout, stderr); with serve(*args) as device: ...


def joints():
    rc, out, err = run("--json", *on, "joint", "list")
    assert rc == 0, err
    return {j["name"]: j for j in json.loads(out)}


with serve() as dev:
    on = ["--device", dev]
    js = joints()
    check(len(js) >= 17 and all(j["allocated"] for j in js.values()),
          f"--json joint list on serve --pty: {len(js)} joints, every one on an allocated slot")
    check(js["left_knee"]["ics"] == 16 and js["left_knee"]["id"] == 8 and js["left_knee"]["bus"] == 1,
          "left_knee is ICS 16 = servo ID 8 on SIO1-4")

    with tempfile.TemporaryDirectory() as tmp:
        rc, out, err = run(*on, "joint", "move", "left_knee=35", "head_yaw=-12.5", "--time", "200", "--wait")
        check(rc == 0 and "left_knee to +35.0 deg" in out, f"joint move --wait ({rc}, {err.strip()!r})")
        pose = os.path.join(tmp, "crouch.json")
        rc, out, err = run(*on, "pose", "capture", pose)
        check(rc == 0 and "captured 20 joints" in out, f"pose capture ({rc}, {err.strip()!r})")
        saved = json.load(open(pose))["joints"]
        check(abs(saved["left_knee"] - 35) < 0.05 and abs(saved["head_yaw"] + 12.5) < 0.05,
              f"the captured file holds the angles ({saved.get('left_knee')}, {saved.get('head_yaw')})")
        rc, out, err = run(*on, "joint", "move", "left_knee=15", "--time", "100", "--wait")
        check(rc == 0 and abs(joints()["left_knee"]["degrees"] - 15) < 0.1, "the joint moved 20 degrees away")
        rc, out, err = run(*on, "pose", "play", pose, "--time", "300", "--wait")
        knee = joints()["left_knee"]["degrees"]
        check(rc == 0 and abs(knee - 35) <= 1.0, f"pose play brings the joint back within 1 degree ({knee})")

        # YAML poses, and pose show without a device.
        yml = os.path.join(tmp, "p.yaml")
        rc, out, err = run(*on, "pose", "capture", yml, "--joints", "legs")
        check(rc == 0 and "captured 10 joints" in out, "pose capture --joints legs into YAML")
        rc, out, err = run("pose", "show", yml)
        check(rc == 0 and "left_knee" in out and "head_yaw" not in out, "pose show reads it back")
        bad = os.path.join(tmp, "bad.json")
        open(bad, "w").write('{"joints": {"left_knee": 131}}')
        rc, out, err = run("pose", "show", bad)
        check(rc == 2 and "beyond its upper limit 130" in err, f"pose show: an angle beyond a limit is exit 2 ({err.strip()!r})")
        rc, out, err = run(*on, "pose", "play", bad)
        check(rc == 2 and "left_knee: 131 degrees is beyond its upper limit 130" in err, "pose play of it: exit 2")
        open(bad, "w").write('{"joints": {"tail": 1}}')
        rc, out, err = run(*on, "pose", "play", bad)
        check(rc == 2 and "bad.json:1:13: no joint of KHR-3HV is called 'tail'" in err, f"unknown joint in a pose: file:line ({err.strip()!r})")
        rc, out, err = run(*on, "pose", "capture", os.path.join(tmp, "p.txt"))
        check(rc == 2 and ".json, .yaml or .yml" in err, "pose capture into a .txt: exit 2")

    before = joints()["right_knee"]["degrees"]
    rc, out, err = run(*on, "joint", "move", "right_knee=140")
    check(rc == 2 and "right_knee: 140 degrees is beyond its upper limit 130" in err, f"move beyond a limit: exit 2 ({err.strip()!r})")
    check(joints()["right_knee"]["degrees"] == before, "and nothing moved")
    rc, out, err = run(*on, "joint", "move", "right_knee=10", "head_yaw=91")
    check(rc == 2 and joints()["right_knee"]["degrees"] == before, "one bad angle among good ones: nothing moves")
    rc, out, err = run(*on, "joint", "move", "tail=3")
    check(rc == 2 and "no joint is called 'tail'" in err, "an unknown joint: exit 2")
    rc, out, err = run(*on, "joint", "move", "head_yaw=3", "--time", "3000")
    check(rc == 1 and "2550 ms at this board's 10 ms period" in err,
          f"a move longer than this board's 255 frames: exit 1, the board's limit ({err.strip()!r})")

    rc, out, err = run("--json", *on, "joint", "free", "left_arm")
    check(rc == 0 and json.loads(out)["freed"] == ["left_shoulder_pitch", "left_shoulder_roll", "left_elbow_yaw", "left_elbow_pitch"],
          "joint free left_arm frees the group's four joints")
    js = joints()
    check(js["left_elbow_pitch"]["state"] == "free" and js["right_elbow_pitch"]["state"] != "free", "only that group is free")
    rc, out, err = run(*on, "joint", "hold", "all")
    check(rc == 0 and joints()["left_elbow_pitch"]["state"] == "hold", "joint hold all")
    rc, out, err = run(*on, "joint", "free", "tail")
    check(rc == 2 and "no joint or group is called 'tail'" in err, "free of an unknown group: exit 2")

    rc, out, err = run(*on, "trim", "set", "left_knee=1.5", "--persist")
    check(rc == 0 and "+44 counts" in out, f"trim set --persist ({out.strip()!r})")
    rc, out, err = run(*on, "joint", "move", "left_knee=10@6000")
    check(rc == 1 and "nothing was sent" in err and joints()["left_knee"]["target"] != 10,
          f"a joint's own time beyond it too, and nothing moves ({rc})")
    rc, out, err = run(*on, "trim", "set", "left_knee=1", "left_knee=2")
    check(rc == 2 and "left_knee is given twice" in err, f"trim set of one joint twice: exit 2 ({rc}, {err.strip()!r})")
    rc, out, err = run("--json", *on, "trim", "get", "left_knee")
    t = json.loads(out)[0] if rc == 0 else {}
    check(t.get("counts") == 44 and abs(t.get("degrees", 0) - 1.49) < 0.01, f"trim get reads it back ({t})")
    rc, out, err = run(*on, "read", "rom", "0x768", "2")
    check(rc == 0 and "2C 00" in out, f"--persist wrote HTH4's servo image in ROM ({out.strip()!r})")
    rc, out, err = run(*on, "trim", "set", "left_knee=45")
    check(rc == 2 and "within ±30 degrees" in err, "a trim beyond 30 degrees: exit 2")

    # Pose files as people handle them: stdin, overwriting, another robot's pose, quoted numbers.
    with tempfile.TemporaryDirectory() as tmp:
        rc, out, err = run(*on, "pose", "play", "-", "--time", "100", stdin='{"joints": {"head_yaw": 10}}')
        check(rc == 0 and "head_yaw to +10.0 deg" in out, f"pose play - reads the pose from stdin ({rc}, {err.strip()!r})")
        rc, out, err = run("pose", "show", "-", stdin="joints:\n  head_yaw: 10\n")
        check(rc == 0 and "head_yaw" in out, "pose show - too (YAML)")
        kept = os.path.join(tmp, "kept.yaml")
        rc, out, err = run(*on, "pose", "capture", kept)
        text = open(kept).read() if rc == 0 else ""
        check(rc == 0 and "0000000" not in text and "-0" not in text.replace("-0.", "x"),
              f"a YAML capture has hundredths, not float noise or -0 ({text[:120]!r})")
        rc, out, err = run(*on, "pose", "capture", kept)
        check(rc == 2 and "exists: --force replaces it" in err and open(kept).read() == text,
              f"capture onto an existing file: exit 2, the file kept ({err.strip()!r})")
        rc, out, err = run(*on, "pose", "capture", kept, "--force")
        check(rc == 0, "capture --force replaces it")
        for name, body in [("x.pose", '{"joints": {"head_yaw": 1}}')]:
            path = os.path.join(tmp, name)
            open(path, "w").write(body)
            rc, out, err = run("pose", "show", path)
            check(rc == 2 and ".json, .yaml or .yml" in err, f"pose show {name}: exit 2, as capture refuses it")
        other = os.path.join(tmp, "kxr.json")
        open(other, "w").write('{"robot": "KXR-L2", "joints": {"head_yaw": 10}}')
        rc, out, err = run(*on, "pose", "play", other)
        check(rc == 2 and "this pose is KXR-L2's, not KHR-3HV's" in err, f"another robot's pose: exit 2 ({err.strip()!r})")
        open(other, "w").write('{"joints": {"head_yaw": "10"}}')
        rc, out, err = run(*on, "pose", "play", other)
        check(rc == 2 and 'not the string "10"' in err, "a quoted angle: exit 2")

        # capture --free: the end of stdin or Ctrl-C captures nothing and holds the joints again.
        rc, out, err = run(*on, "pose", "capture", os.path.join(tmp, "eof.json"), "--free", "--joints", "left_arm", stdin="")
        check(rc == 2 and "stdin ended before Enter: nothing captured" in err and not os.path.exists(os.path.join(tmp, "eof.json"))
              and joints()["left_elbow_pitch"]["state"] == "hold", f"capture --free at the end of stdin: exit 2, joints held ({err.strip()!r})")
        p = subprocess.Popen([RCB4, *on, "pose", "capture", os.path.join(tmp, "int.json"), "--free", "--joints", "left_arm"],
                             stdin=subprocess.PIPE, stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        prompt = p.stderr.readline()  # the joints are free now (the tool holds the port: no one else can look)
        p.send_signal(signal.SIGINT)
        _, err = p.communicate(timeout=30)
        check(p.returncode == 130 and "4 joints free" in prompt and "interrupted before Enter" in err
              and joints()["left_elbow_pitch"]["state"] == "hold", f"capture --free, Ctrl-C: exit 130, joints held again ({p.returncode}, {err.strip()!r})")

    # Messages: the time a move really takes, one prefix.
    rc, out, err = run(*on, "joint", "move", "head_yaw=1@1")
    check(rc == 0 and "over 10 ms (1 frame of 10 ms; 1 ms asked)" in out, f"a move of 1 ms takes one 10 ms frame, and says so ({out.strip()!r})")

    # A running ROM motion would overwrite a move: refused, nothing sent. The motion is one that
    # never ends (pushed into slot 5 of a board of its own): a slow run (ASan, a busy machine)
    # must not see a short demo motion end before the move is asked.
    with serve() as other, tempfile.TemporaryDirectory() as tmp:
        forever = os.path.join(tmp, "forever.yaml")
        with open(forever, "w") as f:
            f.write("robot: KHR-3HV\nperiod_ms: 10\nsteps:\n  - label: top\n  - pose: {head_yaw: 10}\n"
                    "    time_ms: 500\n  - pose: {head_yaw: 0}\n    time_ms: 500\n  - goto: top\n")
        rc, out, err = run("--device", other, "motion", "push", forever, "5")
        assert rc == 0, err
        rc, out, err = run("--device", other, "motion", "play", "5")
        assert rc == 0, err
        rc, out, err = run("--device", other, "joint", "move", "head_yaw=5")
        check(rc == 1 and "motion 5 is running on the board: it would overwrite the move" in err,
              f"joint move during a motion: exit 1 ({rc}, {err.strip()!r})")
    rc, out, err = run(*on, "motion", "play", "2")
    assert rc == 0, err
    rc, out, err = run(*on, "motion", "stop")
    rc, out, err = run(*on, "joint", "move", "head_yaw=0", "--time", "100", "--wait")
    check(rc == 0, f"after motion stop, the move goes ({err.strip()!r})")
    rc, out, err = run(*on, "motion", "resume")
    rc, out, err = run(*on, "motion", "wait")
    # A move of our own under way is no motion: the next move may follow it at once.
    rc, out, err = run(*on, "joint", "move", "head_yaw=30@2000")
    rc2, out, err = run(*on, "joint", "move", "left_knee=20")
    check(rc == 0 and rc2 == 0, f"a move right after another, still interpolating, goes ({rc2}, {err.strip()!r})")

    rc, out, err = run("--json", *on, "motion", "list")
    ms = json.loads(out)["motions"] if rc == 0 else []
    check([(m["slot"], m["name"]) for m in ms] == [(1, "home"), (2, "wave"), (3, "bow")] and ms[0]["size"] == 52,
          f"motion list shows the virtual board's motions with names and sizes ({ms})")
    rc, out, err = run("--json", *on, "scan")
    sc = json.loads(out) if rc == 0 else {}
    check(len(sc.get("slots", [])) == 20 and all(s["answers"] for s in sc["slots"]) and sc["unallocated_joints"] == [],
          "scan: 20 slots, each answering, each a joint")

# A board with silent servos and slots the robot does not have.
with serve("--servos", "4") as dev:
    rc, out, err = run("--device", dev, "scan")
    check(rc == 0 and "4 slots allocated" in out and "16 joints of KHR-3HV without a slot" in out,
          f"scan on a 4-slot board names the joints without a slot ({out.strip().splitlines()[-1]!r})")
    rc, out, err = run("--device", dev, "joint", "move", "left_knee=10")
    check(rc == 1 and "no servo allocated for left_knee (ICS 16)" in err, f"moving a joint the board lacks: exit 1 ({err.strip()!r})")
    rc, out, err = run("--device", dev, "trim", "set", "left_knee=1")
    check(rc == 1 and "no servo allocated for left_knee (ICS 16): nothing written" in err,
          f"trimming a joint the board lacks: exit 1 naming it ({err.strip()!r})")
    rc, out, err = run("--json", "--device", dev, "joint", "list")
    js = {j["name"]: j for j in json.loads(out)} if rc == 0 else {}
    check(rc == 0 and js["head_yaw"]["allocated"] and not js["left_knee"]["allocated"] and js["left_knee"]["degrees"] is None,
          "joint list marks the joints without a slot, with no made-up angle")

# A servo that never answered (serve --silent 3: its measured position stays 0): no command shows
# an angle for it (it showed -253.1 degrees, JSON -253.13, exit 0), every other servo has one.
with serve("--silent", "3") as dev:
    rc, out, err = run("--device", dev, "servo", "list")
    row = next((l for l in out.splitlines() if l.split()[:1] == ["3"]), "")
    check(rc == 0 and "0 (no answer)" in row and "deg" not in row.split("(no answer)")[0] and "-253" not in out,
          f"servo list: ICS 3 has no angle ({row.strip()!r})")
    rc, out, err = run("--json", "--device", dev, "servo", "get", "3", "4")
    got = {s["ics"]: s for s in json.loads(out)} if rc == 0 else {}
    check(rc == 0 and got[3]["degrees"] is None and got[3]["answered"] is False and got[3]["position"] == 0
          and got[4]["degrees"] == 0.0 and got[4]["answered"] is True,
          f"servo get --json: degrees null and answered false for ICS 3 only ({got.get(3)})")
    rc, out, err = run("--device", dev, "monitor", "--count", "1")
    check(rc == 0 and re.search(r"right_shoulder_pitch\s+silent", out) and "-253" not in out,
          f"monitor: ICS 3 (right_shoulder_pitch) silent, no angle ({rc}: {out.strip()[-300:]!r})")
    rc, out, err = run("--json", "--device", dev, "joint", "list")
    js = {j["ics"]: j for j in json.loads(out)} if rc == 0 else {}
    check(rc == 0 and js[3]["degrees"] is None and js[4]["degrees"] is not None, "joint list: none for its joint")
    rc, out, err = run("serve", "--pty", "--servos", "2", "--silent", "5")
    check(rc == 2 and "--silent 5: the board has no servo slot ICS 5" in err, f"serve --silent of a slot it lacks: exit 2 ({err.strip()!r})")

with serve("--servos", "0") as dev:
    rc, out, err = run("--device", dev, "joint", "list")
    check(rc == 1 and "allocates none of KHR-3HV's joints" in err, f"an empty allocation table: exit 1 ({err.strip()!r})")
    rc, out, err = run("--device", dev, "bench", "--count", "5")
    check(rc == 1 and "no servo allocated for any joint of the KHR-3HV" in err, f"bench on an empty table: exit 1 ({err.strip()!r})")

# A board whose allocation table is nonsense (every block one byte off, a duplicate, one outside
# RAM's user area): every reader and writer refuses it with exit 1, no made-up angle, no write.
BAD_TABLE = "the board's ICS allocation table (RAM 0x0044) is not a servo map"
for name, entries in [("shifted by one byte", {k: 0x0091 + 20 * k for k in [*range(10), *range(12, 22)]}),
                      ("a duplicate", {0: 0x0090, 1: 0x00A4, 2: 0x00A4}),
                      ("outside the user area", {0: 0x0090, 1: 0x0500})]:
    table = bytearray([0xFF] * 70)
    for k, a in entries.items():
        table[2 * k:2 * k + 2] = a.to_bytes(2, "little")
    with serve() as dev:
        on = ["--device", dev]
        rc, out, err = run(*on, "write", "ram", "0x0044", table.hex())
        assert rc == 0, err
        rc, trim_before, err = run(*on, "read", "ram", "0x01D2", "2")
        for args in (["joint", "list"], ["trim", "get"], ["servo", "list"], ["scan"], ["pose", "capture", "/tmp/rcb4-bad-table-pose.json"],
                     ["trim", "set", "left_knee=2"], ["joint", "move", "left_knee=10"], ["joint", "free", "all"]):
            rc, out, err = run(*on, *args)
            check(rc == 1 and BAD_TABLE in err and "rcb4 read ram 0x0044 70" in err,
                  f"{name}: `rcb4 {' '.join(args)}` is exit 1 naming the table ({rc}, {err.strip()[:90]!r})")
        rc, out, err = run("--json", *on, "joint", "list")
        check(rc == 1 and BAD_TABLE in json.loads(out or "{}").get("error", ""), f"{name}: and as JSON")
        rc, trim_after, err = run(*on, "read", "ram", "0x01D2", "2")
        check(rc == 0 and trim_after == trim_before, f"{name}: no trim was written ({trim_after.strip()!r})")

# The robot's control cycle behind a USB adapter's millisecond (serve --pace --latency 1000):
# the link is measured and the planner merges the joints' positions into long reads.
with serve("--pace", "--latency", "1000") as dev:
    rc, out, err = run("--json", "--device", dev, "--baud", "1250000", "bench", "--count", "10")
    b = json.loads(out) if rc == 0 else {}
    check(rc == 0 and b["robot"] == "KHR-3HV" and b["servos"] == 20 and b["exchange_overhead_us"] >= 1000,
          f"bench measures the link: at least the 1 ms the board waits ({b.get('exchange_overhead_us')})")
    # ICS 0-9 and 12-21 in blocks 0x0090 + 20·ICS: 7 and 3 positions on each side of ICS 10-11's gap.
    check(b.get("plan_reads") == [122, 42, 122, 42] and b["cycle_bytes"] == 4 * 13 + 328 + 49 + 4,
          f"and reads the 20 positions in 4 reads ({b.get('plan_reads')}, {b.get('cycle_bytes')} bytes)")
    check(b.get("iory_cycle_bytes") == 5 * (10 + 129) + 79 + 4, "next to iory/rcb4's 5 x MOV 126 + CONST35 (ICS 35 is the receiver's)")
    # The rate itself is a figure for `rcb4 bench` to print (docs/performance.md), not a timed
    # assertion: on a loaded machine it is anything. The test checks the figures are there and sane.
    check(b.get("paced") is True and b.get("byte_time_ns") == 8800 and b.get("cycle_hz", 0) > 0
          and b.get("cycle_link_limit_hz", 0) > 0,
          f"on a paced link bench reports the cycle and the link's limit, bytes at 1.25 Mbaud "
          f"({b.get('cycle_hz')} of {b.get('cycle_link_limit_hz')} Hz: a figure, not checked)")
    rc, out, err = run("--device", dev, "--baud", "1250000", "bench", "--count", "5")
    check(rc == 0 and "link limit" in out and "warning" not in out, "its text shows the link limit, without a warning")

# A board that is not paced answers faster than the wire: the bench says so, and the planner still
# merges (the link charges per exchange, hardly per byte) instead of planning 20 reads.
with serve() as dev:
    rc, out, err = run("--json", "--device", dev, "--baud", "1250000", "bench", "--count", "10")
    b = json.loads(out) if rc == 0 else {}
    check(rc == 0 and b.get("paced") is False and len(b.get("plan_reads", [])) <= 4,
          f"bench against an unpaced board: paced false, {len(b.get('plan_reads', []))} reads")
    # The text run measures the link again: whether a board keeps the wire's pace is a timing, and
    # on a loaded machine (sanitizers, CPU hogs) an unpaced pty's replies can come as slowly as the
    # wire's once. The warning must show in one of three runs; each run's verdict is printed.
    verdicts = []
    for _ in range(3):
        rc, out, err = run("--device", dev, "--baud", "1250000", "bench", "--count", "10")
        verdicts.append("warned" if "warning: faster than 1250000 baud carries the bytes" in out else "paced")
        if rc != 0 or verdicts[-1] == "warned":
            break
    check(rc == 0 and verdicts[-1] == "warned", f"and its text warns ({verdicts})")

# The README's whole program, as a reader copies it, against the virtual robot.
if README_JOINTS:
    with serve() as dev:
        p = subprocess.run([README_JOINTS, dev], capture_output=True, text=True, timeout=60)
        lines = p.stdout.splitlines()
        check(p.returncode == 0 and len(lines) == 20 and lines[0].startswith("head_yaw "),
              f"the README's joints.cpp reads the 20 joints ({p.returncode}, {p.stderr.strip()!r})")
        on = ["--device", dev]
        for _ in range(40):  # the board's output (+6) reaches the target when the 800 ms move ends
            knee = joints()["left_knee"]
            if abs(knee["target"] - 40) < 0.1:
                break
            time.sleep(0.1)
        check(abs(knee["target"] - 40) < 0.1, f"and bends the left knee to 40 degrees ({knee['target']})")
    # Failures end in a message and exit 1, never in terminate() (exit 134 before).
    p = subprocess.run([README_JOINTS, "/dev/ttyNOPE9"], capture_output=True, text=True, timeout=60)
    check(p.returncode == 1 and "No such file or directory" in p.stderr, f"joints.cpp on a missing port: exit 1 ({p.returncode}, {p.stderr.strip()!r})")
    silent_board = StandIn(silent=True)
    p = subprocess.run([README_JOINTS, silent_board.path], capture_output=True, text=True, timeout=60)
    check(p.returncode == 1 and p.stderr.strip() != "", f"joints.cpp on a silent board: exit 1 ({p.returncode}, {p.stderr.strip()!r})")

# Profiles: the shipped files, another robot, bad files.
rc, out, err = run("--robot", os.path.join(PROFILES, "kxr-l2.yaml"), "joint", "list")
check(rc == 0 and "KXR-L2 (17 joints)" in out, "--robot profiles/kxr-l2.yaml (on the in-process board it describes)")
with tempfile.TemporaryDirectory() as tmp:
    bad = os.path.join(tmp, "r.yaml")
    open(bad, "w").write("robot: r\njoints:\n  a: {ics: 1, lower: -10, upper: 10}\n  b: {ics: 1, lower: -10, upper: 10}\n")
    rc, out, err = run("--robot", bad, "joint", "list")
    check(rc == 2 and f"{bad}:4:3: b: ICS 1 is already a's" in err, f"a profile with a duplicate ICS: exit 2 with file:line ({err.strip()!r})")
    open(bad, "w").write("robot: r\njoints:\n  a: {ics: 1, lower: -10, upper: 10, speed: 1}\n")
    rc, out, err = run("--json", "--robot", bad, "joint", "list")
    check(rc == 2 and "unknown key 'speed'" in json.loads(out)["error"], "an unknown key, as JSON")
rc, out, err = run("--robot", "khr3", "joint", "list")
check(rc == 2 and "not a built-in profile (khr-3hv, kxr-l2)" in err, "an unknown --robot: exit 2 naming the built-ins")

finish()
