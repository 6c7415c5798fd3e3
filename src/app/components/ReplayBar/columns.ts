/**
 * The replay's overview reduced to the columns its timeline is drawn in: a day-long capture has
 * 86 400 one-second bins (a week's are 5 s) and the timeline about a thousand device pixels.
 * Each column shows its worst bin: the most frames lost and the highest fade rate of the bins
 * that fall in it, each a value one bin of the capture had. Drawn bin by bin the bars would overlap to the same
 * picture, at the cost of drawing every bin (about 0.1 s of the page's CPU while a day capture
 * opens, measured) each time the growing overview is drawn.
 */
import type { Overview } from '../../../worker/protocol.js';

export interface OverviewColumns {
  /** Each column's first bin's start, s. */
  x: number[];
  lost: number[];
  /** NaN where no bin of the column has a fade rate. */
  fadeRate: number[];
}

/**
 * `o`'s bins in at most `columns` columns spread evenly over [`fromS`, `toS`] (the capture's
 * span, s: a growing overview keeps its columns), in time order; each bin whole in one column.
 */
export function overviewColumns(o: Overview, columns: number, fromS: number, toS: number): OverviewColumns {
  const out: OverviewColumns = { x: [], lost: [], fadeRate: [] };
  const n = o.t.length;
  const perS = columns / (toS - fromS);
  let column = Number.NaN;
  for (let b = 0; b < n; b++) {
    const tS = (o.t[b] ?? Number.NaN) / 1e6;
    const c = Math.floor((tS - fromS) * perS);
    const lost = o.lost[b] ?? Number.NaN;
    const fade = o.fadeRate[b] ?? Number.NaN;
    const last = out.x.length - 1;
    // A bin in the column of the one before (an untimed one, column NaN, is a column of its own).
    if (c === column) {
      if (lost > (out.lost[last] ?? Number.NaN) || Number.isNaN(out.lost[last] ?? Number.NaN)) out.lost[last] = lost;
      if (fade > (out.fadeRate[last] ?? Number.NaN) || Number.isNaN(out.fadeRate[last] ?? Number.NaN)) out.fadeRate[last] = fade;
    } else {
      out.x.push(tS);
      out.lost.push(lost);
      out.fadeRate.push(fade);
      column = c;
    }
  }
  return out;
}
