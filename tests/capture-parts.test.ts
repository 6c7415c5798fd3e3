/**
 * An intact .sscap read in parts (as `satscope` reads a big one on two threads) is the capture
 * `parseCapture` reads, to every column, event and header fact; a damaged one is never read in
 * parts (the plan or a part says so), so its salvage stays `parseCapture`'s.
 */
import { describe, expect, it } from 'vitest';
import { assembleParts, partColumns, planParts, readPart } from '../src/capture/parts.js';
import { CaptureWriter } from '../src/capture/writer.js';
import { parseCapture } from '../src/capture/reader.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';

const SECOND = 1_000_000;

/** Two remotes with port events among their chunks, as the page records them. */
function file(timed = true): Uint8Array {
  const ports = [simulate(preset('dsmx-11ms-2048-internal'), 3 * SECOND), simulate(preset('dsm2-22ms-1024-external'), 3 * SECOND)];
  const w = new CaptureWriter({ baudRate: 115200, source: 'test', ports: [{ name: 'A' }, { name: 'B' }] });
  const records = ports.flatMap((p, port) => usbChunks(p.bytes, p.timesUs).map((c) => ({ ...c, port })));
  records.sort((a, b) => a.timeUs - b.timeUs || a.port - b.port);
  const parts = [w.header(), w.event('port opened', 0, 0), w.event('port opened', 0, 1)];
  records.forEach((r, i) => {
    parts.push(w.data(r.bytes, timed ? r.timeUs : NaN, r.port));
    if (i % 97 === 0) parts.push(w.event(`note ${i}`, r.timeUs, r.port));
  });
  return concatBytes(parts);
}

/** The capture read in `count` parts, each part in turn (as threads would, in any order). */
function inParts(bytes: Uint8Array, count: number, shared = false) {
  const plan = planParts(bytes, count);
  if (plan === null) return null;
  const columns = partColumns(plan, shared);
  const reads = [...plan.parts].reverse().map((part) => readPart(bytes, part, columns));
  return assembleParts(plan, columns, reads.reverse());
}

describe('reading an .sscap in parts', () => {
  for (const timed of [true, false]) {
    for (const count of [1, 2, 3, 7]) {
      it(`${timed ? 'timed' : 'untimed'}, ${count} part(s): the capture parseCapture reads`, () => {
        const bytes = file(timed);
        const plan = planParts(bytes, count);
        expect(plan?.parts).toHaveLength(count);
        const got = inParts(bytes, count, count === 2);
        expect(got).not.toBeNull();
        expect({ ...got, bytes: [...(got?.bytes ?? [])] }).toEqual({ ...parseCapture(bytes), bytes: [...parseCapture(bytes).bytes] });
      });
    }
  }

  it('parts take about their shares of the file', () => {
    const bytes = file();
    const [a, b] = planParts(bytes, [2, 3])?.parts ?? [];
    const share = ((a?.to ?? 0) - (a?.from ?? 0)) / ((b?.to ?? 0) - (a?.from ?? 0));
    expect(share).toBeGreaterThan(0.39);
    expect(share).toBeLessThan(0.41);
    expect(() => planParts(bytes, [1, 0])).toThrow(TypeError);
    expect(() => planParts(bytes, [])).toThrow(TypeError);
  });

  it('parts meet at record boundaries and cover every record once', () => {
    const plan = planParts(file(), 4);
    const parts = plan?.parts ?? [];
    for (let i = 1; i < parts.length; i++) {
      expect(parts[i]?.from).toBe(parts[i - 1]?.to);
      expect(parts[i]?.chunk).toBeGreaterThanOrEqual(parts[i - 1]?.chunk ?? 0);
    }
    expect(parts.at(-1)?.to).toBe(file().length);
  });

  it('a damaged file is not read in parts: a flipped payload bit, bytes between records, a cut end, a damaged header', () => {
    const good = file();
    const flipped = good.slice();
    const bit = Math.floor(good.length * 0.8);
    flipped[bit] = (flipped[bit] ?? 0) ^ 0x10;
    expect(inParts(flipped, 2)).toBeNull();
    expect(parseCapture(flipped).issues.length).toBeGreaterThan(0);
    const plan = planParts(good, 2);
    const at = plan?.parts[1]?.from ?? 0;
    expect(planParts(concatBytes([good.subarray(0, at), Uint8Array.of(1, 2, 3), good.subarray(at)]), 2)).toBeNull();
    expect(planParts(good.subarray(0, good.length - 5), 2)).toBeNull();
    const header = good.slice();
    header[20] = (header[20] ?? 0) ^ 0xff;
    expect(planParts(header, 2)).toBeNull();
    expect(planParts(Uint8Array.of(1, 2, 3, 4), 2)).toBeNull();
  });
});
