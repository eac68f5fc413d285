// rcb4 ui: the page's entry (an ES module): the connection, the joints, poses, sensors, and the
// studio's parts (view3d.js, editor.js, tables.js). One WebSocket to the server that owns the
// board; nothing else is reached. Messages: studio/policy/messages.hpp (to the server),
// board_loop.cpp, controller.cpp and studio_ops.cpp (from it).
import { $, el, breakable, fmtDeg, numberIn } from './dom.js';
import { createView } from './view3d.js';
import { createEditor } from './editor.js';
import { createTables } from './tables.js';

const ui = {
  ws: null,
  hello: null,
  role: 'view',
  controlled: false,
  rows: new Map(),       // joint name → {row, slider, angle, target, marker, j, index}
  dragging: new Map(),   // joint name → time the page last moved its slider
  sendTimer: null,
  pendingMoves: {},
  nextId: 1,
  history: [],           // [{t, battery, ad:[…]}] over the last 30 s
  lastState: null,
  motions: [],
  pending: new Map(),    // request id → {resolve, reject}: the studio's requests
  studio: null,          // {view, editor, tables} once the hello came
  measured: {},          // joint → degrees, as last read
};

/** Sends @p msg and resolves with the server's reply (rejects with its error's words). */
function request(msg) {
  return new Promise((resolve, reject) => {
    const id = send(msg);
    if (id === null) return reject(new Error('not connected to rcb4 ui'));
    const timer = setTimeout(() => { ui.pending.delete(id); reject(new Error(`${msg.op}: no answer in 60 s`)); }, 60000);
    ui.pending.set(id, { resolve: (m) => { clearTimeout(timer); resolve(m); }, reject: (e) => { clearTimeout(timer); reject(e); } });
  });
}

// --- the connection -------------------------------------------------------------------------------

function connect() {
  const token = new URLSearchParams(location.search).get('token');
  const url = `ws://${location.host}/ws` + (token ? `?token=${encodeURIComponent(token)}` : '');
  const ws = new WebSocket(url);
  ui.ws = ws;
  ws.onmessage = (ev) => {
    let m;
    try { m = JSON.parse(ev.data); } catch { return; }
    on[m.type]?.(m);
  };
  ws.onclose = () => {
    // The motion being edited is kept in this browser for this address only: an rcb4 ui started
    // again on another port is another address, and the motion is not there. Said while it lasts.
    const unsaved = ui.studio?.editor.history.dirty;
    setLink(false, 'no connection to rcb4 ui: is it still running? retrying…' + (unsaved
      ? ` Your motion has unsaved changes, kept in this browser for ${location.host} only: Save it to a file now (Save works without the connection)` : ''));
    setRole('view', false);
    setTimeout(connect, 1000);
  };
}

/**
 * A free, hold or motion stop stops what plays first (its next pose would power or move the joints
 * again): the words for it, and the editor told that its play from the host has ended.
 */
function stoppedFirst(m) {
  if (m.play_stopped) ui.studio?.editor.played({ error: 'stopped by the free, hold or Stop motion' });
  return m.play_stopped || m.motion_stopped ? 'the motion playing was stopped first; ' : '';
}

function send(msg) {
  if (ui.ws?.readyState !== WebSocket.OPEN) return null;
  msg.id ??= ui.nextId++;
  ui.ws.send(JSON.stringify(msg));
  return msg.id;
}

function say(text, kind = 'note') {
  const m = $('#message');
  m.textContent = text;
  m.className = 'message show' + (kind === 'error' ? ' error' : '');
  clearTimeout(say.timer);
  say.timer = setTimeout(() => { m.className = 'message'; m.textContent = ''; }, kind === 'error' ? 8000 : 4000);
}

// --- what the server sends --------------------------------------------------------------------------

