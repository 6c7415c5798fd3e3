/**
 * The channel traces' data on the worker's side: every frame's channel values in µs (the values
 * the frame carried; NaN for a channel it did not), its time, whether a silence the link monitor
 * would call a hold came before it, and the glitches the library's one rule (`SpikeFinder`) finds,
 * gathered between two batches and handed over as typed arrays with the batch. At most
 * MAX_TRACE_ROWS frames wait: what the page keeps at most; older ones, never shown, are dropped.
 */
import { SpikeFinder } from '../report/spikes.js';
import { CHANNEL_COUNT, channelResolution, servoToMicros } from '../decoder/spec.js';
import type { DecodedFrame } from '../decoder/types.js';
import type { TraceBatch } from './protocol.js';

/** Frames the page keeps per remote for the traces (ten minutes at 11 ms is 54 546). */
export const MAX_TRACE_ROWS = 65_536;
/** Glitches kept between two batches (a stream of nothing but glitches must not pile them up). */
const MAX_SPIKES = 4096;

export class TraceLog {
  readonly #spikes = new SpikeFinder();
  #t = new Float64Array(256);
  #us = new Float32Array(256 * CHANNEL_COUNT);
  #gap = new Uint8Array(256);
  #rows = 0;
  /** The last frame's time (of any batch), for the silences. */
  #lastUs = Number.NaN;
  /** Rows were dropped before the first one waiting: the page must not join across them. */
  #dropped = false;
  #spikeT: number[] = [];
  #spikeChannel: number[] = [];
  #spikeUs: number[] = [];

  /**
   * One frame, after the link monitor counted it: `holdAfterUs` is the silence after which the
   * link monitor calls a hold (a trace does not join across one).
   */
  frame(f: DecodedFrame, holdAfterUs: number): void {
    const t = f.timeUs;
    this.#spikes.frame(f, (s) => {
      if (!Number.isFinite(s.timeUs)) return;
      if (this.#spikeT.length === MAX_SPIKES) return;
      this.#spikeT.push(s.timeUs);
      this.#spikeChannel.push(s.channel);
      this.#spikeUs.push(s.spikeUs);
    });
    // Without a time a frame has no place on a time axis.
    if (!Number.isFinite(t)) return;
    const gap = !(t - this.#lastUs <= holdAfterUs);
    this.#lastUs = t;
    const r = this.#room();
    this.#t[r] = t;
    this.#gap[r] = gap ? 1 : 0;
    const row = this.#us.subarray(r * CHANNEL_COUNT, (r + 1) * CHANNEL_COUNT);
    row.fill(Number.NaN);
    for (let i = 0; i < f.count; i++) {
      const id = f.ids[i];
      const pos = f.positions[i];
      if (id === undefined || pos === undefined) break;
      row[id] = servoToMicros(pos, channelResolution(id, f.resolution));
    }
  }

  /** The index of a new row: the arrays grow to MAX_TRACE_ROWS, then the oldest half is dropped. */
  #room(): number {
    if (this.#rows === this.#t.length) {
      if (this.#rows < MAX_TRACE_ROWS) {
        const t = new Float64Array(this.#rows * 2);
        const us = new Float32Array(this.#rows * 2 * CHANNEL_COUNT);
        const gap = new Uint8Array(this.#rows * 2);
        t.set(this.#t);
        us.set(this.#us);
        gap.set(this.#gap);
        this.#t = t;
        this.#us = us;
        this.#gap = gap;
      } else {
        const keep = this.#rows >> 1;
        const from = this.#rows - keep;
        this.#t.copyWithin(0, from, this.#rows);
        this.#us.copyWithin(0, from * CHANNEL_COUNT, this.#rows * CHANNEL_COUNT);
        this.#gap.copyWithin(0, from, this.#rows);
        this.#rows = keep;
        this.#dropped = true;
      }
    }
    return this.#rows++;
  }

  /** What came since the last call, in fresh arrays to transfer. */
  take(): TraceBatch {
    const n = this.#rows;
    const out: TraceBatch = {
      t: this.#t.slice(0, n),
      us: this.#us.slice(0, n * CHANNEL_COUNT),
      gap: this.#gap.slice(0, n),
      spikes: {
        t: Float64Array.from(this.#spikeT),
        channel: Uint8Array.from(this.#spikeChannel),
        us: Float32Array.from(this.#spikeUs),
      },
    };
    if (this.#dropped && n > 0) out.gap[0] = 1;
    this.#rows = 0;
    this.#dropped = false;
    this.#spikeT = [];
    this.#spikeChannel = [];
    this.#spikeUs = [];
    return out;
  }

  /** The arrays of a `take()`, to transfer. */
  static transfer(t: TraceBatch): ArrayBuffer[] {
    return [t.t.buffer, t.us.buffer, t.gap.buffer, t.spikes.t.buffer, t.spikes.channel.buffer, t.spikes.us.buffer] as ArrayBuffer[];
  }
}
