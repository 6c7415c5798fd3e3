/**
 * A time that jumps is damage (src/capture/time-rule.ts): every reader steps over it, says so
 * once in the capture's issues, and keeps every byte, so that a capture with one bad time reads
 * as the same capture without it, on every surface.
 */
import { describe, expect, it } from 'vitest';
import { assembleParts, partColumns, planParts, readPart } from '../src/capture/parts.js';
import type { Capture } from '../src/capture/model.js';
import { CaptureWriter } from '../src/capture/writer.js';
import { crc32 } from '../src/capture/crc32.js';
import { parseCapture } from '../src/capture/reader.js';
import { RECORD_OVERHEAD } from '../src/capture/layout.js';
import { readCapture } from '../src/capture/sniff.js';
import { LinkSeries, monitorWithSeries } from '../src/report/series.js';
import { summarizeCapture } from '../src/report/summary.js';
import { MAX_SERIES_BINS } from '../src/report/series.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';

const sim = simulate(preset('dsmx-11ms-2048-internal'), 3_000_000);
const CHUNKS = usbChunks(sim.bytes, sim.timesUs);

/** The simulated stream as the page records it, each chunk's time passed through `time` (its index, its true time). */
function recorded(time: (k: number, t: number) => number, events: { at: number; timeUs: number }[] = []): Uint8Array {
  const w = new CaptureWriter({ source: 'test' });
  const parts = [w.header()];
  CHUNKS.forEach((c, k) => {
    for (const e of events) if (e.at === k) parts.push(w.event('port opened', e.timeUs));
    parts.push(w.data(c.bytes, time(k, c.timeUs)));
  });
  return concatBytes(parts);
}

const CLEAN = parseCapture(recorded((_, t) => t));

/** What every surface prints from a capture: `summarizeCapture`'s figures. */
function figures(capture: Capture) {
  const s = summarizeCapture(capture, { port: 0 });
  return {
    frames: s.decoder.frames,
    missed: s.link.lostFrames,
    holds: s.episodes.filter((e) => e.kind === 'hold').length,
    failsafes: s.episodes.filter((e) => e.kind === 'failsafe').length,
    durationUs: s.durationUs,
    fadeRate: s.link.fadeRate,
  };
}

const badTimes = (c: Capture) => c.issues.filter((i) => i.kind === 'bad-time');

describe('one bad chunk time in an .sscap', () => {
  const cases: [string, number][] = [
    ['1e18 µs', 1e18],
    ['1e13 µs', 1e13],
    ['-Infinity', Number.NEGATIVE_INFINITY],
    ['Infinity', Number.POSITIVE_INFINITY],
    ['NaN', Number.NaN],
    ['-1e13 µs', -1e13],
    ['ten seconds back', -10e6],
  ];
  for (const [name, bad] of cases) {
    it(`${name}: keeps every byte, dates the chunk at the next time in line and says so once`, () => {
      const k = 40;
      // The writer refuses infinities: they are written by hand into a good record's time.
      const file = recorded((i, t) =>
        i === k ? (Number.isFinite(bad) && bad < 0 && bad > -1e12 ? t + bad : Number.isFinite(bad) ? bad : -5) : t,
      );
      if (!Number.isFinite(bad)) setTime(file, k, bad);
      const capture = parseCapture(file);
      expect(capture.bytes).toEqual(CLEAN.bytes);
      const want = CLEAN.chunkTimesUs.slice();
      want[k] = want[k + 1]!;
      expect(capture.chunkTimesUs).toEqual(want);
      expect(capture.timing).toBe('per-chunk');
      expect(badTimes(capture)).toHaveLength(1);
      expect(badTimes(capture)[0]?.message).toMatch(/1 of \d+ chunk times jump out of line .*chunk 40.*every byte is kept/);
      expect(figures(capture)).toEqual(figures(CLEAN));
    });
  }

  it('NaN on every 10th chunk: the figures of the clean capture, one issue', () => {
    const capture = parseCapture(recorded((k, t) => (k % 10 === 9 ? Number.NaN : t)));
    expect(capture.bytes).toEqual(CLEAN.bytes);
    expect(badTimes(capture)).toHaveLength(1);
    expect(figures(capture)).toEqual(figures(CLEAN));
    expect(figures(capture).missed).toBeLessThan(3);
  });

  it('reads the same through every reader: parseCapture, readCapture and the reading in parts', () => {
    const file = recorded((k, t) => (k === 7 ? 1e18 : k === 90 ? Number.NaN : t));
    const whole = parseCapture(file);
    const plan = planParts(file, 3);
    expect(plan).not.toBeNull();
    if (plan === null) return;
    const columns = partColumns(plan, false);
    const inParts = assembleParts(
      plan,
      columns,
      plan.parts.map((part) => readPart(file, part, columns)),
    );
    for (const c of [readCapture(file, 'x.sscap'), inParts]) {
      expect(c?.chunkTimesUs).toEqual(whole.chunkTimesUs);
      expect(c?.issues).toEqual(whole.issues);
    }
  });
});

