# rcb4_ros: what the node publishes of each cycle's reading (a mixin of Rcb4Node, node.py), in the
# forms a kxr_controller user reads: joint_states and current_joint_states (positions, and the servo
# error in effort), servo_states (kxr_controller/ServoStateArray), <ns>/state
# (control_msgs/JointTrajectoryControllerState) and <ns>/servo_on_off_real_interface/state
# (kxr_controller/ServoOnOff). Only after a read the board answered, and only what it measured: a
# joint whose servo does not answer is left out; what the RCB-4 does not measure (velocity,
# temperature, current: protocol.md §7) or the node does not know (a joint's target) is NaN or left
# empty, never made up.
# SPDX-License-Identifier: BSL-1.0
import math

import numpy
import rospy
from sensor_msgs.msg import JointState

from rcb4_ros import actions, messages


class States:
    """The publishers of the readings (node.py: init_states once, publish_states each cycle)."""

    def init_states(self):
        self.states = rospy.Publisher("joint_states", JointState, queue_size=10)
        self.current_states = rospy.Publisher("current_joint_states", JointState, queue_size=1)
        self.servo_states = self.controller_state = self.on_off_state = None
        try:
            self.control_msgs, self.kxr_msgs = messages.load()
        except ImportError:  # said by actions.start: no kxr_controller forms, joint_states only
            return
        ns = actions.namespace()
        self.servo_states = rospy.Publisher("servo_states", self.kxr_msgs.ServoStateArray, queue_size=1)
        self.controller_state = rospy.Publisher(ns + "/state", self.control_msgs.JointTrajectoryControllerState,
                                                queue_size=1)
        self.on_off_state = rospy.Publisher(ns + "/servo_on_off_real_interface/state", self.kxr_msgs.ServoOnOff,
                                            queue_size=1)

    def targets(self, now):
        """Degrees: where the board's interpolation of the node's last move has each servo at @p now
        (monotonic), as it interpolates a CONST (protocol.md §4.7, §5: straight, over its frames); NaN
        where the node does not know it (no move since it started, a hold, a free, a ROM motion)."""
        out = numpy.full(len(self.names), numpy.nan)
        for i in list(self.moves):
            out[i] = self.reference(i, now)
        return out

    def publish_states(self, stamp, now):
        """Publishes the reading just made (self.angles, stamped @p stamp, read by monotonic time @p now)."""
        seen = numpy.flatnonzero(~numpy.isnan(self.angles))
        names = [self.prefix + self.names[i] for i in seen]
        target = self.targets(now)
        position = numpy.radians(self.angles[seen])
        desired = numpy.radians(target[seen])
        error = desired - position  # the servo error, as kxr_controller puts it in effort (NaN: target unknown)
        msg = JointState()
        msg.header.stamp = stamp
        msg.name, msg.position, msg.effort = list(names), position.tolist(), error.tolist()
        if self.current_states.get_num_connections():  # kxr_controller's: the servos' joints only
            self.current_states.publish(JointState(header=msg.header, name=list(names), position=msg.position,
                                                   effort=msg.effort))
        for name, j, k, off in self.mimics:  # URDF's mimic: k x the joint it follows, + offset
            if not math.isnan(self.angles[j]):
                msg.name.append(name)
                msg.position.append(math.radians(k * self.angles[j] + off))
                msg.effort.append(math.radians(k * (target[j] - self.angles[j])))
        self.states.publish(msg)
        if self.servo_states is None:
            return
        if self.servo_states.get_num_connections():
            nan = float("nan")  # the RCB-4 reads no temperature nor current (protocol.md §7)
            self.servo_states.publish(self.kxr_msgs.ServoStateArray(header=msg.header, servos=[
                self.kxr_msgs.ServoState(header=msg.header, name=n, position=p, error=e, temperature=nan, current=nan)
                for n, p, e in zip(names, msg.position, msg.effort)]))
        if self.controller_state.get_num_connections():
            s = self.control_msgs.JointTrajectoryControllerState()
            s.header = msg.header
            s.joint_names = list(names)
            s.desired.positions = desired.tolist()
            s.actual.positions = list(msg.position)
            s.error.positions = list(msg.effort[:len(names)])
            self.controller_state.publish(s)
        if self.on_off_state.get_num_connections():
            self.on_off_state.publish(self.kxr_msgs.ServoOnOff(
                joint_names=[self.prefix + n for n in self.names], servo_on_states=[not f for f in self.freed]))
