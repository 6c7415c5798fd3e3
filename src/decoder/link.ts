/**
 * Link health from decoded frames: fades, frame period, missed frames, the adapter's delivery
 * delay, and the failsafe state machine of spec §7.1 (live → hold last values → failsafe after
 * one second without a frame → live again on the next frame). Time is always the caller's:
 * `frame()` uses the frame's own time and `update(now)` advances the clock between frames;
 * nothing here reads a clock.
 *
 * This file and the parts the monitor owns (the frame ledger, ledger.ts; the period and
 * fade-rate windows, link-rates.ts; the stall judge, link-stalls.ts; the restart watch,
 * link-restarts.ts; the plain timing rules, link-rules.ts) are the one home of the link rules
 * every surface shares (live page, replay, `satscope info`, `satscope report`):
 *
 * - **Missed frames** rest on the receiver's own evidence where it gives some: the fade counter
 *   (UINT8 of an internal remote, UINT16 of an external one, §8.3/§8.4: "missed frames for this
 *   remote"). A receiver whose counter never moved from 0 (a clone's `00 00` header, or an
 *   SPM4649T that sends RSSI instead) gives none; then frames received are counted against
 *   frames expected over windows of at least `LEDGER_WINDOW_US`, anchored on the most punctual
 *   frame of each window, so that bytes a USB adapter held back and delivered in a burst are
 *   never counted as missing (`FrameLedger`).
 * - **Hold** starts only when no frame has come for longer than `HOLD_MIN_US` (at least 2.5
 *   periods) plus the delivery jitter measured on this stream; its episode is dated from the
 *   moment the next frame was due (last frame + one period), so that every surface dates it the
 *   same whatever its timing. Failsafe follows one second after the last frame (§7.1).
 * - **Delivery delay and jitter** (how late frames reach us against the receiver's own
 *   schedule) are a measure of their own (`deliveryDelayUs`, `deliveryJitterUs`), never loss.
 *   A silence whose frames the evidence shows were sent (the fade counter did not move over the
 *   burst that ended it, or the burst brought them all) is a **delivery stall** (`stalls`): its
 *   hold, and its failsafe, are withdrawn, since the flight controller, which reads the receiver
 *   directly, saw neither. The frame that ends a silence dates it (its first byte's time): a
 *   hold or failsafe the clock opened while that frame was arriving late is withdrawn if the
 *   frame came within its threshold. And a run of frames the counter says the receiver lost,
 *   longer than a hold, is one even where a stall hid the gap from the adapter.
 * - **A receiver restart**: after a silence of `RESTART_MIN_GAP_US` or more, a fade counter that
 *   fell by more than a wrap explains started again from 0 at power-up (`restarts`). Its count
 *   then says nothing about the silence: the hold stands and the frames due in it are missed.
 * - **The frame period** snaps to 11 or 22 ms at `PERIOD_SNAP_US` (`nominalPeriodOf`).
 * - Fades are the decoder's `fadesDelta`: the decoder already leaves out counter jumps it cannot
 *   attribute to the receiver (`DecoderStats.fadeJumps`).
 */
import { FAILSAFE_TIMEOUT_US, FRAME_PERIOD_11MS_US, systemInfo } from './spec.js';
import type { DecodedFrame } from './types.js';
import { EpisodeLog } from './episode-log.js';
import type { LinkEpisode } from './episode.js';
import type { LinkOptions, LinkRestart, LinkState, LinkStats } from './link-types.js';
import { HOLD_MIN_US, holdThresholdUs, isFrameInterval } from './link-rules.js';
import { LinkRates } from './link-rates.js';
import { RestartWatch } from './link-restarts.js';
import { StallJudge } from './link-stalls.js';
import { FrameLedger } from './ledger.js';
import { copyEpisodes, type LinkCheckpoint } from './checkpoint.js';

/**
 * The link's health from the frames and the clock: the failsafe state machine of spec §7.1,
 * the frame period, missed frames, fades, holds, stalls and restarts. Time is always passed
 * in (`frame(f)` uses the frame's time, `update(nowUs)` the caller's, `finish(endUs)` ends a
 * capture), so live use and replay give the same figures.
 */