const on = {
  hello(m) {
    ui.hello = m;
    document.title = `${m.robot} — rcb4 studio`;
    $('#robot').textContent = m.robot;
    $('#version').textContent = `rcb4 ${m.version}`;
    buildJoints(m);
    buildStudio(m);
  },
  played(m) { ui.studio?.editor.played(m); },
  role(m) { setRole(m.role, m.controlled); },
  lists(m) {
    ui.motions = m.motions;
    renderPoses(m.poses, m.poses_dir);
    renderMotions();
    // The slot table too when the slots changed (another program wrote or erased one).
    const slots = JSON.stringify(m.motions.map((x) => [x.slot, x.frames]));
    if (ui.slotsSeen !== undefined && slots !== ui.slotsSeen) ui.studio?.tables.list();
    ui.slotsSeen = slots;
  },
  state(m) {
    ui.lastState = m;
    window.rcb4State = m;  // the tests and the benchmark read it
    renderState(m);
    // A board that does not answer: every angle unknown (never 0), and the drawn robot says so.
    ui.hello?.joints.forEach((j, i) => { ui.measured[j.name] = m.answering ? m.angles[i] : null; });
    if (ui.studio) {
      ui.studio.view?.setMeasured(ui.measured);
      ui.studio.tables.running(m.motion.running ? m.motion.slot : null);
    }
  },
  reply(m) {
    const p = ui.pending.get(m.id);
    if (p) { ui.pending.delete(m.id); p.resolve(m); return; }
    const what = {
      capture: () => `captured ${m.joints} joints as ${m.name}` + (m.left_out?.length ? ` (left out: ${m.left_out.join(', ')})` : '') +
        (m.clamped?.length ? ` (saved at the limit: ${m.clamped.join(', ')})` : ''),
      play_pose: () => `playing ${m.name} over ${m.ms} ms`,
      motion_play: () => `playing motion ${m.slot}`,
      motion_file: () => showMotionFile(m),
      motion_stop: () => { stoppedFirst(m); return 'motion stopped' + (m.play_stopped ? ' (and the play from the host)' : '') + ': every joint holds where it is'; },
      stop: () => 'stopped: every joint holds where it is',
      free: () => stoppedFirst(m) + `${m.joints} joints free` + (m.missing?.length ? ` (no servo: ${m.missing.join(', ')})` : ''),
      hold: () => stoppedFirst(m) + `${m.joints} joints holding` + (m.missing?.length ? ` (no servo: ${m.missing.join(', ')})` : ''),
      control: () => 'this page controls the robot',
      release: () => 'control released',
    }[m.op];
    if (what) say(what());
  },
  note(m) { say(m.text ?? (m.clamped || []).join('; ')); },
  error(m) {
    const p = ui.pending.get(m.id);
    if (p) { ui.pending.delete(m.id); p.reject(new Error((m.op ? m.op + ': ' : '') + m.message)); return; }
    say((m.op ? m.op + ': ' : '') + m.message, 'error');
  },
};

// --- joints -----------------------------------------------------------------------------------------

function buildJoints(h) {
  const box = $('#joints');
  box.replaceChildren();
  ui.rows.clear();
  const inGroup = new Set();
  const groups = h.groups.filter((g) => g.joints.length);
  for (const g of groups) g.joints.forEach((n) => inGroup.add(n));
  const rest = h.joints.filter((j) => !inGroup.has(j.name)).map((j) => j.name);
  if (rest.length) groups.push({ name: groups.length ? 'other' : 'all', joints: rest, synthetic: true });
  const byName = new Map(h.joints.map((j, i) => [j.name, { ...j, index: i }]));
  // A group whose joints all show in earlier cards (arms = left arm + right arm) gets buttons only.
  const shown = new Set();
  const bar = el('div', { class: 'group wide', 'data-group': '(sets)' }, el('h2', {}, 'groups'));
  for (const g of groups) {
    if (g.joints.every((n) => shown.has(n))) {
      const words = [g.name];
      bar.append(el('span', { class: 'set', 'data-set': g.name }, g.name.replaceAll('_', ' '), ' ',
        el('button', { type: 'button', class: 'needs-control', onclick: () => send({ op: 'free', joints: words }) }, 'Free'),
        ' ',
        el('button', { type: 'button', class: 'needs-control', onclick: () => send({ op: 'hold', joints: words }) }, 'Hold')));
      continue;
    }
    g.joints.forEach((n) => shown.add(n));
    const card = el('div', { class: 'group', 'data-group': g.name });
    const words = g.synthetic ? g.joints : [g.name];
    card.append(el('h2', {}, g.name.replaceAll('_', ' '),
      el('span', { class: 'actions' },
        el('button', { type: 'button', class: 'needs-control', onclick: () => send({ op: 'free', joints: words }) }, 'Free'),
        ' ',
        el('button', { type: 'button', class: 'needs-control', onclick: () => send({ op: 'hold', joints: words }) }, 'Hold'))));
    for (const n of g.joints) {
      if (ui.rows.has(n)) continue;  // a joint in two groups is shown once, in the first
      card.append(jointRow(byName.get(n)));
    }
    box.append(card);
  }
  if (bar.childElementCount > 1) box.append(bar);
  setRole(ui.role, ui.controlled);
}

