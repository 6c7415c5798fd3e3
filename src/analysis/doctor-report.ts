/**
 * The health report with the doctor's findings in it: `healthReport` (the link's figures) plus
 * `doctorCapture`'s findings at the end of the capture, which `reportHtml` shows in a section
 * of their own. The CLI's `satscope report` and the page's Report use it.
 */
import type { Capture } from '../capture/index.js';
import { healthReport, type HealthReport, type HealthReportOptions } from './report.js';
import { doctorCapture } from './doctor-capture.js';

/** `healthReport(capture, options)` with `diagnosis` filled in. Pure, like both. */
export function diagnosedHealthReport(capture: Capture, options: HealthReportOptions = {}): HealthReport {
  const report = healthReport(capture, options);
  const { findings } = doctorCapture(capture, options.resolution !== undefined ? { resolution: options.resolution } : {});
  return {
    ...report,
    diagnosis: findings.map((f) => ({
      severity: f.severity,
      confidence: f.confidence,
      title: f.title,
      evidence: f.evidence.map((e) => ({ text: e.text })),
      todo: f.todo,
      settings: f.settings,
    })),
  };
}
