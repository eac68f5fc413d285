// rcb4 studio: the pose work HTH4 users do every day, as pure functions on a pose ({joint: degrees}):
// mirror left ↔ right and copy one limb to the other (the images and signs come from the server's
// hello, worked out from the robot's body: robot/mirror.hpp), and a clipboard for poses that
// every tab and motion of this robot shares (localStorage).
// SPDX-License-Identifier: BSL-1.0

/** True when the robot's body gives at least one joint a mirror image. */
export function canMirror(hello) { return hello.joints.some((j) => j.mirror); }

/**
 * @p pose mirrored. which: 'both' (left ↔ right, the middle negated where its sign says), 'left'
 * (the left limbs copied onto the right ones) or 'right'. Returns { pose } or { why } when a
 * mirrored angle is beyond the image joint's limits (nothing changes then).
 */
export function mirrorPose(hello, pose, which) {
  const limits = new Map(hello.joints.map((j) => [j.name, j]));
  const out = { ...pose };
  for (const j of hello.joints) {
    const m = j.mirror;
    if (!m || (which !== 'both' && m.side !== which)) continue;
    if (!(j.name in pose)) {  // mirrored: its image leaves the pose too; copied: nothing to copy
      if (which === 'both') delete out[m.joint];
      continue;
    }
    const v = pose[j.name] * m.sign + 0;  // + 0: never -0
    const lim = limits.get(m.joint);
    if (lim && (v < lim.lower || v > lim.upper))
      return { why: `${m.joint} would be ${v}°, beyond its limits ${lim.lower}..${lim.upper}: nothing changed` };
    out[m.joint] = v;
  }
  if (which !== 'both' && !hello.joints.some((j) => j.mirror?.side === which && j.name in pose))
    return { why: `this pose has no ${which} joint to copy: nothing changed` };
  if (!Object.keys(out).length) return { why: 'the pose would have no joint: nothing changed' };
  return { pose: out };
}

const clipKey = (robot) => `rcb4-studio-clipboard:${robot}`;

/** Keeps @p step (a pose step) where every tab of this robot finds it. Returns an error text or null. */
export function copyPose(robot, step) {
  try {
    localStorage.setItem(clipKey(robot), JSON.stringify({ pose: step.pose, time_ms: step.time_ms, name: step.name }));
    return null;
  } catch (e) {
    return `the browser would not keep the pose (${e.name})`;
  }
}

/** The pose step last copied for @p robot, checked against its joints and limits: { step } or { why }. */
export function pastedPose(hello) {
  let v;
  try { v = JSON.parse(localStorage.getItem(clipKey(hello.robot)) ?? 'null'); } catch { v = null; }
  if (!v || typeof v.pose !== 'object' || v.pose === null) return { why: 'no pose copied yet (Copy pose, or Ctrl+C on a pose step)' };
  const limits = new Map(hello.joints.map((j) => [j.name, j]));
  const pose = {};
  for (const [n, a] of Object.entries(v.pose)) {
    const lim = limits.get(n);
    if (!lim) return { why: `the copied pose has ${n}, which ${hello.robot} does not have` };
    if (typeof a !== 'number' || !Number.isFinite(a) || a < lim.lower || a > lim.upper)
      return { why: `the copied pose's ${n} (${a}) is beyond its limits ${lim.lower}..${lim.upper}` };
    pose[n] = a;
  }
  const step = { pose, time_ms: Number.isInteger(v.time_ms) && v.time_ms > 0 ? v.time_ms : 500 };
  if (typeof v.name === 'string' && v.name.trim() && v.name.length <= 80) step.name = v.name;  // its name comes with it
  return { step };
}
