#!/usr/bin/env python3
# The studio's speed, printed (not asserted): frames the 3D view draws per second while the board
# is read at the page's period and while a motion plays, Chromium's CPU while nothing moves, and how long a slider change takes to reach the board (the
# page's performance clock, from the slider's input event to the first state in which the board's
# output for that joint has started toward the new angle), on `rcb4 serve --pty --pace` (the line at 1.25 Mbaud), in Debian's
# headless Chromium drawing WebGL with SwiftShader (a CPU: a GPU draws faster).
#   studio_bench.py RCB4 [OLD_RCB4]
# With OLD_RCB4 (another build of the tool, e.g. of the commit a trial used) both pages are measured
# in the same run, one after the other, and the figures printed side by side.
# SPDX-License-Identifier: BSL-1.0
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "integration"))
from uihelp import tools  # noqa: E402


def measure(RCB4):
    """Every figure for the page that RCB4's `ui` serves, as text by name."""
    run, serve, Ui, browser, wait_until, joints_on = tools(RCB4)
    srv = subprocess.Popen([RCB4, "serve", "--pty", "--pace"], stdout=subprocess.PIPE, text=True)
    dev = srv.stdout.readline().strip()
    ui = Ui("--device", dev, "--baud", "1250000", "ui", "--listen", "127.0.0.1:0", "--poses", "/tmp/rcb4-bench-poses")
    d = browser()
    out = {}
    try:
        d.get(ui.url)
        wait_until(lambda: d.execute_script("return !!(window.rcb4Studio && window.rcb4Studio.view)"), timeout=30)
        wait_until(lambda: d.execute_script("return document.querySelector('#role').textContent") == "controlling")
        names = d.execute_script("return window.rcb4Studio.hello.joints.map((j) => j.name)")
        fr0, s0, t0 = d.execute_script("return [window.rcb4Studio.view.stats.frames, window.rcb4State.seq, performance.now()]")
        time.sleep(5)
        fr1, s1, t1 = d.execute_script("return [window.rcb4Studio.view.stats.frames, window.rcb4State.seq, performance.now()]")
        secs = (t1 - t0) / 1000
        lat = []
        acked = []
        for k in range(12):
            target = 20 if k % 2 == 0 else -20
            ms = d.execute_async_script("""
                const [name, deg, i, done] = arguments;
                const s = document.querySelector(`.joint[data-joint="${name}"] input[type=range]`);
                const before = window.rcb4State.targets[i];
                const acked = window.rcb4State.link.move_at_ms;
                const t0 = performance.now();
                let board = null;
                s.value = deg; s.dispatchEvent(new Event('input'));
                const poll = () => {
                  // The first state whose output for the joint has left where it was: the board has the move
                  // (it then interpolates toward the target at the server's speed limit).
                  const st = window.rcb4State;
                  // The board acknowledged the move (the server's wall clock against the page's).
                  if (board === null && st.link.move_at_ms !== null && st.link.move_at_ms !== acked)
                    board = st.link.move_at_ms - (performance.timeOrigin + t0);
                  if (st && st.targets[i] !== null && Math.abs(st.targets[i] - before) > 0.2) done([performance.now() - t0, board]);
                  else if (performance.now() - t0 > 5000) done(null);
                  else setTimeout(poll, 1);
                };
                poll();""", "head_yaw", target, names.index("head_yaw"))
            if ms is not None:
                lat.append(ms[0])
                if ms[1] is not None:
                    acked.append(ms[1])
            time.sleep(0.6)
        period = d.execute_script("return window.rcb4Studio.hello.period_ms")

        # The page's CPU while the robot stands still: Chromium's processes (browser, renderer, GPU
        # process drawing with SwiftShader), CPU seconds per wall second over 5 s, from /proc.
        def chromium_cpu():
            ticks = 0
            for pid in os.listdir("/proc"):
                if not pid.isdigit():
                    continue
                try:
                    with open(f"/proc/{pid}/cmdline", "rb") as f:
                        if b"chromium" not in f.read().split(b"\0")[0]:
                            continue
                    with open(f"/proc/{pid}/stat") as f:
                        fields = f.read().rsplit(")", 1)[1].split()
                    ticks += int(fields[11]) + int(fields[12])  # utime + stime
                except OSError:
                    continue
            return ticks / os.sysconf("SC_CLK_TCK")

        time.sleep(2)  # the slider moves above have settled
        c0, w0 = chromium_cpu(), time.time()
        time.sleep(5)
        idle_cpu = (chromium_cpu() - c0) / (time.time() - w0)
        # The frame rate while a motion plays (slot 2 of the virtual board, 0.7 s) and the page follows it.
        f0, t0 = d.execute_script("return [window.rcb4Studio.view.stats.frames, performance.now()]")
        d.execute_script("window.rcb4Studio.request({op: 'motion_play', slot: 2})")
        time.sleep(0.7)
        f1, t1 = d.execute_script("return [window.rcb4Studio.view.stats.frames, performance.now()]")
        out["idle_cpu"] = f"{idle_cpu * 100:.0f} % of a core"
        out["motion_fps"] = f"{(f1 - f0) / ((t1 - t0) / 1000):.1f} frames/s"
        out["read_fps"] = f"{(fr1 - fr0) / secs:.1f} frames/s ({(s1 - s0) / secs:.1f} states/s, period {period} ms)"
        out["slider_ack"] = (f"median {statistics.median(acked):.1f} ms, max {max(acked):.1f} ms ({len(acked)} moves)"
                             if acked else "not reported by this page")
        out["slider_moving"] = (f"median {statistics.median(lat):.1f} ms, max {max(lat):.1f} ms ({len(lat)} moves)"
                                if lat else "no move seen")
    finally:
        d.quit()
        ui.stop()
        srv.terminate()
        srv.wait(timeout=10)
    return out


ROWS = [
    ("idle_cpu", "Chromium's CPU while the robot stands still (all its processes, /proc)"),
    ("read_fps", "the 3D view while the board is read and nothing moves"),
    ("motion_fps", "the 3D view while motion 2 plays"),
    ("slider_ack", "slider -> the board has the move (its ACK, server clock against the page's)"),
    ("slider_moving", "slider -> the page sees the board moving the joint"),
]

builds = [("this build", sys.argv[1])] + ([("OLD_RCB4", sys.argv[2])] if len(sys.argv) > 2 else [])
results = [(name, measure(path)) for name, path in builds]
for key, what in ROWS:
    print(what)
    for name, r in results:
        print(f"    {name:<11} {r.get(key, '-')}")
