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
