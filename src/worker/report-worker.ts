/**
 * A short-lived worker that makes one health report (diagnosedHealthReport, reportHtml), so the
 * worker reading the ports never stalls on it.
 */
/// <reference lib="webworker" />
import { type Capture, readCapture } from '../capture/index.js';
import { diagnosedHealthReport, reportHtml } from '../analysis/index.js';

export interface ReportRequest {
  /** A capture file's bytes (the live session's recording), or a capture already read (the one being replayed). */
  of: { bytes: Uint8Array } | { capture: Capture };
  name: string;
  format: 'html' | 'json';
  resolution: 'auto' | 1024 | 2048;
}

export type ReportReply = { data: ArrayBuffer; error?: undefined } | { error: string; data?: undefined };

const scope = self as unknown as DedicatedWorkerGlobalScope;

scope.addEventListener('message', (event: MessageEvent<ReportRequest>) => {
  const { of, name, format, resolution } = event.data;
  try {
    const capture = 'capture' in of ? of.capture : readCapture(of.bytes, name);
    const report = diagnosedHealthReport(capture, { resolution, name });
    const text = format === 'html' ? reportHtml(report) : `${JSON.stringify(report, null, 2)}\n`;
    const data = new TextEncoder().encode(text).buffer as ArrayBuffer;
    const reply: ReportReply = { data };
    scope.postMessage(reply, [data]);
  } catch (error) {
    const reply: ReportReply = { error: String(error) };
    scope.postMessage(reply);
  }
});
