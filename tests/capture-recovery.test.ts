/**
 * .sscap recovery as a whole: a damaged header never loses the records, and reading any file,
 * however crafted, takes time linear in its size.
 */
import { existsSync, readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { CaptureFormatError, captureChunks } from '../src/capture/model.js';
import { CaptureWriter } from '../src/capture/writer.js';
import { parseCapture } from '../src/capture/reader.js';
import { readCapture } from '../src/capture/sniff.js';
import type { Capture, ParsedCapture } from '../src/capture/model.js';
// A test hook, not part of the package: what the reader did, counted.
import { parseCaptureCounting } from '../src/capture/reader.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';

const PX4 = fileURLToPath(new URL('../../shared/captures/px4/', import.meta.url));
const px4Present = existsSync(PX4);
if (!px4Present) console.warn(`capture-recovery.test: skipping the PX4 capture: ${PX4} is absent (see shared/captures/README.md)`);

/** A .sscap as the recorder writes it: metadata with a note and ports, one record per 16 bytes of `bytes`. */
function record(capture: Capture, note: string): Uint8Array {
  const writer = new CaptureWriter({
    createdAt: '2026-11-23T04:30:00.000Z',
    baudRate: 115200,
    usbVendorId: 0x0403,
    usbProductId: 0x6001,
    source: 'webserial',
    ports: [{ name: 'satellite A', baudRate: 115200 }],
    note,
  });
  const parts = [writer.header(), writer.event('port opened', 0)];
  const times = capture.byteTimesUs;
  for (let at = 0; at < capture.bytes.length; at += 16) {
    const end = Math.min(at + 16, capture.bytes.length);
    parts.push(writer.data(capture.bytes.subarray(at, end), times?.[end - 1] ?? NaN));
  }
  return concatBytes(parts);
}

function simulated(): Capture {
  const sim = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 8 }, 2_000_000);
  return {
    kind: 'raw',
    meta: {},
    timing: 'per-byte',
    bytes: sim.bytes,
    byteTimesUs: sim.timesUs,
    chunkEnds: Uint32Array.of(sim.bytes.length),
    chunkTimesUs: Float64Array.of(NaN),
    chunkPorts: new Uint8Array(1),
    events: [],
    issues: [],
  };
}

const sources: [string, () => Capture][] = [['a simulated recording', simulated]];
if (px4Present) {
  const name = 'dsm_x_dx9_px4_binding_data.txt';
  sources.push([`the real PX4 capture ${name}`, () => readCapture(readFileSync(PX4 + name), name)]);
}

const chunksOf = (c: Capture): { bytes: number[]; timeUs: number; port: number }[] =>
  [...captureChunks(c)].map((k) => ({ bytes: [...k.bytes], timeUs: k.timeUs, port: k.port }));

const sameArray = (a: ArrayBufferView, b: ArrayBufferView): boolean =>
  Buffer.from(a.buffer, a.byteOffset, a.byteLength).equals(Buffer.from(b.buffer, b.byteOffset, b.byteLength));

/** The same data chunks (bytes, times, ports) and events: compared as arrays, since it runs thousands of times. */
function sameRecords(a: Capture, b: Capture): boolean {
  return (
    sameArray(a.bytes, b.bytes) &&
    sameArray(a.chunkEnds, b.chunkEnds) &&
    sameArray(a.chunkTimesUs, b.chunkTimesUs) &&
    sameArray(a.chunkPorts, b.chunkPorts) &&
    JSON.stringify(a.events) === JSON.stringify(b.events)
  );
}

