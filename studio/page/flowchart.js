// rcb4 studio: the motion as a flowchart, a second view of the same steps as the list. Every step
// a block; arrows from each block to the next, and from each jump (go to, loop, button and RAM
// branches, with their "yes"/"no" exits) to its label, a backward jump drawn as a loop round the
// side. Drag a block to move it; drag from a jump's handle (the dot on its right) onto any block
// to connect it there (a label is put before that block when it has none). What does not connect
// is marked as you build: a jump to no label, a label nothing jumps to, a loop with no counter set
// before it (or one set again inside it), a motion that runs off its end. A click selects the step (its form below).
// Positions are kept with the motion in the editor (doc.flow, one per step; undo covers moves)
// and in the motion file as each step's `at: [x, y]` (fromFile / toFile), so a motion saved,
// pushed and opened again, or imported from an HTH4 flowchart, keeps its layout.
// SPDX-License-Identifier: BSL-1.0

const NS = 'http://www.w3.org/2000/svg';
const W = 200, H = 34, GAP = 22, X0 = 24, Y0 = 16;
const JUMPS = { goto: 'goto', loop: 'loop', count_down: 'count_down', if_buttons: 'goto', unless_buttons: 'goto', if_ram: 'goto' };

const svg = (tag, attrs = {}, text) => {
  const e = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (text !== undefined) e.textContent = text;
  return e;
};

/** The key of step @p s that names its jump's label, or null. */
export function jumpKey(kind) { return JUMPS[kind] ?? null; }

const placed = (p) => p && Number.isFinite(p.x) && Number.isFinite(p.y);

/**
 * Where step @p i's block is: its kept position; a label without one above the step it names
 * when that step has one (an imported flowchart places blocks, not their labels); else in a
 * column in the list's order.
 */
export function positionOf(doc, i) {
  const p = doc.flow?.[i];
  if (placed(p)) return p;
  const s = doc.steps?.[i], next = doc.flow?.[i + 1];
  if (s && typeof s === 'object' && 'label' in s && placed(next)) return { x: next.x, y: Math.max(0, next.y - H - 6) };
  return { x: X0, y: Y0 + i * (H + GAP) };
}

/** The steps of a motion file → { steps, flow }: each step's `at` becomes its block's place. */
export function fromFile(steps) {
  const flow = steps.map((s) => (s && typeof s === 'object' && Array.isArray(s.at) ? { x: Number(s.at[0]), y: Number(s.at[1]) } : null));
  const clean = steps.map((s) => {
    if (!s || typeof s !== 'object' || !('at' in s)) return s;
    const { at, ...rest } = s;  // eslint-disable-line no-unused-vars
    return rest;
  });
  return { steps: clean, flow: flow.some(placed) ? flow : undefined };
}

/** The editor's steps as the motion file keeps them: each with its block's place (end, a bare word, has none). */
export function toFile(doc) {
  return doc.steps.map((s, i) => {
    const p = doc.flow?.[i];
    if (!placed(p) || !s || typeof s !== 'object') return s;
    return { ...s, at: [Math.min(100000, Math.max(0, Math.round(p.x))), Math.min(100000, Math.max(0, Math.round(p.y)))] };
  });
}

/** Keeps doc.flow in step with the steps: call after inserting at @p at (n = 1) or removing (n = -1). */
export function flowShift(doc, at, n) {
  if (!doc.flow) return;
  if (n > 0) doc.flow.splice(at, 0, null);
  else doc.flow.splice(at, 1);
}
/** Keeps doc.flow in step when a step moves from @p from to @p to. */
export function flowMove(doc, from, to) {
  if (!doc.flow) return;
  while (doc.flow.length < doc.steps.length) doc.flow.push(null);
  const [p] = doc.flow.splice(from, 1);
  doc.flow.splice(to, 0, p);
}

/** What does not connect, per step: { bad: [texts], warn: [texts] }. */
export function problems(doc, kindOf) {
  const steps = doc.steps, out = steps.map(() => ({ bad: [], warn: [] }));
  const labels = new Map();
  steps.forEach((s, i) => { if (kindOf(s) === 'label') labels.set(s.label, i); });
  const targeted = new Set();
  steps.forEach((s, i) => {
    const k = kindOf(s), key = jumpKey(k);
    if (!key) return;
    const to = s[key];
    if (!labels.has(to)) out[i].bad.push(`goes to ${to}: no label is called that`);
    else targeted.add(to);
    if ((k === 'loop' || k === 'count_down') && labels.has(to)) {
      // The counter must be set before the loop's label: set inside the loop, it starts again
      // each time round and the loop never ends.
      const counter = s.counter ?? null, top = Math.min(labels.get(to), i);
      const sets = (from, until) => steps.slice(from, until).some((x) => kindOf(x) === 'set_counter' && (x.counter ?? null) === counter);
      if (sets(top + 1, i)) out[i].warn.push('its counter is set again inside the loop: it goes round for ever');
      else if (!sets(0, top)) out[i].warn.push('no counter is set before this loop: it counts from whatever the RAM holds');
    }
  });
  const seen = new Set();
  steps.forEach((s, i) => {
    if (kindOf(s) !== 'label') return;
    if (seen.has(s.label)) out[i].bad.push(`another label is called ${s.label}: the board would not know which`);
    seen.add(s.label);
    if (!targeted.has(s.label)) out[i].warn.push(`nothing jumps to ${s.label}`);
  });
  const last = steps.length - 1;
  if (last >= 0 && !['end', 'goto'].includes(kindOf(steps[last])))
    out[last].bad.push('the motion runs off its end here: add an end');
  return out;
}

