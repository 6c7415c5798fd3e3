/**
 * A long capture's replay pass on two cores, overview first: as soon as the file's start and end
 * are read, its ports are decoded straight from the file (replay-file-pass.ts) in two halves,
 * the first half in this worker and the later half in a helper worker, and the overview is drawn
 * from both as they go. The file is read whole and parsed for playback after this worker's half.
 *
 * The halves count only for a capture `parseCapture` found intact, on the same span, with every
 * checkpoint on the chunk the capture's own order puts it (`checkpointChunks`) and with the
 * capture's chunk and byte counts. A half that fails or disagrees is decoded again from the
 * capture, here; the overview and seeks are then exactly the one-worker pass's.
 */
import type { Capture } from '../capture/index.js';
import type { Clock } from './host.js';
import { addOverviews } from './overview.js';
import type { Overview } from './protocol.js';
import { ArrivingFile } from './arriving-file.js';
import { type FilePassJob, type FilePassReport, type HelperMessage, passOverFile } from './replay-file-pass.js';
import { CHECKPOINT_US, type Checkpoint, type OverviewPass, ReplayPass } from './replay-pass.js';

/** A pass at work: `feed` hands it the file's next piece (which it may keep or transfer), `fail` says the file could not be read. */
export interface PassHandle {
  feed(piece: Uint8Array): void;
  fail(why: string): void;
  stop(): void;
}

/** Starts a pass on `job`, its reports to `onReport`; null when there is none to start (one core, no workers). */
export type PassHelperMaker = (job: FilePassJob, onReport: (r: FilePassReport) => void) => PassHandle | null;

/** The browser's: a module worker, when there is a second core for it. Pieces are transferred. */
export const WORKER_PASS_HELPER: PassHelperMaker = (job, onReport) => {
  if (typeof Worker === 'undefined' || typeof navigator === 'undefined' || (navigator.hardwareConcurrency ?? 1) < 2) return null;
  const helper = new Worker(new URL('./replay-helper-worker.ts', import.meta.url), { type: 'module', name: 'satscope-replay-helper' });
  helper.addEventListener('message', (event: MessageEvent<FilePassReport>) => onReport(event.data));
  helper.addEventListener('error', (event) => onReport({ type: 'failed', why: event.message || 'the replay helper failed' }));
  const send = (m: HelperMessage, transfer: Transferable[] = []): void => helper.postMessage(m, transfer);
  send({ job });
  return {
    feed: (piece) => send({ piece }, [piece.buffer]),
    fail: (why) => send({ failed: why }),
    stop: () => helper.terminate(),
  };
};

/** The same pass in this worker, between its other tasks (it awaits each piece of the file). */
export function inThisWorker(clock: Clock): PassHelperMaker {
  return (job, onReport) => {
    let stopped = false;
    const file = new ArrivingFile(job.size);
    void passOverFile(
      job,
      file,
      (r) => {
        if (!stopped) onReport(r);
      },
      () => clock.now(),
      () => stopped,
    );
    return {
      feed: (piece) => file.push(piece),
      fail: (why) => file.fail(new Error(why)),
      stop: () => {
        stopped = true;
        file.fail(new Error('stopped'));
      },
    };
  };
}

/** A file pass at work on some ports, and what it has reported so far. */
export class HelperRun {
  readonly checkpoints: Checkpoint[] = [];
  overview: Overview | null = null;
  done = false;
  failed: string | null = null;
  /** What the pass walked (once done): the capture's chunk count and data bytes, if intact. */
  walked = { chunks: Number.NaN, dataBytes: Number.NaN };
  /** Called after each report. */
  onReport: () => void = () => {};
  /** Settles when the pass is done, has failed or was stopped. */
  readonly ended: Promise<void>;
  #end: () => void = () => {};
  readonly #handle: PassHandle;

