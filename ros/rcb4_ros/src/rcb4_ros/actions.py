# rcb4_ros.actions: kxr_controller's action interface over the node's trajectory engine, so a
# kxr_controller user's client runs unchanged (docs/ros.md):
#  - control_msgs/FollowJointTrajectory on <ns>/follow_joint_trajectory (follow.py);
#  - kxr_controller's ServoOnOff (<ns>/servo_on_off_real_interface), Stretch (<ns>/stretch_interface,
#    what was set on <ns>/stretch) and AdjustAngleVector (<ns>/adjust_angle_vector_interface).
# <ns> is ~controller_namespace, "fullbody_controller" by default. Each server's callback runs in
# actionlib's thread and only asks the node's loop thread, which alone talks to the board.
# SPDX-License-Identifier: BSL-1.0
import threading

import actionlib
import rospy

from rcb4_ros import messages
from rcb4_ros.follow import FollowTrajectory


class Actions(FollowTrajectory):
    """The action servers of @p node (an Rcb4Node)."""

    def __init__(self, node, ns):
        self.node = node
        self.ns = ns
        self.control, self.kxr = messages.load()
        R = self.control.FollowJointTrajectoryResult
        self.R = R
        self.path_default = float(rospy.get_param("~path_tolerance", 0.0))     # rad; 0: not checked
        self.goal_default = float(rospy.get_param("~goal_tolerance", 0.02))    # rad at the end
        self.goal_time_default = float(rospy.get_param("~goal_time_tolerance", 0.5))  # s after the last point
        self.following = threading.Event()  # the trajectory server's callback runs (follow.py)
        self.stretches = {}  # joint -> the stretch last set (the RCB-4 cannot read it back: protocol.md §4.9)
        self.stretch_pub = rospy.Publisher(ns + "/stretch", self.kxr.Stretch, queue_size=1, latch=True)
        self.trajectory = actionlib.SimpleActionServer(ns + "/follow_joint_trajectory",
                                                       self.control.FollowJointTrajectoryAction,
                                                       execute_cb=self.follow, auto_start=False)
        self.servo_on_off = actionlib.SimpleActionServer(ns + "/servo_on_off_real_interface",
                                                         self.kxr.ServoOnOffAction, execute_cb=self.on_off,
                                                         auto_start=False)
        self.stretch = actionlib.SimpleActionServer(ns + "/stretch_interface", self.kxr.StretchAction,
                                                    execute_cb=self.set_stretch, auto_start=False)
        self.adjust = actionlib.SimpleActionServer(ns + "/adjust_angle_vector_interface",
                                                   self.kxr.AdjustAngleVectorAction, execute_cb=self.adjust_angles,
                                                   auto_start=False)
        for s in (self.trajectory, self.servo_on_off, self.stretch, self.adjust):
            s.start()

    def quiet(self):
        """Before the node shuts rospy down: the servers take no more goals and their status timers
        publish nothing more (actionlib's timer checks rospy's shutdown, then publishes: closing the
        topics in between made it raise "publish() to a closed topic"). Results already published go
        out; nothing is unregistered here."""
        for s in (self.trajectory, self.servo_on_off, self.stretch, self.adjust):
            server = s.action_server
            with server.lock:  # publish_status_async takes it and publishes only when started
                server.started = False
                if server.status_timer is not None:
                    server.status_timer.shutdown()

    # --- kxr_controller's servo actions ------------------------------------------------------------
    def servo_joint(self, name, mimic):
        """The node's name for joint @p name, or None; with @p mimic, a mimic joint stands for the joint
        whose servo it shares (a servo's power or stretch is the servo's)."""
        node = self.node
        if name in node.index:
            return name
        leader = next((node.prefix + node.names[j] for m, j, _, _ in node.mimics if m == name), None)
        return leader if mimic else None

    def joints_of(self, names, server, result, mimic=False):
        """The node's names for @p names (empty: every joint), or None after aborting @p server."""
        found = [self.servo_joint(n, mimic) for n in names]
        unknown = [n for n, j in zip(names, found) if j is None]
        if unknown:
            text = f"no joint is called {', '.join(repr(n) for n in unknown)}: nothing was done"
            rospy.logwarn("rcb4: %s", text)
            server.set_aborted(result, text)
            return None
        return list(dict.fromkeys(found)) if names else [self.node.prefix + n for n in self.node.names]

    def on_off(self, goal):
        """Each joint free (off) or held where it is (on). A mimic joint stands for the servo it shares;
        a name the node does not have is left out and said, as kxr_controller skips it (all of them
        unknown: aborted, nothing done)."""
        result = self.kxr.ServoOnOffResult()
        if len(goal.joint_names) != len(goal.servo_on_states):
            return self.servo_on_off.set_aborted(result, f"{len(goal.joint_names)} joints but "
                                                         f"{len(goal.servo_on_states)} states: nothing was done")
        states, skipped = {}, []
        for name, on in zip(goal.joint_names, goal.servo_on_states):
            joint = self.servo_joint(name, mimic=True)
            if joint is None:
                skipped.append(name)
            else:
                states[joint] = bool(on)  # a joint given twice (itself and its mimic): the last one says
        unknown = f"no joint is called {', '.join(repr(n) for n in skipped)}"
        if skipped and not states:
            rospy.logwarn("rcb4: servo_on_off: %s: nothing was done", unknown)
            return self.servo_on_off.set_aborted(result, f"{unknown}: nothing was done")
        if skipped:
            rospy.logwarn("rcb4: servo_on_off: %s: left out, as kxr_controller does", unknown)
        self.cancel_goal("servo_on_off: the trajectory under way was cancelled")
        said = []
        for what, want in (("free", False), ("hold", True)):
            which = " ".join(n for n, on in states.items() if on == want)
            if which:
                ok, message = self.node.ask(what, which)
                if not ok:
                    return self.servo_on_off.set_aborted(result, message)
                said.append(message)
        if skipped:
            said.append(f"{unknown}: left out")
        return self.servo_on_off.set_succeeded(result, "; ".join(said))

    def set_stretch(self, goal):
        result = self.kxr.StretchResult()
        names = self.joints_of(goal.joint_names, self.stretch, result, mimic=True)
        if names is None:
            return None
        if not 1 <= goal.stretch <= 127:
            return self.stretch.set_aborted(result, f"stretch {goal.stretch}: the servos take 1-127 "
                                                    "(protocol.md §4.9): nothing was done")
        ok, message = self.node.ask("stretch", (goal.stretch, names))
        if not ok:
            return self.stretch.set_aborted(result, message)
        for n in names:
            self.stretches[n] = goal.stretch
        self.publish_stretch()
        return self.stretch.set_succeeded(result, message)

    def publish_stretch(self):
        names = sorted(self.stretches, key=lambda n: self.node.index[n])
        self.stretch_pub.publish(self.kxr.Stretch(joint_names=names, stretch=[self.stretches[n] for n in names]))

    def adjust_angles(self, goal):
        result = self.kxr.AdjustAngleVectorResult()
        if len(goal.joint_names) != len(goal.error_threshold):
            return self.adjust.set_aborted(result, f"{len(goal.joint_names)} joints but {len(goal.error_threshold)} "
                                                   "thresholds: nothing was done")
        names = self.joints_of(goal.joint_names, self.adjust, result)
        if names is None:
            return None
        # Thresholds are degrees, as kxr_controller's own server reads them; its Python client's default,
        # numpy.deg2rad(5) = 0.087, is radians read as degrees, so a joint 0.1 deg off would be held.
        small = [f"{n} {t:g}" for n, t in zip(names, goal.error_threshold) if 0 < t < 0.5]
        note = ""
        if small:
            note = (f" (thresholds are degrees: {', '.join(small)} look like radians; 5 deg is 5.0, not "
                    "numpy.deg2rad(5))")
            rospy.logwarn("rcb4: adjust_angle_vector:%s", note)
        ok, message = self.node.ask("adjust", list(zip(names, goal.error_threshold)))
        if not ok:
            return self.adjust.set_aborted(result, message + note)
        if message.startswith("held"):  # a joint was held where it is: what is under way stops (as kxr does)
            self.cancel_goal(f"adjust_angle_vector: {message}; the trajectory under way was cancelled")
        return self.adjust.set_succeeded(result, message + note)


def namespace():
    """Where kxr_controller's fullbody_controller is: ~controller_namespace, in the node's namespace."""
    return rospy.get_param("~controller_namespace", "fullbody_controller")


def start(node):
    """The action servers for @p node, or None (said) when the messages are not to be had."""
    ns = namespace()
    rospy.set_param(ns + "/joints", [node.prefix + n for n in node.names])  # before a client sees a server
    try:
        actions = Actions(node, ns)
    except ImportError as e:
        rospy.logwarn("rcb4: no action servers: %s", e)
        return None
    rospy.loginfo("rcb4: actions on %s (follow_joint_trajectory, servo_on_off_real_interface, stretch_interface, "
                  "adjust_angle_vector_interface)", rospy.resolve_name(ns))
    return actions