/**
 * The flowchart in @p box. api: { doc(), sel(), select(i), change(fn), kindOf, describe, say }.
 * Returns { render() }.
 */
export function createFlowchart(box, api) {
  const root = svg('svg', { class: 'flow', id: 'ed-flow', role: 'img', 'aria-label': 'the motion as a flowchart' });
  const defs = svg('defs');
  const arrow = svg('marker', { id: 'flow-arrow', viewBox: '0 0 10 10', refX: 9, refY: 5, markerWidth: 7, markerHeight: 7, orient: 'auto-start-reverse' });
  arrow.append(svg('path', { d: 'M 0 0 L 10 5 L 0 10 z', class: 'flow-arrowhead' }));
  defs.append(arrow);
  box.replaceChildren(root);
  let drag = null;  // { kind: 'move'|'wire', i, dx, dy, x, y, moved }

  // What covers the top of the page: the sticky header and the robot's panel above the editor. A
  // block scrolled under them cannot be seen, so a drag there scrolls it into view and a drop there
  // changes nothing (it would land on a block the user never saw).
  const coveredTo = () => Math.max(0, ...[...document.querySelectorAll('header, .studio > .panel:first-child')]
    .filter((x) => getComputedStyle(x).position === 'sticky').map((x) => x.getBoundingClientRect().bottom));
  const point = (e) => {
    const r = root.getBoundingClientRect();
    return { x: e.clientX - r.left, y: e.clientY - r.top };
  };
  const blockAt = (p, doc) => doc.steps.findIndex((_, i) => {
    const q = positionOf(doc, i);
    return p.x >= q.x && p.x <= q.x + W && p.y >= q.y && p.y <= q.y + H;
  });

  function connect(from, to) {
    const doc = api.doc(), kindOf = api.kindOf;
    const key = jumpKey(kindOf(doc.steps[from]));
    if (!key || to < 0) return;
    api.change(() => {
      let target = to;
      if (kindOf(doc.steps[target]) !== 'label' && !(target > 0 && kindOf(doc.steps[target - 1]) === 'label')) {
        const used = new Set(doc.steps.filter((s) => kindOf(s) === 'label').map((s) => s.label));
        let n = 1;
        while (used.has(`L${n}`)) n += 1;
        const p = positionOf(doc, target);
        doc.steps.splice(target, 0, { label: `L${n}` });
        flowShift(doc, target, 1);
        if (doc.flow) doc.flow[target] = { x: p.x, y: Math.max(0, p.y - H - 6) };
        if (from >= target) from += 1;
      } else if (kindOf(doc.steps[target]) !== 'label') {
        target -= 1;
      }
      doc.steps[from][key] = doc.steps[target].label;
    });
  }

  root.addEventListener('pointerdown', (e) => {
    const doc = api.doc(), p = point(e);
    const wire = e.target.closest?.('.flow-exit');
    const i = wire ? Number(wire.dataset.step) : blockAt(p, doc);
    if (i < 0) return;
    const q = positionOf(doc, i);
    drag = { kind: wire ? 'wire' : 'move', i, dx: p.x - q.x, dy: p.y - q.y, x: p.x, y: p.y, moved: false, start: p };
    try { root.setPointerCapture(e.pointerId); } catch { /* a pointer the browser no longer tracks */ }
    e.preventDefault();
  });
  root.addEventListener('pointermove', (e) => {
    if (!drag) return;
    const p = point(e);
    drag.moved ||= Math.abs(p.x - drag.start.x) + Math.abs(p.y - drag.start.y) > 3;
    drag.x = p.x;
    drag.y = p.y;
    // Near the box's bottom edge, or the top of what is seen of it, the box scrolls (then the page,
    // when the box is scrolled to its top and its top is under the robot's panel), so a jump reaches
    // a block out of view.
    const b = box.getBoundingClientRect(), top = Math.max(b.top, coveredTo());
    if (e.clientY > Math.min(b.bottom, window.innerHeight) - 24) {
      if (box.scrollTop + box.clientHeight < box.scrollHeight) box.scrollTop += 16;
      else window.scrollBy(0, 16);
    } else if (e.clientY < top + 24) {
      if (box.scrollTop > 0) box.scrollTop -= 16;
      else if (b.top < coveredTo()) window.scrollBy(0, -16);
    }
    render();
  });
  const end = (e) => {
    if (!drag) return;
    const d = drag, doc = api.doc();
    drag = null;
    if (d.moved && e.clientY < coveredTo()) {  // let go over the robot's panel: nothing changes
      api.say?.('dropped under the robot\'s panel: nothing changed (drag to a block you can see)', 'error');
      render();
      return;
    }
    if (d.kind === 'wire') {
      if (d.moved) connect(d.i, blockAt(point(e), doc));
      render();
    } else if (!d.moved) {
      api.select(d.i);
    } else {
      api.change(() => {
        doc.flow ??= [];
        while (doc.flow.length < doc.steps.length) doc.flow.push(null);
        doc.flow[d.i] = { x: Math.max(0, Math.round(d.x - d.dx)), y: Math.max(0, Math.round(d.y - d.dy)) };
      });
    }
  };
  root.addEventListener('pointerup', end);
  root.addEventListener('pointercancel', () => { drag = null; render(); });

  function render() {
    const doc = api.doc(), kindOf = api.kindOf, sel = api.sel();
    const where = doc.steps.map((_, i) => (drag?.kind === 'move' && drag.moved && drag.i === i
      ? { x: Math.max(0, drag.x - drag.dx), y: Math.max(0, drag.y - drag.dy) } : positionOf(doc, i)));
    const labels = new Map();
    doc.steps.forEach((s, i) => { if (kindOf(s) === 'label') labels.set(s.label, i); });
    const marks = problems(doc, kindOf);
    const edges = svg('g', { class: 'flow-edges' }), blocks = svg('g', { class: 'flow-blocks' });
    const line = (d, cls, text, tx, ty) => {
      edges.append(svg('path', { d, class: cls, 'marker-end': 'url(#flow-arrow)' }));
      if (text) edges.append(svg('text', { x: tx, y: ty, class: 'flow-edge-label' }, text));
    };
    doc.steps.forEach((s, i) => {
      const k = kindOf(s), a = where[i], key = jumpKey(k);
      const branch = key && k !== 'goto';
      const yes = k === 'loop' || k === 'count_down' ? 'repeat' : 'yes', no = k === 'loop' || k === 'count_down' ? 'done' : 'no';
      if (k !== 'end' && k !== 'goto' && i + 1 < doc.steps.length) {  // on to the next step
        const b = where[i + 1];
        line(`M ${a.x + W / 2} ${a.y + H} C ${a.x + W / 2} ${a.y + H + 14}, ${b.x + W / 2} ${b.y - 14}, ${b.x + W / 2} ${b.y}`,
          'flow-next', branch ? no : '', a.x + W / 2 + 4, a.y + H + 12);
      }
      if (key && labels.has(s[key])) {  // the jump, round the right side (a loop when it goes back)
        const b = where[labels.get(s[key])];
        const out = Math.max(a.x, b.x) + W + 26 + (i % 3) * 10;
        line(`M ${a.x + W} ${a.y + H / 2} C ${out} ${a.y + H / 2}, ${out} ${b.y + H / 2}, ${b.x + W} ${b.y + H / 2}`,
          'flow-jump' + (b.y < a.y ? ' back' : ''), branch ? yes : '', a.x + W + 6, a.y + H / 2 - 4);
      }
    });
    doc.steps.forEach((s, i) => {
      const k = kindOf(s), a = where[i], m = marks[i];
      const g = svg('g', { class: `flow-block ${k}` + (i === sel ? ' selected' : '') + (m.bad.length ? ' bad' : m.warn.length ? ' warn' : ''),
        'data-step': i, transform: `translate(${a.x} ${a.y})` });
      const shape = k === 'label' ? svg('rect', { width: W, height: H, rx: 17 })
        : jumpKey(k) && k !== 'goto' ? svg('polygon', { points: `12,0 ${W - 12},0 ${W},${H / 2} ${W - 12},${H} 12,${H} 0,${H / 2}` })
          : svg('rect', { width: W, height: H, rx: 3 });
      g.append(shape, svg('text', { x: 10, y: H / 2 + 4 }, `${i + 1}  ${api.describe(s)}`.slice(0, 30)));
      const why = [...m.bad, ...m.warn];
      g.append(svg('title', {}, `step ${i + 1}: ${api.describe(s)}` + (why.length ? `\n${why.join('\n')}` : '')));
      if (jumpKey(k)) g.append(svg('circle', { cx: W, cy: H / 2, r: 6, class: 'flow-exit', 'data-step': i }));
      blocks.append(g);
    });
    if (drag?.kind === 'wire' && drag.moved) {
      const a = where[drag.i];
      line(`M ${a.x + W} ${a.y + H / 2} L ${drag.x} ${drag.y}`, 'flow-wire', '', 0, 0);
    }
    const right = Math.max(...where.map((p) => p.x)) + W + 80, bottom = Math.max(...where.map((p) => p.y)) + H + 30;
    root.setAttribute('width', String(Math.max(right, 300)));
    root.setAttribute('height', String(Math.max(bottom, 120)));
    root.replaceChildren(defs, edges, blocks);
  }

  return { render };
}
