# rcb4_ros: the node's trajectory engine (a mixin of Rcb4Node, node.py). The callbacks check a
# goal (every joint named once, inside its limits) and hand it over under the lock; the loop
# thread follows it: each cycle it writes the segment due (the board interpolates between the
# points) and adjusts for joints that lag; a stop asks that every joint hold where it is
# (holds.py: sent first in the next cycle, or as soon as a silent board answers again).
# SPDX-License-Identifier: BSL-1.0
import math
import time

import numpy
import rospy

import pyrcb4


def due_at_once(last, period):
    """Why a trajectory whose last point is at time_from_start @p last (s) is refused, or None:
    every point due within one output period would be a jump at the servos' full speed (ROS 1's
    joint_trajectory_controller drops the points due before its next update and refuses the goal)."""
    if last >= period:
        return None
    return (f"every point is due at once (the last at time_from_start {last:.3f} s, within one output period "
            f"of {period * 1000:.0f} ms): the joints would jump at full servo speed; give the points their times")


class Trajectories:
    """Goals and streamed targets, checked in the callbacks and followed by the loop (node.py)."""

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

    def stop_now(self, why="stopped (~stop, an empty trajectory or a cancel)", failed=False):
        """Stop: what is under way is dropped and every joint holds where it is (HOLD: the board ends its
        interpolation there), at the next cycle or as soon as a silent board answers again. Returns the
        hold request, for wait_hold."""
        with self.lock:
            self.trajectory = []
            self.stream = None
            token = self.ask_hold()
            self.replaced(why, token, failed)
            return token

    def replaced(self, why, hold=0, failed=False, replacing=()):
        """Says (under the lock) that what was under way ended early: @p why, the hold request asked with
        it (holds.py), whether a goal under way fails (aborted) rather than gives way (preempted), and
        the joints (indices) the new command names. Actions watch the generation."""
        self.generation += 1
        self.replacements.append((self.generation, why, hold, failed, set(replacing)))

    def replacement(self, generation):
        """What ended generation @p generation (why, hold, failed, replacing): the first one after it."""
        with self.lock:
            return next((r[1:] for r in self.replacements if r[0] > generation), ("replaced", 0, False, set()))

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
        at_once = due_at_once(last, self.period) if points else None
        if at_once:
            raise ValueError(at_once)
        begin = time.monotonic() + max(0.0, stamp - rospy.get_time()) if stamp else time.monotonic()
        with self.lock:  # a newer trajectory replaces what is left of the old one
            self.trajectory = [(begin + at, targets, frames) for at, targets, frames in moves]
            self.stream = None
            self.replaced("replaced by a newer trajectory or command",
                          replacing={int(i) for _, t, _ in self.trajectory for i in numpy.flatnonzero(~numpy.isnan(t))})
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
            self.replaced("replaced by a joint_command",
                          replacing={int(i) for i in numpy.flatnonzero(~numpy.isnan(targets))})
            # The joints it names leave the trajectory under way; the others go on with it.
            named = ~numpy.isnan(targets)
            rest = []
            for at, t, frames in self.trajectory:
                t = t.copy()
                t[named] = numpy.nan
                if not numpy.isnan(t).all():
                    rest.append((at, t, frames))
            self.trajectory = rest

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
                self.replaced(f"{refusal} (~stop_motion first)")
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
            self.write(stream, self.frame_count, now)  # kxr_controller's frame_count (reconfigure.py)

    def write(self, targets, frames, now):
        """Sends a move; one the board refuses (a joint with no servo on it) is dropped and said, with
        what was under way: it is not the link failing."""
        self.writing = targets  # until the board answers: one that goes silent may take it late
        try:
            self.loop.write(targets, frames=frames)
        except pyrcb4.BoardRefused as e:
            self.writing = None
            with self.lock:
                self.trajectory, self.stream = [], None
                self.replaced(f"dropped: {e}", failed=True)
            self.refuse(f"a command was dropped: {e}")
            return
        self.writing = None
        self.moved(targets, frames, now)

    def moved(self, targets, frames, now):
        """Keeps the moves just sent (for AdjustAngleVector's reference)."""
        for i in numpy.flatnonzero(~numpy.isnan(targets)):
            i = int(i)
            start = self.reference(i, now)
            if math.isnan(start):
                start = self.angles[i]
            self.moves[i] = (now, start, float(targets[i]), now + frames * self.period)
