# rcb4_ros: a ROS 1 node for KONDO's RCB-4 (KHR-3HV, KXR) over pyrcb4. One thread owns the line:
# callbacks only check what they are given and queue it; the loop sends the holds asked first
# (holds.py), reads the joints once per cycle, publishes them, and carries out what was queued.
# Standard messages only; SI units.
# SPDX-License-Identifier: BSL-1.0
import collections
import json
import logging
import math
import os
import queue
import signal
import sys
import threading
import time

import numpy
import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from sensor_msgs.msg import BatteryState, JointState
from std_msgs.msg import String, UInt8
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory

import pyrcb4
from rcb4_ros import actions, reconfigure
from rcb4_ros.holds import Holds
from rcb4_ros.requests import Requests
from rcb4_ros.states import States
from rcb4_ros.trajectory import Trajectories

class Rcb4Node(Trajectories, Requests, Holds, States):
    """The node: parameters ~device (empty: the in-process virtual board), ~baud, ~robot, ~rate
    (default: one cycle per board output period), ~joint_prefix, ~timeout, ~frame_count (the frames
    of each ~joint_command target's move; default: one cycle's worth)."""

    def __init__(self):
        device = rospy.get_param("~device", None)
        if device is not None and not str(device).strip():
            # As the tool refuses --device "": an empty device is a mistake, not a wish for a simulation.
            raise ValueError("~device is set but empty (leave it out for the in-process virtual board)")
        self.device = str(device) if device is not None else None
        self.baud = int(rospy.get_param("~baud", 0)) or None
        self.robot = rospy.get_param("~robot", "khr-3hv")
        try:
            self.timeout = float(rospy.get_param("~timeout", 0.1))
        except (TypeError, ValueError):
            raise ValueError(f"~timeout: {rospy.get_param('~timeout')!r} is not a number of seconds") from None
        if self.device is None:
            rospy.logwarn("rcb4: no ~device given: the in-process virtual board, a simulation, not a robot")
        self.prefix = rospy.get_param("~joint_prefix", "")
        self.board = pyrcb4.Board(self.device, baud=self.baud, robot=self.robot, timeout=self.timeout)
        self.period = self.board.period
        try:
            self.rate = float(rospy.get_param("~rate", 1.0 / self.period))
        except (TypeError, ValueError):
            raise ValueError(f"~rate: {rospy.get_param('~rate')!r} is not a number of Hz") from None
        if not 0 < self.rate <= 1000:
            raise ValueError(f"~rate: {self.rate:g} Hz: it must be above 0 and at most 1000")
        # The frames of the move each ~joint_command target becomes (kxr_controller's frame_count;
        # dynamic_reconfigure changes it: reconfigure.py): by default one cycle's worth.
        self.frame_count = reconfigure.frame_count_of(
            rospy.get_param("~frame_count", min(255, max(1, round(1.0 / self.rate / self.period)))))
        self.reopen_at = None  # when the device went away: the next time to open it again
        self.released = False  # the dead device closed, a new one not yet open
        self.where = self.board.where
        self.stopping = threading.Event()  # SIGINT/SIGTERM: the loop ends, the board is let go
        self.names = self.board.joint_names
        self.limits = self.board.joint_limits
        self.index = {self.prefix + n: i for i, n in enumerate(self.names)}
        # Joints on another's servo (the profile's mimic:), in joint_states as URDF's mimic says.
        self.mimics = [(self.prefix + n, self.names.index(j), k, off)
                       for n, (j, k, off) in self.board.mimic_joints.items()]
        self.loop = self.board.control_loop()
        self.angles = numpy.full(len(self.names), numpy.nan)
        self.requests = queue.Queue()  # (what, argument, reply) for the loop thread
        self.lock = threading.RLock()  # guards the trajectory, the streamed target and the holds asked
        self.trajectory = []           # [(due monotonic time, targets in degrees, frames)], next first
        self.stream = None             # (targets in degrees, received) from ~joint_command
        self.freed = numpy.zeros(len(self.names), dtype=bool)  # freed joints: no command powers them again
        self.read_freed()
        self.generation = 0            # counts what replaced the trajectory (a new one, a stop): actions watch it
        # What ended each trajectory early, by generation (replaced()): why, the hold asked with it,
        # whether a goal under way fails, and the joints (indices) the command that replaced it names.
        self.replacements = collections.deque(maxlen=32)
        self.moves = {}                # joint index -> (t0, from, to, t1) degrees: the move the board makes now
        self.init_holds()              # holds asked and not yet taken by the board (holds.py)
        self.refused_at = {}           # refusal text -> when it was last logged (repeats once a second)
        self.link_ok, self.link_reason = True, ""
        self.cycles, self.errors, self.timeouts = 0, 0, 0
        self.rate_window = (time.monotonic(), 0)
        self.cycles_per_s = 0.0
        self.last_motion = None
        self.init_states()  # joint_states and the other readings (states.py)
        self.motion_pub = rospy.Publisher("~motion", String, queue_size=2, latch=True)
        self.sensors_pub = rospy.Publisher("~sensors", String, queue_size=2)
        self.battery_pub = rospy.Publisher("~battery", BatteryState, queue_size=2)
        self.diag_pub = rospy.Publisher("diagnostics", DiagnosticArray, queue_size=2)
        rospy.Subscriber("~command", JointTrajectory, self.on_trajectory, queue_size=2)
        rospy.Subscriber("~joint_command", JointState, self.on_joint_command, queue_size=1)
        rospy.Subscriber("~free_joints", String, lambda m: self.some_joints("free", m.data), queue_size=5)
        rospy.Subscriber("~hold_joints", String, lambda m: self.some_joints("hold", m.data), queue_size=5)
        rospy.Subscriber("~play_motion", UInt8, lambda m: self.queue("play", m.data), queue_size=5)
        rospy.Service("~free", Trigger, lambda r: self.trigger("free", ""))
        rospy.Service("~hold", Trigger, lambda r: self.trigger("hold", ""))
        rospy.Service("~stop_motion", Trigger, lambda r: self.trigger("stop", None))
        rospy.Service("~stop", Trigger, lambda r: self.stop_service())
        rospy.Service("~resume_motion", Trigger, lambda r: self.trigger("resume", None))
        rospy.loginfo("rcb4: %s, %d joints, %g Hz (output period %.0f ms)", self.where, len(self.names),
                      self.rate, self.period * 1000)
        self.describe_robot()
        self.actions = actions.start(self)
        self.reconfigure = reconfigure.start(self)

    def describe_robot(self):
        """robot_description from the profile's kinematics (rcb4 urdf), unless one is set already."""
        if not rospy.get_param("~robot_description", True):
            return
        if rospy.has_param("robot_description"):
            rospy.loginfo("rcb4: robot_description is set already: left as it is")
            return
        try:
            rospy.set_param("robot_description", self.board.urdf(self.prefix))
        except pyrcb4.UsageError as e:
            rospy.logwarn("rcb4: no robot_description: %s", e)

    # --- callbacks: check, queue, never touch the line (trajectory.py, requests.py) ----------------
    def refuse(self, text):
        """One line per refused command; the same refusal again within a second is not repeated."""
        now = time.monotonic()
        if now - self.refused_at.get(text, -10.0) >= 1.0:
            rospy.logerr("rcb4: %s", text)
            self.refused_at[text] = now
            if len(self.refused_at) > 100:  # forget the old ones
                self.refused_at = {k: v for k, v in self.refused_at.items() if now - v < 1.0}

    # --- the loop: the only thread on the line ------------------------------------------------------
    def unprefixed(self, name):
        return name[len(self.prefix):] if self.prefix and name.startswith(self.prefix) else name

    def cycle(self):
        self.send_holds()  # first: a stop, cancel or abort asked while the board was silent, as soon as it answers
        if self.link_ok:   # a board that was silent is read first: nothing is asked of it before it answers
            self.carry_out()
            self.write_due()
        self.loop.read(out=self.angles)
        self.publish_states(rospy.Time.now(), time.monotonic())  # a servo that does not answer is left out
        self.cycles += 1

    def slow_things(self):
        try:
            st = self.board.motion_status()
        except pyrcb4.BoardRefused as e:  # a board without an HTH4 program: no motions, the link is fine
            st = {"running": False, "motion": None, "error": str(e)}
        if st != self.last_motion:
            self.motion_pub.publish(String(json.dumps(st)))
            self.last_motion = st
        if pyrcb4.move_refusal(st):  # a ROM motion moves the servos: the node's last moves say nothing of them
            self.moves.clear()
        s = self.board.sensors()
        self.sensors_pub.publish(String(json.dumps(
            {"battery_volts": s["battery_volts"], "ad_volts": s["ad_volts"], "buttons": s["button_names"]})))
        b = BatteryState()
        b.header.stamp = rospy.Time.now()
        b.voltage = s["battery_volts"]
        nan = float("nan")  # what the board does not measure (the message says NaN, not 0)
        b.temperature = b.current = b.charge = b.capacity = b.design_capacity = b.percentage = nan
        b.power_supply_status = BatteryState.POWER_SUPPLY_STATUS_UNKNOWN
        b.power_supply_health = BatteryState.POWER_SUPPLY_HEALTH_UNKNOWN
        b.power_supply_technology = BatteryState.POWER_SUPPLY_TECHNOLOGY_UNKNOWN
        b.present = True
        self.battery_pub.publish(b)

    def reopen(self):
        self.reopen_at = time.monotonic() + 1.0
        if not self.released:
            # Let the dead device go first: while it is held open, the kernel cannot give its name
            # (/dev/ttyUSB0, /dev/pts/N) to the adapter plugged in again.
            self.board.close()
            self.released = True
        try:
            board = pyrcb4.Board(self.device, baud=self.baud, robot=self.robot, timeout=self.timeout)
        except pyrcb4.Error as e:
            self.link_reason = f"{self.device} cannot be opened again: {e}"
            return
        self.board, self.released, self.where = board, False, board.where
        self.loop = self.board.control_loop()
        self.moves.clear()  # what the node sent went to the board that went away
        self.read_freed()  # the board that answers now may not be the one whose joints were freed
        self.reopen_at = None
        rospy.loginfo("rcb4: %s opened again", self.device)

    def drop_asked(self, why, hold=0):
        """Drops what is under way and what was asked, said to whoever waits (an action goal, a service
        caller) and logged; @p hold: the hold asked for the joints the board may still be moving."""
        with self.lock:
            pending = bool(self.trajectory) or self.stream is not None
            self.trajectory, self.stream = [], None
            if pending or hold:
                self.replaced(f"{why}: what was under way is dropped", hold, failed=True)
        if pending:
            self.refuse(f"a command was dropped: {why}")
        self.drop_requests(why)

    def diagnostics(self):
        now = time.monotonic()
        since, count = self.rate_window
        if now - since >= 1.0:
            self.cycles_per_s = (self.cycles - count) / (now - since)
            self.rate_window = (now, self.cycles)
        st = DiagnosticStatus()
        st.name = "rcb4: link"
        st.hardware_id = self.where
        missing = [self.prefix + n for n, d in zip(self.names, self.angles) if math.isnan(d)]
        if not self.link_ok:
            st.level, st.message = DiagnosticStatus.ERROR, f"the board does not answer: {self.link_reason}"
        elif missing:
            st.level, st.message = DiagnosticStatus.WARN, f"{len(missing)} joints do not answer"
        else:
            st.level, st.message = DiagnosticStatus.OK, "all joints answer"
        st.values = [KeyValue("cycles_per_s", f"{self.cycles_per_s:.1f}"), KeyValue("rate", f"{self.rate:g}"),
                     KeyValue("errors", str(self.errors)), KeyValue("timeouts", str(self.timeouts)),
                     KeyValue("missing_joints", " ".join(missing))]
        a = DiagnosticArray()
        a.header.stamp = rospy.Time.now()
        a.status = [st]
        self.diag_pub.publish(a)

    def run(self):
        period = 1.0 / self.rate
        next_cycle = time.monotonic()
        last_slow = last_diag = 0.0
        try:
            while not (rospy.is_shutdown() or self.stopping.is_set()):
                try:
                    if self.released:
                        raise pyrcb4.DeviceError(self.link_reason)
                    self.cycle()
                    if not self.link_ok:
                        rospy.loginfo("rcb4: the board answers again")
                        self.drop_asked(f"asked while the board did not answer ({self.link_reason})")
                    self.link_ok = True
                    if time.monotonic() - last_slow >= 0.2:  # 5 Hz, on a grid: no drift
                        self.slow_things()
                        last_slow = max(last_slow + 0.2, time.monotonic() - 0.2)
                except pyrcb4.Error as e:
                    # No joint_states until it answers again: nothing stale is published. A device
                    # that went away (unplugged) is opened again once a second, by its path.
                    if isinstance(e, pyrcb4.DeviceError) and self.device and self.reopen_at is None:
                        self.reopen_at = time.monotonic() + 1.0
                    self.errors += 1
                    if isinstance(e, pyrcb4.Timeout):
                        self.timeouts += 1
                    went = self.link_ok
                    if went:
                        rospy.logerr("rcb4: %s", e)
                    self.link_ok, self.link_reason = False, str(e)
                    self.angles[:] = numpy.nan
                    # What the board may still be moving holds as soon as it answers again (it must
                    # not run on to the end of its segment); what is under way (or comes in) while it
                    # is silent is dropped, and said: it must not run late, all at once, either.
                    self.drop_asked(f"the board does not answer ({e})", self.hold_under_way() if went else 0)
                    self.writing = None
                    self.holds_not_sent()
                if self.released:
                    self.drop_requests(f"the board does not answer ({self.link_reason})")
                if self.reopen_at is not None and time.monotonic() >= self.reopen_at:
                    self.reopen()
                if time.monotonic() - last_diag >= 1.0:
                    self.diagnostics()
                    last_diag = time.monotonic()
                next_cycle = max(next_cycle + period, time.monotonic() - period)
                delay = next_cycle - time.monotonic()
                if delay > 0:
                    self.stopping.wait(delay)  # SIGINT, SIGTERM or rospy's shutdown wake it at once
        finally:
            # An action goal under way ends (aborted, said to its client) and every joint holds
            # where it is before the board is let go: nothing runs on after the node.
            self.stop_now("the node stopped (SIGINT/SIGTERM)", failed=True)
            if not self.released:
                try:
                    self.send_holds()
                except pyrcb4.Error as e:
                    rospy.logerr("rcb4: the joints could not be held before the node stops (%s): the board runs "
                                 "what it was moving to its end", e)
                    self.holds_not_sent()
            if self.actions:
                self.actions.wait_idle(1.0)
                self.actions.quiet()
            if not self.released:
                self.board.close()

