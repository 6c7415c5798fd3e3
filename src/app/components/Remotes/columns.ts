/**
 * Every remote's fade rate on one x axis, for the Remotes chart: the remotes' buckets share one
 * 100 ms grid on one clock, so the axis is that grid and each remote is a column on it. The
 * columns grow: each redraw takes only the buckets a remote gained since the last one (and its
 * provisional ones again) and writes them in place; nothing is merged, sorted or rebuilt per
 * redraw. A bucket a remote did not send stays null, a gap in its line (nothing is drawn where
 * nothing arrived).
 */
import { BUCKET_US } from '../../../worker/protocol.js';
import type { SeriesBuffer } from '../../live.js';

const BUCKET_S = BUCKET_US / 1e6;
/** Ten minutes of buckets (the longest window); 2.5 minutes more piled up are dropped in one step. */
const KEEP = 6000;
const SLACK = 1500;

interface Reader {
  series: SeriesBuffer | undefined;
  epoch: number;
  /** `series.appended` when last read. */
  appended: number;
}

export class AlignedColumns {
  /** The grid, s (uPlot's x). */
  readonly x: number[] = [];
  /** One column per remote, fades/s, null where the remote has no bucket. */
  readonly columns: (number | null)[][];
  /** The grid index of x[0]. */
  #first = 0;
  readonly #readers: Reader[];

  constructor(remotes: number) {
    this.columns = Array.from({ length: remotes }, () => []);
    this.#readers = Array.from({ length: remotes }, () => ({ series: undefined, epoch: -1, appended: 0 }));
  }

  /**
   * Takes the buckets each remote's series (in column order) gained since the last call; starts
   * over when one was cleared or replaced (a new source on that id, a seek).
   */
  update(series: readonly (SeriesBuffer | undefined)[]): void {
    if (this.#readers.some((r, i) => r.series !== series[i] || r.epoch !== (series[i]?.epoch ?? -1))) this.#restart(series);
    this.#readers.forEach((reader, r) => {
      const s = reader.series;
      if (s === undefined) return;
      const fresh = s.unreadSince(reader.appended);
      for (let i = s.length - fresh; i < s.length; i++) {
        const t = s.t[i];
        if (t !== undefined) this.#put(r, Math.round(t / BUCKET_S), s.fadeRate[i] ?? null);
      }
      reader.appended = s.appended;
    });
    if (this.x.length > KEEP + SLACK) {
      const drop = this.x.length - KEEP;
      this.x.splice(0, drop);
      for (const col of this.columns) col.splice(0, drop);
      this.#first += drop;
    }
  }

  #restart(series: readonly (SeriesBuffer | undefined)[]): void {
    this.x.length = 0;
    for (const col of this.columns) col.length = 0;
    this.#readers.forEach((reader, r) => {
      const s = series[r];
      reader.series = s;
      reader.epoch = s?.epoch ?? -1;
      reader.appended = 0;
    });
  }

  /** Writes remote `r`'s value for grid index `k`, growing the grid to reach it. */
  #put(r: number, k: number, value: number | null): void {
    if (this.x.length === 0) this.#first = k;
    if (k < this.#first) {
      // A remote whose buckets start before the others' (read later): the grid grows to the left.
      const n = this.#first - k;
      this.x.unshift(...Array.from({ length: n }, (_, i) => (k + i) * BUCKET_S));
      for (const col of this.columns) col.unshift(...new Array<null>(n).fill(null));
      this.#first = k;
    }
    while (k >= this.#first + this.x.length) {
      this.x.push((this.#first + this.x.length) * BUCKET_S);
      for (const col of this.columns) col.push(null);
    }
    const col = this.columns[r];
    if (col !== undefined) col[k - this.#first] = value;
  }
}
