#!/usr/bin/env python3
# `rcb4 ui` as people use it: a browser (Debian's chromium, headless, driven by chromium-driver
# through selenium) on the page served for a virtual KHR-3HV (`rcb4 serve --pty`), and hostile
# or careless clients on plain sockets. What the page does is checked on the board through the
# CLI, with the ui stopped (the pty has one owner at a time).
# Usage: ui_test.py RCB4 SCREENSHOT.png
# SPDX-License-Identifier: BSL-1.0
import contextlib
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

from checks import check, finish
from uihelp import tools
from wsclient import WebSocket, http_get

RCB4 = sys.argv[1]
SCREENSHOT = sys.argv[2]
KHR = ["head_yaw", "waist_yaw", "left_shoulder_pitch", "right_shoulder_pitch", "left_shoulder_roll",
       "right_shoulder_roll", "left_elbow_yaw", "right_elbow_yaw", "left_elbow_pitch", "right_elbow_pitch",
       "left_hip_roll", "right_hip_roll", "left_hip_pitch", "right_hip_pitch", "left_knee", "right_knee",
       "left_ankle_pitch", "right_ankle_pitch", "left_ankle_roll", "right_ankle_roll"]  # profiles/khr-3hv.yaml


run, serve, Ui, browser, wait_until, joints_on = tools(RCB4)


def closed_within(ws, seconds):
    """True when the server closes @ws within @seconds (whatever it sends before)."""
    end = time.time() + seconds
    while time.time() < end:
        try:
            if ws.recv(timeout=max(0.05, end - time.time())) is None:
                return True
        except OSError:
            return False
    return False


