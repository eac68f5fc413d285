// rcb4 studio: a form for every kind of step that is not a pose (docs/motions.md: the motion file's
// steps), so that nothing is typed as JSON: labels and jumps picked from the motion's labels, the
// remote's buttons clicked on its picture, a RAM test's comparison chosen, a called motion picked
// from the board's slots, speed and stretch per joint or group. Each form reads back a step, or
// says what is wrong with the box marked (dom.js numberIn), and nothing changes then.
// SPDX-License-Identifier: BSL-1.0

import { el, numberIn, numberBox } from './dom.js';
import { PAD, SYMBOL } from './remote.js';

const COMPARES = [['equal', '='], ['not_equal', '≠'], ['below', '<'], ['at_least', '≥'], ['at_most', '≤']];
const RAM_TOP = 0x048F;  // the highest RAM address a motion may test or count in (motion_file.cpp)

const field = (label, ...kids) => el('label', { class: 'field' }, el('span', { class: 'small muted', text: label }), ...kids);
const fail = (why) => ({ why });

/** A RAM address typed as 0x50 or 80: { value } or { why } (the box marked); empty is null. */
function addressIn(input, what) {
  const text = input.value.trim();
  if (text === '') return { value: null };
  const v = /^0x[0-9a-f]{1,4}$/i.test(text) ? parseInt(text, 16) : /^\d{1,5}$/.test(text) ? Number(text) : NaN;
  if (!(v >= 0 && v <= RAM_TOP)) {
    input.classList.add('invalid');
    input.title = `${what}: '${text}' is no RAM address 0x0000..0x048F`;
    return { why: input.title };
  }
  input.classList.remove('invalid');
  input.title = '';
  return { value: v };
}
const hex4 = (v) => '0x' + Number(v).toString(16).toUpperCase().padStart(4, '0');

/**
 * The form for step @p s of @p doc. ctx: { hello, motions() (the board's slots) }. Returns
 * { el, read() → { step } | { why } }.
 */
export function stepForm(s, doc, ctx) {
  const kind = s === 'end' ? 'end' : Object.keys(KIND_FORMS).find((k) => s && typeof s === 'object' && k in s);
  const make = KIND_FORMS[kind];
  if (!make) return { el: el('div', { class: 'small muted', text: 'this step has no form' }), read: () => fail('unknown step') };
  const labels = doc.steps.filter((x) => x && typeof x === 'object' && 'label' in x).map((x) => x.label);
  return make(s, { ...ctx, labels });
}

/** A select of the motion's labels, @p value chosen (kept even if no label has it yet, marked). */
function labelPick(id, value, labels) {
  const names = [...new Set(labels)];
  const sel = el('select', { id, class: 'label-pick', 'aria-label': 'the label to jump to' },
    ...names.map((n) => el('option', { value: n, text: n })));
  if (value && !names.includes(value)) sel.append(el('option', { value, text: `${value} (no such label)` }));
  sel.value = value ?? names[0] ?? '';
  const read = () => {
    if (!sel.value) return fail('add a label step first: a jump needs somewhere to go');
    if (!names.includes(sel.value)) return fail(`no label is called ${sel.value}: add it, or pick another`);
    return { value: sel.value };
  };
  return { sel, read };
}

function counterBox(id, s) {
  return el('input', { id, value: s.counter === undefined ? '' : hex4(s.counter), placeholder: 'default', size: 8,
    'aria-label': 'the counter\'s RAM address (empty: the default counter)' });
}

function remotePad(initial) {
  const chosen = new Set(String(initial ?? '').split('+').filter(Boolean).map((b) => (b === 'tri' ? 'triangle' : b)));
  const pad = el('div', { class: 'pad small-pad', role: 'group', 'aria-label': 'the buttons: click on the remote' });
  for (const [b, c, r] of PAD) {
    const k = el('button', { type: 'button', class: 'key', 'data-button': b, title: b, text: SYMBOL[b] ?? b.toUpperCase(),
      'aria-pressed': String(chosen.has(b)) });
    k.style.gridColumn = String(c + 1);
    k.style.gridRow = String(r + 1);
    k.addEventListener('click', () => {
      if (chosen.has(b)) chosen.delete(b); else chosen.add(b);
      k.setAttribute('aria-pressed', String(chosen.has(b)));
    });
    pad.append(k);
  }
  return { pad, read: () => (chosen.size ? { value: PAD.map(([b]) => b).filter((b) => chosen.has(b)).join('+') } : fail('click at least one button on the remote')) };
}