/** Sets the time of data record `k` (0-based) of a file `recorded` made, fixing its CRC. */
function setTime(file: Uint8Array, k: number, timeUs: number): void {
  const view = new DataView(file.buffer, file.byteOffset, file.byteLength);
  let p = new CaptureWriter({ source: 'test' }).header().length;
  for (let i = 0; i < k; i++) p += RECORD_OVERHEAD + view.getUint32(p + 4, true);
  view.setFloat64(p + 8, timeUs, true);
  const end = p + RECORD_OVERHEAD - 4 + view.getUint32(p + 4, true);
  // The CRC-32 covers type through payload.
  view.setUint32(end, crc32(file, p + 2, end), true);
}

describe('a clock that steps', () => {
  it('two days forward for good: the stream goes on from the time before, with no gap made up, said once', () => {
    const step = 2 * 86_400e6;
    const capture = parseCapture(recorded((k, t) => (k >= 50 ? t + step : t)));
    const want = CLEAN.chunkTimesUs.slice();
    const back = want[50]! - want[49]!;
    for (let k = 50; k < want.length; k++) want[k] = want[k]! - back;
    expect(capture.chunkTimesUs).toEqual(want);
    expect(badTimes(capture).map((i) => i.message)).toEqual([expect.stringMatching(/clock steps once .*chunk 50, 2\.00 days forward/)]);
    expect(figures(capture).failsafes).toBe(0);
  });

  it('an hour forward is a gap, not damage: a failsafe that happened', () => {
    const capture = parseCapture(recorded((k, t) => (k >= 50 ? t + 3600e6 : t)));
    expect(badTimes(capture)).toEqual([]);
    expect(figures(capture).failsafes).toBe(1);
  });

  it('a logic analyser pre-trigger start (negative times in line) is no damage', () => {
    const capture = parseCapture(recorded((_, t) => t - 1e6));
    expect(badTimes(capture)).toEqual([]);
    expect(capture.chunkTimesUs[0]).toBeLessThan(0);
  });
});

describe('events', () => {
  it('an event at 1e18 µs is dated at the data before it, and the span stays the data', () => {
    const capture = parseCapture(recorded((_, t) => t, [{ at: 30, timeUs: 1e18 }]));
    expect(capture.events[0]?.timeUs).toBe(CLEAN.chunkTimesUs[29]);
    expect(badTimes(capture)).toHaveLength(1);
    expect(figures(capture)).toEqual(figures(CLEAN));
  });
});

describe('Saleae CSV', () => {
  const rows = (bad: (i: number) => string | null) =>
    `Time [s],Value,Parity Error,Framing Error\n${Array.from(sim.bytes.subarray(0, 4000), (b, i) => `${bad(i) ?? (sim.timesUs[i]! / 1e6).toFixed(9)},0x${b.toString(16).padStart(2, '0')},,`).join('\n')}\n`;
  const clean = readCapture(new TextEncoder().encode(rows(() => null)));

  for (const bad of ['1e18', '-Infinity', 'NaN', 'Infinity', 'soon']) {
    it(`one row at ${bad} s: every byte kept, dated at the next byte in line, said once`, () => {
      const capture = readCapture(new TextEncoder().encode(rows((i) => (i === 1000 ? bad : null))));
      expect(capture.bytes).toEqual(clean.bytes);
      const want = clean.byteTimesUs!.slice();
      want[1000] = want[1001]!;
      expect(capture.byteTimesUs).toEqual(want);
      expect(capture.issues.map((i) => i.kind)).toEqual(['bad-time']);
      expect(badTimes(capture).map((i) => i.message)).toEqual([expect.stringMatching(/^port 0: 1 of 4000 byte times jump out of line/)]);
      expect(figures(capture)).toEqual(figures(clean));
    });
  }

  it('every row absurd: read untimed, not stretched over the absurd span', () => {
    const capture = readCapture(new TextEncoder().encode(rows((i) => `${1e15 * (i % 2 ? 1 : -1)}`)));
    expect(capture.timing).toBe('none');
    expect(capture.byteTimesUs).toBeUndefined();
    expect(capture.bytes).toEqual(clean.bytes);
  });
});

describe('LinkSeries with absurd times passed straight in', () => {
  it('allocates by bins it may hold, not by the span, and counts what fell past them', () => {
    const series = new LinkSeries(100_000);
    const link = monitorWithSeries({}, series);
    const started = performance.now();
    series.missed(0, 1e18, 1e15, 11_000);
    expect(series.bins).toBeLessThanOrEqual(MAX_SERIES_BINS);
    expect(series.unbinned).toBeGreaterThan(0);
    let lost = 0;
    for (let i = 0; i < series.bins; i++) lost += series.lost(i);
    expect(lost + series.unbinned).toBe(1e15);
    void link;
    expect(performance.now() - started).toBeLessThan(5000);
  });

  it('bins missed frames as one frame at a time would', () => {
    const a = new LinkSeries(1_000, 0);
    a.seal(3);
    a.missed(1_234.5, 90_000, 130, 707.3);
    const sums = new Map<number, number>();
    for (let k = 0; k < 130; k++) {
      const b = Math.max(3, Math.floor(Math.min(1_234.5 + k * 707.3, 90_000) / 1_000));
      sums.set(b, (sums.get(b) ?? 0) + 1);
    }
    for (let i = 0; i < a.bins; i++) expect(a.lost(i), `bin ${i}`).toBe(sums.get(i) ?? 0);
    expect(a.bins).toBe(Math.max(...sums.keys()) + 1);
  });
});