function jointRow(j) {
  const slider = el('input', {
    type: 'range', min: j.lower, max: j.upper, step: 0.5, value: Math.min(Math.max(0, j.lower), j.upper),
    'data-joint': j.name, 'aria-label': `${j.name} target in degrees`,
  });
  const marker = el('span', { class: 'measured', title: 'measured angle' });  // under the thumb's centre (style.css)
  const angle = el('span', { class: 'angle', text: '–', title: 'measured angle' });
  const target = el('span', { class: 'target', text: '' });
  const row = el('div', { class: 'joint', 'data-joint': j.name },
    el('span', { class: 'name', title: `ICS ${j.ics}` }, ...breakable(j.name)),
    el('div', { class: 'slider' }, slider, marker),
    angle,
    el('span', { class: 'power' },
      el('button', { type: 'button', title: 'no torque', onclick: () => send({ op: 'free', joints: [j.name] }) }, 'free'),
      el('button', { type: 'button', title: 'torque on where it is', onclick: () => send({ op: 'hold', joints: [j.name] }) }, 'hold')),
    el('span', { class: 'target-line' }, target),
    el('div', { class: 'limits' }, el('span', { text: `${j.lower}°` }), el('span', { text: `${j.upper}°` })));
  // While the pointer holds the slider it is the person's; otherwise it follows the board.
  slider.addEventListener('pointerdown', () => { ui.rows.get(j.name).held = true; });
  const letGo = () => { ui.rows.get(j.name).held = false; ui.dragging.set(j.name, performance.now()); };
  slider.addEventListener('pointerup', letGo);
  slider.addEventListener('pointercancel', letGo);
  slider.addEventListener('input', () => {
    ui.dragging.set(j.name, performance.now());
    ui.pendingMoves[j.name] = Number(slider.value);
    target.textContent = `→ ${fmtDeg(Number(slider.value))}`;
    // The first move of a drag goes at once; what follows is gathered: at most 25 messages a second.
    if (!ui.sendTimer) { sendMoves(); ui.sendTimer = setTimeout(flushMoves, 40); }
  });
  ui.rows.set(j.name, { row, slider, angle, target, marker, j });
  return row;
}

/** Sends the gathered slider moves, if any; true when it did. */
function sendMoves() {
  const joints = ui.pendingMoves;
  ui.pendingMoves = {};
  if (!Object.keys(joints).length) return false;
  if (ui.ws?.readyState === WebSocket.OPEN) ui.ws.send(JSON.stringify({ op: 'move', joints }));
  return true;
}

/** Every 40 ms while a drag goes on: what was gathered; with nothing, the next move goes at once. */
function flushMoves() {
  ui.sendTimer = sendMoves() ? setTimeout(flushMoves, 40) : null;
}

