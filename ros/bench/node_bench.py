#!/usr/bin/env python3
# The node measured (issue 33 item 6): its CPU (user + system, of one core) at 100 Hz with a
# KHR-3HV's 20 joints, idle and while a FollowJointTrajectory goal runs, side by side with the
# joint_states rate it keeps; and the action's tracking error (feedback's desired - actual) on
# `rcb4 serve --pty --pace` (replies at the 1.25 Mbaud line's pace). Figures, not assertions.
#   node_bench.py RCB4_TOOL PYRCB4_DIR NODE_SRC_DIR MESSAGES_DIR [SECONDS]
# SPDX-License-Identifier: BSL-1.0
import math
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import master as rosmaster  # noqa: E402 (ros/tests/master.py)

TOOL, PYRCB4, NODE_SRC, MESSAGES = sys.argv[1:5]
SECONDS = float(sys.argv[5]) if len(sys.argv) > 5 else 10.0
master, env = rosmaster.start(PYRCB4, NODE_SRC, "/bench")
env["RCB4_ROS_MESSAGES"] = MESSAGES
sys.path.append(MESSAGES)
import actionlib  # noqa: E402
import rospy  # noqa: E402
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from trajectory_msgs.msg import JointTrajectoryPoint  # noqa: E402

rospy.init_node("rcb4_node_bench", anonymous=True, disable_signals=True)
stamps = []
rospy.Subscriber("/joint_states", JointState, lambda m: stamps.append(time.monotonic()), queue_size=1000)
TICK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / TICK  # utime, stime


def measure(pid, seconds, during=None):
    """(CPU share of one core, joint_states per second) over @p seconds, running @p during meanwhile."""
    stamps.clear()
    c0, t0 = cpu_seconds(pid), time.monotonic()
    result = during() if during else time.sleep(seconds)
    while time.monotonic() - t0 < seconds:
        time.sleep(0.05)
    c1, t1 = cpu_seconds(pid), time.monotonic()
    return (c1 - c0) / (t1 - t0), len(stamps) / (t1 - t0), result


srv = subprocess.Popen([TOOL, "serve", "--pty", "--pace"], stdout=subprocess.PIPE, text=True)
device = srv.stdout.readline().strip()
node = subprocess.Popen([sys.executable, os.path.join(NODE_SRC, "..", "scripts", "rcb4_node"), f"_device:={device}",
                         "_baud:=1250000", "_rate:=100"], env=env, stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL)
try:
    client = actionlib.SimpleActionClient("/fullbody_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    client.wait_for_server(rospy.Duration(30))
    time.sleep(1.0)
    joints = rospy.get_param("/fullbody_controller/joints")
    idle = measure(node.pid, SECONDS)

    def track():
        """Every joint through a 2 s sine of 20 degrees, 50 points; the feedback's errors (degrees)."""
        errors = []
        g = FollowJointTrajectoryGoal()
        g.trajectory.joint_names = joints
        for k in range(1, 51):
            t = k * SECONDS / 50
            deg = 20 * math.sin(2 * math.pi * t / 2.0)
            g.trajectory.points.append(JointTrajectoryPoint(positions=[math.radians(deg)] * len(joints),
                                                            time_from_start=rospy.Duration(t)))
        client.send_goal(g, feedback_cb=lambda fb: errors.extend(abs(math.degrees(e)) for e in fb.error.positions))
        client.wait_for_result(rospy.Duration(SECONDS + 10))
        return errors, client.get_state()

    busy = measure(node.pid, SECONDS, track)
    errors, state = busy[2]
    print(f"rcb4_ros node at 100 Hz, a KHR-3HV's {len(joints)} joints, rcb4 serve --pace at 1.25 Mbaud, "
          f"{SECONDS:g} s each (this machine: compare the rows, not the absolute figures)")
    print(f"{'':>28} {'CPU (one core)':>15} {'joint_states/s':>15}")
    print(f"{'idle (reading, publishing)':>28} {idle[0] * 100:>14.1f}% {idle[1]:>15.1f}")
    print(f"{'a FollowJointTrajectory goal':>28} {busy[0] * 100:>14.1f}% {busy[1]:>15.1f}")
    if errors:
        errors.sort()
        print(f"tracking error (feedback desired - actual, every joint, {len(errors)} samples): "
              f"median {statistics.median(errors):.2f} deg, p99 {errors[int(len(errors) * 0.99)]:.2f} deg, "
              f"max {errors[-1]:.2f} deg; goal state {state} (3: succeeded)")
finally:
    node.terminate()
    node.wait(timeout=10)
    srv.terminate()
    master.terminate()
