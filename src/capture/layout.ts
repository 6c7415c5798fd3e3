/**
 * The .sscap byte layout (docs/capture-format.md): the constants here are its single source of truth.
 */

/** Conventional file name extension. */
export const CAPTURE_FILE_EXTENSION = '.sscap';
/** The format version this code writes and reads. */
export const CAPTURE_FORMAT_VERSION = 1;

/**
 * File signature: 0x89 "SSCAP" CR LF. As in PNG, the high-bit first byte keeps text tools from
 * taking the file for text, and CR LF is mangled by any transfer that rewrites line endings,
 * so such damage is caught at the first bytes.
 */
export const MAGIC = [0x89, 0x53, 0x53, 0x43, 0x41, 0x50, 0x0d, 0x0a] as const;
export const MAGIC_SIZE = MAGIC.length;
/** Fixed part of the header: magic[8], u16 version, u16 flags, u32 metadata length. */
export const HEADER_FIXED_SIZE = 16;
export const OFF_VERSION = 8;
export const OFF_META_LENGTH = 12;
export const CRC_SIZE = 4;
/** Upper bound on the metadata block; a larger announced length means a damaged header. */
export const MAX_META_BYTES = 1 << 20;

/** Record sync marker. Only used to find records again after damage; the CRC confirms them. */
export const SYNC0 = 0xa5;
export const SYNC1 = 0x5c;
/** Record header: sync[2], u8 type, u8 port, u32 payload length, f64 time (µs). */
export const RECORD_HEADER_SIZE = 16;
export const REC_OFF_TYPE = 2;
export const REC_OFF_PORT = 3;
export const REC_OFF_LENGTH = 4;
export const REC_OFF_TIME = 8;
/** Bytes a record adds around its payload: header plus trailing CRC-32. */
export const RECORD_OVERHEAD = RECORD_HEADER_SIZE + CRC_SIZE;
/** Largest payload of one record: 16 MiB, the largest read buffer Web Serial allows. */
export const MAX_RECORD_PAYLOAD = 1 << 24;

export const RECORD_TYPE_DATA = 1;
export const RECORD_TYPE_EVENT = 2;
/** Where records start (capture-index.ts); readers that do not use it step over it. */
export const RECORD_TYPE_INDEX = 3;

/** Whether `type` is a record type this code knows (another is a damaged record). */
export function isRecordType(type: number | undefined): boolean {
  return type === RECORD_TYPE_DATA || type === RECORD_TYPE_EVENT || type === RECORD_TYPE_INDEX;
}

/** True when `bytes` starts with the .sscap signature. */
export function hasCaptureMagic(bytes: Uint8Array): boolean {
  if (bytes.length < MAGIC_SIZE) return false;
  for (let i = 0; i < MAGIC_SIZE; i++) if (bytes[i] !== MAGIC[i]) return false;
  return true;
}

/** True when `bytes` is shorter than the signature and matches its beginning. */
export function isCaptureMagicPrefix(bytes: Uint8Array): boolean {
  if (bytes.length === 0 || bytes.length >= MAGIC_SIZE) return false;
  for (let i = 0; i < bytes.length; i++) if (bytes[i] !== MAGIC[i]) return false;
  return true;
}
