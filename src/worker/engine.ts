/**
 * The decode pipeline every source feeds (serial, demo, replay): the library's decoder and link
 * monitor, the latest value of each channel, and 100 ms graph buckets. `batch()` hands the page
 * what changed since the last call.
 */
import {
  CHANNEL_COUNT, LinkMonitor, SpektrumDecoder, type LinkEpisode,
} from '../decoder/index.js';
import { InspectorLog } from './inspector.js';
import { BUCKET_US, type Batch } from './protocol.js';

export interface EngineOptions {
  resolution: 'auto' | 1024 | 2048;
  /** How late chunk times may be from USB batching (see LinkMonitor). */
  jitterUs: number;
}

/** A growable set of columns for completed buckets. */
class Series {
  t: number[] = [];
  fadeRate: number[] = [];
  rssi: number[] = [];
  periodMs: number[] = [];
  lost: number[] = [];
  take(): Batch['series'] {
    const out = {
      t: Float64Array.from(this.t), fadeRate: Float32Array.from(this.fadeRate), rssi: Float32Array.from(this.rssi),
      periodMs: Float32Array.from(this.periodMs), lost: Float32Array.from(this.lost),
    };
    this.t = []; this.fadeRate = []; this.rssi = []; this.periodMs = []; this.lost = [];
    return out;
  }
}

export class Engine {
  readonly decoder: SpektrumDecoder;
  /** The recent frames, discards and resyncs with their bytes, for the frame inspector. */
  readonly inspector = new InspectorLog();
  readonly link: LinkMonitor;
  readonly #positions = new Uint16Array(CHANNEL_COUNT);
  readonly #seenUs = new Float64Array(CHANNEL_COUNT).fill(NaN);
  #frames = 0;
  #arrivedMs = 0;
  #changed = false;
  // The open bucket.
  #bucketStart = NaN;
  #bFades = 0;
  #bRssiSum = 0;
  #bRssiN = 0;
  #bIntervalSum = 0;
  #bIntervalN = 0;
  #bFrames = 0;
  /** Frames missing by the clock (the link monitor's count) that arrived in this bucket. */
  #bLost = 0;
  /** Frames already shown as lost in the empty buckets of the current gap. */
  #gapLost = 0;
  #lastFrameUs = NaN;
  readonly #series = new Series();
  /** Episode ids up to which every episode has been reported as ended; and open ones reported. */
  #episodesDone = 0;
  #episodesOpenSent = new Set<number>();

  constructor(readonly options: EngineOptions) {
    this.decoder = new SpektrumDecoder({ resolution: options.resolution, onEvent: (e) => this.inspector.onEvent(e) });
    // A live view may run for days: keep the newest episodes (the page shows ten minutes).
    this.link = new LinkMonitor({ jitterUs: options.jitterUs, maxEpisodes: 1000 });
  }

  /** Bytes as they arrived: `timeUs` is the chunk's arrival (or per-byte times). */
  push(bytes: Uint8Array, time: number | Float64Array | undefined, arrivedMs: number): void {
    // The log first: the decoder's events (fired in next()) take their times from these chunks.
    this.inspector.onBytes(bytes, time);
    this.decoder.push(bytes, time);
    this.#arrivedMs = arrivedMs;
    this.#drain();
  }

  /** End of the source: decide the bytes still held. */
  end(): void {
    this.decoder.end();
    this.#drain();
  }

  #drain(): void {
    const d = this.decoder;
    this.#changed = true;
    for (let f = d.next(); f !== undefined; f = d.next()) {
      this.inspector.onFrame(f);
      const t = f.timeUs;
      if (Number.isFinite(t)) this.#closeBuckets(t);
      const missed = this.link.stats.missedFrames;
      this.link.frame(f);
      // A gap's frames were shown in its empty buckets already; the rest belong here.
      this.#bLost += Math.max(0, this.link.stats.missedFrames - missed - this.#gapLost);
      this.#gapLost = 0;
      this.#frames++;
      for (let i = 0; i < f.count; i++) {
        const id = f.ids[i] as number;
        this.#positions[id] = f.positions[i] as number;
        // Untimed data (a raw .bin) still marks the channel as seen, at an unknown time.
        this.#seenUs[id] = Number.isFinite(t) ? t : Infinity;
      }
      this.#bFades += f.fadesDelta;
      if (f.rssi !== null) {
        this.#bRssiSum += f.rssi;
        this.#bRssiN++;
      }
      // Frame spacing, without the gaps (those are lost frames, graphed on their own).
      const nominal = this.link.stats.nominalPeriodUs;
      const maxInterval = Number.isFinite(nominal) ? 1.5 * nominal + this.options.jitterUs : 5 * BUCKET_US;
      if (Number.isFinite(this.#lastFrameUs) && t > this.#lastFrameUs && t - this.#lastFrameUs < maxInterval) {
        this.#bIntervalSum += t - this.#lastFrameUs;
        this.#bIntervalN++;
      }
      this.#bFrames++;
      this.#lastFrameUs = t;
    }
  }

