#!/usr/bin/env python3
# The rcb4 ROS node against a real ROS master (rosmaster --core on a free port): joint_states at
# the asked rate with every joint, a trajectory that moves left_knee (checked through the rcb4 tool
# once the node has let the board go), a point beyond a limit or due at once that moves nothing,
# stop and ~stop holding where the joint is, free and hold,
# SIGINT and SIGTERM ending it within 1 s with exit 0; then on a board of our own that falls silent: diagnostics ERROR and no stale
# joint_states until it answers again.
#   node_test.py RCB4 PYRCB4_DIR NODE_SRC_DIR
# SPDX-License-Identifier: BSL-1.0
import json
import math
import os
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "tests", "integration")]
from checks import check, finish  # noqa: E402
import master as rosmaster  # noqa: E402 (ros/tests/master.py)
from master import wait_for  # noqa: E402
from standin import StandIn  # noqa: E402

RCB4, PYRCB4, NODE_SRC = sys.argv[1], sys.argv[2], sys.argv[3]
NODE = os.path.join(NODE_SRC, "..", "scripts", "rcb4_node")

master, env = rosmaster.start(PYRCB4, NODE_SRC)

import rospy  # noqa: E402
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus  # noqa: E402
from sensor_msgs.msg import BatteryState, JointState  # noqa: E402
from std_msgs.msg import String, UInt8  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint  # noqa: E402

rospy.init_node("rcb4_test", anonymous=True, disable_signals=True)

states, diags = [], []
rospy.Subscriber("/joint_states", JointState, lambda m: states.append((time.monotonic(), m)), queue_size=100)
rospy.Subscriber("/diagnostics", DiagnosticArray, lambda m: diags.append((time.monotonic(), m)), queue_size=10)


def start_node(*params):
    return subprocess.Popen([sys.executable, NODE, *params], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)


def stop(node, sig=signal.SIGINT):
    sent = time.monotonic()
    node.send_signal(sig)
    try:
        node.wait(timeout=5)
    except subprocess.TimeoutExpired:
        node.kill()
        node.wait()
    return time.monotonic() - sent


def last_position(name):
    for _, m in reversed(states):
        if name in m.name:
            return math.degrees(m.position[m.name.index(name)])
    return None


def tool_joints(dev):
    r = subprocess.run([RCB4, "--json", "--device", dev, "joint", "list"], capture_output=True, text=True, timeout=30)
    return {j["name"]: j for j in json.loads(r.stdout)} if r.returncode == 0 else {}


