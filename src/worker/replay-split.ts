/**
 * A long capture's replay pass on two cores: a helper worker decodes some of its ports straight
 * from the file (replay-file-pass.ts) from the moment it opens, while this worker reads the whole
 * file and then decodes the others. The two halves are merged bin by bin and checkpoint by
 * checkpoint. The helper's part counts only for a file `parseCapture` found intact, read on the
 * same span, whose checkpoints fall on the same chunks and whose chunk and byte counts are the
 * capture's; otherwise (or if the helper fails) this worker decodes those ports itself, and the
 * overview and seeks are exactly the one-worker pass's.
 */
import type { Capture } from '../capture/index.js';
import { addOverviews } from './overview.js';
import type { Overview } from './protocol.js';
import type { FilePassJob, FilePassReport } from './replay-file-pass.js';
import { type Checkpoint, type OverviewPass, ReplayPass } from './replay-pass.js';

/** Starts a helper on `job`, its reports to `onReport`; null when there is none to start (one core, no workers). */
export type PassHelperMaker = (job: FilePassJob, onReport: (r: FilePassReport) => void) => { stop(): void } | null;

/** The browser's: a module worker, when there is a second core for it. */
export const WORKER_PASS_HELPER: PassHelperMaker = (job, onReport) => {
  if (typeof Worker === 'undefined' || typeof navigator === 'undefined' || (navigator.hardwareConcurrency ?? 1) < 2) return null;
  const helper = new Worker(new URL('./replay-helper-worker.ts', import.meta.url), { type: 'module', name: 'satscope-replay-helper' });
  helper.addEventListener('message', (event: MessageEvent<FilePassReport>) => onReport(event.data));
  helper.addEventListener('error', (event) => onReport({ type: 'failed', why: event.message || 'the replay helper failed' }));
  helper.postMessage(job);
  return { stop: () => helper.terminate() };
};

/** A helper at work on some ports, and what it has reported so far. */
export class HelperRun {
  readonly checkpoints: Checkpoint[] = [];
  overview: Overview | null = null;
  done = false;
  failed: string | null = null;
  /** What the helper walked (once done): the capture's chunk count and data bytes, if intact. */
  walked = { chunks: Number.NaN, dataBytes: Number.NaN };
  /** Called after each report. */
  onReport: () => void = () => {};
  readonly #handle: { stop(): void };

  /** The helper started on `job`, or null when `make` has none. */
  static start(make: PassHelperMaker, job: FilePassJob): HelperRun | null {
    let run: HelperRun | null = null;
    const handle = make(job, (r) => {
      if (run !== null) run.#report(r);
    });
    if (handle === null) return null;
    run = new HelperRun(job, handle);
    return run;
  }

  private constructor(
    readonly job: FilePassJob,
    handle: { stop(): void },
  ) {
    this.#handle = handle;
  }

  #report(r: FilePassReport): void {
    if (this.done || this.failed !== null) return;
    if (r.type === 'failed') {
      this.failed = r.why;
    } else {
      this.checkpoints.push(...r.checkpoints);
      this.overview = r.overview;
      if (r.type === 'done') {
        this.done = true;
        this.walked = { chunks: r.chunks, dataBytes: r.dataBytes };
        this.stop();
      }
    }
    this.onReport();
  }

  stop(): void {
    this.#handle.stop();
  }
}

export class SplitPass implements OverviewPass {
  /** The ports decoded here: `localPorts` first, the helper's after it failed. */
  readonly #parts: ReplayPass[];
  #run: HelperRun | null;
  /** The helper's checkpoints found on the same chunks as this worker's. */
  #matched = 0;

  /**
   * @param run the helper, started on the same span and resolution, on ports of `capture` other than `localPorts`
   * @param wake called when the helper has reported (the replay decodes and draws on)
   */
  constructor(
    readonly capture: Capture,
    localPorts: readonly number[],
    run: HelperRun,
    wake: () => void,
  ) {
    const { resolution, originUs, endUs } = run.job;
    this.resolution = resolution;
    this.#parts = [new ReplayPass(capture, localPorts, resolution, originUs, endUs)];
    this.#run = run;
    run.onReport = () => {
      this.#check();
      wake();
    };
    this.#check();
  }

  readonly resolution: 'auto' | 1024 | 2048;

  get done(): boolean {
    return this.#parts.every((p) => p.done) && (this.#run === null || this.#run.done);
  }

  /** Everything here is decoded and the helper has not finished: nothing to step until it reports. */
  get waiting(): boolean {
    return this.#run !== null && !this.#run.done && this.#parts.every((p) => p.done);
  }

  step(budgetMs: number, now: () => number): boolean {
    this.#check();
    this.#parts.find((p) => !p.done)?.step(budgetMs, now);
    this.#check();
    return this.done;
  }

  /** Drops the helper's part if it failed or disagrees with this worker's; its ports are then decoded here. */
  #check(): void {
    const run = this.#run;
    if (run === null) return;
    const mine = this.#parts[0]?.checkpoints ?? [];
    const theirs = run.checkpoints;
    let why = run.failed;
    for (; why === null && this.#matched < Math.min(mine.length, theirs.length); this.#matched++) {
      const a = mine[this.#matched];
      const b = theirs[this.#matched];
      if (a?.chunk !== b?.chunk || a?.fedUntilUs !== b?.fedUntilUs) why = `checkpoint ${this.#matched} fell elsewhere`;
    }
    if (
      why === null &&
      run.done &&
      (run.walked.chunks !== this.capture.chunkEnds.length || run.walked.dataBytes !== this.capture.bytes.length)
    )
      why = 'it walked other records';
    if (why === null) return;
    run.stop();
    this.#run = null;
    const { ports, resolution, originUs, endUs } = run.job;
    this.#parts.push(new ReplayPass(this.capture, ports, resolution, originUs, endUs));
  }

  overview(): Overview {
    const parts = this.#parts.map((p) => p.overview());
    const run = this.#run;
    if (run !== null) parts.push(run.overview ?? addOverviews([], run.job.originUs));
    return addOverviews(parts, run?.job.originUs ?? Number.NaN);
  }

  /**
   * The latest checkpoint every part has made (the helper's only once matched) a replay at
   * `targetUs` may start from, `historyUs` before it at least.
   */
  checkpointFor(targetUs: number, historyUs: number): Checkpoint | undefined {
    let count = Math.min(...this.#parts.map((p) => p.checkpoints.length));
    if (this.#run !== null) count = Math.min(count, this.#matched);
    const first = this.#parts[0]?.checkpoints ?? [];
    const before = targetUs - historyUs;
    let lo = 0;
    let hi = count;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if ((first[mid]?.fedUntilUs ?? Number.POSITIVE_INFINITY) <= before) lo = mid + 1;
      else hi = mid;
    }
    const k = lo - 1;
    const base = first[k];
    if (base === undefined) return undefined;
    const ports = new Map(base.ports);
    for (const p of this.#parts.slice(1)) for (const [port, cp] of p.checkpoints[k]?.ports ?? []) ports.set(port, cp);
    for (const [port, cp] of this.#run?.checkpoints[k]?.ports ?? []) ports.set(port, cp);
    return { ...base, ports };
  }

  stop(): void {
    this.#run?.stop();
  }
}
