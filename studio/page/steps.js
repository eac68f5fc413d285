// rcb4 studio: a motion's steps as the motion file says them (docs/motions.md), without the page:
// the kinds of step and a new one of each, a line describing a step, and the motion as the board
// plays it (segments of interpolation, loops counted) with the joints at any moment of it.
// SPDX-License-Identifier: BSL-1.0

/** A new step of each kind (a pose is made from the robot or the ghost). */
export const KINDS = {
  pose: () => null,  // made from the robot or the ghost
  label: () => ({ label: 'again' }),
  set_counter: () => ({ set_counter: 3 }),
  loop: () => ({ loop: 'again' }),
  if_buttons: () => ({ if_buttons: 'up', goto: 'again' }),
  unless_buttons: () => ({ unless_buttons: 'up', goto: 'again' }),
  if_ram: () => ({ if_ram: 0x0050, size: 2, at_least: 512, goto: 'again' }),
  goto: () => ({ goto: 'again' }),
  call: () => ({ call: 2 }),
  speed: () => ({ speed: { all: 127 } }),
  stretch: () => ({ stretch: { all: 127 } }),
  end: () => 'end',
};

/** The kind of step @p s ("pose", "end", "if_buttons" …). */
export function kindOf(s) {
  if (s === 'end') return 'end';
  for (const k of ['pose', 'label', 'set_counter', 'loop', 'count_down', 'if_buttons', 'unless_buttons', 'if_ram', 'goto',
    'call', 'call_address', 'speed', 'stretch'])
    if (s && typeof s === 'object' && k in s) return k;
  return '?';
}

/** One line for step @p s, after its name when it has one. */
export function describe(s) {
  const d = describeKind(s);
  return s && typeof s === 'object' && s.name ? `${s.name}: ${d}` : d;
}

function describeKind(s) {
  const k = kindOf(s);
  if (k === 'pose') return `pose: ${Object.keys(s.pose).length} joints, ${s.time_ms} ms`;
  if (k === 'end') return 'end';
  if (k === 'label') return `label ${s.label}:`;
  if (k === 'set_counter') return `counter = ${s.set_counter}`;
  if (k === 'loop') return `loop to ${s.loop} while the counter is not 0`;
  if (k === 'if_buttons') return `if ${s.if_buttons} held: go to ${s.goto}`;
  if (k === 'unless_buttons') return `unless ${s.unless_buttons} held: go to ${s.goto}`;
  if (k === 'if_ram') return `if RAM ${s.if_ram} … go to ${s.goto}`;
  if (k === 'goto') return `go to ${s.goto}`;
  if (k === 'call') return `call motion ${s.call}`;
  if (k === 'call_address') return `call the motion at ${hex(s.call_address)}`;
  if (k === 'count_down') return `count down, then to ${s.count_down} once the counter is 0`;
  if (k === 'speed' || k === 'stretch') return `${k} ${perJoint(s[k])}`;
  return 'a step this page does not know';
}

const hex = (v) => (typeof v === 'number' ? '0x' + v.toString(16).toUpperCase().padStart(4, '0') : String(v));
/** "all 127", "legs 60, head_yaw 90": a speed or stretch step's values in words, never JSON. */
const perJoint = (m) => (m && typeof m === 'object' ? Object.entries(m).map(([k, v]) => `${k} ${v}`).join(', ') || 'of nothing' : String(m));

/**
 * The motion as the board plays it: [{from, to, ms, step}] segments of interpolation, counters and
 * loops counted, no button held and every RAM value 0 (as a preview assumes), calls skipped; at
 * most @p limitMs long. @p start: the joints before the first pose (degrees).
 */
export function segments(steps, start, limitMs = 120000) {
  const labels = new Map();
  steps.forEach((s, i) => { if (kindOf(s) === 'label') labels.set(s.label, i); });
  const counters = new Map();
  const out = [];
  let cur = { ...start }, pc = 0, total = 0, quiet = 0;
  const jump = (to) => { if (!labels.has(to)) throw new Error(`no label called ${to}`); pc = labels.get(to); };
  for (;;) {
    if (total > limitMs || quiet >= 10000) { out.endless = true; break; }  // round for ever (or spinning)
    if (pc >= steps.length) break;
    const s = steps[pc], k = kindOf(s), here = pc;
    pc += 1;
    if (k === 'pose') {
      const to = { ...cur, ...s.pose };
      out.push({ from: cur, to, ms: s.time_ms, step: here });
      cur = to;
      total += s.time_ms;
      quiet = 0;
      continue;
    }
    quiet += 1;
    if (k === 'end') break;
    if (k === 'set_counter') counters.set(s.counter ?? 'c', s.set_counter & 255);
    else if (k === 'loop' || k === 'count_down') {
      const c = ((counters.get(s.counter ?? 'c') ?? 0) - 1) & 255;
      counters.set(s.counter ?? 'c', c);
      if ((c === 0) === (s.when === 'zero')) jump(s.loop ?? s.count_down);
    } else if (k === 'unless_buttons' || k === 'goto') jump(s.goto);
    else if (k === 'if_ram') {
      const v = 0;
      if (('equal' in s && v === s.equal) || ('not_equal' in s && v !== s.not_equal) || ('below' in s && v < s.below) ||
        ('at_least' in s && v >= s.at_least) || ('at_most' in s && v <= s.at_most)) jump(s.goto);
    }
  }
  return out;
}

/** Joint angles at @p t ms into @p segs, each joint moving in a straight line as the board interpolates. */
export function at(segs, t) {
  let acc = 0;
  for (const g of segs) {
    if (t <= acc + g.ms) {
      const f = g.ms ? Math.min(Math.max((t - acc) / g.ms, 0), 1) : 1;
      const out = {};
      for (const [k, v] of Object.entries(g.to)) {
        const a = g.from[k];
        out[k] = Number.isFinite(a) ? a + (v - a) * f : v;
      }
      return out;
    }
    acc += g.ms;
  }
  return segs.length ? segs[segs.length - 1].to : null;
}