const KIND_FORMS = {
  end: () => ({ el: el('div', { class: 'small muted', text: 'the motion ends here (RETURN)' }), read: () => ({ step: 'end' }) }),

  label(s, ctx) {
    const name = el('input', { id: 'f-label', value: s.label, maxlength: 32, 'aria-label': 'label name' });
    return {
      el: field('label (the jumps to it follow a new name)', name),
      read: () => {
        const n = name.value.trim();
        if (!n) return fail('a label needs a name');
        if (n !== s.label && ctx.labels.includes(n)) return fail(`another label is called ${n} already`);
        return { step: { label: n }, renamed: n !== s.label ? [s.label, n] : null };
      },
    };
  },

  set_counter(s) {
    const v = numberBox({ id: 'f-count', value: s.set_counter, 'aria-label': 'counter value' }, { min: 0, max: 255, whole: true, step: 1, what: 'the count' });
    const c = counterBox('f-counter', s);
    return {
      el: el('div', { class: 'row' }, field('counter =', v), field('counter at (RAM)', c)),
      read: () => {
        const r = numberIn(v);
        if (r.value === null) return fail(r.why || 'type the count, 0 to 255');
        const a = addressIn(c, 'the counter');
        if (a.why) return fail(a.why);
        return { step: a.value === null ? { set_counter: r.value } : { set_counter: r.value, counter: a.value } };
      },
    };
  },

  loop(s, ctx) { return countDown(s, ctx, 'loop'); },
  count_down(s, ctx) { return countDown(s, ctx, 'count_down'); },

  if_buttons(s, ctx) { return buttonBranch(s, ctx, 'if_buttons'); },
  unless_buttons(s, ctx) { return buttonBranch(s, ctx, 'unless_buttons'); },

  if_ram(s, ctx) {
    const address = el('input', { id: 'f-address', value: typeof s.if_ram === 'number' ? hex4(s.if_ram) : s.if_ram, size: 8, 'aria-label': 'RAM address' });
    const size = el('select', { id: 'f-size', 'aria-label': 'value size' }, el('option', { value: 1, text: '1 byte' }), el('option', { value: 2, text: '2 bytes' }));
    size.value = String(s.size ?? 2);
    const how = el('select', { id: 'f-compare', 'aria-label': 'comparison' }, ...COMPARES.map(([k, t]) => el('option', { value: k, text: t })));
    how.value = COMPARES.map(([k]) => k).find((k) => k in s) ?? 'equal';
    const value = numberBox({ id: 'f-value', value: s[how.value] ?? 0, 'aria-label': 'value compared with' }, { min: 0, max: 65535, whole: true, step: 1, what: 'the value' });
    const to = labelPick('f-goto', s.goto, ctx.labels);
    return {
      el: el('div', { class: 'row' }, field('if RAM at', address), size, how, value, field('go to', to.sel)),
      read: () => {
        const a = addressIn(address, 'the address');
        if (a.why || a.value === null) return fail(a.why || 'type the RAM address to test (0x0000..0x048F)');
        const n = Number(size.value);
        const r = numberIn(value, { min: 0, max: n === 1 ? 255 : 65535, whole: true, what: 'the value' });
        if (r.value === null) return fail(r.why || 'type the value to compare with');
        const t = to.read();
        if (t.why) return t;
        return { step: { if_ram: a.value, size: n, [how.value]: r.value, goto: t.value } };
      },
    };
  },

  goto(s, ctx) {
    const to = labelPick('f-goto', s.goto, ctx.labels);
    return { el: field('go to', to.sel), read: () => { const t = to.read(); return t.why ? t : { step: { goto: t.value } }; } };
  },

  call(s, ctx) {
    const slots = new Map((ctx.motions?.() ?? []).map((m) => [m.slot, m.name]));
    const pick = el('select', { id: 'f-call', 'aria-label': 'the motion to call' });
    for (let n = 1; n <= 120; n++)
      pick.append(el('option', { value: n, text: `${n}` + (slots.has(n) ? ` ${slots.get(n) ?? '(in ROM)'}` : ' (empty)') }));
    pick.value = String(s.call);
    return { el: field('call motion', pick), read: () => ({ step: { call: Number(pick.value) } }) };
  },

  call_address(s) {
    const a = el('input', { id: 'f-call-address', value: '0x' + Number(s.call_address).toString(16).toUpperCase(), 'aria-label': 'ROM address' });
    return {
      el: field('call ROM address', a),
      read: () => {
        const t = a.value.trim();
        const v = /^0x[0-9a-f]{1,5}$/i.test(t) ? parseInt(t, 16) : /^\d{1,6}$/.test(t) ? Number(t) : NaN;
        if (!(v >= 0 && v <= 0x3FFFF)) { a.classList.add('invalid'); return fail(`'${t}' is no ROM address 0x0..0x3FFFF`); }
        a.classList.remove('invalid');
        return { step: { call_address: v } };
      },
    };
  },

  speed(s, ctx) { return params(s, ctx, 'speed'); },
  stretch(s, ctx) { return params(s, ctx, 'stretch'); },
};

