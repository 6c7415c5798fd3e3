/**
 * The health report with the doctor's findings in it: `healthReport` (the link's figures) plus
 * the doctor's findings at the end of the capture, which `reportHtml` shows in a section of their
 * own. The CLI's `satscope report` and the page's Report use it.
 *
 * The doctor listens to the report's own decode of every port (one pass: the same frames, the
 * same link monitors, finished at the capture's end), so the diagnosis and the figures beside it
 * rest on one reading. A capture without timing is the exception: the doctor reads it on a clock
 * of its own (bytes back to back at 115200, `doctorCapture`), which the report does not use.
 */
import type { AnyCapture } from '../capture/capture-windows.js';
import { capturePorts } from '../capture/facts.js';
import { healthReportFeeding, type ReadingsElsewhere } from './report.js';
import type { PortReadingJob } from './report-port-message.js';
import { likelyReadings } from './resolution-key.js';
import type { HealthReport, HealthReportOptions } from './report-types.js';
import { decodeCapture } from './capture-pass.js';
import { captureSpan } from './capture-span.js';
import { doctorCapture } from './doctor-capture.js';
import { Doctor } from './doctor.js';
import type { DoctorFinding, DoctorOptions } from './doctor-types.js';

/** The report's doctor for a timed capture: the whole capture remembered, times from its start. */
function reportDoctorOptions(capture: AnyCapture, span: { startUs: number }): DoctorOptions {
  return {
    timing: capture.timing === 'per-byte' ? 'per-byte' : 'per-chunk',
    memoryUs: Infinity,
    originUs: Number.isFinite(span.startUs) ? span.startUs : 0,
  };
}

/**
 * The port readings `diagnosedHealthReport(capture, options)` will most likely ask for besides
 * its first (`likelyReadings`), with its clock and its doctor's options: jobs for other threads
 * (`readPortMessage`), handed back through its `elsewhere`.
 */
export function diagnosedReportJobs(capture: AnyCapture, options: HealthReportOptions = {}): PortReadingJob[] {
  const span = captureSpan(capture);
  const doctor = capture.timing === 'none' ? null : reportDoctorOptions(capture, span);
  return likelyReadings(capture, capturePorts(capture), options.resolution ?? 'auto').map((r) => ({
    ...r,
    originUs: span.startUs,
    endUs: span.endUs,
    doctor,
  }));
}

/** `healthReport(capture, options)` with `diagnosis` filled in. Pure, like both. */
export function diagnosedHealthReport(capture: AnyCapture, options: HealthReportOptions = {}, elsewhere?: ReadingsElsewhere): HealthReport {
  let report: HealthReport;
  let findings: DoctorFinding[];
  if (capture.timing === 'none') {
    report = healthReportFeeding(capture, options, undefined, undefined, elsewhere);
    findings = doctorCapture(capture, options.resolution !== undefined ? { resolution: options.resolution } : {}).findings;
  } else {
    const span = captureSpan(capture);
    const doctor = new Doctor(reportDoctorOptions(capture, span));
    report = healthReportFeeding(capture, options, doctor, span, elsewhere);
    // Ports with events but no data (opened, and nothing came): the doctor hears their events.
    const data = new Set(capturePorts(capture));
    const quiet = [...new Set(capture.events.map((e) => e.port))].filter((p) => !data.has(p)).sort((a, b) => a - b);
    for (const port of quiet)
      decodeCapture(
        capture,
        { port, doctor, resolution: options.resolution ?? 'auto', originUs: span.startUs, endUs: span.endUs },
        () => {},
      );
    for (const port of new Set([...data, ...quiet])) doctor.ended(port);
    findings = doctor.findings(Number.isFinite(span.endUs) ? span.endUs : 0);
  }
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
