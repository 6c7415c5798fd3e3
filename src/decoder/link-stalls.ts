/**
 * Delivery stalls: the holds that wait to be judged, and the judgement that withdraws those
 * the adapter caused. A hold whose silence, by the evidence (the fade counter over the burst
 * of frames after it, the burst's frame count, or the frame count of the ledger window that
 * closes over it), lost under half the frames due in it, and where the receiver's counter
 * shows no run of lost frames itself long enough for a hold, was the adapter holding bytes
 * back, not the link: it is withdrawn, with the failsafe it became, and counted as a stall.
 * The link monitor (link.ts) owns a judge, over its own episodes and stats.
 */
import type { LinkEpisode } from './episode.js';
import type { FrameLedger } from './ledger.js';
import type { LinkStats } from './link-types.js';

/**
 * The frames that came right after a hold, closer together than half a period: how many, the
 * longest run of frames the receiver's counter says were lost before one of them, and whether
 * the counter counts (it did before, or moved in the burst).
 */
export interface StallBurst {
  episode: LinkEpisode;
  frames: number;
  run: number;
  /** null: the counter moved over the silence by a count no frame's delta gives: it says nothing of this burst. */
  counted: boolean | null;
}

/** What the judge needs of its link monitor: its thresholds, and a new episode in its list. */
export interface StallMonitor {
  holdAfterUs(): number;
  /**
   * The hold threshold for a silence the receiver's counter measures, µs: with the delivery
   * jitter the monitor was told to expect, not the one it measured (stalls inflate that, and
   * the counter's silence has no delivery in it).
   */
  counterHoldUs(): number;
  /** Whether the frame period is the system byte's (known for sure), not an estimate from intervals. */
  periodKnown(): boolean;
  readonly failsafeAfterUs: number;
  add(kind: 'hold' | 'failsafe', startUs: number, lastFrameUs: number): LinkEpisode;
}

/**
 * A hold not yet judged: the receiver's fade count when it ended, and once its burst is over
 * without a counter known to count, the longest run the counter said was lost over it (judged
 * by it should the counter later be seen to count), else null.
 */
export interface UnjudgedHold {
  episode: LinkEpisode;
  endFades: number;
  counterRun: number | null;
}
import { FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US } from './spec.js';

/**
 * The holds not yet confirmed and the burst after one, judged as the evidence comes; writes
 * the withdrawals into the monitor's `episodes` and `stats` (holds, failsafes, stalls).
 */
export class StallJudge {
  readonly #episodes: LinkEpisode[];
  readonly #stats: LinkStats;
  /**
   * Holds not yet confirmed: a hold whose silence the frames after it show held no missing
   * frame was the adapter holding bytes back (a delivery stall), not the link: it is
   * withdrawn (`retracted`).
   */
  readonly #unconfirmed: UnjudgedHold[] = [];
  readonly #retracted: number[] = [];
  /**
   * A hold that just ended and the frames that came right after it: a stall delivers the
   * frames it held all at once, while a link that lost them resumes at its pace.
   */
  #burst: StallBurst | null = null;
  #closesSeen = 0;
  readonly #monitor: StallMonitor;

  /**
   * Judges the holds of `episodes` (the monitor's list) and counts in `stats` (the monitor's),
   * by the monitor's thresholds; adds episodes through it.
   */
  constructor(episodes: LinkEpisode[], stats: LinkStats, monitor: StallMonitor) {
    this.#episodes = episodes;
    this.#stats = stats;
    this.#monitor = monitor;
  }

  /** The holds not yet judged (the monitor's episode objects), oldest first: the judge's own list, for checkpoints to copy. */
  get unconfirmed(): UnjudgedHold[] {
    return this.#unconfirmed;
  }

