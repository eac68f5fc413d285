#!/usr/bin/env python3
# rcb4_ros as a kxr_controller user meets it, against a real ROS master: an actionlib client of
# control_msgs/FollowJointTrajectory on /fullbody_controller/follow_joint_trajectory (success within
# tolerance, INVALID_JOINTS and INVALID_GOAL with nothing moved (a point due at once too), cancel and
# preemption holding the joints, a ROM motion refusing the goal), kxr_controller's ServoOnOff
# (a mimic joint's servo, unknown names left out), Stretch and AdjustAngleVector (a threshold that
# looks like radians said), the joints parameter and robot_description; the topics a kxr_controller
# user reads (current_joint_states, servo_states, fullbody_controller/state and ServoOnOff's state:
# the servo error, NaN for what is not known) and its dynamic_reconfigure parameters (frame_count
# acting on a streamed command; a value out of range, the current limit and a start-up
# ~current_limit refused, said); on a board of our own whose servos never move,
# PATH_TOLERANCE_VIOLATED, an adjustment, the servo error of a servo that does not follow, and
# nothing published while that board is silent; a script written as a kxr_controller user writes
# it, run unchanged. interrupts_test.py: a silent board, takeovers.
#   actions_test.py RCB4 PYRCB4_DIR NODE_SRC_DIR MESSAGES_DIR
# SPDX-License-Identifier: BSL-1.0
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path[:0] = [HERE, os.path.join(HERE, "..", "..", "tests", "integration")]
from checks import check, finish  # noqa: E402
import master as rosmaster  # noqa: E402
from master import wait_for  # noqa: E402
from standin import StandIn  # noqa: E402

RCB4, PYRCB4, NODE_SRC, MESSAGES = sys.argv[1:5]
NODE = os.path.join(NODE_SRC, "..", "scripts", "rcb4_node")
master, env = rosmaster.start(PYRCB4, NODE_SRC, name="/rcb4_actions_test")
env["RCB4_ROS_MESSAGES"] = MESSAGES
sys.path.append(MESSAGES)

import actionlib  # noqa: E402
import dynamic_reconfigure.client  # noqa: E402
import rospy  # noqa: E402
from actionlib_msgs.msg import GoalStatus  # noqa: E402
from control_msgs.msg import FollowJointTrajectoryAction, FollowJointTrajectoryGoal, JointTolerance  # noqa: E402
from control_msgs.msg import FollowJointTrajectoryResult as Result  # noqa: E402
from control_msgs.msg import JointTrajectoryControllerState  # noqa: E402
from kxr_controller.msg import AdjustAngleVectorAction, AdjustAngleVectorGoal  # noqa: E402
from kxr_controller.msg import ServoOnOff, ServoOnOffAction, ServoOnOffGoal, ServoStateArray  # noqa: E402
from kxr_controller.msg import Stretch, StretchAction, StretchGoal  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from std_msgs.msg import UInt8  # noqa: E402
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint  # noqa: E402

rospy.init_node("rcb4_actions_test", anonymous=True, disable_signals=True)
states = []
rospy.Subscriber("/joint_states", JointState, lambda m: states.append(m), queue_size=100)
# What a kxr_controller user reads besides joint_states: (monotonic time received, message).
READINGS = {"/current_joint_states": JointState, "/servo_states": ServoStateArray,
            "/fullbody_controller/state": JointTrajectoryControllerState,
            "/fullbody_controller/servo_on_off_real_interface/state": ServoOnOff}
readings = {topic: [] for topic in READINGS}
for topic, kind in READINGS.items():
    rospy.Subscriber(topic, kind, lambda m, t=topic: readings[t].append((time.monotonic(), m)), queue_size=100)


def latest(topic, timeout=5):
    """The newest message on @p topic received from now on (None when none comes within @p timeout s)."""
    since = time.monotonic()
    got = wait_for(lambda: [m for t, m in readings[topic][-5:] if t >= since], timeout=timeout)
    return got[-1] if got else None


def value_of(msg, name, field=None):
    """@p msg's value for joint @p name (a JointState's position/effort, a controller state's
    desired/actual/error positions, a ServoStateArray's ServoState), or None when it is not there."""
    if isinstance(msg, ServoStateArray):
        return next((s for s in msg.servos if s.name == name), None)
    names = msg.name if isinstance(msg, JointState) else msg.joint_names
    if name not in names:
        return None
    values = getattr(msg, field) if isinstance(msg, JointState) else getattr(msg, field).positions
    return values[names.index(name)]


