# rcb4_ros.messages: the message classes the node's actions use (control_msgs, kxr_controller).
# A system that has the real packages (ROS Noetic, a catkin workspace with kxr_controller) gives
# them; else the ones generated from ros/messages in the build (Debian 12 ships neither), found
# installed beside the node, in $RCB4_ROS_MESSAGES, or in the build tree beside pyrcb4. They go
# last on sys.path, so they never shadow a real package.
# SPDX-License-Identifier: BSL-1.0
import importlib
import os
import sys


def _generated_dirs():
    here = os.path.dirname(os.path.abspath(__file__))
    dirs = [os.environ.get("RCB4_ROS_MESSAGES"), os.path.join(here, "messages")]
    try:
        import pyrcb4
        # The build tree: BUILD/python/pyrcb4 and BUILD/ros/generated.
        dirs.append(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(pyrcb4.__file__))), "..", "ros",
                                 "generated"))
    except ImportError:
        pass
    return [d for d in dirs if d and os.path.isdir(os.path.join(d, "control_msgs"))]


def load():
    """(control_msgs.msg, kxr_controller.msg), or ImportError saying where they were looked for."""
    found = {}
    for package in ("control_msgs", "kxr_controller"):
        try:
            found[package] = importlib.import_module(package + ".msg")
            getattr(found[package], "FollowJointTrajectoryAction" if package == "control_msgs" else "ServoOnOffAction")
            continue
        except (ImportError, AttributeError):
            for k in [k for k in sys.modules if k == package or k.startswith(package + ".")]:
                del sys.modules[k]
        dirs = _generated_dirs()
        for d in dirs:
            if d not in sys.path:
                sys.path.append(d)
        try:
            found[package] = importlib.import_module(package + ".msg")
        except ImportError as e:
            raise ImportError(f"{package}.msg: not installed, and not generated in {dirs or 'any known place'} "
                              f"({e}); build rcb4 with python3-genpy (cmake/install-deps.sh)") from None
    return found["control_msgs"], found["kxr_controller"]
