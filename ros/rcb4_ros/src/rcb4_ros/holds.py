# rcb4_ros: holds that must reach the board (a mixin of Rcb4Node, node.py). A stop, a cancel, an
# abort, or a newer command taking over asks that joints hold where they are; the board falling
# silent with joints under way asks it too. What is asked stays pending until the board has taken
# it: the loop sends it first in every cycle, so when a silent board answers again the joints stop
# there and then, instead of running on to the end of the segment the board was interpolating.
# Whoever asked can wait for the outcome and tell the truth about it.
# SPDX-License-Identifier: BSL-1.0
import threading
import time

import numpy

import pyrcb4


class Holds:
    """Pending holds (joint index -> the number of the request that asked for it), sent by the loop."""

    def init_holds(self):
        self.to_hold = {}
        self.holds_asked = 0    # requests so far
        self.holds_done = 0     # every request up to this one has reached the board
        self.holds_failed = 0   # a request up to this one met a board that did not answer
        self.held = threading.Condition(self.lock)
        self.writing = None     # the targets of a write under way (the board may take it late)

    def ask_hold(self, indices=None):
        """Asks that the joints at @p indices (None: every joint) hold where they are; the request's
        number, for wait_hold (0: nothing asked)."""
        indices = range(len(self.names)) if indices is None else [int(i) for i in indices]
        with self.lock:
            if not indices:
                return 0
            self.holds_asked += 1
            for i in indices:
                self.to_hold[i] = self.holds_asked
            return self.holds_asked

    def send_holds(self):
        """The loop, first in every cycle: HOLD for every joint asked to hold (a freed one stays
        free: it is not moving). pyrcb4.Error leaves them pending, for the next cycle."""
        with self.lock:
            pending, asked = dict(self.to_hold), self.holds_asked
        if not pending:
            return
        names = [self.names[i] for i in sorted(pending) if not self.freed[i]]
        if names:
            try:
                self.board.hold(*names)
            except pyrcb4.BoardRefused as e:  # it answered: joints with no servo on it do not move anyway
                self.refuse(f"hold {', '.join(self.prefix + n for n in names)}: {e}")
        with self.lock:
            for i, n in pending.items():
                if self.to_hold.get(i) == n:
                    del self.to_hold[i]
                self.moves.pop(i, None)
            self.holds_done = max(self.holds_done, asked)
            self.held.notify_all()

    def holds_not_sent(self):
        """The loop, when the board did not answer: whoever waits on a pending hold is told."""
        with self.lock:
            if self.to_hold:
                self.holds_failed = self.holds_asked
                self.held.notify_all()

    def hold_under_way(self):
        """The board stopped answering: the joints it may still be moving (a move not over yet, or a
        write it may have taken without answering) are to hold as soon as it answers again; the hold
        request (0: none)."""
        now = time.monotonic()
        moving = {i for i, (_, _, _, t1) in self.moves.items() if t1 > now - self.period}
        if self.writing is not None:
            moving.update(int(i) for i in numpy.flatnonzero(~numpy.isnan(self.writing)))
            self.writing = None
        return self.ask_hold(sorted(moving)) if moving else 0

    def hold_timeout(self):
        """How long the outcome of a hold may take: the next cycle, or a silent board's three tries."""
        return 3 * 3 * self.timeout + 2.0 / self.rate + 0.5

    def wait_hold(self, token, timeout=None):
        """True once hold request @p token has reached the board; False when the board did not answer
        (or not within @p timeout s): it stays pending, sent as soon as the board answers."""
        if not token:
            return True
        with self.held:
            self.held.wait_for(lambda: self.holds_done >= token or self.holds_failed >= token,
                               self.hold_timeout() if timeout is None else timeout)
            return self.holds_done >= token

    def hold_outcome(self, token):
        """(True, "") once hold request @p token has reached the board; (False, " (why)") when the board
        did not answer (the hold stays pending, sent as soon as it does). Waits while the link looks fine."""
        if not token or (self.link_ok and self.wait_hold(token)):
            return True, ""
        return False, f" ({self.link_reason})" if not self.link_ok and self.link_reason else " in time"

    def hold_said(self, token, text, joints="the joints"):
        """@p text, and what is true of the hold request @p token for @p joints: they hold where they
        are, or will be held as soon as the board answers."""
        ok, why = self.hold_outcome(token)
        if ok:
            return f"{text}: {joints} hold where they are"
        said = "" if why.startswith(" (") and why[2:-1] in text else f"the board did not answer{why}: "
        if self.stopping.is_set():  # the node ends: nothing will send it later
            return f"{text}; {said}{joints} could not be held"
        if not said:  # the reason is said already
            return f"{text}; {joints} will be held as soon as it answers"
        return f"{text}; {said}{joints} will be held as soon as it does"
