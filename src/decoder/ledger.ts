/**
 * The frame ledger: frames received against frames expected over windows of at least
 * `LEDGER_WINDOW_US`, for a receiver whose own counter gives no evidence of missed frames, and
 * the adapter's delivery delay and jitter that the same lateness measures. The link monitor
 * (link.ts) owns one.
 */
import type { LedgerCheckpoint } from './checkpoint.js';
import { BYTE_TIME_US } from './spec.js';

/** The shortest window over which frames received are counted against frames expected, µs. */
export const LEDGER_WINDOW_US = 500_000;
/** At the end of a stream, the least late of this many last frames tells, beyond the delivery jitter, what is missing after the last window's most punctual frame. */
const TAIL_FRAMES = 4;
/** The last frames kept for the end of the stream: a whole delivery of an adapter that batches them (up to 170 ms of 11 ms frames) and the frame before it. */
const TAIL_KEPT = 16;
/**
 * How much later than a frame the reference may have come and the frame still count what it
 * shows missing: half the 15 byte times by which a frame a later delivery vouches for is less
 * late than a period (see `finish`).
 */
const VOUCHED_MARGIN_US = 7.5 * BYTE_TIME_US;
/** Delivery jitter is the largest spread of the last this many windows. */
const JITTER_WINDOWS = 8;

/**
 * Frames received against frames expected. Each frame is given the next slot of the receiver's
 * schedule; its lateness is how far after that slot it came, against a reference frame. Frames
 * can only come late (an adapter holds bytes back; it never delivers them before they were
 * sent), so the most punctual frame of a window tells the schedule: when even it is a whole
 * period or more late, frames are missing, and the window's largest gap is where.
 */
export class FrameLedger {
  #period = NaN;
  #refUs = NaN;
  #refSlot = 0;
  /**
   * How late the reference came against the schedule before it, less the frames counted missing
   * there (negative where it came early, or a window's rounding counted a frame for its
   * lateness); NaN until a window has closed on this schedule.
   */
  #refLateUs = NaN;
  #slot = 0;
  #lastUs = NaN;
  /**
   * The time of the frame `frame()` hands to #frameAt (see `frame()`): read at once, never
   * between calls, so it is no part of the ledger's state (`checkpoint()` leaves it out).
   */
  #nowUs = NaN;
  // The open window, from its first frame.
  #winStartUs = NaN;
  #winFrames = 0;
  #winMinL = Infinity;
  #winMinSlot = 0;
  #winMinUs = NaN;
  #winMaxL = -Infinity;
  /** The last frames' times and slots (a ring), for the end of the stream. */
  readonly #tailUs = new Float64Array(TAIL_KEPT);
  readonly #tailSlot = new Float64Array(TAIL_KEPT);
  #tailCount = 0;
  #winSumL = 0;
  #winGapUs = 0;
  #winGapFromUs = NaN;
  #winGapToUs = NaN;
  readonly #spreads: number[] = [];
  /** Frames after the first of the delivery burst the last frame came in, and that first frame's time. */
  #burstFrames = 0;
  #burstStartUs = NaN;
  /**
   * The longest a delivery burst proves the adapter held a frame: a burst of frames closer than
   * half a period were sent a period apart each (or more, with frames missing among them), so
   * its first frame was late by at least the periods between them less their arrival span.
   */
  #heldUs = 0;
  #pendingSpread = NaN;
  #pendingDelay = NaN;
  delayUs = NaN;
  jitterUs = NaN;
  /** Windows closed so far, and of the last: the frames it found missing and its most punctual frame's time. */
  closes = 0;
  closedMissing = 0;
  closedPunctualUs = NaN;

  /** @param priorJitterUs the delivery jitter to assume until measured */
  constructor(readonly priorJitterUs: number) {}

  reset(): void {
    this.#period = NaN;
    this.#burstFrames = 0;
    this.#refUs = NaN;
    this.#lastUs = NaN;
    this.#openWindow(NaN);
  }

