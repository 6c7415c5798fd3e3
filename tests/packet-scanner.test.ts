/**
 * The doctor's foreign-packet scanner: every packet the simulator's streams send is found once,
 * whatever the chunking, and a satellite's frames are scanned too (chance packets in them are
 * possible: the scanner does not skip bytes the decoder took as frames).
 */
import fc from 'fast-check';
import { describe, expect, it } from 'vitest';
import { PacketScanner, type PacketKind } from '../src/report/doctor-line.js';
import { crsfStream, ibusStream, sbusStream, srxl2Stream, srxlV1Stream } from '../src/simulator/protocols.js';
import { preset } from '../src/simulator/presets.js';
import { receiveAs } from '../src/simulator/line.js';
import { simulate } from '../src/simulator/simulator.js';

const SECOND = 1_000_000;

/** Every packet reported, as "kind@endIndex", with the bytes pushed in pieces cut at `cuts`. */
function scan(bytes: Uint8Array, cuts: number[] = []): string[] {
  const found: string[] = [];
  const scanner = new PacketScanner((kind: PacketKind, end: number) => found.push(`${kind}@${end}`));
  let from = 0;
  for (const cut of [...cuts].sort((a, b) => a - b)) {
    scanner.push(bytes.subarray(from, cut));
    from = cut;
  }
  scanner.push(bytes.subarray(from));
  return found;
}

const count = (found: string[], kind: PacketKind): number => found.filter((f) => f.startsWith(`${kind}@`)).length;

describe('PacketScanner', () => {
  it('finds every IBUS, SRXL v1, SRXL2 and CRSF packet of a stream, each at its last byte', () => {
    const cases: [PacketKind, Uint8Array, number][] = [
      ['ibus', ibusStream({ durationUs: SECOND }).bytes, 32],
      ['srxl-v1', srxlV1Stream({ durationUs: SECOND }).bytes, 18],
      ['srxl2', receiveAs(srxl2Stream({ durationUs: SECOND })).bytes, 0],
      ['crsf', crsfStream({ durationUs: SECOND }).bytes, 0],
    ];
    for (const [kind, bytes, size] of cases) {
      const found = scan(bytes);
      expect(count(found, kind), kind).toBeGreaterThan(50);
      if (size > 0) {
        expect(count(found, kind), kind).toBe(bytes.length / size);
        expect(found.filter((f) => f.startsWith(`${kind}@`))[0]).toBe(`${kind}@${size - 1}`);
      }
    }
  });

  it('finds SBUS packets by their header, footer and the next header', () => {
    const { bytes } = sbusStream({ durationUs: SECOND });
    // Each packet but the last is confirmed by the next one's header.
    expect(count(scan(bytes), 'sbus')).toBe(bytes.length / 25 - 1);
  });

  it('reports the same packets however the bytes are chunked', () => {
    const mixed = new Uint8Array([
      ...ibusStream({ durationUs: 0.1 * SECOND }).bytes,
      ...simulate(preset('damaged-line'), 0.2 * SECOND).bytes,
      ...srxlV1Stream({ durationUs: 0.1 * SECOND }).bytes,
      ...receiveAs(srxl2Stream({ durationUs: 0.1 * SECOND })).bytes,
      ...crsfStream({ durationUs: 0.1 * SECOND }).bytes,
    ]);
    const whole = scan(mixed);
    expect(whole.length).toBeGreaterThan(20);
    fc.assert(
      fc.property(fc.uniqueArray(fc.integer({ min: 1, max: mixed.length - 1 }), { maxLength: 60 }), (cuts) => {
        expect(scan(mixed, cuts)).toEqual(whole);
      }),
      { numRuns: 60 },
    );
    const oneByOne = Array.from({ length: mixed.length - 1 }, (_, i) => i + 1);
    expect(scan(mixed, oneByOne)).toEqual(whole);
  });

  it('keeps at most 16 candidates open: a run of start bytes evicts the oldest, and packets after it are still found', () => {
    const ibus = ibusStream({ durationUs: 0.05 * SECOND }).bytes;
    const srxl = srxlV1Stream({ durationUs: 0.05 * SECOND }).bytes;
    const bytes = new Uint8Array([...new Uint8Array(40).fill(0xa5), ...srxl, ...new Uint8Array(40).fill(0xc8), ...ibus]);
    const found = scan(bytes);
    expect(count(found, 'srxl-v1')).toBe(srxl.length / 18);
    expect(count(found, 'ibus')).toBe(ibus.length / 32);
    expect(scan(bytes, [17, 41, 100, 300])).toEqual(found);
  });
});
