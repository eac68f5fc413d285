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
 * or sent. A browser number box reads "" for letters (validity.badInput): that is no 0.
 */
export function numberIn(input, { min = -Infinity, max = Infinity, whole = false, what = 'the value', unit = '' } = {}) {
  const mark = (why) => {
    input.classList.add('invalid');
    input.title = why;
    input.setCustomValidity?.(why);
    input.setAttribute('aria-invalid', 'true');
    return { value: null, why };
  };
  const text = String(input.value ?? '').trim();
  if (input.validity?.badInput) return mark(`${what}: not a number: nothing changed`);
  if (text === '') return { value: null, why: null, empty: true };
  if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(text)) return mark(`${what}: '${text}' is not a number: nothing changed`);
  const v = Number(text);
  if (!Number.isFinite(v)) return mark(`${what}: '${text}' is not a number: nothing changed`);
  if (whole && !Number.isInteger(v)) return mark(`${what}: ${text} is not a whole number: nothing changed`);
  if (v < min || v > max) return mark(`${what}: ${text}${unit} is outside ${min}..${max}${unit}: nothing changed`);
  input.classList.remove('invalid');
  input.title = '';
  input.setCustomValidity?.('');
  input.removeAttribute('aria-invalid');
  return { value: v, why: null };
}
