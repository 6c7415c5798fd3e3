/**
 * Raw byte dumps (.bin): the bytes, with no recorded timing.
 */
import type { Capture } from './model.js';

/**
 * A raw byte dump (e.g. `cat /dev/ttyUSB0 > capture.bin`): one chunk on port 0, no timing.
 * `capture.bytes` is `bytes` itself (no copy). An empty input gives a capture with no chunks.
 * @throws {TypeError} when `bytes` is not a Uint8Array.
 */
export function importRaw(bytes: Uint8Array): Capture {
  if (!(bytes instanceof Uint8Array)) throw new TypeError('importRaw expects a Uint8Array');
  const chunks = bytes.length > 0 ? 1 : 0;
  return {
    kind: 'raw',
    meta: { source: 'raw' },
    timing: 'none',
    bytes,
    chunkEnds: Uint32Array.from(chunks ? [bytes.length] : []),
    chunkTimesUs: Float64Array.from(chunks ? [NaN] : []),
    chunkPorts: new Uint8Array(chunks),
    events: [],
    issues: [],
  };
}