export class LinkMonitor {
  readonly #holdOption: number | undefined;
  readonly #failsafeAfterUs: number;
  /** The jitter in force until one is measured; a double from the start (NaN), as the measured one is (bench/README.md). */
  readonly #jitterPrior: number = NaN;
  readonly #onMissed: LinkOptions['onMissed'];
  #state: LinkState = 'waiting';
  #lastUs = NaN;
  /** The period and fade-rate windows. */
  readonly #rates = new LinkRates();
  /** The last system byte seen, and whether `systemInfo` knew it (one lookup per change, not per frame). */
  #systemByte = -1;
  readonly #episodes: LinkEpisode[] = [];
  /** The episodes that can no longer change, for checkpoints (unless `maxEpisodes`: then they are few). */
  #log = new EpisodeLog();
  readonly #maxEpisodes: number;
  #nextEpisode = 0;
  #open: LinkEpisode | null = null;
  readonly #ledger: FrameLedger;
  /** `#missedByCount` bound once, for the ledger (no closure made per frame). */
  readonly #missed = (fromUs: number, toUs: number, count: number): void => this.#missedByCount(fromUs, toUs, count);
  /** The fade counter has shown that it counts (a value other than 0, or a rise). */
  #counting = false;
  /** The fade counter from frame to frame, and the receiver restarts it showed. */
  readonly #restarts = new RestartWatch();
  #lastFades = 0;
  #lastInterval = NaN;
  #finished = false;
  /** Where the source stopped delivering (`stopped()`), until its first frame after that; NaN when not. */
  #stoppedUs = NaN;
  readonly #stats: LinkStats = {
    frames: 0,
    fades: 0,
    missedFrames: 0,
    missedBasis: 'none',
    lostFrames: 0,
    holds: 0,
    failsafes: 0,
    restarts: 0,
    stalls: 0,
    longestStallUs: 0,
    periodUs: NaN,
    nominalPeriodUs: NaN,
    fadeRate: 0,
    longestGapUs: 0,
    rssi: NaN,
    minRssi: NaN,
    deliveryDelayUs: NaN,
    deliveryJitterUs: NaN,
  };
  /** The holds that wait to be judged, the delivery stalls they turn out to be, and the silences stalls hid. */
  readonly #stalls: StallJudge;

  /** @throws {TypeError} when a duration is not a positive finite number. */
  constructor(options: LinkOptions = {}) {
    for (const key of ['holdAfterUs', 'failsafeAfterUs', 'jitterUs', 'maxEpisodes'] as const) {
      const v = options[key];
      if (v !== undefined && !(Number.isFinite(v) && v >= 0)) throw new TypeError(`${key} must be a finite number ≥ 0, not ${String(v)}`);
    }
    this.#holdOption = options.holdAfterUs;
    this.#failsafeAfterUs = options.failsafeAfterUs ?? FAILSAFE_TIMEOUT_US;
    this.#jitterPrior = options.jitterUs ?? 0;
    this.#maxEpisodes = options.maxEpisodes ?? Infinity;
    this.#onMissed = options.onMissed;
    this.#ledger = new FrameLedger(this.#jitterPrior);
    this.#stalls = new StallJudge(this.#episodes, this.#stats, {
      holdAfterUs: () => this.holdAfterUs,
      counterHoldUs: () => this.#holdOption ?? holdThresholdUs(this.#stats.nominalPeriodUs, this.#jitterPrior),
      periodKnown: () => Number.isFinite(this.#rates.stated) && this.#stats.nominalPeriodUs === this.#rates.stated,
      failsafeAfterUs: this.#failsafeAfterUs,
      add: (kind, startUs, lastFrameUs) => this.#add(kind, startUs, lastFrameUs),
    });
  }

  get state(): LinkState {
    return this.#state;
  }

  /** Live counters (the same object each time; read it again after more frames). */
  get stats(): Readonly<LinkStats> {
    return this.#stats;
  }

  /** The hold and failsafe episodes kept (all, unless `maxEpisodes`), oldest first; the last may still be open. */
  get episodes(): readonly LinkEpisode[] {
    return this.#episodes;
  }

  /** The last receiver restarts (up to 64), oldest first. */
  get restarts(): readonly LinkRestart[] {
    return this.#restarts.restarts;
  }

  /** Time of the last frame, µs (NaN before the first, without timing, or after `interrupt()`). */
  get lastFrameUs(): number {
    return this.#lastUs;
  }

  /** Fades the last frame reported (its `fadesDelta`). */
  get lastFades(): number {
    return this.#lastFades;
  }

  /** The interval before the last frame when it was an ordinary one (`isFrameInterval`), else NaN. */
  get lastIntervalUs(): number {
    return this.#lastInterval;
  }

  /** The delivery jitter in force: measured, else the `jitterUs` option, µs. */
  get jitterUs(): number {
    const j = this.#stats.deliveryJitterUs;
    return Number.isFinite(j) ? j : this.#jitterPrior;
  }

  /** The hold threshold in force, µs (`holdThresholdUs`, unless the `holdAfterUs` option fixes it). */
  get holdAfterUs(): number {
    return this.#holdOption ?? holdThresholdUs(this.#stats.nominalPeriodUs, this.jitterUs);
  }

  /** Feeds one decoded frame (in stream order). */
  frame(frame: DecodedFrame): void {
    const s = this.#stats;
    const t = frame.timeUs;
    if (t > this.#stoppedUs) {
      // The first frame after the source came back: its absence is no silence of the link.
      this.interrupt(this.#stoppedUs);
      this.#stoppedUs = NaN;
    }
    s.frames++;
    if (frame.rssi !== null) {
      s.rssi = frame.rssi;
      if (!(s.minRssi <= frame.rssi)) s.minRssi = frame.rssi;
    }
    if (frame.system === null && this.#systemByte !== -1) {
      // The frames are an external remote's after all (re-read, or a rebind): the byte the period
      // was taken from was a fade count, and its period is no evidence; timing decides it again.
      this.#systemByte = -1;
      this.#rates.state(NaN, s);
    } else if (frame.system !== null && frame.system !== this.#systemByte) {
      const info = systemInfo(frame.system);
      if (info) {
        this.#systemByte = frame.system;
        this.#rates.state(info.periodUs, s);
      }
    }
    const last = this.#lastUs;
    const open = this.#open;
    if (open !== null && Number.isFinite(last) && open.lastFrameUs > last && !(t <= open.lastFrameUs)) {
      // The silence was counted from bytes the decoder held and then discarded (not a frame):
      // it is dated from the last frame instead, as it would have been without them.
      this.#redate(open.lastFrameUs, last);
    }
    const gap = Number.isFinite(t) && Number.isFinite(last) && t >= last ? t - last : NaN;
    const inBurst = this.#stalls.frame(t, last, frame.fadesDelta);
    const restartDue = this.#restarts.frame(frame, gap, s);
    const fades = frame.fadesDelta;
    s.fades += fades;
    this.#lastFades = fades;
    if (frame.fades !== null && (frame.fades !== 0 || fades > 0) && !this.#counting) {
      this.#counting = true;
      this.#stalls.counting();
    }
    this.#lastInterval = NaN;
    if (Number.isFinite(t)) {
      if (!Number.isNaN(gap)) {
        // Open the episodes a caller that never called update() in the gap would have missed.
        this.update(t);
        if (gap > s.longestGapUs) s.longestGapUs = gap;
        const p = s.nominalPeriodUs;
        if (Number.isFinite(p) && isFrameInterval(gap, p, this.jitterUs)) this.#lastInterval = gap;
        // A silence the delivery jitter does not explain ends the period window. Before the
        // period is known nothing does: the snap weighs the window's gaps itself (link-rates.ts).
        if (Number.isFinite(p) && gap > 3 * p && gap > this.holdAfterUs) this.#rates.clearPeriod();
      }
      this.#lastUs = t;
      this.#rates.measure(t, fades, s, frame.fades !== null);
      this.#ledger.frame(t, s.nominalPeriodUs, this.#missed);
      this.#stalls.confirm(this.#ledger);
      s.deliveryDelayUs = this.#ledger.delayUs;
      s.deliveryJitterUs = this.#ledger.jitterUs;
    }
    if (this.#counting) {
      s.missedBasis = 'fade-counter';
      if (restartDue > 0) {
        // A counter that restarted, or moved by what the decoder could not attribute, does not
        // count the silence: the frames due in it are missed.
        const p = s.nominalPeriodUs;
        s.missedFrames += restartDue;
        this.#onMissed?.(t - gap + p, t, restartDue, p);
      }
      if (fades > 0) {
        s.missedFrames += fades;
        if (Number.isFinite(t)) {
          const p = Number.isFinite(s.nominalPeriodUs) ? s.nominalPeriodUs : FRAME_PERIOD_11MS_US;
          this.#onMissed?.(Number.isNaN(gap) ? t : t - gap + p, t, fades, p);
        }
      }
    } else if (Number.isFinite(s.nominalPeriodUs) && Number.isFinite(t)) {
      s.missedBasis = 'frame-count';
    }
    if (this.#open !== null && Number.isFinite(t)) {
      // The frame the silence is counted from (held by the decoder: `pendingUs`) or older: it goes on.
      if (t <= this.#open.lastFrameUs) return;
      this.#open = this.#stalls.shorter(this.#open, t);
    }
    const ended = this.#open;
    if (ended !== null) {
      ended.endUs = Number.isFinite(t) ? t : ended.startUs;
      // What the receiver says it missed in the silence: the evidence where its counter counts
      // (null: it moved by more than the decoder could attribute, a relock after the silence).
      const counter = this.#counting && (restartDue > 0 || this.#restarts.evidence);
      this.#stalls.ended(ended, counter, restartDue > 0 ? restartDue : fades, fades);
      this.#open = null;
    }
    if (this.#counting && this.#restarts.vouched && !inBurst && fades > 0) this.#stalls.hidden(t, last, fades, ended);
    this.#state = 'live';
  }

  /**
   * Ids of hold episodes withdrawn since the last call (a silence that was only the adapter
   * holding bytes back, as the frames that followed showed); they are gone from `episodes` and
   * from the count of holds.
   */
  takeRetracted(): number[] {
    return this.#stalls.takeRetracted();
  }

  /** Frames the ledger found missing: they count while the receiver has given no counter to go by. */
  #missedByCount(fromUs: number, toUs: number, count: number): void {
    this.#stats.lostFrames += count;
    if (this.#counting) return;
    this.#stats.missedFrames += count;
    this.#onMissed?.(fromUs, toUs, count, this.#stats.nominalPeriodUs);
  }

  /**
   * Advances the clock to `nowUs` (the caller's time, same clock as the frames) and returns
   * the state: 'hold' once the hold threshold has passed without a frame, 'failsafe' after 1 s.
   * `pendingUs`: the time of a frame received but not handed out yet (a decoder holds a frame
   * until the next one confirms where it ends): the silence counts from it, as it will once
   * the frame comes.
   */
  update(nowUs: number, pendingUs = Number.NaN): LinkState {
    // While the source is away, the link is judged no later than when it stopped.
    if (nowUs > this.#stoppedUs) nowUs = this.#stoppedUs;
    const last = pendingUs > this.#lastUs ? pendingUs : this.#lastUs;
    if (this.#state === 'waiting' || !Number.isFinite(last) || !Number.isFinite(nowUs)) return this.#state;
    const gap = nowUs - last;
    const s = this.#stats;
    // No hold threshold is below HOLD_MIN_US (or the holdAfterUs option): the common short gap
    // is decided without working the threshold out.
    if (this.#state === 'live' && gap > (this.#holdOption ?? HOLD_MIN_US) && gap > this.holdAfterUs) {
      // A new silence: a counted burst before it is over (the frames may have stopped for good).
      if (this.#stalls.burst?.counted === true) this.#stalls.endBurst();
      this.#state = 'hold';
      s.holds++;
      // The hold began when the next frame was due, whenever it was noticed.
      const p = s.nominalPeriodUs;
      this.#open = this.#add('hold', last + (Number.isFinite(p) ? p : this.holdAfterUs), last);
      this.#stalls.held(this.#open);
    }
    const hold = this.#state === 'hold' ? this.#open : null;
    // A frame held now came a second or more after the hold's: the hold's silence reached failsafe.
    const heldLate = hold !== null && last - hold.lastFrameUs >= this.#failsafeAfterUs;
    if ((gap >= this.#failsafeAfterUs || heldLate) && this.#state === 'hold') {
      this.#state = 'failsafe';
      s.failsafes++;
      // A second after the last frame received (held or not), or the hold's own; of the hold's silence.
      const from = heldLate ? (hold?.lastFrameUs ?? last) : last;
      if (hold !== null) hold.endUs = from + this.#failsafeAfterUs;
      this.#open = this.#add('failsafe', from + this.#failsafeAfterUs, hold?.lastFrameUs ?? last);
    }
    return this.#state;
  }

  /**
   * The end of the stream at `endUs` (the capture's last recorded time): the state there, and
   * the frames due in a silence before it that the delivery jitter does not explain, counted as
   * missed. Call once; frames fed afterwards are not expected.
   */
  finish(endUs: number): LinkState {
    if (this.#finished) return this.#state;
    this.#finished = true;
    if (Number.isFinite(this.#stoppedUs)) {
      // The stream ended with its source away: nothing after the stop is the link's.
      this.interrupt(this.#stoppedUs);
      this.#stoppedUs = NaN;
    }
    this.#stalls.endBurst();
    const state = this.update(endUs);
    const s = this.#stats;
    if (!Number.isFinite(endUs) || !Number.isFinite(this.#lastUs) || !Number.isFinite(s.nominalPeriodUs)) return state;
    const silence = endUs - this.#lastUs;
    const grace = this.holdAfterUs;
    if (silence > grace && silence > s.longestGapUs) s.longestGapUs = silence;
    if (this.#counting) {
      // The receiver never got to report these: frames due in a silence longer than a hold.
      this.#ledger.finish(endUs, Infinity, this.#missed);
      this.#stalls.confirm(this.#ledger);
      if (silence > grace) {
        const p = s.nominalPeriodUs;
        const k = Math.max(0, Math.floor((silence - this.jitterUs) / p));
        if (k > 0) {
          s.missedFrames += k;
          s.lostFrames += k;
          this.#onMissed?.(this.#lastUs + p, endUs, k, p);
        }
      }
    } else {
      this.#ledger.finish(endUs, silence > grace ? this.jitterUs : Infinity, this.#missed);
      this.#stalls.confirm(this.#ledger);
    }
    return state;
  }

  /**
   * The frames stopped at `atUs` for a reason that is not the link (the user forced a resolution
   * that no frame fits, the source was paused or moved): an open episode ends there, the state
   * is 'waiting', and the next frame starts afresh, with no gap, missed frame or episode counted
   * for the time in between.
   */
  interrupt(atUs: number): void {
    this.#stalls.interrupt();
    if (this.#open !== null) {
      this.#open.endUs = Number.isFinite(atUs) ? Math.max(atUs, this.#open.startUs) : this.#open.startUs;
      this.#open = null;
    }
    this.#lastUs = NaN;
    this.#rates.clearPeriod();
    this.#ledger.reset();
    this.#state = 'waiting';
  }

  /**
   * The source stopped delivering at `atUs` for a reason that is not the link (its port was lost,
   * the demo's simulation paused over a stall). The link stops being judged now (`interrupt`),
   * and again at the first frame after `atUs`, once the frames the decoder still held from before
   * it are counted: no hold, failsafe or missed frame is counted for the time the source was away.
   * Live, replayed and in every command alike (a recorded "device lost" event).
   */
  stopped(atUs: number): void {
    this.interrupt(atUs);
    this.#stoppedUs = atUs;
  }

  /**
   * The monitor's whole state now (checkpoint.ts): state, episodes (copies), the period and
   * fade-rate windows, the ledger, the holds not yet judged and the counters.
   */
  checkpoint(): LinkCheckpoint {
    // Kept whole otherwise: a monitor that drops old episodes has only a few to copy.
    const logged = this.#maxEpisodes === Infinity ? this.#log.take(this.#episodes, this.#settled) : null;
    const stalls = this.#stalls;
    return {
      state: this.#state,
      lastUs: this.#lastUs,
      systemByte: this.#systemByte,
      ...this.#rates.checkpoint(),
      settled: logged?.blocks ?? [],
      graph: copyEpisodes({
        episodes: logged?.open ?? this.#episodes,
        open: this.#open,
        unconfirmed: stalls.unconfirmed,
        burst: stalls.burst,
      }),
      nextEpisode: this.#nextEpisode,
      retracted: stalls.retracted.slice(),
      ledger: this.#ledger.checkpoint(),
      closesSeen: stalls.closesSeen,
      counting: this.#counting,
      ...this.#restarts.checkpoint(),
      lastFades: this.#lastFades,
      lastInterval: this.#lastInterval,
      finished: this.#finished,
      stoppedUs: this.#stoppedUs,
      stats: { ...this.#stats },
    };
  }

  /**
   * Puts the monitor back where `checkpoint()` was taken (on this monitor or another): fed the
   * same frames and times from there, it gives the same states, episodes, counters and missed
   * frames. Its own options and `onMissed` stay; `cp` can be restored again.
   */
  restore(cp: LinkCheckpoint): void {
    this.#state = cp.state;
    this.#lastUs = cp.lastUs;
    this.#rates.restore(cp);
    this.#systemByte = cp.systemByte;
    const g = copyEpisodes(cp.graph);
    // Pushed one by one: a long session's thousands of episodes are too many for spread arguments.
    // The settled ones are copied (the monitor's own are written: redated, ended; the log's never),
    // and put in order of id with the others.
    this.#episodes.length = 0;
    for (const block of cp.settled) for (const e of block) this.#episodes.push({ ...e });
    for (const e of g.episodes) this.#episodes.push(e);
    if (cp.settled.length > 0) this.#episodes.sort((a, b) => a.id - b.id);
    this.#log = EpisodeLog.of(cp.settled, g.episodes);
    this.#open = g.open;
    this.#stalls.restore(g.unconfirmed, g.burst, cp.retracted, cp.closesSeen);
    this.#nextEpisode = cp.nextEpisode;
    this.#ledger.restore(cp.ledger);
    this.#counting = cp.counting;
    this.#restarts.restore(cp);
    this.#lastFades = cp.lastFades;
    this.#lastInterval = cp.lastInterval;
    this.#finished = cp.finished;
    this.#stoppedUs = cp.stoppedUs;
    Object.assign(this.#stats, cp.stats);
  }

  /**
   * Whether episode `e` can no longer change: it has ended (the open one has not), no hold waits
   * to be judged by it and it is not of the silence still open (`#redate` moves those).
   */
  readonly #settled = (e: LinkEpisode): boolean =>
    e.endUs !== null && !(this.#open !== null && e.lastFrameUs === this.#open.lastFrameUs) && !this.#stalls.waits(e.lastFrameUs);

  /** Re-dates the episodes counted from `fromUs` to count from the frame at `lastUs`. */
  #redate(fromUs: number, lastUs: number): void {
    const p = this.#stats.nominalPeriodUs;
    for (let i = this.#episodes.length - 1; i >= 0; i--) {
      const e = this.#episodes[i] as LinkEpisode;
      if (e.lastFrameUs !== fromUs) break;
      e.lastFrameUs = lastUs;
      if (e.kind === 'failsafe') {
        e.startUs = lastUs + this.#failsafeAfterUs;
      } else {
        e.startUs = lastUs + (Number.isFinite(p) ? p : this.holdAfterUs);
        if (e.endUs !== null) e.endUs = lastUs + this.#failsafeAfterUs;
      }
    }
  }

  /** A new episode, kept in `episodes` (the newest never dropped). */
  #add(kind: 'hold' | 'failsafe', startUs: number, lastFrameUs: number): LinkEpisode {
    const episode: LinkEpisode = { id: this.#nextEpisode++, kind, startUs, endUs: null, lastFrameUs };
    this.#episodes.push(episode);
    // Drop the oldest in one go (an amortised splice), never this one.
    if (this.#episodes.length > this.#maxEpisodes * 1.25) this.#episodes.splice(0, this.#episodes.length - Math.max(1, this.#maxEpisodes));
    return episode;
  }
}
