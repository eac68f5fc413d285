// rcb4 ui: small helpers every module of the page shares: elements, angles.
export const $ = (sel) => document.querySelector(sel);

/** An element with attributes (class, text, on* handlers, others) and children (nodes or text). */
export const el = (tag, attrs = {}, ...kids) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === false) continue;
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v === true ? '' : v);
  }
  for (const k of kids) e.append(k);
  return e;
};

/** A joint name with a line-break opportunity after each underscore (text nodes and <wbr>, no HTML). */
export const breakable = (name) => name.split(/(?<=_)/).flatMap((part, i) => (i ? [el('wbr'), part] : [part]));

/** "+12.5°", or "–" for unknown. */
export const fmtDeg = (d) => (d === null || d === undefined ? '–' : (d > 0 ? '+' : '') + d.toFixed(1) + '°');

/**
 * The number typed in @p input, checked, never coerced: null when the box is empty (nothing is to
 * change) or holds no valid number in [min, max] (whole when @p whole): then the box is marked
 * with the reason (class "invalid", its title and validity message) and nothing may be applied
 * or sent. The check is @p check, or the one numberBox() gave the box. The raw text is read, so
 * "4,5" or "12x" is refused as typed (a browser's type=number box would read 45 or 12).
 */
export function numberIn(input, check = input.numberCheck ?? {}) {
  const { min = -Infinity, max = Infinity, whole = false, multipleOf = 0, what = 'the value', unit = '' } = check;
  const mark = (why) => {
    input.classList.add('invalid');
    input.title = why;
    input.setCustomValidity?.(why);
    input.setAttribute('aria-invalid', 'true');
    return { value: null, why };
  };
  const unmark = () => {
    input.classList.remove('invalid');
    input.title = input.numberCheck?.min !== undefined ? `${min} to ${max}${unit}` : '';
    input.setCustomValidity?.('');
    input.removeAttribute('aria-invalid');
  };
  const text = String(input.value ?? '').trim();
  if (input.validity?.badInput) return mark(`${what}: not a number: nothing changed`);
  // A message still saying this box was refused is stale once the box is emptied or good.
  const clearStale = () => {
    const banner = document.querySelector('#message.error');
    if (banner && banner.textContent.startsWith(`${what}: `)) { banner.className = 'message'; banner.textContent = ''; }
  };
  if (text === '') {  // nothing to change: the caller puts the kept value back, unmarked
    unmark();
    clearStale();
    return { value: null, why: null, empty: true };
  }
  // Plain decimals only: an exponent (1e1) or a comma is far likelier a typo than a number meant,
  // and a whole number is digits alone (10.0 is no slot).
  if (whole && /^[+-]?(\d+\.\d*|\.\d+)$/.test(text)) return mark(`${what}: ${text} is not a whole number: nothing changed`);
  if (whole && /^[+-]\d+$/.test(text)) return mark(`${what}: ${text}: digits only, no sign: nothing changed`);
  if (!(whole ? /^\d+$/ : /^[+-]?(\d+\.?\d*|\.\d+)$/).test(text)) return mark(`${what}: '${text}' is not a number: nothing changed`);
  const v = Number(text);
  if (!Number.isFinite(v)) return mark(`${what}: '${text}' is not a number: nothing changed`);
  if (v < min || v > max) return mark(`${what}: ${text}${unit} is outside ${min}..${max}${unit}: nothing changed`);
  if (multipleOf && Math.abs(v / multipleOf - Math.round(v / multipleOf)) > 1e-9)
    return mark(`${what}: ${text}${unit} is not a multiple of ${multipleOf}${unit} (the board counts in steps of ${multipleOf}${unit}): nothing changed`);
  unmark();
  clearStale();
  return { value: v, why: null };
}

/**
 * A box for a number: type=text (inputmode decimal or numeric), so what numberIn() reads is exactly
 * what was typed; a browser's number box drops what it cannot parse ("12x" reads 12) or takes a
 * comma as a grouping mark ("4,5" reads 45). @p check (numberIn's options, plus step) is kept on the
 * box: it is marked or cleared as the user types (nothing is applied until 'change'), and ArrowUp /
 * ArrowDown step it by check.step within [min, max] as a number box would.
 */
export function numberBox(attrs = {}, check = {}) {
  const input = el('input', { type: 'text', inputmode: check.whole ? 'numeric' : 'decimal', autocomplete: 'off',
    spellcheck: 'false', ...attrs, class: ['num', attrs.class].filter(Boolean).join(' ') });
  input.numberCheck = check;
  if (check.min !== undefined && check.max !== undefined && !input.title)
    input.title = `${check.min} to ${check.max}${check.unit ?? ''}`;
  input.addEventListener('input', () => numberIn(input));  // marked or cleared as typed (emptied: unmarked)
  input.addEventListener('keydown', (e) => {
    if ((e.key !== 'ArrowUp' && e.key !== 'ArrowDown') || !check.step) return;
    const r = numberIn(input);
    if (r.value === null) return;
    e.preventDefault();
    const next = r.value + (e.key === 'ArrowUp' ? check.step : -check.step);
    const lo = check.min ?? -Infinity, hi = check.max ?? Infinity;
    input.value = String(Math.round(Math.min(Math.max(next, lo), hi) * 1e6) / 1e6);
    input.dispatchEvent(new Event('change', { bubbles: true }));
  });
  return input;
}