  /** The pass started on `job`, or null when `make` has none. */
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
    handle: PassHandle,
  ) {
    this.#handle = handle;
    this.ended = new Promise((resolve) => {
      this.#end = resolve;
    });
  }

  #report(r: FilePassReport): void {
    if (this.done || this.failed !== null) return;
    if (r.type === 'walked') {
      this.#walkedTo = r.to;
      this.#wakeReader();
      return;
    }
    if (r.type === 'failed') {
      this.failed = r.why;
      this.#end();
      this.#wakeReader();
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

  /** How far into the file the pass has walked. */
  #walkedTo = 0;
  #reader: (() => void) | null = null;

  #wakeReader(): void {
    const go = this.#reader;
    this.#reader = null;
    go?.();
  }

  /** Settles once the pass has walked to `offset` of the file, or has ended (pieces beyond it would only pile up). */
  async reached(offset: number): Promise<void> {
    while (this.#walkedTo < offset && !this.done && this.failed === null && !this.#stopped) {
      await new Promise<void>((resolve) => {
        this.#reader = resolve;
      });
    }
  }

  /** The file's next piece (kept or transferred: the caller lets go of it). */
  feed(piece: Uint8Array): void {
    if (!this.done && this.failed === null) this.#handle.feed(piece);
  }

  /** The file could not be read to its end. */
  fail(why: string): void {
    this.#handle.fail(why);
  }

  #stopped = false;

  stop(): void {
    this.#stopped = true;
    this.#handle.stop();
    this.#end();
    this.#wakeReader();
  }
}

/**
 * Where the replay pass's checkpoints fall in `capture` (ReplayPass's rule: before the first
 * chunk at or past each CHECKPOINT_US from `originUs`), and the latest arrival fed before each.
 */
export function checkpointChunks(capture: Capture, originUs: number): { chunk: number; fedUntilUs: number }[] {
  const out: { chunk: number; fedUntilUs: number }[] = [];
  const times = capture.chunkTimesUs;
  let next = originUs + CHECKPOINT_US;
  let fed = Number.NEGATIVE_INFINITY;
  for (let i = 0; i < times.length; i++) {
    const t = times[i] ?? Number.NaN;
    if (t >= next) {
      out.push({ chunk: i, fedUntilUs: fed });
      while (next <= t) next += CHECKPOINT_US;
    }
    if (t > fed) fed = t;
  }
  return out;
}

export class SplitPass implements OverviewPass {
  /** The file passes still counted. */
  #runs: HelperRun[];
  /** Ports decoded here from the capture: those of a pass that failed or disagreed, and any no pass has. */
  readonly #parts: ReplayPass[] = [];
  /** Ports whose pass was dropped before the capture was read: decoded from it once it is. */
  #orphans: number[] = [];
  #capture: Capture | null = null;
  #truth: { chunk: number; fedUntilUs: number }[] = [];
  /** Checkpoints of each run found where the capture puts them. */
  readonly #matched = new Map<HelperRun, number>();

  /**
   * @param runs file passes on disjoint ports, on the same span (`originUs`, `endUs`) and resolution
   * @param wake called when a run has reported (the replay draws on, and steps what is left)
   */
  constructor(
    runs: HelperRun[],
    readonly resolution: 'auto' | 1024 | 2048,
    readonly originUs: number,
    readonly endUs: number,
    wake: () => void,
  ) {
    this.#runs = runs;
    for (const run of runs) {
      this.#matched.set(run, 0);
      run.onReport = () => {
        this.#check();
        wake();
      };
    }
  }

