/**
 * The .sscap index: written by CaptureWriter in segments and at close, read back and checked by
 * readCaptureIndex, stepped over by every reader of records. The truth each entry is held to is
 * the capture's own columns (parseCapture), never the writer's bookkeeping.
 */
import { describe, expect, it } from 'vitest';
import { type CaptureIndex, INDEX_STRETCH_US, type IndexEntry, readCaptureIndex, readLastTotals } from '../src/capture/capture-index.js';
import { crc32 } from '../src/capture/crc32.js';
import { REC_OFF_PORT, REC_OFF_TIME, REC_OFF_TYPE, RECORD_TYPE_DATA } from '../src/capture/layout.js';
import type { ParsedCapture } from '../src/capture/model.js';
import { parseCapture } from '../src/capture/reader.js';
import { CaptureWriter } from '../src/capture/writer.js';
import { concatBytes } from './bytes.js';

/** Deterministic bytes. */
function rng(seed: number): () => number {
  let x = seed >>> 0 || 1;
  return () => {
    x ^= x << 13;
    x ^= x >>> 17;
    x ^= x << 5;
    return (x >>> 0) / 2 ** 32;
  };
}

/**
 * `minutes` of two satellites on ports 0 and 2 (16-byte chunks every 11 ms and 22 ms, with
 * jitter), a port 5 with big chunks every 9.9 s, and events; closed unless `open`.
 */
function recording(minutes: number, open = false): { file: Uint8Array; segmentsAt: number[] } {
  const random = rng(7);
  const w = new CaptureWriter({ source: 'test' });
  const parts = [w.header()];
  const segmentsAt: number[] = [];
  let at = parts[0]!.length;
  const add = (bytes: Uint8Array, recordSize: number): void => {
    if (bytes.length > recordSize) segmentsAt.push(at + recordSize);
    parts.push(bytes);
    at += bytes.length;
  };
  const chunk = (n: number): Uint8Array => Uint8Array.from({ length: n }, () => Math.floor(random() * 256));
  const end = minutes * 60e6;
  for (let t = 1000, k = 0; t < end; t += 11_000, k++) {
    // Arrival jitter of up to 3 ms, in order across ports.
    const now = t + random() * 3000;
    add(w.data(chunk(16), now, 0), 36);
    if (k % 2 === 0) add(w.data(chunk(16), now + 500, 2), 36);
    if (k % 900 === 0) add(w.data(chunk(4096), now + 900, 5), 4116);
    if (k % 5000 === 1) {
      const text = `note ${k}`;
      add(w.event(text, now + 700, 0), 20 + text.length);
    }
  }
  if (!open) parts.push(w.close());
  return { file: concatBytes(parts), segmentsAt };
}

const readerOf = (file: Uint8Array) => (offset: number, length: number) => file.subarray(offset, Math.min(file.length, offset + length));

/** Each entry checked against the capture's columns: a data record of its port, its time, its stream offset and chunk. */
function checkEntries(file: Uint8Array, capture: ParsedCapture, entries: readonly IndexEntry[]): void {
  const view = new DataView(file.buffer, file.byteOffset, file.length);
  // The capture's chunks of each port in order, with their data offset in the port's stream.
  const byPort = new Map<number, { time: number; streamOffset: number }[]>();
  const portBytes = new Map<number, number>();
  for (let i = 0, start = 0; i < capture.chunkEnds.length; i++) {
    const port = capture.chunkPorts[i]!;
    const list = byPort.get(port) ?? [];
    const streamOffset = portBytes.get(port) ?? 0;
    list.push({ time: capture.chunkTimesUs[i]!, streamOffset });
    byPort.set(port, list);
    portBytes.set(port, streamOffset + capture.chunkEnds[i]! - start);
    start = capture.chunkEnds[i]!;
  }
  for (const e of entries) {
    expect(file[e.offset + REC_OFF_TYPE]).toBe(RECORD_TYPE_DATA);
    expect(file[e.offset + REC_OFF_PORT]).toBe(e.port);
    expect(Object.is(view.getFloat64(e.offset + REC_OFF_TIME, true), e.timeUs)).toBe(true);
    const truth = byPort.get(e.port)?.[e.chunk];
    expect(truth?.streamOffset).toBe(e.streamOffset);
    expect(Object.is(truth?.time, e.timeUs)).toBe(true);
  }
}

