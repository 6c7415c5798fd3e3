/**
 * satscope/capture: capture files. The columnar in-memory `Capture` every consumer reads, the
 * SatScope .sscap format (writer, salvaging reader), raw and Saleae CSV import, and
 * `readCapture`, which recognises any of them. This file names every public export.
 */
export {
  CaptureFormatError,
  captureChunks,
  chunkFirstByteUs,
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
export { crc32 } from './crc32.js';
export {
  type ChunkFacts,
  captureChunksByPort,
  captureFact,
  capturePortIndex,
  capturePorts,
  captureTimesInOrder,
  seedCaptureFact,
  seedChunkFacts,
} from './facts.js';
export { RecordTally } from './record-tally.js';
export {
  CAPTURE_FILE_EXTENSION,
  CAPTURE_FORMAT_VERSION,
  MAX_META_BYTES,
  MAX_RECORD_PAYLOAD,
  RECORD_OVERHEAD,
  RECORD_TYPE_DATA,
  RECORD_TYPE_EVENT,
  hasCaptureMagic,
} from './layout.js';
export { CaptureWriter, encodeCapture, type CaptureRecordInput } from './writer.js';
export { parseCapture, type ReadOptions } from './reader.js';
export {
  assembleParts,
  partColumns,
  planParts,
  readPart,
  type CaptureColumns,
  type CapturePart,
  type CapturePlan,
  type PartRead,
} from './parts.js';
export {
  type RecordSink,
  type SlicedFile,
  type WalkedRecords,
  type WalkOptions,
  recordTimeUs,
  walkDataRecords,
} from './record-walk.js';
export { CaptureBuilder } from './capture-builder.js';
export { importRaw } from './raw.js';
export { importSaleaeCsv } from './saleae.js';
export { readCapture } from './sniff.js';
