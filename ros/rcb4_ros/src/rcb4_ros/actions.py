# rcb4_ros.actions: kxr_controller's action interface over the node's trajectory engine, so a
# kxr_controller user's client runs unchanged (docs/ros.md):
#  - control_msgs/FollowJointTrajectory on <ns>/follow_joint_trajectory: goal checks, feedback at
#    the control rate, path and goal tolerances and the goal time tolerance, preemption and cancel
#    (the joints hold where they are);
#  - kxr_controller's ServoOnOff (<ns>/servo_on_off_real_interface), Stretch (<ns>/stretch_interface,
#    what was set on <ns>/stretch) and AdjustAngleVector (<ns>/adjust_angle_vector_interface).
# <ns> is ~controller_namespace, "fullbody_controller" by default. Each server's callback runs in
# actionlib's thread and only asks the node's loop thread, which alone talks to the board.
# SPDX-License-Identifier: BSL-1.0
import math
import time

import actionlib
import numpy
import rospy
from trajectory_msgs.msg import JointTrajectoryPoint

from rcb4_ros import messages


class Refused(Exception):
    """A goal that cannot be carried out: the FollowJointTrajectory error code and why."""

    def __init__(self, code, text):
        super().__init__(text)
        self.code = code


class Actions:
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

    # --- FollowJointTrajectory -------------------------------------------------------------------
    def check_goal(self, goal):
        """The goal's joints (node indices), times (s), positions (rad, one row per point) and
        tolerances; Refused with the error code for what is wrong, before anything moves."""
        R, node, traj = self.R, self.node, goal.trajectory
        idx = []
        for name in traj.joint_names:
            if name not in node.index:
                follows = next((node.prefix + node.names[j] for m, j, _, _ in node.mimics if m == name), None)
                if follows:
                    raise Refused(R.INVALID_JOINTS, f"{name} follows {follows} (mimic: no servo of its own): "
                                                    f"command {follows}")
                raise Refused(R.INVALID_JOINTS, f"no joint is called '{name}' (the joints: "
                                                f"{rospy.resolve_name(self.ns + '/joints')})")
            if node.index[name] in idx:
                raise Refused(R.INVALID_JOINTS, f"{name} is named twice")
            idx.append(node.index[name])
        if traj.points and not idx:
            raise Refused(R.INVALID_JOINTS, "the trajectory names no joint")
        times, rows, last = [], [], -1.0
        for k, p in enumerate(traj.points):
            t = p.time_from_start.to_sec()
            if len(p.positions) != len(idx):
                raise Refused(R.INVALID_GOAL, f"point {k}: {len(p.positions)} positions for {len(idx)} joints")
            if not math.isfinite(t) or t < 0:
                raise Refused(R.INVALID_GOAL, f"point {k}: time_from_start {t:.3f} s is not a time from the start")
            if k > 0 and t <= last:
                raise Refused(R.INVALID_GOAL, f"point {k}: time_from_start {t:.3f} s does not come after "
                                              f"{last:.3f} s")
            for field in ("velocities", "accelerations", "effort"):
                given = len(getattr(p, field))
                if given and given != len(idx):
                    raise Refused(R.INVALID_GOAL, f"point {k}: {given} {field} for {len(idx)} joints")
            try:
                node.degrees_of(traj.joint_names, p.positions, f"point {k}")  # NaN, limits
            except ValueError as e:
                raise Refused(R.INVALID_GOAL, str(e)) from None
            times.append(t)
            rows.append(list(p.positions))
            last = t
        stamp = traj.header.stamp.to_sec() if not traj.header.stamp.is_zero() else 0.0
        if stamp and traj.points and stamp + times[-1] < rospy.get_time():
            raise Refused(R.OLD_HEADER_TIMESTAMP, f"the trajectory ended {rospy.get_time() - stamp - times[-1]:.2f} s "
                                                  "ago (header.stamp + the last point's time)")
        path = self.tolerances(goal.path_tolerance, traj.joint_names, self.path_default)
        end = self.tolerances(goal.goal_tolerance, traj.joint_names, self.goal_default)
        goal_time = goal.goal_time_tolerance.to_sec() or self.goal_time_default
        return idx, times, numpy.array(rows), stamp, path, end, goal_time

    def tolerances(self, given, names, default):
        """Position tolerance per joint of the goal, in rad (inf: not checked); 0 is the server's
        default, -1 none; a tolerance for a joint the goal does not name is refused."""
        tol = numpy.full(len(names), default if default > 0 else math.inf)
        for t in given:
            if t.name not in names:
                raise Refused(self.R.INVALID_GOAL, f"a tolerance for {t.name}, which the trajectory does not name")
            if t.position < 0:
                tol[names.index(t.name)] = math.inf
            elif t.position > 0:
                tol[names.index(t.name)] = t.position
        return tol

    def end(self, how, code, text, hold=True):
        """Ends the active goal: @p how is set_aborted or set_preempted; the joints hold first."""
        if hold:
            self.node.stop_now()
        r = self.control.FollowJointTrajectoryResult(error_code=code, error_string=text)
        if code != self.R.SUCCESSFUL:
            rospy.logwarn("rcb4: follow_joint_trajectory: %s", text)
        how(r, text)

    def follow(self, goal):
        node, R = self.node, self.R
        try:
            idx, times, rows, stamp, path, tol, goal_time = self.check_goal(goal)
            refusal = node.move_refusal()
            if refusal:
                raise Refused(R.INVALID_GOAL, f"{refusal} (~stop_motion first)")
        except Refused as e:
            return self.end(self.trajectory.set_aborted, e.code, f"refused, nothing moves: {e}", hold=False)
        names = goal.trajectory.joint_names
        if not goal.trajectory.points:  # an empty trajectory: stop, every joint holds where it is
            node.stop_now()
            return self.trajectory.set_succeeded(R(error_code=R.SUCCESSFUL, error_string="stopped"), "stopped")
        start = numpy.radians(node.angles[idx])
        generation = node.follow(names, [(t, list(r)) for t, r in zip(times, rows)], stamp)
        begin = time.monotonic() + (max(0.0, stamp - rospy.get_time()) if stamp else 0.0)
        ts = numpy.concatenate(([0.0], times))
        freed_said = False
        period = 1.0 / node.rate
        while True:
            if self.trajectory.is_preempt_requested():
                return self.end(self.trajectory.set_preempted, R.SUCCESSFUL,
                                "cancelled: the joints hold where they are")
            if node.generation != generation:
                # Another command took over: the goal's joints it does not name hold where they
                # are (the rest of this goal does not run on unwatched); the client is told.
                keep = [i for i in idx if i not in node.replacing] if node.replaced_by.startswith("replaced") else []
                if keep:
                    node.drop(keep)
                    node.queue("hold_some", keep)
                why = node.replaced_by or "replaced"
                if why.startswith(("the node stopped", "dropped")):
                    return self.end(self.trajectory.set_aborted, R.INVALID_GOAL, why, hold=False)
                return self.end(self.trajectory.set_preempted, R.SUCCESSFUL, why, hold=False)
            if not node.link_ok:
                return self.end(self.trajectory.set_aborted, R.INVALID_GOAL,
                                f"the board does not answer: {node.link_reason}")
            t = time.monotonic() - begin
            actual = numpy.radians(node.angles[idx])
            known = numpy.where(numpy.isnan(start), actual, start)
            desired = numpy.array([numpy.interp(t, ts, numpy.concatenate(([known[j]], rows[:, j])))
                                   for j in range(len(idx))])
            error = desired - actual
            free = node.freed[idx]
            if free.any() and not freed_said:
                node.refuse(f"follow_joint_trajectory: {', '.join(n for n, f in zip(names, free) if f)} "
                            "free: left out (servo off), as kxr_controller does")
                freed_said = True
            fb = self.control.FollowJointTrajectoryFeedback()
            fb.header.stamp = rospy.Time.now()
            fb.joint_names = names
            fb.desired = JointTrajectoryPoint(positions=list(desired), time_from_start=rospy.Duration(max(t, 0.0)))
            fb.actual = JointTrajectoryPoint(positions=list(actual), time_from_start=rospy.Duration(max(t, 0.0)))
            fb.error = JointTrajectoryPoint(positions=list(error), time_from_start=rospy.Duration(max(t, 0.0)))
            self.trajectory.publish_feedback(fb)
            checked = ~free & ~numpy.isnan(error)
            if 0 <= t < times[-1]:
                bad = checked & (numpy.abs(error) > path)
                if bad.any():
                    j = int(numpy.flatnonzero(bad)[0])
                    return self.end(self.trajectory.set_aborted, R.PATH_TOLERANCE_VIOLATED,
                                    f"{names[j]} is {math.degrees(abs(error[j])):.2f} deg from its path at "
                                    f"{t:.2f} s (tolerance {math.degrees(path[j]):.2f}): the joints hold where they are")
            elif t >= times[-1]:
                final_error = rows[-1] - actual
                # A joint whose position is not measured is not within any tolerance.
                bad = ~free & (numpy.isnan(final_error) | (numpy.abs(final_error) > tol))
                if not bad.any():
                    return self.trajectory.set_succeeded(R(error_code=R.SUCCESSFUL, error_string=""), "")
                if t > times[-1] + goal_time:
                    j = int(numpy.flatnonzero(bad)[0])
                    far = ("has no measured position (its servo does not answer)" if math.isnan(final_error[j])
                           else f"is {math.degrees(abs(final_error[j])):.2f} deg from its goal")
                    return self.end(self.trajectory.set_aborted, R.GOAL_TOLERANCE_VIOLATED,
                                    f"{names[j]} {far} {goal_time:.2f} s after the last point (tolerance "
                                    f"{math.degrees(tol[j]):.2f}): the joints hold where they are")
            time.sleep(period)

    def wait_idle(self, timeout):
        """Waits (at most @p timeout s) for the trajectory goal under way to end."""
        end = time.monotonic() + timeout
        while self.trajectory.is_active() and time.monotonic() < end:
            time.sleep(0.02)

    def cancel_goal(self, why):
        """Ends the trajectory goal under way (kxr_controller cancels it before servo changes)."""
        if self.trajectory.is_active():
            self.node.stop_now(why)

    # --- kxr_controller's servo actions ------------------------------------------------------------
    def joints_of(self, names, server, result):
        """The node's names for @p names (empty: every joint), or None after aborting @p server."""
        unknown = [n for n in names if n not in self.node.index]
        if unknown:
            text = f"no joint is called {', '.join(repr(n) for n in unknown)}: nothing was done"
            rospy.logwarn("rcb4: %s", text)
            server.set_aborted(result, text)
            return None
        return list(names) if names else [self.node.prefix + n for n in self.node.names]

    def on_off(self, goal):
        result = self.kxr.ServoOnOffResult()
        if len(goal.joint_names) != len(goal.servo_on_states):
            return self.servo_on_off.set_aborted(result, f"{len(goal.joint_names)} joints but "
                                                         f"{len(goal.servo_on_states)} states: nothing was done")
        names = self.joints_of(goal.joint_names, self.servo_on_off, result)
        if names is None:
            return None
        self.cancel_goal("servo_on_off: the trajectory under way was cancelled (the joints hold)")
        off = " ".join(n for n, on in zip(names, goal.servo_on_states) if not on)
        on = " ".join(n for n, on in zip(names, goal.servo_on_states) if on)
        said = []
        for what, which in (("free", off), ("hold", on)):
            if which:
                ok, message = self.node.ask(what, which)
                if not ok:
                    return self.servo_on_off.set_aborted(result, message)
                said.append(message)
        return self.servo_on_off.set_succeeded(result, "; ".join(said))

    def set_stretch(self, goal):
        result = self.kxr.StretchResult()
        names = self.joints_of(goal.joint_names, self.stretch, result)
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
        ok, message = self.node.ask("adjust", list(zip(names, goal.error_threshold)))
        if not ok:
            return self.adjust.set_aborted(result, message)
        if message.startswith("held"):  # a joint was held where it is: what is under way stops (as kxr does)
            self.cancel_goal(f"adjust_angle_vector: {message}; the trajectory under way was cancelled")
        return self.adjust.set_succeeded(result, message)


def start(node):
    """The action servers for @p node, or None (said) when the messages are not to be had."""
    ns = rospy.get_param("~controller_namespace", "fullbody_controller")
    rospy.set_param(ns + "/joints", [node.prefix + n for n in node.names])  # before a client sees a server
    try:
        actions = Actions(node, ns)
    except ImportError as e:
        rospy.logwarn("rcb4: no action servers: %s", e)
        return None
    rospy.loginfo("rcb4: actions on %s (follow_joint_trajectory, servo_on_off_real_interface, stretch_interface, "
                  "adjust_angle_vector_interface)", rospy.resolve_name(ns))
    return actions
