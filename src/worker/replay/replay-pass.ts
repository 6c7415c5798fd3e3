/**
 * The one decode of a whole capture a replay makes when it opens (captures with recorded chunk
 * times): every port's decoder, link monitor and 1 s link series (the report's), fed the chunks
 * in the capture's order a slice at a time, so that the page draws the overview as it grows and
 * stays responsive. On the way it keeps a checkpoint of every port's decoder and link monitor
 * each CHECKPOINT_US of capture time: a seek restores the nearest one and feeds only from there,
 * with the counters, episodes and link state of the whole capture up to the target.
 */
import type { DecoderCheckpoint, LinkCheckpoint } from '../../decoder/checkpoint.js';
import type { LinkMonitor } from '../../decoder/link.js';
import { SpektrumDecoder } from '../../decoder/decoder.js';
import type { Capture } from '../../capture/model.js';
import { recordTimeUs } from '../../capture/record-walk.js';
import { LinkSeries, monitorWithSeries } from '../../report/series.js';
import { timingJitterUs } from '../../report/capture-pass.js';
import { recordedStops, StopCursor } from '../../report/doctor-events.js';
import { failsafeAsRead, failsafesOf, overviewBinUs, sumOverview } from './overview.js';
import type { Overview } from '../protocol.js';

/** Capture time between two checkpoints: 1440 of them a day, each a few kilobytes a port. */
export const CHECKPOINT_US = 60e6;

/**
 * The rule for where checkpoints fall: a chunk arriving at `atUs` at or past `nextUs` gets one
 * before it, and the next is due a whole interval on, however long the silence before it.
 * Returns the next due time (`nextUs` itself when this chunk gets none).
 */
export function checkpointDue(nextUs: number, atUs: number): number {
  let next = nextUs;
  while (next <= atUs) next += CHECKPOINT_US;
  return next;
}

/**
 * How far behind the slowest port's last frame the overview is drawn while the pass runs: frames
 * found missing are confirmed over ledger windows (0.5 s) and placed where they were due.
 */
const SETTLE_US = 2_000_000;

interface PortPass {
  port: number;
  decoder: SpektrumDecoder;
  link: LinkMonitor;
  series: LinkSeries;
}

/** Every port's decode state before the capture's chunk `chunk` (all chunks before it fed). */
export interface Checkpoint {
  chunk: number;
  /** The latest arrival among the chunks fed, µs: a seek to a target at or after it may start here. */
  fedUntilUs: number;
  ports: Map<number, { decoder: DecoderCheckpoint; link: LinkCheckpoint }>;
}

/** What the replay asks of its capture's decode, made here or split with a helper (replay-split.ts). */
export interface OverviewPass {
  readonly resolution: 'auto' | 1024 | 2048;
  readonly done: boolean;
  /** Nothing to decode here until a helper reports (it wakes the replay then). */
  readonly waiting: boolean;
  /** Decodes for about `budgetMs`; whether the pass is done. */
  step(budgetMs: number, now: () => number): boolean;
  overview(): Overview;
  checkpointFor(targetUs: number, historyUs: number): Checkpoint | undefined;
  /** The pass is dropped (the replay closed): anything it runs elsewhere stops. */
  stop(): void;
}

export class ReplayPass implements OverviewPass {
  readonly checkpoints: Checkpoint[] = [];
  /**
   * The capture decoded; while `#prefix`, only the first records of the file (replay-preview.ts);
   * null: a file's records fed one by one as it is read (`feed`, replay-file-pass.ts).
   */
  #capture: Capture | null;
  #prefix: boolean;
  readonly #ports: PortPass[];
  /** The overview's bin width (overviewBinUs: a short capture's are narrow). */
  readonly #binUs: number;
  /** Each port's decode by port number (0–255), undefined for the ports not decoded here. */
  readonly #byPort: (PortPass | undefined)[] = [];
  /** The next chunk of the capture to feed (the count fed so far). */
  #chunk = 0;
  #fedUntilUs = Number.NEGATIVE_INFINITY;
  /** The time of the chunk being fed (`#feed`). */
  readonly #at = new Float64Array(1);
  #nextCheckpointUs: number;
  #done = false;
  /** The capture's recorded stops ("device lost"), each told to its port's link before the chunk after it. */
  #stops: StopCursor;

