# rcb4_ros: what the node is asked to do on the board (a mixin of Rcb4Node, node.py): services and
# topics queue a request; the loop thread carries it out between two cycles and answers; what is
# asked while the board does not answer is dropped and answered as failed (it must never run later).
# A stop is not a request: it is a hold that stays pending until the board takes it (holds.py).
# SPDX-License-Identifier: BSL-1.0
import queue
import threading

import rospy
from std_srvs.srv import TriggerResponse

import pyrcb4


class Requests:
    """The request queue between the ROS callbacks and the loop thread (node.py)."""

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

    def stop_service(self):
        """~stop: what is under way is dropped and every joint holds where it is; answered once the board
        has taken the hold, or (not a success) that it will be held as soon as the board answers."""
        ok, why = self.hold_outcome(self.stop_now())
        if ok:
            return TriggerResponse(True, "stopped: every joint holds where it is")
        return TriggerResponse(False, f"stopped, but the board did not answer{why}: every joint will hold where it "
                                      "is as soon as it does")

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
                if what in ("free", "hold"):
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
                elif what == "resume":
                    self.moves.clear()  # the ROM program moves the servos from here
                    self.board.resume_motion()
                    message = "the ROM program runs again"
                elif what == "play":
                    self.moves.clear()
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

    def drop_requests(self, why):
        """What was asked while the board does not answer is dropped, answered and logged: it must not
        run later, when a board answers again."""
        while True:
            try:
                what, _, reply = self.requests.get_nowait()
            except queue.Empty:
                return
            rospy.logwarn("rcb4: %s: dropped, %s", what, why)
            if reply:
                reply[1].update(ok=False, message=f"{what}: {why}: nothing was done")
                reply[0].set()
