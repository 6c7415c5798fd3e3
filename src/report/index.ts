/**
 * satscope/report: what a whole capture or a live session says. Decoding a capture
 * (`decodeCapture`, `summarizeCapture` for `satscope info`), the one binned time series every
 * graph is drawn from (`LinkSeries`), the health report (`healthReport`, rendered by
 * `reportHtml`) and the doctor's findings. Every public name of src/report is exported here.
 *
 * The doctor: findings about a satellite setup from what the wire shows.
 *
 * Live use (one `Doctor` per session, every port on one clock):
 *
 * ```ts
 * const doctor = new Doctor();                          // { timing: 'per-byte' } for logic-analyser times
 * doctor.attach(id, { decoder, link, label: 'A' });     // the port's own decoder and link monitor
 * doctor.open(id, nowUs());                             // when the port opens (again on reconnect)
 * doctor.bytes(id, chunk, nowUs());                     // each chunk as it arrives
 * for (let f = decoder.next(); f; f = decoder.next()) { link.frame(f); doctor.frame(id, f); }
 * doctor.lineError(id, error.name, nowUs());            // FramingError, ParityError, BreakError, BufferOverrunError
 * doctor.close(id);                                     // port closed or lost
 * const findings = doctor.findings(nowUs());            // a few times a second: worst first
 * ```
 *
 * A whole capture: `doctorCapture(capture)`; the health report with the findings in it:
 * `diagnosedHealthReport(capture)`.
 */
export { Doctor } from './doctor.js';
export type { Confidence, DoctorCode, DoctorFinding, DoctorOptions, Evidence, Severity } from './doctor-types.js';
export { diagnosedHealthReport } from './doctor-report.js';
export { doctorCapture, type DoctorCaptureOptions, type DoctorReport } from './doctor-capture.js';
export { decodeCapture, type DecodeCaptureOptions } from './capture-pass.js';
export { summarizeCapture, type CaptureSummary, type ChannelSummary } from './summary.js';
export { formatCsvHeader, formatCsvLine, formatJsonLine } from './frame-text.js';
export { LinkSeries } from './series.js';
export { healthReport } from './report.js';
export type {
  HealthReport,
  HealthReportOptions,
  RemoteReport,
  ReportChannel,
  ReportEpisode,
  ReportFinding,
} from './report-types.js';
export { reportHtml } from './report-html.js';
