/**
 * A file pass (replay-file-pass.ts) at work on some ports of a long capture, in a helper worker
 * or in this one, fed the file's pieces as they are read, and what it has reported so far: the
 * halves of a split replay pass (replay-split.ts).
 */
import type { ParsedCapture } from '../../capture/model.js';
import { ArrivingFile } from './arriving-file.js';
import type { Clock } from '../host.js';
import type { Overview } from '../protocol.js';
import { type FilePassJob, type FilePassReport, type HelperMessage, type WalkedFacts, passOverFile } from './replay-file-pass.js';
import type { Checkpoint } from './replay-pass.js';

/** A pass at work: `feed` hands it the file's next piece (which it may keep or transfer), `fail` says the file could not be read. */
export interface PassHandle {
  feed(piece: Uint8Array): void;
  fail(why: string): void;
  stop(): void;
}

/** Starts a pass on `job`, its reports to `onReport`; null when there is none to start (one core, no workers). */
export interface PassHelperMaker {
  (job: FilePassJob, onReport: (r: FilePassReport) => void): PassHandle | null;
  /** A long capture starts to open: the helper may start now, to be ready for its job. */
  prepare?(): void;
}

const canHelp = (): boolean =>
  typeof Worker !== 'undefined' && typeof navigator !== 'undefined' && (navigator.hardwareConcurrency ?? 1) >= 2;

/** A helper worker started, and where its reports go from its job on. */
interface Helper {
  worker: Worker;
  /** Its reports go to `onReport` from now on (a failure to start, already seen, too). */
  listen(onReport: (r: FilePassReport) => void): void;
}

function newHelper(): Helper {
  const worker = new Worker(new URL('./replay-helper-worker.ts', import.meta.url), { type: 'module', name: 'satscope-replay-helper' });
  let to: ((r: FilePassReport) => void) | null = null;
  // A helper that fails to load before it has a job: said once it has one (its pass then fails).
  let failed: FilePassReport | null = null;
  worker.addEventListener('message', (event: MessageEvent<FilePassReport>) => to?.(event.data));
  worker.addEventListener('error', (event) => {
    const r: FilePassReport = { type: 'failed', why: event.message || 'the replay helper failed' };
    if (to === null) failed = r;
    else to(r);
  });
  return {
    worker,
    listen: (onReport) => {
      to = onReport;
      const r = failed;
      if (r !== null) queueMicrotask(() => onReport(r));
    },
  };
}

/**
 * A helper started ahead (`prepare`), waiting for its job. A worker started from this one starts
 * through this worker's thread, which is busy once the file is read and walked: a helper started
 * with its job got it 150-350 ms later in most opens of the day capture (timed in the page);
 * one started as the file's start is read gets it at once. At most one waits, for the next long
 * capture when this one gives it no job.
 */
let waiting: Helper | null = null;

/** The browser's: a module worker, when there is a second core for it. Pieces are transferred. */
export const WORKER_PASS_HELPER: PassHelperMaker = Object.assign(
  (job: FilePassJob, onReport: (r: FilePassReport) => void): PassHandle | null => {
    if (!canHelp()) return null;
    const helper = waiting ?? newHelper();
    waiting = null;
    helper.listen(onReport);
    const send = (m: HelperMessage, transfer: Transferable[] = []): void => helper.worker.postMessage(m, transfer);
    send({ job });
    return {
      feed: (piece) => send({ piece }, [piece.buffer]),
      fail: (why) => send({ failed: why }),
      stop: () => helper.worker.terminate(),
    };
  },
  {
    prepare: (): void => {
      if (canHelp()) waiting ??= newHelper();
    },
  },
);

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
  /** What the pass walked (once done): the capture's chunk count and data bytes, if intact, and where the file ends inside a record. */
  walked: { chunks: number; dataBytes: number; cutAt?: number | undefined } = { chunks: Number.NaN, dataBytes: Number.NaN };
  /** The capture the pass kept from its walk (a job that keeps it, once done; see replay-split.ts for when it counts). */
  kept: ParsedCapture | null = null;
  /** The capture's chunk facts and span as the pass found them (a job that tallies them, once done). */
  facts: WalkedFacts | null = null;
  /** Called after each report. */
  onReport: () => void = () => {};
  /** Settles when the pass is done, has failed or was stopped. */
  readonly ended: Promise<void>;
  #end: () => void = () => {};
  readonly #handle: PassHandle;
  #stopped = false;
  /** How far into the file the pass has walked, and the reading waiting for it to walk further. */
  #walkedTo = 0;
  #reader: (() => void) | null = null;
  /** Buffers of pieces the pass has walked past, given back to be read into again. */
  readonly #spare: ArrayBuffer[] = [];

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
      this.#spare.push(...r.spare);
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
        this.walked = { chunks: r.chunks, dataBytes: r.dataBytes, cutAt: r.cutAt };
        this.kept = r.kept ?? null;
        this.facts = r.facts ?? null;
        this.stop();
      }
    }
    this.onReport();
  }

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

  /** A buffer of a piece the pass has walked past, given back (the caller takes it over), if there is one. */
  takeSpare(): ArrayBuffer | undefined {
    return this.#spare.shift();
  }

  /** The file's next piece (kept or transferred: the caller lets go of it). */
  feed(piece: Uint8Array): void {
    if (!this.done && this.failed === null) this.#handle.feed(piece);
  }

  /** The file could not be read to its end. */
  fail(why: string): void {
    this.#handle.fail(why);
  }

  stop(): void {
    this.#stopped = true;
    this.#handle.stop();
    this.#end();
    this.#wakeReader();
  }
}
