/**
 * A capture's chunks of one port, read from its columns by index (replay.ts plays them): where a
 * seek starts, what each chunk holds and when it arrived, recorded or on a paced clock.
 */
import { BYTE_TIME_US } from '../../decoder/spec.js';
import { captureTimesInOrder } from '../../capture/facts.js';
import { chunkFirstByteUs, type Capture } from '../../capture/model.js';
import { recordedStops, StopCursor } from '../../report/doctor-events.js';

/** One chunk's bytes with their times. */
export interface Chunk {
  bytes: Uint8Array;
  /** Per-byte times (logic-analyser captures): bytes are fed as their own times pass. */
  byteTimes: Float64Array | undefined;
  /** The chunk's arrival (its last byte), µs; NaN without timing. */
  atUs: number;
}

/**
 * The chunks of one port straight from the capture's columns: an hour of USB batches is 225 000
 * chunks, so they are read by index when fed, never turned into objects up front. The index is
 * the one array a port adds (4 bytes a chunk): the capture's `capturePortIndex`.
 */
export class PortChunks {
  readonly length: number;
  /** The capture's chunk number of each of this port's chunks. */
  readonly #index: Uint32Array;
  /** Next chunk to feed, and bytes of it already fed (per-byte-timed chunks go piece by piece). */
  next = 0;
  nextByte = 0;

  /** Without timing: this port's bytes up to the end of each chunk, for the paced clock. */
  readonly #bytesBefore: Float64Array | undefined;
  /** Whether the chunks' times never go back (as recorded): a seek then bisects for its chunk. */
  readonly #ordered: boolean;
  /** Whether the per-byte times inside each chunk never go back: a seek then bisects for its byte. */
  readonly #bytesOrdered: boolean;
  /** This port's recorded stops ("device lost"): each told once since the cursor was last put. */
  readonly #stops: StopCursor;

  /**
   * @param index the capture's chunk number of each of this port's chunks, in order (`capturePortIndex`)
   * @param usPerByte without timing, the pace bytes are played at (µs a byte); NaN with timing
   */
  constructor(
    readonly capture: Capture,
    readonly port: number,
    index: Uint32Array,
    readonly usPerByte: number,
  ) {
    const n = index.length;
    this.#index = index;
    this.length = n;
    const { chunkEnds, chunkTimesUs, byteTimesUs: times } = capture;
    if (Number.isFinite(usPerByte)) {
      const before = new Float64Array(n);
      let total = 0;
      for (let k = 0; k < n; k++) {
        const i = index[k] ?? 0;
        total += (chunkEnds[i] ?? 0) - (i === 0 ? 0 : (chunkEnds[i - 1] ?? 0));
        before[k] = total;
      }
      this.#bytesBefore = before;
    }
    let ordered = true;
    if (this.#bytesBefore === undefined && times === undefined) {
      // Chunk times: in order for the capture (one pass for all ports), in order for each port; else
      // this port's are checked, read straight from the column (a day's capture has eleven million).
      if (!captureTimesInOrder(capture))
        for (let k = 1; k < n && ordered; k++)
          ordered = (chunkTimesUs[index[k] ?? 0] ?? Number.NaN) >= (chunkTimesUs[index[k - 1] ?? 0] ?? Number.NaN);
    } else {
      for (let k = 1; k < n && ordered; k++) ordered = this.atUs(k) >= this.atUs(k - 1);
    }
    this.#ordered = ordered;
    let bytesOrdered = true;
    for (let k = 0; k < n && times !== undefined && bytesOrdered; k++) {
      const i = this.#chunk(k);
      for (let j = this.#start(i) + 1; j < this.#end(i) && bytesOrdered; j++)
        bytesOrdered = (times[j] ?? Number.NaN) >= (times[j - 1] ?? Number.NaN);
    }
    this.#bytesOrdered = bytesOrdered;
    this.#stops = new StopCursor(recordedStops(capture).filter((e) => e.port === port));
  }

  /**
   * The time of this port's next recorded stop before its chunk k (all that are left: k =
   * length) and, with `untilUs`, at or before that time, taken; undefined when none. A seek
   * tells again those from its first chunk on.
   */
  takeStop(k: number, untilUs?: number): number | undefined {
    return this.#stops.take(k < this.length ? this.#chunk(k) : Number.POSITIVE_INFINITY, untilUs)?.timeUs;
  }

  /** The stops not told yet are those from the cursor's chunk on. */
  #seekStops(): void {
    this.#stops.seek(this.done ? Number.POSITIVE_INFINITY : this.#chunk(this.next));
  }

