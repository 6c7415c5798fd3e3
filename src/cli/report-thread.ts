/**
 * The second thread of `satscope report` (`threadedReport`): makes the port readings it is
 * given (`readPortMessage`) one after another and posts each, then counts it in `signal` so
 * that the report's thread, which waits without an event loop, wakes. Whatever goes wrong is
 * posted as an error instead: the report's thread then decodes that port itself.
 */
import { workerData, type MessagePort } from 'node:worker_threads';
import type { Capture } from '../capture/index.js';
import type { PortReadingJob } from '../analysis/index.js';

/** What `threadedReport` hands this thread. */
export interface ReportThreadData {
  capture: Capture;
  jobs: PortReadingJob[];
  port: MessagePort;
  /** Readings posted so far (each a message on `port`). */
  signal: Int32Array;
}

/** One reading, or why there is none. */
export type ReportThreadResult = { ok: import('../analysis/index.js').PortReadingMessage } | { error: string };

const { capture, jobs, port, signal } = workerData as ReportThreadData;

function post(result: ReportThreadResult): void {
  port.postMessage(result);
  Atomics.add(signal, 0, 1);
  Atomics.notify(signal, 0);
}

try {
  // Loaded here rather than imported above: a module that fails to load is posted too.
  const { readPortMessage } = await import('../analysis/index.js');
  for (const job of jobs) {
    try {
      post({ ok: readPortMessage(capture, job) });
    } catch (error) {
      post({ error: String(error) });
    }
  }
} catch (error) {
  for (let i = 0; i < jobs.length; i++) post({ error: String(error) });
}
