// rcb4 studio: the motion played: previewed in 3D without the robot (at the authored timing, from
// the start or from the selected step), played on the robot from the host (the whole motion
// checked before anything moves, its first played pose reached at the speed limit; from the
// selected step with the counters set before it carried over), and stopped.
// SPDX-License-Identifier: BSL-1.0

import { $ } from './dom.js';
import { at, kindOf, segments } from './steps.js';

/**
 * The editor's playback. @p ed: the editor's state (doc, sel, preview, run, playing, previewFrom);
 * @p ctx: the page (request, send, say, measured, controlling, view); @p text(): the motion file's
 * text; @p cursor: the timeline's cursor; @p poseAt(i): the whole robot after step i.
 */
export function createPlayback(ed, ctx, text, cursor, poseAt) {
  /** Plays the motion in 3D; @p fromSel: from the first time the board reaches the selected step. */
  function preview(fromSel = false) {
    stop();
    let segs;
    try { segs = segments(ed.doc.steps, ctx.measured()); } catch (e) { return ctx.say(`preview: ${e.message}`, 'error'); }
    const total = segs.reduce((a, g) => a + g.ms, 0);
    let skip = 0;
    if (fromSel) {
      const k = segs.findIndex((g) => g.step >= ed.sel);
      if (k < 0) return ctx.say(`preview: no pose is played from step ${ed.sel + 1} on (no button held, RAM 0)`, 'error');
      skip = segs.slice(0, k).reduce((a, g) => a + g.ms, 0);
    }
    const t0 = performance.now() - skip;
    ed.previewFrom = skip;
    cursor.hidden = false;
    $('#ed-result').textContent = 'previewing…';
    const tick = () => {
      const t = performance.now() - t0;
      ctx.view?.setGhost(at(segs, Math.min(t, total)));
      cursor.style.left = `${Math.min(t / Math.max(total, 1), 1) * 100}%`;
      if (t < total && ed.preview) ed.preview = requestAnimationFrame(tick);
      else {
        ed.preview = null;
        cursor.hidden = true;
        $('#ed-result').textContent = `preview: ${(total / 1000).toFixed(2)} s of motion, shown in ${(t / 1000).toFixed(2)} s`;
      }
    };
    ed.preview = requestAnimationFrame(tick);
  }
  /**
   * The steps played from step @p k: the counters the steps before it set (their last values, so
   * a loop from there on goes round as often as from the top, not 255 times from whatever RAM
   * holds), then a jump to a label put before step k; every step kept, so the loops and branches
   * from there find their labels, and the steps before k run only when something jumps back.
   */
  function fromStep(list, k) {
    if (k <= 0) return list;
    const names = new Set(list.filter((s) => kindOf(s) === 'label').map((s) => s.label));
    let label = 'from_here';
    for (let n = 2; names.has(label); n += 1) label = `from_here_${n}`;
    const counters = new Map();
    for (const s of list.slice(0, k)) if (kindOf(s) === 'set_counter') counters.set(s.counter ?? 'C1', s);
    return [...counters.values(), { goto: label }, ...list.slice(0, k), { label }, ...list.slice(k)];
  }
  /** Plays the motion on the robot from the host; @p fromSel: from the selected step. */
  async function play(fromSel = false) {
    stop();
    // A Stop pressed while the robot moves into the first pose holds it there and ends this play:
    // nothing more is sent once the run it started is no longer the current one.
    const run = ++ed.run;
    ed.playing = true;
    const played = fromSel ? fromStep(ed.doc.steps, ed.sel) : ed.doc.steps;
    const motion = fromSel ? JSON.stringify({ ...JSON.parse(text()), steps: played }) : text();
    let first;  // the first pose the board plays (no button held, RAM 0: as a preview assumes)
    try {
      const segs = segments(played, ctx.measured());
      first = segs.length ? played[segs[0].step] : null;
    } catch (e) { first = null; }
    if (fromSel && !first) {
      ed.playing = false;
      return ctx.say(`not played: no pose is played from step ${ed.sel + 1} on (nothing moved)`, 'error');
    }
    try {
      // The whole motion is checked before the robot moves into its first pose: a motion that
      // will be refused moves nothing (the server checks it again when it plays it).
      const checked = await ctx.request({ op: 'motion_check', text: motion });
      if (run !== ed.run) return;
      if (checked.problem) {
        ed.playing = false;
        return ctx.say(`not played: ${checked.problem} (nothing moved)`, 'error');
      }
      if (first) {  // into the first pose at the speed limit; from there, the authored timing
        const r = await ctx.request({ op: 'move', joints: first.pose });
        await new Promise((done) => setTimeout(done, (r.ms ?? 0) + 50));
        if (run !== ed.run) return;
      }
      await ctx.request({ op: 'play_motion', text: motion });
      if (run === ed.run) ctx.say(fromSel ? `playing on the robot from the host, from step ${ed.sel + 1}` : 'playing on the robot from the host');
    } catch (e) {
      if (run !== ed.run) return;
      ed.playing = false;  // refused or failed: nothing of this play runs, nothing to stop
      ctx.say(e.message, 'error');
    }
  }
  function stop() {
    ed.run += 1;
    if (ed.preview) { cancelAnimationFrame(ed.preview); ed.preview = null; cursor.hidden = true; }
    if (ed.playing && ctx.controlling()) ctx.send({ op: 'stop' });  // the play from the host, and a ROM motion it called
    ed.playing = false;
    ctx.view?.setGhost(poseAt(ed.sel));
  }
  return { preview, play, stop };
}
