/**
 * A capture read a window at a time: what decoding needs of a capture (its chunks in file order,
 * with their ports and times) handed over a stretch at a time, so that a file is streamed, not
 * held. A capture in memory is one window; a file read by `satscope info`, `report` or `doctor`
 * is as many as it takes (src/cli/streamed-file.ts), each walk of its windows reading the file
 * again. Everything but the columns (kind, metadata, timing, events, issues, size) is known
 * before the first window: a reader finds it in a first, cheap pass over the file.
 */
import type { Capture } from './model.js';

/**
 * A stretch of a capture's chunks, laid out as a `Capture`'s columns are: chunk `i` of the
 * window is chunk `firstChunk + i` of the capture, its bytes `bytes[chunkEnds[i - 1] ?? 0 ..
 * chunkEnds[i])`. Only an untimed chunk or a chunk timed per byte may be cut between windows, and
 * then only where the decoding pass cuts it anyway (`CAPTURE_CUT_BYTES` from the chunk's start):
 * the window holds its part, and says how many of its bytes came before (`headBefore`, of chunk
 * 0) and come after (`tailAfter`, of the last chunk), so the chunk's place is known.
 */
export interface CaptureWindow {
  readonly bytes: Uint8Array;
  readonly chunkEnds: Uint32Array;
  readonly chunkTimesUs: Float64Array;
  readonly chunkPorts: Uint8Array;
  readonly byteTimesUs?: Float64Array | undefined;
  /** The capture's index of chunk 0. */
  readonly firstChunk: number;
  /** Offset of `bytes[0]` in the capture's data (all ports' bytes in file order). */
  readonly byteOffset: number;
  /** Bytes of chunk 0 in earlier windows (0: it starts here). */
  readonly headBefore: number;
  /** Bytes of the last chunk in later windows (0: it ends here). */
  readonly tailAfter: number;
}

/**
 * Where a long chunk may be cut between windows, in bytes from its start: a multiple of both
 * pieces the decoding pass pushes (`SLICE_BYTES` of a chunk timed per byte, 256, and the 64 KiB
 * of an untimed one), so a chunk cut there is pushed in the same pieces as one held whole.
 */
export const CAPTURE_CUT_BYTES = 1 << 16;

/** A capture that is not held: its facts, and its chunks a window at a time, walked as often as asked. */
export interface StreamedCapture {
  readonly kind: Capture['kind'];
  readonly meta: Capture['meta'];
  readonly timing: Capture['timing'];
  readonly events: Capture['events'];
  readonly issues: Capture['issues'];
  /** How many data bytes the capture holds (a held capture's `bytes.length`). */
  readonly dataBytes: number;
  /** The ports with data, in increasing order (`capturePorts`). */
  readonly ports: readonly number[];
  /** The capture's span (`captureSpan`), when the reader found it as it read (else a walk finds it). */
  readonly span?: { readonly startUs: number; readonly endUs: number };
  /** The capture's windows in file order, from its start; only `port`'s chunks are needed when given (others may be left out). */
  windows(port?: number): Iterable<CaptureWindow>;
}

/** A capture held in memory or read a window at a time: what the decoding surfaces (info, report, doctor) read. */
export type AnyCapture = Capture | StreamedCapture;

/** Whether `capture` is read a window at a time. */
export function isStreamed(capture: AnyCapture): capture is StreamedCapture {
  return 'windows' in capture;
}

/** How many data bytes the capture holds. */
export function captureDataBytes(capture: AnyCapture): number {
  return isStreamed(capture) ? capture.dataBytes : capture.bytes.length;
}

/** The capture's windows in file order (a held capture is one; `port`: only its chunks are needed). */
export function captureWindows(capture: AnyCapture, port?: number): Iterable<CaptureWindow> {
  if (isStreamed(capture)) return capture.windows(port);
  const { bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs } = capture;
  return [{ bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs, firstChunk: 0, byteOffset: 0, headBefore: 0, tailAfter: 0 }];
}