  /** The capture's chunk number of this port's chunk k. */
  #chunk(k: number): number {
    return this.#index[k] ?? 0;
  }

  /** Where the capture's chunk i starts and ends in its bytes. */
  #start(i: number): number {
    return i === 0 ? 0 : (this.capture.chunkEnds[i - 1] ?? 0);
  }

  #end(i: number): number {
    return this.capture.chunkEnds[i] ?? 0;
  }

  /** Arrival time of chunk k (µs): recorded, or on the paced clock without timing. */
  atUs(k: number): number {
    if (this.#bytesBefore !== undefined) return (this.#bytesBefore[k] ?? Number.NaN) * this.usPerByte;
    const i = this.#chunk(k);
    const times = this.capture.byteTimesUs;
    if (times !== undefined) return times[this.#end(i) - 1] ?? Number.NaN;
    return this.capture.chunkTimesUs[i] ?? Number.NaN;
  }

  /**
   * The first chunk that arrives at or after `timeUs` (`length` when none does), as a walk from
   * the first chunk finds it; found by bisection when the times never go back.
   */
  firstAtOrAfter(timeUs: number): number {
    if (!this.#ordered) {
      let k = 0;
      while (k < this.length && this.atUs(k) < timeUs) k++;
      return k;
    }
    let lo = 0;
    let hi = this.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (this.atUs(mid) < timeUs) lo = mid + 1;
      else hi = mid;
    }
    return lo;
  }

  /**
   * Puts the cursor on the first byte a walk from the start finds at or after `fromUs`: the
   * first chunk that arrives then and, in a chunk with per-byte times (a logic analyser's one
   * chunk per port), its first byte timed then, so that a seek in a long one feeds only its
   * history, not everything before it.
   */
  seekTo(fromUs: number): void {
    this.next = this.firstAtOrAfter(fromUs);
    this.nextByte = 0;
    this.#seekStops();
    const times = this.capture.byteTimesUs;
    if (times === undefined || this.done) return;
    const i = this.#chunk(this.next);
    const start = this.#start(i);
    const end = this.#end(i);
    let lo = start;
    if (this.#bytesOrdered) {
      let hi = end;
      while (lo < hi) {
        const mid = (lo + hi) >>> 1;
        if ((times[mid] ?? Number.NaN) < fromUs) lo = mid + 1;
        else hi = mid;
      }
    } else {
      while (lo < end && (times[lo] ?? Number.NaN) < fromUs) lo++;
    }
    this.nextByte = lo - start;
  }

  /** Puts the cursor on this port's first chunk at or after the capture's chunk `i` (a checkpoint's). */
  seekToChunk(i: number): void {
    const index = this.#index;
    let lo = 0;
    let hi = this.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if ((index[mid] ?? 0) < i) lo = mid + 1;
      else hi = mid;
    }
    this.next = lo;
    this.nextByte = 0;
    this.#seekStops();
  }

  get(k: number): Chunk {
    const i = this.#chunk(k);
    const c = this.capture;
    const start = this.#start(i);
    const end = this.#end(i);
    return { bytes: c.bytes.subarray(start, end), byteTimes: c.byteTimesUs?.subarray(start, end), atUs: this.atUs(k) };
  }

  /** Without timing: the port's bytes before chunk k. */
  bytesBeforeChunk(k: number): number {
    return k === 0 || this.#bytesBefore === undefined ? 0 : (this.#bytesBefore[k - 1] ?? 0);
  }

  /** Whether chunk k's bytes are decoded with times (recorded ones); not on the paced clock. */
  get timed(): boolean {
    return this.#bytesBefore === undefined;
  }

  get done(): boolean {
    return this.next >= this.length;
  }

  /**
   * The earliest time a byte not fed yet can carry, µs (Infinity when all are fed): its own
   * time, or for a chunk-timed chunk, the chunk's arrival less its bytes at line rate, which
   * is as early as the decoder dates a frame in it.
   */
  nextByteUs(): number {
    if (this.done) return Number.POSITIVE_INFINITY;
    const i = this.#chunk(this.next);
    const c = this.capture;
    const start = this.#start(i);
    if (c.byteTimesUs !== undefined) return c.byteTimesUs[start + this.nextByte] ?? Number.POSITIVE_INFINITY;
    if (!this.timed) return (this.bytesBeforeChunk(this.next) + this.nextByte + 1) * this.usPerByte;
    return chunkFirstByteUs(this.atUs(this.next), this.#end(i) - start, BYTE_TIME_US);
  }
}