  /**
   * @param originUs, endUs the capture's span (`captureSpan`): bin 0 starts at the first, the links are judged at the last
   * @param prefix `capture` is the file's first records only: decoding stops at its end, and
   *   goes on once `continueWith` is given the whole capture
   * @param capture null: the chunks come through `feed` (records of a file with chunk times)
   */
  constructor(
    capture: Capture | null,
    readonly ports: readonly number[],
    readonly resolution: 'auto' | 1024 | 2048,
    readonly originUs: number,
    readonly endUs: number,
    prefix = false,
  ) {
    this.#capture = capture;
    this.#prefix = prefix;
    this.#stops = new StopCursor(capture === null ? [] : recordedStops(capture));
    this.#binUs = overviewBinUs(endUs - originUs);
    this.#ports = ports.map((port) => {
      const series = new LinkSeries(this.#binUs, originUs);
      return {
        port,
        decoder: new SpektrumDecoder({ resolution }),
        link: monitorWithSeries({ jitterUs: timingJitterUs(capture?.timing ?? 'per-chunk') }, series),
        series,
      };
    });
    for (const p of this.#ports) this.#byPort[p.port] = p;
    this.#nextCheckpointUs = originUs + CHECKPOINT_US;
  }

  get done(): boolean {
    return this.#done;
  }

  /** Everything is decoded here. */
  readonly waiting = false;

  /** Nothing runs elsewhere: nothing to stop. */
  stop(): void {}

