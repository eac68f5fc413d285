# rcb4_ros: a ROS 1 node for KONDO's RCB-4 (KHR-3HV, KXR) over pyrcb4. One thread owns the line:
# callbacks only check what they are given and queue it; the loop reads the joints once per
# cycle, publishes them, and carries out what was queued. Standard messages only; SI units.
# SPDX-License-Identifier: BSL-1.0
import json
import math
import queue
import signal
import threading
import time

import numpy
import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from sensor_msgs.msg import BatteryState, JointState
from std_msgs.msg import String, UInt8
from std_srvs.srv import Trigger, TriggerResponse
from trajectory_msgs.msg import JointTrajectory

import pyrcb4
from rcb4_ros import actions


class Rcb4Node:
    """The node: parameters ~device (empty: the in-process virtual board), ~baud, ~robot, ~rate
    (default: one cycle per board output period), ~joint_prefix, ~timeout."""

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
        self.lock = threading.Lock()   # guards the trajectory and the streamed target
        self.trajectory = []           # [(due monotonic time, targets in degrees, frames)], next first
        self.stream = None             # (targets in degrees, received) from ~joint_command
        self.freed = numpy.zeros(len(self.names), dtype=bool)  # freed joints: no command powers them again
        self.read_freed()
        self.halt = False              # stop: every joint under way holds where it is, at the next cycle
        self.generation = 0            # counts what replaced the trajectory (a new one, a stop): actions watch it
        self.replaced_by = ""          # why the last trajectory ended early
        self.replacing = set()         # the joints (indices) the command that replaced it names
        self.moves = {}                # joint index -> (t0, from, to, t1) degrees: the move the board makes now
        self.refused_at = {}           # refusal text -> when it was last logged (repeats once a second)
        self.link_ok, self.link_reason = True, ""
        self.cycles, self.errors, self.timeouts = 0, 0, 0
        self.rate_window = (time.monotonic(), 0)
        self.cycles_per_s = 0.0
        self.last_motion = None
        self.states = rospy.Publisher("joint_states", JointState, queue_size=10)
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
        rospy.Service("~stop", Trigger, lambda r: self.trigger("halt", None))
        rospy.Service("~resume_motion", Trigger, lambda r: self.trigger("resume", None))
        rospy.loginfo("rcb4: %s, %d joints, %g Hz (output period %.0f ms)", self.where, len(self.names),
                      self.rate, self.period * 1000)
        self.describe_robot()
        self.actions = actions.start(self)

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

    # --- callbacks: check, queue, never touch the line ----------------------------------------------
    def degrees_of(self, names, positions, what):
        """Degrees for every joint (NaN: not given), or a refusal naming the joint and the limit."""
        if len(names) != len(positions):
            raise ValueError(f"{what}: {len(names)} names but {len(positions)} positions")
        targets = numpy.full(len(self.names), numpy.nan)
        for name, rad in zip(names, positions):
            i = self.index.get(name)
            if i is None:
                follows = next((self.prefix + self.names[j] for m, j, _, _ in self.mimics if m == name), None)
                if follows:
                    raise ValueError(f"{what}: {name} follows {follows} (mimic: no servo of its own): command {follows}")
                raise ValueError(f"{what}: no joint is called '{name}'")
            if not math.isnan(targets[i]):
                raise ValueError(f"{what}: {name} is given twice")
            if not math.isfinite(rad):
                raise ValueError(f"{what}: {name}: {rad} is not a position")
            deg = math.degrees(rad)
            lower, upper = self.limits[self.names[i]]
            if not (lower - 1e-6 <= deg <= upper + 1e-6):
                raise ValueError(f"{what}: {name}: {deg:.2f} degrees is beyond its "
                                 f"{'lower' if deg < lower else 'upper'} limit {lower if deg < lower else upper:g}")
            targets[i] = deg
        return targets

    def refuse(self, text):
        """One line per refused command; the same refusal again within a second is not repeated."""
        now = time.monotonic()
        if now - self.refused_at.get(text, -10.0) >= 1.0:
            rospy.logerr("rcb4: %s", text)
            self.refused_at[text] = now
            if len(self.refused_at) > 100:  # forget the old ones
                self.refused_at = {k: v for k, v in self.refused_at.items() if now - v < 1.0}

    def stop_now(self, why="stopped (~stop, an empty trajectory or a cancel): the joints hold where they are"):
        """Stop: what is under way is dropped and every joint that moves holds where it is now."""
        with self.lock:
            self.trajectory = []
            self.stream = None
            self.halt = True
            self.generation += 1
            self.replaced_by = why

    def move_refusal(self):
        """Why a move would fight a ROM motion now (the one rule, through pyrcb4), or None."""
        return pyrcb4.move_refusal(self.last_motion or {})

    def follow(self, names, points, stamp=0.0):
        """Replaces what is under way by the trajectory @p points [(time_from_start s, positions rad)]
        of joints @p names, from @p stamp (ROS time; 0: now); ValueError when a point does not check.
        Returns its generation (it changes when something else replaces or stops it)."""
        moves, last = [], 0.0
        before = self.angles.copy()  # where the first segment starts: the joints as last read
        for k, (t, positions) in enumerate(points):
            targets = self.degrees_of(names, positions, f"point {k}")
            if t < last:
                raise ValueError(f"point {k}: its time goes back ({t:.3f} s after {last:.3f} s)")
            moves += self.segment(last, t, before, targets)
            before, last = targets, t
        begin = time.monotonic() + max(0.0, stamp - rospy.get_time()) if stamp else time.monotonic()
        with self.lock:  # a newer trajectory replaces what is left of the old one
            self.trajectory = [(begin + at, targets, frames) for at, targets, frames in moves]
            self.stream = None
            self.generation += 1
            self.replaced_by = "replaced by a newer trajectory or command"
            self.replacing = {i for _, t, _ in self.trajectory for i in numpy.flatnonzero(~numpy.isnan(t))}
            return self.generation

    def on_trajectory(self, msg):
        if not msg.points:  # an empty trajectory: stop, every joint holds where it is now
            self.stop_now()
            return
        stamp = msg.header.stamp.to_sec() if msg.header.stamp and not msg.header.stamp.is_zero() else 0.0
        try:
            self.follow(msg.joint_names, [(p.time_from_start.to_sec(), p.positions) for p in msg.points], stamp)
        except ValueError as e:
            self.refuse(f"trajectory refused, nothing moves: {e}")

    def segment(self, t0, t1, before, targets):
        """The moves that take the joints from @p before (degrees at t0) to @p targets at t1:
        [(start time, targets, frames)]. A move lasts at most 255 board periods, so a longer segment
        becomes equal moves along the same straight line, as the board interpolates it (a joint
        whose start is unknown, NaN, moves in the last of them only)."""
        frames = round((t1 - t0) / self.period)
        if t1 <= t0:
            return [(t0, targets, 0)]
        pieces = max(1, math.ceil(frames / 255))
        moves = []
        for j in range(1, pieces + 1):
            at = targets if j == pieces else before + (targets - before) * (j / pieces)
            n = max(1, round(frames * j / pieces) - round(frames * (j - 1) / pieces))
            moves.append((t0 + (t1 - t0) * (j - 1) / pieces, at, n))
        return moves

    def on_joint_command(self, msg):
        try:
            targets = self.degrees_of(msg.name, msg.position, "joint_command")
        except ValueError as e:
            self.refuse(f"joint_command refused, nothing moves: {e}")
            return
        with self.lock:
            self.stream = targets
            self.generation += 1
            self.replaced_by = "replaced by a joint_command"
            self.replacing = set(int(i) for i in numpy.flatnonzero(~numpy.isnan(targets)))
            # The joints it names leave the trajectory under way; the others go on with it.
            named = ~numpy.isnan(targets)
            rest = []
            for at, t, frames in self.trajectory:
                t = t.copy()
                t[named] = numpy.nan
                if not numpy.isnan(t).all():
                    rest.append((at, t, frames))
            self.trajectory = rest

    def some_joints(self, what, names):
        """~free_joints / ~hold_joints: an empty message names nothing (~free and ~hold are for all)."""
        if not names.replace(",", " ").split():
            self.refuse(f"~{what}_joints: the message names no joint, so nothing was done (~{what} is for every joint)")
            return
        self.queue(what, names)

    def queue(self, what, argument, reply=None):
        self.requests.put((what, argument, reply))

    def ask(self, what, argument, timeout=2.0):
        """Has the loop thread do @p what and waits for it: (ok, message)."""
        done = threading.Event()
        result = {}
        self.queue(what, argument, (done, result))
        if not done.wait(timeout):
            result["abandoned"] = True  # not carried out later, when nobody waits for it any more
            return False, f"the board did not answer in {timeout:g} s: nothing was done"
        return result.get("ok", False), result.get("message", "")

    def trigger(self, what, argument):
        return TriggerResponse(*self.ask(what, argument))

    # --- the loop: the only thread on the line ------------------------------------------------------
    def carry_out(self):
        while True:
            try:
                what, argument, reply = self.requests.get_nowait()
            except queue.Empty:
                return
            ok, message = True, ""
            if reply and reply[1].get("abandoned"):
                rospy.logwarn("rcb4: %s: dropped, its caller gave up waiting (the board did not answer)", what)
                continue
            try:
                if what == "hold_some":
                    names = [self.names[i] for i in argument if not self.freed[i]]
                    if names:
                        self.board.hold(*names)
                    for i in argument:
                        self.moves.pop(i, None)
                    message = f"held {len(names)} joints"
                elif what in ("free", "hold"):
                    names = [n[len(self.prefix):] if n.startswith(self.prefix) else n
                             for n in (argument or "").replace(",", " ").split()]
                    done = (self.board.free if what == "free" else self.board.hold)(*names)
                    for n in done:
                        self.freed[self.names.index(n)] = what == "free"
                        self.moves.pop(self.names.index(n), None)
                    # What was under way for a freed joint is dropped (this thread writes nothing in
                    # between): its next point would power the joint again.
                    dropped = self.drop([self.names.index(n) for n in done]) if what == "free" else []
                    message = f"{what}: {len(done)} joints"
                    if what == "free" and dropped:
                        message += f" (what was under way for {', '.join(dropped)} is dropped)"
                        rospy.logwarn("rcb4: %s", message)
                elif what == "halt":
                    self.stop_now()
                    message = "stopped: every joint holds where it is"
                elif what == "resume":
                    self.board.resume_motion()
                    message = "the ROM program runs again"
                elif what == "play":
                    self.board.play_motion(int(argument), wait=False)
                    message = f"playing motion {argument}"
                elif what == "stop":
                    self.board.stop_motion()
                    message = "motion stopped"
                elif what == "stretch":
                    value, names = argument
                    done = self.board.stretch(value, *[self.unprefixed(n) for n in names])
                    message = f"stretch {value}: {len(done)} joints"
                elif what == "adjust":
                    message = self.adjust(argument)
            except pyrcb4.Error as e:
                ok, message = False, str(e) if str(e).startswith(what + ":") else f"{what}: {e}"
                rospy.logerr("rcb4: %s", message)
            if reply:
                reply[1].update(ok=ok, message=message)
                reply[0].set()

    def read_freed(self):
        """Which joints are free on the board now (target FREE): at start and after a reconnect the
        node knows nothing else of them."""
        try:
            servos = self.board.servos()
        except pyrcb4.Error as e:
            rospy.logwarn("rcb4: the servos' states could not be read (%s): joints taken as held", e)
            self.freed[:] = False
            return
        targets = {v["joint"]: v["target"] for v in servos.values()}
        for i, n in enumerate(self.names):
            self.freed[i] = targets.get(n) == 0x8000
        if self.freed.any():
            rospy.loginfo("rcb4: free on the board: %s", ", ".join(self.prefix + n for n, f in zip(self.names, self.freed) if f))

    def unprefixed(self, name):
        return name[len(self.prefix):] if self.prefix and name.startswith(self.prefix) else name

    def reference(self, i, now):
        """Where joint @p i is meant to be at @p now, as the board interpolates its move (NaN: unknown)."""
        m = self.moves.get(i)
        if m is None:
            return math.nan
        t0, a, b, t1 = m
        return b if now >= t1 or t1 <= t0 else a + (b - a) * (now - t0) / (t1 - t0)

    def adjust(self, thresholds):
        """kxr_controller's AdjustAngleVector: a held joint further than its threshold (degrees) from
        where it is meant to be now holds where it is."""
        now = time.monotonic()
        over = []
        for name, limit in thresholds:
            i = self.index[name]
            error = abs(self.reference(i, now) - self.angles[i])
            if not self.freed[i] and error > limit:  # NaN (no move known, not measured) is not over
                over.append((i, error, limit))
        if not over:
            return "no joint is further from its reference than its threshold"
        self.board.hold(*[self.names[i] for i, _, _ in over])
        for i, _, _ in over:
            self.moves.pop(i, None)
        return "held " + ", ".join(f"{self.prefix + self.names[i]} ({e:.1f} deg > {lim:g})" for i, e, lim in over)

    def drop(self, indices):
        """Drops what is under way (trajectory, stream) for the joints at @p indices; their names."""
        idx = list(indices)
        with self.lock:
            busy = set()
            rest = []
            for at, t, frames in self.trajectory:
                t = t.copy()
                busy.update(i for i in idx if not math.isnan(t[i]))
                t[idx] = numpy.nan
                if not numpy.isnan(t).all():
                    rest.append((at, t, frames))
            self.trajectory = rest
            if self.stream is not None:
                busy.update(i for i in idx if not math.isnan(self.stream[i]))
                self.stream = self.stream.copy()
                self.stream[idx] = numpy.nan
                if numpy.isnan(self.stream).all():
                    self.stream = None
        return [self.prefix + self.names[i] for i in sorted(busy)]

    def halt_now(self):
        """Every joint that is held holds where it is now (HOLD: the board stops its interpolation there)."""
        held = [n for n, f in zip(self.names, self.freed) if not f]
        if held:
            self.board.hold(*held)
        self.moves.clear()

    def without_freed(self, targets, what):
        """@p targets with the freed joints left out (a position would power them again), said once."""
        named = ~numpy.isnan(targets) & self.freed
        if named.any():
            self.refuse(f"{what}: {', '.join(self.prefix + self.names[i] for i in numpy.flatnonzero(named))} "
                        f"{'is' if named.sum() == 1 else 'are'} free: left out (~hold or ~hold_joints first)")
            targets = targets.copy()
            targets[named] = numpy.nan
        return targets

    def write_due(self):
        now = time.monotonic()
        with self.lock:
            halt, self.halt = self.halt, False
        if halt:
            self.halt_now()
            return
        with self.lock:
            due = None
            while self.trajectory and self.trajectory[0][0] <= now:
                due = self.trajectory.pop(0)
            stream, self.stream = self.stream, None
        motion = self.last_motion or {}
        # The one rule for a move during a ROM motion (rcb4/robot/services/moves.hpp, through pyrcb4).
        refusal = pyrcb4.move_refusal(motion) if (due or stream is not None) else None
        if refusal:
            self.refuse(f"{refusal} (~stop_motion first)")
            with self.lock:
                self.trajectory = []
                self.generation += 1
                self.replaced_by = f"{refusal} (~stop_motion first)"
            return
        if due:
            due = (due[0], self.without_freed(due[1], "trajectory"), due[2])
            if numpy.isnan(due[1]).all():
                due = None
        if stream is not None:
            stream = self.without_freed(stream, "joint_command")
            if numpy.isnan(stream).all():
                stream = None
        if due:
            # Points due in the same cycle (denser than the rate, or a late cycle): the last one, over
            # what is left of its time, so the joints do not hurry and then wait.
            at, targets, frames = due
            if frames > 0:
                frames = max(1, round((at + frames * self.period - now) / self.period))
            self.write(targets, frames, now)
        elif stream is not None:
            self.write(stream, max(1, round(1.0 / self.rate / self.period)), now)

    def write(self, targets, frames, now):
        """Sends a move; one the board refuses (a joint with no servo on it) is dropped and said, with
        what was under way: it is not the link failing."""
        try:
            self.loop.write(targets, frames=frames)
        except pyrcb4.BoardRefused as e:
            with self.lock:
                self.trajectory, self.stream = [], None
                self.generation += 1
                self.replaced_by = f"dropped: {e}"
            self.refuse(f"a command was dropped: {e}")
            return
        self.moved(targets, frames, now)

    def moved(self, targets, frames, now):
        """Keeps the moves just sent (for AdjustAngleVector's reference)."""
        for i in numpy.flatnonzero(~numpy.isnan(targets)):
            i = int(i)
            start = self.reference(i, now)
            if math.isnan(start):
                start = self.angles[i]
            self.moves[i] = (now, start, float(targets[i]), now + frames * self.period)

    def cycle(self):
        self.carry_out()
        self.write_due()
        self.loop.read(out=self.angles)
        stamp = rospy.Time.now()
        msg = JointState()
        msg.header.stamp = stamp
        for name, deg in zip(self.names, self.angles):
            if not math.isnan(deg):  # a servo that does not answer is left out, never made up
                msg.name.append(self.prefix + name)
                msg.position.append(math.radians(deg))
        for name, j, k, off in self.mimics:
            if not math.isnan(self.angles[j]):
                msg.name.append(name)
                msg.position.append(math.radians(k * self.angles[j] + off))
        self.states.publish(msg)
        self.cycles += 1

    def slow_things(self):
        try:
            st = self.board.motion_status()
        except pyrcb4.BoardRefused as e:  # a board without an HTH4 program: no motions, the link is fine
            st = {"running": False, "motion": None, "error": str(e)}
        if st != self.last_motion:
            self.motion_pub.publish(String(json.dumps(st)))
            self.last_motion = st
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
        self.read_freed()  # the board that answers now may not be the one whose joints were freed
        self.reopen_at = None
        rospy.loginfo("rcb4: %s opened again", self.device)

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
                    if self.link_ok:
                        rospy.logerr("rcb4: %s", e)
                    self.link_ok, self.link_reason = False, str(e)
                    self.angles[:] = numpy.nan
                    # What is under way (or comes in) while the board is silent is dropped, and
                    # said: it must not run late, all at once, when the board answers again.
                    with self.lock:
                        pending = bool(self.trajectory) or self.stream is not None
                        self.trajectory, self.stream = [], None
                        if pending:
                            self.generation += 1
                            self.replaced_by = f"dropped: the board does not answer ({e})"
                    if pending:
                        self.refuse(f"a command was dropped: the board does not answer ({e})")
                    self.drop_requests(str(e))
                if self.released:
                    self.drop_requests(self.link_reason)
                if self.reopen_at is not None and time.monotonic() >= self.reopen_at:
                    self.reopen()
                if time.monotonic() - last_diag >= 1.0:
                    self.diagnostics()
                    last_diag = time.monotonic()
                next_cycle = max(next_cycle + period, time.monotonic() - period)
                delay = next_cycle - time.monotonic()
                while delay > 0 and not (rospy.is_shutdown() or self.stopping.is_set()):
                    time.sleep(min(delay, 0.05))  # wakes for shutdown within 50 ms
                    delay = next_cycle - time.monotonic()
        finally:
            # An action goal under way ends (aborted, said to its client) and every joint holds
            # where it is before the board is let go: nothing runs on after the node.
            self.stop_now("the node stopped (SIGINT/SIGTERM): the joints hold where they are")
            if not self.released:
                try:
                    self.halt_now()
                except pyrcb4.Error:
                    pass
            if self.actions:
                self.actions.wait_idle(1.0)
            if not self.released:
                self.board.close()

    def drop_requests(self, why):
        """What was asked while the board does not answer is dropped, answered and logged: it must not
        run later, when a board answers again."""
        while True:
            try:
                what, _, reply = self.requests.get_nowait()
            except queue.Empty:
                return
            rospy.logwarn("rcb4: %s: dropped, the board does not answer (%s)", what, why)
            if reply:
                reply[1].update(ok=False, message=f"{what}: the board does not answer ({why}): nothing was done")
                reply[0].set()


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
    try:
        node.run()
    finally:
        rospy.signal_shutdown("stopped")
