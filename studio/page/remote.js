// rcb4 studio: the KRR remote's buttons (motion/buttons.hpp), laid out as on the pad, for every
// picture of the remote on the page (the button table, a motion's button branches).
// SPDX-License-Identifier: BSL-1.0

/** [name, column, row] of each button on the pad. */
export const PAD = [['s1', 0, 0], ['s2', 1, 0], ['s3', 5, 0], ['s4', 6, 0],
  ['up', 1, 1], ['triangle', 5, 1], ['left', 0, 2], ['right', 2, 2], ['square', 4, 2], ['circle', 6, 2],
  ['down', 1, 3], ['cross', 5, 3]];
/** What each button shows (the shoulder buttons their names). */
export const SYMBOL = { up: '▲', down: '▼', left: '◀', right: '▶', triangle: '△', circle: '○', cross: '✕', square: '□' };
