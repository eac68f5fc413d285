# rcb4_ros: control_msgs/FollowJointTrajectory over the node's trajectory engine (a mixin of
# actions.Actions): goal checks before anything moves, feedback at the control rate, path and goal
# tolerances and the goal time tolerance. A cancel, a failure or another command taking over holds
# the joints (holds.py: as soon as a silent board answers, and the result says which); a newer
# goal takes over from where the joints are at the next cycle, without a stop, as ROS 1's
# joint_trajectory_controller does.
# SPDX-License-Identifier: BSL-1.0
import math
import time

import numpy
import rospy
from trajectory_msgs.msg import JointTrajectoryPoint

from rcb4_ros.trajectory import due_at_once


class Refused(Exception):
    """A goal that cannot be carried out: the FollowJointTrajectory error code and why."""

    def __init__(self, code, text):
        super().__init__(text)
        self.code = code


class FollowTrajectory:
    """The follow_joint_trajectory server's callback (self.trajectory, self.node, self.R: actions.py)."""

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
        at_once = due_at_once(times[-1], node.period) if times else None
        if at_once:
            raise Refused(R.INVALID_GOAL, at_once)
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

    def end(self, how, code, text, hold=True, joints="the joints"):
        """Ends the active goal: @p how is set_aborted or set_preempted. With @p hold every joint holds
        where it is first, and the text says whether the board has taken it or will as soon as it answers."""
        if hold:
            text = self.node.hold_said(self.node.stop_now(text), text, joints)
        r = self.control.FollowJointTrajectoryResult(error_code=code, error_string=text)
        if code != self.R.SUCCESSFUL:
            rospy.logwarn("rcb4: follow_joint_trajectory: %s", text)
        how(r, text)

    def follow(self, goal):
        """The execute callback: follows @p goal, then each newer goal that replaces it, here: the newer
        one takes over at the next cycle (SimpleActionServer would start it only 100 ms after this
        callback returns, and the joints would stand still in between)."""
        self.following.set()
        try:
            previous = []
            while goal is not None:
                goal, previous = self.follow_one(goal, previous)
        finally:
            self.following.clear()

    def follow_one(self, goal, previous):
        """Follows @p goal; @p previous: the joints of the goal it replaces, still under way. Returns the
        newer goal that replaces this one and this one's joints, or (None, [])."""
        node, R, server = self.node, self.R, self.trajectory
        try:
            idx, times, rows, stamp, path, tol, goal_time = self.check_goal(goal)
            refusal = node.move_refusal()
            if refusal:
                raise Refused(R.INVALID_GOAL, f"{refusal} (~stop_motion first)")
        except Refused as e:
            # The goal it replaced was left under way for it: those joints hold.
            self.end(server.set_aborted, e.code, f"refused, nothing moves: {e}", hold=bool(previous))
            return None, []
        names = goal.trajectory.joint_names
        if not goal.trajectory.points:  # an empty trajectory: stop, every joint holds where it is
            text = node.hold_said(node.stop_now(), "stopped")
            server.set_succeeded(R(error_code=R.SUCCESSFUL, error_string=text), text)
            return None, []
        if server.is_preempt_requested():  # cancelled before it started
            self.end(server.set_preempted, R.SUCCESSFUL, "cancelled before it started")
            return None, []
        start = numpy.radians(node.angles[idx])
        freed_at_start = node.freed[idx].copy()
        try:
            generation = node.follow(names, [(t, list(r)) for t, r in zip(times, rows)], stamp)
        except ValueError as e:  # checked above: only what changed since
            self.end(server.set_aborted, R.INVALID_GOAL, f"refused, nothing moves: {e}", hold=bool(previous))
            return None, []
        keep = [i for i in previous if i not in idx]
        if keep:  # the goal it replaces named them, this one does not: they hold where they are
            node.ask_hold(keep)
        begin = time.monotonic() + (max(0.0, stamp - rospy.get_time()) if stamp else 0.0)
        ts = numpy.concatenate(([0.0], times))
        freed_said = False
        period = 1.0 / node.rate
        while True:
            if server.is_preempt_requested():
                if server.is_new_goal_available():
                    # A newer goal: it takes over from where the joints are, at the next cycle.
                    text = "replaced by a newer goal, which takes over from where the joints are"
                    server.set_preempted(R(error_code=R.SUCCESSFUL, error_string=text), text)
                    newer = server.accept_new_goal()
                    if newer is not None:
                        return newer, idx
                    node.stop_now("the newer goal was gone")
                    return None, []
                self.end(server.set_preempted, R.SUCCESSFUL, "cancelled")
                return None, []
            if node.generation != generation:
                # Another command took over: the goal's joints it does not name hold where they
                # are (the rest of this goal does not run on unwatched); the client is told.
                why, token, failed, replacing = node.replacement(generation)
                keep = [i for i in idx if i not in replacing] if why.startswith("replaced") else []
                if keep:
                    node.drop(keep)
                    why = node.hold_said(node.ask_hold(keep), why, "the joints it does not name")
                elif token:
                    why = node.hold_said(token, why)
                how = server.set_aborted if failed else server.set_preempted
                self.end(how, R.INVALID_GOAL if failed else R.SUCCESSFUL, why, hold=False)
                return None, []
            if not node.link_ok:
                self.end(server.set_aborted, R.INVALID_GOAL, f"the board does not answer ({node.link_reason})")
                return None, []
            newly = node.freed[idx] & ~freed_at_start
            if newly.any():
                self.end(server.set_aborted, R.INVALID_GOAL,
                         f"{', '.join(n for n, f in zip(names, newly) if f)} freed (~free or ~free_joints) before "
                         "the goal was reached", joints="the joints still powered")
                return None, []
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
            server.publish_feedback(fb)
            checked = ~free & ~numpy.isnan(error)
            if 0 <= t < times[-1]:
                bad = checked & (numpy.abs(error) > path)
                if bad.any():
                    j = int(numpy.flatnonzero(bad)[0])
                    self.end(server.set_aborted, R.PATH_TOLERANCE_VIOLATED,
                             f"{names[j]} is {math.degrees(abs(error[j])):.2f} deg from its path at {t:.2f} s "
                             f"(tolerance {math.degrees(path[j]):.2f})")
                    return None, []
            elif t >= times[-1]:
                final_error = rows[-1] - actual
                # A joint whose position is not measured is not within any tolerance.
                bad = ~free & (numpy.isnan(final_error) | (numpy.abs(final_error) > tol))
                if not bad.any():
                    server.set_succeeded(R(error_code=R.SUCCESSFUL, error_string=""), "")
                    return None, []
                if t > times[-1] + goal_time:
                    j = int(numpy.flatnonzero(bad)[0])
                    far = ("has no measured position (its servo does not answer)" if math.isnan(final_error[j])
                           else f"is {math.degrees(abs(final_error[j])):.2f} deg from its goal")
                    self.end(server.set_aborted, R.GOAL_TOLERANCE_VIOLATED,
                             f"{names[j]} {far} {goal_time:.2f} s after the last point (tolerance "
                             f"{math.degrees(tol[j]):.2f})")
                    return None, []
            time.sleep(period)

    def wait_idle(self, timeout):
        """Waits (at most @p timeout s) for the trajectory goal under way to end and its result to be
        published (the goal's status changes before its result goes out: the node must not close its
        topics in between)."""
        end = time.monotonic() + timeout
        while (self.trajectory.is_active() or self.following.is_set()) and time.monotonic() < end:
            time.sleep(0.02)

    def cancel_goal(self, why):
        """Ends the trajectory goal under way (kxr_controller cancels it before servo changes)."""
        if self.trajectory.is_active():
            self.node.stop_now(why)
