/**
 * Pieces the time-axis views share: hold/failsafe episodes drawn as bands on a strip. (The
 * graphs' axes, seconds before now and labelled values, are in axes.ts.)
 */
import type { Episode } from './live.js';

/**
 * Redraws `strip` with the episodes that overlap the window ending at `nowUs` (`spanUs` long),
 * each a band positioned in % of the strip. Returns the kinds drawn.
 */
export function drawEpisodes(strip: HTMLElement, episodes: Iterable<Episode>, nowUs: number, spanUs: number): Episode['kind'][] {
  const start = nowUs - spanUs;
  const drawn: Episode['kind'][] = [];
  strip.replaceChildren();
  for (const e of episodes) {
    const end = e.endUs ?? nowUs;
    if (end < start) continue;
    const a = Math.max(0, (e.startUs - start) / spanUs);
    const b = Math.min(1, (end - start) / spanUs);
    const div = document.createElement('div');
    div.className = `episode ${e.kind}`;
    div.style.left = `${(a * 100).toFixed(3)}%`;
    div.style.width = `${Math.max(0.3, (b - a) * 100).toFixed(3)}%`;
    div.title = `${e.kind} ${((end - e.startUs) / 1e6).toFixed(2)} s`;
    strip.append(div);
    drawn.push(e.kind);
  }
  return drawn;
}
