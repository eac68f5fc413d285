#!/usr/bin/env python3
# The pose work HTH4 users do every day, in the studio (issue 41 item 8), in Debian's headless
# Chromium over `rcb4 serve --pty`: a pose mirrored left <-> right has the paired joints swapped
# with their signs right (KHR-3HV: head yaw negated, pitch, roll and yaw of the limbs kept, as
# robot/mirror.hpp works out from the body); a limb copied onto the other; Home; a joint "as in the
# pose before"; a pose copied in one tab and pasted in another tab's motion; undo after each; and
# with "live on the robot" off, none of it moves the robot (read through the studio's share); a
# pose whose centre of mass lies outside its feet marked as the motion is edited.
# Usage: studio_poses_test.py RCB4 [SCREENSHOT_DIR]
# SPDX-License-Identifier: BSL-1.0
import json
import os
import re
import sys
import tempfile
import time

from checks import check, finish
from uihelp import tools

RCB4 = sys.argv[1]
run, serve, Ui, browser, wait_until, joints_on = tools(RCB4)


def js(driver, code, *args):
    return driver.execute_script(code, *args)


def click(driver, what):
    js(driver, "document.getElementById(arguments[0]).click()", what)


def typed(driver, joint, degrees):
    js(driver, """const n = document.querySelector(`.pose-joint[data-joint="${arguments[0]}"] input.num`);
                  n.value = arguments[1]; n.dispatchEvent(new Event('change'));""", joint, degrees)


def pose(driver, step=None):
    return js(driver, """const e = window.rcb4Studio.editor; const s = e.doc.steps[arguments[0] ?? e.sel];
                         return s && s.pose ? s.pose : null;""", step)


def message(driver):
    return js(driver, "return document.querySelector('#message').textContent")