  /** The burst after a hold still arriving, or null. */
  get burst(): StallBurst | null {
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
    this.#unconfirmed.push({ episode, endFades: 0, counterRun: null });
    if (this.#unconfirmed.length > 64) this.#unconfirmed.shift();
  }

  /**
   * A frame at `t` came, the last one before it at `last`, its fade count moved by `fades`:
   * within a burst after a hold, frames closer together than half a period count in the burst
   * (those of chunks delivered together may even be dated out of order); any other ends it.
   * Returns whether the frame counted in a burst.
   */
  frame(t: number, last: number, fades: number): boolean {
    const b = this.#burst;
    if (b === null) return false;
    const p = this.#stats.nominalPeriodUs;
    if (Number.isFinite(t) && !(t - last >= (Number.isFinite(p) ? p : FRAME_PERIOD_11MS_US) / 2)) {
      b.frames++;
      if (fades > b.run) b.run = fades;
      if (fades > 0 && b.counted !== null) b.counted = true;
      return true;
    }
    this.endBurst();
    return false;
  }

  /**
   * The silence of `open` ended with a frame whose fade count moved by `fades`. The hold waits
   * for the burst after it: where the counter counts (`counting`), the runs it says were lost
   * (`missed` now, then those over the burst) are the evidence, and the hold is judged when the
   * burst ends; otherwise (and where the count moved by what no delta gives, `counting` null:
   * the decoder relocked after the silence, and the frames lost in it are not known) by the
   * burst's frame count, and then by the frame count of the ledger window that closes over it.
   */
  ended(open: LinkEpisode, counting: boolean | null, missed: number, fades: number): void {
    // The hold of this silence (`open` is its failsafe if it became one).
    const u = this.#unconfirmed.find((x) => x.episode.lastFrameUs === open.lastFrameUs);
    if (u === undefined) return;
    u.endFades = fades;
    this.#burst = { episode: u.episode, frames: 1, run: missed, counted: counting === null ? null : counting || missed > 0 };
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
      this.#judge(u.episode, null, Math.max(l.closedMissing, u.endFades));
    }
  }

