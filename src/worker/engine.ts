/**
 * The decode pipeline every source feeds (serial, demo, replay): the library's decoder, link
 * monitor and binned series (the same ones `satscope report` uses), the latest value of each
 * channel, and 100 ms graph buckets. `batch()` hands the page what changed since the last call.
 * Time is always passed in: the arrival clock live, the capture's own clock in replay.
 */
import { CHANNEL_COUNT, type Resolution } from '../decoder/spec.js';
import type { LinkEpisode } from '../decoder/episode.js';
import { LinkMonitor } from '../decoder/link.js';
import { SpektrumDecoder } from '../decoder/decoder.js';
import type { DecodedFrame } from '../decoder/types.js';
import type { DecoderCheckpoint, LinkCheckpoint } from '../decoder/checkpoint.js';
import { LinkSeries } from '../report/series.js';
import { ChannelRanges } from '../report/summary.js';
import { InspectorLog } from './inspector.js';
import { TraceLog } from './traces.js';
import { BUCKET_US, type Batch } from './protocol.js';

export interface EngineOptions {
  resolution: 'auto' | 1024 | 2048;
  /** The delivery jitter to assume until it is measured (see LinkMonitor's `jitterUs`). */
  jitterUs: number;
}

/**
 * How far back frames found missing may still be placed in the graph buckets, µs: the link
 * monitor confirms frames missing by count over windows (`LEDGER_WINDOW_US`), so a bucket is
 * handed to the page only once it is this old. Missing frames due earlier go into the oldest
 * bucket not yet handed out. Placing them by the time they were reported, never by when the
 * page asked, keeps replay identical at every speed.
 */
export const SETTLE_US = 500_000;

/** Pushes remembered to date the bytes the decoder still holds. */

/** What an engine hands a listener (the doctor): each chunk as it arrives, each frame after the link monitor counted it. */
export interface EngineTap {
  bytes(bytes: Uint8Array, time: number | Float64Array | undefined): void;
  frame(f: DecodedFrame): void;
}

export class Engine {
  readonly decoder: SpektrumDecoder;
  /** The recent frames, discards and resyncs with their bytes, for the frame inspector. */
  readonly inspector = new InspectorLog();
  /** The doctor's feed (diagnosis.ts): every chunk, and every frame after the link counted it. */
  tap: EngineTap | null = null;
  readonly link: LinkMonitor;
  readonly series = new LinkSeries(BUCKET_US);
  /** Every frame's channel values and the glitches found, for the page's channel traces. */
  readonly traces = new TraceLog();
  /** Each channel's frames and lowest, highest and last pulse width, as `satscope info` counts them. */
  #ranges = new ChannelRanges();
  /** Where the ranges start: NaN from the stream's start, else the checkpoint a seek restored. */
  #rangesSinceUs = Number.NaN;
  readonly #positions = new Uint16Array(CHANNEL_COUNT);
  readonly #seenUs = new Float64Array(CHANNEL_COUNT).fill(NaN);
  #frames = 0;
  #arrivedMs = 0;
  #changed = false;
  /** Time of the frame (or end) being handled, for placing missing frames. */
  #currentUs = NaN;
  /** The next bucket to hand out. */
  #nextBin = 0;
  /** `end()` was called; the end of the stream, when known (replay): the clock never goes past it. */
  #ended = false;
  #endUs = NaN;
  /** Each episode as last sent to the page. */
  readonly #sent = new Map<number, { startUs: number; endUs: number | null }>();
  /** While a forced resolution matches no frame: the resolution the stream looks like. */
  #mismatch: Resolution | null = null;

  constructor(readonly options: EngineOptions) {
    this.decoder = new SpektrumDecoder({ resolution: options.resolution, onEvent: (e) => this.inspector.onEvent(e) });
    // A live view may run for days: keep the newest episodes (the page shows ten minutes).
    this.link = new LinkMonitor({
      jitterUs: options.jitterUs,
      maxEpisodes: 1000,
      // Missing frames due before the settled buckets go into the oldest one still open.
      onMissed: (from, to, n, p) => {
        const floor = this.#currentUs - SETTLE_US;
        this.series.missed(Math.max(from, floor), Math.max(to, floor), n, p);
      },
    });
  }

  /** Bytes as they arrived: `time` is the chunk's arrival (or per-byte times). */
  push(bytes: Uint8Array, time: number | Float64Array | undefined, arrivedMs: number): void {
    this.tap?.bytes(bytes, time);
    this.decoder.push(bytes, time);
    this.#arrivedMs = arrivedMs;
    this.#drain();
  }

