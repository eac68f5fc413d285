# A private ROS master for a test or a benchmark: `rosmaster --core` on a free port, with its own
# ROS_MASTER_URI and ROS_HOME, and PYTHONPATH reaching pyrcb4 and the node. start() sets them in
# os.environ before anything imports rospy, and returns once the master answers.
# SPDX-License-Identifier: BSL-1.0
import os
import socket
import subprocess
import tempfile
import time


def start(pyrcb4_dir, node_src, name="/rcb4_test"):
    """(the master's process, the environment for the node's processes)."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    # ROS_IP: every node on loopback by address, so the machine's host name need not resolve.
    env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_HOME=tempfile.mkdtemp(prefix="rcb4-ros-"),
               ROS_IP="127.0.0.1", PYTHONPATH=os.pathsep.join([pyrcb4_dir, node_src, os.environ.get("PYTHONPATH", "")]))
    env.pop("ROS_HOSTNAME", None)
    os.environ.pop("ROS_HOSTNAME", None)
    os.environ.update(env)
    master = subprocess.Popen(["rosmaster", "--core", "-p", str(port)], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    import rosgraph
    for _ in range(100):
        try:
            rosgraph.Master(name).getPid()
            return master, env
        except Exception:  # noqa: BLE001 (not up yet)
            time.sleep(0.1)
    master.kill()
    raise RuntimeError(f"rosmaster on port {port} did not answer in 10 s")


def wait_for(pred, timeout=10):
    """@p pred's first true value within @p timeout seconds (polled every 50 ms), or None."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        v = pred()
        if v:
            return v
        time.sleep(0.05)
    return None
