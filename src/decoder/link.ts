/**
 * Link health from decoded frames: fades, frame period, missed frames, the adapter's delivery
 * delay, and the failsafe state machine of spec §7.1 (live → hold last values → failsafe after
 * one second without a frame → live again on the next frame). Time is always the caller's:
 * `frame()` uses the frame's own time and `update(now)` advances the clock between frames;
 * nothing here reads a clock.
 *
 * This file is the one home of the link rules every surface shares (live page, replay,
 * `satscope info`, `satscope report`):
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
 *   A silence whose frames the evidence shows were sent (the fade counter did not move, or a
 *   burst brought them all) is a **delivery stall** (`stalls`): its hold, and its failsafe, are
 *   withdrawn, since the flight controller, which reads the receiver directly, saw neither.
 * - **A receiver restart**: after a silence of `RESTART_MIN_GAP_US` or more, a fade counter that
 *   fell by more than a wrap explains started again from 0 at power-up (`restarts`). Its count
 *   then says nothing about the silence: the hold stands and the frames due in it are missed.
 * - **The frame period** snaps to 11 or 22 ms at `PERIOD_SNAP_US` (`nominalPeriodOf`).
 * - Fades are the decoder's `fadesDelta`: the decoder already leaves out counter jumps it cannot
 *   attribute to the receiver (`DecoderStats.fadeJumps`).
 */
import { FAILSAFE_TIMEOUT_US, FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US, systemInfo } from './spec.js';
import type { DecodedFrame } from './types.js';
import { EpisodeLog } from './episode-log.js';
import type { LinkEpisode } from './episode.js';
import type { LinkOptions, LinkRestart, LinkState, LinkStats } from './link-types.js';
import { HOLD_MIN_US, holdThresholdUs, isFrameInterval, nominalPeriodOf } from './link-rules.js';
import { FrameLedger } from './ledger.js';
import { copyEpisodes, type LinkCheckpoint } from './checkpoint.js';

/** A fade counter that falls after a silence at least this long is a restart, not line damage (a restart takes a satellite longer). */
export const RESTART_MIN_GAP_US = 100_000;
/** Restarts kept in `restarts` (the count in `stats` keeps counting). */
const RESTARTS_KEPT = 64;

const PERIOD_WINDOW = 33;
/** A mean frame interval below this (0.8 × 11 ms) is no system's period: frames a delivery burst brought together. */
const BURST_MEAN_US = 0.8 * FRAME_PERIOD_11MS_US;
const RATE_WINDOW = 512;

/**
 * The link's health from the frames and the clock: the failsafe state machine of spec §7.1,
 * the frame period, missed frames, fades, holds, stalls and restarts. Time is always passed
 * in (`frame(f)` uses the frame's time, `update(nowUs)` the caller's, `finish(endUs)` ends a
 * capture), so live use and replay give the same figures.
 */
