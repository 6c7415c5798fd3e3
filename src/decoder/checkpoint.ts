/**
 * Checkpoints: the whole state of a decoder, a link monitor or its frame ledger at a point
 * between calls, as plain data no later call changes. `restore()` puts an instance of the same
 * options back exactly there, as many times as asked, so that a replay seeks by restoring the
 * nearest checkpoint and feeding only the bytes after it: the same frames, counters, events
 * and episodes as feeding everything from the start. A checkpoint holds what was still
 * undecided (the bytes the decoder holds, the open ledger window, the episodes), never the
 * stream before it: a few kilobytes.
 *
 * What an instance was constructed with (options, callbacks) is not state: the instance that
 * restores keeps its own.
 */
import type { LinkEpisode } from './episode.js';
import type { LinkRestart, LinkState, LinkStats } from './link-types.js';
import type { StallBurst, UnjudgedHold } from './link-stalls.js';

declare const opaque: unique symbol;

/**
 * `SpektrumDecoder.checkpoint()`: opaque. What it holds is the decoder's own and changes between
 * versions (a decoder refuses one of another version); it survives `structuredClone`.
 */
export interface DecoderCheckpoint {
  readonly [opaque]: 'DecoderCheckpoint';
}

/** `FrameLedger.checkpoint()`. */
export interface LedgerCheckpoint {
  readonly period: number;
  readonly refUs: number;
  readonly refSlot: number;
  readonly refLateUs: number;
  readonly slot: number;
  readonly lastUs: number;
  readonly winStartUs: number;
  readonly winFrames: number;
  readonly winMinL: number;
  readonly winMinSlot: number;
  readonly winMinUs: number;
  readonly winMaxL: number;
  readonly tailUs: Float64Array;
  readonly tailSlot: Float64Array;
  readonly tailCount: number;
  readonly winSumL: number;
  readonly winGapUs: number;
  readonly winGapFromUs: number;
  readonly winGapToUs: number;
  readonly spreads: readonly number[];
  readonly pendingSpread: number;
  readonly pendingDelay: number;
  readonly delayUs: number;
  readonly jitterUs: number;
  readonly burstFrames: number;
  readonly burstStartUs: number;
  readonly heldUs: number;
  readonly closes: number;
  readonly closedMissing: number;
  readonly closedPunctualUs: number;
}

/** The link monitor's episodes and what refers to them: the open one, the holds not yet judged, the burst after one. */
export interface EpisodeGraph {
  episodes: LinkEpisode[];
  open: LinkEpisode | null;
  unconfirmed: UnjudgedHold[];
  burst: StallBurst | null;
}

/**
 * A copy of `g` in which every episode is a new object and each one, wherever it is referred
 * to (the monitor compares them by identity), is the same copy; a hold judged later may be one
 * the episode list no longer keeps.
 */
export function copyEpisodes(g: Readonly<EpisodeGraph>): EpisodeGraph {
  const copies = new Map<LinkEpisode, LinkEpisode>();
  const copy = (e: LinkEpisode): LinkEpisode => {
    let c = copies.get(e);
    if (c === undefined) {
      c = { ...e };
      copies.set(e, c);
    }
    return c;
  };
  return {
    episodes: g.episodes.map(copy),
    open: g.open === null ? null : copy(g.open),
    unconfirmed: g.unconfirmed.map((u) => ({ ...u, episode: copy(u.episode) })),
    burst: g.burst === null ? null : { ...g.burst, episode: copy(g.burst.episode) },
  };
}

/** `LinkMonitor.checkpoint()`. */
export interface LinkCheckpoint {
  readonly state: LinkState;
  readonly lastUs: number;
  readonly periodTimes: Float64Array;
  readonly periodCount: number;
  readonly periodOldest: number;
  readonly periodStated: number;
  readonly periodRefuted: boolean;
  readonly periodAgainst: number;
  readonly periodCounted: number;
  readonly systemByte: number;
  readonly rateTimes: Float64Array;
  readonly rateFades: Float64Array;
  readonly rateCount: number;
  readonly rateNext: number;
  /**
   * The episodes that can no longer change, in blocks shared with the monitor's later
   * checkpoints (episode-log.ts): never written. `graph` holds the others; a restore puts both
   * back in order of id.
   */
  readonly settled: readonly (readonly LinkEpisode[])[];
  readonly graph: Readonly<EpisodeGraph>;
  readonly nextEpisode: number;
  readonly retracted: readonly number[];
  readonly ledger: LedgerCheckpoint;
  readonly closesSeen: number;
  readonly counting: boolean;
  readonly prevCount: number;
  readonly restarts: readonly LinkRestart[];
  readonly lastFades: number;
  readonly lastInterval: number;
  readonly finished: boolean;
  readonly stoppedUs: number;
  readonly stats: Readonly<LinkStats>;
}
