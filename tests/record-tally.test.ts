/**
 * A capture's chunk facts and span found as its records are walked (record-tally.ts, with the
 * analysis's spanBetween), as a long capture's replay finds them: for any capture and any slice
 * size, what the passes over the columns of the capture the file reads as find. Each port's
 * chunk counts and chunk numbers, whether the times never go back, and the span with its events.
 */
import { describe, expect, it } from 'vitest';
import { captureSpan, spanBetween } from '../src/report/capture-span.js';
import { BYTE_TIME_US } from '../src/decoder/spec.js';
import { RecordTally } from '../src/capture/record-tally.js';
import { captureChunksByPort, capturePortIndex, capturePorts, captureTimesInOrder } from '../src/capture/facts.js';
import { encodeCapture } from '../src/capture/writer.js';
import { parseCapture } from '../src/capture/reader.js';
import { walkDataRecords } from '../src/capture/record-walk.js';
import { longCapture } from './long-capture.js';

/**
 * A made-up capture (seed `seed`): up to 300 data records on a few of ports 0, 1, 5, 200 and 255
 * (or none), 1–64 bytes (some empty, some 700: a first byte dated far back), times in order with
 * equal ones, or with a step back, a NaN, or none at all; events here and there, some before the
 * first chunk or after the last, some untimed (all in an untimed capture).
 */
function made(seed: number): Uint8Array {
  let s = seed * 2654435761 + 1;
  const next = (n: number): number => {
    s = (s * 1103515245 + 12345) >>> 0;
    return s % n;
  };
  const ports = [0, 1, 5, 200, 255].filter(() => next(2) === 0);
  const count = ports.length === 0 ? 0 : next(300);
  const kind = seed % 5; // 0, 1: in order; 2: a step back; 3: a NaN; 4: untimed
  const records: Parameters<typeof encodeCapture>[1][number][] = [];
  let t = 1e6 + next(1e6);
  const event = (timeUs: number) =>
    records.push({ type: 'event', text: `event ${records.length}`, timeUs: kind === 4 ? Number.NaN : timeUs, port: ports[0] ?? 0 });
  if (next(3) === 0) event(t - 5e6);
  for (let k = 0; k < count; k++) {
    t += next(4) === 0 ? 0 : next(20_000);
    let timeUs = kind === 4 ? Number.NaN : t;
    if (kind === 2 && k === count >> 1) timeUs = t - 30_000;
    if (kind === 3 && k === count >> 2) timeUs = Number.NaN;
    const roll = next(40);
    const length = roll === 0 ? 0 : roll === 1 ? 700 : 1 + next(64);
    records.push({ type: 'data', bytes: new Uint8Array(length).fill(k & 0xff), timeUs, port: ports[next(ports.length)] ?? 0 });
    if (next(25) === 0) event(next(5) === 0 ? Number.NaN : t + next(3) * 1000);
  }
  if (next(3) === 0) event(t + 9e6);
  // An empty chunk last, later than any byte: it has no byte, so it is not in the span.
  if (count > 0 && next(3) === 0)
    records.push({ type: 'data', bytes: new Uint8Array(0), timeUs: kind === 4 ? Number.NaN : t + 9e6, port: ports[0] ?? 0 });
  return encodeCapture({ baudRate: 115200 }, records);
}

async function tallied(bytes: Uint8Array, sliceBytes: number | undefined, reserve?: number[]) {
  const tally = new RecordTally(BYTE_TIME_US);
  if (reserve !== undefined) tally.reserve(reserve);
  await walkDataRecords(new Blob([bytes.slice()]), () => {}, {
    runs: (b, view, from, to) => tally.records(b, view, from, to),
    ...(sliceBytes === undefined ? {} : { sliceBytes }),
  });
  const { chunksByPort, timesInOrder, portIndex, firstUs, lastUs } = tally.facts();
  return {
    chunksByPort: Array.from(chunksByPort),
    timesInOrder,
    portIndex: portIndex.map((a) => Array.from(a)),
    span: spanBetween(firstUs, lastUs),
  };
}

describe('the chunk facts and span of a capture found as its records are walked', () => {
  it('are those of the passes over the capture the file reads as, for any slice size', async () => {
    const seen = { outOfOrder: 0, untimed: 0, ports: new Set<number>(), empty: 0, eventOutside: 0, badTime: 0 };
    for (let seed = 0; seed < 60; seed++) {
      const bytes = made(seed);
      const capture = parseCapture(bytes);
      // A chunk time that is NaN among times is damage the reader steps over (time-rule.ts): the
      // capture's times are then not the file's, and the replay seeds no fact the walk found.
      if (capture.issues.length > 0) {
        expect(capture.issues.map((i) => i.kind)).toEqual(['bad-time']);
        seen.badTime++;
        continue;
      }
      const want = {
        chunksByPort: Array.from(captureChunksByPort(capture)),
        timesInOrder: captureTimesInOrder(capture),
        portIndex: capturePortIndex(capture).map((a) => Array.from(a)),
        span: captureSpan(capture),
      };
      for (const slice of [40, 1000, undefined])
        expect({ seed, slice, ...(await tallied(bytes, slice)) }).toEqual({ seed, slice, ...want });
      if (!want.timesInOrder) seen.outOfOrder++;
      if (Number.isNaN(want.span.startUs)) seen.untimed++;
      for (const [p, n] of want.chunksByPort.entries()) if (n > 0) seen.ports.add(p);
      if (capture.chunkEnds.length === 0) seen.empty++;
      const times = capture.events.map((e) => e.timeUs);
      if (times.includes(want.span.startUs) || times.includes(want.span.endUs)) seen.eventOutside++;
    }
    // The made-up captures hold what the facts turn on.
    expect(seen.outOfOrder).toBeGreaterThan(10);
    expect(seen.untimed).toBeGreaterThan(5);
    expect([...seen.ports].sort((a, b) => a - b)).toEqual([0, 1, 5, 200, 255]);
    expect(seen.empty).toBeGreaterThan(0);
    expect(seen.eventOutside).toBeGreaterThan(5);
    expect(seen.badTime).toBeGreaterThan(5);
  });

  it('and of a long recording, each port’s chunk numbers grown as they come, with or without a guess of how many', async () => {
    const bytes = longCapture();
    const capture = parseCapture(bytes);
    const index = capturePortIndex(capture);
    expect(capturePorts(capture).length).toBeGreaterThan(1);
    expect(Math.min(...capturePorts(capture).map((p) => index[p]?.length ?? 0))).toBeGreaterThan(20_000);
    const want = {
      chunksByPort: Array.from(captureChunksByPort(capture)),
      timesInOrder: captureTimesInOrder(capture),
      portIndex: index.map((a) => Array.from(a)),
      span: captureSpan(capture),
    };
    // Without a guess of each port's chunks, with one that falls short, one that is right, and
    // ones that miss a port or make room on a port that has none.
    const counts = want.chunksByPort;
    const first = capturePorts(capture)[0] ?? 0;
    const guesses = {
      none: undefined,
      short: counts.map((n) => n >> 3),
      right: counts,
      onePort: counts.map((n, p) => (p === first ? n : 0)),
      elsewhere: counts.map((n) => (n > 0 ? 0 : 500)),
    };
    for (const [guess, reserve] of Object.entries(guesses))
      expect({ guess, ...(await tallied(bytes, 1 << 16, reserve)) }).toEqual({ guess, ...want });
  });
});
