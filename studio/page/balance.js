// rcb4 studio: does the motion stand? After each change the server checks every pose held still
// (its centre of mass over the soles on the floor: rcb4 motion check, robot/motion_balance.hpp);
// a pose whose centre of mass lies outside its feet is marked in the list and the timeline, and
// the line under the timeline says the smallest margin. Nothing is computed here: the page draws.
// SPDX-License-Identifier: BSL-1.0

/**
 * The editor's balance marks. @p ctx: the page (request); @p text(): the motion file's text;
 * @p out: the element the verdict goes in; @p lists: the elements whose [data-step] children are
 * marked (the step list, the timeline).
 */
export function createBalance(ctx, text, out, lists) {
  let key = null, timer = null, byStep = new Map(), asked = 0;
  const mark = () => {
    for (const list of lists)
      for (const e of list.querySelectorAll('[data-step]')) {
        const b = byStep.get(Number(e.dataset.step));
        e.classList.toggle('falls', !!b && !b.stable);
        if (b && !b.stable) e.dataset.balance = `centre of mass ${Math.abs(b.margin_mm).toFixed(1)} mm outside its feet: it falls`;
        else delete e.dataset.balance;
      }
  };
  const show = (poses) => {
    byStep = new Map((poses ?? []).map((b) => [b.step, b]));
    if (!poses) { out.textContent = ''; mark(); return; }  // a robot without a mass model
    const falls = poses.filter((b) => !b.stable);
    const worst = poses.reduce((w, b) => (!w || b.margin_mm < w.margin_mm ? b : w), null);
    out.textContent = !worst ? ''
      : falls.length ? `balance: ${falls.length} pose${falls.length > 1 ? 's' : ''} off its feet (step ${falls.map((b) => b.step + 1).join(', ')}): it falls there`
      : `balance: every pose stands, held still (smallest margin ${worst.margin_mm.toFixed(1)} mm, step ${worst.step + 1})`;
    out.classList.toggle('error', falls.length > 0);
    mark();
  };
  /** Asks again once the motion has not changed for a moment (and only when it did change). */
  function schedule() {
    mark();  // a re-drawn list keeps its marks until the answer
    clearTimeout(timer);
    timer = setTimeout(async () => {
      const t = text();
      if (t === key) return;
      const n = ++asked;
      try {
        const r = await ctx.request({ op: 'motion_check', text: t });
        if (n !== asked) return;  // an older answer than the last question
        key = t;
        show(r.balance);
      } catch { /* a motion that does not parse yet: the editor says why elsewhere */ }
    }, 400);
  }
  return { schedule, mark };
}