with serve() as dev, tempfile.TemporaryDirectory() as poses:
    os.environ["RCB4_SLOT_NAMES"] = os.path.join(poses, "slot-names.yaml")  # not the user's own
    with open(os.path.join(poses, "crouch.yaml"), "w") as f:  # saved poses, as `rcb4 pose capture` writes them
        f.write("robot: KHR-3HV\ntime_ms: 800\njoints:\n  left_knee: 60\n  right_knee: -60\n")
    with open(os.path.join(poses, "broken.yaml"), "w") as f:
        f.write("robot: KHR-3HV\njoints:\n  left_knee: 400\n")
    ui = Ui("--device", dev, "ui", "--listen", "127.0.0.1:0", "--poses", poses)
    driver = browser()
    try:
        driver.get(ui.url)
        check(wait_until(lambda: js(driver, "return !!(window.rcb4Studio && window.rcb4Studio.editor)"), timeout=20),
              "the studio is up")
        hello = js(driver, "return window.rcb4Studio.hello")
        mirror = {j["name"]: j["mirror"] for j in hello["joints"]}
        check(mirror["head_yaw"] == {"joint": "head_yaw", "sign": -1, "side": "middle"}
              and mirror["left_knee"] == {"joint": "right_knee", "sign": 1, "side": "left"}
              and mirror["right_shoulder_roll"] == {"joint": "left_shoulder_roll", "sign": 1, "side": "right"},
              f"hello gives each joint its mirror image ({mirror['head_yaw']}, {mirror['left_knee']})")
        before = {n: j["degrees"] for n, j in joints_on(dev).items()}

        click(driver, "ed-new")
        js(driver, "document.querySelector('#ed-kind').value = 'pose'")
        click(driver, "ed-add")  # a pose of every joint, from the robot as it stands
        for joint, deg in (("head_yaw", 20), ("left_knee", 45), ("right_knee", 10), ("left_shoulder_roll", 30),
                           ("right_shoulder_roll", -5), ("left_elbow_yaw", 12)):
            typed(driver, joint, deg)
        p0 = pose(driver)
        js(driver, "window.confirm = () => true")  # the first mirror of a page asks (the profile's senses are unchecked)
        click(driver, "ed-mirror")
        p = pose(driver)
        check(p["head_yaw"] == -20 and p["left_knee"] == 10 and p["right_knee"] == 45
              and p["left_shoulder_roll"] == -5 and p["right_shoulder_roll"] == 30 and p["right_elbow_yaw"] == 12
              and p["left_elbow_yaw"] == p0["right_elbow_yaw"],
              f"Mirror: pairs swapped, head yaw negated ({json.dumps(p)})")
        click(driver, "ed-undo")
        check(pose(driver) == p0, "one Undo: the pose as typed")
        click(driver, "ed-l2r")
        p = pose(driver)
        check(p["right_knee"] == 45 and p["left_knee"] == 45 and p["right_shoulder_roll"] == 30
              and p["head_yaw"] == 20, f"Left → right: the left limbs onto the right, the middle kept ({json.dumps(p)})")
        click(driver, "ed-undo")
        click(driver, "ed-r2l")
        p = pose(driver)
        check(p["left_knee"] == 10 and p["left_shoulder_roll"] == -5 and p["right_knee"] == 10,
              f"Right → left ({json.dumps(p)})")
        click(driver, "ed-undo")
        for n in [j["name"] for j in hello["joints"] if j["name"].startswith("right_")]:  # a pose of left joints only
            js(driver, "document.querySelector(`.pose-joint[data-joint=\"${arguments[0]}\"] input[type=checkbox]`).click()", n)
        left_only = pose(driver)
        click(driver, "ed-r2l")
        check(pose(driver) == left_only and "no right joint" in message(driver),
              f"Right → left on a pose with no right joint changes nothing and says so ({message(driver)!r})")
        for _ in range(len(p0) - len(left_only)):  # one undo per joint unticked
            click(driver, "ed-undo")
        check(pose(driver) == p0, "and Undo brings the whole pose back")

        # A second pose: Home, then one joint as in the pose before.
        click(driver, "ed-add")
        typed(driver, "right_knee", 30)
        click(driver, "ed-home")
        p = pose(driver)
        check(p and all(v == 0 for v in p.values()), f"Home: every joint of the pose at 0° ({json.dumps(p)})")
        js(driver, """document.querySelector('.pose-joint[data-joint="left_knee"] .as-before').click()""")
        p = pose(driver)
        check(p["left_knee"] == 45 and p["right_knee"] == 0, f"↶ left_knee as in the pose before: 45 ({p['left_knee']})")

        # Scrub the timeline: pressed at its middle, the ghost is between the two poses (500 ms each:
        # the end of the first, right_knee 10 -> 0); a preview from step 2 starts there.
        def pointer(kind, fraction):
            js(driver, """const t = document.getElementById('ed-timeline'), r = t.getBoundingClientRect();
                          t.dispatchEvent(new PointerEvent(arguments[0], {bubbles: true, pointerId: 1,
                            clientX: r.left + r.width * arguments[1], clientY: r.top + r.height / 2}));""", kind, fraction)
            return js(driver, "return window.rcb4Studio.view.ghost")

        g = pointer("pointerdown", 0.25)
        check(g and abs(g["right_knee"] - 5) < 1 and abs(g["left_knee"] - 22.5) < 1,
              f"the timeline pressed a quarter in: the ghost half way into pose 1 ({g and (g['right_knee'], g['left_knee'])})")
        g = pointer("pointermove", 0.75)
        check(g and abs(g["right_knee"] - 5) < 1 and abs(g["left_knee"] - 45) < 1 and abs(g["head_yaw"] - 10) < 1,
              f"dragged to three quarters: half way from pose 1 to pose 2 ({g and (g['right_knee'], g['head_yaw'])})")
        pointer("pointerup", 0.75)
        js(driver, "window.rcb4Studio.editor.sel = 1")
        click(driver, "ed-preview-here")
        start = js(driver, "return window.rcb4Studio.editor.previewFrom")
        g = wait_until(lambda: js(driver, "const g = window.rcb4Studio.view.ghost; return g && g.left_knee === 45 && g")
                       , timeout=3)
        check(start == 500 and g and g["left_knee"] == 45,
              f"From here: the preview starts where the board reaches step 2, 500 ms in ({start}, {g and g['right_knee']})")
        click(driver, "ed-stop")

        # Copy in this tab, paste into another tab's motion.
        js(driver, "window.rcb4Studio.editor.sel = 1")
        click(driver, "ed-copy")
        first = driver.current_window_handle
        driver.switch_to.new_window("tab")
        driver.get(ui.url)
        check(wait_until(lambda: js(driver, "return !!(window.rcb4Studio && window.rcb4Studio.editor)"), timeout=20),
              "a second tab")
        click(driver, "ed-new")
        click(driver, "ed-paste")
        steps = js(driver, "return window.rcb4Studio.editor.doc.steps")
        pasted = [s for s in steps if isinstance(s, dict) and "pose" in s]
        check(len(pasted) == 1 and pasted[0]["pose"] == p, f"the other tab pastes the copied pose ({len(pasted)} poses)")
        driver.close()
        driver.switch_to.window(first)

        # Every other kind of step from a form, nothing typed as JSON: a loop with a counter, a
        # button branch clicked on the remote's picture, a speed; pushed, and the board has it.
        js(driver, "window.confirm = () => true")  # New over an unsaved motion asks first
        click(driver, "ed-new")

        def add(kind):
            js(driver, "document.querySelector('#ed-kind').value = arguments[0]", kind)
            click(driver, "ed-add")

        def field(fid, value):
            js(driver, """const f = document.getElementById(arguments[0]); f.value = arguments[1];
                          f.dispatchEvent(new Event('change'));""", fid, value)

        add("label")
        field("f-label", "again")
        click(driver, "ed-step-apply")
        add("set_counter")
        # Typed with the keyboard, as the trial did: each is refused as typed (a browser number box
        # read "12x" as 12 and "4,5" as 45), the box marked with the reason, the step unchanged.
        for text in ("abc", "12x", "4,5", "1e9", "2.5"):
            box = driver.find_element("id", "f-count")
            box.clear()
            box.send_keys(text)
            marked_as_typed = js(driver, "return document.getElementById('f-count').classList.contains('invalid')")
            click(driver, "ed-step-apply")
            bad = message(driver)
            check("nothing changed" in bad and marked_as_typed
                  and js(driver, "return document.getElementById('f-count').title").startswith("the count")
                  and js(driver, "return window.rcb4Studio.editor.doc.steps[1]") == {"set_counter": 3},
                  f"{text!r} in the count: marked as typed, said, the step unchanged ({bad!r})")
        field("f-count", "4")
        click(driver, "ed-step-apply")
        add("pose")
        add("if_buttons")
        js(driver, "document.querySelectorAll('#ed-detail .key[data-button=up]')[0].click()")  # the default 'up' off
        for b in ("s1", "circle"):
            js(driver, "document.querySelector(`#ed-detail .key[data-button=${arguments[0]}]`).click()", b)
        field("f-goto", "again")
        click(driver, "ed-step-apply")
        add("loop")
        field("f-goto", "again")
        click(driver, "ed-step-apply")
        add("if_ram")  # a RAM test: an AD sensor branch, its address typed as in the docs
        field("f-address", "0x0050")
        field("f-compare", "at_least")
        field("f-value", "600")
        field("f-goto", "again")
        click(driver, "ed-step-apply")
        add("speed")
        js(driver, "document.querySelector('#ed-detail .param-target').value = 'legs'")
        speed_box = driver.find_element("css selector", "#ed-detail .param-value")
        speed_box.clear()
        speed_box.send_keys("12x")
        click(driver, "ed-step-apply")
        check("nothing changed" in message(driver)
              and js(driver, "const s = window.rcb4Studio.editor.doc.steps; return s[s.length - 2]") == {"speed": {"all": 127}},
              f"'12x' as a speed: refused, the step keeps all 127 ({message(driver)!r})")
        speed_box.clear()
        speed_box.send_keys("60")
        click(driver, "ed-step-apply")
        check("speed legs 60" in js(driver, "return document.querySelector('#ed-steps').textContent"),
              "the speed step is listed in words (speed legs 60), never as JSON")
        steps = js(driver, "return window.rcb4Studio.editor.doc.steps")
        shape = [s if not (isinstance(s, dict) and "pose" in s) else "pose" for s in steps]
        check(shape == [{"label": "again"}, {"set_counter": 4}, "pose", {"if_buttons": "s1+circle", "goto": "again"},
                        {"loop": "again"}, {"if_ram": 80, "size": 2, "at_least": 600, "goto": "again"},
                        {"speed": {"legs": 60}}, "end"],
              f"the steps as the forms made them ({shape})")
        field("ed-slot", "11")
        click(driver, "ed-push")
        check(wait_until(lambda: "slot 11" in message(driver) or "backup" in message(driver), timeout=20),
              f"pushed to slot 11 ({message(driver)!r})")
        rc, out, err = run("--device", dev, "motion", "show", "11")
        check(rc == 0 and "MOV literal {04}" in out and "CONST 20 servos" in out,
              f"rcb4 motion show 11, through the studio, lists it ({rc}, {out[:300]!r} {err.strip()!r})")

        # The flowchart: a motion with a button branch and a loop built by clicking and dragging:
        # blocks added, each jump's handle dragged onto the block it goes to (a label appears there).
        click(driver, "ed-new")
        for kind in ("pose", "if_buttons", "pose", "loop"):
            add(kind)
        flow = lambda: js(driver, """return [...document.querySelectorAll('#ed-flow .flow-block')].map(
            (g) => ({ step: Number(g.dataset.step), cls: g.getAttribute('class'), title: g.querySelector('title').textContent }));""")
        blocks = flow()
        bad = [b["step"] for b in blocks if " bad" in b["cls"]]
        check(len(blocks) == 5 and bad == [1, 3],
              f"a jump to no label is marked as it is built, not at push ({bad}: {[b['title'] for b in blocks if ' bad' in b['cls']]})")

        summary = js(driver, "return document.getElementById('ed-summary').textContent")
        check("does not play: no label called again" in summary, f"and the summary says it does not play ({summary!r})")

        def drag_wire(src, dst):
            js(driver, """const svg = document.getElementById('ed-flow');
                const exit = svg.querySelector(`.flow-exit[data-step="${arguments[0]}"]`);
                const to = svg.querySelector(`.flow-block[data-step="${arguments[1]}"]`).getBoundingClientRect();
                const from = exit.getBoundingClientRect();
                const at = (x, y) => ({ bubbles: true, pointerId: 1, clientX: x, clientY: y });
                exit.dispatchEvent(new PointerEvent('pointerdown', at(from.x + 3, from.y + 3)));
                svg.dispatchEvent(new PointerEvent('pointermove', at(to.x + 40, to.y + 10)));
                svg.dispatchEvent(new PointerEvent('pointerup', at(to.x + 40, to.y + 10)));""", src, dst)

        drag_wire(1, 2)  # the branch: when held, on to the second pose
        drag_wire(4, 0)  # the loop: back to the first pose (its label becomes step 0)
        steps = js(driver, "return window.rcb4Studio.editor.doc.steps")
        shape = [s if not (isinstance(s, dict) and "pose" in s) else "pose" for s in steps]
        check(shape == [{"label": "L2"}, "pose", {"if_buttons": "up", "goto": "L1"}, {"label": "L1"}, "pose",
                        {"loop": "L2"}, "end"], f"dragging the handles connected both jumps ({shape})")
        blocks = flow()
        warn = [b["title"].split("\n", 1)[-1] for b in blocks if " warn" in b["cls"]]
        check(not [b for b in blocks if " bad" in b["cls"]] and any("no counter is set" in w for w in warn),
              f"nothing dangles; the loop without a counter is marked ({warn})")
        js(driver, "window.rcb4Studio.editor.sel = 0")
        add("set_counter")  # after the label: inside the loop
        warn = [b["title"].split("\n", 1)[-1] for b in flow() if " warn" in b["cls"]]
        check(any("set again inside the loop" in w for w in warn), f"a counter set inside the loop is marked ({warn})")
        click(driver, "ed-up")  # before the label
        check(not [b for b in flow() if " warn" in b["cls"]], "with the counter set before the loop, nothing is marked")
        arrows = js(driver, "return document.querySelectorAll('#ed-flow .flow-jump').length")
        back = js(driver, "return document.querySelectorAll('#ed-flow .flow-jump.back').length")
        check(arrows == 2 and back == 1, f"two jump arrows, the loop drawn going back ({arrows}, {back})")

        # A block dragged somewhere else: moved, one undo step.
        def block_xy(i):  # in the flowchart's own coordinates (the page may scroll between two looks)
            return js(driver, """const r = document.querySelector(`#ed-flow .flow-block[data-step="${arguments[0]}"]`).getBoundingClientRect();
                                 const o = document.getElementById('ed-flow').getBoundingClientRect();
                                 return [r.x - o.x, r.y - o.y];""", i)
        # (scrolled to where a user sees it: below the sticky robot panel, clear of the autoscroll edges)
        js(driver, """const b = document.querySelector('#ed-flow .flow-block[data-step="2"]');
                      window.scrollBy(0, b.getBoundingClientRect().top - window.innerHeight * 0.6);""")
        x0, y0 = block_xy(2)  # the first pose
        js(driver, """const svg = document.getElementById('ed-flow');
            const b = svg.querySelector('.flow-block[data-step="2"]').getBoundingClientRect();
            const at = (x, y) => ({ bubbles: true, pointerId: 1, clientX: x, clientY: y });
            svg.dispatchEvent(new PointerEvent('pointerdown', at(b.x + 20, b.y + 10)));
            svg.dispatchEvent(new PointerEvent('pointermove', at(b.x + 220, b.y + 40)));
            svg.dispatchEvent(new PointerEvent('pointerup', at(b.x + 220, b.y + 40)));""")
        x1, y1 = block_xy(2)
        check(abs(x1 - x0 - 200) < 2 and abs(y1 - y0 - 30) < 2, f"a dragged block moves ({x1 - x0:.0f}, {y1 - y0:.0f})")
        click(driver, "ed-undo")
        x2, y2 = block_xy(2)
        check(abs(x2 - x0) < 2 and abs(y2 - y0) < 2, "one Undo puts it back")
        # Let go over the sticky robot panel (where the blocks scrolled under it cannot be seen):
        # nothing changes, and the page says so.
        flow_before = js(driver, "return JSON.stringify(window.rcb4Studio.editor.doc.flow || null)")
        depth = js(driver, "return window.rcb4Studio.editor.history.undo")
        js(driver, """const svg = document.getElementById('ed-flow');
            const b = svg.querySelector('.flow-block[data-step="2"]').getBoundingClientRect();
            const under = document.querySelector('.studio > .panel:first-child').getBoundingClientRect().bottom - 30;
            const at = (x, y) => ({ bubbles: true, pointerId: 1, clientX: x, clientY: y });
            svg.dispatchEvent(new PointerEvent('pointerdown', at(b.x + 20, b.y + 10)));
            svg.dispatchEvent(new PointerEvent('pointermove', at(b.x + 20, under)));
            svg.dispatchEvent(new PointerEvent('pointerup', at(b.x + 20, under)));""")
        check(js(driver, "return JSON.stringify(window.rcb4Studio.editor.doc.flow || null)") == flow_before
              and js(driver, "return window.rcb4Studio.editor.history.undo") == depth
              and "under the robot's panel" in message(driver),
              f"a block let go over the robot's panel: nothing changed, said ({message(driver)!r})")
        field("ed-slot", "13")
        click(driver, "ed-push")
        check(wait_until(lambda: "motion 13" in message(driver), timeout=20), f"the flowchart's motion pushed to slot 13 ({message(driver)!r})")
        rc, out, err = run("--device", dev, "motion", "show", "13")
        check(rc == 0 and out.count("CONST 20 servos") == 2, f"rcb4 motion show 13 lists it ({rc}, {out[:200]!r}, {err.strip()!r})")

        # The layout and the names are kept in the motion file: a block dragged, a pose named, the
        # file saved (the tool's motion_check: the YAML a download holds) and opened again.
        js(driver, """const svg = document.getElementById('ed-flow');
            const b = svg.querySelector('.flow-block[data-step="2"]').getBoundingClientRect();
            const at = (x, y) => ({ bubbles: true, pointerId: 1, clientX: x, clientY: y });
            svg.dispatchEvent(new PointerEvent('pointerdown', at(b.x + 20, b.y + 10)));
            svg.dispatchEvent(new PointerEvent('pointermove', at(b.x + 260, b.y + 10)));
            svg.dispatchEvent(new PointerEvent('pointerup', at(b.x + 260, b.y + 10)));""")
        moved = block_xy(2)
        js(driver, "window.rcb4Studio.editor.sel = 2")
        js(driver, """const n = document.querySelector('#ed-step-name');
                      n.value = 'reach'; n.dispatchEvent(new Event('change'));""")
        saved = driver.execute_async_script(
            "window.rcb4Studio.request({op: 'motion_check', text: window.rcb4Studio.editor.text()})"
            ".then((r) => arguments[0](r.yaml), (e) => arguments[0]('ERROR ' + e.message))") or ""
        check('name: "reach"' in saved and re.search(r"\n    at: \[\d+, \d+\]", saved),
              f"the saved motion file keeps the pose's name and its block's place ({saved[:400]!r})")
        laid_out = os.path.join(poses, "laid-out.yaml")
        with open(laid_out, "w") as f:
            f.write(saved)
        js(driver, "window.savedConfirm = window.confirm; window.confirm = () => true")
        click(driver, "ed-new")
        js(driver, "document.querySelector('#ed-file').hidden = false")
        driver.find_element("id", "ed-file").send_keys(laid_out)
        check(wait_until(lambda: "laid-out.yaml: opened" in message(driver), timeout=10), f"opened again ({message(driver)!r})")
        js(driver, "window.confirm = window.savedConfirm; document.querySelector('#ed-file').hidden = true")
        again = block_xy(2)
        js(driver, "window.rcb4Studio.editor.sel = 2")
        listed = js(driver, "return [...document.querySelectorAll('li.step')].map((x) => x.textContent).join(' | ')")
        on_timeline = js(driver, "return [...document.querySelectorAll('#ed-timeline .block')].map((b) => b.textContent)")
        check(abs(again[0] - moved[0]) < 2 and abs(again[1] - moved[1]) < 2 and "reach" in listed
              and "reach" in on_timeline,
              f"opened, the block is where it was dragged and the pose is named in the list and on the timeline "
              f"({moved} -> {again}, {listed!r}, {on_timeline})")

        # Layout: at three common screen sizes the robot and the pose being edited are seen
        # together (the robot's panel stays under the header while the editor scrolls).
        js(driver, "window.rcb4Studio.editor.sel = 2")
        for w, h in ((1366, 768), (1600, 1000), (1920, 1080)):
            driver.set_window_size(w, h)
            time.sleep(0.6)  # the view resizes to the window
            seen = js(driver, """const detail = document.querySelector('#ed-detail');
                const panel = document.querySelector('.studio > .panel').getBoundingClientRect();
                window.scrollBy(0, detail.getBoundingClientRect().top - panel.bottom - 4);  // the pose just below the robot
                const rows = [...detail.querySelectorAll('.pose-joint')].filter((x) => {
                  const b = x.getBoundingClientRect();
                  return b.top >= 0 && b.bottom <= Math.min(innerHeight, x.parentElement.getBoundingClientRect().bottom); });
                const row = detail.querySelector('.pose-joint');
                const v = document.querySelector('#view3d canvas').getBoundingClientRect();
                const r = row.getBoundingClientRect();
                const top = document.elementFromPoint(v.x + v.width / 2, v.y + v.height / 2);
                const slider = row.querySelector('input[type=range]').getBoundingClientRect();
                const hit = document.elementFromPoint(slider.x + slider.width / 2, slider.y + slider.height / 2);
                return { view: v.top >= 0 && v.bottom <= innerHeight && top && top.tagName === 'CANVAS',
                         pose: r.top >= 0 && r.bottom <= innerHeight && hit && hit.type === 'range',
                         rows: rows.length, v: [v.top, v.bottom], r: [r.top, r.bottom], h: innerHeight };""")
            check(seen["view"] and seen["pose"] and seen["rows"] >= 4,
                  f"at {w}x{h} the robot and the pose's sliders are both in view, neither covered ({seen})")
            if len(sys.argv) > 2:
                driver.save_screenshot(os.path.join(sys.argv[2], f"rcb4-studio-{w}x{h}.png"))
        driver.set_window_size(1400, 1080)

        # A saved pose inserted into the motion from the Poses panel; one beyond a limit is refused.
        js(driver, "window.rcb4Studio.editor.sel = 0")
        n_steps = len(js(driver, "return window.rcb4Studio.editor.doc.steps"))
        js(driver, "document.querySelector('#poses li[data-pose=crouch] button.insert').click()")
        got = wait_until(lambda: js(driver, "const s = window.rcb4Studio.editor.doc.steps; return s.length > arguments[0] && s[1]", n_steps))
        check(got == {"pose": {"left_knee": 60, "right_knee": -60}, "time_ms": 800, "name": "crouch"},
              f"Insert: the saved pose crouch becomes step 2 with its time and its name ({got}, {message(driver)!r})")
        js(driver, "document.querySelector('#poses li[data-pose=broken] button.insert').click()")
        check(wait_until(lambda: "beyond its limits" in message(driver), timeout=5)
              and len(js(driver, "return window.rcb4Studio.editor.doc.steps")) == n_steps + 1,
              f"a saved pose beyond a limit is not inserted, and says why ({message(driver)!r})")

        # Does it stand? A pose with both hips pitched far is marked in the list and the timeline,
        # and the line under the timeline names it (issue 43 item 5: the server's balance check).
        js(driver, """window.rcb4Studio.editor.load({ robot: 'KHR-3HV', period_ms: 10, steps: [
                        { pose: { left_hip_pitch: 0, right_hip_pitch: 0 }, time_ms: 300 },
                        { pose: { left_hip_pitch: -80, right_hip_pitch: -80 }, time_ms: 800, name: 'too far' }, 'end'] })""")
        verdict = wait_until(lambda: (lambda t: t if "off its feet" in t else None)(
            js(driver, "return document.querySelector('#ed-balance').textContent")), timeout=10)
        marks = js(driver, """return [...document.querySelectorAll('#ed-steps [data-step], #ed-timeline [data-step]')]
                              .filter((e) => e.classList.contains('falls')).map((e) => e.parentElement.id + ':' + e.dataset.step)""")
        check(verdict and "step 2" in verdict and sorted(marks) == ["ed-steps:1", "ed-timeline:1"],
              f"the pose off its feet is marked in the list and the timeline and named ({verdict!r}, {marks})")
        js(driver, "window.rcb4Studio.editor.load({ robot: 'KHR-3HV', period_ms: 10, steps: [{ pose: { head_yaw: 30 }, time_ms: 300 }, 'end'] })")
        verdict = wait_until(lambda: (lambda t: t if "every pose stands" in t else None)(
            js(driver, "return document.querySelector('#ed-balance').textContent")), timeout=10)
        check(verdict and not js(driver, "return document.querySelectorAll('.falls').length"),
              f"a motion that stands says so, nothing marked ({verdict!r})")

        # Nothing of it moved the robot: live was off.
        after = {n: j["degrees"] for n, j in joints_on(dev).items()}
        moved = [n for n in before if abs((after[n] or 0) - (before[n] or 0)) > 0.2]
        check(not moved, f"with live off no joint moved ({moved})")
    finally:
        driver.quit()
        rc = ui.stop()
    check(rc == 0, f"rcb4 ui ended with exit 0 ({rc})")

finish()
