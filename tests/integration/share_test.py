#!/usr/bin/env python3
# The command line next to the studio: while `rcb4 ui` holds a board's port, `rcb4 --device PORT`
# and pyrcb4 reach the board through it (transport/share.hpp): their exchanges go through the
# studio's one FIFO (the link's error counters stay at 0 with a page, two programs and the studio
# all talking at once), the page sees what they changed (the joints, the slot list, a note), a
# second studio and another user's programs are refused, garbage on the share does not hurt, and
# once the studio ends the port is the tool's again and the share is gone.
# Usage: share_test.py RCB4 PYRCB4_DIR
# SPDX-License-Identifier: BSL-1.0
import concurrent.futures
import json
import os
import socket
import subprocess
import sys
import tempfile
import time

from checks import check, finish
from uihelp import tools
from wsclient import WebSocket

RCB4 = sys.argv[1]
sys.path.insert(0, sys.argv[2])
run, serve, Ui, browser, wait_until, joints_on = tools(RCB4)


def share_path(dev):
    """Where the studio serves @dev (transport/share.hpp's share_path)."""
    runtime = os.environ.get("XDG_RUNTIME_DIR", "")
    folder = (os.path.join(runtime, "rcb4", "share") if runtime.startswith("/")
              else f"/tmp/rcb4-{os.getuid()}/share")
    return os.path.join(folder, os.path.realpath(dev).replace("/", "_") + ".sock")


with serve() as dev, tempfile.TemporaryDirectory() as poses:
    os.environ["RCB4_SLOT_NAMES"] = os.path.join(poses, "slot-names.yaml")  # not the user's own
    rc, out, err = run("--device", dev, "ping")
    check(rc == 0, f"before the studio: ping on the port itself ({rc}, {err.strip()!r})")
    ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
    check(ui.port > 0, f"rcb4 ui serves ({ui.url!r})")
    sock = share_path(dev)
    check(wait_until(lambda: os.path.exists(sock), timeout=10), f"the studio shares the port at {sock}")
    folder_mode = os.stat(os.path.dirname(sock)).st_mode & 0o777
    check(folder_mode == 0o700, f"in a folder only its user can enter ({oct(folder_mode)})")

    page = WebSocket(ui.port, origin=f"http://127.0.0.1:{ui.port}")
    hello = page.wait_for(lambda m: m["type"] == "hello")
    names = [j["name"] for j in hello["joints"]]
    head = names.index("head_yaw")

    # --- the tool through the studio -----------------------------------------------------------
    rc, out, err = run("--trace", "--device", dev, "ping")
    check(rc == 0 and f"{dev} is held by rcb4 ui (pid {ui.p.pid}): going through it" in err,
          f"rcb4 ping while the studio holds the port: exit 0, through it ({rc}, {err.strip()[:200]!r})")
    rc, out, err = run("--device", dev, "joint", "move", "head_yaw=30@200")
    check(rc == 0, f"rcb4 joint move through the studio: exit 0 ({rc}, {err.strip()!r})")
    state = page.wait_for(lambda m: m["type"] == "state" and m["angles"][head] is not None
                          and abs(m["angles"][head] - 30) < 0.2, timeout=5)
    check(state is not None, "the page shows head_yaw at 30° moved by the command line")
    note = page.wait_for(lambda m: m["type"] == "note" and "another program" in m.get("text", ""), timeout=5)
    check(note is not None and "changed the board" in note["text"], f"and says another program changed the board ({note})")

    # A slot pushed from the command line, then erased, shows in the page's slot list at once.
    flowchart = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "hth4", "wave_twice.xml")
    rc, out, err = run("--device", dev, "motion", "import", flowchart, "--push", "12", timeout=120)
    check(rc == 0, f"rcb4 motion import --push 12 through the studio: exit 0 ({rc}, {err.strip()[-200:]!r})")
    lists = page.wait_for(lambda m: m["type"] == "lists" and 12 in [x["slot"] for x in m["motions"]], timeout=10)
    check(lists is not None, "the page's slot list gains slot 12 without a reload")
    rc, out, err = run("--device", dev, "motion", "erase", "12", "--backup", os.path.join(poses, "slot12.bin"), timeout=120)
    check(rc == 0, f"rcb4 motion erase 12 through the studio: exit 0 ({rc}, {err.strip()[-200:]!r})")
    again = page.wait_for(lambda m: m["type"] == "lists" and 12 not in [x["slot"] for x in m["motions"]], timeout=10)
    check(again is not None, "and loses it when the command line erases it")

    # --- pyrcb4 and the tool at once, with the page reading 30 times a second -------------------------
    import pyrcb4
    b = pyrcb4.Board(device=dev)
    check("through rcb4 ui" in b.where, f"pyrcb4.Board on the held port goes through the studio ({b.where!r})")

    def tool_reads(_):
        return run("--json", "--device", dev, "joint", "list")[0]

    with concurrent.futures.ThreadPoolExecutor(3) as pool:
        tool_rcs = list(pool.map(tool_reads, range(6)))
        for _ in range(50):
            b.ping()
    check(tool_rcs == [0] * 6, f"six joint lists from the tool while pyrcb4 pings 50 times: all exit 0 ({tool_rcs})")
    last = page.wait_for(lambda m: m["type"] == "state", timeout=5)
    link = last["link"] if last else {}
    check(link and link["errors"] == 0 and link["timeouts"] == 0,
          f"the studio's link: no error, no timeout while three programs talk through its FIFO ({link})")
    b.close()

    # --- what must be refused or survived -------------------------------------------------------
    second = subprocess.run([RCB4, "--device", dev, "ui", "--listen", "127.0.0.1:0"], capture_output=True, text=True,
                            timeout=30)
    check(second.returncode == 3 and "held by another rcb4 ui" in second.stderr,
          f"a second studio on the port: exit 3, named ({second.returncode}, {second.stderr.strip()!r})")
    def ask(s, data, want):
        s.sendall(data)
        got = b""
        try:
            while len(got) < want:
                piece = s.recv(16)
                if not piece:
                    break
                got += piece
        except socket.timeout:
            pass
        return got

    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.connect(sock)
    s.settimeout(2)
    got = ask(s, bytes([0x00, 0x01, 0x02]) + bytes([0x03, 0xFE, 0x01]), 4)  # no frame is 0-2 bytes long
    check(got == bytes([0x04, 0xFE, 0x06, 0x08]), f"noise on the share is dropped, the ping after it answered ({got.hex()})")
    s.sendall(bytes([0x10, 0x00]))  # the start of a 16-byte frame, never finished
    time.sleep(0.4)
    got = ask(s, bytes([0x03, 0xFE, 0x01]), 4)
    check(got == bytes([0x04, 0xFE, 0x06, 0x08]), f"an unfinished frame is dropped after 200 ms of silence ({got.hex()})")
    s.close()
    if os.getuid() == 0 and subprocess.run(["id", "nobody"], capture_output=True).returncode == 0:
        other = subprocess.run(["setpriv", "--reuid=nobody", "--regid=nogroup", "--clear-groups", RCB4, "--device",
                                dev, "ping"], capture_output=True, text=True, timeout=30)
        check(other.returncode != 0, f"another user's program is not served (exit {other.returncode})")

    rc = ui.stop()
    check(rc == 0, f"the studio ends with exit 0 ({rc})")
    check(not os.path.exists(sock), "and its share is gone")
    rc, out, err = run("--device", dev, "ping")
    check(rc == 0 and "through" not in err, f"the port is the tool's own again ({rc}, {err.strip()!r})")

finish()