describe.each(sources)('a .sscap of %s with one bit of its header flipped', (_, source) => {
  const file = record(source(), 'bench run 3: long lead to the satellite, gear down ✈');
  const whole = parseCapture(file);

  it('is an intact file to begin with', () => {
    expect(whole.issues).toEqual([]);
    expect(whole.chunkEnds.length).toBeGreaterThan(100);
  });

  it('still gives back every record, and reports the damaged header', () => {
    let metaKept = 0;
    for (let bit = 0; bit < whole.headerLength * 8; bit++) {
      const damaged = file.slice();
      damaged[bit >> 3]! ^= 1 << (bit & 7);
      let parsed: ParsedCapture;
      try {
        parsed = readCapture(damaged, 'recording.sscap') as ParsedCapture;
      } catch (error) {
        throw new Error(`bit ${bit} (byte ${bit >> 3}): ${String(error)}`);
      }
      expect(sameRecords(parsed, whole), `bit ${bit}: the records`).toBe(true);
      expect(parsed.issues[0], `bit ${bit}`).toMatchObject({ kind: 'bad-header', offset: 0, length: whole.headerLength });
      // Only the header is reported (and, at most, a metadata field a flip turned into the wrong type).
      expect(
        parsed.issues.slice(1).every((i) => i.kind === 'bad-meta'),
        `bit ${bit}`,
      ).toBe(true);
      // Damage in the fixed fields (signature, version, flags, length) or the CRC loses no metadata.
      const inMetadata = bit >> 3 >= 16 && bit >> 3 < whole.headerLength - 4;
      if (!inMetadata) expect(parsed.meta, `bit ${bit}`).toEqual(whole.meta);
      if (JSON.stringify(parsed.meta) === JSON.stringify(whole.meta)) metaKept++;
    }
    // The fixed fields and the CRC are 160 bits: their metadata is always kept.
    expect(metaKept).toBeGreaterThanOrEqual(160);
  });

  it('keeps every untouched record whatever bytes are damaged, header and records alike', () => {
    // Where each record starts and ends, from the intact file: the event, then one per data chunk.
    const ends: number[] = [];
    const starts: number[] = [];
    for (let p = whole.headerLength; p < file.length; ) {
      starts.push(p);
      p += 20 + new DataView(file.buffer, file.byteOffset).getUint32(p + 4, true);
      ends.push(p);
    }
    let random = 12345;
    const next = (n: number): number => {
      random = (Math.imul(random, 1103515245) + 12345) >>> 0;
      return (random >>> 8) % n;
    };
    let refused = 0;
    for (let run = 0; run < 400; run++) {
      const damaged = file.slice();
      // Half the runs replace a header byte (the signature included), all replace a few bytes anywhere.
      if (run % 2 === 0) damaged[next(whole.headerLength)] = next(256);
      for (let k = next(4); k > 0; k--) damaged[next(file.length)] = next(256);
      // Data records left untouched (the event record is the first one).
      const untouched = new Set<number>();
      for (let r = 1; r < starts.length; r++) {
        if (damaged.subarray(starts[r], ends[r]).every((b, i) => b === file[starts[r]! + i])) untouched.add(whole.chunkTimesUs[r - 1]!);
      }
      let parsed: ParsedCapture;
      try {
        parsed = parseCapture(damaged);
      } catch (error) {
        // Allowed only when the signature is beyond repair and nothing else proves a capture.
        expect(error, `run ${run}`).toBeInstanceOf(CaptureFormatError);
        expect(signatureBitErrors(damaged), `run ${run}`).toBeGreaterThan(2);
        refused++;
        continue;
      }
      const recovered = new Set(parsed.chunkTimesUs);
      for (const t of untouched) expect(recovered.has(t), `run ${run}: the record at ${t} µs`).toBe(true);
      if (damaged.subarray(0, whole.headerLength).some((b, i) => b !== file[i]))
        expect(
          parsed.issues.some((i) => i.kind === 'bad-header'),
          `run ${run}`,
        ).toBe(true);
    }
    // A signature beyond repair alone is recovered too (the header CRC or the first record proves the file).
    expect(refused).toBe(0);
  });

  it('also recognises the file by its content when a bit of its signature is flipped', () => {
    for (let bit = 0; bit < 64; bit++) {
      const damaged = file.slice();
      damaged[bit >> 3]! ^= 1 << (bit & 7);
      const parsed = readCapture(damaged);
      expect(parsed.kind, `bit ${bit}`).toBe('sscap');
      expect(sameRecords(parsed, whole), `bit ${bit}: the records`).toBe(true);
    }
  });
});

