#!/usr/bin/env python3
# The studio's safety rules where a newcomer's trial (2026-11-29) saw the robot move unasked, in
# Debian's headless Chromium over `rcb4 serve --pty`: Free all, Hold all and Stop motion in the
# middle of a motion played from the host or of a ROM motion stop that motion first, and the
# servos stay as asked (never powered again by the motion's next pose); a motion loaded (Pull) with
# "live" ticked turns live off and moves nothing; "play over" off the board's output period is
# refused, on the page and by the server. What the robot does is read from the page's state
# (the board's modes, angles and targets as the studio reads them).
# Usage: studio_safety_test.py RCB4
# SPDX-License-Identifier: BSL-1.0
import os
import sys
import tempfile
import time

from checks import check, finish
from uihelp import tools

RCB4 = sys.argv[1]
run, serve, Ui, browser, wait_until, joints_on = tools(RCB4)

# A motion long enough to act in the middle of: the shoulders' pitch 60, -60, 60 (the right one the
# other way), 2.55 s each.
LONG = """robot: KHR-3HV
name: swing
period_ms: 10
steps:
  - pose: {left_shoulder_pitch: 60, right_shoulder_pitch: -60}
    time_ms: 2550
  - pose: {left_shoulder_pitch: -60, right_shoulder_pitch: 60}
    time_ms: 2550
  - pose: {left_shoulder_pitch: 60, right_shoulder_pitch: -60}
    time_ms: 2550
  - end
"""


def js(driver, code, *args):
    return driver.execute_script(code, *args)


def click(driver, what):
    js(driver, "document.getElementById(arguments[0]).click()", what)


def message(driver):
    return js(driver, "return document.querySelector('#message').textContent")


def state(driver, key):
    return js(driver, "return window.rcb4State && window.rcb4State[arguments[0]]", key)


def joint(driver, name, key="angles"):
    i = NAMES.index(name)
    values = state(driver, key)
    return values[i] if values else None


def still_for(driver, seconds, what):
    """The board's targets and modes the same over @p seconds (a motion running on would change them)."""
    time.sleep(0.3)  # the action's own effect read back first (the page gets the board's state 30 times a second)
    t0, m0, a0 = state(driver, "targets"), state(driver, "modes"), state(driver, "angles")
    time.sleep(seconds)
    t1, m1, a1 = state(driver, "targets"), state(driver, "modes"), state(driver, "angles")
    moved = [(NAMES[i], x, y) for i, (x, y) in enumerate(zip(a0, a1)) if x is None or y is None or abs(x - y) > 0.5]
    # (a target turning unknown is the board holding: a motion running on would give new targets)
    retargeted = [(NAMES[i], x, y) for i, (x, y) in enumerate(zip(t0, t1)) if x != y and y is not None]
    check(m0 == m1 and not moved and not retargeted,
          f"{what}: nothing moved or changed power for {seconds} s after ({m1[:3]}…, moved {moved}, "
          f"targets {retargeted})")


