/**
 * Delivery stalls: the holds that wait to be judged, and the judgement that withdraws those
 * the adapter caused. A hold whose silence, by the evidence (the fade counter, the burst of
 * frames after it, or the frame count of the ledger window that closes over it), lost under
 * half the frames due in it was the adapter holding bytes back, not the link: it is withdrawn,
 * with the failsafe it became, and counted as a stall. The link monitor (link.ts) owns a judge,
 * over its own episodes and stats.
 */
import type { LinkEpisode } from './episode.js';
import type { FrameLedger } from './ledger.js';
import type { LinkStats } from './link-types.js';
import { FRAME_PERIOD_11MS_US } from './spec.js';

/**
 * The holds not yet confirmed and the burst after one, judged as the evidence comes; writes
 * the withdrawals into the monitor's `episodes` and `stats` (holds, failsafes, stalls).
 */
export class StallJudge {
  readonly #episodes: LinkEpisode[];
  readonly #stats: LinkStats;
  /**
   * Holds not yet confirmed, with the receiver's fade count when each began: a hold whose
   * silence the next punctual frame shows held no missing frame was the adapter holding bytes
   * back (a delivery stall), not the link: it is withdrawn (`retracted`).
   */
  readonly #unconfirmed: { episode: LinkEpisode; endFades: number }[] = [];
  readonly #retracted: number[] = [];
  /**
   * A hold that just ended with no counter to judge it, and the frames that came right after
   * it closer together than half a period: a stall delivers the frames it held all at once,
   * while a link that lost them resumes at its pace.
   */
  #burst: { episode: LinkEpisode; frames: number } | null = null;
  #closesSeen = 0;

  /** Judges the holds of `episodes` (the monitor's list) and counts in `stats` (the monitor's). */
  constructor(episodes: LinkEpisode[], stats: LinkStats) {
    this.#episodes = episodes;
    this.#stats = stats;
  }

  /** The holds not yet judged (the monitor's episode objects), oldest first: the judge's own list, for checkpoints to copy. */
  get unconfirmed(): { episode: LinkEpisode; endFades: number }[] {
    return this.#unconfirmed;
  }

  /** The burst after a hold still arriving, or null. */
  get burst(): { episode: LinkEpisode; frames: number } | null {
    return this.#burst;
  }

  /** Ids of the holds withdrawn and not yet taken (`takeRetracted`). */
  get retracted(): readonly number[] {
    return this.#retracted;
  }

  /** Ledger windows closed so far that the holds were judged by. */
  get closesSeen(): number {
    return this.#closesSeen;
  }

