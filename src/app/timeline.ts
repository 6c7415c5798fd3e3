/**
 * Pieces the time-axis views share: hold/failsafe episodes drawn as bands on a strip, and
 * uPlot's x axis labelled in seconds before now.
 */
import type uPlot from 'uplot';
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

/** The dark-theme x axis of the live graphs: seconds before the window's end. */
export const SECONDS_BEFORE_NOW_AXIS: uPlot.Axis = {
  stroke: '#8a97a8',
  grid: { stroke: '#1e2835' },
  ticks: { stroke: '#1e2835' },
  values: (u, vals) => {
    const end = u.scales.x?.max ?? 0;
    return vals.map((v) => `${(v - end).toFixed(0)} s`);
  },
};

/** The matching y axis, labelled. */
export function valueAxis(label: string): uPlot.Axis {
  return { stroke: '#8a97a8', grid: { stroke: '#1e2835' }, ticks: { stroke: '#1e2835' }, size: 48, label, labelSize: 18 };
}