  #openWindow(t: number): void {
    this.#winStartUs = t;
    this.#winFrames = 0;
    this.#winMinL = Infinity;
    this.#winMaxL = -Infinity;
    this.#winSumL = 0;
    this.#winGapUs = 0;
    this.#winGapFromUs = this.#winGapToUs = NaN;
  }

  /**
   * Feeds a frame at `t`; returns frames confirmed missing (and reports where through `missed`).
   *
   * Kept small, so that it is inlined into the monitor's `frame()`: a double handed to a call
   * that is not inlined is boxed (a 16-byte heap number every frame), so the time goes to
   * #frameAt through #nowUs (a field holding a double is written in place).
   */
  frame(t: number, period: number, missed: (fromUs: number, toUs: number, count: number) => void): number {
    if (!Number.isFinite(period)) return 0;
    this.#nowUs = t;
    return this.#frameAt(period, missed);
  }

  /** `frame()` at #nowUs, with a known period. */
  #frameAt(period: number, missed: (fromUs: number, toUs: number, count: number) => void): number {
    let t = this.#nowUs;
    // Chunk-time estimates of two chunks delivered together can overlap a little: not a clock step.
    if (t < this.#lastUs && t > this.#lastUs - period) t = this.#lastUs;
    if (period !== this.#period || !Number.isFinite(this.#refUs) || !(t >= this.#lastUs || Number.isNaN(this.#lastUs))) {
      // A new period (or the first frame, or time going back): start the schedule here.
      this.#period = period;
      this.#refUs = t;
      this.#refSlot = this.#slot = 0;
      this.#refLateUs = NaN;
      this.#lastUs = t;
      this.#tailCount = 0;
      this.#burstFrames = 0;
      this.#burstStartUs = t;
      this.#openWindow(t);
      this.#take(t, 0, 0);
      return 0;
    }
    const gap = t - this.#lastUs;
    this.#slot++;
    let late = t - this.#refUs - (this.#slot - this.#refSlot) * period;
    if (late < 0) {
      // More punctual than the reference: it becomes the reference, and the window's lateness shifts.
      this.#winMinL -= late;
      this.#winMaxL -= late;
      this.#winSumL -= late * this.#winFrames;
      this.#refUs = t;
      this.#refSlot = this.#slot;
      this.#refLateUs += late;
      late = 0;
    }
    if (gap > this.#winGapUs) {
      this.#winGapUs = gap;
      this.#winGapFromUs = this.#lastUs;
      this.#winGapToUs = t;
    }
    if (gap < period / 2) {
      const held = ++this.#burstFrames * period - (t - this.#burstStartUs);
      if (held > this.#heldUs) this.#heldUs = held;
    } else {
      this.#burstFrames = 0;
      this.#burstStartUs = t;
    }
    this.#lastUs = t;
    this.#take(t, late, this.#slot);
    if (t - this.#winStartUs < LEDGER_WINDOW_US || this.#winFrames < 8) return 0;
    return this.#close(missed);
  }

  #take(t: number, late: number, slot: number): void {
    if (this.#winFrames === 0) this.#winStartUs = t;
    this.#winFrames++;
    this.#winSumL += late;
    if (late > this.#winMaxL) this.#winMaxL = late;
    if (late < this.#winMinL) {
      this.#winMinL = late;
      this.#winMinSlot = slot;
      this.#winMinUs = t;
    }
    this.#tailUs[this.#tailCount % TAIL_KEPT] = t;
    this.#tailSlot[this.#tailCount % TAIL_KEPT] = slot;
    this.#tailCount++;
  }

  /** Closes the window: confirms what even its most punctual frame says is missing (at most `most`). */
  #close(missed: (fromUs: number, toUs: number, count: number) => void, most = Infinity): number {
    const p = this.#period;
    const k = Math.max(0, Math.min(most, Math.round(this.#winMinL / p)));
    if (k > 0 && Number.isFinite(this.#winGapFromUs)) missed(this.#winGapFromUs + p, this.#winGapToUs, k);
    else if (k > 0) missed(this.#winMinUs - k * p, this.#winMinUs, k);
    // The most punctual frame is the schedule from now on (this also follows clock drift).
    // Jitter from windows with nothing missing in them. A frame missed after a window's most
    // punctual frame is only confirmed by the next window, and would pass a period off as
    // lateness: a window's spread counts once the next one has found nothing missing.
    if (k === 0 && Number.isFinite(this.#pendingSpread)) {
      const spreads = this.#spreads;
      spreads.push(this.#pendingSpread);
      if (spreads.length > JITTER_WINDOWS) spreads.shift();
      // The widest by hand: Math.max(...spreads) makes an argument list every window.
      let widest = Number.NEGATIVE_INFINITY;
      for (let k = 0; k < spreads.length; k++) widest = Math.max(widest, spreads[k] ?? Number.NaN);
      this.jitterUs = widest;
      this.delayUs = this.#pendingDelay;
    }
    this.#pendingSpread = k === 0 && this.#winFrames > 1 ? this.#winMaxL - this.#winMinL : NaN;
    this.#pendingDelay = this.#winSumL / this.#winFrames - this.#winMinL;
    this.closes++;
    this.closedMissing = k;
    this.closedPunctualUs = this.#winMinUs;
    this.#refUs = this.#winMinUs;
    this.#refSlot = this.#winMinSlot + k;
    this.#refLateUs = this.#winMinL - k * p;
    this.#slot += k;
    // The last frames after the most punctual one move with it.
    for (let i = 0; i < TAIL_KEPT; i++)
      if ((this.#tailSlot[i] ?? NaN) > this.#winMinSlot) this.#tailSlot[i] = (this.#tailSlot[i] ?? NaN) + k;
    // The next window starts at its own first frame: one that began at this frame would close
    // on the frames of a delivery burst alone after a stall longer than a window, all late,
    // and count the frames the burst brought as missing.
    this.#openWindow(NaN);
    return k;
  }

  /** The ledger's whole state now (checkpoint.ts). */
  checkpoint(): LedgerCheckpoint {
    return {
      period: this.#period,
      refUs: this.#refUs,
      refSlot: this.#refSlot,
      refLateUs: this.#refLateUs,
      slot: this.#slot,
      lastUs: this.#lastUs,
      winStartUs: this.#winStartUs,
      winFrames: this.#winFrames,
      winMinL: this.#winMinL,
      winMinSlot: this.#winMinSlot,
      winMinUs: this.#winMinUs,
      winMaxL: this.#winMaxL,
      tailUs: this.#tailUs.slice(),
      tailSlot: this.#tailSlot.slice(),
      tailCount: this.#tailCount,
      winSumL: this.#winSumL,
      winGapUs: this.#winGapUs,
      winGapFromUs: this.#winGapFromUs,
      winGapToUs: this.#winGapToUs,
      spreads: this.#spreads.slice(),
      pendingSpread: this.#pendingSpread,
      pendingDelay: this.#pendingDelay,
      delayUs: this.delayUs,
      jitterUs: this.jitterUs,
      burstFrames: this.#burstFrames,
      burstStartUs: this.#burstStartUs,
      heldUs: this.#heldUs,
      closes: this.closes,
      closedMissing: this.closedMissing,
      closedPunctualUs: this.closedPunctualUs,
    };
  }

  /** Puts the ledger back where `checkpoint()` was taken; `cp` can be restored again. */
  restore(cp: LedgerCheckpoint): void {
    this.#period = cp.period;
    this.#refUs = cp.refUs;
    this.#refSlot = cp.refSlot;
    this.#refLateUs = cp.refLateUs;
    this.#slot = cp.slot;
    this.#lastUs = cp.lastUs;
    this.#winStartUs = cp.winStartUs;
    this.#winFrames = cp.winFrames;
    this.#winMinL = cp.winMinL;
    this.#winMinSlot = cp.winMinSlot;
    this.#winMinUs = cp.winMinUs;
    this.#winMaxL = cp.winMaxL;
    this.#tailUs.set(cp.tailUs);
    this.#tailSlot.set(cp.tailSlot);
    this.#tailCount = cp.tailCount;
    this.#winSumL = cp.winSumL;
    this.#winGapUs = cp.winGapUs;
    this.#winGapFromUs = cp.winGapFromUs;
    this.#winGapToUs = cp.winGapToUs;
    this.#spreads.splice(0, this.#spreads.length, ...cp.spreads);
    this.#pendingSpread = cp.pendingSpread;
    this.#pendingDelay = cp.pendingDelay;
    this.delayUs = cp.delayUs;
    this.jitterUs = cp.jitterUs;
    this.#burstFrames = cp.burstFrames;
    this.#burstStartUs = cp.burstStartUs;
    this.#heldUs = cp.heldUs;
    this.closes = cp.closes;
    this.closedMissing = cp.closedMissing;
    this.closedPunctualUs = cp.closedPunctualUs;
  }

  /** End of the stream: closes the open window, then counts the frames due in the silence before `endUs` beyond `graceUs`. */
  finish(endUs: number, graceUs: number, missed: (fromUs: number, toUs: number, count: number) => void): number {
    if (!Number.isFinite(this.#refUs)) return 0;
    const p = this.#period;
    // No later window will look at the frames after the reference (the last window's most
    // punctual frame), and the open window's most punctual one may have come in the last
    // delivery, late by the adapter's timer: what is missing since the reference is what these
    // frames prove. The least late of the last of them proves what is beyond the delivery jitter
    // measured. A frame the next one came a delivery after (further apart than the bytes of one
    // delivery put them) proves more: the adapter handed it over before that next frame was
    // sent, a period after it, so it is less late than a period less its own 15 last bytes, and
    // what it shows missing holds to the period, rounded down; the last such frame is the
    // latest evidence.
    let tailMin = Infinity;
    let vouched = Number.NEGATIVE_INFINITY;
    for (let back = Math.min(TAIL_KEPT, this.#tailCount); back >= 1; back--) {
      const i = (this.#tailCount - back) % TAIL_KEPT;
      const slot = this.#tailSlot[i] ?? NaN;
      if (!(slot > this.#refSlot)) continue;
      const t = this.#tailUs[i] ?? NaN;
      const late = t - this.#refUs - (slot - this.#refSlot) * p;
      if (back <= TAIL_FRAMES && late < tailMin) tailMin = late;
      if (back > 1 && (this.#tailUs[(i + 1) % TAIL_KEPT] ?? NaN) - t > p / 2) vouched = late;
    }
    // Until windows have measured the delivery jitter, the adapter may have held the last frames
    // as long as a delivery burst proved it holds one.
    const jitter = Number.isFinite(this.jitterUs) ? this.jitterUs : this.#heldUs;
    const beyondJitter = Number.isFinite(tailMin) ? Math.round((tailMin - jitter) / p) : 0;
    // Against the later of the reference and the schedule before it (a window's rounding may have
    // counted a frame for the reference's lateness), and only on a schedule a window has
    // confirmed: frames timed against a period just taken up may be another's.
    const byVouched = Number.isFinite(this.#refLateUs) ? Math.floor((vouched + Math.min(0, this.#refLateUs) + VOUCHED_MARGIN_US) / p) : 0;
    const shown = Math.max(0, byVouched, beyondJitter);
    const gapFrom = this.#winGapFromUs;
    const gapTo = this.#winGapToUs;
    let n = this.#winFrames > 1 ? this.#close(missed, shown) : 0;
    // The rest are after the window's most punctual frame: in its largest gap.
    const after = shown - n;
    if (after > 0) missed(Number.isFinite(gapFrom) ? gapFrom + p : this.#lastUs, Number.isFinite(gapTo) ? gapTo : this.#lastUs, after);
    n += after;
    const silence = endUs - this.#lastUs;
    if (silence > graceUs) {
      const k = Math.max(0, Math.floor((silence - graceUs) / p));
      if (k > 0) missed(this.#lastUs + p, endUs, k);
      n += k;
    }
    return n;
  }
}