NAMES = None
with serve() as dev, tempfile.TemporaryDirectory() as poses:
    os.environ["RCB4_SLOT_NAMES"] = os.path.join(poses, "slot-names.yaml")
    swing = os.path.join(poses, "swing.yaml")
    with open(swing, "w") as f:
        f.write(LONG)
    with open(os.path.join(poses, "wave.yaml"), "w") as f:
        f.write("robot: KHR-3HV\ntime_ms: 500\njoints:\n  head_yaw: 30\n")
    ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
    driver = browser()
    try:
        driver.get(ui.url)
        check(wait_until(lambda: js(driver, "return !!(window.rcb4Studio && window.rcb4Studio.editor)"), timeout=20)
              and wait_until(lambda: js(driver, "return document.querySelector('#role').textContent") == "controlling"),
              "the studio is up and controls the robot")
        NAMES = js(driver, "return window.rcb4Studio.hello.joints.map((j) => j.name)")
        js(driver, "window.confirm = () => true")  # Free all asks; Pull over unsaved changes asks
        rc, out, err = run("--device", dev, "motion", "push", swing, "12")  # through the studio's share
        check(rc == 0, f"the long motion pushed to slot 12 through the studio ({rc}: {err.strip()[-200:]!r})")

        # 1. Free all in the middle of a ROM motion: the motion stops first, the servos stay free.
        js(driver, "window.rcb4Studio.request({op: 'refresh'})")
        check(wait_until(lambda: js(driver, "return !!document.querySelector('#motions li[data-motion=\"12\"]')"), timeout=10),
              "slot 12 is listed")
        js(driver, """[...document.querySelectorAll('#motions li[data-motion="12"] button')]
                      .find((b) => b.textContent === 'Play').click()""")
        check(wait_until(lambda: (state(driver, "motion") or {}).get("running"), timeout=5), "motion 12 plays")
        time.sleep(1.0)
        click(driver, "free-all")
        check(wait_until(lambda: set(state(driver, "modes") or []) == {"free"}, timeout=5)
              and "stopped first" in message(driver),
              f"Free all during a ROM motion: every servo free, the motion stopped first ({message(driver)!r})")
        check(not (state(driver, "motion") or {}).get("running"), "and motion 12 no longer runs")
        still_for(driver, 1.5, "Free all during a ROM motion")
        click(driver, "hold-all")
        wait_until(lambda: "free" not in (state(driver, "modes") or ["free"]), timeout=5)
        # Resume would run motion 12 on from where it stopped: it asks first; No leaves it stopped.
        js(driver, "window.confirm = () => false")
        click(driver, "motions-resume")
        check(wait_until(lambda: "resume cancelled" in message(driver), timeout=5)
              and (state(driver, "motion") or {}).get("suspended") and not (state(driver, "motion") or {}).get("running"),
              f"Resume after a motion stopped part way asks; No: it stays stopped ({message(driver)!r})")
        still_for(driver, 1.0, "Resume answered No")
        click(driver, "motion-resume")  # the slot table's Resume: the same question
        check(wait_until(lambda: "resume cancelled" in message(driver), timeout=5)
              and not (state(driver, "motion") or {}).get("running"),
              f"the slot table's Resume asks too; No: it stays stopped ({message(driver)!r})")
        still_for(driver, 1.0, "the table's Resume answered No")
        js(driver, "window.confirm = () => true")

        # Stop motion in the middle of a ROM motion's pose: the pose does not run on (the board's own
        # stop would let it finish, up to 2.55 s): every joint holds where it is at once.
        js(driver, """[...document.querySelectorAll('#motions li[data-motion="12"] button')]
                      .find((b) => b.textContent === 'Play').click()""")
        check(wait_until(lambda: (state(driver, "motion") or {}).get("running"), timeout=5), "motion 12 plays again")
        time.sleep(1.2)
        click(driver, "motion-stop")
        check(wait_until(lambda: "every joint holds where it is" in message(driver), timeout=5),
              f"Stop motion in the middle of a pose: said ({message(driver)!r})")
        still_for(driver, 1.5, "Stop motion during a ROM motion's pose")

        # One joint freed in the middle of a ROM motion's pose: the motion stops, and the joints not
        # named hold where they are (the right shoulder was swinging the other way).
        js(driver, """[...document.querySelectorAll('#motions li[data-motion="12"] button')]
                      .find((b) => b.textContent === 'Play').click()""")
        check(wait_until(lambda: (state(driver, "motion") or {}).get("running"), timeout=5), "motion 12 plays again")
        time.sleep(1.2)
        said = driver.execute_async_script(
            "window.rcb4Studio.request({op: 'free', joints: ['left_shoulder_pitch']})"
            ".then((r) => arguments[0](JSON.stringify(r)), (e) => arguments[0](e.message))")
        check('"motion_stopped":true' in said, f"the left shoulder freed: the motion stopped first ({said})")
        still_for(driver, 1.5, "one joint freed during a ROM motion's pose")
        check(joint(driver, "right_shoulder_pitch", "targets") is None or "hold" == state(driver, "modes")[NAMES.index("right_shoulder_pitch")],
              f"the right shoulder holds ({state(driver, 'modes')[NAMES.index('right_shoulder_pitch')]})")
        click(driver, "hold-all")
        wait_until(lambda: "free" not in (state(driver, "modes") or ["free"]), timeout=5)

        # 2. A motion played from the host: Free all, then Hold all, then Stop motion, each in its middle.
        js(driver, "document.querySelector('#ed-file').hidden = false")
        driver.find_element("id", "ed-file").send_keys(swing)
        check(wait_until(lambda: "swing.yaml: opened" in message(driver), timeout=10), f"the motion opened ({message(driver)!r})")
        js(driver, "document.querySelector('#ed-file').hidden = true")
        for button, modes, said in (("free-all", {"free"}, "stopped first"), ("hold-all", None, "stopped first"),
                                    ("motion-stop", None, "and the play from the host")):
            click(driver, "ed-play")
            check(wait_until(lambda: "playing on the robot from the host" in message(driver), timeout=10),
                  f"Play on robot ({message(driver)!r})")
            time.sleep(1.5)  # the first pose reached, the second under way
            click(driver, button)
            check(wait_until(lambda: said in message(driver), timeout=5)
                  and (modes is None or wait_until(lambda: set(state(driver, "modes") or []) == modes, timeout=5)),
                  f"{button} while the host plays: the play stopped first, said ({message(driver)!r})")
            still_for(driver, 1.5, f"{button} during a play from the host")
            check(not js(driver, "return window.rcb4Studio.editor.playing"), f"{button}: the editor knows the play ended")
            if button == "free-all":
                click(driver, "hold-all")
                wait_until(lambda: "free" not in (state(driver, "modes") or ["free"]), timeout=5)

        # 3. Pull with live ticked: live goes off, the robot stays where it is.
        js(driver, "window.rcb4Studio.editor.sel = 0")
        click(driver, "ed-live")  # the selected pose goes to the robot (left_shoulder_pitch 60)
        check(wait_until(lambda: abs((joint(driver, "left_shoulder_pitch") or 0) - 60) < 1, timeout=10),
              "live on: the robot takes the selected pose")
        hips = (joint(driver, "left_hip_pitch"), joint(driver, "right_hip_pitch"))
        js(driver, "document.getElementById('ed-slot').value = '3'")  # the demo's bow: hips and knees
        click(driver, "ed-pull")
        check(wait_until(lambda: "motion 3 in the editor" in message(driver) and "live is now off" in message(driver), timeout=10),
              f"slot 3 pulled ({message(driver)!r})")
        time.sleep(0.8)  # more than three board periods: a pose sent would show
        check(not js(driver, "return document.getElementById('ed-live').checked")
              and (joint(driver, "left_hip_pitch"), joint(driver, "right_hip_pitch")) == hips
              and abs((joint(driver, "left_shoulder_pitch") or 0) - 60) < 1,
              f"Pull with live ticked: live off, the robot unmoved (hips {hips}, {message(driver)!r})")
        # Live on again (the robot takes the bow's first pose), then Undo across the Pull: the other
        # motion comes back, live goes off, and the robot stays in the bow's pose.
        click(driver, "ed-live")
        check(wait_until(lambda: abs((joint(driver, "left_hip_pitch") or 0) - 33.75) < 1, timeout=10),
              "live on: the robot takes the bow's first pose")
        click(driver, "ed-undo")
        time.sleep(0.8)
        check(not js(driver, "return document.getElementById('ed-live').checked")
              and abs((joint(driver, "left_hip_pitch") or 0) - 33.75) < 1 and "live is now off" in message(driver),
              f"Undo across a Pull with live ticked: live off, the robot unmoved ({message(driver)!r})")

        # The slot box takes digits alone (+3 is no slot); Push over another motion's slot asks.
        slot_box = driver.find_element("id", "ed-slot")
        slot_box.clear()
        slot_box.send_keys("+3")
        click(driver, "ed-push")
        check("digits only" in message(driver), f"'+3' as a slot: refused ({message(driver)!r})")
        slot_box.clear()
        slot_box.send_keys("3")
        js(driver, "window.confirm = () => false")
        click(driver, "ed-push")
        check(wait_until(lambda: "push cancelled" in message(driver), timeout=5),
              f"Push over slot 3 (the bow) asks first; No: nothing written ({message(driver)!r})")
        js(driver, "window.confirm = () => true")
        rc, out, err = run("--json", "--device", dev, "motion", "list")
        check(rc == 0 and '"bow"' in out, f"slot 3 still holds the bow ({rc}: {out[:200]!r})")

        # 4. "play over" off the board's 10 ms period: refused on the page and by the server.
        box = driver.find_element("id", "pose-ms")
        box.clear()
        box.send_keys("1005")
        yaw = joint(driver, "head_yaw", "targets")
        js(driver, "document.querySelector('#poses li[data-pose=\"wave\"] button.play').click()")
        time.sleep(0.5)
        check("not a multiple of 10" in message(driver) and joint(driver, "head_yaw", "targets") == yaw,
              f"play over 1005 ms: refused on the page, nothing moved ({message(driver)!r})")
        said = driver.execute_async_script(
            "window.rcb4Studio.request({op: 'play_pose', name: 'wave', ms: 1005})"
            ".then(() => arguments[0]('played'), (e) => arguments[0](e.message))")
        check("not a whole number of this board's 10 ms output periods" in said,
              f"and by the server, whatever a page sends ({said!r})")

        # 5. The robot's panel kept in view (the default) or scrolled away with the page, remembered;
        # what is scrolled to lands below the panel while it is kept in view.
        panel = "getComputedStyle(document.querySelector('.studio > .panel:first-child')).position"
        pad = "parseFloat(document.documentElement.style.scrollPaddingTop)"
        height = "document.querySelector('.studio > .panel:first-child').offsetHeight"
        check(js(driver, f"return {panel}") == "sticky" and js(driver, f"return {pad}") > js(driver, f"return {height}"),
              "the robot's panel is kept in view, and scrolling stops below it")
        click(driver, "pin-robot")
        check(js(driver, f"return {panel}") == "static" and js(driver, f"return {pad}") < js(driver, f"return {height}")
              and js(driver, "return localStorage.getItem('rcb4-studio-unpinned')") == "1",
              "unticked: it scrolls away with the page, and the browser remembers")
        click(driver, "pin-robot")
    finally:
        driver.quit()
        rc = ui.stop()
    check(rc == 0, f"rcb4 ui ends cleanly on SIGINT ({rc})")

finish()