function renderState(s) {
  const h = ui.hello;
  if (!h) return;
  const now = performance.now();
  h.joints.forEach((j, i) => {
    const r = ui.rows.get(j.name);
    if (!r) return;
    const mode = s.modes[i];
    r.row.className = 'joint ' + mode;
    r.angle.textContent = fmtDeg(s.angles[i]);
    if (s.angles[i] !== null) {
      const f = (s.angles[i] - j.lower) / (j.upper - j.lower);
      // The thumb's centre runs from half a thumb in to half a thumb short of the end (--thumb).
      r.marker.style.left = `calc(var(--thumb) / 2 + (100% - var(--thumb)) * ${Math.min(Math.max(f, 0), 1).toFixed(4)} - 1px)`;
      r.marker.hidden = false;
    } else {
      r.marker.hidden = true;
    }
    const t = s.targets[i];
    const moved = ui.dragging.get(j.name);
    const recent = moved !== undefined && now - moved < 800;
    if (!recent && !r.held) {
      r.target.textContent = mode === 'free' ? 'free' : mode === 'hold' ? 'hold' : t === null ? '' : `target ${fmtDeg(t)}`;
      r.target.dataset.degrees = t === null ? '' : String(t);
      // A free or held joint has no target: its slider shows where the joint is.
      const follow = t !== null ? t : s.angles[i];
      if (follow !== null) r.slider.value = follow;
    }
  });
  renderLink(s);
  renderMotion(s.motion, s.answering);
  recordSensors(s);
}

// --- the link, the role -------------------------------------------------------------------------------

function setLink(ok, text) {
  $('#dot').className = 'dot ' + (ok ? 'ok' : 'bad');
  $('#link-text').textContent = text;
}

function renderLink(s) {
  const l = ui.hello.link;
  const where = `${l.device}${l.baud ? ` · ${l.baud} baud` : ''}`;
  const n = (k, word) => `${k} ${word}${k === 1 ? '' : 's'}`;
  const counts = `${s.link.per_second.toFixed(0)} exchanges/s · ${n(s.link.errors, 'error')}` +
    (s.link.timeouts ? ` · ${n(s.link.timeouts, 'timeout')}` : '');
  setLink(s.answering, s.answering ? `${where} · ${counts}` : `${where} · board not answering: ${s.error}`);
  $('#link').dataset.answering = String(s.answering);
}

function setRole(role, controlled) {
  ui.role = role;
  ui.controlled = controlled;
  document.body.classList.toggle('view', role !== 'control');
  const badge = $('#role');
  badge.textContent = role === 'control' ? 'controlling' : controlled ? 'watching (another page controls)' : 'watching';
  badge.className = 'badge' + (role === 'control' ? ' control' : '');
  // Watching: the controls are disabled (keyboard too), not only dimmed.
  for (const e of document.querySelectorAll('.needs-control, .joint input, .joint .power button'))
    e.disabled = role !== 'control';
  const b = $('#control');
  b.textContent = role === 'control' ? 'Release' : 'Take control';
  b.disabled = role !== 'control' && controlled;
  // A watching page says why its controls are off, where they are.
  const note = $('#role-note');
  note.hidden = role === 'control';
  note.textContent = ui.ws?.readyState !== WebSocket.OPEN ? 'No connection to rcb4 ui: nothing on this page reaches the robot until it is back (the header says more).'
    : controlled ? 'Another page controls the robot: this one watches, so its controls are off until that page releases control or closes.'
    : 'This page watches: Take control to move the robot, edit trims and buttons, or write motions.';
}

// --- poses and motions -------------------------------------------------------------------------------

function renderPoses(poses, dir) {
  const list = $('#poses');
  list.replaceChildren(...poses.map((p) => el('li', { 'data-pose': p },
    el('span', { text: p }),
    el('button', { type: 'button', class: 'play needs-control', onclick: () => playPose(p) }, 'Play'),
    el('button', { type: 'button', class: 'insert', title: 'insert into the motion in the editor, after the selected step',
      onclick: () => insertPose(p) }, 'Insert'))));
  if (!poses.length) list.append(el('li', { class: 'muted', text: 'no pose saved yet' }));
  $('#poses-dir').textContent = dir ? `saved in ${dir}` : '';
  setRole(ui.role, ui.controlled);
}