  /**
   * The burst after a hold is over: a hold is judged by the counter over it, for good; without
   * one, a hold whose frames came in it is withdrawn now, any other waits for its ledger window.
   */
  endBurst(): void {
    const b = this.#burst;
    this.#burst = null;
    if (b === null) return;
    const at = this.#unconfirmed.findIndex((x) => x.episode === b.episode);
    const u = this.#unconfirmed[at];
    if (u === undefined) return;
    // Without a counter: the burst brought the silence's frames, and the frame due when it came.
    const missed = Math.max(0, this.#dueIn(b.episode) + 1 - b.frames);
    if (this.#judge(b.episode, b.counted ? b.run : null, missed) || b.counted) this.#unconfirmed.splice(at, 1);
    else u.counterRun = b.run;
  }

  /**
   * The receiver's counter was just seen to count for the first time: the holds whose bursts
   * ended before are judged by what it said over them (a counter that stood still over a burst
   * said no frame was lost there).
   */
  counting(): void {
    for (let i = 0; i < this.#unconfirmed.length; ) {
      const u = this.#unconfirmed[i] as UnjudgedHold;
      if (u.counterRun === null) {
        i++;
        continue;
      }
      this.#unconfirmed.splice(i, 1);
      this.#judge(u.episode, u.counterRun, 0);
    }
  }

  /**
   * A frame at `t` ends the silence `open` (its hold or failsafe), which the clock opened while
   * the frame's bytes were still arriving (the adapter held them back, or the decoder was
   * finding its frames again). The frame's own time says how long the silence was: no hold
   * within the hold threshold, no failsafe within the failsafe's; what did not happen is
   * withdrawn (no stall counted). Returns the episode the frame ends: `open`, its hold open
   * again, or null.
   */
  shorter(open: LinkEpisode, t: number): LinkEpisode | null {
    const silence = t - open.lastFrameUs;
    const last = open.lastFrameUs;
    if (silence <= this.#monitor.holdAfterUs()) {
      const at = this.#unconfirmed.findIndex((x) => x.episode.lastFrameUs === last);
      if (at >= 0) this.#unconfirmed.splice(at, 1);
      this.#remove(last);
      return null;
    }
    if (silence >= this.#monitor.failsafeAfterUs || open.kind === 'hold') return open;
    this.#remove(last, true);
    for (let i = this.#episodes.length - 1; i >= 0; i--) {
      const x = this.#episodes[i] as LinkEpisode;
      if (x.lastFrameUs === last && x.kind === 'hold') {
        x.endUs = null;
        return x;
      }
    }
    return null;
  }

  /**
   * The receiver's counter says it lost the `fades` frames between the frame before (at `last`)
   * and the frame at `t`: they were in a row, its own line silent for fades + 1 periods. Where
   * no hold ended with this frame (`ended`), the adapter saw a shorter silence (a stall hid it:
   * the frames before delivered late and together) or did not call it a hold (its threshold
   * grows with the delivery jitter a stall measured): the hold is added. Where the hold that
   * ended did not become a failsafe and the receiver's silence reached one, the failsafe is.
   * Neither waits to be judged: the counter is the evidence.
   * After a break in the monitor's view (`last` NaN: the start, an interrupt), the count spans
   * time it did not see: nothing is added.
   */
  hidden(t: number, last: number, fades: number, ended: LinkEpisode | null): void {
    const s = this.#stats;
    const m = this.#monitor;
    const p = s.nominalPeriodUs;
    const silence = (fades + 1) * p;
    // A hold's worth of the receiver's own silence (not a run a wrong period estimate stretches);
    // beside a hold that ended here, a hold's worth more than the adapter saw.
    if (!m.periodKnown() || !Number.isFinite(silence) || !Number.isFinite(t) || !Number.isFinite(last)) return;
    if (!((ended === null ? silence : silence - (t - last)) > m.counterHoldUs())) return;
    // When the receiver's first missing frame was due.
    const rxStartUs = t - fades * p;
    let hold = ended;
    if (hold === null) {
      s.holds++;
      hold = m.add('hold', rxStartUs, last);
      hold.endUs = t;
    }
    if (hold.kind === 'hold' && silence >= m.failsafeAfterUs) {
      s.failsafes++;
      // On the receiver's clock: the hold from its first missing frame, the failsafe a second
      // after its last frame (before the adapter saw the silence begin, where a stall hid it).
      if (rxStartUs < hold.startUs) hold.startUs = rxStartUs;
      hold.endUs = t - silence + m.failsafeAfterUs;
      m.add('failsafe', hold.endUs, hold.lastFrameUs).endUs = t;
    }
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
  restore(unconfirmed: readonly UnjudgedHold[], burst: StallBurst | null, retracted: readonly number[], closesSeen: number): void {
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
   * Keeps a hold that ended, or withdraws it (and says so): `run` is the most frames in a row
   * the receiver's counter says it lost (null without a counter), `missed` how many the frame
   * count says were lost in its silence (used without a counter). A stall delivers the frames
   * it held after it, and the failsafe the hold became is the adapter's too (the flight
   * controller, on the receiver's own line, had its frames).
   */
  #judge(e: LinkEpisode, run: number | null, missed: number): boolean {
    // With the receiver's counter, the hold was the link's where a run of frames it lost is a
    // hold's silence itself (lost frames scattered over a silence the adapter made are no hold
    // on the receiver's line).
    if (run !== null) {
      if ((run + 1) * this.#runPeriodUs() > this.#monitor.counterHoldUs()) return false;
    } else {
      // Without, where the frames that came after it do not stand for half of those due in it;
      // with no period to count them by, it stands.
      const due = this.#dueIn(e);
      if (due < 2 || missed >= due / 2) return false;
    }
    const s = this.#stats;
    const silence = (this.#silenceEndUs(e) ?? e.lastFrameUs) - e.lastFrameUs;
    this.#remove(e.lastFrameUs);
    s.stalls++;
    if (silence > s.longestStallUs) s.longestStallUs = silence;
    return true;
  }

  /**
   * The period a run of frames the counter says were lost is timed at: the system byte's, or
   * the one the frames' timing decided (link-rates.ts snaps only where it can tell 11 from 22
   * ms); where none is known yet, the longest: a hold goes only where no period makes the run one.
   */
  #runPeriodUs(): number {
    const p = this.#stats.nominalPeriodUs;
    return Number.isFinite(p) ? p : FRAME_PERIOD_22MS_US;
  }

  /**
   * Takes the hold and failsafe (or only the failsafe) of the silence after the frame at
   * `lastFrameUs` out of the episodes and counts, and says so (`retracted`).
   */
  #remove(lastFrameUs: number, failsafeOnly = false): void {
    const s = this.#stats;
    for (let i = this.#episodes.length - 1; i >= 0; i--) {
      const x = this.#episodes[i] as LinkEpisode;
      if (x.lastFrameUs !== lastFrameUs || (failsafeOnly && x.kind === 'hold')) {
        if (x.lastFrameUs < lastFrameUs) break;
        continue;
      }
      this.#episodes.splice(i, 1);
      if (x.kind === 'hold') s.holds--;
      else s.failsafes--;
      this.#retracted.push(x.id);
    }
  }
}
