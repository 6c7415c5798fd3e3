/**
 * `satscope report` on two cores: while this thread decodes the first port, a worker thread
 * decodes the others the report will most likely ask for (`diagnosedReportJobs`), and the
 * report adopts them when it gets there (`diagnosedHealthReport`'s `elsewhere`). The report is
 * byte for byte the one a single thread makes: a reading guessed wrong, or one the worker could
 * not make, is decoded here instead.
 *
 * The report is synchronous, so this thread waits for a reading without an event loop
 * (`WaitedWorker`).
 */
import { diagnosedHealthReport, diagnosedReportJobs } from '../report/doctor-report.js';
import { sameReading, type PortReadingMessage } from '../report/report-port-message.js';
import type { HealthReport, HealthReportOptions } from '../report/report-types.js';
import { type AnyCapture, captureDataBytes, isStreamed } from '../capture/capture-windows.js';
import type { ReportThreadData, ReportThreadResult } from './report-thread.js';
import { secondCore, WaitedWorker } from './waited-worker.js';

/** Below this many bytes of data a second thread costs more to start than it saves. */
export const THREADED_MIN_BYTES = 2 << 20;

/**
 * `diagnosedHealthReport(capture, options)`, its ports decoded on two threads when the capture
 * is big enough (`minBytes`) and the machine has a second core; `fromWorker`: how many port readings the report took from the
 * worker thread.
 */
export function threadedReport(
  capture: AnyCapture,
  options: HealthReportOptions,
  minBytes = THREADED_MIN_BYTES,
  file?: string,
): { report: HealthReport; fromWorker: number } {
  // A streamed capture's worker streams the file itself (`file`): it is not held to be shared.
  const jobs =
    captureDataBytes(capture) >= minBytes && secondCore() && (!isStreamed(capture) || file !== undefined)
      ? diagnosedReportJobs(capture, options)
      : [];
  if (jobs.length === 0) return { report: diagnosedHealthReport(capture, options), fromWorker: 0 };
  let shared: ReportThreadData['capture'];
  if (isStreamed(capture)) shared = { file: file ?? '' };
  else {
    const { kind, meta, timing, bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs, events } = capture;
    shared = { kind, meta, timing, bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs, events, issues: [] };
  }
  const data: ReportThreadData = { capture: shared, jobs };
  const worker = new WaitedWorker<ReportThreadResult>(new URL('./report-thread.js', import.meta.url), data);
  let fromWorker = 0;
  try {
    const report = diagnosedHealthReport(capture, options, (port, resolution, from): PortReadingMessage | undefined => {
      const i = jobs.findIndex((job) => sameReading(job, port, resolution, from));
      const r = i < 0 ? undefined : worker.result(i);
      if (r === undefined || !('ok' in r)) return undefined;
      fromWorker++;
      return r.ok;
    });
    return { report, fromWorker };
  } finally {
    worker.close();
  }
}
