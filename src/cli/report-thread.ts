/**
 * The second thread of `satscope report` (`threadedReport`): makes the port readings it is
 * given (`readPortMessage`) one after another and posts each. Whatever goes wrong is posted as
 * an error instead: the report's thread then decodes that port itself.
 */
import type { PortReadingJob, PortReadingMessage } from '../report/report-port-message.js';
import type { Capture } from '../capture/model.js';
import { workerSide } from './waited-worker.js';

/** What `threadedReport` hands this thread: the capture's columns, or the file to stream it from (this thread walks it on its own). */
export interface ReportThreadData {
  capture: Capture | { file: string };
  jobs: PortReadingJob[];
}

/** One reading, or why there is none. */
export type ReportThreadResult = { ok: PortReadingMessage } | { error: string };

const { data, post } = workerSide<ReportThreadData>();
const send = (result: ReportThreadResult): void => post(result);

try {
  // Loaded here rather than imported above: a module that fails to load is posted too.
  const { readPortMessage } = await import('../report/report-port-message.js');
  const { openStreamed } = await import('./streamed-file.js');
  const given = data.capture;
  const streamed = 'file' in given ? openStreamed(given.file) : null;
  const capture = 'file' in given ? streamed?.capture : given;
  try {
    for (const job of data.jobs) {
      try {
        if (capture === undefined) throw new Error(`${'file' in given ? given.file : ''} does not stream`);
        send({ ok: readPortMessage(capture, job) });
      } catch (error) {
        send({ error: String(error) });
      }
    }
  } finally {
    streamed?.close();
  }
} catch (error) {
  for (let i = 0; i < data.jobs.length; i++) send({ error: String(error) });
}
