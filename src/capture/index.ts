/**
 * satscope/capture: capture files. The columnar in-memory `Capture` every consumer reads, the
 * SatScope .sscap format (writer, salvaging reader), raw and Saleae CSV import, and
 * `readCapture`, which recognises any of them. This file names every public export.
 */
export {
  CaptureFormatError,
  captureChunks,
  type Capture,
  type CaptureChunk,
  type CaptureEvent,
  type CaptureIssue,
  type CaptureIssueKind,
  type CaptureKind,
  type CaptureMeta,
  type CapturePortInfo,
  type CaptureTiming,
  type MetaScalar,
  type ParsedCapture,
} from './model.js';
export { capturePorts } from './facts.js';
export { CAPTURE_FILE_EXTENSION, CAPTURE_FORMAT_VERSION } from './layout.js';
export { CaptureWriter, encodeCapture, type CaptureRecordInput } from './writer.js';
export { parseCapture, type ReadOptions } from './reader.js';
export { importRaw } from './raw.js';
export { importSaleaeCsv } from './saleae.js';
export { readCapture } from './sniff.js';