export class LinkMonitor {
  readonly #holdOption: number | undefined;
  readonly #failsafeAfterUs: number;
  /**
   * Starts as NaN so that V8 keeps it as a double even when the option is a whole number: the
   * jitter in force is this or the measured one, and a whole-number field beside a double made
   * optimised code box the double every frame (16 bytes a frame).
   */
  readonly #jitterPrior: number = NaN;
  readonly #onMissed: LinkOptions['onMissed'];
  #state: LinkState = 'waiting';
  #lastUs = NaN;
  #systemPeriod = NaN;
  /** The last frame times without a gap, a ring: `#periodCount` of them, the oldest at `#periodOldest` once it is full. */
  readonly #periodTimes = new Float64Array(PERIOD_WINDOW);
  #periodCount = 0;
  #periodOldest = 0;
  /** The last system byte seen, and whether `systemInfo` knew it (one lookup per change, not per frame). */
  #systemByte = -1;
  readonly #rateTimes = new Float64Array(RATE_WINDOW);
  readonly #rateFades = new Float64Array(RATE_WINDOW);
  #rateCount = 0;
  #rateNext = 0;
  readonly #episodes: LinkEpisode[] = [];
  /** The episodes that can no longer change, for checkpoints (unless `maxEpisodes`: then they are few). */
  #log = new EpisodeLog();
  readonly #maxEpisodes: number;
  #nextEpisode = 0;
  #open: LinkEpisode | null = null;
  readonly #ledger: FrameLedger;
  /** `#missedByCount` bound once, for the ledger (no closure made per frame). */
  readonly #missed = (fromUs: number, toUs: number, count: number): void => this.#missedByCount(fromUs, toUs, count);
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
  /** The fade counter has shown that it counts (a value other than 0, or a rise). */
  #counting = false;
  /** The last frame's fade count (NaN: none yet), and the last restarts. */
  #prevCount = NaN;
  readonly #restarts: LinkRestart[] = [];
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
    return this.#restarts;
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
    if (frame.system !== null && frame.system !== this.#systemByte) {
      const info = systemInfo(frame.system);
      if (info) {
        this.#systemByte = frame.system;
        this.#systemPeriod = info.periodUs;
        s.nominalPeriodUs = this.#systemPeriod;
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
    if (this.#burst !== null) {
      // Within a burst, frames of chunks delivered together may even be dated out of order.
      const p = s.nominalPeriodUs;
      if (Number.isFinite(t) && !(t - last >= (Number.isFinite(p) ? p : FRAME_PERIOD_11MS_US) / 2)) this.#burst.frames++;
      else this.#endBurst();
    }
    const restartDue = this.#restarted(frame, gap);
    const fades = frame.fadesDelta;
    s.fades += fades;
    this.#lastFades = fades;
    if (frame.fades !== null && (frame.fades !== 0 || fades > 0)) this.#counting = true;
    this.#lastInterval = NaN;
    if (Number.isFinite(t)) {
      if (!Number.isNaN(gap)) {
        // Open the episodes a caller that never called update() in the gap would have missed.
        this.update(t);
        if (gap > s.longestGapUs) s.longestGapUs = gap;
        const p = s.nominalPeriodUs;
        if (Number.isFinite(p) && isFrameInterval(gap, p, this.jitterUs)) this.#lastInterval = gap;
        if (gap > 3 * (Number.isFinite(p) ? p : FRAME_PERIOD_22MS_US)) this.#periodCount = 0;
      }
      this.#lastUs = t;
      this.#measure(fades); // at #lastUs
      this.#ledger.frame(t, s.nominalPeriodUs, this.#missed);
      this.#confirmHolds();
      s.deliveryDelayUs = this.#ledger.delayUs;
      s.deliveryJitterUs = this.#ledger.jitterUs;
    }
    if (this.#counting) {
      s.missedBasis = 'fade-counter';
      if (restartDue > 0) {
        // The restarted counter does not count the silence: the frames due in it are missed.
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
    // A frame from before the silence began (the decoder held it, `update`'s `pendingUs`): the
    // silence goes on, counted from this frame if it is the later one.
    if (this.#open !== null && Number.isFinite(t) && t < this.#open.startUs) {
      if (t > this.#open.lastFrameUs) this.#redate(this.#open.lastFrameUs, t);
      return;
    }
    if (this.#open !== null) {
      this.#open.endUs = Number.isFinite(t) ? t : this.#open.startUs;
      // What the receiver says it missed in the silence. Where its counter counts, that is the
      // evidence, and the hold is judged now (a stall's frames arrive late, none missed);
      // otherwise it waits for the frame count of the ledger window that closes over it.
      const at = this.#unconfirmed.findIndex((x) => x.episode === this.#open);
      const u = this.#unconfirmed[at];
      if (u !== undefined && this.#counting) {
        this.#unconfirmed.splice(at, 1);
        this.#judge(u.episode, restartDue > 0 ? restartDue : fades);
      } else if (u !== undefined) {
        u.endFades = fades;
        this.#burst = { episode: u.episode, frames: 1 };
      }
      this.#open = null;
    }
    this.#state = 'live';
  }

  /**
   * Whether `frame` ends a silence of `gapUs` with a restarted counter (recorded, and counted in
   * `stats.restarts`); returns the frames due in the silence (0: no restart). A wrap in the
   * silence adds about as many as were due: a fall further from that than 8 frames, or half of
   * them, is no wrap.
   */
  #restarted(frame: DecodedFrame, gapUs: number): number {
    const count = frame.fades;
    if (count === null) return 0;
    const prev = this.#prevCount;
    this.#prevCount = count;
    const p = this.#stats.nominalPeriodUs;
    if (!(count < prev) || !(gapUs >= RESTART_MIN_GAP_US) || !Number.isFinite(p)) return 0;
    const modulus = frame.remote === 'internal' ? 256 : 65536;
    const due = Math.max(0, Math.round(gapUs / p) - 1);
    const wrapped = (count - prev + modulus) % modulus;
    if (Math.abs(wrapped - due) <= Math.max(8, 0.5 * due)) return 0;
    this.#stats.restarts++;
    this.#restarts.push({ timeUs: frame.timeUs, from: prev, to: count, gapUs });
    if (this.#restarts.length > RESTARTS_KEPT) this.#restarts.shift();
    return Math.max(1, due);
  }

  /**
   * Ids of hold episodes withdrawn since the last call (a silence that was only the adapter
   * holding bytes back, as the frames that followed showed); they are gone from `episodes` and
   * from the count of holds.
   */
  takeRetracted(): number[] {
    return this.#retracted.splice(0, this.#retracted.length);
  }

  /** After a ledger window: holds before its most punctual frame are confirmed or withdrawn. */
  #confirmHolds(): void {
    const l = this.#ledger;
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
  #endBurst(): void {
    const b = this.#burst;
    this.#burst = null;
    if (b === null) return;
    // The burst brought the silence's frames, and the frame due when it came.
    const missed = Math.max(0, this.#dueIn(b.episode) + 1 - b.frames);
    const at = this.#unconfirmed.findIndex((x) => x.episode === b.episode);
    if (at >= 0 && this.#judge(b.episode, missed)) this.#unconfirmed.splice(at, 1);
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
      this.#state = 'hold';
      s.holds++;
      // The hold began when the next frame was due, whenever it was noticed.
      const p = s.nominalPeriodUs;
      this.#openEpisode('hold', last + (Number.isFinite(p) ? p : this.holdAfterUs), last);
      if (this.#open !== null) this.#unconfirmed.push({ episode: this.#open, endFades: 0 });
      if (this.#unconfirmed.length > 64) this.#unconfirmed.shift();
    }
    if (gap >= this.#failsafeAfterUs && this.#state === 'hold') {
      this.#state = 'failsafe';
      s.failsafes++;
      if (this.#open !== null) this.#open.endUs = last + this.#failsafeAfterUs;
      this.#openEpisode('failsafe', last + this.#failsafeAfterUs, last);
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
    if (this.#burst !== null) this.#endBurst();
    const state = this.update(endUs);
    const s = this.#stats;
    if (!Number.isFinite(endUs) || !Number.isFinite(this.#lastUs) || !Number.isFinite(s.nominalPeriodUs)) return state;
    const silence = endUs - this.#lastUs;
    const grace = this.holdAfterUs;
    if (silence > grace && silence > s.longestGapUs) s.longestGapUs = silence;
    if (this.#counting) {
      // The receiver never got to report these: frames due in a silence longer than a hold.
      this.#ledger.finish(endUs, Infinity, this.#missed);
      this.#confirmHolds();
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
      this.#confirmHolds();
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
    this.#burst = null;
    if (this.#open !== null) {
      this.#open.endUs = Number.isFinite(atUs) ? Math.max(atUs, this.#open.startUs) : this.#open.startUs;
      this.#open = null;
    }
    this.#lastUs = NaN;
    this.#periodCount = 0;
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
    return {
      state: this.#state,
      lastUs: this.#lastUs,
      systemPeriod: this.#systemPeriod,
      periodTimes: this.#periodTimes.slice(),
      periodCount: this.#periodCount,
      periodOldest: this.#periodOldest,
      systemByte: this.#systemByte,
      rateTimes: this.#rateTimes.slice(),
      rateFades: this.#rateFades.slice(),
      rateCount: this.#rateCount,
      rateNext: this.#rateNext,
      settled: logged?.blocks ?? [],
      graph: copyEpisodes({
        episodes: logged?.open ?? this.#episodes,
        open: this.#open,
        unconfirmed: this.#unconfirmed,
        burst: this.#burst,
      }),
      nextEpisode: this.#nextEpisode,
      retracted: this.#retracted.slice(),
      ledger: this.#ledger.checkpoint(),
      closesSeen: this.#closesSeen,
      counting: this.#counting,
      prevCount: this.#prevCount,
      restarts: this.#restarts.map((r) => ({ ...r })),
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
    this.#systemPeriod = cp.systemPeriod;
    this.#periodTimes.set(cp.periodTimes);
    this.#periodCount = cp.periodCount;
    this.#periodOldest = cp.periodOldest;
    this.#systemByte = cp.systemByte;
    this.#rateTimes.set(cp.rateTimes);
    this.#rateFades.set(cp.rateFades);
    this.#rateCount = cp.rateCount;
    this.#rateNext = cp.rateNext;
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
    this.#unconfirmed.splice(0, this.#unconfirmed.length, ...g.unconfirmed); // at most 64
    this.#burst = g.burst;
    this.#nextEpisode = cp.nextEpisode;
    this.#retracted.splice(0, this.#retracted.length, ...cp.retracted);
    this.#ledger.restore(cp.ledger);
    this.#closesSeen = cp.closesSeen;
    this.#counting = cp.counting;
    this.#prevCount = cp.prevCount;
    this.#restarts.splice(0, this.#restarts.length, ...cp.restarts.map((r) => ({ ...r })));
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
    e.endUs !== null &&
    !(this.#open !== null && e.lastFrameUs === this.#open.lastFrameUs) &&
    this.#burst?.episode.lastFrameUs !== e.lastFrameUs &&
    !this.#unconfirmed.some((u) => u.episode.lastFrameUs === e.lastFrameUs);

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

  #openEpisode(kind: 'hold' | 'failsafe', startUs: number, lastFrameUs: number): void {
    const episode: LinkEpisode = { id: this.#nextEpisode++, kind, startUs, endUs: null, lastFrameUs };
    this.#episodes.push(episode);
    // Drop the oldest in one go (an amortised splice), never the open one.
    if (this.#episodes.length > this.#maxEpisodes * 1.25) this.#episodes.splice(0, this.#episodes.length - this.#maxEpisodes);
    this.#open = episode;
  }

  /**
   * The period and fade-rate windows take the frame at #lastUs (and, without a system byte, the
   * nominal period is snapped, which the frame's own rules read), and the figures follow.
   */
  #measure(fadesDelta: number): void {
    const t = this.#lastUs;
    // Period: the span of the last 32 gap-free intervals, which averages out chunk jitter.
    const times = this.#periodTimes;
    const count = this.#periodCount;
    if (count < PERIOD_WINDOW) {
      if (count === 0) this.#periodOldest = 0;
      times[count] = t;
      this.#periodCount = count + 1;
    } else {
      const oldest = this.#periodOldest;
      times[oldest] = t;
      this.#periodOldest = oldest === PERIOD_WINDOW - 1 ? 0 : oldest + 1;
    }
    if (this.#periodCount >= 9) {
      const s = this.#stats;
      if (!Number.isFinite(this.#systemPeriod) && (!Number.isFinite(s.nominalPeriodUs) || this.#periodCount === PERIOD_WINDOW)) {
        // Without a system byte: snap the mean interval to 11 or 22 ms, first over 8 intervals,
        // then again over every full window, so a few frames missing early do not stick. A
        // window that a delivery burst crowds (frames a stall held back, dated together) is
        // faster than any system sends: it says nothing of the period.
        const mean = (t - (times[this.#periodOldest] ?? NaN)) / (this.#periodCount - 1);
        if (!(mean < BURST_MEAN_US)) s.nominalPeriodUs = nominalPeriodOf(mean);
      }
      // Whole periods in the span, so that a missed frame (one interval two periods long) does
      // not bias it, and chunk-time jitter averages out.
      const newest =
        this.#periodCount < PERIOD_WINDOW ? this.#periodCount - 1 : this.#periodOldest === 0 ? PERIOD_WINDOW - 1 : this.#periodOldest - 1;
      const span = (times[newest] ?? NaN) - (times[this.#periodOldest] ?? NaN);
      s.periodUs = span / Math.max(1, Math.round(span / s.nominalPeriodUs));
    }
    // Fade rate over a window of recent frames.
    const i = this.#rateNext;
    const fades = this.#rateFades;
    const prev = this.#rateCount === 0 ? 0 : (fades[i === 0 ? RATE_WINDOW - 1 : i - 1] ?? 0);
    this.#rateTimes[i] = t;
    fades[i] = prev + fadesDelta;
    this.#rateNext = i === RATE_WINDOW - 1 ? 0 : i + 1;
    if (this.#rateCount < RATE_WINDOW) this.#rateCount++;
    const oldest = this.#rateCount < RATE_WINDOW ? 0 : this.#rateNext;
    const span = t - (this.#rateTimes[oldest] ?? NaN);
    this.#stats.fadeRate = span > 0 ? (((fades[i] ?? 0) - (fades[oldest] ?? 0)) / span) * 1e6 : 0;
  }
}
