#!/usr/bin/env python3
# rcb4 studio (`rcb4 ui`) as an HTH4 user clicks through it, in Debian's headless Chromium
# (selenium) over `rcb4 serve --pty`: the robot drawn in 3D changes when a joint moves; a
# three-pose motion built in the editor (two poses captured, one typed), reordered and retimed,
# previewed, pushed to slot 10 with its backup named; on the board through the tool (the ui
# stopped: the pty has one owner) `motion show 10` lists three CONST frames and a RETURN and
# `motion play 10 --wait` ends at the last pose; pulled back, the editor shows the same poses; a
# button assigned on the remote's picture plays it. Screenshots of the studio for the README.
# Usage: studio_test.py RCB4 SCREENSHOT_DIR
# SPDX-License-Identifier: BSL-1.0
import json
import os
import sys
import tempfile
import time

from checks import check, finish
from uihelp import tools

RCB4, SHOTS = sys.argv[1], sys.argv[2]
run, serve, Ui, browser, wait_until, joints_on = tools(RCB4)


def js(driver, code, *args):
    return driver.execute_script(code, *args)


def click(driver, by, what):
    from selenium.common.exceptions import StaleElementReferenceException
    from selenium.webdriver.common.by import By
    for attempt in range(5):  # a table drawn again between finding and clicking: found again
        try:
            e = driver.find_element(By.CSS_SELECTOR if by == "css" else By.ID, what)
            js(driver, "arguments[0].scrollIntoView({block: 'center'})", e)
            e.click()
            return e
        except StaleElementReferenceException:
            if attempt == 4:
                raise
            time.sleep(0.2)


def message(driver):
    return js(driver, "return document.querySelector('#message').textContent")


def slide(driver, joint, degrees):
    """A joint's slider in the joints panel set as a person drags it (the page sends the move)."""
    js(driver, """const s = document.querySelector(`.joint[data-joint="${arguments[0]}"] input[type=range]`);
                  s.value = arguments[1]; s.dispatchEvent(new Event('input'));""", joint, degrees)


def measured(driver, joint):
    """The joint's measured angle in the page's latest state (the hello's joint order)."""
    return js(driver, "return window.rcb4State && window.rcb4State.angles[arguments[0]]", NAMES.index(joint))


def shot(driver, name):
    """A screenshot of the studio's column (the 3D view and the editor), for the README."""
    driver.set_window_size(1400, 1500)
    js(driver, "window.scrollTo(0, 0)")
    time.sleep(0.5)  # the view resizes to the window, then draws
    driver.save_screenshot(os.path.join(SHOTS, name))
    driver.set_window_size(1400, 1080)


def canvas_png(driver):
    return js(driver, "return document.querySelector('#view3d canvas').toDataURL('image/png')")


