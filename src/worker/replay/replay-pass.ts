/**
 * The one decode of a whole capture a replay makes when it opens (captures with recorded chunk
 * times): every port's decoder, link monitor and link series (the report's), fed the chunks in
 * the capture's order a slice at a time (of a capture read whole, or of a file's records as they
 * are walked), so that the page draws the overview as it grows and stays responsive. On the way
 * it keeps a checkpoint of every port's decoder and link monitor each minute of capture
 * time (further apart in a capture of days), with where its chunk lies: a seek restores the nearest one and feeds only from there,
 * with the counters, episodes and link state of the whole capture up to the target.
 */
import type { DecoderCheckpoint, LinkCheckpoint } from '../../decoder/checkpoint.js';
import type { LinkMonitor } from '../../decoder/link.js';
import { SpektrumDecoder } from '../../decoder/decoder.js';
import type { Capture } from '../../capture/model.js';
import { recordTimeUs } from '../../capture/record-walk.js';
import { RECORD_HEADER_SIZE } from '../../capture/layout.js';
import { LinkSeries, monitorWithSeries } from '../../report/series.js';
import { timingJitterUs } from '../../report/capture-pass.js';
import { recordedStops, StopCursor } from '../../report/doctor-events.js';
import { failsafeAsRead, failsafesOf, overviewBinUs, sumOverview } from './overview.js';
import type { Overview } from '../protocol.js';

/** The capture is decoded for this long at a time, then messages and playback go through. */
export const PASS_SLICE_MS = 40;

/** Capture time between two checkpoints: 1440 of them a day, each about 10 kB a port. */
const CHECKPOINT_US = 60e6;
/**
 * Checkpoints in a capture, at most: one a minute for two days, further apart in a longer one (a
 * week's 3.5 minutes), so that they hold tens of megabytes, not hundreds (a week's at one a
 * minute held 180 MB of the worker's). A seek feeds one interval and a graph's history at most.
 */
const MOST_CHECKPOINTS = 2880;

/** The capture time between two checkpoints of a capture `spanUs` long. */
function checkpointEveryUs(spanUs: number): number {
  return Number.isFinite(spanUs) ? Math.max(CHECKPOINT_US, Math.ceil(spanUs / MOST_CHECKPOINTS)) : CHECKPOINT_US;
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
  /** The file offset of that chunk's record (a file's records walked); NaN for a capture read whole. */
  offset: number;
  /** The latest arrival among the chunks fed, µs: a seek to a target at or after it may start here. */
  fedUntilUs: number;
  ports: Map<number, { decoder: DecoderCheckpoint; link: LinkCheckpoint }>;
}

export class ReplayPass {
  readonly checkpoints: Checkpoint[] = [];
  /** The capture decoded; null: a file's records fed one by one as it is walked (`feedRecord`). */
  readonly #capture: Capture | null;
  readonly #ports: PortPass[] = [];
  /** The overview's bin width (overviewBinUs: a short capture's are narrow). */
  readonly #binUs: number;
  /** Each port's decode by port number (0–255), undefined for the ports not decoded here. */
  readonly #byPort: (PortPass | undefined)[] = [];
  /** The next chunk of the capture to feed (the count fed so far). */
  #chunk = 0;
  #fedUntilUs = Number.NEGATIVE_INFINITY;
  /** The time of the chunk being fed (`#feed`), and its record's file offset (NaN: a capture's chunk). */
  readonly #at = new Float64Array([Number.NaN, Number.NaN]);
  #nextCheckpointUs: number;
  readonly #checkpointEveryUs: number;
  #done = false;
  /** The capture's recorded stops ("device lost"), each told to its port's link before the chunk after it. */
  readonly #stops: StopCursor;

