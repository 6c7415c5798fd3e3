/**
 * A short-lived worker that makes one health report (diagnosedHealthReport, reportHtml), or one
 * remote's decoded frames as `satscope decode` writes them (frames-export.ts), so the worker
 * reading the ports never stalls on it (a long capture's frames take seconds).
 */
/// <reference lib="webworker" />
import type { Capture } from '../capture/model.js';
import { readCapture } from '../capture/sniff.js';
import { diagnosedHealthReport } from '../report/doctor-report.js';
import { reportHtml } from '../report/report-html.js';
import { type FramesExport, framesFile } from './frames-export.js';

export interface ReportRequest {
  /**
   * A capture file's bytes (the live session's recording), a capture already read (one replayed
   * from memory), or the file of one replayed from its File (read here, whole).
   */
  of: { bytes: Uint8Array } | { capture: Capture } | { file: Blob };
  name: string;
  format: 'html' | 'json';
  resolution: 'auto' | 1024 | 2048;
  /** Instead of the report: these decoded frames (`format` is then unused). */
  frames?: Omit<FramesExport, 'resolution'>;
}

/** The file made; with `frames` asked for, how many it holds. */
export type ReportReply = { data: ArrayBuffer; frames?: number; error?: undefined } | { error: string; data?: undefined };

const scope = self as unknown as DedicatedWorkerGlobalScope;

scope.addEventListener('message', async (event: MessageEvent<ReportRequest>) => {
  const { of, name, format, resolution, frames } = event.data;
  try {
    const capture =
      'capture' in of ? of.capture : readCapture('bytes' in of ? of.bytes : new Uint8Array(await of.file.arrayBuffer()), name);
    if (frames !== undefined) {
      const file = framesFile(capture, { ...frames, resolution });
      const reply: ReportReply = { data: file.data, frames: file.frames };
      scope.postMessage(reply, [file.data]);
      return;
    }
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
