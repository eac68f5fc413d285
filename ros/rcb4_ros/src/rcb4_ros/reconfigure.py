# rcb4_ros.reconfigure: kxr_controller's dynamic_reconfigure parameters (its KXRParameters:
# frame_count, wheel_frame_count, temperature_limit, current_limit), under the same names and where
# its client looks for them (<the node's namespace>/rcb4_ros_bridge, ~reconfigure_namespace), so
# that kxr_controller's update_kxr_parameters() and rqt_reconfigure work unchanged. Served with
# Debian's dynamic_reconfigure (its Python server, over a description built here: no generated
# Config class is needed). What each one does here:
#  - frame_count: the frames of the move each ~joint_command target becomes (kxr_controller sends
#    each command it streams as a move of frame_count frames); 1-255, the frames one move can take
#    (protocol.md §5). Trajectories and goals move over their points' times, as before.
#  - wheel_frame_count: the node drives no wheel (continuous rotation) servos: a change is refused.
#  - temperature_limit, current_limit: the RCB-4 cannot set them (protocol.md §4.9: sub-commands
#    0x03/0x04 are iory's ARMH7 firmware's) nor read them (§7): a change is refused, the value is NaN.
# A value outside a parameter's range is refused, not clamped; every refusal is logged.
# SPDX-License-Identifier: BSL-1.0
import math

import rospy

NAN = float("nan")
REFUSED = {
    "wheel_frame_count": "the node drives no wheel (continuous rotation) servos, so there is nothing it would set",
    "temperature_limit": "the RCB-4 can neither set nor read the servos' temperature limit (protocol.md §4.9, §7: "
                         "only iory's ARMH7 firmware forwards it); set it in each servo's EEPROM (rcb4 ics set, on an "
                         "ICS adapter)",
    "current_limit": "the RCB-4 can neither set nor read the servos' current limit (protocol.md §4.9, §7: only "
                     "iory's ARMH7 firmware forwards it); set it in each servo's EEPROM (rcb4 ics set, on an ICS "
                     "adapter)",
}


def frame_count_of(value, what="~frame_count"):
    """@p value as a frame count (1-255), or ValueError saying why not."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != int(value):
        raise ValueError(f"{what}: {value!r} is not a whole number of frames")
    if not 1 <= value <= 255:
        raise ValueError(f"{what}: {value:g} frames: a move takes 1-255 frames (protocol.md §5)")
    return int(value)


class Description:
    """The parameters as dynamic_reconfigure's generated Config modules describe them (the same
    attributes: config_description, defaults, min, max, level, type), built at run time."""

    def __init__(self, frame_count, period):
        ms = period * 1000
        params = [
            ("frame_count", "int", frame_count, 1, 255,
             f"Frames of the move each ~joint_command target becomes (one frame: {ms:.0f} ms); trajectories "
             "and FollowJointTrajectory goals move over their points' times"),
            ("wheel_frame_count", "int", 1, 1, 255, "Not used: no wheel servos here (a change is refused)"),
            ("temperature_limit", "double", NAN, 0.0, 120.0,
             "Not settable through an RCB-4 (a change is refused; NaN: not known)"),
            ("current_limit", "double", NAN, 0.0, 6.0,
             "Not settable through an RCB-4 (a change is refused; NaN: not known)"),
        ]
        self.config_description = {
            "name": "Default", "type": "", "state": True, "cstate": "true", "id": 0, "parent": 0, "groups": [],
            "parameters": [{"name": n, "type": t, "default": d, "level": 0, "description": text, "min": lo, "max": hi,
                            "edit_method": ""} for n, t, d, lo, hi, text in params]}
        self.defaults = {n: d for n, _, d, _, _, _ in params}
        self.min = {n: lo for n, _, _, lo, _, _ in params}
        self.max = {n: hi for n, _, _, _, hi, _ in params}
        self.level = {n: 0 for n in self.defaults}
        self.type = {n: t for n, t, _, _, _, _ in params}
        self.all_level = 0


def same(a, b):
    return a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))


class Parameters:
    """What the server asks for (its callback, in the server's thread: it only sets what the node's
    loop reads, never touches the line)."""

    def __init__(self, node, description):
        self.node = node
        self.description = description
        self.applied = dict(description.defaults)
        self.applied["frame_count"] = node.frame_count

    def out_of_range(self, changes):
        """@p changes with each value outside its range replaced by the value in force, said."""
        for name, value in list(changes.items()):
            if name not in self.description.defaults:
                continue
            lo, hi = self.description.min[name], self.description.max[name]
            if isinstance(value, float) and math.isnan(value):
                continue  # NaN for a limit that cannot be set: the value in force
            if not lo <= value <= hi:
                rospy.logerr("rcb4: dynamic_reconfigure: %s %r is outside %g-%g: refused, it stays %r", name, value,
                             lo, hi, self.applied[name])
                changes[name] = self.applied[name]
        return changes

    def apply(self, config, level):
        for name, why in REFUSED.items():
            if not same(config[name], self.applied[name]):
                rospy.logerr("rcb4: dynamic_reconfigure: %s %r refused: %s", name, config[name], why)
                config[name] = self.applied[name]
        frames = config["frame_count"]
        if frames != self.node.frame_count:
            self.node.frame_count = frames  # the loop reads it at its next streamed target
            rospy.loginfo("rcb4: frame_count %d: each ~joint_command target is a move of %d frames (%.0f ms)",
                          frames, frames, frames * self.node.period * 1000)
        self.applied["frame_count"] = frames
        return config


def start(node):
    """The dynamic_reconfigure server for @p node, or None (said) without Debian's dynamic_reconfigure."""
    try:
        from dynamic_reconfigure.server import Server
    except ImportError as e:
        rospy.logwarn("rcb4: no dynamic_reconfigure server (kxr_controller's update_kxr_parameters): %s "
                      "(cmake/install-deps.sh installs python3-dynamic-reconfigure)", e)
        return None

    class Checked(Server):
        """dynamic_reconfigure's server, refusing (not clamping silently) a value outside its range."""

        def update_configuration(self, changes):
            return super().update_configuration(parameters.out_of_range(changes))

    ns = rospy.resolve_name(rospy.get_param("~reconfigure_namespace", "rcb4_ros_bridge"))
    description = Description(node.frame_count, node.period)
    parameters = Parameters(node, description)
    # The server starts from what it finds under its namespace: the node's own parameters (frame_count
    # as checked at start), never what an earlier run left there.
    for name in description.defaults:
        key = f"{ns}/{name}"
        if name == "frame_count":
            rospy.set_param(key, node.frame_count)
            continue
        if rospy.has_param("~" + name):  # as kxr_controller.launch sets them: nothing here can apply them
            rospy.logerr("rcb4: ~%s %r refused: %s", name, rospy.get_param("~" + name), REFUSED[name])
        if rospy.has_param(key):
            rospy.delete_param(key)
    server = Checked(description, parameters.apply, namespace=ns)
    rospy.loginfo("rcb4: dynamic_reconfigure on %s (frame_count %d)", ns, node.frame_count)
    return server
