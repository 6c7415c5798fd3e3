/** How the tests' bytes reach a decoder: as a USB adapter batches them, or with every byte's time. */
import type { Capture } from '../src/capture/index.js';

/** What a USB adapter delivers from per-byte times: whatever arrived in each 16 ms window, stamped at its end. */
export function usbChunks(bytes: Uint8Array, times: Float64Array, windowUs = 16_000): { bytes: Uint8Array; timeUs: number }[] {
  const out: { bytes: Uint8Array; timeUs: number }[] = [];
  let start = 0;
  for (let i = 0; i <= bytes.length; i++) {
    const deadline = Math.floor(times[start]! / windowUs) * windowUs + windowUs;
    if (i === bytes.length || times[i]! >= deadline) {
      if (i > start) out.push({ bytes: bytes.slice(start, i), timeUs: deadline });
      start = i;
    }
  }
  return out;
}

/** A capture with the time of every byte in one chunk, as a logic analyser records it (and `readCapture` returns a Saleae export). */
export function perByteCapture(sim: { bytes: Uint8Array; timesUs: Float64Array }): Capture {
  return {
    kind: 'saleae-csv',
    meta: {},
    timing: 'per-byte',
    bytes: sim.bytes,
    chunkEnds: Uint32Array.of(sim.bytes.length),
    chunkTimesUs: Float64Array.of(sim.timesUs[sim.timesUs.length - 1]!),
    chunkPorts: new Uint8Array(1),
    byteTimesUs: sim.timesUs,
    events: [],
    issues: [],
  };
}
