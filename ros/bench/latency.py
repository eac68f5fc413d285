#!/usr/bin/env python3
# From a servo's measured position changing on the board to the joint_states message that carries
# it: latency (median, p99) and the achieved joint_states rate, next to the board's output period.
# The board is the Python stand-in of tests/integration (an RCB-4 written from protocol.md), paced
# as a 1.25 Mbaud line with 0 and 1,000 us of adapter latency, so that this script can change a
# servo's measured position itself at a known moment (rcb4 serve's servos move only when told).
#   latency.py RCB4_TOOL PYRCB4_DIR NODE_SRC_DIR [SAMPLES]
# SPDX-License-Identifier: BSL-1.0
import os
import random
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "integration"))
from standin import StandIn  # noqa: E402

TOOL, PYRCB4, NODE_SRC = sys.argv[1:4]
SAMPLES = int(sys.argv[4]) if len(sys.argv) > 4 else 100
PERIOD_MS = 10  # the board's output period: a rate above 100 Hz only repeats data

with socket.socket() as s:
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
env = dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{port}", ROS_HOME=tempfile.mkdtemp(prefix="rcb4-ros-"),
           PYTHONPATH=os.pathsep.join([PYRCB4, NODE_SRC]))
os.environ.update(env)
master = subprocess.Popen(["rosmaster", "--core", "-p", str(port)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
import rosgraph  # noqa: E402
import rospy  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402

for _ in range(100):
    try:
        rosgraph.Master("/bench").getPid()
        break
    except Exception:  # noqa: BLE001
        time.sleep(0.1)
rospy.init_node("rcb4_latency", anonymous=True, disable_signals=True)
seen = []  # (monotonic arrival, head_yaw position in radians)
rospy.Subscriber("/joint_states", JointState,
                 lambda m: seen.append((time.monotonic(), m.position[m.name.index("head_yaw")]))
                 if "head_yaw" in m.name else None, queue_size=1000)


def head_at(board, counts):
    board.ram[0x90 + 4:0x90 + 6] = counts.to_bytes(2, "little")


print(f"position change -> joint_states, {SAMPLES} changes, a 1.25 Mbaud line; board output period {PERIOD_MS} ms")
print(f"{'adapter latency':>16} {'rate':>9} {'median':>9} {'p99':>9}")
try:
    for latency in (0, 1000):
        board = StandIn(pace_baud=1250000, latency_us=latency)
        head_at(board, 7500)
        node = subprocess.Popen([sys.executable, os.path.join(NODE_SRC, "..", "scripts", "rcb4_node"),
                                 f"_device:={board.path}", "_baud:=1250000", "_rate:=1000"], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while len(seen) < 20:
            time.sleep(0.05)
        seen.clear()
        start = time.monotonic()
        lags, value = [], 7500
        for _ in range(SAMPLES):
            time.sleep(random.uniform(0.02, 0.05))  # at a random phase of the node's cycle
            value = 8000 if value == 7500 else 7500
            changed = time.monotonic()
            head_at(board, value)
            want = (value - 7500) / (8000 / 270) * 3.141592653589793 / 180
            while True:
                hit = [t for t, p in list(seen) if t >= changed and abs(p - want) < 1e-3]
                if hit:
                    lags.append(hit[0] - changed)
                    break
                time.sleep(0.0005)
        rate = len([t for t, _ in seen if t >= start]) / (time.monotonic() - start)
        lags.sort()
        print(f"{latency:>13} us {rate:>7.1f}/s {statistics.median(lags) * 1000:>7.2f} ms "
              f"{lags[int(0.99 * (len(lags) - 1))] * 1000:>7.2f} ms")
        node.send_signal(signal.SIGINT)
        node.wait(timeout=10)
        seen.clear()
finally:
    rospy.signal_shutdown("done")
    master.terminate()
    master.wait(timeout=10)
