/** How the tests' bytes reach a decoder: as a USB adapter batches them, or with every byte's time. */
import { CaptureWriter } from '../src/capture/writer.js';
import { readCapture } from '../src/capture/sniff.js';
import type { Capture } from '../src/capture/model.js';
import { concatBytes } from './bytes.js';
import { parseCapture } from '../src/capture/reader.js';
import { RECORD_HEADER_SIZE, RECORD_TYPE_INDEX, REC_OFF_TYPE } from '../src/capture/layout.js';
import { recordSize } from '../src/capture/records.js';
import type { SimChunk } from '../src/simulator/simulator.js';

/** A stream with every byte's time, as the simulator makes it. */
export type Stream = { bytes: Uint8Array; timesUs: Float64Array };

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

/**
 * Streams of several ports recorded as the page records them, as the bytes of an .sscap: USB
 * chunks (16 ms unless `windowUs` says) merged in time order, each port named "port N" and
 * opened at 0 (`timed: false`: without any time).
 */
export function recordingFile(ports: Stream[], timed = true, windowUs = 16_000): Uint8Array {
  const w = new CaptureWriter({ baudRate: 115200, source: 'test', ports: ports.map((_, i) => ({ name: `port ${i}` })) });
  const records = ports.flatMap((p, port) => usbChunks(p.bytes, p.timesUs, windowUs).map((c) => ({ ...c, port })));
  records.sort((a, b) => a.timeUs - b.timeUs || a.port - b.port);
  const parts = [w.header(), ...ports.map((_, port) => w.event('port opened', timed ? 0 : NaN, port))];
  for (const r of records) parts.push(w.data(r.bytes, timed ? r.timeUs : NaN, r.port));
  return concatBytes(parts);
}

/** `recordingFile`, read. */
export function recording(ports: Stream[], timed = true, windowUs = 16_000): Capture {
  return readCapture(recordingFile(ports, timed, windowUs), 'recording.sscap');
}

/** Streams one after another on one line, each shifted to start 20 ms after the last ended. */
export function oneAfterAnother(streams: Stream[]): Stream {
  const times: number[] = [];
  let offset = 0;
  for (const s of streams) {
    const t0 = s.timesUs[0] ?? 0;
    for (const t of s.timesUs) times.push(offset + t - t0);
    offset = (times.at(-1) ?? 0) + 20_000;
  }
  return { bytes: concatBytes(streams.map((s) => s.bytes)), timesUs: Float64Array.from(times) };
}

/** `sim` with channel slot 0 of each frame in `frames` pushed 600 steps (about 44 % travel) away, for that frame only. */
export function withSpikes(sim: SimChunk, frames: number[]): SimChunk {
  const bytes = sim.bytes.slice();
  for (const k of frames) {
    const f = sim.truth?.frames[k];
    if (f === undefined) throw new Error(`no frame ${k}`);
    const at = f.offset + 2;
    const w = ((bytes[at] ?? 0) << 8) | (bytes[at + 1] ?? 0);
    const pos = w & 0x7ff;
    const spiked = (w & ~0x7ff) | (pos > 1024 ? pos - 600 : pos + 600);
    bytes[at] = spiked >> 8;
    bytes[at + 1] = spiked & 0xff;
  }
  return { ...sim, bytes };
}

/** An intact .sscap `file` without its index records: one written before the index, or by another writer. */
export function withoutIndex(file: Uint8Array): Uint8Array {
  const view = new DataView(file.buffer, file.byteOffset, file.byteLength);
  const header = parseCapture(file).headerLength;
  const parts: Uint8Array[] = [file.subarray(0, header)];
  for (let p = header; p + RECORD_HEADER_SIZE <= file.length; ) {
    const total = recordSize(file, view, p);
    if (total < 0) throw new Error(`no record at offset ${p}`);
    if (file[p + REC_OFF_TYPE] !== RECORD_TYPE_INDEX) parts.push(file.subarray(p, p + total));
    p += total;
  }
  return concatBytes(parts);
}
