/**
 * A health report on what the user is looking at: the capture being replayed, or the live
 * session's recording. It is made in a worker of its own (report-worker.ts): decoding a long
 * capture takes a good part of a second, and this worker must keep reading ports meanwhile (a
 * stall shows as a gap in the data and in the recording).
 */
import { type Host, notice } from './host.js';
import { tooLargeToReadWhole } from './replay/capture-file.js';
import type { ReportReply, ReportRequest } from './report-worker.js';

/** The helper that makes one report: a fresh worker in the browser, a stand-in in tests. */
export type ReportMaker = (request: ReportRequest, transfer: Transferable[]) => Promise<ReportReply>;

/** Runs report-worker.ts once for `request`, then lets it go. */
export const WORKER_REPORT_MAKER: ReportMaker = (request, transfer) =>
  new Promise((resolve) => {
    const helper = new Worker(new URL('./report-worker.ts', import.meta.url), { type: 'module', name: 'satscope-report' });
    helper.addEventListener('message', (event: MessageEvent<ReportReply>) => {
      helper.terminate();
      resolve(event.data);
    });
    helper.addEventListener('error', (event) => {
      helper.terminate();
      resolve({ error: event.message || 'the report worker failed' });
    });
    helper.postMessage(request, transfer);
  });

/**
 * Makes a report of `of` and offers it to the page as a download named after `name`: a capture
 * file's bytes (copied, the caller keeps its own) or a capture being replayed (cloned to the
 * helper, so the worker keeps no copy of the file for it). `of` null: the user is told there is
 * nothing yet.
 */
export async function report(
  host: Host,
  make: ReportMaker,
  of: ReportRequest['of'] | null,
  name: string,
  format: 'html' | 'json',
  resolution: 'auto' | 1024 | 2048,
): Promise<void> {
  if (of === null) {
    notice(
      host,
      'warning',
      'Nothing to report on yet',
      'Record the live session (● Record) or open a capture; the report covers what was recorded.',
    );
    return;
  }
  const tooLarge = 'file' in of ? tooLargeToReadWhole(of.file.size, 'a capture reported on') : null;
  if (tooLarge !== null) {
    notice(host, 'error', 'The report could not be made', tooLarge);
    return;
  }
  let request: ReportRequest;
  let transfer: Transferable[] = [];
  if ('bytes' in of) {
    const copy = of.bytes.slice();
    request = { of: { bytes: copy }, name, format, resolution };
    transfer = [copy.buffer];
  } else {
    request = { of, name, format, resolution };
  }
  const reply = await make(request, transfer);
  if (reply.error !== undefined) {
    notice(host, 'error', 'The report could not be made', reply.error);
    return;
  }
  const base = (name.replace(/\.[^.]+$/, '') || 'satscope').replace(/[^\w.-]+/g, '-');
  host.post(
    {
      type: 'export-ready',
      name: `${base}.report.${format}`,
      mime: format === 'html' ? 'text/html' : 'application/json',
      data: reply.data,
    },
    [reply.data],
  );
}
