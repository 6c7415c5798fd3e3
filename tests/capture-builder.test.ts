/**
 * A capture kept from the records of a walk (capture-builder.ts) is the capture parseCapture
 * reads from the same intact file: columns, events, timing and header, whatever the slices and
 * however well the columns' size was guessed.
 */
import { describe, expect, it } from 'vitest';
import { CaptureBuilder } from '../src/capture/capture-builder.js';
import type { ParsedCapture } from '../src/capture/model.js';
import { encodeCapture } from '../src/capture/writer.js';
import { parseCapture } from '../src/capture/reader.js';
import { walkDataRecords } from '../src/capture/record-walk.js';
import { longCapture } from './long-capture.js';

/** Data records of 1–300 bytes on two ports, events among them (two before the first chunk), untimed when `timed` is false. */
function file(timed: boolean): Uint8Array {
  const records: Parameters<typeof encodeCapture>[1][number][] = [
    { type: 'event', text: 'opened at 115200 baud', timeUs: timed ? 0 : Number.NaN, port: 0 },
    { type: 'event', text: 'ünïcode ✓', timeUs: timed ? 1 : Number.NaN, port: 1 },
  ];
  let seed = 11;
  const next = () => (seed = (seed * 1103515245 + 12345) >>> 0);
  for (let k = 0; k < 2000; k++) {
    if (k % 300 === 7) records.push({ type: 'event', text: `event ${k}`, timeUs: timed ? k * 100 : Number.NaN, port: k & 1 });
    const length = k % 500 === 250 ? 300 : 1 + (next() % 60);
    records.push({
      type: 'data',
      bytes: Uint8Array.from({ length }, () => next() & 0xff),
      timeUs: timed ? k * 100 + 3 : Number.NaN,
      port: k & 1,
    });
  }
  return encodeCapture({ baudRate: 115200, source: 'test', ports: [{ name: 'a' }, { name: 'b' }] }, records);
}

/**
 * The capture a builder keeps from a walk of `bytes`, its room guessed after the first slice when
 * `guess`, or made before the walk for `reserve` (chunks, data bytes).
 */
async function kept(bytes: Uint8Array, sliceBytes: number | undefined, guess: boolean, reserve?: [number, number]): Promise<ParsedCapture> {
  const builder = new CaptureBuilder();
  if (reserve !== undefined) builder.reserve(...reserve);
  const walked = await walkDataRecords(new Blob([bytes.slice()]), () => {}, {
    checked: () => true,
    eventsChecked: true,
    runs: (b, view, from, to) => builder.records(b, view, from, to),
    goOn: (to) => {
      if (guess) builder.expect(to, bytes.length);
      return true;
    },
    ...(sliceBytes === undefined ? {} : { sliceBytes }),
  });
  if (walked === null) throw new Error('the walk stopped');
  return builder.capture(walked.header);
}

/** Both captures with their columns as plain arrays, so that a difference reads as one. */
function plain(c: ParsedCapture) {
  return {
    ...c,
    bytes: Array.from(c.bytes),
    chunkEnds: Array.from(c.chunkEnds),
    chunkTimesUs: Array.from(c.chunkTimesUs),
    chunkPorts: Array.from(c.chunkPorts),
  };
}

describe('a capture kept from a walk of its records', () => {
  it('is the capture parseCapture reads, timed or not, for any slice size, guessed or grown', async () => {
    for (const timed of [true, false]) {
      const bytes = file(timed);
      const want = plain(parseCapture(bytes));
      expect(want.issues).toEqual([]);
      expect(want.timing).toBe(timed ? 'per-chunk' : 'none');
      expect(want.events.length).toBe(9);
      for (const slice of [7, 333, 4096, undefined])
        for (const guess of [false, true])
          expect({ timed, slice, guess, c: plain(await kept(bytes, slice, guess)) }).toEqual({ timed, slice, guess, c: want });
      // Room made before the walk: short, exact, or more than enough.
      const n = want.chunkEnds.length;
      for (const reserve of [
        [10, 100],
        [n, want.bytes.length],
        [2 * n, 3 * want.bytes.length],
      ] as [number, number][])
        expect({ timed, reserve, c: plain(await kept(bytes, 333, true, reserve)) }).toEqual({ timed, reserve, c: want });
    }
  });

  it('keeps a long capture of two remotes in columns the size of its own, not grown past them', async () => {
    const bytes = longCapture();
    const want = parseCapture(bytes);
    const got = await kept(bytes, 256 << 10, true);
    expect(plain(got)).toEqual(plain(want));
    // Sized from the first slice: the columns are views of buffers at most 3 % larger (or trimmed copies).
    expect(got.bytes.buffer.byteLength).toBeLessThanOrEqual(Math.ceil(want.bytes.length * 1.05));
    expect(got.chunkTimesUs.buffer.byteLength).toBeLessThanOrEqual(Math.ceil(want.chunkTimesUs.byteLength * 1.05));
  });
});
