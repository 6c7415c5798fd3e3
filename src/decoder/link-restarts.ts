/**
 * Receiver restarts: after a silence of `RESTART_MIN_GAP_US` or more, a fade counter that fell
 * by more than a wrap explains started again from 0 at power-up. Its count then says nothing
 * about the silence, nor does one that moved by what the decoder could not attribute: the link
 * monitor (link.ts), which owns a watch, keeps the hold and counts the frames due in the silence
 * as missed.
 */
import type { LinkCheckpoint } from './checkpoint.js';
import type { LinkRestart, LinkStats } from './link-types.js';
import type { DecodedFrame } from './types.js';

/** A fade counter that falls after a silence at least this long is a restart, not line damage (a restart takes a satellite longer). */
export const RESTART_MIN_GAP_US = 100_000;
/** Restarts kept in `restarts` (the count in `stats` keeps counting). */
const RESTARTS_KEPT = 64;

/** What of a `LinkCheckpoint` is the restart watch's. */
type RestartsCheckpoint = Pick<LinkCheckpoint, 'prevCount' | 'restarts'>;

/** The receiver's fade counter from frame to frame, and the restarts it showed. */
export class RestartWatch {
  /** The last frame's fade count (NaN: none yet). */
  #prevCount = NaN;
  readonly #restarts: LinkRestart[] = [];
  /** What the last frame's count says of the frames lost before it (`evidence`). */
  #evidence: boolean | null = false;

  /**
   * What the last frame's count says of the frames lost before it: true where it moved from the
   * one before by just its `fadesDelta` (the receiver vouches for the frames the delta says were
   * lost); null where it moved by a count no delta gives (a jump the decoder left out: another
   * remote's count after a break, a relock after a silence, a restart), so how many were lost is
   * not known; false where the frame has no count.
   */
  get evidence(): boolean | null {
    return this.#evidence;
  }

  /** `evidence` is true. */
  get vouched(): boolean {
    return this.#evidence === true;
  }

  /** The last receiver restarts (up to 64), oldest first. */
  get restarts(): readonly LinkRestart[] {
    return this.#restarts;
  }

  /**
   * The frames due in a silence of `gapUs` that `frame` ends where its count cannot account for
   * them (0 where it can): a restarted counter (recorded, and counted in `s.restarts`), or one
   * that moved by a count the decoder left out (a 1.5 s dropout takes an 8-bit count from 40 to
   * 176, which the decoder cannot tell from another remote's). A wrap in the silence adds about
   * as many as were due: a fall further from that than 8 frames, or half of them, is no wrap.
   */
  frame(frame: DecodedFrame, gapUs: number, s: LinkStats): number {
    const count = frame.fades;
    this.#evidence = false;
    if (count === null) return 0;
    const prev = this.#prevCount;
    this.#prevCount = count;
    const modulus = frame.remote === 'internal' ? 256 : 65536;
    // No count before this one (none yet, or byte 0 not yet read as one): no evidence either way.
    this.#evidence = Number.isNaN(prev) ? false : (count - prev + modulus) % modulus === frame.fadesDelta ? true : null;
    const p = s.nominalPeriodUs;
    if (!(gapUs >= RESTART_MIN_GAP_US) || !Number.isFinite(p)) return 0;
    const due = Math.max(0, Math.round(gapUs / p) - 1);
    // A count the decoder left out (moved on, or wrapped) says nothing of the silence.
    const unattributed = this.#evidence === null ? Math.max(1, due) : 0;
    if (!(count < prev)) return unattributed;
    const wrapped = (count - prev + modulus) % modulus;
    if (Math.abs(wrapped - due) <= Math.max(8, 0.5 * due)) return unattributed;
    s.restarts++;
    this.#restarts.push({ timeUs: frame.timeUs, from: prev, to: count, gapUs });
    if (this.#restarts.length > RESTARTS_KEPT) this.#restarts.shift();
    return Math.max(1, due);
  }

  /** The last count and the restarts (copies), for `LinkMonitor.checkpoint()`. */
  checkpoint(): RestartsCheckpoint {
    return { prevCount: this.#prevCount, restarts: this.#restarts.map((r) => ({ ...r })) };
  }

  /** Puts the watch back where `checkpoint()` was taken. */
  restore(cp: RestartsCheckpoint): void {
    this.#prevCount = cp.prevCount;
    this.#restarts.splice(0, this.#restarts.length, ...cp.restarts.map((r) => ({ ...r })));
  }
}
