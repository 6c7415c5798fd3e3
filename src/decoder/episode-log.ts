/**
 * The link monitor's episodes that can no longer change, logged for its checkpoints (link.ts):
 * in blocks that every later checkpoint shares, so that a checkpoint holds a reference a block
 * and copies only the episodes still open to change. Copying every episode into every checkpoint
 * made a day of a flaky link quadratic: a hold every 40 s is 2 154 episodes, 1.5 million copies
 * over a day's 1 440 checkpoints, 3 s to send them between workers (node 20).
 */
import type { LinkEpisode } from './episode.js';

/** Episodes a block: a checkpoint copies at most this many references of the last one. */
const BLOCK = 256;

export class EpisodeLog {
  /** Full blocks, never written again. */
  #blocks: (readonly LinkEpisode[])[] = [];
  /** The settled episodes logged since the last full block. */
  #partial: LinkEpisode[] = [];
  /** Episodes from this id on have not been looked at. */
  #scanFrom = 0;
  /** Ids of episodes looked at and found open to change (a hold not yet judged, say): looked at again each time. */
  #waiting: number[] = [];

  /**
   * The log of a checkpoint's `settled` blocks and `open` episodes (`take`'s answer), to go on
   * from: full blocks are shared with it, the last one copied.
   */
  static of(settled: readonly (readonly LinkEpisode[])[], open: readonly LinkEpisode[]): EpisodeLog {
    const log = new EpisodeLog();
    const last = settled.at(-1);
    const full = last === undefined || last.length >= BLOCK ? settled.length : settled.length - 1;
    log.#blocks = settled.slice(0, full);
    log.#partial = full === settled.length ? [] : [...(last ?? [])];
    let maxId = -1;
    for (const block of settled) for (const e of block) maxId = Math.max(maxId, e.id);
    for (const e of open) maxId = Math.max(maxId, e.id);
    log.#scanFrom = maxId + 1;
    log.#waiting = open.map((e) => e.id);
    return log;
  }

  /**
   * Logs the episodes of `episodes` (the monitor's, in order of id; one settled is never
   * removed) that `settled` says can no longer change and that are not logged yet. Returns
   * the others (the monitor's own objects, in order) and the log in blocks for a checkpoint:
   * data no later call changes.
   */
  take(
    episodes: readonly LinkEpisode[],
    settled: (e: LinkEpisode) => boolean,
  ): { open: LinkEpisode[]; blocks: (readonly LinkEpisode[])[] } {
    const looked: LinkEpisode[] = [];
    for (const id of this.#waiting) {
      const e = byId(episodes, id);
      if (e !== undefined) looked.push(e); // else withdrawn
    }
    let i = episodes.length;
    while (i > 0 && (episodes[i - 1]?.id ?? -1) >= this.#scanFrom) i--;
    for (; i < episodes.length; i++) looked.push(episodes[i] as LinkEpisode);
    const open: LinkEpisode[] = [];
    for (const e of looked) {
      if (!settled(e)) {
        open.push(e);
        continue;
      }
      this.#partial.push(Object.freeze({ ...e }));
      if (this.#partial.length === BLOCK) {
        this.#blocks.push(Object.freeze(this.#partial));
        this.#partial = [];
      }
    }
    const lastId = episodes.at(-1)?.id;
    if (lastId !== undefined) this.#scanFrom = Math.max(this.#scanFrom, lastId + 1);
    this.#waiting = open.map((e) => e.id);
    return { open, blocks: this.#partial.length === 0 ? this.#blocks.slice() : [...this.#blocks, this.#partial.slice()] };
  }
}

/** The episode of `episodes` (in order of id) with `id`, by bisection. */
function byId(episodes: readonly LinkEpisode[], id: number): LinkEpisode | undefined {
  let lo = 0;
  let hi = episodes.length;
  while (lo < hi) {
    const mid = (lo + hi) >>> 1;
    if ((episodes[mid]?.id ?? Number.POSITIVE_INFINITY) < id) lo = mid + 1;
    else hi = mid;
  }
  const e = episodes[lo];
  return e?.id === id ? e : undefined;
}