try:
    srv = subprocess.Popen([RCB4, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
    dev = srv.stdout.readline().strip()
    node = start_node(f"_device:={dev}", "_rate:=50")
    first = wait_for(lambda: len(states) > 5, timeout=15)
    check(first is not None, "the node publishes joint_states")
    states.clear()
    time.sleep(2.0)
    got = [m for t, m in states]
    rate = len(got) / 2.0
    check(rate >= 45 and all(len(m.name) == 20 and len(m.position) == 20 for m in got),
          f"joint_states at >= 90% of 50 Hz with every joint of the KHR-3HV ({rate:.1f} Hz)")
    check(all(m.header.stamp.to_sec() > 0 for m in got) and "left_knee" in got[-1].name, "stamped, by joint name")

    cmd = rospy.Publisher("/rcb4/command", JointTrajectory, queue_size=2, latch=False)
    wait_for(lambda: cmd.get_num_connections() > 0)

    def trajectory(points):
        t = JointTrajectory()
        t.joint_names = ["left_knee"]
        for deg, secs in points:
            t.points.append(JointTrajectoryPoint(positions=[math.radians(deg)], time_from_start=rospy.Duration(secs)))
        cmd.publish(t)
    trajectory([(20, 0.3), (35, 0.6)])
    check(wait_for(lambda: (p := last_position("left_knee")) is not None and abs(p - 35) < 1, timeout=5),
          f"a trajectory brings left_knee to its last point, within 1 deg ({last_position('left_knee')})")
    trajectory([(140, 0.5)])
    time.sleep(1.0)
    check(abs(last_position("left_knee") - 35) < 0.5, f"a point beyond the limit moves nothing ({last_position('left_knee')})")
    trajectory([(60, 0.0)])  # due at once: a jump at full servo speed; refused, as ROS 1's JTC does
    time.sleep(0.5)
    check(abs(last_position("left_knee") - 35) < 0.5,
          f"a single point at time_from_start 0 moves nothing ({last_position('left_knee')})")

    # A streamed command for one joint leaves another on its way: head_yaw's 2 s move goes on.
    t = JointTrajectory()
    t.joint_names = ["head_yaw"]
    t.points = [JointTrajectoryPoint(positions=[math.radians(60)], time_from_start=rospy.Duration(2.0))]
    cmd.publish(t)
    time.sleep(0.3)
    stream = rospy.Publisher("/rcb4/joint_command", JointState, queue_size=2)
    wait_for(lambda: stream.get_num_connections() > 0)
    stream.publish(JointState(name=["left_knee"], position=[math.radians(35)]))
    time.sleep(0.3)
    check(5 < last_position("head_yaw") < 45, f"a joint_command for left_knee does not make head_yaw jump ({last_position('head_yaw')})")
    wait_for(lambda: abs(last_position("head_yaw") - 60) < 0.5, timeout=5)
    # A streamed command for left_knee leaves the rest of head_yaw's trajectory (30, then 60) to it.
    t.points = [JointTrajectoryPoint(positions=[math.radians(30)], time_from_start=rospy.Duration(0.5)),
                JointTrajectoryPoint(positions=[math.radians(60)], time_from_start=rospy.Duration(1.0))]
    cmd.publish(t)
    time.sleep(0.3)
    stream.publish(JointState(name=["left_knee"], position=[math.radians(35)]))
    check(wait_for(lambda: abs(last_position("head_yaw") - 60) < 0.5, timeout=5) is not None,
          f"a joint_command for left_knee leaves head_yaw's next point to its trajectory ({last_position('head_yaw')})")
    battery = rospy.wait_for_message("/rcb4/battery", BatteryState, timeout=5)
    check(battery.voltage > 5 and math.isnan(battery.percentage) and math.isnan(battery.current),
          f"~battery: volts, and NaN for what the board does not measure ({battery.voltage}, {battery.percentage})")
    # A ROM motion running: a trajectory is refused rather than fighting it.
    play = rospy.Publisher("/rcb4/play_motion", UInt8, queue_size=2)
    wait_for(lambda: play.get_num_connections() > 0)
    play.publish(UInt8(3))
    time.sleep(0.5)
    t.points = [JointTrajectoryPoint(positions=[math.radians(-50)], time_from_start=rospy.Duration(0.2))]
    cmd.publish(t)  # head_yaw, which motion 3 (a bow: hips and knees) leaves alone
    time.sleep(0.5)
    check(abs(last_position("head_yaw") - 60) < 0.5, f"a trajectory while motion 3 runs moves nothing ({last_position('head_yaw')})")
    wait_for(lambda: "running\": false" in (rospy.wait_for_message("/rcb4/motion", String, timeout=5).data), timeout=10)
    trajectory([(35, 0.2)])
    wait_for(lambda: abs(last_position("left_knee") - 35) < 0.5, timeout=5)
    # A segment longer than one board move (255 periods, 2.55 s): 3 s up to 75 degrees, split into
    # moves along the same line, halfway at 1.5 s; then back to 35.
    trajectory([(75, 3.0), (35, 3.3)])
    time.sleep(1.5)
    half = last_position("left_knee")
    check(45 < half < 65, f"a 3 s segment is halfway (55 deg) at 1.5 s ({half})")
    check(wait_for(lambda: last_position("left_knee") > 74, timeout=5) is not None,
          f"a 3 s segment (more than 255 periods) reaches its point, within 1 deg ({last_position('left_knee')})")
    wait_for(lambda: abs(last_position("left_knee") - 35) < 0.5, timeout=5)

    # Stop (the trial's finding): an empty trajectory, and ~stop, hold every joint where it is now;
    # the segment under way does not run on to its end.
    for how in ("an empty trajectory", "~stop"):
        trajectory([(-60, 2.2)])
        time.sleep(0.6)
        if how == "~stop":
            r = rospy.ServiceProxy("/rcb4/stop", Trigger)()
            check(r.success and "holds where it is" in r.message, f"~stop answers ({r.message!r})")
        else:
            cmd.publish(JointTrajectory(joint_names=["left_knee"]))
        time.sleep(0.1)
        at = last_position("left_knee")
        time.sleep(1.2)
        now = last_position("left_knee")
        check(-50 < at < 30 and abs(now - at) < 3,
              f"{how} stops the segment under way: left_knee stays at {at:.1f} (now {now:.1f}), not -60")
        trajectory([(35, 0.5)])
        wait_for(lambda: abs(last_position("left_knee") - 35) < 0.5, timeout=5)
    # Free during a trajectory: the freed joint stays free; its next points are dropped, said so.
    free_joints = rospy.Publisher("/rcb4/free_joints", String, queue_size=2)
    hold_joints = rospy.Publisher("/rcb4/hold_joints", String, queue_size=2)
    wait_for(lambda: free_joints.get_num_connections() > 0 and hold_joints.get_num_connections() > 0)
    trajectory([(50, 0.5), (60, 1.0), (80, 2.0)])
    time.sleep(0.6)
    free_joints.publish(String("left_knee"))
    time.sleep(0.2)
    at = last_position("left_knee")
    time.sleep(1.8)
    check(abs(last_position("left_knee") - at) < 3,
          f"a trajectory's next points do not power a freed joint: left_knee stays at {at:.1f} "
          f"(now {last_position('left_knee'):.1f}), not 80")
    stream.publish(JointState(name=["left_knee"], position=[math.radians(10)]))
    time.sleep(0.5)
    check(abs(last_position("left_knee") - at) < 3, f"a streamed command does not move a freed joint ({last_position('left_knee')})")
    hold_joints.publish(String("left_knee"))
    time.sleep(0.3)
    trajectory([(35, 0.5)])
    check(wait_for(lambda: abs(last_position("left_knee") - 35) < 0.5, timeout=5) is not None,
          "held again, left_knee follows a trajectory")
    # Two different refusals in a row are both logged (repeats of one are limited, not all refusals).
    bad = JointTrajectory(joint_names=["no_such_joint"],
                          points=[JointTrajectoryPoint(positions=[0.0], time_from_start=rospy.Duration(0.5))])
    cmd.publish(bad)
    trajectory([(140, 0.5)])
    time.sleep(0.5)

    # An empty ~free_joints names nothing: it frees nothing (a robot would fall), and says so.
    free_joints.publish(String(" "))
    time.sleep(0.3)
    free = rospy.ServiceProxy("/rcb4/free", Trigger)
    hold = rospy.ServiceProxy("/rcb4/hold", Trigger)
    r1, r2 = hold(), free()
    check(r1.success and r2.success and "20 joints" in r2.message, f"~hold and ~free answer ({r1.message!r}, {r2.message!r})")
    took = stop(node)
    out = node.stdout.read()
    # 1 s is the documented bound, generous: measured 16-33 ms, 40-140 ms at load average 11 (docs/ros.md).
    check(node.returncode == 0 and took < 1.0, f"SIGINT ends the node within 1 s, exit 0 ({node.returncode}, "
                                               f"{took:.3f} s)")
    check("beyond its upper limit 130" in out, "the refused trajectory is logged with the joint and the limit")
    check("motion 3 is running on the board" in out, "the trajectory refused under motion 3 is logged")
    check("every point is due at once" in out, "the trajectory whose point is due at once is logged")
    check("no joint is called 'no_such_joint'" in out and out.count("beyond its upper limit 130") >= 2,
          "two different refusals in a row are each logged")
    check("what was under way for left_knee is dropped" in out and "left_knee is free: left out" in out,
          "freeing a joint under way and commanding a freed joint are logged")
    check("~free_joints: the message names no joint, so nothing was done" in out, "an empty ~free_joints is refused, logged")
    j = tool_joints(dev)
    check(j and abs(j["left_knee"]["degrees"] - 35) < 1 and all(v["state"] == "free" for v in j.values()),
          f"on the board (rcb4 joint list): left_knee at 35, every joint free ({j.get('left_knee')})")
    srv.terminate()
    srv.wait(timeout=10)

    # An empty ~device is refused (as the tool refuses --device ""), not taken for a simulation.
    rospy.set_param("/rcb4/device", "")  # as a launch file passing device:="" leaves it
    empty = start_node()
    try:
        empty.wait(timeout=20)
    except subprocess.TimeoutExpired:
        empty.kill()
    said = empty.stdout.read()
    check(empty.returncode == 1 and "~device is set but empty" in said,
          f"an empty ~device: exit 1, said ({empty.returncode}: {said.strip()[-160:]!r})")
    rospy.delete_param("/rcb4/device")

    # A board that stops answering, then answers again.
    board = StandIn()
    states.clear()
    diags.clear()
    node = start_node(f"_device:={board.path}", "_baud:=115200", "_rate:=20")
    check(wait_for(lambda: len(states) > 5, timeout=15), "on a stand-in board: joint_states")
    check(all(len(m.name) == 3 for _, m in states[-3:]), "only the joints whose servos answer (3 of 20)")
    check(wait_for(lambda: any(d.status[0].level == DiagnosticStatus.WARN and "17 joints" in d.status[0].message
                               for _, d in diags), timeout=5),
          f"diagnostics: the joints that do not answer ({[(d.status[0].level, d.status[0].message) for _, d in diags][:3]})")
    board.silent = True
    went = time.monotonic()
    check(wait_for(lambda: any(t > went and d.status[0].level == DiagnosticStatus.ERROR for t, d in diags), timeout=5),
          "a silent board: diagnostics ERROR")
    time.sleep(0.5)
    quiet = time.monotonic()
    silent_cmd = rospy.Publisher("/rcb4/command", JointTrajectory, queue_size=2)
    wait_for(lambda: silent_cmd.get_num_connections() > 0)
    silent_cmd.publish(JointTrajectory(joint_names=["head_yaw"], points=[
        JointTrajectoryPoint(positions=[0.3], time_from_start=rospy.Duration(0.2))]))
    time.sleep(1.0)
    check(not [t for t, _ in states if t > quiet], "and no joint_states while it is silent")
    board.silent = False
    back = time.monotonic()
    check(wait_for(lambda: [t for t, _ in states if t > back], timeout=5), "joint_states again once it answers")
    out = stop(node) and node.stdout.read()
    check("a command was dropped: the board does not answer" in out,
          f"a command sent while the board is silent is dropped, and logged ({out[-300:]!r})")

    # A device that goes away (unplugged) and comes back under the same path (a udev link): the
    # node opens it again by itself.
    link = os.path.join(env["ROS_HOME"], "rcb4-link")
    serve_a = subprocess.Popen([RCB4, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
    os.symlink(serve_a.stdout.readline().strip(), link)
    states.clear()
    diags.clear()
    node = start_node(f"_device:={link}", "_rate:=20")
    check(wait_for(lambda: len(states) > 3, timeout=15), "through a link to the device: joint_states")
    serve_a.terminate()
    serve_a.wait(timeout=10)
    gone = time.monotonic()
    check(wait_for(lambda: any(t > gone and d.status[0].level == DiagnosticStatus.ERROR for t, d in diags), timeout=5),
          "the device gone: diagnostics ERROR")
    # The dead device is let go, so that the kernel can give its name to the next one (a pty number,
    # /dev/ttyUSB0 for an adapter plugged in again).
    fds = f"/proc/{node.pid}/fd"
    check(wait_for(lambda: not any("(deleted)" in os.readlink(os.path.join(fds, f)) for f in os.listdir(fds)),
                   timeout=3), "the device gone: the node holds no descriptor of it")
    # Asked while it is gone: answered as failed, and never carried out when a board comes back.
    r = rospy.ServiceProxy("/rcb4/free", Trigger)()
    gone_play = rospy.Publisher("/rcb4/play_motion", UInt8, queue_size=2)
    wait_for(lambda: gone_play.get_num_connections() > 0)
    gone_play.publish(UInt8(2))
    time.sleep(0.5)
    check(not r.success, f"~free while the board is gone: failed, said ({r.message!r})")
    serve_b = subprocess.Popen([RCB4, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
    os.remove(link)
    dev_b = serve_b.stdout.readline().strip()
    subprocess.run([RCB4, "--device", dev_b, "joint", "free", "head_yaw"], capture_output=True, timeout=30)
    os.symlink(dev_b, link)
    back = time.monotonic()
    check(wait_for(lambda: [t for t, _ in states if t > back], timeout=6), "back under the same path: joint_states again")
    time.sleep(1.0)
    # The board now answering has head_yaw free: the node reads it, and a command leaves it out.
    back_cmd = rospy.Publisher("/rcb4/command", JointTrajectory, queue_size=2)
    wait_for(lambda: back_cmd.get_num_connections() > 0)
    back_cmd.publish(JointTrajectory(joint_names=["head_yaw"], points=[
        JointTrajectoryPoint(positions=[0.5], time_from_start=rospy.Duration(0.3))]))
    time.sleep(0.8)
    stop(node)
    out = node.stdout.read()
    check("free on the board: head_yaw" in out and "head_yaw is free: left out" in out,
          f"after a reconnect, the joints free on the new board are read as free ({out[-300:]!r})")
    st = subprocess.run([RCB4, "--json", "--device", dev_b, "motion", "status"], capture_output=True, text=True, timeout=30)
    j = tool_joints(dev_b)
    check(st.returncode == 0 and json.loads(st.stdout).get("motion") is None and j
          and not any(v["state"] == "free" for n, v in j.items() if n != "head_yaw") and j["head_yaw"]["state"] == "free",
          f"back: nothing asked while it was gone was done (no motion played, no joint freed) ({st.stdout.strip()!r})")
    serve_b.terminate()
    serve_b.wait(timeout=10)
    # No ~device: the in-process virtual board, with a warning that it is no robot; a bad ~timeout
    # named at start-up (exit 1).
    states.clear()
    rospy.delete_param("/rcb4/device")  # the runs before left theirs on the parameter server
    node = start_node()
    check(wait_for(lambda: len(states) > 3, timeout=15), "no ~device: joint_states")
    took = stop(node, signal.SIGTERM)
    out = node.stdout.read()
    check(node.returncode == 0 and took < 1.0, f"SIGTERM ends the node within 1 s, exit 0 ({node.returncode}, "
                                               f"{took:.3f} s)")
    check("the in-process virtual board, a simulation, not a robot" in out,
          f"no ~device: a warning that it is the virtual board ({out.strip()[:300]!r})")
    node = start_node("_timeout:=abc")
    out, _ = node.communicate(timeout=30)
    check(node.returncode == 1 and "~timeout: 'abc' is not a number of seconds" in out,
          f"_timeout:=abc: exit 1 naming it ({node.returncode}, {out.strip()[-120:]!r})")
    rospy.delete_param("/rcb4/timeout")  # the run before left it on the parameter server
    node = start_node("_frame_count:=300")
    out, _ = node.communicate(timeout=30)
    check(node.returncode == 1 and "~frame_count: 300 frames: a move takes 1-255 frames" in out,
          f"_frame_count:=300: exit 1 naming it ({node.returncode}, {out.strip()[-120:]!r})")
finally:
    rospy.signal_shutdown("done")
    master.terminate()
    master.wait(timeout=10)

finish()
