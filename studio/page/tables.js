// rcb4 ui: the rest of HeartToHeart4's window: the 120 motion slots (play, stop, resume, pull into
// the editor, erase), the remote's buttons (a button assigned by clicking the remote's picture,
// cleared, pressed and held to test a branch), trims (live, kept in ROM on request), the ROM backup.
// Every change goes through the server's robot services, with their checks and refusals.

import { el, numberIn, numberBox } from './dom.js';
import { PAD, SYMBOL } from './remote.js';

/** The CRC-32 (IEEE 802.3, as zlib and `rcb4 rom backup` compute it) of @p bytes. */
function crc32(bytes) {
  let c = 0xFFFFFFFF;
  for (const b of bytes) {
    c ^= b;
    for (let k = 0; k < 8; k++) c = (c >>> 1) ^ (0xEDB88320 & -(c & 1));
  }
  return (c ^ 0xFFFFFFFF) >>> 0;
}

export function createTables(root, ctx) {
  const tbody = el('tbody', { id: 'slots' });
  const chosen = new Set();
  const pad = el('div', { class: 'pad', id: 'remote', role: 'group', 'aria-label': 'the remote: click buttons to choose a combination' });
  for (const [b, c, r] of PAD) {
    const k = el('button', { type: 'button', class: 'key', 'data-button': b, 'aria-pressed': 'false', title: b, text: SYMBOL[b] ?? b.toUpperCase() });
    k.style.gridColumn = String(c + 1);
    k.style.gridRow = String(r + 1);
    k.addEventListener('click', () => { if (chosen.has(b)) chosen.delete(b); else chosen.add(b); paintPad(); });
    pad.append(k);
  }
  const combo = el('span', { id: 'combo', class: 'combo' });
  const bslot = numberBox({ id: 'button-slot', value: 10, 'aria-label': 'slot the buttons play' }, { min: 1, max: 120, whole: true, step: 1, what: 'the slot' });
  const entries = el('ul', { id: 'button-entries', class: 'list' });
  const trims = el('div', { id: 'trims', class: 'trims' });
  const romFile = el('input', { id: 'rom-file', type: 'file', accept: '.bin', hidden: true });
  const romForce = el('input', { id: 'rom-force', type: 'checkbox', class: 'needs-control' });
  const persist = el('button', { id: 'trims-persist', type: 'button', class: 'needs-control', title: 'write the trims shown into ROM, which the board loads at power-on' }, 'Keep in ROM');
  const bt = (id, text, title, fn, cls = 'needs-control') => el('button', { id, type: 'button', title, class: cls, onclick: fn }, text);
  root.replaceChildren(
    el('details', { open: true, id: 'slots-panel' }, el('summary', {}, 'Motion slots'),
      el('div', { class: 'row' }, bt('slots-refresh', 'Refresh', 'read the 120 slots again', () => list(), ''),
        bt('motion-resume', 'Resume', 'let a motion stopped part way go on (asks first)', () => ctx.resume())),
      el('div', { class: 'slots-box' }, el('table', { class: 'slots' },
        el('thead', {}, el('tr', {}, ...['slot', 'name', 'bytes', 's', ''].map((t) => el('th', { text: t })))), tbody))),
    el('details', { id: 'buttons-panel' }, el('summary', {}, 'Remote buttons'), pad,
      el('div', { class: 'row' }, combo),
      el('div', { class: 'row' }, 'play slot', bslot,
        bt('button-set', 'Assign', 'these buttons play the slot (ROM and RAM)', () => withCombo((b) => { const r = numberIn(bslot); if (r.value === null) return ctx.say(r.why || 'type a slot number, 1 to 120', 'error'); return ask({ op: 'button_set', buttons: b, slot: r.value }, null, showEntries); })),
        bt('button-clear', 'Clear', 'these buttons play nothing any more', () => withCombo((b) => ask({ op: 'button_clear', buttons: b }, null, showEntries)))),
      el('div', { class: 'row' },
        bt('button-press', 'Press', 'press them as the receiver would, until a motion starts', () => withCombo((b) => ask({ op: 'button_press', buttons: b }, `${b} pressed`))),
        bt('button-hold', 'Hold', 'keep them pressed (a motion\'s if_buttons sees them)', () => withCombo((b) => ask({ op: 'button_press', buttons: b, hold: true }, `${b} held`))),
        bt('button-release', 'Release', 'release every button', () => ask({ op: 'button_release' }, 'buttons released'))),
      entries),
    el('details', { id: 'trims-panel' }, el('summary', {}, 'Trims'),
      el('div', { class: 'small muted', text: 'a trim corrects a servo horn\'s mounting (±30°): set live, kept in ROM on request' }),
      trims, el('div', { class: 'row' }, bt('trims-refresh', 'Read', 'read the trims again', () => readTrims(), ''), persist)),
    el('details', { id: 'rom-panel' }, el('summary', {}, 'ROM'),
      el('div', { class: 'row' }, bt('rom-backup', 'Back up the ROM', 'download the whole ROM (256 KiB) with its CRC-32', backup)),
      el('div', { class: 'row' }, romFile, bt('rom-restore', 'Restore…', 'write a backup back (checked as rcb4 rom restore checks it; the ROM it replaces saved first)', () => romFile.click())),
      el('label', { class: 'small' }, romForce, ' write an image that is no RCB-4 program (force)')));

  function paintPad() {
    for (const k of pad.children) k.setAttribute('aria-pressed', String(chosen.has(k.dataset.button)));
    combo.textContent = chosen.size ? [...chosen].join('+') : 'click the remote\'s buttons';
  }
  const withCombo = (fn) => (chosen.size ? fn([...chosen].join('+')) : ctx.say('choose the buttons on the remote first', 'error'));
  async function ask(msg, done, then) {
    try {
      const r = await ctx.request(msg);
      if (done) ctx.say(done);
      then?.(r);
      return r;
    } catch (e) { ctx.say(e.message, 'error'); return null; }
  }

  // --- the 120 slots ---
  let slots = [];
  async function list() {
    const r = await ask({ op: 'motion_list' });
    if (!r) return;
    slots = r.slots;
    tbody.replaceChildren(...slots.map((s) => el('tr', { 'data-slot': s.slot, class: (s.used ? 'used' : 'free') + (s.broken ? ' broken' : '') },
      el('td', { text: String(s.slot) }),
      el('td', { text: s.used ? (s.name || '') + (s.broken ? ' (broken)' : '') : 'free', title: s.problem || '' }),
      el('td', { text: s.used ? String(s.bytes) : '' }),
      el('td', { text: s.used ? (s.endless ? '∞' : s.calls ? 'calls' : s.seconds === null ? '–' : s.seconds.toFixed(2)) : '' }),
      el('td', {}, ...(s.used ? [
        bt('', '▶', 'play', () => ask({ op: 'motion_play', slot: s.slot }, `playing motion ${s.slot}`)),
        bt('', '■', 'stop the motion and hold every joint where it is (every page may stop)', () => ctx.send({ op: 'motion_stop' }), ''),
        bt('', '✎', 'pull into the editor', () => ctx.edit(s.slot), ''),
        bt('', '✕', 'erase (asks first; its bytes backed up first)', () => {
          if (!window.confirm(`Erase motion ${s.slot}${s.name ? ` (${s.name})` : ''} from the board? Its bytes are backed up first.`)) return ctx.say('erase cancelled');
          return ask({ op: 'motion_erase', slot: s.slot }, null, (x) => { ctx.say(`motion ${s.slot} erased; its bytes are in ${x.backup}`); list(); });
        }),
      ] : [])))));
    ctx.controls();
  }

  // --- buttons ---
  function showEntries(r) {
    if (r.done) ctx.say(r.done);
    const row = (e, where) => el('li', {}, el('span', { text: `${e.buttons ?? '(not buttons)'} → ${e.slot ? `motion ${e.slot}${e.name ? ` (${e.name})` : ''}` : '0x' + e.address.toString(16)}` }), el('span', { class: 'small muted', text: where }));
    const shown = r.entries ? r.entries.map((e) => row(e, 'RAM and ROM'))
      : [...r.ram.map((e) => row(e, r.same ? 'RAM and ROM' : 'RAM')), ...(r.same ? [] : r.rom.map((e) => row(e, 'ROM')))];
    entries.replaceChildren(...shown);
    if (!shown.length) entries.append(el('li', { class: 'muted', text: 'no button plays anything' }));
    if (r.rom_program === false) entries.append(el('li', { class: 'error', text: 'the ROM program is off: no button plays anything until it runs (Resume)' }));
  }
  const readButtons = () => ask({ op: 'buttons' }, null, showEntries);

  // --- trims ---
  let trimSeq = 0;  // the latest trim action: an older one's answer does not say over a newer one's
  async function readTrims() {
    if (!trims.children.length) trims.replaceChildren(el('div', { class: 'small muted', text: 'reading the trims…' }));
    const r = await ask({ op: 'trims' });
    if (!r) return trims.replaceChildren(el('div', { class: 'small error', text: 'the trims could not be read (the message above says why): Read tries again' }));
    trims.replaceChildren(...r.trims.filter((t) => t.allocated).map((t) => {
      const n = numberBox({ value: t.degrees, 'data-joint': t.name, class: 'needs-control', 'aria-label': `${t.name} trim in degrees` },
        { min: -30, max: 30, step: 0.1, what: `${t.name} trim`, unit: '°' });
      n.addEventListener('change', () => {
        const typed = numberIn(n);
        if (typed.value === null) {
          if (typed.why) return ctx.say(typed.why, 'error');
          n.value = t.degrees;  // emptied: nothing changes, the board's trim back
          return;
        }
        // read back at once: the row says what RAM and ROM hold now (never "in ROM" for a RAM change),
        // and the message what the board made of the degrees typed (it holds whole counts of a servo step)
        const mine = ++trimSeq;
        ask({ op: 'trim_set', joints: { [t.name]: typed.value } }).then(async (ok) => {
          if (!ok) return;
          const now = (await readTrims())?.find((x) => x.name === t.name);
          if (mine === trimSeq) ctx.say(`${t.name} trim ${typed.value}° (RAM, not kept in ROM)` + (now
            ? `: the board holds ${now.counts} counts, ${Math.round(now.exact_degrees * 1000) / 1000}°` : ''));
        });
      });
      n.title = `${t.counts} counts in RAM: ${Math.round(t.exact_degrees * 1000) / 1000}° (-30 to 30°)`;
      return el('div', { class: 'trim' }, el('span', { text: t.name }), n,
        el('span', { class: 'small muted', text: t.rom_degrees === null ? 'ROM –' : t.rom_degrees === t.degrees ? 'in ROM' : `ROM ${t.rom_degrees}` }));
    }));
    ctx.controls();
    return r.trims;
  }
  persist.addEventListener('click', async () => {
    ++trimSeq;  // a RAM write still answering (a box left by this click) says nothing over this one
    const joints = {};
    for (const n of trims.querySelectorAll('input[data-joint]')) {
      // every box must hold a trim: one that does not stops the whole write (nothing is kept in ROM)
      const r = numberIn(n);
      if (r.value === null) return ctx.say(`${r.why || `${n.dataset.joint} trim: the box is empty`}: nothing was written to ROM`, 'error');
      joints[n.dataset.joint] = r.value;
    }
    if (await ask({ op: 'trim_set', joints, persist: true }, 'trims kept in ROM (the board loads them at power-on)')) readTrims();
  });

  // --- ROM ---
  async function backup() {
    ctx.say('reading the whole ROM…');
    const r = await ask({ op: 'rom_backup' });
    if (!r) return;
    const bytes = Uint8Array.from(atob(r.base64), (c) => c.charCodeAt(0));
    // One download (a browser blocks a second one, and every later one with it): the CRC-32 is in
    // the file's name, where rcb4 rom restore finds it.
    const a = el('a', { href: URL.createObjectURL(new Blob([bytes], { type: 'application/octet-stream' })), download: r.file });
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 5000);
    ctx.say(`ROM read: ${r.bytes} bytes, CRC-32 ${r.crc32}; downloading ${r.file}: check your browser's downloads (rcb4 rom restore checks the CRC in its name)`);
  }

  // A restore: the image sent in pieces with its CRC-32; the server checks both, then the robot
  // service checks the image and writes where it differs.
  romFile.addEventListener('change', async () => {
    const f = romFile.files[0];
    romFile.value = '';
    if (!f) return;
    const bytes = new Uint8Array(await f.arrayBuffer());
    if (bytes.length !== 262144) return ctx.say(`${f.name}: ${bytes.length} bytes; a ROM image is 262,144 (nothing written)`, 'error');
    if (!(await ask({ op: 'rom_restore_begin', bytes: bytes.length, crc32: crc32(bytes).toString(16).padStart(8, '0') }))) return;
    for (let at = 0; at < bytes.length; at += 45000) {
      const piece = bytes.subarray(at, Math.min(at + 45000, bytes.length));
      let text = '';
      for (let i = 0; i < piece.length; i += 8192) text += String.fromCharCode(...piece.subarray(i, i + 8192));
      if (!(await ask({ op: 'rom_restore_piece', offset: at, base64: btoa(text) }))) return;
    }
    const r = await ask({ op: 'rom_restore_commit', force: romForce.checked });
    if (r) ctx.say(r.unchanged ? 'the ROM already was that image: nothing written'
      : `restored: ${r.pieces_written} pieces written; the ROM it replaced is in ${r.before}`);
    if (r && !r.unchanged) { list(); readTrims(); readButtons(); }  // what the page shows is the new ROM's
  });

  paintPad();
  root.querySelector('#buttons-panel').addEventListener('toggle', (e) => { if (e.target.open) readButtons(); });
  root.querySelector('#trims-panel').addEventListener('toggle', (e) => { if (e.target.open) readTrims(); });
  return {
    list, readTrims, readButtons,
    /** The running slot, from the state. */
    running(slot) { for (const tr of tbody.children) tr.classList.toggle('running', String(slot) === tr.dataset.slot); },
    get slots() { return slots; },
  };
}
