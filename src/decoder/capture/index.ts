/**
 * Capture files: the SatScope .sscap format (writer and reader), raw and Saleae CSV import,
 * and the columnar in-memory `Capture` every consumer uses. This file names every public export.
 */

export {
  CaptureFormatError,
  CaptureWriter,
  encodeCapture,
  parseCapture,
  captureChunks,
  capturePorts,
  crc32,
  hasCaptureMagic,
  CAPTURE_FILE_EXTENSION,
  CAPTURE_FORMAT_VERSION,
  MAX_META_BYTES,
  MAX_RECORD_PAYLOAD,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
} from './format.js';
export type {
  Capture,
  CaptureChunk,
  CaptureEvent,
  CaptureIssue,
  CaptureIssueKind,
  CaptureKind,
  CaptureMeta,
  CapturePortInfo,
  CaptureRecordInput,
  CaptureTiming,
  MetaScalar,
  ParsedCapture,
} from './format.js';
export { importRaw, importSaleaeCsv, readCapture } from './import.js';
export { utf8Decode, utf8Encode } from './utf8.js';