def shut_down_ros(timeout=1.0):
    """rospy.signal_shutdown without its idle waits: returns once rospy's shutdown hooks have run (the
    node is unregistered from the master, its TCPROS and XML-RPC servers closed), at most @p timeout s.
    After its hooks, rospy joins its registration thread, which looks for shutdown only every 0.5 s,
    then sleeps 0.1 s more (rospy/core.py, signal_shutdown): 0.6 s of the node's exit for nothing.
    That goes on in a daemon thread, which the interpreter does not wait for."""
    hooks_done = threading.Event()
    # Hooks run in the order they were added: this one after rospy's own (added by init_node). If
    # rospy is shut down already, it runs at once.
    rospy.core.add_shutdown_hook(lambda reason: hooks_done.set())
    threading.Thread(target=rospy.signal_shutdown, args=("stopped",), name="rospy shutdown", daemon=True).start()
    return hooks_done.wait(timeout)


def main():
    # The node's own signal handling: the loop ends at once and lets the board go, then rospy shuts
    # down (its own SIGINT path takes seconds).
    rospy.init_node("rcb4", disable_signals=True)
    try:
        node = Rcb4Node()
    except (pyrcb4.Error, ValueError) as e:
        rospy.logfatal("rcb4: %s", e)
        rospy.signal_shutdown("cannot start")
        raise SystemExit(1)
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: node.stopping.set())
    rospy.on_shutdown(node.stopping.set)  # rospy shut down from outside (rosnode kill): the loop ends at once too
    try:
        node.run()
    except BaseException:
        shut_down_ros()
        raise
    shut_down_ros()
    # All is done: the joints held, the board let go, the node unregistered from the master. The
    # interpreter's teardown of rospy's modules and threads would take 50-70 ms of CPU more, 0.3-0.6 s
    # on a loaded 2-core machine (most of the node's exit there): the node ends without it, once its
    # log is flushed.
    logging.shutdown()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(0)