def position(name):
    for m in reversed(states[-20:]):
        if name in m.name:
            return math.degrees(m.position[m.name.index(name)])
    return None


def goal(points, joints=("left_knee",), path=(), end=(), goal_time=0.0):
    g = FollowJointTrajectoryGoal()
    g.trajectory.joint_names = list(joints)
    for degs, secs in points:
        degs = degs if isinstance(degs, (list, tuple)) else [degs]
        g.trajectory.points.append(JointTrajectoryPoint(positions=[math.radians(d) for d in degs],
                                                        time_from_start=rospy.Duration(secs)))
    g.path_tolerance = [JointTolerance(name=n, position=math.radians(d)) for n, d in path]
    g.goal_tolerance = [JointTolerance(name=n, position=math.radians(d)) for n, d in end]
    g.goal_time_tolerance = rospy.Duration(goal_time)
    return g


def start_node(*params):
    rospy.delete_param("/robot_description") if rospy.has_param("/robot_description") else None
    return subprocess.Popen([sys.executable, NODE, *params], env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)


def stop(node):
    node.send_signal(signal.SIGINT)
    try:
        node.wait(timeout=5)
    except subprocess.TimeoutExpired:
        node.kill()
        node.wait()
    return node.stdout.read()


def tool_joints(dev):
    r = subprocess.run([RCB4, "--json", "--device", dev, "joint", "list"], capture_output=True, text=True, timeout=30)
    return {j["name"]: j for j in json.loads(r.stdout)} if r.returncode == 0 else {}