describe('the capture index', () => {
  const { file, segmentsAt } = recording(12);
  const capture = parseCapture(file);

  it('is stepped over by the reader: the same chunks and events, no issue', () => {
    expect(capture.issues).toEqual([]);
    expect(capture.events.map((e) => e.text).slice(0, 3)).toEqual(['note 1', 'note 5001', 'note 10001']);
    expect(segmentsAt.length).toBeGreaterThan(10);
  });

  it('says where each stretch of each port starts, and the span and counts, at close', async () => {
    const index = (await readCaptureIndex(file.length, capture.headerLength, readerOf(file))) as CaptureIndex;
    expect(index).not.toBeNull();
    expect(index.final).toBe(true);
    expect(index.coversTo).toBe(file.length);
    expect(index.dataRecords).toBe(capture.chunkEnds.length);
    expect(index.eventRecords).toBe(capture.events.length);
    const times = [...capture.chunkTimesUs].filter(Number.isFinite);
    expect(index.firstUs).toBe(times[0]);
    expect(index.lastUs).toBe(times.at(-1));
    // Each port's records and bytes, as the capture's columns count them.
    const ports = [0, 2, 5].map((port) => {
      let records = 0;
      let bytes = 0;
      for (let i = 0, start = 0; i < capture.chunkEnds.length; start = capture.chunkEnds[i]!, i++) {
        if (capture.chunkPorts[i] !== port) continue;
        records++;
        bytes += capture.chunkEnds[i]! - start;
      }
      return { port, records, bytes };
    });
    expect(index.ports).toEqual(ports);
    checkEntries(file, capture, index.entries);
    // Every port, from its first record, a stretch at least INDEX_STRETCH_US long and no longer
    // than that and a chunk period (port 5 sends every 9.9 s: each of its chunks starts one).
    for (const [port, period] of [
      [0, 14_000],
      [2, 25_000],
      [5, 9.9e6],
    ] as const) {
      const own = index.entries.filter((e) => e.port === port);
      expect(own[0]?.chunk).toBe(0);
      const gaps = own.slice(1).map((e, i) => e.timeUs - own[i]!.timeUs);
      expect(Math.max(...gaps)).toBeLessThan(Math.max(INDEX_STRETCH_US, period) + period);
      expect(Math.min(...gaps)).toBeGreaterThanOrEqual(port === 5 ? 9e6 : INDEX_STRETCH_US);
    }
  });

  it('starts a stretch every 64 KiB of a port where there are no times', async () => {
    const w = new CaptureWriter();
    const parts = [w.header()];
    for (let i = 0; i < 100; i++) parts.push(w.data(new Uint8Array(4096).fill(i), Number.NaN, 1));
    parts.push(w.close());
    const untimed = concatBytes(parts);
    const truth = parseCapture(untimed);
    const index = (await readCaptureIndex(untimed.length, truth.headerLength, readerOf(untimed))) as CaptureIndex;
    expect(index.entries.map((e) => e.chunk)).toEqual([0, 16, 32, 48, 64, 80, 96]);
    expect(index.entries.map((e) => e.streamOffset)).toEqual([0, 16, 32, 48, 64, 80, 96].map((c) => c * 4096));
    expect([index.firstUs, index.lastUs]).toEqual([Number.NaN, Number.NaN]);
    checkEntries(untimed, truth, index.entries);
  });

  it('keeps what the segments cover when the recording is cut short', async () => {
    const full = (await readCaptureIndex(file.length, capture.headerLength, readerOf(file))) as CaptureIndex;
    const open = recording(12, true).file;
    for (const cut of [open.length, open.length - 5, segmentsAt.at(-3)! + 3, segmentsAt[1]! + 100]) {
      const bytes = open.subarray(0, cut);
      const index = await readCaptureIndex(bytes.length, capture.headerLength, readerOf(bytes));
      expect(index?.final).toBe(false);
      // The last whole segment before the cut: everything before it is indexed, nothing after.
      const last = segmentsAt
        .filter((s) => s < cut)
        .map((s) => s + (file[s + 4]! | (file[s + 5]! << 8)) + 20)
        .filter((end) => end <= cut)
        .at(-1)!;
      expect(index?.coversTo).toBe(last);
      expect(index?.entries).toEqual(full.entries.filter((e) => e.offset < last));
    }
  });

  it('is none rather than wrong after damage: any bit flipped gives null or entries that hold', async () => {
    const small = recording(3).file;
    const truth = parseCapture(small);
    const full = (await readCaptureIndex(small.length, truth.headerLength, readerOf(small))) as CaptureIndex;
    const known = new Set(full.entries.map((e) => JSON.stringify(e)));
    const random = rng(3);
    // Bits inside the index segments, and anywhere in the file.
    const positions = [
      ...recording(3).segmentsAt.flatMap((s) => [s, s + 4, s + 16, s + 18, s + 24, s + 70, s + 90]),
      small.length - 9,
      small.length - 5,
    ];
    for (let i = 0; i < 300; i++) positions.push(Math.floor(random() * small.length));
    let none = 0;
    for (const p of positions) {
      const damaged = small.slice();
      damaged[p]! ^= 1 << Math.floor(random() * 8);
      const index = await readCaptureIndex(damaged.length, truth.headerLength, readerOf(damaged));
      if (index === null) {
        none++;
        continue;
      }
      for (const e of index.entries) expect(known.has(JSON.stringify(e))).toBe(true);
      expect(index.coversTo).toBeLessThanOrEqual(small.length);
    }
    expect(none).toBeGreaterThan(0);
  });

  it('gives its totals from the final segment alone, or for a file cut short the last segment and where it ends', async () => {
    const index = (await readCaptureIndex(file.length, capture.headerLength, readerOf(file))) as CaptureIndex;
    let reads = 0;
    const totals = await readLastTotals(file.length, capture.headerLength, (offset, length) => {
      reads++;
      return readerOf(file)(offset, length);
    });
    expect(totals).toMatchObject({ final: true, dataRecords: index.dataRecords, eventRecords: index.eventRecords, ports: index.ports });
    expect(reads).toBeLessThanOrEqual(3);
    const open = recording(12, true).file;
    const cut = (await readCaptureIndex(open.length, capture.headerLength, readerOf(open))) as CaptureIndex;
    expect(await readLastTotals(open.length, capture.headerLength, readerOf(open))).toMatchObject({
      final: false,
      coversTo: cut.coversTo,
      dataRecords: cut.dataRecords,
      ports: cut.ports,
    });
  });

  it('is none when its counts could not fit in the file, however intact its CRC', async () => {
    // The final segment's first port made to claim a terabyte, its CRC made right again.
    const forged = file.slice();
    const view = new DataView(forged.buffer);
    const length = view.getUint32(forged.length - 12, true);
    const at = forged.length - 20 - length;
    view.setFloat64(at + 16 + 56 + 8, 2 ** 40, true);
    view.setUint32(at + 16 + length, crc32(forged, at + 2, at + 16 + length), true);
    expect(await readCaptureIndex(forged.length, capture.headerLength, readerOf(forged))).toBeNull();
    expect(await readLastTotals(forged.length, capture.headerLength, readerOf(forged))).toBeNull();
  });

  it('gives up in bounded work on crafted bytes: tags everywhere, each pointing at a large record', async () => {
    // A header that claims a 4 MiB INDEX record, then "length, SSIX" over and over, each length
    // reaching back to that header: read and checked in full, each would cost 4 MiB.
    const size = 4 << 20;
    const crafted = new Uint8Array(size);
    const view = new DataView(crafted.buffer);
    crafted.set([0xa5, 0x5c, 3, 0], 100);
    view.setUint32(104, size - 200, true);
    let reads = 0;
    let readBytes = 0;
    for (let end = size; end > size - 200_000; end -= 12) {
      view.setUint32(end - 12, end - 20 - 100, true);
      crafted.set([0x53, 0x53, 0x49, 0x58], end - 8);
    }
    const started = performance.now();
    const index = await readCaptureIndex(size, 50, (offset, length) => {
      reads++;
      readBytes += Math.max(0, Math.min(length, size - offset));
      return crafted.subarray(offset, offset + length);
    });
    expect(index).toBeNull();
    expect(reads).toBeLessThan(300);
    expect(readBytes).toBeLessThan(6 << 20);
    expect(performance.now() - started).toBeLessThan(2000);
  });

  it('is absent from a file written without one, and from bytes that are no capture', async () => {
    const records = parseCapture(file);
    const header = file.subarray(0, records.headerLength);
    // The records up to the first segment: a file as version-1 writers made it.
    const old = file.subarray(0, segmentsAt[0]);
    expect(await readCaptureIndex(old.length, header.length, readerOf(old))).toBeNull();
    const noise = Uint8Array.from({ length: 5000 }, (_, i) => (i * 97) & 0xff);
    expect(await readCaptureIndex(noise.length, 0, readerOf(noise))).toBeNull();
    expect(await readCaptureIndex(0, 0, readerOf(new Uint8Array(0)))).toBeNull();
  });
});