/** A saved pose into the motion being edited, as a new pose step (read and checked by the server). */
async function insertPose(name) {
  try {
    const r = await request({ op: 'pose_read', name });
    ui.studio?.editor.insertPose(r.joints, r.time_ms, name);
  } catch (e) {
    say(`${name}: ${e.message}`, 'error');
  }
}

/**
 * "play over"'s check: whole periods of the board's output period (the state says it; 10 ms until
 * the first state), 255 of them at most (the server stretches the time to the speed limit).
 */
function playOverCheck() {
  const period = ui.lastState?.output_period_ms || 10;
  return { min: period, max: 255 * period, whole: true, multipleOf: period, what: 'play over', unit: ' ms' };
}

function playPose(name) {
  // the time the pose is played over: checked, never coerced (letters are no 0 ms snap)
  const box = $('#pose-ms');
  box.numberCheck = playOverCheck();
  const r = numberIn(box);
  if (r.value === null) return say(r.why || `play over: type a time in ms (${box.numberCheck.min} to ${box.numberCheck.max})`, 'error');
  send({ op: 'play_pose', name, ms: r.value });
}

// A ROM motion read back as a motion file: shown, and saved by the browser (rcb4 motion push reads it).
function showMotionFile(m) {
  const name = (m.name || `motion-${m.slot}`) + '.yaml';
  $('#motion-file-title').textContent = `motion ${m.slot}` + (m.name ? ` (${m.name})` : '');
  $('#motion-file-text').textContent = m.yaml;
  $('#motion-file-problem').textContent = m.problem ? `as it is, it would not push back: ${m.problem}` : '';
  const link = $('#motion-file-save');
  if (link.href) URL.revokeObjectURL(link.href);
  link.href = URL.createObjectURL(new Blob([m.yaml], { type: 'application/yaml' }));
  link.download = name;
  $('#motion-file').hidden = false;
  return `motion ${m.slot} as a motion file`;
}

function renderMotions() {
  const list = $('#motions');
  list.replaceChildren(...ui.motions.map((m) => el('li', { 'data-motion': m.slot },
    el('span', { text: `${m.slot} ${m.name ?? ''}`.trim() + (m.readable ? '' : ' (unreadable)') }),
    el('button', { type: 'button', class: 'needs-control', onclick: () => send({ op: 'motion_play', slot: m.slot }) }, 'Play'),
    el('button', { type: 'button', title: 'the motion as a motion file (rcb4 motion pull)', onclick: () => send({ op: 'motion_file', slot: m.slot }) }, 'YAML'))));
  if (!ui.motions.length) list.append(el('li', { class: 'muted', text: 'no motion in ROM' }));
  setRole(ui.role, ui.controlled);
}

function renderMotion(m, answering = true) {
  // A board that does not answer tells nothing: its motion may still run (a cable out).
  const text = !answering ? 'motion unknown: the board does not answer (it may still be playing one)'
    : m.suspended ? (m.slot ? `motion ${m.slot} stopped part way` : 'the ROM program is stopped')
    : m.running ? (m.slot ? `motion ${m.slot} running` : 'the ROM program runs outside the motion slots')
    : 'no motion running';
  $('#motion-state').textContent = text;
  $('#motion-progress').value = m.progress ?? 0;
  for (const li of document.querySelectorAll('#motions li[data-motion]'))
    li.classList.toggle('running', m.running && !m.suspended && String(m.slot) === li.dataset.motion);
}

// --- sensors -----------------------------------------------------------------------------------------

const adColours = ['#2f6fdf', '#d0342c', '#1f9d55', '#c77700', '#7b3fc4', '#0f9aa8', '#b83280', '#5a6372', '#8c6d1f', '#3f51b5'];

