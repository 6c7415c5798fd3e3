/**
 * A raw byte dump read a window at a time: the capture `importRaw` makes of it (one untimed chunk
 * on port 0), its chunk cut into windows of `PIECE_BYTES`, where the decoding pass cuts it anyway.
 * Nothing in a raw dump needs the rest of the file, so there is no first pass.
 */
import { type ByteFile, PIECE_BYTES } from './byte-file.js';
import type { CaptureWindow, StreamedCapture } from './capture-windows.js';

/** `file` as `importRaw` reads it, a window at a time. The file is read as its size says it is: a file that shrinks ends early. */
export function streamRaw(file: ByteFile): StreamedCapture {
  const size = file.size;
  return {
    kind: 'raw',
    meta: { source: 'raw' },
    timing: 'none',
    events: [],
    issues: [],
    dataBytes: size,
    ports: size > 0 ? [0] : [],
    span: { startUs: NaN, endUs: NaN },
    windows: () => rawWindows(file, size),
  };
}

function* rawWindows(file: ByteFile, size: number): Generator<CaptureWindow, void, undefined> {
  for (let at = 0; at < size; ) {
    const bytes = new Uint8Array(Math.min(PIECE_BYTES, size - at));
    const n = file.read(bytes, at);
    if (n === 0) return;
    yield {
      bytes: bytes.subarray(0, n),
      chunkEnds: Uint32Array.of(n),
      chunkTimesUs: Float64Array.of(NaN),
      chunkPorts: new Uint8Array(1),
      firstChunk: 0,
      byteOffset: at,
      headBefore: at,
      tailAfter: size - at - n,
    };
    at += n;
  }
}
