// rcb4 ui: the motion editor. A motion is its steps as a motion file says them (the YAML the tool
// reads and writes, docs/motions.md): poses with their times, counters and loops, branches, labels
// and jumps, calls, speed/stretch, end. Edited here, checked and written by the server (the robot
// services): pushed to a slot with its backup named, pulled from one, played from the host at the
// authored timing, previewed in 3D without the robot, opened from and saved to a file.

import { canMirror, copyPose, mirrorPose, pastedPose } from './posetools.js';
import { stepForm } from './stepforms.js';
import { createFlowchart, flowMove, flowShift, fromFile, toFile } from './flowchart.js';
import { el, $, numberIn, numberBox } from './dom.js';
import { KINDS, describe, kindOf, segments } from './steps.js';
import { createPlayback } from './playback.js';
import { createBalance } from './balance.js';

/** The largest motion file the editor opens (the server's max_text_bytes, docs/browser.md). */
const MAX_FILE_BYTES = 512 * 1024;

export function createEditor(root, ctx) {
  const h = ctx.hello;
  const limits = new Map(h.joints.map((j) => [j.name, j]));
  const ed = { doc: { robot: h.robot, name: '', period_ms: 10, steps: ['end'] }, sel: 0, undo: [], redo: [], preview: null, run: 0, playing: false };
  let balance = null;  // the balance marks (balance.js), made once the page's parts exist

  // --- the parts of the panel ---
  const name = el('input', { id: 'ed-name', placeholder: 'motion name (names its slot)', maxlength: 64, 'aria-label': 'motion name' });
  const slot = numberBox({ id: 'ed-slot', value: 10, 'aria-label': 'slot number' }, { min: 1, max: 120, whole: true, step: 1, what: 'the slot' });
  /** The slot typed, 1-120, or null (said, the box marked): nothing is read or written then. */
  const slotIn = () => {
    const r = numberIn(slot);
    if (r.value === null) ctx.say(r.why || 'type a slot number, 1 to 120', 'error');
    return r.value;
  };
  const file = el('input', { id: 'ed-file', type: 'file', accept: '.yaml,.yml,.json,.bin', hidden: true });
  const kind = el('select', { id: 'ed-kind', 'aria-label': 'kind of step to add' },
    ...Object.keys(KINDS).map((k) => el('option', { value: k, text: k.replace('_', ' ') })));
  const steps = el('ol', { id: 'ed-steps', class: 'steps', tabindex: 0, 'aria-label': 'the motion\'s steps: arrows select, Alt+arrows move, Delete removes, Ctrl+D duplicates, Ctrl+Z undoes' });
  const jumps = document.createElementNS('http://www.w3.org/2000/svg', 'svg');
  jumps.setAttribute('class', 'jumps');
  const timeline = el('div', { id: 'ed-timeline', class: 'timeline', 'aria-label': 'the poses in time' });
  const cursor = el('div', { class: 'cursor', hidden: true });
  timeline.append(cursor);
  // Scrubbing: a press and drag along the timeline shows the pose at that point in the ghost
  // (the poses in the list's order, each joint moving in a straight line as the board moves it).
  const scrubAt = (e) => {
    const poses = ed.doc.steps.map((st, i) => [st, i]).filter(([st]) => kindOf(st) === 'pose');
    const total = poses.reduce((a, [st]) => a + st.time_ms, 0);
    if (!total) return;
    const r = timeline.getBoundingClientRect();
    const t = Math.min(Math.max((e.clientX - r.left) / r.width, 0), 1) * total;
    let acc = 0;
    for (const [st, i] of poses) {
      if (t <= acc + st.time_ms) {
        const from = poseAt(i - 1), f = st.time_ms ? (t - acc) / st.time_ms : 1, g = { ...from };
        for (const [n, v] of Object.entries(st.pose)) g[n] = Number.isFinite(from[n]) ? from[n] + (v - from[n]) * f : v;
        ctx.view?.setGhost(g);
        cursor.hidden = false;
        cursor.style.left = `${(t / total) * 100}%`;
        timeline.dataset.scrubStep = String(i);
        return;
      }
      acc += st.time_ms;
    }
  };
  timeline.addEventListener('pointerdown', (e) => {
    if (ed.preview) return;
    try { timeline.setPointerCapture(e.pointerId); } catch { /* a pointer the browser no longer tracks */ }
    timeline.dataset.scrubbing = String(e.clientX);
    scrubAt(e);
  });
  timeline.addEventListener('pointermove', (e) => { if (timeline.dataset.scrubbing) scrubAt(e); });
  const scrubEnd = (e) => {
    if (!timeline.dataset.scrubbing) return;
    const still = Math.abs(e.clientX - Number(timeline.dataset.scrubbing)) < 4;  // a click, not a drag
    delete timeline.dataset.scrubbing;
    cursor.hidden = true;
    if (still && timeline.dataset.scrubStep) { ed.sel = Number(timeline.dataset.scrubStep); render(); }  // selects its pose
    else ctx.view?.setGhost(poseAt(ed.sel));  // the selected pose again
  };
  timeline.addEventListener('pointerup', scrubEnd);
  timeline.addEventListener('pointercancel', scrubEnd);
  const detail = el('div', { id: 'ed-detail', class: 'detail' });
  const summary = el('div', { id: 'ed-summary', class: 'small muted' });
  const flowBox = el('div', { class: 'flow-box' });
  const bt = (id, text, title, fn, cls = '') => el('button', { id, type: 'button', title, class: cls, onclick: fn }, text);
  root.replaceChildren(
    el('div', { class: 'row' }, name,
      bt('ed-new', 'New', 'an empty motion', () => { if (mayReplace('New')) { const note = load({ robot: h.robot, name: '', period_ms: 10, steps: ['end'] }); markClean(); if (note) ctx.say('a new motion' + note); } }),
      bt('ed-open', 'Open…', 'a motion file (.yaml) from this computer, or a slot\'s .bin backup to put back into the slot', () => file.click()), file,
      bt('ed-save', 'Save', 'download the motion as a motion file (.yaml), as rcb4 motion push reads it', save)),
    el('div', { class: 'row' }, 'slot', slot,
      bt('ed-pull', 'Pull', 'the slot into the editor', pull),
      bt('ed-push', 'Push', 'write the motion into the slot (its old bytes are backed up first)', push, 'needs-control'),
      bt('ed-preview', 'Preview', 'play it in 3D, at its timing, without the robot', () => preview(false)),
      bt('ed-preview-here', 'From here', 'preview from the selected step (where the board first reaches it)', () => preview(true)),
      bt('ed-play', 'Play on robot', 'play it from the host at its timing (the first pose is reached at the speed limit)', () => play(false), 'needs-control'),
      bt('ed-play-here', 'Play from here', 'play it on the robot from the selected step (its pose reached at the speed limit; the steps before it are not played)', () => play(true), 'needs-control'),
      bt('ed-stop', 'Stop', 'stop the preview and a play on the robot', () => stop())),
    el('div', { class: 'row' }, kind,
      bt('ed-add', 'Add', 'add a step of that kind after the selected one (a pose: the ghost\'s)', () => add(kind.value)),
      bt('ed-capture', 'Capture', 'add the robot\'s measured pose (all joints, or the ticked ones of the selected pose)', capture),
      bt('ed-dup', 'Duplicate', 'Ctrl+D', () => duplicate()),
      bt('ed-copy', 'Copy pose', 'Ctrl+C: the selected pose, for any motion or tab of this robot', copy),
      bt('ed-paste', 'Paste pose', 'Ctrl+V: the copied pose as a new step after the selected one', paste),
      bt('ed-del', 'Delete', 'Delete', () => remove()),
      bt('ed-up', '↑', 'Alt+↑', () => move(-1)), bt('ed-down', '↓', 'Alt+↓', () => move(1)),
      bt('ed-undo', 'Undo', 'Ctrl+Z', undo), bt('ed-redo', 'Redo', 'Ctrl+Y', redo)),
    timeline, summary,
    detail,  // the step being edited first, in view with the robot (the list and flowchart below)
    el('details', { id: 'ed-flow-panel', class: 'flow-panel', open: true }, el('summary', {}, 'Flowchart'), flowBox),
    el('div', { class: 'steps-box' }, jumps, steps));

  // --- history ---
  // A quiet step of the history (a motion loaded, a mirror) never drives the robot: undone or
  // redone with live ticked, it turns live off, as it did when it was made.
  // (with the slot the motion came from: Push asks before it writes over any other slot)
  const snapshot = (quiet = false) => JSON.stringify({ doc: ed.doc, sel: ed.sel, from: ed.from ?? null, ...(quiet ? { quiet: true } : {}) });
  const change = (fn, quiet = false) => {
    ed.undo.push(snapshot(quiet));
    if (ed.undo.length > 200) ed.undo.shift();
    ed.redo = [];
    fn();
    render();
  };
  const across = (from, to, what) => {
    const e = JSON.parse(from.pop());
    to.push(snapshot(!!e.quiet));
    ({ doc: ed.doc, sel: ed.sel } = e);
    ed.from = e.from ?? null;
    if (e.quiet && ed.live) {
      ed.live = false;
      ed.liveSent = null;
      ctx.say(`${what}: a motion loaded or a mirror, so live is now off and the robot did not move (tick live to send the pose)`);
    }
    render();
  };
  function undo() { if (ed.undo.length) across(ed.undo, ed.redo, 'undone'); }
  function redo() { if (ed.redo.length) across(ed.redo, ed.undo, 'redone'); }
  const flow = createFlowchart(flowBox, { doc: () => ed.doc, sel: () => ed.sel, select: (i) => { ed.sel = i; render(); },
    change, kindOf, describe, say: ctx.say });

  // --- kept in the browser: the motion, its undo history and what was last saved survive a
  // reconnect (a restarted rcb4 ui) and a reload, per tab (sessionStorage: two tabs never
  // overwrite each other's work); leaving the page with unsaved changes asks first ---
  const storeKey = `rcb4-studio-editor:${h.robot}`;
  let storeFailed = false;
  let kept = null;
  function keep() {
    try {
      const text = JSON.stringify({ doc: ed.doc, sel: ed.sel, from: ed.from ?? null, undo: ed.undo, redo: ed.redo, clean: ed.clean });
      if (text === kept) return;  // unchanged: nothing to write
      sessionStorage.setItem(storeKey, text);
      kept = text;
      storeFailed = false;
    } catch (e) {
      if (!storeFailed) ctx.say(`the browser would not keep the motion (${e.name}): save it to a file`, 'error');
      storeFailed = true;
    }
  }
  (function restore() {
    try {
      const was = JSON.parse(sessionStorage.getItem(storeKey) || 'null');
      if (!was || !was.doc || !Array.isArray(was.doc.steps) || !was.doc.steps.length) return;
      ed.doc = was.doc;
      ed.sel = Number.isInteger(was.sel) ? was.sel : 0;
      ed.from = Number.isInteger(was.from) ? was.from : null;
      ed.undo = Array.isArray(was.undo) ? was.undo.filter((u) => typeof u === 'string') : [];
      ed.redo = Array.isArray(was.redo) ? was.redo.filter((u) => typeof u === 'string') : [];
      ed.clean = typeof was.clean === 'string' ? was.clean : null;
    } catch { /* a damaged entry: start empty */ }
  }());
  ed.clean ??= snapshotDoc();
  /** The motion as the dirty check sees it (the selection is no change). */
  function snapshotDoc() { return JSON.stringify(ed.doc); }
  /** True when the motion differs from what was last opened, pulled, saved or pushed. */
  const dirty = () => snapshotDoc() !== ed.clean;
  const markClean = () => { ed.clean = snapshotDoc(); keep(); };
  window.addEventListener('beforeunload', (e) => {
    if (!dirty()) return undefined;
    e.preventDefault();  // the browser asks before the page goes (the motion is kept in the browser too)
    e.returnValue = '';
    return '';
  });
  /** Asks before @p what replaces a motion with unsaved changes; true: go ahead. */
  const mayReplace = (what) => !dirty() || window.confirm(`The motion in the editor has changes not saved or pushed. ${what} replaces it (Undo brings it back). Go on?`);

  // --- steps ---
  const clampSel = () => { ed.sel = Math.min(Math.max(ed.sel, 0), ed.doc.steps.length - 1); };
  // A new step goes after the selected one; with the closing end selected, before it.
  const insert = (s) => change(() => {
    const last = ed.sel === ed.doc.steps.length - 1 && kindOf(ed.doc.steps[ed.sel]) === 'end';
    const where = last ? ed.sel : ed.sel + 1;
    ed.doc.steps.splice(where, 0, s);
    flowShift(ed.doc, where, 1);
    ed.sel = where;
  });
  function poseAt(i) {  // the whole robot after step i: the measured angles, then every pose up to it
    const out = { ...ctx.measured() };
    for (let k = 0; k <= i && k < ed.doc.steps.length; k++) if (kindOf(ed.doc.steps[k]) === 'pose') Object.assign(out, ed.doc.steps[k].pose);
    return out;
  }
  function add(k) {
    if (k !== 'pose') return insert(KINDS[k]());
    const from = poseAt(ed.sel), pose = {};
    for (const j of h.joints) if (Number.isFinite(from[j.name])) pose[j.name] = Math.round(from[j.name] * 10) / 10;
    insert({ pose, time_ms: 500 });
  }
  function capture() {
    const m = ctx.measured(), cur = ed.doc.steps[ed.sel];
    const only = kindOf(cur) === 'pose' ? Object.keys(cur.pose) : null;  // the ticked joints of the selected pose
    const pose = {};
    const outside = [];
    for (const j of h.joints) {
      if (only && !only.includes(j.name)) continue;
      const a = m[j.name];
      if (!Number.isFinite(a)) continue;
      const v = Math.round(a * 10) / 10;
      if (v < j.lower || v > j.upper) outside.push(j.name);
      pose[j.name] = Math.min(Math.max(v, j.lower), j.upper);
    }
    if (!Object.keys(pose).length) return ctx.say('capture: no joint answers', 'error');
    insert({ pose, time_ms: 500 });
    ctx.say(`captured ${Object.keys(pose).length} joints` + (outside.length ? ` (at the limit: ${outside.join(', ')})` : ''));
  }
  function duplicate() { const s = ed.doc.steps[ed.sel]; if (s !== undefined) insert(JSON.parse(JSON.stringify(s))); }
  // --- poses: copy and paste (every tab of this robot), mirror, a limb onto the other, home ---
  function copy() {
    const s = ed.doc.steps[ed.sel];
    if (kindOf(s) !== 'pose') return ctx.say('select a pose step to copy', 'error');
    const failed = copyPose(h.robot, s);
    ctx.say(failed ?? `pose of step ${ed.sel + 1} copied: paste it in any motion or tab (Ctrl+V)`, failed ? 'error' : 'note');
  }
  function paste() {
    const r = pastedPose(h);
    if (!r.step) return ctx.say(r.why, 'error');
    insert(r.step);
  }
  /** Replaces the selected pose's joints by @p fn(pose) → { pose } or { why }; live on the robot when ticked. */
  function reshape(fn, quiet = false) {
    const s = ed.doc.steps[ed.sel];
    if (kindOf(s) !== 'pose') return;
    const r = fn(s.pose);
    if (!r.pose) return ctx.say(r.why, 'error');
    change(() => { s.pose = r.pose; }, quiet);  // live on the robot: render() sends the pose
  }
  // Mirror's signs come from the profile's body (docs/browser.md, "Mirror and a real robot"): no
  // built-in body has been checked on a real robot, so the first mirror of a page asks, and a
  // mirrored pose never goes to the robot by itself: "live" is turned off first (the user looks at
  // it in the 3D view, then ticks live to send it).
  let mirrorAsked = false;
  function mirrorTool(which) {
    if (kindOf(ed.doc.steps[ed.sel]) !== 'pose') return;
    if (!mirrorAsked) {
      if (!window.confirm(`Mirror takes each joint's turning sense from the ${h.robot} profile's body, which has not been checked on a real robot: `
        + 'on yours a mirrored joint may turn the wrong way (docs/browser.md, "Mirror and a real robot", says how to check and fix it). '
        + 'The mirrored pose is shown here first; it goes to the robot only when you tick "live". Mirror the pose?'))
        return ctx.say('mirror cancelled: the pose is as it was');
      mirrorAsked = true;
    }
    const wasLive = ed.live;
    ed.live = false;
    ed.liveSent = null;
    const before = snapshot();
    reshape((p) => mirrorPose(h, p, which), true);
    if (snapshot() === before) return;  // refused (said) or nothing to mirror
    ctx.say(wasLive ? 'mirrored; live is now off, so the robot did not move: look at the pose in the 3D view, then tick live to send it'
      : 'mirrored (the robot did not move: live is off)');
  }
  function home() {  // every joint of the pose at 0°, the robot's home with its trims
    reshape((pose) => {
      const out = {};
      for (const n of Object.keys(pose)) {
        const j = limits.get(n);
        if (j && (0 < j.lower || 0 > j.upper)) return { why: `${n}: 0° is beyond its limits ${j.lower}..${j.upper}` };
        out[n] = 0;
      }
      return { pose: out };
    });
  }
  function remove() {
    if (ed.doc.steps.length <= 1) return;
    change(() => { ed.doc.steps.splice(ed.sel, 1); flowShift(ed.doc, ed.sel, -1); clampSel(); });
  }
  function move(d) {
    const i = ed.sel, j = i + d;
    if (j < 0 || j >= ed.doc.steps.length) return;
    change(() => { [ed.doc.steps[i], ed.doc.steps[j]] = [ed.doc.steps[j], ed.doc.steps[i]]; flowMove(ed.doc, i, j); ed.sel = j; });
  }
  function reorder(from, to) {
    if (from === to) return;
    change(() => { const [s] = ed.doc.steps.splice(from, 1); ed.doc.steps.splice(to, 0, s); flowMove(ed.doc, from, to); ed.sel = to; });
  }

  steps.addEventListener('keydown', (e) => {
    const key = e.key, mod = e.ctrlKey || e.metaKey;
    if (key === 'ArrowUp' || key === 'ArrowDown') {
      const d = key === 'ArrowUp' ? -1 : 1;
      if (e.altKey) move(d); else { ed.sel += d; clampSel(); render(); }
    } else if (key === 'Delete') remove();
    else if (mod && key.toLowerCase() === 'd') duplicate();
    else if (mod && key.toLowerCase() === 'c') copy();
    else if (mod && key.toLowerCase() === 'v') paste();
    else if (mod && key.toLowerCase() === 'z') undo();
    else if (mod && key.toLowerCase() === 'y') redo();
    else return;
    e.preventDefault();
  });

  // --- drawing ---
  function render() {
    clampSel();
    keep();
    name.value = ed.doc.name || '';
    let unplayable = null;  // why the board could not play it (a jump to no label): said in the summary
    const segs = (() => { try { return segments(ed.doc.steps, ctx.measured()); } catch (e) { unplayable = e.message; return []; } })();
    steps.replaceChildren(...ed.doc.steps.map((s, i) => {
      const k = kindOf(s);
      const bad = k === 'pose' && Object.entries(s.pose).some(([n, v]) => limits.has(n) && (v < limits.get(n).lower || v > limits.get(n).upper));
      const li = el('li', { class: `step ${k}` + (i === ed.sel ? ' selected' : '') + (bad ? ' beyond' : ''), draggable: 'true', 'data-step': i },
        el('span', { class: 'n', text: String(i + 1) }), el('span', { text: describe(s) }));
      li.addEventListener('click', () => { ed.sel = i; render(); });
      li.addEventListener('dragstart', (e) => { e.dataTransfer.setData('text/plain', String(i)); });
      li.addEventListener('dragover', (e) => e.preventDefault());
      li.addEventListener('drop', (e) => { e.preventDefault(); reorder(Number(e.dataTransfer.getData('text/plain')), i); });
      return li;
    }));
    drawJumps();
    flow.render();
    // The timeline: each pose a block as long as its time (one pass).
    const poses = ed.doc.steps.map((s, i) => [s, i]).filter(([s]) => kindOf(s) === 'pose');
    const total = poses.reduce((a, [s]) => a + s.time_ms, 0) || 1;
    timeline.replaceChildren(cursor, ...poses.map(([s, i]) => {
      const b = el('div', { class: 'block' + (i === ed.sel ? ' selected' : ''), 'data-step': i, title: `step ${i + 1}${s.name ? ` (${s.name})` : ''}: ${s.time_ms} ms`, text: s.name || String(i + 1) });
      b.style.flexGrow = String(Math.max(s.time_ms, 1) / total);
      b.addEventListener('click', () => { ed.sel = i; render(); });
      return b;
    }));
    const played = segs.reduce((a, g) => a + g.ms, 0);
    summary.textContent = `${ed.doc.steps.length} steps, ${poses.length} poses; ` + (unplayable
      ? `does not play: ${unplayable}`
      : segs.endless ? 'plays until stopped: it goes round for ever (no button held)'
      : `plays ${(played / 1000).toFixed(2)} s as the board would (loops counted, no button held)`);
    renderDetail();
    ctx.view?.setGhost(poseAt(ed.sel));
    // Live on the robot: the robot shows the selected pose, whatever changed it (an edit, a pose
    // tool, undo or redo, another step selected), at the server's speed limit.
    const cur = ed.doc.steps[ed.sel];
    if (ed.live && kindOf(cur) === 'pose' && ctx.controlling()) {
      const key = JSON.stringify(cur.pose);
      if (key !== ed.liveSent) { ed.liveSent = key; sendLive(cur.pose); }
    }
    ctx.controls();
    balance?.schedule();
  }

  function drawJumps() {
    const rows = [...steps.children];
    const labels = new Map();
    ed.doc.steps.forEach((s, i) => { if (kindOf(s) === 'label') labels.set(s.label, i); });
    jumps.replaceChildren();
    const h0 = steps.offsetTop;
    jumps.setAttribute('height', String(steps.offsetHeight + 4));
    ed.doc.steps.forEach((s, i) => {
      const to = s.goto ?? s.loop ?? s.count_down;
      if (typeof to !== 'string' || !labels.has(to) || !rows[i]) return;
      const y1 = rows[i].offsetTop - h0 + rows[i].offsetHeight / 2, y2 = rows[labels.get(to)].offsetTop - h0 + rows[labels.get(to)].offsetHeight / 2;
      const bend = 8 + Math.min(Math.abs(y2 - y1) / 6, 18);
      const p = document.createElementNS('http://www.w3.org/2000/svg', 'path');
      p.setAttribute('d', `M 34 ${y1} C ${34 - bend} ${y1}, ${34 - bend} ${y2}, 34 ${y2}`);
      p.setAttribute('class', 'jump');
      jumps.append(p);
    });
  }

  function renderDetail() {
    const s = ed.doc.steps[ed.sel];
    if (kindOf(s) !== 'pose') {  // a form for its kind: nothing typed as JSON
      const form = stepForm(s, ed.doc, ctx);
      const apply = el('button', { type: 'button', id: 'ed-step-apply' }, 'Apply');
      apply.addEventListener('click', () => {
        const r = form.read();
        if (!r.step) return ctx.say(`step ${ed.sel + 1}: ${r.why}` + (r.why.endsWith('nothing changed') ? '' : ': nothing changed'), 'error');
        ctx.say(`step ${ed.sel + 1}: ${describe(r.step)}`);  // what was applied (a refusal said before is stale)
        change(() => {
          ed.doc.steps[ed.sel] = s?.name && r.step && typeof r.step === 'object' ? { ...r.step, name: s.name } : r.step;
          if (r.renamed) {  // a renamed label: the jumps to it follow
            const [from, to] = r.renamed;
            for (const x of ed.doc.steps)
              for (const key of ['goto', 'loop', 'count_down'])
                if (x && typeof x === 'object' && x[key] === from && !(key === 'goto' && 'label' in x)) x[key] = to;
          }
        });
      });
      // Enter in a box of the form applies it, as in a pose's boxes.
      form.el.addEventListener('keydown', (e) => { if (e.key === 'Enter' && e.target.matches('input')) { e.preventDefault(); apply.click(); } });
      detail.replaceChildren(el('div', { class: 'small muted', text: `step ${ed.sel + 1}: ${describe(s)}` }), form.el, el('div', { class: 'row' }, apply));
      return;
    }
    // A pose takes one board period at least (0 ms would snap the robot to it) and 255 frames at most.
    const period = ed.doc.period_ms || 10;
    // The board counts a pose's time in whole periods (docs/motions.md §3): 1005 ms is refused, not rounded.
    const time = numberBox({ id: 'ed-time', value: s.time_ms, 'aria-label': 'time of the pose in ms' },
      { min: period, max: 255 * period, whole: true, multipleOf: period, step: period, what: 'the pose time', unit: ' ms' });
    time.addEventListener('change', () => {
      const r = numberIn(time);
      if (r.value === null) {
        if (r.why) ctx.say(`${r.why} (a pose takes ${period} to ${255 * period} ms: one to 255 periods of ${period} ms)`, 'error');
        else time.value = s.time_ms;  // emptied: nothing changes, the kept time back
        return;
      }
      change(() => { s.time_ms = r.value; });
    });
    const live = el('input', { id: 'ed-live', type: 'checkbox', class: 'needs-control' });
    live.checked = !!ed.live;
    live.addEventListener('change', () => { ed.live = live.checked; ed.liveSent = null; if (ed.live) render(); });
    const rows = h.joints.map((j) => {
      const on = j.name in s.pose;
      const v = on ? s.pose[j.name] : poseAt(ed.sel - 1)[j.name] ?? 0;
      const tick = el('input', { type: 'checkbox', 'aria-label': `${j.name} in this pose` });
      tick.checked = on;
      const slider = el('input', { type: 'range', min: j.lower, max: j.upper, step: 0.5, value: v, disabled: !on, 'aria-label': `${j.name} degrees` });
      const num = numberBox({ value: Math.round(v * 10) / 10, disabled: !on, 'aria-label': `${j.name} degrees, typed` },
        { min: j.lower, max: j.upper, step: 0.5, what: j.name, unit: '°' });
      const before = poseAt(ed.sel - 1)[j.name];
      const same = el('button', { type: 'button', class: 'as-before', text: '↶', disabled: !on || !Number.isFinite(before),
        title: Number.isFinite(before) ? `as in the pose before: ${Math.round(before * 10) / 10}°` : 'no angle before this pose',
        'aria-label': `${j.name} as in the pose before` });
      same.addEventListener('click', () => set(before, true));
      const row = el('div', { class: 'pose-joint' + (on && (v < j.lower || v > j.upper) ? ' beyond' : ''), 'data-joint': j.name },
        tick, el('span', { class: 'name', text: j.name }), slider, num, same);
      tick.addEventListener('change', () => {
        if (!tick.checked) return change(() => { delete s.pose[j.name]; });
        // the joint joins the pose at the angle its box shows, checked as a typed one is
        const r = numberIn(num);
        if (r.value === null) { tick.checked = false; return ctx.say(r.why || `${j.name}: type its angle first`, 'error'); }
        change(() => { s.pose[j.name] = r.value; });  // live: render() sends the pose
      });
      const set = (x, commit) => {
        if (!(x >= j.lower && x <= j.upper)) {  // refused: said, shown red a moment, the kept value back
          row.classList.add('beyond');
          ctx.say(`${j.name}: ${x}° is beyond its limits ${j.lower}..${j.upper}: not taken`, 'error');
          setTimeout(() => { num.value = s.pose[j.name]; row.classList.remove('beyond'); }, 1500);
          return;
        }
        row.classList.remove('beyond');
        if (commit) {
          change(() => { s.pose[j.name] = x; });  // live: render() sends the pose
        } else {  // a drag: the joint goes live as it moves (render() comes at the drag's end)
          s.pose[j.name] = x;
          ctx.view?.setGhost(poseAt(ed.sel));
          if (ed.live) sendLive({ [j.name]: x });
        }
      };
      // A drag is one undo step: the motion as it was before the drag's first movement.
      let beforeDrag = null;
      slider.addEventListener('input', () => {
        beforeDrag ??= snapshot();
        num.value = slider.value;
        set(Number(slider.value), false);
      });
      slider.addEventListener('change', () => {
        if (beforeDrag !== null && beforeDrag !== snapshot()) { ed.undo.push(beforeDrag); ed.redo = []; }
        beforeDrag = null;
        render();
      });
      num.addEventListener('change', () => {
        // letters or a cleared box are no angle: marked, nothing applied, nothing sent, nothing moves
        const r = numberIn(num);  // beyond the joint's limits: marked, its reason on the box
        if (r.value === null) {
          if (r.why) ctx.say(r.why, 'error');
          else num.value = s.pose[j.name];  // emptied: the kept angle back
          return;
        }
        set(r.value, true);
      });
      return row;
    });
    const mirrorable = canMirror(h), noBody = mirrorable ? '' : ' (this robot\'s profile has no body: kinematics)';
    const tools = el('div', { class: 'row small' },
      bt('ed-mirror', 'Mirror ⇄', 'the pose mirrored left ↔ right (from the robot\'s body)' + noBody, () => mirrorTool('both')),
      bt('ed-l2r', 'Left → right', 'the left limbs\' angles onto the right ones' + noBody, () => mirrorTool('left')),
      bt('ed-r2l', 'Right → left', 'the right limbs\' angles onto the left ones' + noBody, () => mirrorTool('right')),
      bt('ed-home', 'Home', 'every joint of this pose at 0° (the robot\'s home, with its trims)', home));
    for (const id of ['ed-mirror', 'ed-l2r', 'ed-r2l']) tools.querySelector(`#${id}`).disabled = !mirrorable;
    // Its name, shown in the list and on the timeline (kept in the motion file; the board never sees it).
    const named = el('input', { id: 'ed-step-name', type: 'text', maxlength: 80, value: s.name || '', placeholder: 'name', 'aria-label': 'name of the pose' });
    named.addEventListener('change', () => change(() => { const v = named.value.trim().slice(0, 80); if (v) s.name = v; else delete s.name; }));
    detail.replaceChildren(el('div', { class: 'row small' }, `step ${ed.sel + 1}:`, named, 'pose over', time, 'ms',
      el('label', { class: 'small' }, live, ' live on the robot')), tools, el('div', { class: 'pose-joints' }, ...rows));
    ctx.controls();
  }

  // Live editing moves the robot through the server (its speed limit, its limits, its move rule).
  function sendLive(joints) { if (ctx.controlling()) ctx.send({ op: 'move', joints }); }

  // --- files and slots ---
  // The motion file: the steps, each with its flowchart block's place (`at`) and its name.
  const text = () => JSON.stringify({ ...ed.doc, steps: toFile(ed.doc), flow: undefined, name: name.value.trim() || undefined, robot: h.robot });
  name.addEventListener('change', () => change(() => { ed.doc.name = name.value.trim(); }));
  function load(doc) {
    // A motion loaded (New, Pull, Open…) is no move asked for: live goes off, the robot stays. The
    // words for it are returned, for the caller's message.
    const wasLive = ed.live;
    ed.live = false;
    ed.liveSent = null;
    ed.undo.push(snapshot(true));
    ed.redo = [];  // what was undone before belongs to the motion replaced
    const opened = fromFile(doc.steps?.length ? doc.steps : ['end']);
    ed.doc = { robot: doc.robot || h.robot, name: doc.name || '', period_ms: doc.period_ms || 10, steps: opened.steps, flow: opened.flow };
    ed.from = null;  // a pull sets it again: the slot it came from
    ed.sel = 0;
    render();
    return wasLive ? '; live is now off, so the robot did not move (tick live to send the selected pose)' : '';
  }
  async function pull() {
    try {
      const n = slotIn(); if (n === null) return;
      if (!mayReplace(`Pulling slot ${n}`)) return ctx.say('pull cancelled: the motion in the editor is kept');
      const r = await ctx.request({ op: 'motion_pull', slot: n });
      const note = load(r.motion);
      ed.from = n;
      markClean();
      ctx.say(`motion ${r.slot} in the editor (${r.plays})` + (r.problem ? `; as it is, it would not push back: ${r.problem}` : '') + note);
    } catch (e) { ctx.say(e.message, 'error'); }
  }
  async function push() {
    try {
      const n = slotIn(); if (n === null) return;
      // Another motion's slot is replaced only when the user says so (its bytes are backed up
      // anyway); the slot this motion was pulled from or last pushed to is not asked about.
      const held = (ctx.motions() ?? []).find((m) => m.slot === n);
      if (held && n !== ed.from && !window.confirm(`Slot ${n} holds ${held.name ? `"${held.name}"` : 'a motion'}: Push replaces it with the motion in the editor (its bytes are backed up first). Push to slot ${n}?`))
        return ctx.say(`push cancelled: slot ${n} is as it was`);
      const r = await ctx.request({ op: 'motion_push', slot: n, text: text() });
      ed.from = n;
      const notes = r.notes?.length ? ` (${r.notes.join('; ')})` : '';
      markClean();
      ctx.say(r.unchanged ? `motion ${r.slot} already holds these ${r.bytes} bytes: nothing written${notes}`
        : `wrote ${r.bytes} bytes to motion ${r.slot}: ${r.summary}; the old bytes are in ${r.backup}${notes}`);
      $('#ed-result').textContent = r.unchanged ? '' : `backup: ${r.backup}`;
      ctx.refresh();
    } catch (e) { ctx.say(e.message, 'error'); }
  }
  async function save() {
    const base = (name.value.trim() || 'motion').replace(/[^A-Za-z0-9_-]+/g, '_');
    if (!ctx.connected()) {  // rcb4 ui gone: the motion file as JSON (the tool reads it as it reads YAML)
      const a = el('a', { href: URL.createObjectURL(new Blob([text()], { type: 'application/json' })), download: base + '.json' });
      a.click();
      markClean();
      setTimeout(() => URL.revokeObjectURL(a.href), 5000);
      return ctx.say(`downloading ${a.download} (no connection to rcb4 ui: saved as JSON, unchecked; rcb4 motion push reads it): check your browser's downloads`);
    }
    try {
      const r = await ctx.request({ op: 'motion_check', text: text() });
      const a = el('a', { href: URL.createObjectURL(new Blob([r.yaml], { type: 'application/yaml' })), download: base + '.yaml' });
      a.click();
      markClean();
      setTimeout(() => URL.revokeObjectURL(a.href), 5000);
      // The page cannot know whether the browser kept the file: it says what it did.
      ctx.say(r.problem ? `downloading ${a.download} (check your browser's downloads), but as it is it would not play: ${r.problem}`
        : `downloading ${a.download} (${r.plays}): check your browser's downloads`, r.problem ? 'error' : 'note');
    } catch (e) { ctx.say(e.message, 'error'); }
  }
  file.addEventListener('change', async () => {
    const f = file.files[0];
    if (!f) return;
    file.value = '';  // the same file chosen again opens again
    if (/\.bin$/i.test(f.name)) return putBack(f);
    if (f.size > MAX_FILE_BYTES)  // beyond what a page may send: refused here, the connection kept
      return ctx.say(`${f.name}: ${Math.ceil(f.size / 1024)} KiB: a motion file may be up to ${MAX_FILE_BYTES / 1024} KiB (a slot holds a few KiB): not opened`, 'error');
    if (!mayReplace(`Opening ${f.name}`)) return ctx.say('open cancelled: the motion in the editor is kept');
    try {
      const r = await ctx.request({ op: 'motion_check', text: await f.text() });
      const note = load(r.motion);
      markClean();
      ctx.say(`${f.name}: ${r.problem ? 'opened; as it is it would not play: ' + r.problem : 'opened'}${note}`, r.problem ? 'error' : 'note');
    } catch (e) { ctx.say(`${f.name}: ${e.message}`, 'error'); }
  });

  // A slot's .bin backup (a push or an erase saved it) goes back into the slot typed, as `rcb4
  // motion push FILE.bin N` puts it: checked, the slot's bytes backed up first, read back.
  async function putBack(f) {
    const n = slotIn(); if (n === null) return;
    if (f.size === 0 || f.size > 16384) return ctx.say(`${f.name}: ${f.size} bytes: not a slot's backup (a slot holds at most a few KiB)`, 'error');
    if (!window.confirm(`Write the backup ${f.name} (${f.size} bytes) into slot ${n}? The slot's bytes are backed up first.`)) return ctx.say('nothing written');
    const bytes = new Uint8Array(await f.arrayBuffer());
    let binary = '';
    for (let i = 0; i < bytes.length; i += 8192) binary += String.fromCharCode(...bytes.subarray(i, i + 8192));
    try {
      const r = await ctx.request({ op: 'motion_put_back', slot: n, base64: btoa(binary), file: f.name.slice(0, 64) });
      ctx.refresh();  // first: the refresh's own answer would take the place of what is said here
      ctx.say(r.unchanged ? `slot ${n} already holds ${f.name}: nothing written` : `${f.name} is back in slot ${n} (${r.bytes} bytes); the bytes it replaced are in ${r.backup}`);
    } catch (e) { ctx.say(`${f.name}: ${e.message}`, 'error'); }
  }

  // --- preview, play, stop: playback.js ---
  const playback = createPlayback(ed, ctx, text, cursor, poseAt);
  const { preview, play, stop } = playback;
  // --- does it stand? balance.js ---
  const balanceLine = el('div', { id: 'ed-balance', class: 'small' });
  summary.after(balanceLine);
  balance = createBalance(ctx, text, balanceLine, [steps, timeline]);
  root.append(el('div', { id: 'ed-result', class: 'small muted' }));
  // Ctrl+Z / Ctrl+Y right after typing a value, in its box, as HTH4 users do: the box's value is
  // taken first (as leaving it would), then the motion's undo or redo; the browser's own text undo
  // would only change the box.
  root.addEventListener('keydown', (e) => {
    if (!(e.ctrlKey || e.metaKey) || !e.target.matches?.('input.num')) return;
    const k = e.key.toLowerCase();
    if (k !== 'z' && k !== 'y') return;
    e.preventDefault();
    e.target.blur();
    if (k === 'y' || e.shiftKey) redo(); else undo();
  });

  render();
  return {
    load, render,
    get doc() { return ed.doc; },
    /** The motion as the page saves and pushes it: the file's JSON text (tests). */
    text,
    /** The selected step's index; setting it selects that step (tests). */
    get sel() { return ed.sel; },
    set sel(i) { ed.sel = i; render(); },
    /** Inserts a saved pose (@p joints: name → degrees) as a pose step after the selected one. */
    insertPose(joints, timeMs, poseName) {
      const period = ed.doc.period_ms || 10;
      const ok = Number.isInteger(timeMs) && timeMs >= period && timeMs <= 255 * period;
      insert({ pose: { ...joints }, time_ms: ok ? timeMs : 500, ...(poseName ? { name: String(poseName).slice(0, 80) } : {}) });
      const own = ok || timeMs === null || timeMs === undefined ? '' : ` over 500 ms (its own ${timeMs} ms is no pose time here)`;
      ctx.say(`pose ${poseName} inserted as step ${ed.sel + 1}${own}`);
    },
    /** Where the last preview started, ms into the motion (tests). */
    get previewFrom() { return ed.previewFrom ?? null; },
    /** The undo and redo depths, and whether the motion has unsaved changes (tests). */
    get history() { return { undo: ed.undo.length, redo: ed.redo.length, dirty: dirty() }; },
    /** True while a motion plays from the host (tests). */
    get playing() { return !!ed.playing; },
    /** A motion played from the host ended (the server's "played"). */
    played(m) { ed.playing = false; ctx.say(m.error ? `the play stopped: ${m.error}` : `played ${m.poses} poses in ${m.seconds} s`, m.error ? 'error' : 'note'); },
    stop,
  };
}