  /** A hold just opened: it waits to be judged (at most 64 wait). */
  held(episode: LinkEpisode): void {
    this.#unconfirmed.push({ episode, endFades: 0 });
    if (this.#unconfirmed.length > 64) this.#unconfirmed.shift();
  }

  /**
   * A frame at `t` came, the last one before it at `last`: within a burst after a hold, frames
   * closer together than half a period count in the burst (those of chunks delivered together
   * may even be dated out of order); any other ends it.
   */
  frame(t: number, last: number): void {
    if (this.#burst === null) return;
    const p = this.#stats.nominalPeriodUs;
    if (Number.isFinite(t) && !(t - last >= (Number.isFinite(p) ? p : FRAME_PERIOD_11MS_US) / 2)) this.#burst.frames++;
    else this.endBurst();
  }

  /**
   * The silence of `open` ended with a frame whose fade count moved by `fades`. Where the
   * counter counts (`counting`), that is the evidence (`missed`: the frames it says were lost)
   * and a hold is judged now (a stall's frames arrive late, none missed); otherwise it waits
   * for the burst after it and for the frame count of the ledger window that closes over it.
   */
  ended(open: LinkEpisode, counting: boolean, missed: number, fades: number): void {
    const at = this.#unconfirmed.findIndex((x) => x.episode === open);
    const u = this.#unconfirmed[at];
    if (u !== undefined && counting) {
      this.#unconfirmed.splice(at, 1);
      this.#judge(u.episode, missed);
    } else if (u !== undefined) {
      u.endFades = fades;
      this.#burst = { episode: u.episode, frames: 1 };
    }
  }

  /** After a ledger window: holds before its most punctual frame are confirmed or withdrawn. */
  confirm(l: FrameLedger): void {
    if (l.closes === this.#closesSeen) return;
    this.#closesSeen = l.closes;
    for (let i = 0; i < this.#unconfirmed.length; ) {
      const u = this.#unconfirmed[i];
      // A hold whose burst is still arriving is judged by the burst first.
      const waiting = u === undefined || u.episode === this.#burst?.episode;
      if (waiting || !(u.episode.lastFrameUs < l.closedPunctualUs) || u.episode.endUs === null) {
        i++;
        continue;
      }
      this.#unconfirmed.splice(i, 1);
      this.#judge(u.episode, Math.max(l.closedMissing, u.endFades));
    }
  }

  /** The burst after a hold is over: a hold whose frames came in it is withdrawn now; any other waits for its ledger window. */
  endBurst(): void {
    const b = this.#burst;
    this.#burst = null;
    if (b === null) return;
    // The burst brought the silence's frames, and the frame due when it came.
    const missed = Math.max(0, this.#dueIn(b.episode) + 1 - b.frames);
    const at = this.#unconfirmed.findIndex((x) => x.episode === b.episode);
    if (at >= 0 && this.#judge(b.episode, missed)) this.#unconfirmed.splice(at, 1);
  }

  /** The frames stopped for a reason that is not the link: a burst then is no evidence. */
  interrupt(): void {
    this.#burst = null;
  }

  /** Whether a hold of the silence after the frame at `lastFrameUs` still waits to be judged (by its burst or its ledger window). */
  waits(lastFrameUs: number): boolean {
    return this.#burst?.episode.lastFrameUs === lastFrameUs || this.#unconfirmed.some((u) => u.episode.lastFrameUs === lastFrameUs);
  }

  /**
   * Ids of hold episodes withdrawn since the last call (a silence that was only the adapter
   * holding bytes back, as the frames that followed showed); they are gone from `episodes` and
   * from the count of holds.
   */
  takeRetracted(): number[] {
    return this.#retracted.splice(0, this.#retracted.length);
  }

  /** Puts the judge back where a checkpoint found it (`unconfirmed` and `burst` of the restored episodes). */
  restore(
    unconfirmed: readonly { episode: LinkEpisode; endFades: number }[],
    burst: { episode: LinkEpisode; frames: number } | null,
    retracted: readonly number[],
    closesSeen: number,
  ): void {
    this.#unconfirmed.splice(0, this.#unconfirmed.length, ...unconfirmed); // at most 64
    this.#burst = burst;
    this.#retracted.splice(0, this.#retracted.length, ...retracted);
    this.#closesSeen = closesSeen;
  }

  /** Frames a hold's silence (through its failsafe, if it became one) would have held had the link lost them (0 while it is open or no period is known). */
  #dueIn(e: LinkEpisode): number {
    const p = this.#stats.nominalPeriodUs;
    const end = this.#silenceEndUs(e);
    return Number.isFinite(p) && end !== null ? Math.round((end - e.lastFrameUs) / p) - 1 : 0;
  }

  /** Where the silence a hold began ended: the hold's end, or its failsafe's (null while it lasts). */
  #silenceEndUs(e: LinkEpisode): number | null {
    for (let i = this.#episodes.length - 1; i >= 0; i--) {
      const f = this.#episodes[i] as LinkEpisode;
      if (f.kind === 'failsafe' && f.lastFrameUs === e.lastFrameUs) return f.endUs;
      if (f.lastFrameUs < e.lastFrameUs) break;
    }
    return e.endUs;
  }

  /**
   * Keeps a hold that ended, or withdraws it (and says so): `missed` is how many frames the
   * evidence says were lost in its silence. A stall delivers the frames it held after it, so a
   * hold that lost under half of them was the adapter's: a delivery stall, and so is the
   * failsafe it became (the flight controller, on the receiver's own line, had its frames).
   */
  #judge(e: LinkEpisode, missed: number): boolean {
    const due = this.#dueIn(e);
    if (due < 2 || missed >= due / 2) return false;
    const s = this.#stats;
    const silence = (this.#silenceEndUs(e) ?? e.lastFrameUs) - e.lastFrameUs;
    for (let i = this.#episodes.length - 1; i >= 0; i--) {
      const x = this.#episodes[i] as LinkEpisode;
      if (x.lastFrameUs !== e.lastFrameUs) {
        if (x.lastFrameUs < e.lastFrameUs) break;
        continue;
      }
      this.#episodes.splice(i, 1);
      if (x.kind === 'hold') s.holds--;
      else s.failsafes--;
      this.#retracted.push(x.id);
    }
    s.stalls++;
    if (silence > s.longestStallUs) s.longestStallUs = silence;
    return true;
  }
}
