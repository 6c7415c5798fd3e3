/**
 * satscope: decode Spektrum satellite ("remote receiver") serial streams.
 * Every public name is exported here and only here.
 */
export { SpektrumDecoder, type DecoderOptions } from './decoder.js';
export {
  HOLD_MIN_US, LEDGER_WINDOW_US, LinkMonitor, PERIOD_SNAP_US, holdThresholdUs, isFrameInterval, nominalPeriodOf,
  type LinkEpisode, type LinkOptions, type LinkState, type LinkStats, type MissedBasis,
} from './link.js';
export { LinkSeries, monitorWithSeries } from './series.js';
export { copyFrame, type ChannelValue, type FrameSnapshot } from './snapshot.js';
export { decodeStream, type TimedChunk } from './stream.js';
export type {
  DecodedFrame, DecoderEvent, DecoderStats, FormatInfo, HeaderMode, HeaderReading, RemoteKind, ResolutionReason, VtxControl,
} from './types.js';
export {
  BAUD_RATE, BYTE_TIME_US, CHANNEL_COUNT, CHANNEL_NAMES, channelResolution, EMPTY_SLOT, FAILSAFE_TIMEOUT_US, FRAME_SIZE,
  FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US, PULSE_MAX_US, PULSE_MIN_US, USB_CHUNK_JITTER_US, SYSTEM_DSM2_11MS_2048, SYSTEM_DSM2_22MS_1024, SYSTEM_DSMX_11MS_2048,
  SYSTEM_DSMX_22MS_2048, SYSTEM_TYPES, XPLUS_FIRST, XPLUS_LAST, channelName, servoToMicros, servoToPercent,
  systemInfo, type Resolution, type SystemInfo,
} from './spec.js';
export {
  CaptureFormatError, CaptureWriter, captureChunks, capturePorts, encodeCapture, importRaw, importSaleaeCsv,
  parseCapture, readCapture, CAPTURE_FILE_EXTENSION, CAPTURE_FORMAT_VERSION,
  type Capture, type CaptureChunk, type CaptureEvent, type CaptureIssue, type CaptureIssueKind, type CaptureKind,
  type CaptureMeta, type CapturePortInfo, type CaptureRecordInput, type CaptureTiming, type ParsedCapture,
} from '../capture/index.js';
export {
  captureSpan, decodeCapture, resolutionKey, summarizeCapture, timingJitterUs,
  type CaptureSummary, type ChannelSummary, type DecodeCaptureOptions,
} from './summary.js';
export {
  healthReport, reportHtml, REPORT_THRESHOLDS,
  type FindingCode, type FindingLevel, type HealthReport, type HealthReportOptions, type RemoteReport, type ReportChannel,
  type ReportEpisode, type ReportFinding, type ReportGlitch, type ReportPeriodStats, type ReportSeries, type ReportStatus,
  type ReportDiagnosis, type ReportThresholds,
} from './report.js';