with serve() as dev, tempfile.TemporaryDirectory() as poses:
    # --- the command line and HTTP ---------------------------------------------------------
    rc, out, err = run("ui", "--listen", "nonsense")
    check(rc == 2 and "--listen: expected HOST:PORT" in err, f"ui --listen nonsense: exit 2 ({rc}, {err.strip()!r})")
    for bad, why in ((["--speed", "nan"], "--speed: degrees per second, 1 to 1000"),
                     (["--listen", "0.0.0.0:0", "--token", "short"], "--token: at least 16"),
                     (["--poses", os.path.abspath(__file__)], "not a folder")):
        rc, out, err = run("ui", *bad)
        check(rc == 2 and why in err, f"ui {' '.join(bad)}: exit 2 ({rc}, {err.strip()!r})")
    ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
    check(ui.port > 0 and ui.url == f"http://127.0.0.1:{ui.port}/", f"the URL is the first line of stdout ({ui.url!r})")
    busy = subprocess.run([RCB4, "ui", "--listen", f"127.0.0.1:{ui.port}"], capture_output=True, text=True, timeout=30)
    check(busy.returncode == 3 and "cannot listen on" in busy.stderr and "127.0.0.1:0" in busy.stderr,
          f"a port in use: exit 3 with the fix ({busy.returncode}, {busy.stderr.strip()!r})")
    status, h, body = http_get(ui.port, "/")
    check(status == 200 and h["content-type"].startswith("text/html") and b"<title>rcb4 studio</title>" in body,
          "GET / serves the embedded page")
    check("default-src 'none'" in h.get("content-security-policy", ""), "with a Content-Security-Policy")
    for path in ("/app.js", "/style.css"):
        check(http_get(ui.port, path)[0] == 200, f"GET {path}: 200")
    for path in ("/../../etc/passwd", "/index.html", "/app.js.map", "/%2e%2e/etc/passwd", "/ws"):
        check(http_get(ui.port, path)[0] in (404, 426), f"GET {path}: nothing that is not embedded")
    check(http_get(ui.port, "/", host="rebind.example:80")[0] == 421, "a foreign Host on loopback (DNS rebinding): 421")

    # --- WebSockets: origin, roles, bad messages, a lost page ----------------------------------
    foreign = WebSocket(ui.port, origin="http://evil.example")
    check(foreign.status == 403, f"a WebSocket from a foreign Origin: 403, not upgraded ({foreign.status})")
    foreign.close()
    a = WebSocket(ui.port, origin=f"http://127.0.0.1:{ui.port}")
    check(a.status == 101, "the page's own origin is upgraded")
    hello = a.wait_for(lambda m: m["type"] == "hello")
    check(hello and [j["name"] for j in hello["joints"]] == KHR, "hello: the robot's 20 joints in order")
    names = [j["name"] for j in hello["joints"]]
    role = a.wait_for(lambda m: m["type"] == "role")
    check(role and role["role"] == "control", "the first page controls")
    t0 = time.time()
    states = 0
    while time.time() - t0 < 1.0:
        m = a.recv()
        states += m is not None and m["type"] == "state"
    check(states >= 20, f"at least 20 states a second ({states})")
    b = WebSocket(ui.port)  # no Origin: not a browser; allowed
    check(b.wait_for(lambda m: m["type"] == "role")["role"] == "view", "a second page watches")
    b.send({"op": "move", "id": 5, "joints": {"left_knee": 10}})
    e = b.wait_for(lambda m: m["type"] == "error")
    check(e and e["id"] == 5 and "only watches" in e["message"], "a watching page cannot move the robot")
    b.send({"op": "stop", "id": 6})
    r = b.wait_for(lambda m: m.get("id") == 6)
    check(r is not None and r["type"] == "reply", f"but it may Stop: every page keeps Stop (issue 41, M5) ({r})")
    for bad in ["", "{", "[]", "null", '{"op":"move","joints":{"left_knee":"10"}}', '{"op":"capture","name":"../x"}',
                '{"op":"x"}', "\u00e9" * 100, '{"a":' * 50]:
        a.send_text(bad)
    a.send_text(b"\x00\x01", opcode=2)
    errors = 0
    while errors < 10:
        m = a.wait_for(lambda m: m["type"] == "error", timeout=5)
        if not m:
            break
        errors += 1
    check(errors == 10, f"ten bad messages, ten errors ({errors})")
    a.send({"op": "refresh", "id": 77})
    check(a.wait_for(lambda m: m["type"] == "reply" and m["id"] == 77) is not None, "and the server still answers")
    # A motion file's text fits (issue 41: a file over 64 KiB dropped the page): a long message is
    # answered, one over 4 MiB is refused unread with an error, one over the socket's limit
    # (4 MiB + 64 KiB) closes that page's socket.
    a.send({"op": "motion_check", "id": 78, "text": "# " + "x" * 200000 + "\n"})
    r = a.wait_for(lambda m: m.get("id") == 78, timeout=10)
    check(r is not None, f"a 200 KB motion file text is answered, the page stays connected ({(r or {}).get('message', r and r['type'])})")
    a.send_text("x" * (4 * 1024 * 1024 + 1))
    e = a.wait_for(lambda m: m["type"] == "error", timeout=10)
    check(e is not None and "at most 4194304" in e["message"], f"a message over 4 MiB: an error, unread ({e})")
    try:
        a.send_text("x" * (4 * 1024 * 1024 + 64 * 1024 + 1))
        closed = closed_within(a, 10)
    except (BrokenPipeError, ConnectionResetError):  # closed while the message was still going out
        closed = True
    check(closed, "a message over the socket's limit closes that page's socket")
    # The controller went with it: a second page may take control; then it vanishes mid-move.
    took = None
    for attempt in range(30):  # the server learns of the closed page a moment after the client does
        b.send({"op": "control", "id": 100 + attempt})
        took = b.wait_for(lambda m: m["type"] in ("reply", "error") and m.get("id") == 100 + attempt)
        if took and took["type"] == "reply":
            break
        time.sleep(0.1)
    check(took is not None and took["type"] == "reply", "the watcher takes control once free")
    knee = names.index("left_knee")
    b.send({"op": "move", "joints": {"left_knee": 120}, "ms": 6000})  # 2.55 s: the slowest a 10 ms board moves
    moving = b.wait_for(lambda m: m["type"] == "state" and m["targets"][knee] is not None and m["targets"][knee] > 3)
    check(moving is not None, "a slow move starts")
    b.drop()
    c = WebSocket(ui.port)
    held = c.wait_for(lambda m: m["type"] == "state" and m["modes"][knee] == "hold", timeout=5)
    check(held is not None, "a page lost mid-move: the joint it moved holds where it was (the move stops)")
    c.close()
    local = WebSocket(ui.port, origin=f"http://localhost:{ui.port}", host=f"localhost:{ui.port}")
    check(local.status == 101, "the page's own origin (localhost) is upgraded")
    local.close()
    rc = ui.stop()
    check(rc == 0 and "stopped" in ui.err, f"SIGINT: exit 0 ({rc}, {ui.err.strip()!r})")
    knee_deg = joints_on(dev)["left_knee"]["degrees"]
    check(knee_deg is not None and 3 < knee_deg < 100, f"the knee stopped part way ({knee_deg})")

    # --- a ROM motion: its progress, and stopped part way ----------------------------------------
    ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
    w = WebSocket(ui.port)
    lists = w.wait_for(lambda m: m["type"] == "lists", timeout=10)
    check(lists is not None and [m["slot"] for m in lists["motions"]] == [1, 2, 3] and lists["motions"][1]["name"] == "wave",
          f"the motion list with the profile's names ({lists and lists['motions']})")
    w.send({"op": "motion_play", "id": 3, "slot": 2})
    st = w.wait_for(lambda m: m["type"] == "state" and m["motion"]["slot"] == 2 and
                    (m["motion"]["progress"] or 0) > 0.05, timeout=10)
    check(st is not None and st["motion"]["running"] and 0 < st["motion"]["progress"] < 1,
          f"motion 2 plays, with how far it has got ({st and st['motion']})")
    w.send({"op": "motion_stop", "id": 4})
    st = w.wait_for(lambda m: m["type"] == "state" and m["motion"]["suspended"], timeout=5)
    check(st is not None, "motion_stop: the state says stopped part way, not running")
    w.close()
    check(ui.stop() == 0, "stopped")
    run("--device", dev, "motion", "resume")
    run("--device", dev, "motion", "wait", "--timeout", "10")

    # --- a token for other addresses ----------------------------------------------------------
    ui = Ui("--device", dev, "ui", "--listen", "0.0.0.0:0", "--poses", poses)
    token = re.search(r"\?token=([0-9a-f]{32})$", ui.url)
    check(token is not None, f"--listen 0.0.0.0: a token is made and printed in the URL ({ui.url})")
    token = token.group(1) if token else ""
    check(http_get(ui.port, "/")[0] == 401, "without the token: 401")
    check(http_get(ui.port, "/?token=" + "0" * 32)[0] == 401, "with a wrong token: 401")
    status, h, _ = http_get(ui.port, "/?token=" + token, host=f"robot.lan:{ui.port}")
    check(status == 200 and "HttpOnly" in h.get("set-cookie", "") and "SameSite=Strict" in h.get("set-cookie", ""),
          "with it: 200 and a SameSite cookie")
    check(http_get(ui.port, "/app.js", {"Cookie": "rcb4_token=" + token}, host=f"robot.lan:{ui.port}")[0] == 200,
          "the cookie carries it for the page's files")
    check(WebSocket(ui.port, path="/ws", host=f"robot.lan:{ui.port}").status == 401, "a WebSocket without it: 401")
    check(WebSocket(ui.port, path="/ws?token=" + token, host=f"robot.lan:{ui.port}",
                    origin="http://evil.example").status == 403, "with it but from a foreign Origin: 403")
    check(ui.stop() == 0, "stopped")

    # --- boards that are not ours: a partial one, one that dies ---------------------------------
    standin = os.path.join(os.path.dirname(os.path.abspath(__file__)), "standin.py")
    for mode in ("partial", "die"):
        sp = subprocess.Popen([sys.executable, standin] + (["--mode", "die"] if mode == "die" else []),
                              stdout=subprocess.PIPE, text=True)
        try:
            sdev = sp.stdout.readline().strip()
            ui = Ui("--device", sdev, "--baud", "115200", "ui", "--listen", "127.0.0.1:0", "--poses", poses)
            w = WebSocket(ui.port)
            if mode == "partial":  # ICS 0-2 allocated: three joints, seventeen without a servo
                st = w.wait_for(lambda m: m["type"] == "state" and m["answering"], timeout=10)
                modes = st["modes"] if st else []
                check(modes[:3] == ["on"] * 3 and modes[3:] == ["missing"] * 17,
                      f"a board with 3 of 20 servos: those 3 shown, the others 'missing' ({modes[:5]}...)")
                w.send({"op": "move", "id": 2, "joints": {"left_knee": 10}})
                e = w.wait_for(lambda m: m["type"] in ("error", "reply") and m["op"] == "move", timeout=5)
                check(e and e["type"] == "error" and "left_knee: the board has no servo block" in e["message"],
                      f"moving a joint it lacks: an error naming it ({e})")
            else:
                st = w.wait_for(lambda m: m["type"] == "state" and not m["answering"], timeout=15)
                check(st is not None and st["error"] and "reading the robot" in st["error"],
                      f"a board that stops answering: shown as such, with the reason ({st and st['error']})")
                check(st is not None and all(a is None for a in st["angles"]), "and no stale angles")
            w.close()
            t = time.time()
            rc = ui.stop()
            check(rc == 0 and time.time() - t < 5, f"SIGINT with that board: exit 0 at once ({rc}, {time.time() - t:.1f} s)")
        finally:
            sp.kill()
            sp.wait()

    # --- the page in a real browser -------------------------------------------------------------
    try:
        driver = browser()
    except Exception as ex:  # noqa: BLE001 - any failure to start the browser is the test's
        check(False, f"chromium headless through chromedriver starts ({ex})")
        finish()
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    try:
        ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
        driver.get(ui.url)
        rows = wait_until(lambda: driver.find_elements(By.CSS_SELECTOR, ".joint[data-joint]") if len(
            driver.find_elements(By.CSS_SELECTOR, ".joint[data-joint]")) == 20 else None)
        shown = [r.find_element(By.CSS_SELECTOR, ".name").text for r in rows or []]
        check(sorted(shown) == sorted(KHR), f"the page lists every joint by name as rendered ({len(shown)})")
        # No name is cut, down to a narrow window (at 1280 px long names ended in an ellipsis).
        for width in (1280, 1024, 800):
            driver.set_window_size(width, 900)
            cut = driver.execute_script(
                "return [...document.querySelectorAll('.joint .name')]"
                ".filter(e => e.scrollWidth > e.clientWidth + 1 || e.scrollHeight > e.clientHeight + 1)"
                ".map(e => e.textContent)")
            check(cut == [], f"at {width} px every joint name is shown whole ({cut})")
        driver.set_window_size(1400, 1080)
        check(wait_until(lambda: "exchanges/s" in driver.find_element(By.ID, "link-text").text),
              "the link line shows the exchanges")
        check(wait_until(lambda: driver.find_element(By.ID, "role").text == "controlling"), "the page controls")
        # The slider, moved the way a person does with the keyboard: focus it, End.
        slider = driver.find_element(By.CSS_SELECTOR, 'input[data-joint="head_yaw"]')
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", slider)  # not under the sticky header
        slider.click()
        slider.send_keys(Keys.END)
        target = lambda: driver.find_element(By.CSS_SELECTOR, '.joint[data-joint="head_yaw"] .target').get_attribute(
            "data-degrees")
        near = lambda v, want: v not in (None, "") and abs(float(v) - want) < 0.05
        check(wait_until(lambda: near(target(), 90), timeout=10), f"the page shows head_yaw's target at 90 ({target()})")
        check(wait_until(lambda: driver.find_element(
            By.CSS_SELECTOR, '.joint[data-joint="head_yaw"] .angle').text == "+90.0°", timeout=10),
            "and the measured angle reaches it")
        rc = ui.stop()
        j = joints_on(dev)["head_yaw"]
        check(rc == 0 and abs(j["target"] - 90) < 0.05, f"on the board (CLI): head_yaw's target is 90 ({j['target']}, exit {rc}, {ui.err.strip()!r})")

        # Capture, move away, play it back.
        ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
        driver.get(ui.url)
        wait_until(lambda: driver.find_element(By.ID, "role").text == "controlling")
        wait_until(lambda: "90" in driver.find_element(By.CSS_SELECTOR, '.joint[data-joint="head_yaw"] .angle').text)
        name = driver.find_element(By.ID, "pose-name")
        name.send_keys("look_left")
        driver.find_element(By.ID, "capture").click()
        item = wait_until(lambda: driver.find_elements(By.CSS_SELECTOR, '#poses li[data-pose="look_left"]'))
        saved = os.path.join(poses, "look_left.yaml")
        check(item and os.path.exists(saved), "capture: the pose is listed and saved as look_left.yaml")
        check(os.path.exists(saved) and re.search(r"head_yaw:\s*90\b", open(saved).read()), "with head_yaw at 90")
        slider = driver.find_element(By.CSS_SELECTOR, 'input[data-joint="head_yaw"]')
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'})", slider)  # not under the sticky header
        slider.click()
        slider.send_keys(Keys.HOME)
        check(wait_until(lambda: driver.find_element(
            By.CSS_SELECTOR, '.joint[data-joint="head_yaw"] .angle').text == "-90.0°", timeout=10),
            "the joint moved away to -90")
        ms = driver.find_element(By.ID, "pose-ms")
        ms.clear()
        ms.send_keys("300")
        driver.find_element(By.CSS_SELECTOR, '#poses li[data-pose="look_left"] button.play').click()
        check(wait_until(lambda: "playing look_left over 2" in driver.find_element(By.ID, "message").text),
              f"the page says it plays ({driver.find_element(By.ID, 'message').text!r})")
        check(wait_until(lambda: driver.find_element(
            By.CSS_SELECTOR, '.joint[data-joint="head_yaw"] .angle').text == "+90.0°", timeout=10),
            "play: back at 90 (the speed limit stretched 300 ms to 2 s)")
        # A second browser page only watches.
        driver.switch_to.new_window("tab")
        driver.get(ui.url)
        check(wait_until(lambda: "watching" in driver.find_element(By.ID, "role").text), "a second tab watches")
        check(not driver.find_element(By.CSS_SELECTOR, 'input[data-joint="head_yaw"]').is_enabled() and
              not driver.find_element(By.ID, "capture").is_enabled(), "its sliders and buttons are disabled")
        check(driver.find_element(By.ID, "stop").is_enabled() and driver.find_element(By.ID, "motion-stop").is_enabled(),
              "but Stop and Stop motion are not: a watching tab may stop the robot")
        # Reading a ROM motion as a motion file is for any page: the watching tab asks for motion 2.
        driver.find_element(By.CSS_SELECTOR, '#motions li[data-motion="2"] button[title^="the motion as"]').click()
        text = wait_until(lambda: driver.find_element(By.ID, "motion-file-text").text or None)
        check(text and "period_ms: 10" in text and "right_shoulder_pitch: 67.5" in text and text.rstrip().endswith("- end"),
              f"YAML: motion 2 as a motion file, in degrees and ms ({(text or '')[:160]!r})")
        check(driver.find_element(By.ID, "motion-file-save").get_attribute("download") == "wave.yaml" and
              "beyond" not in driver.find_element(By.ID, "motion-file-problem").text,
              "saved as wave.yaml; the demo's wave breaks no limit, so no problem is said")
        driver.close()
        driver.switch_to.window(driver.window_handles[0])
        time.sleep(1.5)  # let the 30 s plots gather a little for the picture
        driver.save_screenshot(SCREENSHOT)
        check(os.path.getsize(SCREENSHOT) > 10000, f"a screenshot is written ({SCREENSHOT})")
        rc = ui.stop()
        j = joints_on(dev)["head_yaw"]
        check(rc == 0 and abs(j["degrees"] - 90) < 0.05, f"on the board (CLI): head_yaw is back at 90 ({j['degrees']})")
    finally:
        driver.quit()
        if ui.p.poll() is None:
            ui.stop()

finish()
