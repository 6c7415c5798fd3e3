/**
 * The browser's replay helper (replay-helper.ts's WORKER_PASS_HELPER) started ahead of its job:
 * it gets its job and reports as one started with it, and one that failed to start before it
 * had a job says so once it has one (its pass fails, and the worker decodes those ports): it
 * never leaves the replay waiting. A stand-in Worker class plays the browser's.
 */
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import type { FilePassJob, FilePassReport } from '../src/worker/replay/replay-file-pass.js';
import { WORKER_PASS_HELPER } from '../src/worker/replay/replay-helper.js';

/** Workers made, in order; each fails to load when `failNext` is set as it is made. */
const made: StandInWorker[] = [];
let failNext = false;

class StandInWorker extends EventTarget {
  readonly posted: unknown[] = [];
  terminated = false;
  constructor(readonly url: URL) {
    super();
    made.push(this);
    if (failNext) setTimeout(() => this.dispatchEvent(Object.assign(new Event('error'), { message: 'could not load the helper' })), 0);
  }
  postMessage(message: unknown): void {
    this.posted.push(message);
  }
  terminate(): void {
    this.terminated = true;
  }
  /** The helper reports `r`. */
  report(r: FilePassReport): void {
    this.dispatchEvent(Object.assign(new Event('message'), { data: r }));
  }
}

const job: FilePassJob = { size: 1, ports: [1], alsoChecked: [], resolution: 'auto', originUs: 0, endUs: 1 };
const tick = () => new Promise((resolve) => setTimeout(resolve, 5));

describe('a replay helper started ahead of its job', () => {
  const saved = { Worker: globalThis.Worker, navigator: Object.getOwnPropertyDescriptor(globalThis, 'navigator') };
  beforeAll(() => {
    Object.assign(globalThis, { Worker: StandInWorker });
    Object.defineProperty(globalThis, 'navigator', { value: { hardwareConcurrency: 2 }, configurable: true });
  });
  afterAll(() => {
    Object.assign(globalThis, { Worker: saved.Worker });
    if (saved.navigator) Object.defineProperty(globalThis, 'navigator', saved.navigator);
  });

  it('is the one that gets the job, and its reports reach the pass', async () => {
    WORKER_PASS_HELPER.prepare?.();
    WORKER_PASS_HELPER.prepare?.();
    expect(made.length).toBe(1);
    const reports: FilePassReport[] = [];
    const handle = WORKER_PASS_HELPER(job, (r) => reports.push(r));
    expect(made.length).toBe(1);
    expect(made[0]?.posted).toEqual([{ job }]);
    made[0]?.report({ type: 'walked', to: 10, spare: [] });
    expect(reports).toEqual([{ type: 'walked', to: 10, spare: [] }]);
    handle?.stop();
    expect(made[0]?.terminated).toBe(true);
    // The next job without one waiting: a helper started with it.
    WORKER_PASS_HELPER(job, () => {});
    expect(made.length).toBe(2);
  });

  it('that failed to start says so once it has a job', async () => {
    failNext = true;
    WORKER_PASS_HELPER.prepare?.();
    failNext = false;
    await tick();
    const reports: FilePassReport[] = [];
    WORKER_PASS_HELPER(job, (r) => reports.push(r));
    expect(reports).toEqual([]);
    await tick();
    expect(reports).toEqual([{ type: 'failed', why: 'could not load the helper' }]);
  });
});