function recordSensors(s) {
  const t = performance.now() / 1000;
  if (s.battery !== null) ui.history.push({ t, battery: s.battery, ad: s.ad });
  while (ui.history.length && ui.history[0].t < t - 30) ui.history.shift();
  $('#battery').textContent = s.battery === null ? '–' : `${s.battery.toFixed(2)} V`;
  if (!recordSensors.drawn || t - recordSensors.drawn > 0.2) {  // drawn 5 times a second: calm, cheap
    recordSensors.drawn = t;
    plot($('#battery-plot'), t, [(p) => p.battery], ['#2f6fdf'], null);
    plot($('#ad-plot'), t, adColours.map((_, k) => (p) => p.ad[k]), adColours, [0, 1023]);
  }
}

function plot(canvas, now, series, colours, fixed) {
  const g = canvas.getContext('2d');
  const w = canvas.width, h = canvas.height;
  g.clearRect(0, 0, w, h);
  const pts = ui.history;
  if (!pts.length) return;
  let lo = fixed ? fixed[0] : Infinity, hi = fixed ? fixed[1] : -Infinity;
  if (!fixed) for (const p of pts) for (const f of series) { lo = Math.min(lo, f(p)); hi = Math.max(hi, f(p)); }
  if (hi - lo < 0.2) { const mid = (hi + lo) / 2; lo = mid - 0.1; hi = mid + 0.1; }
  const x = (t) => ((t - (now - 30)) / 30) * w;
  const y = (v) => h - 4 - ((v - lo) / (hi - lo)) * (h - 16);
  g.font = '10px system-ui, sans-serif';
  g.fillStyle = '#6b7385';
  g.fillText(fixed ? String(hi) : hi.toFixed(2), 2, 10);
  g.fillText(fixed ? String(lo) : lo.toFixed(2), 2, h - 2);
  series.forEach((f, k) => {
    g.strokeStyle = colours[k];
    g.lineWidth = 1.2;
    g.beginPath();
    pts.forEach((p, i) => (i ? g.lineTo(x(p.t), y(f(p))) : g.moveTo(x(p.t), y(f(p)))));
    g.stroke();
  });
}

// --- the studio -------------------------------------------------------------------------------------------

async function buildStudio(h) {
  const ctx = {
    hello: h,
    request,
    send,
    say,
    connected: () => ui.ws?.readyState === WebSocket.OPEN,
    resume: () => resume(),
    view: null,
    measured: () => ({ ...ui.measured }),
    motions: () => ui.motions,
    controlling: () => ui.role === 'control',
    controls: () => setRole(ui.role, ui.controlled),
    refresh: () => { send({ op: 'refresh' }); ui.studio?.tables.list(); },
    edit: async (slot) => { $('#ed-slot').value = slot; $('#ed-pull').click(); },
  };
  const editor = createEditor($('#editor'), ctx);
  const tables = createTables($('#tables'), ctx);
  ui.studio = { view: null, editor, tables };
  tables.list();
  // Shift+drag in the 3D view: the virtual board's hand turns a freed joint (a person posing it).
  const onHand = h.link.virtual ? (joint, degrees) => request({ op: 'hand', joint, degrees }).catch((e) => say(e.message, 'error')) : null;
  const view = await createView($('#view3d'), h, { onSelect: selectJoint, onHand });
  ctx.view = view;
  ui.studio.view = view;
  window.rcb4Studio = { view, editor, tables, hello: h, request };  // for the tests and the benchmark (frames drawn, state)
  if (view) { view.setMeasured(ui.measured); editor.render(); }
}

function selectJoint(name) {
  for (const r of document.querySelectorAll('.joint.selected')) r.classList.remove('selected');
  const row = ui.rows.get(name)?.row;
  if (!row) return;
  row.classList.add('selected');
  row.scrollIntoView({ block: 'nearest' });
  say(`${name} selected`);
}

/**
 * Resume, from either of its buttons (the Motions panel's, the slot table's): asks first when a
 * motion was stopped part way, since it runs on from where it stopped and the robot moves.
 */