srv = subprocess.Popen([RCB4, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
dev = srv.stdout.readline().strip()
# ~current_limit, as kxr_controller.launch sets it: the RCB-4 cannot apply it (refused at start, said).
node = start_node(f"_device:={dev}", "_rate:=50", "_current_limit:=4.0")
try:
    client = actionlib.SimpleActionClient("/fullbody_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    check(client.wait_for_server(rospy.Duration(20)), "the FollowJointTrajectory server is up")
    joints = rospy.get_param("/fullbody_controller/joints", [])
    check(len(joints) == 20 and "left_knee" in joints, f"fullbody_controller/joints: the 20 joints ({len(joints)})")
    urdf = rospy.get_param("/robot_description", "")
    check('<robot name="' in urdf and 'joint name="left_knee"' in urdf, "robot_description: the profile's URDF")
    wait_for(lambda: position("left_knee") is not None)

    # The check: left_knee to 40 deg over 1 s, SUCCEEDED, joint_states within 1 deg.
    feedback = []
    client.send_goal(goal([(40, 1.0)]), feedback_cb=feedback.append)
    done = client.wait_for_result(rospy.Duration(10))
    r = client.get_result()
    check(done and client.get_state() == GoalStatus.SUCCEEDED and r.error_code == Result.SUCCESSFUL,
          f"a two-second goal succeeds ({client.get_state()}, {r and r.error_string!r})")
    time.sleep(0.2)
    check(abs(position("left_knee") - 40) < 1, f"joint_states: left_knee within 1 deg of 40 ({position('left_knee')})")
    check(len(feedback) > 20 and feedback[-1].joint_names == ["left_knee"]
          and abs(math.degrees(feedback[len(feedback) // 2].desired.positions[0]) - 20) < 8,
          f"feedback at the control rate: desired, actual, error ({len(feedback)} messages)")
    # The readings a kxr_controller user takes: left_knee's target is known (40, where the goal put
    # it), head_yaw's is not (never commanded): its error is NaN, not a made-up 0.
    js, cur, servos, ctl = (states[-1], latest("/current_joint_states"), latest("/servo_states"),
                            latest("/fullbody_controller/state"))
    knee = value_of(servos, "left_knee") if servos else None
    check(len(js.effort) == len(js.name) == 20 and abs(value_of(js, "left_knee", "effort")) < math.radians(0.5)
          and math.isnan(value_of(js, "head_yaw", "effort")) and not js.velocity,
          f"joint_states: effort is the servo error (left_knee at its target: {value_of(js, 'left_knee', 'effort')}; "
          f"head_yaw's target unknown: {value_of(js, 'head_yaw', 'effort')}), no velocities ({len(js.velocity)})")
    check(cur is not None and len(cur.name) == 20 and abs(math.degrees(value_of(cur, "left_knee", "position")) - 40) < 1
          and len(cur.effort) == 20, f"current_joint_states: the servos' joints, positions and errors "
                                     f"({cur and len(cur.name)})")
    check(knee is not None and len(servos.servos) == 20 and abs(math.degrees(knee.position) - 40) < 1
          and abs(knee.error) < math.radians(0.5) and math.isnan(knee.temperature) and math.isnan(knee.current)
          and math.isnan(value_of(servos, "head_yaw").error),
          f"servo_states: position and error; temperature and current NaN (the RCB-4 reads neither) "
          f"({knee and (knee.position, knee.error, knee.temperature, knee.current)})")
    check(ctl is not None and len(ctl.joint_names) == 20 and abs(math.degrees(value_of(ctl, "left_knee", "desired")) - 40) < 0.1
          and abs(value_of(ctl, "left_knee", "error")) < math.radians(0.5) and math.isnan(value_of(ctl, "head_yaw", "desired"))
          and not ctl.actual.velocities,
          f"fullbody_controller/state: desired, actual, error; head_yaw's desired unknown (NaN) "
          f"({ctl and (ctl.desired.positions[:3], ctl.error.positions[:3])})")
    # Two joints, two points.
    client.send_goal(goal([([10, 20], 0.4), ([-10, 0], 0.8)], joints=("left_knee", "head_yaw")))
    client.wait_for_result(rospy.Duration(10))
    # SUCCEEDED when its time is up (as joint_trajectory_controller without goal tolerances); the
    # joint_states this test receives lag on a loaded machine: read until they arrive, bounded.
    there = wait_for(lambda: abs(position("left_knee") + 10) < 1 and abs(position("head_yaw")) < 1, timeout=3)
    check(client.get_state() == GoalStatus.SUCCEEDED and there,
          f"a two-point goal of two joints succeeds ({client.get_state()}, {position('left_knee')}, {position('head_yaw')})")

    # Refused goals: nothing moves.
    for g, code, what in ((goal([(20, 1.0)], joints=("no_such_joint",)), Result.INVALID_JOINTS, "an unknown joint"),
                          (goal([(20, 1.0)], joints=("left_knee", "left_knee")), Result.INVALID_JOINTS, "a joint twice"),
                          (goal([(140, 1.0)]), Result.INVALID_GOAL, "a point beyond the limit"),
                          (goal([(20, 1.0), (30, 0.5)]), Result.INVALID_GOAL, "times that go back"),
                          (goal([(float("nan"), 1.0)]), Result.INVALID_GOAL, "NaN"),
                          (goal([(60, 0.0)]), Result.INVALID_GOAL, "a single point at time_from_start 0")):
        client.send_goal(g)
        client.wait_for_result(rospy.Duration(5))
        r = client.get_result()
        time.sleep(0.3)
        check(client.get_state() == GoalStatus.ABORTED and r.error_code == code and abs(position("left_knee") + 10) < 0.5
              and ("due at once" in r.error_string or "time_from_start 0" not in what),
              f"{what}: {code}, nothing moves ({client.get_state()}, {r.error_code}: {r.error_string!r})")

    # Cancel mid-way: the joint holds where it is.
    client.send_goal(goal([(-60, 2.0)]))
    time.sleep(0.8)
    client.cancel_goal()
    client.wait_for_result(rospy.Duration(5))
    time.sleep(0.2)
    at = position("left_knee")
    time.sleep(1.5)
    check(client.get_state() == GoalStatus.PREEMPTED and -50 < at < -12 and abs(position("left_knee") - at) < 1,
          f"cancel mid-way: PREEMPTED, left_knee holds at {at:.1f} (now {position('left_knee'):.1f}), not -60")
    # A new goal preempts the one under way.
    first = actionlib.SimpleActionClient("/fullbody_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    first.wait_for_server(rospy.Duration(5))
    first.send_goal(goal([(60, 2.0)], joints=("head_yaw",)))
    time.sleep(0.5)
    client.send_goal(goal([(0, 0.5)], joints=("head_yaw",)))
    client.wait_for_result(rospy.Duration(5))
    first.wait_for_result(rospy.Duration(5))
    check(first.get_state() == GoalStatus.PREEMPTED and client.get_state() == GoalStatus.SUCCEEDED
          and abs(position("head_yaw")) < 1, f"a newer goal preempts: ({first.get_state()}, {client.get_state()})")

    # A ROM motion running refuses the goal, as the topic does.
    play = rospy.Publisher("/rcb4/play_motion", UInt8, queue_size=2)
    wait_for(lambda: play.get_num_connections() > 0)
    play.publish(UInt8(3))
    time.sleep(0.5)
    client.send_goal(goal([(30, 0.5)], joints=("head_yaw",)))
    client.wait_for_result(rospy.Duration(5))
    r = client.get_result()
    check(client.get_state() == GoalStatus.ABORTED and r.error_code == Result.INVALID_GOAL and "motion 3" in r.error_string,
          f"a goal while motion 3 runs: refused ({r.error_string!r})")
    time.sleep(3.0)

    # kxr_controller's servo actions.
    on_off = actionlib.SimpleActionClient("/fullbody_controller/servo_on_off_real_interface", ServoOnOffAction)
    check(on_off.wait_for_server(rospy.Duration(5)), "the ServoOnOff server is up")
    on_off.send_goal(ServoOnOffGoal(joint_names=["left_knee"], servo_on_states=[False]))
    on_off.wait_for_result(rospy.Duration(5))
    check(on_off.get_state() == GoalStatus.SUCCEEDED, f"ServoOnOff frees left_knee ({on_off.get_goal_status_text()!r})")
    servo_on = latest("/fullbody_controller/servo_on_off_real_interface/state")
    ctl = latest("/fullbody_controller/state")
    check(servo_on is not None and len(servo_on.joint_names) == 20
          and dict(zip(servo_on.joint_names, servo_on.servo_on_states)) == {n: n != "left_knee" for n in joints}
          and math.isnan(value_of(ctl, "left_knee", "desired")),
          f"servo_on_off_real_interface/state: left_knee off, the others on; a free joint has no target "
          f"({servo_on and [n for n, on in zip(servo_on.joint_names, servo_on.servo_on_states) if not on]})")
    on_off.send_goal(ServoOnOffGoal(joint_names=["no_such_joint"], servo_on_states=[True]))
    on_off.wait_for_result(rospy.Duration(5))
    check(on_off.get_state() == GoalStatus.ABORTED and "no_such_joint" in on_off.get_goal_status_text(),
          f"ServoOnOff of an unknown joint: aborted, named ({on_off.get_goal_status_text()!r})")
    # A goal naming the freed joint moves the others and leaves it free, as kxr_controller does.
    knee = position("left_knee")
    client.send_goal(goal([([knee + 30, 20], 0.5)], joints=("left_knee", "head_yaw")))
    client.wait_for_result(rospy.Duration(5))
    check(client.get_state() == GoalStatus.SUCCEEDED and abs(position("head_yaw") - 20) < 1
          and abs(position("left_knee") - knee) < 1, f"a goal naming a freed joint leaves it out ({position('left_knee')})")

    stretch = actionlib.SimpleActionClient("/fullbody_controller/stretch_interface", StretchAction)
    check(stretch.wait_for_server(rospy.Duration(5)), "the Stretch server is up")
    stretch.send_goal(StretchGoal(joint_names=["head_yaw"], stretch=60))
    stretch.wait_for_result(rospy.Duration(5))
    said = rospy.wait_for_message("/fullbody_controller/stretch", Stretch, timeout=5)
    check(stretch.get_state() == GoalStatus.SUCCEEDED and said.joint_names == ["head_yaw"] and list(said.stretch) == [60],
          f"Stretch 60 on head_yaw, said on fullbody_controller/stretch ({said})")
    stretch.send_goal(StretchGoal(joint_names=[], stretch=200))
    stretch.wait_for_result(rospy.Duration(5))
    check(stretch.get_state() == GoalStatus.ABORTED and "1-127" in stretch.get_goal_status_text(),
          f"Stretch 200: aborted ({stretch.get_goal_status_text()!r})")
    adjust = actionlib.SimpleActionClient("/fullbody_controller/adjust_angle_vector_interface", AdjustAngleVectorAction)
    check(adjust.wait_for_server(rospy.Duration(5)), "the AdjustAngleVector server is up")
    adjust.send_goal(AdjustAngleVectorGoal(joint_names=["head_yaw"], error_threshold=[5.0]))
    adjust.wait_for_result(rospy.Duration(5))
    check(adjust.get_state() == GoalStatus.SUCCEEDED and "no joint" in adjust.get_goal_status_text(),
          f"AdjustAngleVector with the joints on their way: nothing held ({adjust.get_goal_status_text()!r})")
    # kxr_controller's client passes numpy.deg2rad(5): read as degrees (as its server does), and said.
    adjust.send_goal(AdjustAngleVectorGoal(joint_names=["head_yaw"], error_threshold=[math.radians(5)]))
    adjust.wait_for_result(rospy.Duration(5))
    check(adjust.get_state() == GoalStatus.SUCCEEDED and "look like radians" in adjust.get_goal_status_text(),
          f"AdjustAngleVector with a threshold of 0.087: a warning that it looks like radians "
          f"({adjust.get_goal_status_text()!r})")

    # A script as a kxr_controller user writes it, unchanged.
    script = os.path.join(tempfile.mkdtemp(), "kxr_user.py")
    with open(script, "w") as f:
        f.write(textwrap.dedent("""\
            import actionlib, rospy
            import control_msgs.msg
            from kxr_controller.msg import ServoOnOffAction, ServoOnOffGoal
            from trajectory_msgs.msg import JointTrajectoryPoint
            rospy.init_node("kxr_user", anonymous=True)
            joints = rospy.get_param("/fullbody_controller/joints")
            servo = actionlib.SimpleActionClient("/fullbody_controller/servo_on_off_real_interface", ServoOnOffAction)
            servo.wait_for_server()
            servo.send_goal_and_wait(ServoOnOffGoal(joint_names=joints, servo_on_states=[True] * len(joints)))
            traj = actionlib.SimpleActionClient("/fullbody_controller/follow_joint_trajectory",
                                                control_msgs.msg.FollowJointTrajectoryAction)
            traj.wait_for_server()
            g = control_msgs.msg.FollowJointTrajectoryGoal()
            g.trajectory.joint_names = joints
            g.trajectory.points = [JointTrajectoryPoint(positions=[0.1] * len(joints), time_from_start=rospy.Duration(1.0))]
            traj.send_goal_and_wait(g)
            print("result", traj.get_state(), traj.get_result().error_code)
            """))
    r = subprocess.run([sys.executable, script], env=dict(env, PYTHONPATH=env["PYTHONPATH"] + os.pathsep + MESSAGES),
                       capture_output=True, text=True, timeout=60)
    check(r.returncode == 0 and "result 3 0" in r.stdout and abs(position("left_knee") - math.degrees(0.1)) < 1,
          f"a kxr_controller user's script runs unchanged: every servo on, all joints to 0.1 rad ({r.stdout.strip()!r} "
          f"{r.stderr.strip()[-300:]!r})")
    # kxr_controller's dynamic_reconfigure parameters, through its client's way of reaching them
    # (update_kxr_parameters: Client("rcb4_ros_bridge")).
    params = dynamic_reconfigure.client.Client("rcb4_ros_bridge", timeout=10)
    cfg = params.get_configuration(timeout=5)
    check(cfg["frame_count"] == 2 and cfg["wheel_frame_count"] == 1 and math.isnan(cfg["current_limit"])
          and math.isnan(cfg["temperature_limit"]),
          f"dynamic_reconfigure: frame_count one cycle (2 frames at 50 Hz), the limits NaN (not known) "
          f"({ {k: v for k, v in cfg.items() if k != 'groups'} })")
    r = params.update_configuration({"frame_count": 100})
    stream = rospy.Publisher("/rcb4/joint_command", JointState, queue_size=2)
    wait_for(lambda: stream.get_num_connections() > 0)
    sent = time.monotonic()
    stream.publish(JointState(name=["left_knee"], position=[math.radians(45)]))  # from 0.1 rad (5.7 deg)
    time.sleep(max(0.0, sent + 0.5 - time.monotonic()))
    half = position("left_knee")
    arrived = wait_for(lambda: abs(position("left_knee") - 45) < 1, timeout=5)
    check(r["frame_count"] == 100 and 10 < half < 40 and arrived,
          f"frame_count 100: a streamed target is a 1 s move (left_knee {half:.1f} deg 0.5 s after it, on its "
          f"way from 5.7 to 45)")
    r = params.update_configuration({"frame_count": 300})
    r2 = params.update_configuration({"current_limit": 3.0, "temperature_limit": 70.0})
    check(r["frame_count"] == 100 and math.isnan(r2["current_limit"]) and math.isnan(r2["temperature_limit"]),
          f"frame_count 300 (beyond 255) refused, it stays 100; current and temperature limits refused, NaN "
          f"({r['frame_count']}, {r2['current_limit']}, {r2['temperature_limit']})")
    params.update_configuration({"frame_count": 2})
    stream.publish(JointState(name=["left_knee"], position=[0.1]))
    check(wait_for(lambda: abs(position("left_knee") - math.degrees(0.1)) < 1, timeout=5) is not None,
          f"frame_count 2 again: left_knee back at 0.1 rad ({position('left_knee')})")
    # A ~command for another joint takes over: the goal is preempted, its joints hold (they do not
    # run on to the end of a goal nobody watches any more).
    cmd = rospy.Publisher("/rcb4/command", JointTrajectory, queue_size=2)
    wait_for(lambda: cmd.get_num_connections() > 0)
    client.send_goal(goal([(60, 2.0)], joints=("right_knee",)))
    time.sleep(0.5)
    cmd.publish(JointTrajectory(joint_names=["head_yaw"], points=[
        JointTrajectoryPoint(positions=[0.0], time_from_start=rospy.Duration(0.3))]))
    client.wait_for_result(rospy.Duration(5))
    time.sleep(0.2)
    at = position("right_knee")
    time.sleep(1.0)
    check(client.get_state() == GoalStatus.PREEMPTED and at < 40 and abs(position("right_knee") - at) < 1,
          f"a ~command takes over: the goal PREEMPTED, right_knee holds at {at:.1f} (now {position('right_knee'):.1f})")
    # The node stopped (SIGINT) during a goal: the client is told, the joints hold.
    client.send_goal(goal([(-60, 3.0)], joints=("right_knee",)))
    time.sleep(0.6)
    first_out = out = stop(node)
    # The final state, within a deadline: actionlib's client threads may still be taking the result
    # (and may log "a goal handle that we're not tracking" for the goals before it).
    ended = wait_for(lambda: client.get_state() == GoalStatus.ABORTED and "node stopped" in client.get_goal_status_text(),
                     timeout=5)
    last = position("right_knee")
    check(ended and "publish() to a closed topic" not in out,
          f"SIGINT during a goal: ABORTED, said ({client.get_state()}, {client.get_goal_status_text()!r}"
          f"{''.join(', ' + l.strip()[-200:] for l in out.splitlines() if 'publish() to a closed topic' in l)})")
    knee = tool_joints(dev).get("right_knee", {}).get("degrees")
    check(knee is not None and abs(knee - last) < 3 and knee > -50,
          f"and right_knee holds where it was (the tool reads {knee}, the last joint_states {last:.1f}), not -60")
    node = start_node(f"_device:={dev}", "_rate:=50")
    on_off = actionlib.SimpleActionClient("/fullbody_controller/servo_on_off_real_interface", ServoOnOffAction)
    on_off.wait_for_server(rospy.Duration(20))
    on_off.send_goal(ServoOnOffGoal(joint_names=["left_knee"], servo_on_states=[False]))
    on_off.wait_for_result(rospy.Duration(5))
finally:
    out = stop(node)
j = tool_joints(dev)
check(j.get("left_knee", {}).get("state") == "free" and abs(j["left_knee"]["degrees"] - math.degrees(0.1)) < 1,
      f"rcb4 joint list after the node: the joints where the goal put them (0.1 rad), left_knee free ({j.get('left_knee')})")
check("follow_joint_trajectory: refused, nothing moves: no joint is called 'no_such_joint'" in first_out,
      "a refused goal is logged with its reason")
check("~current_limit 4.0 refused: the RCB-4 can neither set nor read" in first_out
      and "frame_count 100: each ~joint_command target is a move of 100 frames (1000 ms)" in first_out
      and "frame_count 300 is outside 1-255: refused, it stays 100" in first_out
      and "current_limit 3.0 refused" in first_out and "temperature_limit 70.0 refused" in first_out,
      "dynamic_reconfigure: what is applied and what is refused is logged")
srv.terminate()
srv.wait(timeout=10)

# A board whose servos never move (our stand-in answers every move and keeps its positions):
# the path tolerance is violated, and AdjustAngleVector holds the joint that lags.
board = StandIn()
node = start_node(f"_device:={board.path}", "_baud:=115200", "_rate:=20")
try:
    client = actionlib.SimpleActionClient("/fullbody_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    client.wait_for_server(rospy.Duration(20))
    client.send_goal(goal([(30, 1.0)], joints=("head_yaw",), path=[("head_yaw", 5.0)]))
    client.wait_for_result(rospy.Duration(10))
    r = client.get_result()
    check(client.get_state() == GoalStatus.ABORTED and r.error_code == Result.PATH_TOLERANCE_VIOLATED
          and "head_yaw" in r.error_string, f"a servo that lags: PATH_TOLERANCE_VIOLATED ({r.error_string!r})")
    client.send_goal(goal([(30, 0.3)], joints=("head_yaw",), end=[("head_yaw", 1.0)], goal_time=0.3))
    client.wait_for_result(rospy.Duration(10))
    r = client.get_result()
    check(client.get_state() == GoalStatus.ABORTED and r.error_code == Result.GOAL_TOLERANCE_VIOLATED,
          f"and it never arrives: GOAL_TOLERANCE_VIOLATED ({r.error_string!r})")
    client.send_goal(goal([(30, 3.0)], joints=("head_yaw",)))
    time.sleep(1.5)
    adjust = actionlib.SimpleActionClient("/fullbody_controller/adjust_angle_vector_interface", AdjustAngleVectorAction)
    adjust.wait_for_server(rospy.Duration(5))
    adjust.send_goal(AdjustAngleVectorGoal(joint_names=["head_yaw"], error_threshold=[5.0]))
    adjust.wait_for_result(rospy.Duration(5))
    client.wait_for_result(rospy.Duration(5))
    check(adjust.get_state() == GoalStatus.SUCCEEDED and "held head_yaw" in adjust.get_goal_status_text()
          and client.get_state() in (GoalStatus.ABORTED, GoalStatus.PREEMPTED),
          f"AdjustAngleVector holds the lagging joint and ends the goal ({adjust.get_goal_status_text()!r}, "
          f"{client.get_state()})")
    # A servo that does not follow: its error is where the board has it go (30 deg) minus where it is (0).
    cmd = rospy.Publisher("/rcb4/command", JointTrajectory, queue_size=2)
    wait_for(lambda: cmd.get_num_connections() > 0)
    cmd.publish(JointTrajectory(joint_names=["head_yaw"], points=[
        JointTrajectoryPoint(positions=[math.radians(30)], time_from_start=rospy.Duration(0.3))]))
    time.sleep(0.8)
    js, servos, ctl = states[-1], latest("/servo_states"), latest("/fullbody_controller/state")
    errors = [math.degrees(e) for e in (value_of(js, "head_yaw", "effort"), servos and value_of(servos, "head_yaw").error,
                                        ctl and value_of(ctl, "head_yaw", "error")) if e is not None]
    check(len(js.name) == 3 and abs(value_of(js, "head_yaw", "position")) < 1e-9 and len(errors) == 3
          and all(abs(e - 30) < 0.5 for e in errors),
          f"a servo that stays at 0 while the board has it at 30: its error is 30 deg in joint_states' effort, "
          f"servo_states and fullbody_controller/state ({errors})")
    # The board falls silent: nothing new on any of them until it answers again.
    board.silent = True
    time.sleep(1.0)  # its reads time out (3 x 0.1 s): from here on nothing is read
    counts = [len(states)] + [len(readings[t]) for t in READINGS]
    time.sleep(1.0)
    still = [len(states)] + [len(readings[t]) for t in READINGS]
    board.silent = False
    again = wait_for(lambda: all(len(x) > n for x, n in zip([states] + list(readings.values()), still)), timeout=5)
    check(counts == still and again, f"a silent board: nothing published on joint_states, {', '.join(READINGS)} "
                                     f"for 1 s ({counts} then {still}); published again once it answers")
finally:
    stop(node)
# A servo that never answers (serve --silent 16: left_knee) is not within any tolerance.
srv = subprocess.Popen([RCB4, "serve", "--pty", "--silent", "16"], stdout=subprocess.PIPE, text=True)
dev = srv.stdout.readline().strip()
node = start_node(f"_device:={dev}", "_rate:=50")
try:
    client = actionlib.SimpleActionClient("/fullbody_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    client.wait_for_server(rospy.Duration(20))
    client.send_goal(goal([([20, -20], 0.3)], joints=("left_knee", "right_knee"), goal_time=0.3))
    client.wait_for_result(rospy.Duration(10))
    r = client.get_result()
    check(client.get_state() == GoalStatus.ABORTED and r.error_code == Result.GOAL_TOLERANCE_VIOLATED
          and "left_knee has no measured position" in r.error_string,
          f"a joint that never answers: GOAL_TOLERANCE_VIOLATED ({r.error_string!r})")
finally:
    stop(node)
    srv.terminate()
    srv.wait(timeout=10)

# A robot whose URDF names its joints in upper case and has two joints on one servo (a gripper):
# joint_states carries both, the follower as URDF's mimic says; it cannot be commanded itself.
profile = os.path.join(tempfile.mkdtemp(), "gripper.yaml")
with open(profile, "w") as f:
    f.write("robot: gripper\njoints:\n  HEAD_JOINT0: {ics: 0, lower: -90, upper: 90}\n"
            "  L_FINGER: {ics: 2, lower: 0, upper: 60}\nmimic:\n  R_FINGER: {joint: L_FINGER, multiplier: -1}\n")
srv = subprocess.Popen([RCB4, "serve", "--pty"], stdout=subprocess.PIPE, text=True)
dev = srv.stdout.readline().strip()
states.clear()
node = start_node(f"_device:={dev}", f"_robot:={profile}", "_rate:=50")
try:
    client = actionlib.SimpleActionClient("/fullbody_controller/follow_joint_trajectory", FollowJointTrajectoryAction)
    client.wait_for_server(rospy.Duration(20))
    wait_for(lambda: position("R_FINGER") is not None)
    check(rospy.get_param("/fullbody_controller/joints", []) == ["HEAD_JOINT0", "L_FINGER"] and
          position("HEAD_JOINT0") is not None, f"upper-case joint names ({states[-1].name if states else None})")
    client.send_goal(goal([(30, 0.5)], joints=("L_FINGER",)))
    client.wait_for_result(rospy.Duration(10))
    time.sleep(0.2)
    check(client.get_state() == GoalStatus.SUCCEEDED and abs(position("L_FINGER") - 30) < 1
          and abs(position("R_FINGER") + 30) < 1,
          f"a mimic joint in joint_states: R_FINGER = -1 x L_FINGER ({position('L_FINGER')}, {position('R_FINGER')})")
    client.send_goal(goal([(-10, 0.5)], joints=("R_FINGER",)))
    client.wait_for_result(rospy.Duration(10))
    r = client.get_result()
    check(client.get_state() == GoalStatus.ABORTED and r.error_code == Result.INVALID_JOINTS and "follows L_FINGER" in r.error_string,
          f"a goal for the mimic joint: INVALID_JOINTS, saying what it follows ({r.error_string!r})")
    # ServoOnOff on the mimic joint acts on the servo it shares; a name the node does not have is
    # left out and said (as kxr_controller skips it), when another is known.
    on_off = actionlib.SimpleActionClient("/fullbody_controller/servo_on_off_real_interface", ServoOnOffAction)
    on_off.wait_for_server(rospy.Duration(5))
    on_off.send_goal(ServoOnOffGoal(joint_names=["R_FINGER"], servo_on_states=[False]))
    on_off.wait_for_result(rospy.Duration(5))
    said = on_off.get_goal_status_text()
    client.send_goal(goal([(10, 0.3)], joints=("L_FINGER",)))  # a freed joint is left out: it stays
    client.wait_for_result(rospy.Duration(5))
    time.sleep(0.3)
    check(on_off.get_state() == GoalStatus.SUCCEEDED and "free: 1 joints" in said and abs(position("L_FINGER") - 30) < 1,
          f"ServoOnOff off for the mimic R_FINGER frees the servo it shares: L_FINGER stays at "
          f"{position('L_FINGER'):.1f}, not 10 ({said!r})")
    on_off.send_goal(ServoOnOffGoal(joint_names=["L_FINGER", "L_WHEEL"], servo_on_states=[True, True]))
    on_off.wait_for_result(rospy.Duration(5))
    said = on_off.get_goal_status_text()
    client.send_goal(goal([(10, 0.3)], joints=("L_FINGER",)))
    client.wait_for_result(rospy.Duration(5))
    time.sleep(0.3)
    check(on_off.get_state() == GoalStatus.SUCCEEDED and "L_WHEEL" in said and "left out" in said
          and abs(position("L_FINGER") - 10) < 1,
          f"ServoOnOff naming a joint the node does not have, with one it has: that one left out, said, the "
          f"other on ({said!r}; L_FINGER {position('L_FINGER'):.1f})")
finally:
    out = stop(node)
    srv.terminate()
    srv.wait(timeout=10)
check("no robot_description" in out, "the log says why there is no robot_description")
master.terminate()
finish()