  /** Closes buckets that end at or before `t` (also the empty ones of a dropout). */
  #closeBuckets(t: number): void {
    const start = Math.floor(t / BUCKET_US) * BUCKET_US;
    if (Number.isNaN(this.#bucketStart)) {
      this.#bucketStart = start;
      return;
    }
    // A jump far ahead (a long pause in a replay) emits at most ten minutes of empty buckets.
    if (start - this.#bucketStart > 6000 * BUCKET_US) this.#bucketStart = start - 6000 * BUCKET_US;
    while (this.#bucketStart < start) {
      const s = this.#series;
      const period = this.link.stats.nominalPeriodUs;
      const expected = Number.isFinite(period) ? BUCKET_US / period : NaN;
      s.t.push(this.#bucketStart);
      s.fadeRate.push(this.#bFades / (BUCKET_US / 1e6));
      s.rssi.push(this.#bRssiN > 0 ? this.#bRssiSum / this.#bRssiN : NaN);
      s.periodMs.push(this.#bIntervalN > 0 ? this.#bIntervalSum / this.#bIntervalN / 1000 : NaN);
      // A bucket without a single frame is silence: all its frames were lost.
      let lost = this.#bLost;
      if (this.#bFrames === 0 && Number.isFinite(expected)) {
        lost = Math.round(expected);
        this.#gapLost += lost;
      }
      s.lost.push(lost);
      this.#bFades = this.#bRssiSum = this.#bRssiN = this.#bIntervalSum = this.#bIntervalN = this.#bFrames = this.#bLost = 0;
      this.#bucketStart += BUCKET_US;
      this.#changed = true;
    }
  }

  /**
   * What changed since the last call, at source time `nowUs` (advances the failsafe timer and
   * closes silent buckets), or null when nothing did. The typed arrays are fresh: transfer them.
   */
  batch(nowUs: number): { batch: Batch; transfer: ArrayBuffer[] } | null {
    const before = this.link.state;
    this.link.update(nowUs);
    if (this.link.state !== 'waiting' && this.link.state !== 'live') this.#closeBuckets(nowUs);
    const episodes = this.#newEpisodes();
    if (!this.#changed && before === this.link.state && episodes.length === 0) return null;
    this.#changed = false;
    const l = this.link.stats;
    const s = this.decoder.stats;
    const series = this.#series.take();
    const batch: Batch = {
      nowUs,
      arrivedMs: this.#arrivedMs,
      frames: this.#frames,
      positions: this.#positions.slice(),
      seenUs: this.#seenUs.slice(),
      resolution: this.decoder.format.resolution,
      link: {
        state: this.link.state, lastFrameUs: this.link.lastFrameUs, holds: l.holds, failsafes: l.failsafes,
        periodUs: l.periodUs, nominalPeriodUs: l.nominalPeriodUs, fades: l.fades, fadeRate: l.fadeRate,
        missedFrames: l.missedFrames, rssi: l.rssi,
      },
      counters: { bytes: s.bytes, frames: s.frames, resyncs: s.resyncs, discardedBytes: s.discardedBytes, badFrames: s.badFrames },
      series,
      episodes,
    };
    this.#frames = 0;
    return {
      batch,
      transfer: [batch.positions.buffer, batch.seenUs.buffer, series.t.buffer, series.fadeRate.buffer, series.rssi.buffer, series.periodMs.buffer, series.lost.buffer] as ArrayBuffer[],
    };
  }

  #newEpisodes(): Batch['episodes'] {
    const all: readonly LinkEpisode[] = this.link.episodes;
    const out: Batch['episodes'] = [];
    for (const e of all) {
      if (e.id < this.#episodesDone) continue;
      if (e.endUs !== null) {
        out.push({ id: e.id, kind: e.kind, startUs: e.startUs, endUs: e.endUs });
        this.#episodesOpenSent.delete(e.id);
        if (e.id === this.#episodesDone) this.#episodesDone++;
      } else if (!this.#episodesOpenSent.has(e.id)) {
        out.push({ id: e.id, kind: e.kind, startUs: e.startUs, endUs: null });
        this.#episodesOpenSent.add(e.id);
      }
    }
    return out;
  }
}
