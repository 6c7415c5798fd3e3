/**
 * satscope/report: what a whole capture or a live session says. Decoding a capture
 * (`decodeCapture`, `summarizeCapture` for `satscope info`), the one binned time series every
 * graph is drawn from (`LinkSeries`), the health report (`healthReport`, rendered by
 * `reportHtml`) and the doctor's findings. Every public name of src/analysis is exported here.
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
export { LINE_WINDOW_BINS, NOTHING_AFTER_US, NOTHING_CERTAIN_US } from './doctor-state.js';
export type {
  Confidence,
  ConfirmProbe,
  DoctorCode,
  DoctorFinding,
  DoctorOptions,
  DoctorPortSource,
  Evidence,
  Severity,
} from './doctor-types.js';
export { diagnosedHealthReport, diagnosedReportJobs } from './doctor-report.js';
export { readPortMessage, sameReading, type PortReadingJob, type PortReadingMessage } from './report-port-message.js';
export { doctorCapture, type DoctorCaptureOptions, type DoctorReport, type DoctorTimelineEntry } from './doctor-capture.js';
export { doctorEvent } from './doctor-events.js';
export {
  ArduPilotGuess,
  ARDUPILOT_GUESS_FRAMES,
  bindPulses,
  channelSetText,
  foreignSettings,
  PROTOCOL_SETTINGS,
  satelliteSettings,
  type FlightStack,
  type ForeignProtocol,
  type GuessTally,
  type StackSetting,
  type StreamFacts,
} from './doctor-stacks.js';
export { classifyLine, PacketScanner, PACKET_KINDS, type LineCounts, type LineVerdict, type PacketKind } from './doctor-line.js';
export { decodeCapture, timingJitterUs, type DecodeCaptureOptions } from './capture-pass.js';
export { type CaptureSpan, SpanTally, captureSpan, seedCaptureSpan, spanBetween } from './capture-span.js';
export { resolutionKey } from './resolution-key.js';
export { summarizeCapture, type CaptureSummary, type ChannelSummary } from './summary.js';
export { formatCsvHeader, formatCsvLine, formatJsonLine } from './frame-text.js';
export { LinkSeries, monitorWithSeries } from './series.js';
export { healthReport, type ReadingsElsewhere } from './report.js';
export { formatClock, formatDuration } from './report-text.js';
export { REPORT_BIN_US, REPORT_THRESHOLDS, SPIKE_MIN_JUMP_PERCENT, type ReportThresholds } from './report-thresholds.js';
export type {
  FindingCode,
  FindingLevel,
  HealthReport,
  HealthReportOptions,
  RemoteReport,
  ReportChannel,
  ReportEpisode,
  ReportFinding,
  ReportGlitch,
  ReportPeriodStats,
  ReportSeries,
  ReportStatus,
  ReportDiagnosis,
} from './report-types.js';
export { escapeHtml, reportHtml } from './report-html.js';
