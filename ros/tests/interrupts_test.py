#!/usr/bin/env python3
# What stops or takes over a FollowJointTrajectory goal, against a real ROS master and `rcb4 serve
# --pty --pace`: a board that falls silent mid-segment (the served board SIGSTOPped, as a USB
# adapter stall or a starved host does) with a cancel, a ~stop, a newer goal or nothing at all
# arriving meanwhile: the client is told the truth, and once the board answers again (SIGCONT) the
# joint stops there instead of running on to the end of its segment; a newer goal that takes over
# from where the joints are without standing still; a newer goal that is refused; ~free during a
# goal.
#   interrupts_test.py RCB4 PYRCB4_DIR NODE_SRC_DIR MESSAGES_DIR
# SPDX-License-Identifier: BSL-1.0
import math
import os
import signal
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "tests", "integration")]
from checks import check, finish  # noqa: E402
import master as rosmaster  # noqa: E402
from master import wait_for  # noqa: E402

RCB4, PYRCB4, NODE_SRC, MESSAGES = sys.argv[1:5]
NODE = os.path.join(NODE_SRC, "..", "scripts", "rcb4_node")
master, env = rosmaster.start(PYRCB4, NODE_SRC, name="/rcb4_interrupts_test")
env["RCB4_ROS_MESSAGES"] = MESSAGES
sys.path.append(MESSAGES)

import actionlib  # noqa: E402
import rospy  # noqa: E402
from actionlib_msgs.msg import GoalStatus  # noqa: E402
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal  # noqa: E402
from control_msgs.msg import FollowJointTrajectoryResult as Result  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from trajectory_msgs.msg import JointTrajectoryPoint  # noqa: E402

rospy.init_node("rcb4_interrupts_test", anonymous=True, disable_signals=True)
states = []  # (stamp in ROS seconds, {joint: degrees})
rospy.Subscriber("/joint_states", JointState, queue_size=200, callback=lambda m: states.append(
    (m.header.stamp.to_sec(), {n: math.degrees(p) for n, p in zip(m.name, m.position)})))
FJT = "/fullbody_controller/follow_joint_trajectory"


def position(name):
    for _, p in reversed(states[-20:]):
        if name in p:
            return p[name]
    return None


def trace(name, since):
    """[(stamp, degrees)] of joint @p name from ROS time @p since on."""
    return [(t, p[name]) for t, p in list(states) if t >= since and name in p]


def last_change(samples, at_least=0.05):
    """The stamp of the last sample that differs from the one before by more than @p at_least degrees."""
    changed = [t for (_, a), (t, b) in zip(samples, samples[1:]) if abs(b - a) > at_least]
    return changed[-1] if changed else None


def longest_still(samples, at_least=0.05):
    """The longest time (s, by stamps) over which consecutive samples stay within @p at_least degrees."""
    longest, since = 0.0, None
    for (t0, a), (t1, b) in zip(samples, samples[1:]):
        if abs(b - a) <= at_least:
            since = t0 if since is None else since
            longest = max(longest, t1 - since)
        else:
            since = None
    return longest


def goal(points, joints=("left_knee",)):
    g = FollowJointTrajectoryGoal()
    g.trajectory.joint_names = list(joints)
    for degs, secs in points:
        degs = degs if isinstance(degs, (list, tuple)) else [degs]
        g.trajectory.points.append(JointTrajectoryPoint(positions=[math.radians(d) for d in degs],
                                                        time_from_start=rospy.Duration(secs)))
    return g


def client():
    c = actionlib.SimpleActionClient(FJT, FollowJointTrajectoryAction)
    c.wait_for_server(rospy.Duration(20))
    return c


def final(c, timeout=5.0):
    """The goal's final state and text, once the client has them (a deadline, no race with its threads)."""
    wait_for(lambda: c.get_state() in (GoalStatus.SUCCEEDED, GoalStatus.ABORTED, GoalStatus.PREEMPTED,
                                       GoalStatus.REJECTED, GoalStatus.RECALLED), timeout=timeout)
    return c.get_state(), c.get_goal_status_text()


def to(c, joints, degs, secs=0.5):
    c.send_goal(goal([(degs, secs)], joints=joints))
    c.wait_for_result(rospy.Duration(10))
    time.sleep(0.2)