function resume() {
  const mo = ui.lastState?.motion, free = (ui.lastState?.modes ?? []).filter((x) => x === 'free').length;
  if (mo?.suspended && mo.slot && !window.confirm(`Motion ${mo.slot} of the ROM (its slot, not a play from the editor) was stopped part way: `
    + 'Resume runs it on from where it stopped (the pose that was under way is not played again), and the robot moves'
    + (free ? `; the ${free} servos that are free now are powered again by its next pose` : '') + '. Resume it?'))
    return say('resume cancelled: the ROM program stays stopped');
  request({ op: 'motion_resume' }).then(() => say(mo?.suspended && mo.slot ? `motion ${mo.slot} runs on from where it stopped` : 'the ROM program runs again'),
    (e) => say(e.message, 'error'));
}

// --- the buttons ----------------------------------------------------------------------------------------

function wire() {
  $('#control').addEventListener('click', () => send({ op: ui.role === 'control' ? 'release' : 'control' }));
  // Every servo limp: a standing robot falls. Asked first (a joint's or a limb's Free does not ask).
  $('#free-all').addEventListener('click', () => {
    if (!window.confirm('Free all: every servo goes limp, and a robot standing or held up by its servos falls. Hold the robot first. Free every servo now?'))
      return say('Free all cancelled: every servo as it was');
    send({ op: 'free', joints: ['all'] });
  });
  $('#hold-all').addEventListener('click', () => send({ op: 'hold', joints: ['all'] }));
  $('#stop').addEventListener('click', () => send({ op: 'stop' }));
  $('#motion-stop').addEventListener('click', () => send({ op: 'motion_stop' }));
  // Resume runs the ROM program on from where it stopped: a motion stopped part way goes on, and
  // the robot moves. Asked first then (a user who wants the buttons back may not expect it).
  $('#motions-resume').addEventListener('click', () => resume());
  $('#refresh').addEventListener('click', () => send({ op: 'refresh' }));
  $('#capture-form').addEventListener('submit', (ev) => {
    ev.preventDefault();
    send({ op: 'capture', name: $('#pose-name').value.trim(), force: $('#pose-force').checked });
  });
  const legend = $('#ad-legend');
  adColours.forEach((c, k) => {
    const s = el('span', { text: `AD${k + 1}` });
    s.style.setProperty('--c', c);
    legend.append(s);
  });
}

wire();
// "play over" is marked or cleared as typed, like every number box (its check: playPose()).
$('#pose-ms').numberCheck = playOverCheck();
$('#pose-ms').addEventListener('input', (e) => { e.target.numberCheck = playOverCheck(); numberIn(e.target); });

// The robot's panel sticks below the header (style.css), whose height depends on the window. What
// is scrolled to (a focused box, a selected step) lands below both, never under the robot's panel.
const headerHeight = () => {
  const root = document.documentElement, head = $('header').offsetHeight;
  root.style.setProperty('--header-h', `${head}px`);
  const panel = document.querySelector('.studio > .panel:first-child');
  const pinned = !document.querySelector('.studio').classList.contains('unpinned');
  root.style.scrollPaddingTop = `${head + (pinned && panel ? panel.offsetHeight : 0) + 8}px`;
};
// The robot kept in view (the default), or scrolled away with the page (this browser remembers).
const pin = $('#pin-robot');
try { pin.checked = localStorage.getItem('rcb4-studio-unpinned') !== '1'; } catch { /* no storage: pinned */ }
const pinned = () => {
  document.querySelector('.studio').classList.toggle('unpinned', !pin.checked);
  try { localStorage.setItem('rcb4-studio-unpinned', pin.checked ? '0' : '1'); } catch { /* not kept */ }
  headerHeight();
};
pin.addEventListener('change', pinned);
window.addEventListener('resize', headerHeight);
new ResizeObserver(headerHeight).observe(document.querySelector('.studio > .panel:first-child'));
pinned();
connect();
