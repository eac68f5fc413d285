#!/usr/bin/env python3
# From a servo's measured position changing on the board to the joint_states message that carries
# it: latency (median, p99) and the achieved joint_states rate, next to the board's output period.
# The board is `rcb4 serve --pty --pace` (a KHR-3HV's 20 servos; replies at the 1.25 Mbaud line's
# pace, plus 0 or 1,000 us of adapter latency) with `--turn 0:MS`: a hand turns head_yaw (ICS 0)
# 500 counts and back every MS ms and the server prints each turn's CLOCK_MONOTONIC time, which is
# time.monotonic() here. Latency = the first joint_states message carrying the new position minus
# that time.
#   latency.py RCB4_TOOL PYRCB4_DIR NODE_SRC_DIR [SAMPLES]
# SPDX-License-Identifier: BSL-1.0
import math
import os
import signal
import statistics
import subprocess
import sys
import threading
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import master as rosmaster  # noqa: E402 (ros/tests/master.py)

TOOL, PYRCB4, NODE_SRC = sys.argv[1:4]
SAMPLES = int(sys.argv[4]) if len(sys.argv) > 4 else 100
PERIOD_MS = 10  # the board's output period: a rate above 100 Hz only repeats data
TURN_MS = 37    # not a multiple of the period or of the node's cycle: turns fall at every phase

master, env = rosmaster.start(PYRCB4, NODE_SRC, "/bench")
import rospy  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402

rospy.init_node("rcb4_latency", anonymous=True, disable_signals=True)
seen = []  # (monotonic arrival, head_yaw position in radians)
rospy.Subscriber("/joint_states", JointState,
                 lambda m: seen.append((time.monotonic(), m.position[m.name.index("head_yaw")]))
                 if "head_yaw" in m.name else None, queue_size=1000)


print(f"position change -> joint_states, {SAMPLES} changes, rcb4 serve --pace at 1.25 Mbaud; "
      f"board output period {PERIOD_MS} ms")
print(f"{'adapter latency':>16} {'rate':>9} {'median':>9} {'p99':>9}")
COUNTS_PER_RAD = 8000 / 270 * 180 / math.pi  # KHR-3HV: 270 degrees over counts 3500..11500
try:
    for latency in (0, 1000):
        srv = subprocess.Popen([TOOL, "serve", "--pty", "--pace", "--latency", str(latency), "--turn", f"0:{TURN_MS}"],
                               stdout=subprocess.PIPE, text=True)
        device = srv.stdout.readline().strip()
        turns = []  # (monotonic time, counts)
        threading.Thread(target=lambda: [turns.append((float(w[-1]), int(w[-3])))
                                         for w in (line.split() for line in srv.stdout) if w and w[0] == "turned"],
                         daemon=True).start()
        node = subprocess.Popen([sys.executable, os.path.join(NODE_SRC, "..", "scripts", "rcb4_node"),
                                 f"_device:={device}", "_baud:=1250000", "_rate:=1000"], env=env,
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while len(seen) < 20 or not turns:
            time.sleep(0.05)
        seen.clear()
        done = len(turns)
        start = time.monotonic()
        while len(turns) < done + SAMPLES + 1:
            time.sleep(0.05)
        time.sleep(0.1)
        lags = []
        for at, counts in turns[done:done + SAMPLES]:
            want = (counts - 7500) / COUNTS_PER_RAD  # the built-in profile: head_yaw 0 at 7500, no trim
            hit = [t for t, p in list(seen) if t >= at and abs(p - want) < 2 / COUNTS_PER_RAD]
            if hit:
                lags.append(hit[0] - at)
        rate = len([t for t, _ in seen if t >= start]) / (time.monotonic() - start)
        node.send_signal(signal.SIGINT)
        node.wait(timeout=10)
        srv.send_signal(signal.SIGINT)
        srv.wait(timeout=10)
        if len(lags) < SAMPLES:
            sys.exit(f"only {len(lags)} of {SAMPLES} turns reached joint_states")
        lags.sort()
        print(f"{latency:>13} us {rate:>7.1f}/s {statistics.median(lags) * 1000:>7.2f} ms "
              f"{lags[int(0.99 * (len(lags) - 1))] * 1000:>7.2f} ms")
        seen.clear()
finally:
    rospy.signal_shutdown("done")
    master.terminate()
    master.wait(timeout=10)