srv = node = None
out = ""
try:
    srv = subprocess.Popen([RCB4, "serve", "--pty", "--pace"], stdout=subprocess.PIPE, text=True)
    dev = srv.stdout.readline().strip()
    node = subprocess.Popen([sys.executable, NODE, f"_device:={dev}", "_rate:=50"], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    main, other = client(), client()
    check(wait_for(lambda: position("left_knee") is not None, timeout=15) is not None, "the node publishes joint_states")
    stop_srv = rospy.ServiceProxy("/rcb4/stop", Trigger)

    # The board falls silent 0.5 s into a 2.5 s segment (left_knee to 90 deg, one board move) and
    # answers again 1.0 s later; 0.1 s into the silence a cancel, a ~stop or a newer goal arrives,
    # or nothing (the node aborts the goal itself).
    for how in ("cancel", "~stop", "a newer goal", "nothing (the board-gone abort)"):
        to(main, ("left_knee",), 0.0)
        main.send_goal(goal([(90, 2.5)]))
        time.sleep(0.5)
        os.kill(srv.pid, signal.SIGSTOP)
        went = time.monotonic()
        answer = None
        try:
            time.sleep(0.1)
            if how == "cancel":
                main.cancel_goal()
            elif how == "~stop":
                answer = stop_srv()
            elif how == "a newer goal":
                other.send_goal(goal([(0, 1.0)]))
            time.sleep(max(0.0, went + 1.0 - time.monotonic()))
        finally:
            os.kill(srv.pid, signal.SIGCONT)
        back = rospy.get_time()
        state, text = final(main)
        time.sleep(1.5)
        samples = trace("left_knee", back)
        end = samples[-1][1] if samples else None
        moved = last_change(samples)
        after = None if moved is None else moved - back
        check(samples and end < 85 and (after is None or after < 0.25),
              f"{how} while the board is silent: once it answers again left_knee stops where it is "
              f"({end if end is None else round(end, 1)} deg, last moved "
              f"{'never' if after is None else f'{after * 1000:.0f} ms'} after it answered), not at 90")
        if how == "~stop":
            check(answer is not None and not answer.success and "did not answer" in answer.message
                  and "as soon as it" in answer.message,
                  f"~stop while the board is silent: not a success, said ({answer and answer.message!r})")
        expected = GoalStatus.ABORTED if how.startswith("nothing") else GoalStatus.PREEMPTED
        told = "as soon as it" in text and "hold where they are" not in text
        if how == "a newer goal":
            state_b, text_b = final(other)
            check(state == GoalStatus.PREEMPTED and state_b == GoalStatus.ABORTED and "does not answer" in text_b
                  and "as soon as it" in text_b,
                  f"a newer goal while the board is silent: PREEMPTED, and the newer one ABORTED, said "
                  f"({state}, {state_b}: {text_b!r})")
        else:
            check(state == expected and told, f"{how} while the board is silent: the client is told the joints "
                                              f"will be held once the board answers ({state}: {text!r})")
        wait_for(lambda: position("left_knee") is not None, timeout=5)

    # A newer goal takes over from where the joints are, at the next cycle: head_yaw does not stand
    # still between the two; right_knee, which only the first goal names, holds where it is.
    to(main, ("head_yaw", "right_knee"), [0.0, 0.0])
    main.send_goal(goal([([60, 60], 2.0)], joints=("head_yaw", "right_knee")))
    time.sleep(0.8)
    sent = rospy.get_time()
    other.send_goal(goal([(80, 1.2)], joints=("head_yaw",)))
    state_b, _ = final(other)
    state_a, text_a = final(main)
    time.sleep(0.5)
    yaw = trace("head_yaw", sent - 0.1)
    still = longest_still([s for s in yaw if s[0] <= sent + 0.6])
    knee = trace("right_knee", sent)
    check(state_a == GoalStatus.PREEMPTED and "newer goal" in text_a and state_b == GoalStatus.SUCCEEDED
          and abs(position("head_yaw") - 80) < 1,
          f"a newer goal: the first PREEMPTED, the newer SUCCEEDED ({state_a}: {text_a!r}, {state_b}, "
          f"head_yaw {position('head_yaw')})")
    check(yaw and still < 0.08, f"a newer goal takes over without a stop: head_yaw never stood still "
                                f"(longest {still * 1000:.0f} ms at rest within 0.6 s of the newer goal)")
    moved = last_change(knee)
    check(knee and knee[-1][1] < 45 and (moved is None or moved - sent < 0.5),
          f"and right_knee, which only the first goal named, holds where it was ({knee[-1][1] if knee else None}"
          f" deg), not 60")

    # A newer goal that is refused: the first has given way, so its joints hold where they are.
    to(main, ("head_yaw",), 0.0)
    main.send_goal(goal([(-60, 2.0)], joints=("head_yaw",)))
    time.sleep(0.6)
    other.send_goal(goal([(140, 1.0)], joints=("head_yaw",)))
    state_b, text_b = final(other)
    state_a, _ = final(main)
    time.sleep(0.3)
    at = position("head_yaw")
    time.sleep(1.5)
    check(state_b == GoalStatus.ABORTED and other.get_result().error_code == Result.INVALID_GOAL
          and state_a == GoalStatus.PREEMPTED and -50 < at < -5 and abs(position("head_yaw") - at) < 1,
          f"a newer goal refused (beyond a limit): the first PREEMPTED, head_yaw holds at {at:.1f} "
          f"(now {position('head_yaw'):.1f}), not -60 ({text_b!r})")

    # ~free during a goal: the goal cannot be reached, so it is ABORTED, saying so (not SUCCEEDED).
    to(main, ("left_knee",), 0.0)
    main.send_goal(goal([(90, 2.0)]))
    time.sleep(0.8)
    freed = threading.Event()
    threading.Thread(target=lambda: (rospy.ServiceProxy("/rcb4/free", Trigger)(), freed.set()), daemon=True).start()
    state, text = final(main, timeout=3.0)
    check(state == GoalStatus.ABORTED and "freed" in text and main.get_result().error_code == Result.INVALID_GOAL,
          f"~free during a goal: ABORTED, saying the joints were freed ({state}: {text!r})")
    freed.wait(5)
    rospy.ServiceProxy("/rcb4/hold", Trigger)()
finally:
    if node:
        node.send_signal(signal.SIGINT)
        try:
            out, _ = node.communicate(timeout=10)
        except subprocess.TimeoutExpired:
            node.kill()
            out, _ = node.communicate()
    if srv:
        os.kill(srv.pid, signal.SIGCONT)
        srv.terminate()
        srv.wait(timeout=10)
    rospy.signal_shutdown("done")
    master.terminate()
    master.wait(timeout=10)
check("the board answers again" in out, "the node logs that the board answers again")
finish()
