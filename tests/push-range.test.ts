/**
 * `pushRange(bytes, start, end, time)` is `push(bytes.subarray(start, end), time)` without the
 * view: the same frames, counters, events and format on damaged streams, with chunk times,
 * per-byte times (indexed like the bytes) and none, in chunks of every size (the hand copy for
 * short ones, `set` for long ones). The doctor's `bytes(…, start, end)` likewise leaves it in the
 * same state. A range that is not one of the bytes is refused.
 */
import { describe, expect, it } from 'vitest';
import { Doctor } from '../src/report/doctor.js';
import type { DecoderEvent } from '../src/decoder/types.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { ibusStream } from '../src/simulator/protocols.js';
import { receiveAs } from '../src/simulator/line.js';
import { concatBytes } from './bytes.js';
import { damagedStream } from './decoder-streams.js';

/** Chunk bounds of every size from 0 to 300 bytes, repeatable. */
function cuts(length: number, seed: number): [number, number][] {
  const out: [number, number][] = [];
  let s = seed;
  for (let i = 0; i < length; ) {
    s = (Math.imul(s, 1103515245) + 12345) >>> 0;
    const end = Math.min(length, i + ((s >>> 16) % 301));
    out.push([i, end]);
    i = end;
  }
  return out;
}

type Timing = 'chunk' | 'per-byte' | 'none';

/** Everything a decoder gives for a feed, as plain data. */
function decode(bytes: Uint8Array, times: Float64Array, timing: Timing, ranged: boolean): string {
  const events: string[] = [];
  const asJson = (e: DecoderEvent) => JSON.stringify(e, (_k, v: unknown) => (v instanceof Uint8Array ? Array.from(v) : v));
  const d = new SpektrumDecoder({ onEvent: (e) => events.push(asJson(e)) });
  const out: string[] = [];
  for (const [s, e] of cuts(bytes.length, 7)) {
    const time = timing === 'chunk' ? (times[e - 1] ?? NaN) : timing === 'per-byte' ? times : undefined;
    if (ranged) d.pushRange(bytes, s, e, time);
    else d.push(bytes.subarray(s, e), time instanceof Float64Array ? time.subarray(s, e) : time);
    for (let f = d.next(); f !== undefined; f = d.next())
      out.push(`${f.index} ${f.offset} ${f.timeUs} ${f.system} ${f.fades} ${Array.from(f.bytes)} ${JSON.stringify(d.stats)}`);
  }
  d.end();
  for (let f = d.next(); f !== undefined; f = d.next()) out.push(`${f.index} ${f.offset} ${f.timeUs}`);
  return JSON.stringify({ out, events, stats: d.stats, format: d.format });
}

describe('pushRange', () => {
  for (const name of ['damaged-line', 'dsmx-11ms-2048-external', 'dropouts-and-damage']) {
    const { bytes, times } = damagedStream(name, 3, 4_000_000);
    for (const timing of ['chunk', 'per-byte', 'none'] as const) {
      it(`${name}, ${timing} times: what push of the same views gives`, () => {
        const ranged = decode(bytes, times, timing, true);
        expect(ranged).toBe(decode(bytes, times, timing, false));
        expect(ranged.length).toBeGreaterThan(10_000);
      });
    }
  }

  it('refuses a range that is not one of the bytes', () => {
    const d = new SpektrumDecoder();
    const bytes = new Uint8Array(10);
    for (const [s, e] of [
      [-1, 2],
      [3, 2],
      [0, 11],
      [0.5, 2],
      [Number.NaN, 2],
    ] as const)
      expect(() => d.pushRange(bytes, s, e)).toThrow(TypeError);
    d.pushRange(bytes, 2, 2);
    expect(d.stats.bytes).toBe(0);
  });
});

describe("the doctor's bytes in ranges", () => {
  it('leave it as the same bytes as views do, foreign packets and unscanned bytes included', () => {
    const ibus = receiveAs(ibusStream({ durationUs: 2_000_000 }));
    const { bytes: sat, times: satTimes } = damagedStream('damaged-line', 5, 2_000_000);
    const bytes = concatBytes([sat, ibus.bytes]);
    const times = Float64Array.from([...satTimes, ...Array.from(ibus.timesUs, (t) => t + (satTimes.at(-1) ?? 0))]);
    for (const perByte of [false, true]) {
      const viewed = new Doctor({ timing: perByte ? 'per-byte' : 'per-chunk' });
      const ranged = new Doctor({ timing: perByte ? 'per-byte' : 'per-chunk' });
      cuts(bytes.length, 11).forEach(([s, e], i) => {
        const unscanned = i % 5 === 0 ? (e - s) >> 1 : 0;
        if (perByte) {
          viewed.bytes(0, bytes.subarray(s, e), times.subarray(s, e), unscanned);
          ranged.bytes(0, bytes, times, unscanned, s, e);
        } else {
          viewed.bytes(0, bytes.subarray(s, e), times[e - 1], unscanned);
          ranged.bytes(0, bytes, times[e - 1], unscanned, s, e);
        }
      });
      const cp = viewed.portCheckpoint(0);
      // Every byte counted and passed through the scanner, none twice.
      expect(cp?.activity).toBe(bytes.length);
      expect(cp?.scanner.n).toBe(bytes.length);
      expect(ranged.portCheckpoint(0)).toEqual(cp);
      expect(ranged.findings(times.at(-1) ?? 0)).toEqual(viewed.findings(times.at(-1) ?? 0));
    }
  });
});
