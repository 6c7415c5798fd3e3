import { existsSync, readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { describe, expect, it } from 'vitest';
import { CaptureFormatError, captureChunks } from '../src/capture/model.js';
import { CaptureWriter, encodeCapture } from '../src/capture/writer.js';
import { RECORD_OVERHEAD } from '../src/capture/layout.js';
import { capturePorts } from '../src/capture/facts.js';
import { crc32 } from '../src/capture/crc32.js';
import { importRaw } from '../src/capture/raw.js';
import { importSaleaeCsv } from '../src/capture/saleae.js';
import { parseCapture } from '../src/capture/reader.js';
import { readCapture } from '../src/capture/sniff.js';
import type { Capture, CaptureMeta } from '../src/capture/model.js';
import type { CaptureRecordInput } from '../src/capture/writer.js';
import { crcFollows } from '../src/capture/crc32.js';
import { concatBytes } from './bytes.js';

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

/** Deterministic pseudo-random bytes (mulberry32), so every run tests the same data. */
function randomBytes(length: number, seed: number): Uint8Array {
  let a = seed >>> 0;
  const out = new Uint8Array(length);
  for (let i = 0; i < length; i++) {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    out[i] = (t ^ (t >>> 14)) & 0xff;
  }
  return out;
}

const concat = (...parts: Uint8Array[]): Uint8Array => concatBytes(parts);

const ascii = (text: string): Uint8Array => new TextEncoder().encode(text);

/** Data chunks of a capture as plain values, for comparing with what was written. */
function chunksOf(capture: Capture): { bytes: number[]; timeUs: number; port: number }[] {
  return [...captureChunks(capture)].map((c) => ({ bytes: [...c.bytes], timeUs: c.timeUs, port: c.port }));
}

function expectFormatError(run: () => unknown, message: RegExp): void {
  let caught: unknown;
  try {
    run();
  } catch (e) {
    caught = e;
  }
  expect(caught).toBeInstanceOf(CaptureFormatError);
  expect((caught as Error).name).toBe('CaptureFormatError');
  expect((caught as Error).message).toMatch(message);
}

// A Spektrum DSMX 11 ms frame (internal remote, system 0xB2), as a satellite sends it.
const FRAME = Uint8Array.from([0x00, 0xb2, 0x0b, 0xff, 0x14, 0x00, 0x2c, 0x00, 0x1c, 0x00, 0x34, 0x00, 0x44, 0x00, 0x5c, 0x00]);

const META: CaptureMeta = {
  createdAt: '2025-03-01T12:00:00.000Z',
  baudRate: 115200,
  usbVendorId: 0x0403,
  usbProductId: 0x6001,
  source: 'webserial',
  ports: [{ name: 'satellite A' }, { name: 'satellite B', baudRate: 115200 }],
  note: 'bench test, ünïcödé ✈',
  firmware: 'v1.2',
  channels: 12,
  external: true,
  location: null,
};

const RECORDS: CaptureRecordInput[] = [
  { type: 'event', text: 'port opened', timeUs: 0 },
  { type: 'data', bytes: FRAME, timeUs: 11_000.5 },
  { type: 'data', bytes: FRAME.subarray(0, 7), timeUs: 12_345.25, port: 1 },
  { type: 'data', bytes: new Uint8Array(0), timeUs: 13_000 },
  { type: 'data', bytes: randomBytes(300, 1), timeUs: 22_000, port: 0 },
  { type: 'event', text: 'device lost 🔌', timeUs: 30_000, port: 1 },
  { type: 'data', bytes: FRAME.subarray(7), timeUs: 33_000, port: 255 },
];
const DATA_RECORDS = RECORDS.filter((r): r is Extract<CaptureRecordInput, { type: 'data' }> => r.type === 'data');

/** A small capture: the byte offset where each record starts, and the file. */
function smallCapture(): { file: Uint8Array; starts: number[]; headerLength: number } {
  const writer = new CaptureWriter({ createdAt: '2025-03-01T12:00:00.000Z', source: 'demo' });
  const header = writer.header();
  const records = [
    writer.event('port opened', 0),
    writer.data(FRAME, 11_000),
    writer.data(FRAME.subarray(0, 5), 22_000, 1),
    writer.data(FRAME.subarray(5), 22_100, 1),
    writer.event('device lost', 30_000),
    writer.data(FRAME, 33_000),
  ];
  const starts: number[] = [];
  let at = header.length;
  for (const r of records) {
    starts.push(at);
    at += r.length;
  }
  return { file: concat(header, ...records), starts, headerLength: header.length };
}

// ---------------------------------------------------------------------------------------------
// Building blocks
// ---------------------------------------------------------------------------------------------

describe('crc32', () => {
  it('gives the standard CRC-32 check value for "123456789"', () => {
    expect(crc32(ascii('123456789'))).toBe(0xcbf43926);
  });

  it('covers only the requested range', () => {
    expect(crc32(ascii('xx123456789yy'), 2, 11)).toBe(0xcbf43926);
  });

  it('agrees with the CRC bit by bit for every length and start, in a view of a larger buffer, with or without a DataView', () => {
    const bitwise = (b: Uint8Array): number => {
      let c = 0xffffffff;
      for (const x of b) {
        c ^= x;
        for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
      }
      return (c ^ 0xffffffff) >>> 0;
    };
    const whole = Uint8Array.from({ length: 200 }, (_, i) => (i * 73 + 11) & 0xff);
    const bytes = whole.subarray(3, 190);
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    for (let start = 0; start < 8; start++)
      for (let length = 0; length <= 100; length++) {
        const want = bitwise(bytes.subarray(start, start + length));
        expect([start, length, crc32(bytes, start, start + length), crc32(bytes, start, start + length, view)]).toEqual([
          start,
          length,
          want,
          want,
        ]);
      }
  });

  it('agrees with the CRC bit by bit over 64 kB of random bytes, enough to read every entry of its tables many times', () => {
    let seed = 3;
    const bytes = Uint8Array.from({ length: 1 << 16 }, () => {
      seed = (seed * 48271) % 2147483647;
      return seed & 0xff;
    });
    const view = new DataView(bytes.buffer);
    // The reference, a bit at a time, with the running register kept for each prefix.
    const prefix = new Uint32Array(bytes.length + 1);
    let c = 0xffffffff;
    bytes.forEach((x, i) => {
      c ^= x;
      for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
      prefix[i + 1] = (c ^ 0xffffffff) >>> 0;
    });
    expect(crc32(bytes)).toBe(prefix[bytes.length]);
    for (const end of [30, 1000, 4099, 65_535]) expect([end, crc32(bytes, 0, end, view)]).toEqual([end, prefix[end]]);
  });

  it('tells whether the CRC stored after a range (as records and headers store it) is the range’s, one wrong bit anywhere apart', () => {
    const whole = Uint8Array.from({ length: 120 }, (_, i) => (i * 151 + 7) & 0xff);
    for (let start = 0; start < 8; start++)
      for (let length = 0; length <= 100; length += 3) {
        const bytes = whole.slice();
        const view = new DataView(bytes.buffer);
        const end = start + length;
        view.setUint32(end, crc32(bytes, start, end), true);
        const stored = bytes.slice();
        expect([start, length, crcFollows(bytes, start, end, view)]).toEqual([start, length, true]);
        for (const at of [start, end - 1, end, end + 3]) {
          if (at < start) continue;
          bytes.set(stored);
          bytes[at] = (bytes[at] ?? 0) ^ 0x10;
          expect([start, length, at, crcFollows(bytes, start, end, view)]).toEqual([start, length, at, false]);
        }
      }
  });
});

// ---------------------------------------------------------------------------------------------
// .sscap writer and reader
// ---------------------------------------------------------------------------------------------

describe('.sscap round trip', () => {
  const file = encodeCapture(META, RECORDS);
  const parsed = parseCapture(file);

  it('gives back the metadata exactly, free-form fields included', () => {
    expect(parsed.meta).toEqual(META);
    expect(parsed.version).toBe(1);
  });

  it('gives back every data chunk byte-exact, with its time and port', () => {
    expect(chunksOf(parsed)).toEqual(DATA_RECORDS.map((r) => ({ bytes: [...r.bytes], timeUs: r.timeUs, port: r.port ?? 0 })));
    expect(parsed.bytes).toEqual(concat(...DATA_RECORDS.map((r) => r.bytes)));
    expect(parsed.timing).toBe('per-chunk');
    expect(parsed.issues).toEqual([]);
  });

  it('gives back the events with their place among the data chunks', () => {
    expect(parsed.events).toEqual([
      { text: 'port opened', timeUs: 0, port: 0, chunkIndex: 0 },
      { text: 'device lost 🔌', timeUs: 30_000, port: 1, chunkIndex: 4 },
    ]);
  });

  it('reports timing "none" when no chunk has a time', () => {
    const untimed = parseCapture(encodeCapture({}, [{ type: 'data', bytes: FRAME, timeUs: NaN }]));
    expect(untimed.timing).toBe('none');
    expect([...captureChunks(untimed)][0]?.time).toBeUndefined();
  });

  it('reads a file held in a view with a non-zero byte offset', () => {
    const padded = new Uint8Array(file.length + 10);
    padded.set(file, 7);
    expect(chunksOf(parseCapture(padded.subarray(7, 7 + file.length)))).toEqual(chunksOf(parsed));
  });

  it('costs RECORD_OVERHEAD bytes per record on top of the payload, and the index after them', () => {
    const w = new CaptureWriter(META);
    const header = w.header();
    const records = RECORDS.map((r) => (r.type === 'data' ? w.data(r.bytes, r.timeUs, r.port) : w.event(r.text, r.timeUs, r.port)));
    const payload =
      DATA_RECORDS.reduce((n, r) => n + r.bytes.length, 0) +
      new TextEncoder().encode('port opened').length +
      new TextEncoder().encode('device lost 🔌').length;
    const recorded = records.reduce((n, r) => n + r.length, 0);
    expect(recorded).toBe(payload + RECORDS.length * RECORD_OVERHEAD);
    // The final index: 20 bytes of record, 64 of its own, 24 a port and 32 an entry (one a port
    // here: the stretches are short).
    const ports = new Set(DATA_RECORDS.map((r) => r.port ?? 0)).size;
    expect(w.close().length).toBe(RECORD_OVERHEAD + 64 + (24 + 32) * ports);
    expect(file.length).toBe(header.length + recorded + RECORD_OVERHEAD + 64 + (24 + 32) * ports);
  });
});

describe('CaptureWriter', () => {
  it('streams exactly the bytes encodeCapture produces in one go', () => {
    const w = new CaptureWriter(META);
    const parts = [w.header()];
    for (const r of RECORDS) parts.push(r.type === 'data' ? w.data(r.bytes, r.timeUs, r.port) : w.event(r.text, r.timeUs, r.port));
    parts.push(w.close());
    expect(concat(...parts)).toEqual(encodeCapture(META, RECORDS));
    expect(() => w.data(FRAME, 0)).toThrow(/closed/);
    expect(() => w.close()).toThrow(/closed/);
  });

  it('hands out a header copy that callers cannot use to change later headers', () => {
    const w = new CaptureWriter(META);
    const first = w.header();
    first.fill(0);
    expect(w.header()).toEqual(encodeCapture(META, []).subarray(0, first.length));
  });

  it('rejects bad arguments with a TypeError', () => {
    const w = new CaptureWriter();
    expect(() => w.data([1, 2] as unknown as Uint8Array, 0)).toThrow(TypeError);
    expect(() => w.data(FRAME, Infinity)).toThrow(/timeUs/);
    expect(() => w.data(FRAME, '5' as unknown as number)).toThrow(TypeError);
    expect(() => w.data(FRAME, 0, 256)).toThrow(/port/);
    expect(() => w.data(FRAME, 0, 1.5)).toThrow(/port/);
    expect(() => w.data(FRAME, 0, -1)).toThrow(TypeError);
    expect(() => w.event(42 as unknown as string, 0)).toThrow(TypeError);
    expect(() => encodeCapture({}, [{ type: 'frame' } as unknown as CaptureRecordInput])).toThrow(TypeError);
  });

  it('rejects metadata that would not survive JSON, naming the field', () => {
    expect(() => new CaptureWriter({ baudRate: NaN })).toThrow(/meta\.baudRate/);
    expect(() => new CaptureWriter({ createdAt: 5 as unknown as string })).toThrow(/meta\.createdAt must be a string/);
    expect(() => new CaptureWriter({ extra: { nested: 1 } } as unknown as CaptureMeta)).toThrow(/meta\.extra/);
    expect(() => new CaptureWriter({ ports: [{ name: 'a', speed: [1] }] } as unknown as CaptureMeta)).toThrow(/meta\.ports\[0\]\.speed/);
    expect(() => new CaptureWriter(null as unknown as CaptureMeta)).toThrow(TypeError);
  });

  it('accepts NaN as an unknown time and negative times', () => {
    const parsed = parseCapture(encodeCapture({}, [{ type: 'data', bytes: FRAME, timeUs: -5.5 }]));
    expect(parsed.chunkTimesUs[0]).toBe(-5.5);
    expect(() => new CaptureWriter().data(FRAME, NaN)).not.toThrow();
  });
});

describe('.sscap damage recovery', () => {
  it('recovers exactly the complete records before any cut point and reports the cut tail', () => {
    const { file, starts, headerLength } = smallCapture();
    const whole = parseCapture(file);
    const recordEnds = [...starts.slice(1), file.length];
    for (let cut = headerLength; cut <= file.length; cut++) {
      const parsed = parseCapture(file.subarray(0, cut));
      const complete = recordEnds.filter((end) => end <= cut).length;
      // Records 0 and 4 are events; the others are data chunks 0–3.
      const completeChunks = [1, 2, 3, 5].filter((r) => r < complete).length;
      const completeEvents = [0, 4].filter((r) => r < complete).length;
      expect(parsed.chunkEnds.length, `cut at ${cut}`).toBe(completeChunks);
      expect(chunksOf(parsed)).toEqual(chunksOf(whole).slice(0, completeChunks));
      expect(parsed.events).toEqual(whole.events.slice(0, completeEvents));
      const tailStart = complete === 0 ? headerLength : recordEnds[complete - 1]!;
      if (tailStart === cut) {
        expect(parsed.issues, `cut at ${cut}`).toEqual([]);
      } else {
        expect(
          parsed.issues.map((i) => [i.kind, i.offset, i.length]),
          `cut at ${cut}`,
        ).toEqual([['truncated-record', tailStart, cut - tailStart]]);
        expect(parsed.issues[0]?.message).toMatch(/ends inside a record/);
      }
    }
  });

  it('throws CaptureFormatError, not something else, for a file cut inside the header', () => {
    const { file, headerLength } = smallCapture();
    for (let cut = 1; cut < headerLength; cut++) {
      expectFormatError(() => parseCapture(file.subarray(0, cut)), /truncated SatScope capture/);
    }
  });

  it('reports a record with any one damaged byte and recovers every other record', () => {
    const { file, starts } = smallCapture();
    const whole = chunksOf(parseCapture(file));
    const start = starts[2]!; // the 5-byte data chunk on port 1 (chunk 1)
    const end = starts[3]!;
    for (let at = start; at < end; at++) {
      const damaged = file.slice();
      damaged[at]! ^= 0x41;
      const parsed = parseCapture(damaged);
      expect(chunksOf(parsed), `byte ${at - start} damaged`).toEqual([whole[0], ...whole.slice(2)]);
      expect(parsed.events).toHaveLength(2);
      expect(
        parsed.issues.map((i) => [i.offset, i.length]),
        `byte ${at - start} damaged`,
      ).toEqual([[start, end - start]]);
      // A damaged sync marker looks like stray bytes; any other damaged byte is a damaged record.
      expect(parsed.issues[0]?.kind).toBe(at - start < 2 ? 'garbage' : 'bad-checksum');
    }
  });

  it('reports a record whose length runs past the end of the file as damaged when intact records follow', () => {
    const { file, starts } = smallCapture();
    const damaged = file.slice();
    new DataView(damaged.buffer).setUint32(starts[1]! + 4, 100_000, true);
    const parsed = parseCapture(damaged);
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([['bad-checksum', starts[1], starts[2]! - starts[1]!]]);
    expect(parsed.chunkEnds).toHaveLength(3);
  });

  it('skips garbage between, before and after records and reports each run exactly', () => {
    const { file, starts, headerLength } = smallCapture();
    // The middle run contains a fake record header (sync, type, length) to tempt the reader.
    const middle = concat(randomBytes(37, 7), Uint8Array.from([0xa5, 0x5c, 0x01, 0x00, 0x04, 0x00, 0x00, 0x00]), randomBytes(5, 8));
    const before = randomBytes(3, 9).map((b) => b & 0x7f); // no 0xA5: cannot look like a sync byte
    const after = Uint8Array.from([0x00, 0x01, 0x02]);
    expect(randomBytes(37, 7).includes(0xa5), 'test data: no sync byte in the first garbage run').toBe(false);
    const cut = starts[3]!;
    const mangled = concat(file.subarray(0, headerLength), before, file.subarray(headerLength, cut), middle, file.subarray(cut), after);
    const parsed = parseCapture(mangled);
    expect(chunksOf(parsed)).toEqual(chunksOf(parseCapture(file)));
    expect(parsed.events).toEqual(parseCapture(file).events);
    const shift = before.length;
    const middleAt = cut + shift;
    const afterAt = file.length + shift + middle.length;
    // The fake header with its failed CRC is reported as a damaged record of its own.
    const fakeAt = middleAt + 37;
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([
      ['garbage', headerLength, before.length],
      ['garbage', middleAt, 37],
      ['bad-checksum', fakeAt, middle.length - 37],
      ['garbage', afterAt, after.length],
    ]);
  });

  it('finds a record that starts right after a single stray byte', () => {
    const { file, starts } = smallCapture();
    const at = starts[2]!;
    const mangled = concat(file.subarray(0, at), Uint8Array.from([0x00]), file.subarray(at));
    const parsed = parseCapture(mangled);
    expect(chunksOf(parsed)).toEqual(chunksOf(parseCapture(file)));
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([['garbage', at, 1]]);
  });

  it('reports a damaged record and a cut-off last record as two issues', () => {
    const { file, starts } = smallCapture();
    const damaged = file.slice(0, file.length - 3);
    damaged[starts[4]! + 18]! ^= 0xff; // inside the "device lost" event's payload
    const parsed = parseCapture(damaged);
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([
      ['bad-checksum', starts[4], starts[5]! - starts[4]!],
      ['truncated-record', starts[5], damaged.length - starts[5]!],
    ]);
    expect(parsed.events.map((e) => e.text)).toEqual(['port opened']);
    expect(parsed.chunkEnds).toHaveLength(3);
  });

  it('keeps reading past a damaged header checksum when the metadata still parses', () => {
    const { file, headerLength } = smallCapture();
    const damaged = file.slice();
    const at = new TextDecoder().decode(damaged).indexOf('demo');
    damaged[at] = 'D'.charCodeAt(0);
    const parsed = parseCapture(damaged);
    expect(parsed.meta.source).toBe('Demo');
    expect(parsed.issues).toHaveLength(1);
    expect(parsed.issues[0]).toMatchObject({ kind: 'bad-header', offset: 0, length: headerLength });
    expect(parsed.issues[0]?.message).toMatch(/metadata may be wrong/);
    expect(chunksOf(parsed)).toEqual(chunksOf(parseCapture(file)));
  });

  it('repairs a damaged metadata length from where the records start, and keeps the metadata', () => {
    const { file, headerLength } = smallCapture();
    for (const bit of [0, 3, 9, 20, 31]) {
      const damaged = file.slice();
      damaged[12 + (bit >> 3)]! ^= 1 << (bit & 7);
      const parsed = parseCapture(damaged);
      expect(parsed.meta, `bit ${bit}`).toEqual(parseCapture(file).meta);
      expect(chunksOf(parsed), `bit ${bit}`).toEqual(chunksOf(parseCapture(file)));
      expect(parsed.headerLength).toBe(headerLength);
      expect(
        parsed.issues.map((i) => [i.kind, i.offset, i.length]),
        `bit ${bit}`,
      ).toEqual([['bad-header', 0, headerLength]]);
      expect(parsed.issues[0]?.message).toMatch(/metadata length \(\d+, not \d+\) is wrong; repaired/);
    }
  });

  it('loses only the metadata when it no longer reads as JSON, and says so', () => {
    const { file, headerLength } = smallCapture();
    const damaged = file.slice();
    damaged[16] = 0x7e; // '{' → '~'
    const parsed = parseCapture(damaged);
    expect(parsed.meta).toEqual({});
    expect(chunksOf(parsed)).toEqual(chunksOf(parseCapture(file)));
    expect(parsed.events).toEqual(parseCapture(file).events);
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([['bad-header', 0, headerLength]]);
    expect(parsed.issues[0]?.message).toMatch(/metadata cannot be read/);
  });

  it('finds the records after a header whose length and metadata are both damaged', () => {
    const { file, headerLength } = smallCapture();
    const damaged = file.slice();
    new DataView(damaged.buffer).setUint32(12, 0x7fffffff, true);
    damaged[20]! ^= 0x01;
    const parsed = parseCapture(damaged);
    expect(chunksOf(parsed)).toEqual(chunksOf(parseCapture(file)));
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([['bad-header', 0, headerLength]]);
    expect(parsed.issues[0]?.message).toMatch(new RegExp(`records start at offset ${headerLength}`));
  });

  it('keeps the metadata when both the metadata length and the first record are damaged', () => {
    const { file, starts, headerLength } = smallCapture();
    const damaged = file.slice();
    damaged[13]! ^= 0x10; // the metadata length, off by 4096
    damaged[starts[0]! + 17]! ^= 0x01; // the first record ("port opened")
    const parsed = parseCapture(damaged);
    expect(parsed.meta).toEqual(parseCapture(file).meta);
    expect(parsed.headerLength).toBe(headerLength);
    expect(chunksOf(parsed)).toEqual(chunksOf(parseCapture(file)));
    expect(parsed.events.map((e) => e.text)).toEqual(['device lost']);
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([
      ['bad-header', 0, headerLength],
      ['bad-checksum', starts[0], starts[1]! - starts[0]!],
    ]);
  });

  it('reads a version field damaged by one bit as version 1 and reports it', () => {
    const { file } = smallCapture();
    const damaged = file.slice();
    damaged[8]! ^= 0x02; // version 1 → 3, and the header CRC no longer matches
    const parsed = parseCapture(damaged);
    expect(parsed.version).toBe(1);
    expect(chunksOf(parsed)).toEqual(chunksOf(parseCapture(file)));
    expect(parsed.issues[0]?.message).toMatch(/version \(3\) is wrong; repaired/);
  });

  it('reads a capture whose signature has a flipped bit, even when it must be recognised by content', () => {
    const { file } = smallCapture();
    const damaged = file.slice();
    damaged[0]! ^= 0x80; // 0x89 → 0x09: no longer a high-bit first byte
    for (const capture of [parseCapture(damaged), readCapture(damaged), readCapture(damaged, 'capture.bin')]) {
      expect(capture.kind).toBe('sscap');
      expect(chunksOf(capture)).toEqual(chunksOf(parseCapture(file)));
      expect(capture.issues[0]?.message).toMatch(/signature is wrong; repaired/);
    }
  });

  it('recovers exactly the untouched records under random damage, and accounts for every other byte', () => {
    const { file, starts, headerLength } = smallCapture();
    const ends = [...starts.slice(1), file.length];
    const isData = [false, true, true, true, false, true];
    const whole = parseCapture(file);
    const wholeChunks = chunksOf(whole);
    for (let seed = 1; seed <= 300; seed++) {
      const noise = randomBytes(16, seed);
      const damaged = file.slice();
      const hits = 1 + ((noise[0] ?? 0) % 4);
      for (let k = 0; k < hits; k++) {
        const at = headerLength + ((((noise[1 + k] ?? 0) << 8) | (noise[5 + k] ?? 0)) % (file.length - headerLength));
        damaged[at] = noise[9 + k] ?? 0;
      }
      const touched = (r: number): boolean => damaged.subarray(starts[r], ends[r]).some((b, i) => b !== file[starts[r]! + i]);
      const parsed = parseCapture(damaged);
      let chunk = 0;
      const expected: typeof wholeChunks = [];
      let intactBytes = 0;
      for (let r = 0; r < starts.length; r++) {
        if (!touched(r)) intactBytes += ends[r]! - starts[r]!;
        if (isData[r]) {
          if (!touched(r)) expected.push(wholeChunks[chunk] as (typeof wholeChunks)[number]);
          chunk++;
        }
      }
      expect(chunksOf(parsed), `seed ${seed}`).toEqual(expected);
      const skipped = parsed.issues.reduce((n, i) => n + i.length, 0);
      expect(intactBytes + skipped, `seed ${seed}`).toBe(file.length - headerLength);
    }
  });
});

describe('.sscap metadata from other writers', () => {
  it('drops metadata fields of the wrong type, reports them, and keeps the rest', () => {
    // Build a header by hand, as a foreign or older writer might, with a correct CRC.
    const json = ascii('{"note":"ok","baudRate":"fast","nested":{"a":1},"ports":[{"name":"A","extra":[1]}]}');
    const header = new Uint8Array(16 + json.length + 4);
    const view = new DataView(header.buffer);
    header.set([0x89, 0x53, 0x53, 0x43, 0x41, 0x50, 0x0d, 0x0a]);
    view.setUint16(8, 1, true);
    view.setUint32(12, json.length, true);
    header.set(json, 16);
    view.setUint32(16 + json.length, crc32(header, 0, 16 + json.length), true);
    const record = new CaptureWriter().data(FRAME, 1);
    const parsed = parseCapture(concat(header, record));
    expect(parsed.meta).toEqual({ note: 'ok', ports: [{ name: 'A' }] });
    expect(parsed.issues).toHaveLength(1);
    expect(parsed.issues[0]).toMatchObject({ kind: 'bad-meta', offset: 16, length: json.length });
    expect(parsed.issues[0]?.message).toMatch(/meta\.baudRate must be a finite number.*meta\.nested.*meta\.ports\[0\]\.extra/);
    expect(chunksOf(parsed)).toEqual([{ bytes: [...FRAME], timeUs: 1, port: 0 }]);
  });
});

describe('.sscap header errors', () => {
  it('names a file with the wrong signature "not a SatScope capture" and shows its first bytes', () => {
    expectFormatError(() => parseCapture(ascii('PK\u0003\u0004 this is a zip file')), /^not a SatScope capture: .*starts with 50 4b 03 04/);
  });

  it('says an empty file is empty', () => {
    expectFormatError(() => parseCapture(new Uint8Array(0)), /empty/);
  });

  it('refuses a newer format version (an intact header) with a message naming both versions', () => {
    const file = encodeCapture(META, [{ type: 'data', bytes: FRAME, timeUs: 0 }]);
    const view = new DataView(file.buffer);
    const crcAt = 16 + view.getUint32(12, true);
    view.setUint16(8, 2, true);
    view.setUint32(crcAt, crc32(file, 0, crcAt), true);
    expectFormatError(() => parseCapture(file), /version 2.*version 1/);
  });

  it('keeps a capture without records whose metadata is not JSON, reporting the header', () => {
    const file = encodeCapture({ note: 'x' }, []);
    file[16] = 0x7e; // '{' → '~'
    const parsed = parseCapture(file);
    expect(parsed.meta).toEqual({});
    expect(parsed.chunkEnds).toHaveLength(0);
    expect(parsed.issues.map((i) => i.kind)).toEqual(['bad-header']);
  });

  it('repairs the metadata length of a capture without records from where its metadata ends', () => {
    const file = new CaptureWriter({ note: 'nothing recorded' }).header();
    new DataView(file.buffer).setUint32(12, 0x7fffffff, true);
    const parsed = parseCapture(file);
    expect(parsed.meta).toEqual({ note: 'nothing recorded' });
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([['bad-header', 0, file.length]]);
  });

  it('refuses a header with an impossible metadata length and damaged metadata when no record follows', () => {
    const file = new CaptureWriter({ note: 'nothing recorded' }).header();
    new DataView(file.buffer).setUint32(12, 0x7fffffff, true);
    file[20]! ^= 0x01;
    expectFormatError(() => parseCapture(file), /damaged SatScope capture header.*no intact record/);
  });

  it('reports metadata that is not a JSON object under an intact CRC, and keeps the records', () => {
    // A foreign writer's header: valid CRC, but the metadata is a JSON array.
    const json = ascii('[1,2]');
    const header = new Uint8Array(16 + json.length + 4);
    const view = new DataView(header.buffer);
    header.set([0x89, 0x53, 0x53, 0x43, 0x41, 0x50, 0x0d, 0x0a]);
    view.setUint16(8, 1, true);
    view.setUint32(12, json.length, true);
    header.set(json, 16);
    view.setUint32(16 + json.length, crc32(header, 0, 16 + json.length), true);
    const parsed = parseCapture(concat(header, new CaptureWriter().data(FRAME, 1)));
    expect(parsed.meta).toEqual({});
    expect(parsed.issues.map((i) => [i.kind, i.offset, i.length])).toEqual([['bad-meta', 16, json.length]]);
    expect(chunksOf(parsed)).toEqual([{ bytes: [...FRAME], timeUs: 1, port: 0 }]);
  });
});

// How fast it parses is measured by the benchmarks (bench:day's `satscope info`), not here.
describe('.sscap at length', () => {
  it('parses an hour of 11 ms frames (327 k records of 16 bytes)', () => {
    const frames = 327_273; // 3600 s / 11 ms
    const w = new CaptureWriter({ source: 'simulator' });
    const record = w.data(FRAME, 0);
    const file = new Uint8Array(w.header().length + frames * record.length);
    file.set(w.header());
    for (let i = 0; i < frames; i++) file.set(record, w.header().length + i * record.length);
    const parsed = parseCapture(file);
    expect(parsed.chunkEnds).toHaveLength(frames);
    expect(parsed.bytes.length).toBe(frames * 16);
  });
});

// ---------------------------------------------------------------------------------------------
// Capture model helpers and raw import
// ---------------------------------------------------------------------------------------------

describe('captureChunks and capturePorts', () => {
  const parsed = parseCapture(encodeCapture(META, RECORDS));

  it('walks only the chunks of the requested port, with the chunk time as push time', () => {
    const port1 = [...captureChunks(parsed, 1)];
    expect(port1.map((c) => [c.index, [...c.bytes], c.time])).toEqual([[1, [...FRAME.subarray(0, 7)], 12_345.25]]);
    expect(port1[0]?.byteTimesUs).toBeUndefined();
  });

  it('gives undefined as push time for a chunk without a time', () => {
    const untimed = parseCapture(encodeCapture({}, [{ type: 'data', bytes: FRAME, timeUs: NaN, port: 255 }]));
    const last = [...captureChunks(untimed, 255)];
    expect(last).toHaveLength(1);
    expect(last[0]?.time).toBeUndefined();
  });

  it('lists the ports that carry data', () => {
    expect(capturePorts(parsed)).toEqual([0, 1, 255]);
  });
});

describe('importRaw', () => {
  it('makes one untimed chunk of the whole file on port 0', () => {
    const bytes = concat(FRAME, FRAME);
    const capture = importRaw(bytes);
    expect(capture).toMatchObject({ kind: 'raw', timing: 'none', issues: [], events: [] });
    expect(chunksOf(capture)).toEqual([{ bytes: [...bytes], timeUs: NaN, port: 0 }]);
    expect([...captureChunks(capture)][0]?.time).toBeUndefined();
  });

  it('makes no chunks from an empty file', () => {
    expect(importRaw(new Uint8Array(0)).chunkEnds).toHaveLength(0);
  });
});

// ---------------------------------------------------------------------------------------------
// Saleae CSV
// ---------------------------------------------------------------------------------------------

const PX4 = fileURLToPath(new URL('../../shared/captures/px4/', import.meta.url));
const px4Present = existsSync(PX4);
if (!px4Present) console.warn(`capture.test: skipping the PX4 Saleae captures: ${PX4} is absent (see shared/captures/README.md)`);

describe.skipIf(!px4Present)('Saleae CSV: real PX4 captures (skipped when ../shared/captures is absent)', () => {
  const load = (name: string): Capture => readCapture(readFileSync(PX4 + name), name);

  it('reads dsm_x_data.txt: 1105 bytes, the first at 9 260 826 µs', () => {
    const capture = load('dsm_x_data.txt');
    expect(capture.kind).toBe('saleae-csv');
    expect(capture.timing).toBe('per-byte');
    expect(capture.bytes).toHaveLength(1105);
    expect(capture.byteTimesUs).toHaveLength(1105);
    expect(capture.byteTimesUs?.[0]).toBe(9_260_826);
    expect(capture.byteTimesUs?.[2]).toBe(9_261_000); // printed as 9.260999999999999
    expect([...capture.bytes.subarray(0, 4)]).toEqual([0x00, 0x00, 0x8c, 0x00]);
    expect(capture.issues).toEqual([]);
    expect(capture.chunkEnds).toEqual(Uint32Array.from([1105]));
    expect(capture.chunkTimesUs[0]).toBe(capture.byteTimesUs?.[1104]);
  });

  it('reads dsm_x_dx9_data.txt: 7296 bytes', () => {
    const capture = load('dsm_x_dx9_data.txt');
    expect(capture.bytes).toHaveLength(7296);
    expect(capture.issues).toEqual([]);
  });

  it('reads dsm_x_dx9_px4_binding_data.txt: 7280 bytes starting 3E B2', () => {
    const capture = load('dsm_x_dx9_px4_binding_data.txt');
    expect(capture.bytes).toHaveLength(7280);
    expect([...capture.bytes.subarray(0, 2)]).toEqual([0x3e, 0xb2]);
    expect(capture.byteTimesUs?.[0]).toBe(3400.8);
  });
});

describe('Saleae CSV: inline exports', () => {
  it('reads decimal values, CRLF line ends, a byte-order mark and trailing blank lines', () => {
    const csv = '\ufeffTime [s],Value,Parity Error,Framing Error\r\n0.5,0,,\r\n0.5000868,178,,\r\n0.5001736,0x0B,,\r\n\r\n\r\n';
    const capture = importSaleaeCsv(ascii(csv));
    expect([...capture.bytes]).toEqual([0, 178, 11]);
    expect([...(capture.byteTimesUs ?? [])]).toEqual([500_000, 500_086.8, 500_173.6]);
    expect(capture.issues).toEqual([]);
  });

  it('accepts a string as well as bytes', () => {
    const capture = importSaleaeCsv('Time [s],Value\n1,0x41\n');
    expect([...capture.bytes]).toEqual([0x41]);
  });

  it('reads a Logic 2 export by column name, with quoted headers and analyser names', () => {
    const csv =
      'name,type,start_time,duration,"data"\n"Async Serial","data",0.00123,8.68e-05,0x3E\n"Async Serial","data",1.5e-3,8.68e-05,0xB2\n';
    const capture = importSaleaeCsv(csv);
    expect([...capture.bytes]).toEqual([0x3e, 0xb2]);
    expect([...(capture.byteTimesUs ?? [])]).toEqual([1230, 1500]);
    expect(capture.meta.ports).toEqual([{ name: 'Async Serial' }]);
  });

  it('unescapes doubled quotes in quoted fields', () => {
    const csv = 'name,type,start_time,duration,data\n"Sat ""A""","data",1,0,0x10\n"Sat ""A""",data,2,0,0x11\n';
    const capture = importSaleaeCsv(csv);
    expect([...capture.bytes]).toEqual([0x10, 0x11]);
    expect(capture.meta.ports).toEqual([{ name: 'Sat "A"' }]);
  });

  it('turns each Logic 2 analyser into its own port', () => {
    const csv = 'name,type,start_time,duration,data\nA,data,1,0,1\nB,data,2,0,2\nA,data,3,0,3\n';
    const capture = importSaleaeCsv(csv);
    expect([...captureChunks(capture)].map((c) => [c.port, [...c.bytes], [...(c.byteTimesUs ?? [])]])).toEqual([
      [0, [1, 3], [1e6, 3e6]],
      [1, [2], [2e6]],
    ]);
    expect(capture.meta.ports).toEqual([{ name: 'A' }, { name: 'B' }]);
  });

  it('skips a malformed row and reports it with its line number', () => {
    const csv = 'Time [s],Value,Parity Error,Framing Error\n0.1,0x01,,\n0.2,zz,,\nbanana\n0.4,0x04,,\n';
    const capture = importSaleaeCsv(csv);
    expect([...capture.bytes]).toEqual([1, 4]);
    expect(capture.issues.map((i) => [i.kind, i.line])).toEqual([
      ['malformed-row', 3],
      ['malformed-row', 4],
    ]);
    expect(capture.issues[0]?.message).toMatch(/^line 3: value "zz"/);
    expect(capture.issues[1]).toMatchObject({ offset: csv.indexOf('banana'), length: 'banana'.length });
  });

  it('leaves out bytes flagged with a parity or framing error and reports them', () => {
    const csv = 'Time [s],Value,Parity Error,Framing Error\n0.1,0x01,,\n0.2,0x02,Error,\n0.3,0x03,,Error\n0.4,0x04,,\n';
    const capture = importSaleaeCsv(csv);
    expect([...capture.bytes]).toEqual([1, 4]);
    expect(capture.issues.map((i) => [i.kind, i.line])).toEqual([
      ['flagged-byte', 3],
      ['flagged-byte', 4],
    ]);
    expect(capture.issues[0]?.message).toMatch(/Parity Error/);
    expect(capture.issues[1]?.message).toMatch(/Framing Error/);
  });

  it('reports a Logic 2 character-rendered value as unsupported', () => {
    const csv = 'name,type,start_time,duration,"data"\n"Async Serial","data",0.1,8.68e-05,">"\n"Async Serial","data",0.2,8.68e-05,0x3E\n';
    const capture = importSaleaeCsv(csv);
    expect([...capture.bytes]).toEqual([0x3e]);
    expect(capture.issues).toHaveLength(1);
    expect(capture.issues[0]).toMatchObject({ kind: 'malformed-row', line: 2 });
    expect(capture.issues[0]?.message).toMatch(/">" is not a byte in hex/);
  });

  it('refuses a file with a header but no usable row, saying why', () => {
    expectFormatError(() => importSaleaeCsv('Time [s],Value\n'), /no usable bytes: there are no rows/);
    expectFormatError(
      () => importSaleaeCsv('Time [s],Value\n0.1,hello\n'),
      /no usable bytes: all 1 row\(s\) were rejected \(first: line 2/,
    );
  });

  it('refuses text without a recognisable header', () => {
    expectFormatError(() => importSaleaeCsv('a,b,c\n1,2,3\n'), /not a Saleae async-serial CSV: line 1/);
    expectFormatError(() => importSaleaeCsv('\n\n'), /no header line/);
  });
});

// ---------------------------------------------------------------------------------------------
// readCapture
// ---------------------------------------------------------------------------------------------

describe('readCapture', () => {
  it('reads a .sscap file whatever it is called', () => {
    const capture = readCapture(encodeCapture(META, RECORDS), 'recording.dat');
    expect(capture.kind).toBe('sscap');
    expect(capture.meta).toEqual(META);
  });

  it('reads a Saleae CSV by its header', () => {
    expect(readCapture(ascii('Time [s],Value,Parity Error,Framing Error\n0.1,0x01,,\n'), 'x.txt').kind).toBe('saleae-csv');
    expect(readCapture(ascii('\ufeffname,type,start_time,duration,"data"\r\n"S","data",0.1,0,0x01\r\n')).kind).toBe('saleae-csv');
  });

  it('reads binary content as a raw dump', () => {
    const capture = readCapture(concat(FRAME, FRAME));
    expect(capture.kind).toBe('raw');
    expect(capture.bytes).toHaveLength(32);
  });

  it('reads binary content without any NUL byte as a raw dump too', () => {
    const noisy = randomBytes(256, 3).map((b) => b | 1);
    expect(readCapture(noisy).kind).toBe('raw');
  });

  it('reads a .bin file as raw even when its bytes happen to be text', () => {
    expect(readCapture(ascii('{"hello": 1}'), 'dump.bin').kind).toBe('raw');
  });

  it('refuses text that is not a Saleae export, quoting its first line', () => {
    expectFormatError(
      () => readCapture(ascii('{"hello": 1}\n'), 'settings.json'),
      /settings\.json.*looks like text but not a Saleae async-serial CSV.*"\{\\"hello\\": 1\}"/,
    );
    expectFormatError(() => readCapture(ascii('# SatScope\n\nA decoder.\n')), /looks like text but not a Saleae async-serial CSV/);
  });

  it('refuses an empty file', () => {
    expectFormatError(() => readCapture(new Uint8Array(0), 'empty.bin'), /^empty file \(empty\.bin\)/);
  });

  it('refuses a file named .sscap without the signature', () => {
    expectFormatError(() => readCapture(concat(FRAME), 'broken.sscap'), /^not a SatScope capture/);
  });

  it('says a file cut inside the signature is a truncated capture', () => {
    expectFormatError(() => readCapture(encodeCapture({}, []).subarray(0, 5)), /truncated SatScope capture/);
  });
});