  /**
   * The capture read whole: the runs count if it is intact and on their span; every port of
   * `ports` no run decodes (or that of a run dropped) is decoded from it here.
   */
  adopt(capture: Capture, ports: readonly number[], span: { startUs: number; endUs: number }): void {
    this.#capture = capture;
    if (capture.issues.length > 0 || span.startUs !== this.originUs || span.endUs !== this.endUs) {
      for (const run of this.#runs) this.#drop(run);
    }
    this.#truth = checkpointChunks(capture, this.originUs);
    this.#check();
    const covered = new Set([...this.#runs.flatMap((r) => r.job.ports), ...this.#parts.flatMap((p) => p.ports)]);
    const rest = ports.filter((p) => !covered.has(p) && !this.#orphans.includes(p));
    this.#decodeHere([...this.#orphans, ...rest]);
    this.#orphans = [];
  }

  get done(): boolean {
    return this.#capture !== null && this.#parts.every((p) => p.done) && this.#runs.every((r) => r.done);
  }

  get waiting(): boolean {
    return !this.done && this.#parts.every((p) => p.done);
  }

  step(budgetMs: number, now: () => number): boolean {
    this.#check();
    this.#parts.find((p) => !p.done)?.step(budgetMs, now);
    return this.done;
  }

  #decodeHere(ports: number[]): void {
    const capture = this.#capture;
    if (capture === null) this.#orphans.push(...ports);
    else if (ports.length > 0)
      this.#parts.push(
        new ReplayPass(
          capture,
          [...ports].sort((a, b) => a - b),
          this.resolution,
          this.originUs,
          this.endUs,
        ),
      );
  }

  #drop(run: HelperRun): void {
    run.stop();
    this.#runs = this.#runs.filter((r) => r !== run);
    this.#matched.delete(run);
    this.#decodeHere(run.job.ports);
  }

  /** Drops every run that failed or, once the capture is read, disagrees with it. */
  #check(): void {
    // One that failed (a damaged record, a read that failed) drops all: a damaged port byte puts
    // a record on another port, and what that port's pass decodes is then not the capture.
    if (this.#runs.some((r) => r.failed !== null)) {
      for (const run of [...this.#runs]) this.#drop(run);
      return;
    }
    for (const run of [...this.#runs]) {
      if (this.#capture === null) continue;
      let k = this.#matched.get(run) ?? 0;
      const truth = this.#truth;
      let agrees = true;
      for (; agrees && k < run.checkpoints.length; k++) {
        const a = run.checkpoints[k];
        const b = truth[k];
        agrees = a !== undefined && b !== undefined && a.chunk === b.chunk && a.fedUntilUs === b.fedUntilUs;
      }
      this.#matched.set(run, k);
      if (agrees && run.done)
        agrees =
          k === truth.length && run.walked.chunks === this.#capture.chunkEnds.length && run.walked.dataBytes === this.#capture.bytes.length;
      if (!agrees) this.#drop(run);
    }
  }

  overview(): Overview {
    const parts = [...this.#runs.map((r) => r.overview ?? addOverviews([], this.originUs)), ...this.#parts.map((p) => p.overview())];
    if (this.#orphans.length > 0) parts.push(addOverviews([], this.originUs));
    return addOverviews(parts, this.originUs);
  }

  /**
   * The latest checkpoint every port has (a run's only once found where the capture puts it) that
   * a replay at `targetUs` may start from, `historyUs` before it at least.
   */
  checkpointFor(targetUs: number, historyUs: number): Checkpoint | undefined {
    if (this.#capture === null) return undefined;
    let count = this.#truth.length;
    for (const p of this.#parts) count = Math.min(count, p.checkpoints.length);
    for (const run of this.#runs) count = Math.min(count, this.#matched.get(run) ?? 0);
    const before = targetUs - historyUs;
    let lo = 0;
    let hi = count;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if ((this.#truth[mid]?.fedUntilUs ?? Number.POSITIVE_INFINITY) <= before) lo = mid + 1;
      else hi = mid;
    }
    const k = lo - 1;
    const at = this.#truth[k];
    if (at === undefined) return undefined;
    const ports = new Map<number, Checkpoint['ports'] extends Map<number, infer V> ? V : never>();
    for (const source of [...this.#runs, ...this.#parts]) for (const [port, cp] of source.checkpoints[k]?.ports ?? []) ports.set(port, cp);
    return { chunk: at.chunk, fedUntilUs: at.fedUntilUs, ports };
  }

  stop(): void {
    for (const run of this.#runs) run.stop();
  }
}
