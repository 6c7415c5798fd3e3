/**
 * A thin WHATWG-streams adapter over the push decoder:
 * `port.readable.pipeThrough(decodeStream())` gives a stream of frame snapshots.
 */
import { SpektrumDecoder, type DecoderOptions } from './decoder.js';
import { copyFrame, type FrameSnapshot } from './snapshot.js';

/** A chunk with its arrival time (µs), or per-byte times, for streams that carry timing. */
export interface TimedChunk {
  bytes: Uint8Array;
  time?: number | Float64Array;
}

/**
 * A TransformStream from raw bytes (or timed chunks) to owned frame snapshots. Untimed
 * `Uint8Array` chunks give frames with `timeUs` NaN. When the writable side closes, the bytes
 * still held are decided (`end()`).
 */
export function decodeStream(options?: DecoderOptions): TransformStream<Uint8Array | TimedChunk, FrameSnapshot> {
  const decoder = new SpektrumDecoder(options);
  const drain = (controller: TransformStreamDefaultController<FrameSnapshot>): void => {
    for (let frame = decoder.next(); frame !== undefined; frame = decoder.next()) controller.enqueue(copyFrame(frame));
  };
  return new TransformStream<Uint8Array | TimedChunk, FrameSnapshot>({
    transform(chunk, controller) {
      if (chunk instanceof Uint8Array) decoder.push(chunk);
      else decoder.push(chunk.bytes, chunk.time);
      drain(controller);
    },
    flush(controller) {
      decoder.end();
      drain(controller);
    },
  });
}