const SIGNATURE = [0x89, 0x53, 0x53, 0x43, 0x41, 0x50, 0x0d, 0x0a];

function signatureBitErrors(bytes: Uint8Array): number {
  let errors = 0;
  for (let i = 0; i < 8; i++) for (let x = (bytes[i]! ^ SIGNATURE[i]!) & 0xff; x !== 0; x &= x - 1) errors++;
  return errors;
}

// ---------------------------------------------------------------------------------------------
// Linear time on crafted input
// ---------------------------------------------------------------------------------------------

const SYNC = [0xa5, 0x5c];

/**
 * Crafted files of `size` bytes: a valid header, then record headers that fail their CRC,
 * followed by three genuine 1000-byte records that must still be found.
 */
const crafted: Record<string, (size: number) => Uint8Array> = {
  // A sync marker every 16 bytes, each announcing a record that runs to the end of the file.
  'markers every 16 bytes announcing records to the end of the file': (size) =>
    craft(size, (out, view, p, end) => {
      out.set([...SYNC, 1, 0], p);
      view.setUint32(p + 4, Math.max(0, end - p - 20), true);
      return 16;
    }),
  // Intact empty records between headers announcing long records, so the reader keeps starting over.
  'intact empty records between headers announcing long records': (size) =>
    craft(size, (out, view, p, end) => {
      out.set(new CaptureWriter().data(new Uint8Array(0), 0), p);
      out.set([...SYNC, 1, 0], p + 20);
      view.setUint32(p + 24, Math.max(0, end - p - 60), true);
      return 36;
    }),
  // A marker every 8 bytes announcing 128-byte records.
  'markers every 8 bytes announcing short records': (size) =>
    craft(size, (out, view, p) => {
      out.set([...SYNC, 2, 0], p);
      view.setUint32(p + 4, 128, true);
      return 8;
    }),
};

const GENUINE = [1, 2, 3].map((k) => new CaptureWriter().data(new Uint8Array(1000).fill(k), k));

function craft(size: number, fill: (out: Uint8Array, view: DataView, p: number, end: number) => number): Uint8Array {
  const header = new CaptureWriter({ source: 'crafted' }).header();
  const tail = concatBytes(GENUINE);
  const out = new Uint8Array(size);
  const view = new DataView(out.buffer);
  out.set(header);
  const end = size - tail.length;
  let p = header.length;
  while (p + 64 <= end) p += fill(out, view, p, end);
  out.set(tail, end);
  return out;
}

/** Everything the reader computed, in bytes: those run through the CRC table, plus 64 per CRC it combined. */
function work(file: Uint8Array): { total: number; capture: ParsedCapture } {
  const { capture, work } = parseCaptureCounting(file);
  return { total: work.crcBytes + 64 * work.crcCombines + work.probes, capture };
}

describe('reading a crafted .sscap', () => {
  it.each(Object.keys(crafted))('takes work linear in the file size: %s', (shape) => {
    const make = crafted[shape]!;
    const small = work(make(64 * 1024));
    const large = work(make(1024 * 1024));
    for (const { capture } of [small, large]) {
      // The genuine records at the end are found behind the crafted ones.
      expect(
        chunksOf(capture)
          .slice(-3)
          .map((c) => [c.timeUs, c.bytes.length, c.bytes[0]]),
      ).toEqual([
        [1, 1000, 1],
        [2, 1000, 2],
        [3, 1000, 3],
      ]);
    }
    // 16 times the size: linear work grows 16 times, quadratic 256 times.
    expect(large.total / small.total).toBeLessThan(20);
    expect(large.total).toBeLessThan(40 * 1024 * 1024);
  });

  it('checks a clean file once, byte by byte', () => {
    const file = record(simulated(), 'clean');
    const { work } = parseCaptureCounting(file);
    expect(work.crcCombines).toBe(0);
    expect(work.crcBytes).toBeLessThan(file.length);
  });
});