  /**
   * A pass begun on the file's first records goes on with the whole capture, when that starts
   * with every chunk decoded so far (the same ends, times and ports), on the same ports and span;
   * false (and nothing changed) otherwise.
   */
  continueWith(capture: Capture, ports: readonly number[], originUs: number, endUs: number): boolean {
    const head = this.#capture;
    const n = this.#chunk;
    if (head === null || !this.#prefix || originUs !== this.originUs || endUs !== this.endUs || capture.chunkEnds.length < n) return false;
    if (ports.length !== this.ports.length || ports.some((p, k) => p !== this.ports[k])) return false;
    for (let i = 0; i < n; i++) {
      if (
        capture.chunkEnds[i] !== head.chunkEnds[i] ||
        capture.chunkTimesUs[i] !== head.chunkTimesUs[i] ||
        capture.chunkPorts[i] !== head.chunkPorts[i]
      )
        return false;
    }
    this.#capture = capture;
    this.#prefix = false;
    // The stops before chunk n were told from the head, which holds the same chunks.
    this.#stops = new StopCursor(recordedStops(capture));
    this.#stops.seek(n);
    return true;
  }

  /**
   * Feeds chunks for about `budgetMs` of `now()`'s time (at least one), the end of the stream
   * once they are all in. Returns whether the pass is done.
   */
  step(budgetMs: number, now: () => number): boolean {
    if (this.#done) return true;
    const capture = this.#capture;
    if (capture === null) throw new Error('a pass fed records is stepped by feed(), not step()');
    const started = now();
    const { bytes, chunkEnds, chunkTimesUs, chunkPorts } = capture;
    const n = chunkEnds.length;
    let i = this.#chunk;
    while (i < n) {
      this.#stopsBefore(i);
      // A range of the capture's bytes, not a view of them: a view a chunk is most of a chunk's cost.
      this.feed(bytes, i === 0 ? 0 : (chunkEnds[i - 1] ?? 0), chunkEnds[i] ?? 0, chunkTimesUs[i] ?? Number.NaN, chunkPorts[i] ?? -1);
      i++;
      // The clock is read every 256 chunks: reading it costs more than a chunk.
      if ((i & 0xff) === 0 && now() - started >= budgetMs) break;
    }
    // A prefix's end is not the capture's: the rest comes with continueWith.
    if (i < n || this.#prefix) return false;
    this.finish();
    return true;
  }

  /**
   * Feeds the next chunk: `bytes[start, end)` arrived on `port` at `atUs` (a port not decoded
   * here only moves the checkpoints' clock, as in the capture's order it does).
   */
  feed(bytes: Uint8Array, start: number, end: number, atUs: number, port: number): void {
    this.#at[0] = atUs;
    this.#feed(bytes, start, end, port);
  }

  /** `feed()` of a data record of a file as it is walked (a RecordSink): its time is read from `view` here. */
  feedRecord(bytes: Uint8Array, view: DataView, start: number, end: number, port: number): void {
    this.#at[0] = recordTimeUs(view, start);
    this.#feed(bytes, start, end, port);
  }

  /**
   * `feed()` at #at[0]. The time goes on in a typed-array slot, not as an argument: a double
   * handed to a call that is not inlined is boxed (an allocation a chunk).
   */
  #feed(bytes: Uint8Array, start: number, end: number, port: number): void {
    const atUs = this.#at[0] ?? Number.NaN;
    if (atUs >= this.#nextCheckpointUs) this.#checkpoint(this.#chunk, atUs);
    const p = this.#byPort[port];
    if (p !== undefined) {
      // A NaN time is none: the chunk goes in untimed. Two calls, not one with `undefined` or the
      // time: a call given only doubles can have pushRange inlined, where the other boxes the time.
      if (Number.isNaN(atUs)) p.decoder.pushRange(bytes, start, end);
      else p.decoder.pushRange(bytes, start, end, atUs);
      drain(p);
    }
    if (atUs > this.#fedUntilUs) this.#fedUntilUs = atUs;
    this.#chunk++;
  }

  /**
   * A recorded stop ("device lost") of `port` at `atUs`, in a file walked record by record
   * (`feedRecord`): told to its link before the next chunk, as `step` tells a capture's.
   */
  stopped(port: number, atUs: number): void {
    this.#byPort[port]?.link.stopped(atUs);
  }

  /** Tells each link its recorded stops before the capture's chunk `chunk` (`LinkMonitor.stopped`). */
  #stopsBefore(chunk: number): void {
    for (let e = this.#stops.take(chunk); e !== undefined; e = this.#stops.take(chunk)) this.#byPort[e.port]?.link.stopped(e.timeUs);
  }

  /** The end of the stream: every decoder flushed, every link judged at the capture's end. */
  finish(): void {
    if (this.#done) return;
    this.#stopsBefore(Infinity);
    for (const p of this.#ports) {
      p.decoder.end();
      drain(p);
      p.link.finish(this.endUs);
      p.series.extendTo(this.endUs);
    }
    this.#done = true;
  }

  #checkpoint(chunk: number, atUs: number): void {
    const ports = new Map<number, { decoder: DecoderCheckpoint; link: LinkCheckpoint }>();
    for (const p of this.#ports) ports.set(p.port, { decoder: p.decoder.checkpoint(), link: p.link.checkpoint() });
    this.checkpoints.push({ chunk, fedUntilUs: this.#fedUntilUs, ports });
    this.#nextCheckpointUs = checkpointDue(this.#nextCheckpointUs, atUs);
  }

  /**
   * The latest checkpoint a replay at `targetUs` may start from, `historyUs` before it at least
   * (the graphs' history), or undefined when the capture's start is as near.
   */
  checkpointFor(targetUs: number, historyUs: number): Checkpoint | undefined {
    const before = targetUs - historyUs;
    let lo = 0;
    let hi = this.checkpoints.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if ((this.checkpoints[mid]?.fedUntilUs ?? Number.POSITIVE_INFINITY) <= before) lo = mid + 1;
      else hi = mid;
    }
    return this.checkpoints[lo - 1];
  }

  /**
   * The overview as far as it is known: every port decoded up to `readUntilUs` (all of it once
   * done); what lies after is not read yet, and nothing there is drawn.
   */
  overview(): Overview {
    let readUntilUs = this.endUs;
    if (!this.#done) {
      // Bins still open to frames and to missing frames not yet confirmed are not drawn.
      readUntilUs = this.#fedUntilUs;
      for (const p of this.#ports) {
        const last = p.link.lastFrameUs;
        if (Number.isFinite(last) && last < readUntilUs) readUntilUs = last;
      }
      const bin = this.#binUs;
      readUntilUs = Math.max(this.originUs, Math.floor((readUntilUs - this.originUs - SETTLE_US) / bin) * bin + this.originUs);
    }
    const bins = this.#done ? undefined : Math.max(0, Math.round((readUntilUs - this.originUs) / this.#binUs));
    const failsafe = this.#ports.flatMap((p) => failsafeAsRead(failsafesOf(p.link.episodes), readUntilUs, this.#done));
    return sumOverview(
      this.#ports.map((p) => p.series),
      failsafe,
      bins,
      readUntilUs,
      this.#done,
    );
  }
}

function drain(p: PortPass): void {
  const { decoder, link, series } = p;
  for (let f = decoder.next(); f !== undefined; f = decoder.next()) {
    link.frame(f);
    series.frame(f, link);
  }
}
