/**
 * A short-lived worker that makes one health report (diagnosedHealthReport, reportHtml), so the
 * worker reading the ports never stalls on it.
 */
/// <reference lib="webworker" />
import { readCapture } from '../capture/index.js';
import { diagnosedHealthReport, reportHtml } from '../analysis/index.js';

export interface ReportRequest {
  bytes: Uint8Array;
  name: string;
  format: 'html' | 'json';
  resolution: 'auto' | 1024 | 2048;
}

export type ReportReply = { data: ArrayBuffer; error?: undefined } | { error: string; data?: undefined };

const scope = self as unknown as DedicatedWorkerGlobalScope;

scope.addEventListener('message', (event: MessageEvent<ReportRequest>) => {
  const { bytes, name, format, resolution } = event.data;
  try {
    const report = diagnosedHealthReport(readCapture(bytes, name), { resolution, name });
    const text = format === 'html' ? reportHtml(report) : `${JSON.stringify(report, null, 2)}\n`;
    const data = new TextEncoder().encode(text).buffer as ArrayBuffer;
    const reply: ReportReply = { data };
    scope.postMessage(reply, [data]);
  } catch (error) {
    const reply: ReportReply = { error: String(error) };
    scope.postMessage(reply);
  }
});