  /**
   * A fresh engine starts where a checkpoint of this source's decode was taken (a replay's
   * seek): the counters, lock, format, episodes and link state are the stream's up to there;
   * the graph buckets, channels and inspector fill from the bytes fed after it.
   */
  restore(decoder: DecoderCheckpoint, link: LinkCheckpoint): void {
    this.decoder.restore(decoder);
    this.link.restore(link);
    this.#ranges = new ChannelRanges();
    this.#rangesSinceUs = this.link.lastFrameUs;
    // Frames found missing from here on are placed from the checkpoint's last frame.
    this.#currentUs = this.link.lastFrameUs;
    this.#changed = true;
  }

  /**
   * End of the source at `endUs` (the capture's last recorded time; NaN when unknown): decide
   * the bytes still held, and judge the link there. The state then stays as it was at the end.
   */
  end(endUs = NaN): void {
    this.decoder.end();
    this.#drain();
    this.#ended = true;
    this.#endUs = endUs;
    this.#currentUs = Number.isFinite(endUs) ? endUs : this.#currentUs;
    if (this.#mismatch === null) this.link.finish(endUs);
    this.#changed = true;
  }

  /**
   * The source stopped sending at `atUs` for a reason that is not the link (its port was lost,
   * the demo's simulation paused over a stall, a recorded "device lost"): `LinkMonitor.stopped`.
   */
  interrupt(atUs: number): void {
    this.link.stopped(atUs);
    this.#changed = true;
  }

  /**
   * Forces (or frees) the resolution at source time `nowUs`. The frames may stop until the
   * decoder finds them again: that is the user's doing, not the link's, so the link monitor
   * counts nothing for the time in between (no hold, failsafe or missed frame).
   */
  setResolution(resolution: 'auto' | 1024 | 2048, nowUs: number, by: 'user' | 'internal-remote' = 'user'): void {
    const locked = this.decoder.format.locked;
    this.decoder.setResolution(resolution, by);
    // A decoder that stays locked reads the same frames on: nothing paused, nothing to leave uncounted.
    if (!locked || !this.decoder.format.locked) this.link.interrupt(nowUs);
    this.#mismatch = null;
    this.#changed = true;
  }

  /**
   * The resolution the stream looks like while a forced one matches no frame (e.g. 2048 when
   * 1024 was forced on a 2048 stream), else null.
   */
  get mismatch(): Resolution | null {
    return this.#mismatch;
  }

  #checkMismatch(): void {
    // Only a forced resolution can match no frame (and the decoder's format is made afresh on each read).
    if (this.decoder.resolutionSetting === 'auto' && this.#mismatch === null) return;
    // The decoder's word: the forced resolution fits no frame, the other one does.
    const mismatch = this.decoder.format.forcedMismatch;
    if (mismatch !== this.#mismatch) {
      this.#mismatch = mismatch;
      this.#changed = true;
    }
  }

  #drain(): void {
    const d = this.decoder;
    this.#changed = true;
    for (let f = d.next(); f !== undefined; f = d.next()) {
      this.inspector.onFrame(f);
      const t = f.timeUs;
      this.#currentUs = t;
      this.link.frame(f);
      this.series.frame(f, this.link);
      this.traces.frame(f, this.link.holdAfterUs);
      this.#ranges.frame(f);
      this.#frames++;
      this.tap?.frame(f);
      for (let i = 0; i < f.count; i++) {
        const id = f.ids[i];
        const position = f.positions[i];
        if (id === undefined || position === undefined) break;
        this.#positions[id] = position;
        // Untimed data (a raw .bin) still marks the channel as seen, at an unknown time.
        this.#seenUs[id] = Number.isFinite(t) ? t : Infinity;
      }
    }
    this.#checkMismatch();
  }

  /**
   * The buckets not handed out yet, up to the one holding `untilUs`: first those that have
   * settled (final), then the open ones as counted so far (provisional: the page shows them and
   * replaces them with the next batch's), so the graphs hold every fade and missed frame the
   * counters do.
   */
  #takeSeries(untilUs: number): Batch['series'] {
    const s = this.series;
    let last = Number.isFinite(untilUs) && !Number.isNaN(s.originUs) ? s.binOf(untilUs - SETTLE_US) : -1;
    // At the end of a replay everything has settled.
    if (this.#ended && Number.isFinite(this.#endUs) && !Number.isNaN(s.originUs)) last = s.binOf(this.#endUs) + 1;
    s.extendTo(untilUs);
    last = Math.min(last, s.bins);
    const from = this.#nextBin;
    const settled = Math.max(0, last - from);
    const n = Math.max(settled, s.bins - from);
    const out = {
      settled,
      t: new Float64Array(n),
      fadeRate: new Float32Array(n),
      rssi: new Float32Array(n),
      periodMs: new Float32Array(n),
      lost: new Float32Array(n),
    };
    for (let k = 0; k < n; k++) {
      const b = from + k;
      out.t[k] = s.startOf(b);
      out.fadeRate[k] = s.fades(b) / (BUCKET_US / 1e6);
      out.rssi[k] = s.rssiMean(b);
      const iv = s.intervalMean(b);
      out.periodMs[k] = iv / 1000;
      out.lost[k] = s.lost(b);
    }
    this.#nextBin = from + settled;
    return out;
  }