NAMES = None
with serve() as dev, tempfile.TemporaryDirectory() as poses:
    os.environ["RCB4_SLOT_NAMES"] = os.path.join(poses, "slot-names.yaml")
    ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
    driver = browser()
    try:
        from selenium.webdriver.common.by import By
        driver.get(ui.url)
        check(wait_until(lambda: js(driver, "return !!(window.rcb4Studio && window.rcb4Studio.view)"), timeout=20),
              "the studio draws the robot (three.js from Debian, WebGL)")
        NAMES = js(driver, "return window.rcb4Studio.hello.joints.map((j) => j.name)")
        wait_until(lambda: driver.find_element(By.ID, "role").text == "controlling")
        wait_until(lambda: js(driver, "return window.rcb4Studio.view.stats.frames") > 0)
        # An idle page draws nothing (issue 41, item 10): the robot stands still, the view waits.
        time.sleep(1.0)
        f0 = js(driver, "return window.rcb4Studio.view.stats.frames")
        time.sleep(2.0)
        f1 = js(driver, "return window.rcb4Studio.view.stats.frames")
        check(f1 - f0 <= 2, f"the 3D view draws nothing while nothing moves ({f1 - f0} frames in 2 s)")
        gl = js(driver, "const c = document.querySelector('#view3d canvas'); return !!(c.getContext('webgl2') || c.getContext('webgl'))")
        check(gl, "the 3D view is a WebGL canvas")

        # The 3D view changes when a joint moves.
        before = canvas_png(driver)
        slide(driver, "left_shoulder_pitch", 80)
        check(wait_until(lambda: abs((measured(driver, "left_shoulder_pitch") or 0) - 80) < 1, timeout=10),
              "the slider moved left_shoulder_pitch to 80")
        time.sleep(0.3)
        check(canvas_png(driver) != before, "the 3D view changed as the joint moved")
        slide(driver, "left_shoulder_pitch", 0)
        wait_until(lambda: abs(measured(driver, "left_shoulder_pitch") or 99) < 1, timeout=10)

        # Build a motion: two poses captured from the robot, one typed.
        click(driver, "id", "ed-new")
        driver.find_element(By.ID, "ed-name").send_keys("knee test")
        slide(driver, "left_knee", 30)
        wait_until(lambda: abs((measured(driver, "left_knee") or 0) - 30) < 0.6, timeout=10)
        click(driver, "id", "ed-capture")
        slide(driver, "left_knee", -20)
        slide(driver, "head_yaw", 15)
        wait_until(lambda: abs((measured(driver, "left_knee") or 0) + 20) < 0.6
                   and abs((measured(driver, "head_yaw") or 0) - 15) < 0.6, timeout=10)
        click(driver, "id", "ed-capture")
        js(driver, "document.querySelector('#ed-kind').value = 'pose'")
        click(driver, "id", "ed-add")  # a pose from the ghost (the last one), then typed
        js(driver, """const n = document.querySelector('.pose-joint[data-joint="left_knee"] input.num');
                      n.value = 10; n.dispatchEvent(new Event('change'));""")
        doc = js(driver, "return window.rcb4Studio.editor.doc")
        kinds = ["pose" if isinstance(s, dict) and "pose" in s else s for s in doc["steps"]]
        knees = [s["pose"].get("left_knee") for s in doc["steps"] if isinstance(s, dict) and "pose" in s]
        check(kinds == ["pose", "pose", "pose", "end"] and knees == [30, -20, 10],
              f"three poses: two captured (30, -20), one typed (10), then end ({kinds}, {knees})")
        # Reordered (the typed pose up one, and back down with the keyboard), retimed.
        click(driver, "id", "ed-up")
        knees = [s["pose"]["left_knee"] for s in js(driver, "return window.rcb4Studio.editor.doc")["steps"][:3]]
        check(knees == [30, 10, -20], f"↑ moves the selected pose up ({knees})")
        js(driver, "document.querySelector('#ed-steps').focus()")  # the selection stays on the pose moved up
        from selenium.webdriver.common.keys import Keys
        from selenium.webdriver.common.action_chains import ActionChains
        ActionChains(driver).key_down(Keys.ALT).send_keys(Keys.ARROW_DOWN).key_up(Keys.ALT).perform()
        doc = js(driver, "return window.rcb4Studio.editor.doc")
        knees = [s["pose"]["left_knee"] for s in doc["steps"][:3]]
        check(knees == [30, -20, 10], f"Alt+↓ (the keyboard) moves it back ({knees})")
        # Dragged: the first pose dropped on the third. WebDriver cannot drag HTML5 draggables in
        # headless Chromium, so the browser's drag events are dispatched to the page's handlers
        # as a drag delivers them (dragstart on the source, dragover and drop on the target).
        drag = """const [from, to] = arguments, dt = new DataTransfer();
                  const at = (i) => document.querySelector(`#ed-steps li[data-step="${i}"]`);
                  at(from).dispatchEvent(new DragEvent('dragstart', { dataTransfer: dt, bubbles: true }));
                  const target = at(to);
                  target.dispatchEvent(new DragEvent('dragover', { dataTransfer: dt, bubbles: true, cancelable: true }));
                  target.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));"""
        js(driver, drag, 0, 2)
        knees = [s["pose"]["left_knee"] for s in js(driver, "return window.rcb4Studio.editor.doc")["steps"][:3]]
        check(knees == [-20, 10, 30], f"the first pose dragged onto the third ({knees})")
        js(driver, drag, 2, 0)
        knees = [s["pose"]["left_knee"] for s in js(driver, "return window.rcb4Studio.editor.doc")["steps"][:3]]
        check(knees == [30, -20, 10], f"and dragged back ({knees})")
        # Retime the second pose.
        click(driver, "css", '#ed-steps li[data-step="1"]')
        js(driver, "const t = document.querySelector('#ed-time'); t.value = 400; t.dispatchEvent(new Event('change'))")
        times = [s["time_ms"] for s in js(driver, "return window.rcb4Studio.editor.doc")["steps"][:3]]
        check(times == [500, 400, 500], f"the second pose retimed to 400 ms ({times})")
        click(driver, "id", "ed-undo")
        click(driver, "id", "ed-redo")
        times = [s["time_ms"] for s in js(driver, "return window.rcb4Studio.editor.doc")["steps"][:3]]
        check(times == [500, 400, 500], f"undo, redo: the same ({times})")
        # A typed value beyond a limit is refused, not taken.
        js(driver, """const n = document.querySelector('.pose-joint[data-joint="head_yaw"] input.num');
                      n.value = 300; n.dispatchEvent(new Event('change'));""")
        check("is outside" in message(driver)
              and js(driver, "return document.querySelector('.pose-joint[data-joint=\"head_yaw\"] input.num').title").startswith("head_yaw: 300°")
              and js(driver, "return window.rcb4Studio.editor.doc.steps[1].pose.head_yaw") == 15,
              f"300° on head_yaw is refused, the pose keeps 15 ({message(driver)!r})")
        # Typed values are checked, never coerced (issue 41): with "live on the robot" ticked, what
        # is no number (letters, an emptied box) marks the box, is not applied, sends nothing, and
        # the robot does not move; a pose time below one board period is refused.
        from selenium.webdriver.common.keys import Keys as K
        click(driver, "id", "ed-live")
        wait_until(lambda: abs((measured(driver, "left_knee") or 0) + 20) < 0.6, timeout=10)
        knee_box = '.pose-joint[data-joint="left_knee"] input.num'
        # (typed with the keyboard, as the trial did: a browser's number box read "4,5" as 45 and "12x" as 12)
        for typed, what in (("4,5", "a decimal comma"), ("12x", "a trailing letter"), ("--5", "letters (not a number)"),
                            ("", "an emptied box")):
            box = driver.find_element(By.CSS_SELECTOR, knee_box)
            js(driver, "arguments[0].scrollIntoView({block: 'center'})", box)
            box.send_keys(K.CONTROL, "a")
            box.send_keys(K.DELETE)
            if typed:
                box.send_keys(typed)
            box.send_keys(K.TAB)
            time.sleep(0.6)  # three board periods and more: a move sent would show
            kept = js(driver, "return window.rcb4Studio.editor.doc.steps[1].pose.left_knee")
            marked = js(driver, f"return document.querySelector('{knee_box}').classList.contains('invalid')")
            check(kept == -20 and abs((measured(driver, "left_knee") or 0) + 20) < 0.6 and (marked or not typed),
                  f"{what} in left_knee with live on: the pose keeps -20, the robot stays, "
                  f"the box {'marked' if typed else 'restored'} ({kept}, {measured(driver, 'left_knee')}, {message(driver)!r})")
        # Mirror with live on: the first mirror asks (the profile's signs are unchecked on a real
        # robot); the mirrored pose is not sent: live goes off and the robot stays where it is.
        kept_pose = js(driver, "return window.rcb4Studio.editor.doc.steps[1].pose")
        js(driver, "window.confirm = () => false")
        click(driver, "id", "ed-mirror")
        check(js(driver, "return window.rcb4Studio.editor.doc.steps[1].pose") == kept_pose and "cancelled" in message(driver),
              f"Mirror, answered No: the pose unchanged ({message(driver)!r})")
        js(driver, "window.confirm = () => true")
        click(driver, "id", "ed-mirror")
        mirrored = js(driver, "return window.rcb4Studio.editor.doc.steps[1].pose")
        time.sleep(0.6)  # three board periods and more: a move sent would show
        check(mirrored != kept_pose and mirrored.get("right_knee") == -20
              and not js(driver, "return document.getElementById('ed-live').checked")
              and abs((measured(driver, "left_knee") or 0) + 20) < 0.6 and abs((measured(driver, "head_yaw") or 0) - 15) < 0.6,
              f"Mirror with live on: mirrored in the editor, live off, the robot unmoved ({mirrored}, {message(driver)!r})")
        click(driver, "id", "ed-undo")
        check(js(driver, "return window.rcb4Studio.editor.doc.steps[1].pose") == kept_pose, "Undo: the pose as it was")
        for typed in ("--1", "", "0", "5", "12x", "4,5", "1005"):  # 1005: not a whole number of 10 ms periods
            box = driver.find_element(By.ID, "ed-time")
            box.send_keys(K.CONTROL, "a")
            box.send_keys(K.DELETE)
            if typed:
                box.send_keys(typed)
            box.send_keys(K.TAB)
            t = js(driver, "return window.rcb4Studio.editor.doc.steps[1].time_ms")
            check(t == 400, f"pose time {typed!r}: refused or ignored, the pose keeps 400 ms ({t}, {message(driver)!r})")
        check("multiple of 10" in message(driver), f"1005 ms: the board's 10 ms period named ({message(driver)!r})")
        # Undo covers a slider drag as one step (issue 41, M1): the motion as it was before the drag.
        depth = js(driver, "return window.rcb4Studio.editor.history.undo")
        js(driver, """const s = document.querySelector('.pose-joint[data-joint="head_yaw"] input[type=range]');
                      for (const v of [16, 17, 18, 19, 20]) { s.value = v; s.dispatchEvent(new Event('input')); }
                      s.dispatchEvent(new Event('change'));""")
        yaw = lambda: js(driver, "return window.rcb4Studio.editor.doc.steps[1].pose.head_yaw")  # noqa: E731
        check(js(driver, "return window.rcb4Studio.editor.history.undo") == depth + 1 and yaw() == 20,
              f"a drag 15 -> 20 is one undo step ({depth} -> {js(driver, 'return window.rcb4Studio.editor.history.undo')}, {yaw()})")
        click(driver, "id", "ed-undo")
        check(yaw() == 15, f"and Undo brings back 15, as before the drag ({yaw()})")
        # Kept in the browser (issue 41, H3/H4): another page of this browser (a reload, a restarted
        # rcb4 ui) opens with the same motion and the same undo history.
        doc_now = js(driver, "return JSON.stringify(window.rcb4Studio.editor.doc)")
        hist = js(driver, "return window.rcb4Studio.editor.history")
        check(hist["dirty"], f"the motion has unsaved changes ({hist})")
        first_tab = driver.current_window_handle
        # another tab (it watches) clicking about in its own editor does not overwrite this tab's motion
        driver.switch_to.new_window("tab")
        driver.get(ui.url)
        wait_until(lambda: js(driver, "return !!(window.rcb4Studio && window.rcb4Studio.editor)"), timeout=20)
        click(driver, "id", "ed-new")
        driver.close()
        driver.switch_to.window(first_tab)
        # this tab reloaded (a reconnect keeps the page; a reload starts it again): the same motion, the same history
        from selenium.common.exceptions import NoAlertPresentException, UnexpectedAlertPresentException
        for _ in range(2):
            try:
                driver.refresh()
                break
            except UnexpectedAlertPresentException:  # the unsaved-changes question: leave all the same
                try:
                    driver.switch_to.alert.accept()
                    break
                except NoAlertPresentException:
                    pass
        wait_until(lambda: js(driver, "return !!(window.rcb4Studio && window.rcb4Studio.editor)"), timeout=20)
        wait_until(lambda: driver.find_element(By.ID, "role").text == "controlling", timeout=10)
        check(js(driver, "return JSON.stringify(window.rcb4Studio.editor.doc)") == doc_now
              and js(driver, "return window.rcb4Studio.editor.history") == hist,
              f"reloaded, the tab has its motion and its history, whatever another tab did "
              f"({js(driver, 'return window.rcb4Studio.editor.history')})")
        click(driver, "css", '#ed-steps li[data-step="1"]')
        # Pulling over unsaved changes asks first; declined, the motion stays.
        js(driver, "window.asked = null; window.savedConfirm = window.confirm; window.confirm = (m) => { window.asked = m; return false; }")
        js(driver, "document.querySelector('#ed-slot').value = 2")
        click(driver, "id", "ed-pull")
        check(js(driver, "return window.asked") and "not saved" in js(driver, "return window.asked")
              and js(driver, "return JSON.stringify(window.rcb4Studio.editor.doc)") == doc_now,
              f"pull over unsaved changes asks, and when declined the motion stays ({js(driver, 'return window.asked')!r})")
        js(driver, "window.confirm = window.savedConfirm; document.querySelector('#ed-slot').value = 10")
        # Previewed in 3D without the robot: the ghost moves at the authored timing.
        click(driver, "id", "ed-preview")
        shown = wait_until(lambda: "preview:" in driver.find_element(By.ID, "ed-result").text and
                           driver.find_element(By.ID, "ed-result").text, timeout=10)
        check(shown, "the preview runs to its end")
        import re
        m = re.search(r"preview: ([\d.]+) s of motion, shown in ([\d.]+) s", shown or "")
        check(m and float(m.group(1)) == 1.4 and 1.4 <= float(m.group(2)) < 1.6,
              f"at the authored timing: 1.4 s of poses shown in 1.4 s ({shown!r})")
        check(abs((measured(driver, "left_knee") or 0) + 20) < 1, "a preview does not move the robot")
        shot(driver, "rcb4-studio.png")

        # Played on the robot from the host at its timing: it ends at the last pose.
        js(driver, "document.querySelector('#message').textContent = ''")
        click(driver, "id", "ed-play")
        said = wait_until(lambda: "played" in message(driver) and message(driver), timeout=15)
        check(said and abs((measured(driver, "left_knee") or 0) - 10) < 1 and abs((measured(driver, "head_yaw") or 0) - 15) < 1,
              f"Play on robot ends at the last pose ({said!r}, knee {measured(driver, 'left_knee')})")
        # Play from here: from the selected pose on (its pose reached first), the poses before it not played.
        slide(driver, "left_knee", -20)
        wait_until(lambda: abs((measured(driver, "left_knee") or 0) + 20) < 0.6, timeout=10)
        poses_at = js(driver, "return window.rcb4Studio.editor.doc.steps.map((s, i) => s && s.pose ? i : -1).filter((i) => i >= 0)")
        js(driver, "window.rcb4Studio.editor.sel = arguments[0]", poses_at[-2])
        js(driver, "document.querySelector('#message').textContent = ''")
        click(driver, "id", "ed-play-here")
        said = wait_until(lambda: "played" in message(driver) and message(driver), timeout=15)
        check(said and "played 2 poses" in said and abs((measured(driver, "left_knee") or 0) - 10) < 1,
              f"Play from here plays the last two of {len(poses_at)} poses and ends at the last ({said!r}, "
              f"knee {measured(driver, 'left_knee')})")
        # Stop while the robot is still on its way into the first pose: it holds there and the
        # motion is not played after all (nothing the user did not ask for).
        slide(driver, "left_knee", -40)
        wait_until(lambda: abs((measured(driver, "left_knee") or 0) + 40) < 0.6, timeout=10)
        js(driver, "document.querySelector('#message').textContent = ''")
        # Play, and Stop 0.2 s later (clicked by the page's script: WebDriver's clicks take longer
        # than the 0.8 s the move from -40° to the first pose's 30° takes at 90°/s).
        js(driver, "document.querySelector('#ed-play').click(); setTimeout(() => document.querySelector('#ed-stop').click(), 200)")
        time.sleep(0.7)
        held = measured(driver, "left_knee") or 0
        time.sleep(2.5)  # longer than the rest of the move and the whole motion would take
        now = measured(driver, "left_knee") or 0
        check(abs(now - held) < 1.5 and held < 20 and "played" not in message(driver)
              and not (js(driver, "return window.rcb4State.motion") or {}).get("running"),
              f"Stop during the move into the first pose: the knee holds ({held:.1f} then {now:.1f}), nothing played ({message(driver)!r})")
        slide(driver, "left_knee", -20)
        wait_until(lambda: abs((measured(driver, "left_knee") or 0) + 20) < 0.6, timeout=10)

        # Pushed to slot 10: the backup named.
        js(driver, "document.querySelector('#ed-slot').value = 10")
        click(driver, "id", "ed-push")
        check(wait_until(lambda: "backup:" in driver.find_element(By.ID, "ed-result").text, timeout=20),
              f"pushed to slot 10, its backup named ({message(driver)!r})")
        backup = driver.find_element(By.ID, "ed-result").text.split("backup: ")[-1]
        check(os.path.exists(backup) and os.path.getsize(backup) == 2048, f"the backup is the old slot ({backup})")
        # The slot table shows it, by its name.
        click(driver, "id", "slots-refresh")
        check(wait_until(lambda: "knee test" in js(driver, "return document.querySelector('#slots tr[data-slot=\"10\"]').textContent"),
                         timeout=10), "the motion table lists slot 10 as 'knee test'")
        # A button assigned on the remote's picture plays it.
        click(driver, "css", "#buttons-panel summary")
        click(driver, "css", '#remote .key[data-button="triangle"]')
        click(driver, "css", '#remote .key[data-button="circle"]')
        js(driver, "document.querySelector('#button-slot').value = 10")
        click(driver, "id", "button-set")
        check(wait_until(lambda: "plays motion 10" in message(driver), timeout=10), f"triangle+circle assigned ({message(driver)!r})")
        slide(driver, "left_knee", 0)
        wait_until(lambda: abs(measured(driver, "left_knee") or 99) < 0.6, timeout=10)
        click(driver, "id", "button-press")
        played = wait_until(lambda: (js(driver, "return window.rcb4State.motion") or {}).get("slot") == 10, timeout=5)
        check(played, "pressing them plays motion 10")
        check(wait_until(lambda: abs((measured(driver, "left_knee") or 0) - 10) < 1
                         and not js(driver, "return window.rcb4State.motion.running"), timeout=10),
              f"and it ends at its last pose ({measured(driver, 'left_knee')})")
        shot(driver, "rcb4-studio-buttons.png")
        # Free all asks first (every servo limp: a standing robot falls); No frees nothing.
        modes = lambda: js(driver, "return window.rcb4State.modes")  # noqa: E731
        js(driver, "window.confirm = () => false")
        click(driver, "id", "free-all")
        time.sleep(0.6)  # three board periods and more: a free sent would show
        check("free" not in modes() and "cancelled" in message(driver),
              f"Free all, answered No: no servo freed ({modes()}, {message(driver)!r})")
        js(driver, "window.confirm = () => true")
        click(driver, "id", "free-all")
        check(wait_until(lambda: set(modes()) == {"free"}, timeout=10), f"Free all, answered Yes: every servo free ({modes()})")
        click(driver, "id", "hold-all")
        check(wait_until(lambda: "free" not in modes(), timeout=10), f"and Hold all holds them ({modes()})")
        # Trims: set live, then kept in ROM.
        click(driver, "css", "#trims-panel summary")
        wait_until(lambda: driver.find_elements(By.CSS_SELECTOR, '#trims input[data-joint="left_knee"]'), timeout=10)
        ram_trim = ("window.rcb4Studio.request({op: 'trims'}).then((r) => arguments[0]("
                    "r.trims.find((t) => t.name === 'left_knee').degrees), (e) => arguments[0]('ERROR ' + e.message))")
        before = driver.execute_async_script(ram_trim)
        for text in ("12x", "4,5"):  # typed: a browser's number box wrote 12 (and 45) into the servo's RAM
            box = driver.find_element(By.CSS_SELECTOR, '#trims input[data-joint="left_knee"]')
            box.send_keys(K.CONTROL, "a")
            box.send_keys(text, K.TAB)
            check("is not a number" in message(driver) and driver.execute_async_script(ram_trim) == before,
                  f"{text!r} as a trim: refused, the board's trim unchanged ({before}; {message(driver)!r})")
        js(driver, """const n = document.querySelector('#trims input[data-joint="left_knee"]');
                      n.value = 1.5; n.dispatchEvent(new Event('change'));""")
        check(wait_until(lambda: "left_knee trim 1.5" in message(driver), timeout=10), f"a trim set live ({message(driver)!r})")
        click(driver, "id", "trims-persist")
        check(wait_until(lambda: "trims kept in ROM" in message(driver), timeout=10), f"and kept in ROM ({message(driver)!r})")
        # A motion saved as the YAML file the tool reads.
        yaml_text = driver.execute_async_script(
            "window.rcb4Studio.request({op: 'motion_check', text: JSON.stringify(window.rcb4Studio.editor.doc)})"
            ".then((r) => arguments[0](r.yaml), (e) => arguments[0]('ERROR ' + e.message))")
        with open(os.path.join(poses, "saved.yaml"), "w") as f:
            f.write(yaml_text)
    finally:
        driver.quit()
        ui.stop()

    # On the board, through the tool.
    rc, out, err = run("--json", "--device", dev, "trim", "get", "left_knee")
    t = json.loads(out)[0] if rc == 0 else {}
    check(abs(t.get("degrees", 0) - 1.5) < 0.05 and abs((t.get("rom_degrees") or 0) - 1.5) < 0.05,
          f"rcb4 trim get: left_knee 1.5 in RAM and ROM ({t})")
    rc, out, err = run("--device", dev, "motion", "push", os.path.join(poses, "saved.yaml"), "10", "--dry-run")
    check(rc == 0 and "would write 150 bytes" in out, f"the saved YAML is a motion file the tool pushes ({rc}: {out[:80]!r} {err.strip()!r})")
    rc, out, err = run("--device", dev, "motion", "show", "10")
    consts = out.count("CONST")
    check(rc == 0 and consts == 3 and "RETURN" in out, f"motion show 10: three CONST frames and a RETURN ({consts}; {err.strip()!r})")
    rc, out, err = run("--device", dev, "motion", "play", "10", "--wait", "--timeout", "10")
    j = joints_on(dev)
    check(rc == 0 and abs(j["left_knee"]["degrees"] - 10) < 1 and abs(j["head_yaw"]["degrees"] - 15) < 1,
          f"motion play 10 --wait ends at the last pose ({j.get('left_knee', {}).get('degrees')}, {err.strip()!r})")

    # Pulled back into the editor: the same poses.
    ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
    driver = browser()
    try:
        driver.get(ui.url)
        wait_until(lambda: js(driver, "return !!(window.rcb4Studio && window.rcb4Studio.editor)"), timeout=20)
        js(driver, "document.querySelector('#ed-slot').value = 10")
        click(driver, "id", "ed-pull")
        wait_until(lambda: "in the editor" in message(driver), timeout=10)
        doc = js(driver, "return window.rcb4Studio.editor.doc")
        poses_back = [s for s in doc["steps"] if isinstance(s, dict) and "pose" in s]
        check(len(poses_back) == 3 and [round(p["pose"]["left_knee"]) for p in poses_back] == [30, -20, 10]
              and [p["time_ms"] for p in poses_back] == [500, 400, 500] and doc["name"] == "knee test",
              f"pulled back: the same three poses and times, and the name ({poses_back}, {doc.get('name')})")
        wait_until(lambda: js(driver, "return window.rcb4Studio.view && window.rcb4Studio.view.stats.frames") > 0)
        shot(driver, "rcb4-studio-editor.png")
        # The ROM: backed up through the page, and a restore checked as the tool checks it.
        r = driver.execute_async_script("window.rcb4Studio.request({op: 'rom_backup'}).then(arguments[0], "
                                        "(e) => arguments[0]({error: e.message}))")
        check(r.get("bytes") == 262144 and len(r.get("crc32", "")) == 8, f"rom_backup: 256 KiB and its CRC-32 ({r.get('error')})")
        import base64
        import binascii
        image = base64.b64decode(r["base64"])
        check(f"{binascii.crc32(image):08x}" == r["crc32"], "the CRC-32 is the image's")
        erased = os.path.join(poses, "erased.bin")
        with open(erased, "wb") as f:
            f.write(b"\xff" * 262144)
        same = os.path.join(poses, "same.bin")
        with open(same, "wb") as f:
            f.write(image)
        click(driver, "css", "#rom-panel summary")
        for path, want in ((erased, "no "), (same, "already was that image")):
            js(driver, "document.querySelector('#message').textContent = ''; document.querySelector('#rom-file').hidden = false")
            driver.find_element("id", "rom-file").send_keys(path)
            said = wait_until(lambda: ("restore" in message(driver).lower() or "image" in message(driver)
                                       or "boot" in message(driver)) and message(driver), timeout=30)
            check(said and want in said, f"restore of {os.path.basename(path)} through the page: {said!r}")
        # Erase asks first (declined: nothing erased); accepted, its bytes are backed up, and that
        # .bin goes back into the slot through Open… (issue 41, M8).
        click(driver, "id", "slots-refresh")
        row10 = lambda: js(driver, "const r = document.querySelector('#slots tr[data-slot=\"10\"]'); return r ? r.textContent : ''")  # noqa: E731
        wait_until(lambda: "free" not in row10(), timeout=10)
        js(driver, "window.savedConfirm = window.confirm; window.confirm = () => false")
        click(driver, "css", '#slots tr[data-slot="10"] button[title^="erase"]')
        check(wait_until(lambda: "erase cancelled" in message(driver), timeout=5) and "free" not in row10(),
              f"erase asks first; declined, the slot stays ({row10()!r})")
        js(driver, "window.confirm = () => true")
        click(driver, "css", '#slots tr[data-slot="10"] button[title^="erase"]')
        said = wait_until(lambda: "erased; its bytes are in" in message(driver) and message(driver), timeout=10)
        kept = said.split("its bytes are in ")[-1].strip() if said else ""
        check(os.path.exists(kept) and wait_until(lambda: "free" in row10(), timeout=10),
              f"accepted: erased, its bytes kept ({said!r})")
        js(driver, "document.querySelector('#ed-slot').value = 10; document.querySelector('#ed-file').hidden = false")
        driver.find_element(By.ID, "ed-file").send_keys(kept)
        back = wait_until(lambda: "is back in slot 10" in message(driver) and message(driver), timeout=20)
        click(driver, "id", "slots-refresh")
        check(back and wait_until(lambda: "free" not in row10(), timeout=10),
              f"its .bin opened in the editor goes back into slot 10 ({back!r}, {row10()!r}, {message(driver)!r})")
        js(driver, "window.confirm = window.savedConfirm; document.querySelector('#ed-file').hidden = true")
        # A second page watching is told why its controls are off.
        second = browser()
        try:
            second.get(ui.url)
            note = wait_until(lambda: second.find_element("id", "role-note").text, timeout=10)
            check(note and "Another page controls the robot" in note, f"a watching page says why its controls are off ({note!r})")
        finally:
            second.quit()
    finally:
        driver.quit()
        ui.stop()
finish()
