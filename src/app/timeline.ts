/**
 * Pieces the time-axis views share: hold/failsafe episodes drawn as bands on a strip. (The
 * graphs' axes, seconds before now and labelled values, are in axes.ts.)
 */
import type { Episode } from './live.js';

/**
 * Redraws `strip` with the episodes that overlap the window ending at `nowUs` (`spanUs` long),
 * each a band positioned in % of the strip. Returns the kinds drawn. The strips are redrawn
 * several times a second as the window slides: the bands already there are moved, and only
 * what changed is written (a new element each time was a node styled and laid out afresh).
 */
/** Where each band was last put (left and width as written). */
const placed = new WeakMap<Element, string>();

export function drawEpisodes(strip: HTMLElement, episodes: Iterable<Episode>, nowUs: number, spanUs: number): Episode['kind'][] {
  const start = nowUs - spanUs;
  const drawn: Episode['kind'][] = [];
  for (const e of episodes) {
    const end = e.endUs ?? nowUs;
    if (end < start) continue;
    const a = Math.max(0, (e.startUs - start) / spanUs);
    const b = Math.min(1, (end - start) / spanUs);
    const old = strip.children[drawn.length];
    const band = old instanceof HTMLElement ? old : strip.appendChild(document.createElement('div'));
    const className = `episode ${e.kind}`;
    const left = `${(a * 100).toFixed(3)}%`;
    const width = `${Math.max(0.3, (b - a) * 100).toFixed(3)}%`;
    const title = `${e.kind} ${((end - e.startUs) / 1e6).toFixed(2)} s`;
    if (band.className !== className) band.className = className;
    // Compared with what was written (the style reads back normalised: 0.000% as 0%).
    const at = `${left} ${width}`;
    if (placed.get(band) !== at) {
      band.style.left = left;
      band.style.width = width;
      placed.set(band, at);
    }
    if (band.title !== title) band.title = title;
    drawn.push(e.kind);
  }
  while (strip.children.length > drawn.length) strip.lastElementChild?.remove();
  return drawn;
}