  /**
   * What changed since the last call, at source time `nowUs` (advances the failsafe timer and
   * closes silent buckets), or null when nothing did. After `end()`, and while a forced
   * resolution matches no frame, the link's state stands still. The typed arrays are fresh:
   * transfer them.
   */
  batch(nowUs: number): { batch: Batch; transfer: ArrayBuffer[] } | null {
    const before = this.link.state;
    const ended = this.#ended;
    const now = ended && Number.isFinite(this.#endUs) ? this.#endUs : nowUs;
    if (!ended && this.#mismatch === null) this.link.update(now, this.decoder.pendingSinceUs);
    const episodes = this.#newEpisodes();
    // Only those the page was shown (a hold may open and be withdrawn between two batches).
    const retracted = this.link.takeRetracted().filter((id) => this.#sent.delete(id));
    const series = this.#takeSeries(now);
    if (!this.#changed && before === this.link.state && episodes.length === 0 && retracted.length === 0 && series.settled === 0)
      return null;
    this.#changed = false;
    const l = this.link.stats;
    const s = this.decoder.stats;
    const batch: Batch = {
      nowUs: now,
      arrivedMs: this.#arrivedMs,
      frames: this.#frames,
      positions: this.#positions.slice(),
      seenUs: this.#seenUs.slice(),
      resolution: this.decoder.format.resolution,
      link: {
        state: this.link.state,
        lastFrameUs: this.link.lastFrameUs,
        holds: l.holds,
        failsafes: l.failsafes,
        periodUs: l.periodUs,
        nominalPeriodUs: l.nominalPeriodUs,
        fades: l.fades,
        fadeRate: l.fadeRate,
        missedFrames: l.missedFrames,
        missedBasis: l.missedBasis,
        rssi: l.rssi,
        deliveryDelayUs: l.deliveryDelayUs,
        deliveryJitterUs: l.deliveryJitterUs,
      },
      mismatch: this.#mismatch,
      ended,
      counters: {
        bytes: s.bytes,
        frames: s.frames,
        resyncs: s.resyncs,
        discardedBytes: s.discardedBytes,
        badFrames: s.badFrames,
        emptySlots: s.emptySlots,
        vtxFrames: s.vtxFrames,
      },
      series,
      episodes,
      retracted,
      traces: this.traces.take(),
      channels: {
        frames: this.#ranges.frames.slice(),
        minUs: this.#ranges.min.slice(),
        maxUs: this.#ranges.max.slice(),
        lastUs: this.#ranges.last.slice(),
        sinceUs: this.#rangesSinceUs,
      },
    };
    this.#frames = 0;
    const c = batch.channels;
    return {
      batch,
      transfer: [
        c.frames.buffer,
        c.minUs.buffer,
        c.maxUs.buffer,
        c.lastUs.buffer,
        batch.positions.buffer,
        batch.seenUs.buffer,
        series.t.buffer,
        series.fadeRate.buffer,
        series.rssi.buffer,
        series.periodMs.buffer,
        series.lost.buffer,
        ...TraceLog.transfer(batch.traces),
      ] as ArrayBuffer[],
    };
  }

  /**
   * Episodes new or changed (ended, or re-dated) since they were last sent. Episodes are made
   * in order and only the newest change, so the walk stops at the first one sent as it is.
   */
  #newEpisodes(): Batch['episodes'] {
    const all: readonly LinkEpisode[] = this.link.episodes;
    const out: Batch['episodes'] = [];
    for (let i = all.length - 1; i >= 0; i--) {
      const e = all[i];
      if (e === undefined) break;
      const sent = this.#sent.get(e.id);
      if (sent !== undefined && sent.endUs === e.endUs && sent.startUs === e.startUs) {
        if (e.endUs !== null) break;
        continue;
      }
      this.#sent.set(e.id, { startUs: e.startUs, endUs: e.endUs });
      out.push({ id: e.id, kind: e.kind, startUs: e.startUs, endUs: e.endUs });
    }
    // Forget what the link no longer keeps.
    const oldest = all[0]?.id ?? Infinity;
    if (this.#sent.size > 2 * all.length + 16) for (const id of this.#sent.keys()) if (id < oldest) this.#sent.delete(id);
    return out.reverse();
  }
}
