#!/usr/bin/env python3
# Does it stand? `rcb4 motion check` as a motion author uses it (issue 43 items 1 and 5): a motion
# file whose poses keep the KHR-3HV's centre of mass over its feet (exit 0), one that pitches both
# hips far (exit 5, the step named), a slot of the board, --json; what must be refused: a profile
# with no mass model, a file that is no motion, a file of another robot. And `rcb4 urdf` carries
# the mass model's inertials.
#   balance_test.py RCB4
# SPDX-License-Identifier: BSL-1.0
import json
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from checks import check, finish, tool

RCB4 = sys.argv[1]
run, serve = tool(RCB4)
work = tempfile.mkdtemp(prefix="rcb4-balance-")
os.chdir(work)


def write(name, text):
    with open(name, "w") as f:
        f.write(text)


write("squat.yaml", """# a gentle squat: the feet stay flat, the hips over them
robot: KHR-3HV
period_ms: 10
steps:
  - pose: {left_hip_pitch: -20, right_hip_pitch: -20, left_knee: 40, right_knee: 40,
           left_ankle_pitch: -20, right_ankle_pitch: -20}
    time_ms: 500
    name: squat
  - pose: {left_hip_pitch: 0, right_hip_pitch: 0, left_knee: 0, right_knee: 0,
           left_ankle_pitch: 0, right_ankle_pitch: 0}
    time_ms: 500
    name: up
  - end
""")
write("lean.yaml", """# stands, then pitches both hips far: the torso leans out over the toes
robot: KHR-3HV
period_ms: 10
steps:
  - pose: {left_hip_pitch: 0, right_hip_pitch: 0}
    time_ms: 300
  - pose: {left_hip_pitch: -80, right_hip_pitch: -80}
    time_ms: 800
    name: too far
  - end
""")

rc, out, err = run("motion", "check", "squat.yaml")
check(rc == 0 and "squat.yaml on KHR-3HV (1458 g): 2 poses" in out and "stands: every pose" in out
      and "OUTSIDE" not in out, f"a squat stands: exit 0 ({rc}: {out[-300:]!r} {err[-200:]!r})")
check("left_foot+right_foot" in out and "squat" in out and "note: the first pose leaves 14 joints unnamed" in out,
      f"each pose's feet and name; the joints taken at home are counted ({out[:400]!r})")

rc, out, err = run("motion", "check", "lean.yaml")
check(rc == 5 and "falls: 1 of 2 poses off their feet; the worst, step 2's" in out and "OUTSIDE its feet" in out
      and "80.0° " in out,
      f"hips pitched 80 degrees fall: exit 5 naming step 2 ({rc}: {out[-300:]!r} {err[-200:]!r})")

rc, out, err = run("--json", "motion", "check", "lean.yaml")
try:
    j = json.loads(out)
except ValueError:
    j = {}
poses = j.get("poses", [])
check(rc == 5 and j.get("stands") is False and j.get("worst_step") == 2 and len(poses) == 2
      and poses[0]["stable"] and not poses[1]["stable"] and poses[1]["margin_mm"] < 0
      and abs(poses[1]["tilt_deg"] - 80) < 1 and abs(abs(poses[1]["lean_forward_deg"]) - 80) < 1
      and abs(poses[0]["com_mm"][1]) < 0.5 and poses[0]["touching"] == ["left_foot", "right_foot"]
      and j.get("physics") is False and j.get("mass_g") == 1458,
      f"--json: each pose's margin, tilt and feet ({rc}: {out[:600]!r})")

# A slot of the board: the demo's motion 3 ("bow": the hips' pitch and the knees), pulled and checked.
with serve() as dev:
    rc, out, err = run("--device", dev, "--json", "motion", "check", "3")
    try:
        j = json.loads(out)
    except ValueError:
        j = {}
    check(rc in (0, 5) and j.get("motion") == "motion 3" and len(j.get("poses", [])) >= 2
          and (rc == 0) == j.get("stands"),
          f"motion check 3 reads the slot from the board, exit matching 'stands' ({rc}: {out[:300]!r} {err[-200:]!r})")
    rc, out, err = run("--device", dev, "motion", "check", "40")
    check(rc == 1 and "40" in err, f"an empty slot: exit 1 naming it ({rc}: {err[-200:]!r})")

# Refused: a profile with no mass model (before any device opens), no such file, another robot's.
write("bare.yaml", """robot: bare
joints:
  left_knee: {ics: 16, lower: -90, upper: 90}
""")
write("bare_motion.yaml", "robot: bare\nperiod_ms: 10\nsteps:\n  - pose: {left_knee: 10}\n    time_ms: 100\n")
rc, out, err = run("--robot", "bare.yaml", "motion", "check", "bare_motion.yaml")
check(rc == 2 and "no mass model (dynamics:)" in err, f"a profile without dynamics: exit 2 ({rc}: {err[-200:]!r})")
rc, out, err = run("motion", "check", "121")
check(rc == 2 and "1..120" in err, f"a number outside 1..120: exit 2 saying so ({rc}: {err[-200:]!r})")
rc, out, err = run("motion", "check", "missing.yaml")
check(rc == 2 and "missing.yaml" in err, f"no such file: exit 2 naming it ({rc}: {err[-200:]!r})")
rc, out, err = run("motion", "check", "bare_motion.yaml")
check(rc == 2 and "bare" in err, f"a motion of another robot: exit 2 ({rc}: {err[-200:]!r})")

# --json urdf: one JSON object (the URDF text in it), as every command's --json gives.
rc, out, err = run("--json", "urdf")
try:
    j = json.loads(out)
except ValueError:
    j = {}
check(rc == 0 and j.get("robot") == "KHR-3HV" and str(j.get("urdf", "")).lstrip().startswith("<?xml")
      and "<inertial>" in j.get("urdf", ""), f"--json urdf: a JSON object holding the URDF ({rc}: {out[:120]!r})")

# The mass model in URDF: one <inertial> per link, 1.458 kg in all.
rc, out, err = run("urdf")
masses = [float(x.split('"')[1]) for x in out.split("<mass value=")[1:]]
check(rc == 0 and len(masses) == 21 and abs(sum(masses) - 1.458) < 0.002,
      f"rcb4 urdf: 21 links with their inertials, {sum(masses):.4f} kg in all ({rc})")

finish()