  /**
   * @param originUs, endUs the capture's span (`captureSpan`): bin 0 starts at the first, the links are judged at the last
   * @param capture null: the chunks come through `feedRecord` (records of a file with chunk times)
   * @param ports the ports decoded; null: every port a record is found on (a file whose ports
   *   are not known before it is walked), each from its first record on
   */
  constructor(
    capture: Capture | null,
    ports: readonly number[] | null,
    readonly resolution: 'auto' | 1024 | 2048,
    readonly originUs: number,
    readonly endUs: number,
  ) {
    this.#capture = capture;
    this.#stops = new StopCursor(capture === null ? [] : recordedStops(capture));
    this.#binUs = overviewBinUs(endUs - originUs);
    this.#anyPort = ports === null;
    for (const port of ports ?? []) this.#add(port);
    this.#checkpointEveryUs = checkpointEveryUs(endUs - originUs);
    this.#nextCheckpointUs = originUs + this.#checkpointEveryUs;
  }

  /** Every port a record is found on is decoded. */
  readonly #anyPort: boolean;

  /** The ports decoded, in increasing order. */
  get ports(): number[] {
    return this.#ports.map((p) => p.port);
  }

  #add(port: number): PortPass {
    const series = new LinkSeries(this.#binUs, this.originUs);
    const p: PortPass = {
      port,
      decoder: new SpektrumDecoder({ resolution: this.resolution }),
      link: monitorWithSeries({ jitterUs: timingJitterUs(this.#capture?.timing ?? 'per-chunk') }, series),
      series,
    };
    this.#byPort[port] = p;
    this.#ports.push(p);
    this.#ports.sort((a, b) => a.port - b.port);
    return p;
  }

  get done(): boolean {
    return this.#done;
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
    if (i < n) return false;
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

  /**
   * `feed()` of a data record of a file as it is walked (a RecordSink, `bytes[0]` the file's
   * byte `at`): its time is read from `view` here.
   */
  feedRecord(bytes: Uint8Array, view: DataView, start: number, end: number, port: number, at: number): void {
    this.#at[0] = recordTimeUs(view, start);
    this.#at[1] = at + start - RECORD_HEADER_SIZE;
    this.#feed(bytes, start, end, port);
  }

  /**
   * `feed()` at #at[0]. The time goes on in a typed-array slot, not as an argument: a double
   * handed to a call that is not inlined is boxed (an allocation a chunk).
   */
  #feed(bytes: Uint8Array, start: number, end: number, port: number): void {
    const atUs = this.#at[0] ?? Number.NaN;
    if (atUs >= this.#nextCheckpointUs) this.#checkpoint(this.#chunk, atUs);
    const p = this.#byPort[port] ?? (this.#anyPort ? this.#add(port) : undefined);
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
    this.checkpoints.push({ chunk, offset: this.#at[1] ?? Number.NaN, fedUntilUs: this.#fedUntilUs, ports });
    // The next is due a whole interval on, however long the silence before this chunk.
    let next = this.#nextCheckpointUs;
    while (next <= atUs) next += this.#checkpointEveryUs;
    this.#nextCheckpointUs = next;
  }

  /** The first checkpoint taken after `targetUs`'s data: where a seek to it has fed all it will. */
  checkpointAfter(targetUs: number): Checkpoint | undefined {
    return this.checkpoints[this.#countWhere((fedUntilUs) => fedUntilUs < targetUs)];
  }

  /**
   * The latest checkpoint a replay at `targetUs` may start from, `historyUs` before it at least
   * (the graphs' history), or undefined when the capture's start is as near.
   */
  checkpointFor(targetUs: number, historyUs: number): Checkpoint | undefined {
    const before = targetUs - historyUs;
    return this.checkpoints[this.#countWhere((fedUntilUs) => fedUntilUs <= before) - 1];
  }

  /** How many checkpoints from the first have a `fedUntilUs` that passes `test` (one that holds for a prefix of them), by bisection. */
  #countWhere(test: (fedUntilUs: number) => boolean): number {
    let lo = 0;
    let hi = this.checkpoints.length;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if (test(this.checkpoints[mid]?.fedUntilUs ?? Number.POSITIVE_INFINITY)) lo = mid + 1;
      else hi = mid;
    }
    return lo;
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