function countDown(s, ctx, kind) {
  const to = labelPick('f-goto', s[kind], ctx.labels);
  const c = counterBox('f-counter', s);
  const when = el('select', { id: 'f-when', 'aria-label': 'jump when the counter is' },
    el('option', { value: 'not_zero', text: 'not 0 (loop)' }), el('option', { value: 'zero', text: '0' }));
  when.value = s.when ?? 'not_zero';
  const parts = [field(kind === 'loop' ? 'count down, go to while not 0' : 'count down, go to', to.sel), field('counter at (RAM)', c)];
  if (kind === 'count_down') parts.push(field('jump when the counter is', when));
  return {
    el: el('div', { class: 'row' }, ...parts),
    read: () => {
      const t = to.read();
      if (t.why) return t;
      const a = addressIn(c, 'the counter');
      if (a.why) return fail(a.why);
      const step = { [kind]: t.value };
      if (a.value !== null) step.counter = a.value;
      if (kind === 'count_down' && when.value === 'zero') step.when = 'zero';
      return { step };
    },
  };
}

function buttonBranch(s, ctx, kind) {
  const pad = remotePad(s[kind]);
  const to = labelPick('f-goto', s.goto, ctx.labels);
  return {
    el: el('div', { class: 'row' }, field(kind === 'if_buttons' ? 'if these are held' : 'unless these are held', pad.pad), field('go to', to.sel)),
    read: () => {
      const b = pad.read();
      if (b.why) return b;
      const t = to.read();
      if (t.why) return t;
      return { step: { [kind]: b.value, goto: t.value } };
    },
  };
}

function params(s, ctx, kind) {
  const h = ctx.hello;
  const targets = ['all', ...h.groups.map((g) => g.name), ...h.joints.map((j) => j.name)];
  const rows = el('div', { class: 'param-rows' });
  const addRow = (key, value) => {
    const t = el('select', { class: 'param-target', 'aria-label': `${kind} of` }, ...targets.map((n) => el('option', { value: n, text: n })));
    t.value = targets.includes(key) ? key : 'all';
    const v = numberBox({ class: 'param-value', value, 'aria-label': `${kind} 1 to 127` }, { min: 1, max: 127, whole: true, step: 1, what: kind });
    const x = el('button', { type: 'button', text: '×', title: 'remove', 'aria-label': 'remove this row' });
    const row = el('div', { class: 'row' }, t, v, x);
    x.addEventListener('click', () => row.remove());
    rows.append(row);
  };
  for (const [k, v] of Object.entries(s[kind] ?? {})) addRow(k, v);
  const add = el('button', { type: 'button', id: 'f-param-add', text: '+ joint or group' });
  add.addEventListener('click', () => addRow('all', 127));
  return {
    el: el('div', {}, field(`${kind} (1 to 127) of`, rows), add),
    read: () => {
      const out = {};
      for (const row of rows.children) {
        const key = row.querySelector('.param-target').value;
        const r = numberIn(row.querySelector('.param-value'), { min: 1, max: 127, whole: true, what: `${kind} of ${key}` });
        if (r.value === null) return fail(r.why || `type the ${kind} of ${key}, 1 to 127`);
        if (key in out) return fail(`${key} is given twice`);
        out[key] = r.value;
      }
      if (!Object.keys(out).length) return fail(`give the ${kind} of one joint or group at least`);
      return { step: { [kind]: out } };
    },
  };
}
