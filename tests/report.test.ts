/**
 * The link-health report (`healthReport`, `reportHtml`) and `satscope report`, on captures made
 * from the simulator, checked against its ground truth; and on the real PX4 captures when they
 * are beside the repository. The CLI tests need `npm run build:lib` first (`npm test` does it).
 */
import { DATA_COLORS } from '../src/report/palette.js';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { servoToMicros } from '../src/decoder/spec.js';
import { CaptureWriter, encodeCapture, type CaptureRecordInput } from '../src/capture/writer.js';
import { importRaw } from '../src/capture/raw.js';
import { importSaleaeCsv } from '../src/capture/saleae.js';
import { readCapture } from '../src/capture/sniff.js';
import type { Capture, CaptureMeta } from '../src/capture/model.js';
import { diagnosedHealthReport } from '../src/report/doctor-report.js';
import { reportHtml } from '../src/report/report-html.js';
import { escapeHtml } from '../src/report/report-text.js';
import { healthReport } from '../src/report/report.js';
import { SPIKE_MIN_JUMP_PERCENT } from '../src/report/report-thresholds.js';
import type { HealthReport } from '../src/report/report-types.js';
import { encodeServo2048 } from '../src/simulator/encode.js';
import { preset } from '../src/simulator/presets.js';
import { simulate, type SimChunk } from '../src/simulator/simulator.js';
import type { Scenario } from '../src/simulator/scenario.js';
import { perByteCapture } from './feeds.js';
import { satscope } from './built-cli.js';

// ---------------------------------------------------------------------------------------------
// Captures from the simulator
// ---------------------------------------------------------------------------------------------

/** What a USB adapter delivers: whatever arrived in each 16 ms window, stamped at its end. */
function usbRecords(sim: { bytes: Uint8Array; timesUs: Float64Array }, port = 0): CaptureRecordInput[] {
  const out: CaptureRecordInput[] = [];
  let start = 0;
  for (let i = 0; i <= sim.bytes.length; i++) {
    const deadline = Math.floor(sim.timesUs[start]! / 16_000) * 16_000 + 16_000;
    if (i === sim.bytes.length || sim.timesUs[i]! >= deadline) {
      if (i > start) out.push({ type: 'data', bytes: sim.bytes.slice(start, i), timeUs: deadline, port });
      start = i;
    }
  }
  return out;
}

function sscap(records: CaptureRecordInput[], meta: CaptureMeta = { baudRate: 115200, source: 'test' }): Capture {
  return readCapture(encodeCapture(meta, records), 'test.sscap');
}

const run = (scenario: Scenario, durationUs: number): SimChunk => simulate(scenario, durationUs, { truth: true });
const intactOf = (sim: SimChunk) => sim.truth!.frames.filter((f) => f.damage === null);
const sum = (xs: readonly (number | null)[]) => xs.reduce<number>((n, x) => n + (x ?? 0), 0);

/** Rewrites channel `id` of truth frame `index` to `pos` (2048 mode), keeping the slot's phase bit. */
function setChannel(sim: SimChunk, index: number, id: number, pos: number): void {
  const f = sim.truth!.frames[index]!;
  const slot = f.words.findIndex((w) => w !== 0xffff && ((w >> 11) & 0xf) === id);
  if (slot < 0) throw new Error(`frame ${index} does not carry channel ${id}`);
  const w = encodeServo2048(id, pos, ((f.words[slot]! >> 15) & 1) as 0 | 1);
  sim.bytes[f.offset + 2 + 2 * slot] = w >> 8;
  sim.bytes[f.offset + 3 + 2 * slot] = w & 0xff;
}

const positionOf = (sim: SimChunk, index: number, id: number): number | undefined =>
  sim.truth!.frames[index]!.channels.find((c) => c.id === id)?.pos;

/** Frames of `sim` that carry channel `id`, from frame `from` on. */
const carrying = (sim: SimChunk, id: number, from: number): number[] =>
  sim.truth!.frames.filter((f) => f.index >= from && f.channels.some((c) => c.id === id)).map((f) => f.index);

// ---------------------------------------------------------------------------------------------
// A well-formedness check for the HTML: every element closed, in order.
// ---------------------------------------------------------------------------------------------

const VOID = new Set(['meta', 'br', 'hr', 'img', 'input', 'link', 'col', 'wbr']);

function tagProblems(html: string): string[] {
  const problems: string[] = [];
  const stack: string[] = [];
  const body = html.replace(/^<!DOCTYPE html>/i, '').replace(/<style>[\s\S]*?<\/style>/, '<style></style>');
  for (const m of body.matchAll(/<(\/?)([a-zA-Z][\w-]*)((?:[^>"']|"[^"]*"|'[^']*')*?)(\/?)>/g)) {
    const [, close, tag, , self] = m;
    const name = tag!.toLowerCase();
    if (self || (!close && VOID.has(name))) continue;
    if (!close) stack.push(name);
    else if (stack.pop() !== name) problems.push(`</${name}> at ${m.index} closes the wrong element`);
  }
  if (stack.length > 0) problems.push(`unclosed: ${stack.join(', ')}`);
  // Text never holds a raw '<' that is not a tag.
  if (/<(?![a-zA-Z/!])/.test(body)) problems.push('a raw < in text');
  return problems;
}

// ---------------------------------------------------------------------------------------------
// healthReport
// ---------------------------------------------------------------------------------------------

describe('healthReport: failsafe, holds and lost frames against the simulator', () => {
  const sim = run({ ...preset('dropouts-failsafe'), seed: 3 }, 4_000_000);
  const truth = sim.truth!;
  const report = healthReport(perByteCapture(sim), { name: 'dropouts.csv' });
  const r = report.remotes[0]!;
  const origin = report.timeline.originUs!;

  it('covers the one port, with time zero at the first byte and one bin a second', () => {
    expect(report.format).toBe('satscope-health-report');
    expect(report.source).toMatchObject({
      name: 'dropouts.csv',
      kind: 'saleae-csv',
      timing: 'per-byte',
      ports: [0],
      bytes: sim.bytes.length,
    });
    expect(report.remotes).toHaveLength(1);
    expect(origin).toBeCloseTo(sim.timesUs[0]!, 0);
    expect(report.timeline.bins).toBe(Math.ceil(report.timeline.durationUs! / 1e6));
    expect(r).toMatchObject({
      port: 0,
      label: 'Port 0',
      remote: 'internal',
      headerMode: 'fades',
      system: { byte: 0xb2, name: 'DSMX 11 ms 2048', valid: true },
    });
    expect(r.resolution).toMatchObject({ value: 2048, reason: 'system-byte' });
    expect(r.resolution.explanation).toMatch(/system byte/);
  });

  it('finds each failsafe where the receiver went silent for over a second, with its times', () => {
    const gaps = truth.gaps.filter((g) => g.failsafe);
    expect(gaps.length).toBeGreaterThan(0);
    expect(r.failsafes).toHaveLength(gaps.length);
    gaps.forEach((g, i) => {
      const e = r.failsafes[i]!;
      expect(e.lastFrameUs + origin).toBeCloseTo(g.lastFrameUs!, 0);
      expect(e.startUs + origin).toBeCloseTo(g.lastFrameUs! + 1_000_000, 0);
      expect(e.endUs + origin).toBeCloseTo(g.endUs, 0);
      expect(e.durationUs).toBeCloseTo(g.endUs - g.lastFrameUs! - 1_000_000, 0);
      expect(e.ongoing).toBe(false);
    });
    const longest = r.failsafes[0]!;
    const at = `${Math.floor(longest.startUs / 60e6)}:${((longest.startUs / 1e6) % 60).toFixed(1).padStart(4, '0')}`;
    expect(report.verdict[0]).toMatchObject({ level: 'problem', code: 'failsafe' });
    expect(report.verdict[0]!.text).toBe(
      `1 failsafe episode, ${Math.round(longest.durationUs / 1000)} ms at ${at} (1.3 s without frames from 0:01.2)`,
    );
    expect(report.status).toBe('poor');
  });

  it('counts the holds (every failsafe began as one) and the longest that recovered', () => {
    const short = truth.gaps.filter((g) => !g.failsafe && g.endUs - g.lastFrameUs! > 40_000);
    expect(short.length).toBeGreaterThan(0);
    expect(r.holds.count).toBe(short.length + r.failsafes.length);
    expect(r.holds.recovered).toBe(short.length);
    const longest = short.reduce((a, b) => (b.endUs - b.lastFrameUs! > a.endUs - a.lastFrameUs! ? b : a));
    // Declared once no frame has come for 40 ms (the least hold threshold), the hold is dated from
    // when the next frame was due (one period after the last) and ends with the next frame.
    expect(r.holds.longestUs).toBeCloseTo(longest.endUs - longest.lastFrameUs! - 11_000, 0);
    expect(r.holds.longestAtUs! + origin).toBeCloseTo(longest.lastFrameUs! + 11_000, 0);
    expect(r.longestGapUs).toBeCloseTo(Math.max(...truth.gaps.map((g) => g.endUs - g.lastFrameUs!)), 0);
    expect(report.verdict.find((f) => f.code === 'holds')!.text).toMatch(
      /^1 hold \(last values held, recovered before failsafe\), \d+ ms at 0:00\.5$/,
    );
  });

  it('counts the lost frames as the truth does, and the lost ratio and fades per minute from them', () => {
    const intact = intactOf(sim);
    const missed = sum(truth.gaps.map((g) => g.missedFrames));
    expect(r.frames).toBe(intact.length);
    expect(r.missedFrames).toBe(missed);
    expect(r.expectedFrames).toBe(intact.length + missed);
    expect(r.lostRatio).toBeCloseTo(missed / (intact.length + missed), 5);
    const fades = sum(intact.map((f) => f.fadesDelta));
    const minutes = (intact.at(-1)!.timeUs - intact[0]!.timeUs) / 60e6;
    expect(r.fades!.total).toBe(fades);
    expect(r.fades!.perMinute).toBeCloseTo(fades / minutes, 2);
    expect(r.durationUs).toBeCloseTo(intact.at(-1)!.timeUs - intact[0]!.timeUs, 0);
    expect(report.verdict.find((f) => f.code === 'lost-frames')).toMatchObject({ level: 'problem' });
    expect(report.verdict.find((f) => f.code === 'fade-rate')!.text).toMatch(/^Fade rate \d+\/min is high \(over 10\/min\)/);
  });

  it('spreads frames, fades and lost frames over the per-second series', () => {
    const s = r.series;
    for (const xs of [s.frames, s.fades!, s.lost]) expect(xs).toHaveLength(report.timeline.bins);
    expect(sum(s.frames)).toBe(r.frames);
    expect(sum(s.fades!)).toBe(r.fades!.total);
    expect(sum(s.lost)).toBe(r.missedFrames);
    // The 1.3 s dropout starting at 1.2 s: most of its frames were due in second 1.
    expect(s.lost[1]).toBeGreaterThan(60);
    expect(s.rssiMean).toBeNull();
    expect(r.rssi).toBeNull();
  });

  it('measures the frame period without the gaps', () => {
    const fp = r.framePeriod!;
    expect(fp.basis).toBe('per-byte');
    expect(fp.intervals).toBe(r.frames - 1 - truth.gaps.length);
    expect(fp.meanUs).toBeGreaterThan(10_990);
    expect(fp.meanUs).toBeLessThan(11_010);
    expect(fp.maxUs).toBeLessThan(11_020);
    expect(fp.p50Us).toBeLessThanOrEqual(fp.p95Us);
    expect(fp.p95Us).toBeLessThanOrEqual(fp.p99Us);
  });

  it('is plain JSON: it survives a round trip unchanged', () => {
    expect(JSON.parse(JSON.stringify(report))).toEqual(report);
  });
});

describe('healthReport: timing', () => {
  it('gives the jitter of the frame period, as the frame times say (per-byte timing)', () => {
    const sim = run(preset('dsmx-11ms-2048-internal'), 5_000_000);
    const r = healthReport(perByteCapture(sim)).remotes[0]!;
    const times = intactOf(sim).map((f) => f.timeUs);
    const gapFree = times
      .slice(1)
      .map((t, i) => t - times[i]!)
      .filter((d) => d < 16_500);
    const mean = gapFree.reduce((a, b) => a + b, 0) / gapFree.length;
    const sd = Math.sqrt(gapFree.reduce((a, b) => a + (b - mean) ** 2, 0) / gapFree.length);
    const sorted = gapFree.slice().sort((a, b) => a - b);
    expect(r.framePeriod!.intervals).toBe(gapFree.length);
    expect(r.framePeriod!.meanUs).toBeCloseTo(mean, 0);
    expect(r.framePeriod!.stdDevUs).toBeCloseTo(sd, 0);
    expect(r.framePeriod!.p50Us).toBeCloseTo(sorted[Math.ceil(0.5 * sorted.length) - 1]!, 0);
    expect(r.framePeriod!.p99Us).toBeCloseTo(sorted[Math.ceil(0.99 * sorted.length) - 1]!, 0);
    expect(r.findings.find((f) => f.code === 'jitter')).toMatchObject({ level: 'ok' });
  });

  it('gives the same period statistics past 4096 distinct intervals, when every interval is kept', () => {
    // 70 s of per-byte times: over 6000 intervals, most of them distinct.
    const sim = run(preset('dsmx-11ms-2048-internal'), 70_000_000);
    const fp = healthReport(perByteCapture(sim)).remotes[0]!.framePeriod!;
    const times = intactOf(sim).map((f) => f.timeUs);
    const sorted = times
      .slice(1)
      .map((t, i) => t - times[i]!)
      .filter((d) => d < 16_500)
      .sort((a, b) => a - b);
    expect(new Set(sorted).size).toBeGreaterThan(4096);
    const r1 = (x: number): number => Math.round(x * 10) / 10;
    const rank = (p: number): number => sorted[Math.ceil((p / 100) * sorted.length) - 1]!;
    expect(fp.intervals).toBe(sorted.length);
    expect([fp.minUs, fp.p50Us, fp.p95Us, fp.p99Us, fp.maxUs]).toEqual([sorted[0]!, rank(50), rank(95), rank(99), sorted.at(-1)!].map(r1));
    expect(fp.meanUs).toBeCloseTo(sorted.reduce((a, b) => a + b, 0) / sorted.length, 0);
  });

  it('calls an irregular frame period out', () => {
    // Every other frame 3 ms late: intervals of 19 and 25 ms on a 22 ms system, a 3 ms deviation.
    const sim = run(preset('dsmx-22ms-2048-internal'), 4_000_000);
    const times = sim.timesUs.slice();
    for (const f of sim.truth!.frames) if (f.index % 2 === 1) for (let i = 0; i < f.length; i++) times[f.offset + i]! += 3000;
    const r = healthReport(perByteCapture({ bytes: sim.bytes, timesUs: times })).remotes[0]!;
    expect(r.nominalPeriodUs).toBe(22_000);
    expect(r.framePeriod!.stdDevUs).toBeGreaterThan(2900);
    expect(r.framePeriod!.stdDevUs).toBeLessThan(3100);
    expect(r.framePeriod!.p95Us).toBeGreaterThan(24_900);
    // Late frames are not missed ones: only what the receiver's counter says it missed.
    expect(r.missedBasis).toBe('fade-counter');
    expect(r.missedFrames).toBe(r.fades!.total);
    expect(r.missedFrames).toBeLessThanOrEqual(
      sum(sim.truth!.gaps.map((g) => g.missedFrames)) + sum(intactOf(sim).map((f) => f.fadesDelta)),
    );
    expect(r.holds.count).toBe(0);
    expect(r.findings.find((f) => f.code === 'jitter')).toMatchObject({ level: 'warning' });
    expect(r.findings.find((f) => f.code === 'jitter')!.text).toMatch(/jitter 3\.0\d ms \(over 10 % of the period\)/);
  });

  it("finds the same failsafe from 16 ms USB chunks, within the batching, and says the jitter is the adapter's", () => {
    const sim = run({ ...preset('dropouts-failsafe'), seed: 3 }, 4_000_000);
    const report = healthReport(sscap(usbRecords(sim)));
    const r = report.remotes[0]!;
    const gaps = sim.truth!.gaps.filter((g) => g.failsafe);
    expect(report.source.timing).toBe('per-chunk');
    expect(r.failsafes).toHaveLength(gaps.length);
    const origin = report.timeline.originUs!;
    gaps.forEach((g, i) => {
      expect(Math.abs(r.failsafes[i]!.startUs + origin - (g.lastFrameUs! + 1e6))).toBeLessThan(30_000);
      expect(Math.abs(r.failsafes[i]!.endUs + origin - g.endUs)).toBeLessThan(30_000);
    });
    expect(r.framePeriod!.basis).toBe('per-chunk');
    expect(r.findings.some((f) => f.code === 'chunk-timing')).toBe(true);
    expect(r.findings.some((f) => f.code === 'jitter')).toBe(false);
    // Dropouts are long enough to be seen through the batching: the same frames are missing.
    expect(Math.abs(r.missedFrames! - sum(sim.truth!.gaps.map((g) => g.missedFrames)))).toBeLessThanOrEqual(2);
  });

  it('without timing: frames, channels and fades, but no rates, episodes or series', () => {
    const sim = run({ ...preset('dropouts-failsafe'), seed: 3 }, 4_000_000);
    const report = healthReport(importRaw(sim.bytes), { name: 'dump.bin' });
    const r = report.remotes[0]!;
    expect(report.timeline).toEqual({ originUs: null, durationUs: null, binUs: 1e6, bins: 0 });
    expect(r.frames).toBe(intactOf(sim).length);
    expect(r).toMatchObject({ failsafes: [], framePeriod: null, durationUs: null });
    // The receiver's own count of missed frames needs no clock.
    expect(r).toMatchObject({ missedBasis: 'fade-counter', missedFrames: r.fades!.total, expectedFrames: r.frames + r.fades!.total });
    expect(r.fades).toMatchObject({ perMinute: null });
    expect(r.series).toMatchObject({ frames: [], lost: [], fades: [] });
    expect(r.findings.map((f) => f.code)).toContain('no-timing');
    expect(report.status).toBe('good');
    expect(JSON.parse(JSON.stringify(report))).toEqual(report);
    const html = reportHtml(report);
    expect(html).toMatch(/No timing in this file/);
    expect(html).not.toMatch(/<svg/);
    expect(tagProblems(html)).toEqual([]);
  });
});

describe('healthReport: RSSI', () => {
  it('sums up SPM4649T RSSI (loss reports apart) instead of fades', () => {
    const sim = run(preset('rssi-spm4649t'), 20_000_000);
    const report = healthReport(perByteCapture(sim));
    const r = report.remotes[0]!;
    const levels = intactOf(sim).map((f) => f.rssi!);
    const real = levels.filter((v) => v !== -128);
    expect(r.headerMode).toBe('rssi');
    expect(r.fades).toBeNull();
    expect(r.rssi).toEqual({
      minDbm: Math.min(...real),
      maxDbm: Math.max(...real),
      meanDbm: Math.round((real.reduce((a, b) => a + b, 0) / real.length) * 10) / 10,
      frames: real.length,
      lossReports: levels.length - real.length,
    });
    expect(r.rssi!.lossReports).toBeGreaterThan(0);
    expect(r.series.fades).toBeNull();
    expect(r.series.rssiMean).toHaveLength(report.timeline.bins);
    expect(Math.min(...r.series.rssiMin!.map((v) => v ?? 0))).toBe(r.rssi!.minDbm);
    const html = reportHtml(report);
    expect(html).toMatch(/RSSI dBm/);
    expect(html).not.toMatch(/fades \/s/);
  });
});

describe('healthReport: glitches', () => {
  // DSMX 11 ms, 10 channels: gear (4) and aux 3 (7) sit at −100 % (position 341), aux 5 (9) at
  // 0 % (1024), aux 1 (5) holds its step, aileron (1) moves as a sine.
  const sim = run(preset('dsmx-11ms-2048-internal'), 3_000_000);
  const gear = carrying(sim, 4, 100)[0]!;
  const aileron = carrying(sim, 1, 150)[0]!;
  const twoFrames = carrying(sim, 5, 120).slice(0, 2);
  const small = carrying(sim, 7, 140)[0]!;
  const step = carrying(sim, 9, 200);
  const before = (id: number, at: number) =>
    positionOf(
      sim,
      carrying(sim, id, 0)
        .filter((i) => i < at)
        .at(-1)!,
      id,
    )!;
  const expected = [
    { frame: gear, id: 4, pos: positionOf(sim, gear, 4)! + 800 },
    { frame: aileron, id: 1, pos: positionOf(sim, aileron, 1)! - 700 },
  ];
  for (const g of expected) setChannel(sim, g.frame, g.id, g.pos);
  // Not glitches: the same wrong value twice running, a 20 % spike, and a switch that stays.
  for (const i of twoFrames) setChannel(sim, i, 5, 1500);
  setChannel(sim, small, 7, positionOf(sim, small, 7)! + Math.round((0.2 * 2048) / 3));
  for (const i of step) setChannel(sim, i, 9, 1707);

  it('finds the single-frame spikes that come back, and nothing else', () => {
    const report = healthReport(perByteCapture(sim));
    const r = report.remotes[0]!;
    expect(r.glitches.count).toBe(2);
    expect(r.glitches.frames).toBe(2);
    const truth = sim.truth!.frames;
    const origin = report.timeline.originUs!;
    expect(r.glitches.listed.map((g) => [g.channel, g.frameIndex])).toEqual(
      expected.map((g) => [g.id, g.frame]).sort((a, b) => a[1]! - b[1]!),
    );
    for (const g of r.glitches.listed) {
      const e = expected.find((x) => x.id === g.channel)!;
      expect(g.kind).toBe('spike');
      expect(g.name).toBe(g.channel === 4 ? 'Gear' : 'Aileron');
      expect(g.timeUs! + origin).toBeCloseTo(truth[e.frame]!.timeUs, 0);
      expect(g.spikeUs).toBe(servoToMicros(e.pos, 2048));
      expect(g.beforeUs).toBe(servoToMicros(before(g.channel, e.frame), 2048));
      expect(Math.abs(g.jumpPercent)).toBeGreaterThanOrEqual(SPIKE_MIN_JUMP_PERCENT);
    }
    expect(r.findings.find((f) => f.code === 'glitches')).toMatchObject({ level: 'warning' });
    expect(r.findings.find((f) => f.code === 'glitches')!.text).toMatch(
      /^2 glitches: single-frame spikes .* \(first on Gear at 0:01\.\d\)$/,
    );
    expect(reportHtml(report)).toMatch(/<h3>Glitches<\/h3>/);
  });

  it('finds them by frame count in a capture without timing', () => {
    const r = healthReport(importRaw(sim.bytes)).remotes[0]!;
    expect(r.glitches.listed.map((g) => [g.channel, g.frameIndex, g.timeUs])).toEqual([
      [4, gear, null],
      [1, aileron, null],
    ]);
  });

  it('shows empty (0xFFFF) slots and VTX frames where a stream has them, and no such row where it has none', () => {
    const empty = healthReport(perByteCapture(run(preset('empty-slots-12ch'), 2_000_000)));
    const vtx = healthReport(perByteCapture(run(preset('vtx'), 2_000_000)));
    const plain = healthReport(perByteCapture(run(preset('dsmx-11ms-2048-internal'), 2_000_000)));
    expect(empty.remotes[0]!.decoder.emptySlots).toBeGreaterThan(0);
    expect(reportHtml(empty)).toMatch(new RegExp(`${empty.remotes[0]!.decoder.emptySlots} empty \\(0xFFFF\\)`));
    expect(reportHtml(vtx)).toMatch(new RegExp(`${vtx.remotes[0]!.decoder.vtxFrames} VTX frames`));
    expect(reportHtml(plain)).not.toMatch(/empty \(0xFFFF\)|VTX frames/);
  });

  it('finds none in clean streams of every preset without damage', () => {
    for (const name of ['dsm2-22ms-1024-internal', 'dsmx-22ms-2048-external', 'xplus-dx9', 'xplus-8', 'vtx', 'demo']) {
      const r = healthReport(perByteCapture(run(preset(name), 12_000_000))).remotes[0]!;
      expect({ name, glitches: r.glitches.count }).toEqual({ name, glitches: 0 });
    }
  });

  it('on a damaged line, puts every glitch on a damaged frame', () => {
    const damaged = run({ ...preset('damaged-line'), damage: { bitFlipRate: 0.05, truncateRate: 0.02, noiseRate: 0.02 } }, 20_000_000);
    const report = healthReport(perByteCapture(damaged));
    const r = report.remotes[0]!;
    const origin = report.timeline.originUs!;
    expect(r.glitches.count).toBeGreaterThan(0);
    for (const g of r.glitches.listed) {
      const frame = damaged.truth!.frames.find((f) => Math.abs(f.timeUs - (g.timeUs! + origin)) < 1);
      expect(frame?.damage?.kind).toMatch(/^(bit-flip|truncated)$/);
    }
    // Flipped bits in the 00 00 header make the fade counter leap and fall back: the decoder
    // counts none of it as fades.
    const headerFlips = damaged.truth!.frames.filter((f) => f.damage?.kind === 'bit-flip' && f.damage.byte < 2).length;
    expect(headerFlips).toBeGreaterThan(0);
    expect(r.fades!.total).toBe(0);
    expect(r.decoder.badFrames).toBeGreaterThan(0);
    expect(r.decoder.discardedBytes).toBeGreaterThan(0);
    expect(r.findings.find((f) => f.code === 'line-damage')!.text).toMatch(
      /^Line damage: \d+ bad frames, \d+ resyncs, \d+ bytes discarded$/,
    );
  });
});

describe('healthReport: several ports on one clock', () => {
  // Port 0 runs throughout; port 1 drops out into failsafe; port 2 stops at 1.5 s and never
  // comes back while the others go on.
  const a = run({ ...preset('dsmx-11ms-2048-internal'), seed: 1 }, 4_000_000);
  const b = run({ ...preset('dropouts-failsafe'), seed: 5, timing: { startUs: 300_000 } }, 3_600_000);
  const c = run(preset('dsm2-22ms-1024-external'), 1_500_000);
  const records = [...usbRecords(a, 0), ...usbRecords(b, 1), ...usbRecords(c, 2)].sort((x, y) => x.timeUs - y.timeUs);
  const report = healthReport(sscap(records, { source: 'test', ports: [{ name: 'left wing' }, { name: 'tail <b>' }, { name: 'belly' }] }), {
    name: 'three.sscap',
  });
  const [r0, r1, r2] = report.remotes as [HealthReport['remotes'][0], HealthReport['remotes'][0], HealthReport['remotes'][0]];

  it('reports one remote per port, named from the metadata, on one time axis', () => {
    expect(report.source.ports).toEqual([0, 1, 2]);
    expect(report.remotes.map((r) => [r.port, r.label, r.system.name, r.remote])).toEqual([
      [0, 'left wing', 'DSMX 11 ms 2048', 'internal'],
      [1, 'tail <b>', 'DSMX 11 ms 2048', 'internal'],
      [2, 'belly', null, 'external'],
    ]);
    for (const r of report.remotes) {
      for (const xs of [r.series.frames, r.series.lost, r.series.fades!]) expect(xs).toHaveLength(report.timeline.bins);
    }
    // Time zero is the first frame of port 0, as its first chunk's time dates it.
    expect(r0.firstFrameUs).toBe(0);
    expect(Math.abs(r1.firstFrameUs! + report.timeline.originUs! - b.timesUs[0]!)).toBeLessThan(20_000);
    expect(Math.abs(r2.firstFrameUs! + report.timeline.originUs! - c.timesUs[0]!)).toBeLessThan(20_000);
    expect(r2.resolution.value).toBe(1024);
  });

  it("keeps each port's episodes apart, and sees the port that went silent for good", () => {
    expect(r0.failsafes).toEqual([]);
    expect(r1.failsafes).toHaveLength(b.truth!.gaps.filter((g) => g.failsafe).length);
    expect(r2.failsafes).toHaveLength(1);
    const open = r2.failsafes[0]!;
    expect(open.ongoing).toBe(true);
    expect(open.endUs).toBe(report.timeline.durationUs);
    expect(open.startUs).toBeCloseTo(r2.lastFrameUs! + 1e6, 0);
    // Silence to the end of the capture counts as lost frames, at 22 ms.
    const silent = report.timeline.durationUs! - r2.lastFrameUs!;
    expect(Math.abs(r2.missedFrames! - silent / 22_000)).toBeLessThan(3);
  });

  it("puts every port's findings in the verdict under its label, worst first", () => {
    expect(report.status).toBe('poor');
    expect(report.verdict.filter((f) => f.code === 'failsafe' && f.level === 'problem').map((f) => f.port)).toEqual([1, 2]);
    expect(report.verdict.find((f) => f.port === 2 && f.code === 'failsafe')!.text).toMatch(
      /^belly: 1 failsafe episode, .*; the capture ends in failsafe$/,
    );
    expect(report.verdict.find((f) => f.port === 1)!.text).toMatch(/^tail <b>: /);
    // What every port shares is said once.
    expect(report.verdict.filter((f) => f.code === 'chunk-timing')).toEqual([
      {
        level: 'info',
        code: 'chunk-timing',
        port: null,
        text: expect.stringMatching(/^All ports: Frame times are USB chunk arrival times/),
      },
    ]);
    const levels = report.verdict.map((f) => ['problem', 'warning', 'info', 'ok'].indexOf(f.level));
    expect(levels).toEqual(levels.slice().sort((x, y) => x - y));
  });

  it('draws every port over the same axis in the HTML, with escaped labels', () => {
    const html = reportHtml(report);
    expect(tagProblems(html)).toEqual([]);
    expect(html.match(/<svg/g)).toHaveLength(1);
    expect(html).toContain('tail &lt;b&gt;: lost frames /s');
    expect(html).not.toContain('tail <b>');
    // Red failsafe bands in each of a remote's panels (lost frames and fades).
    const bands = html.split(`fill="${DATA_COLORS.light.failsafeBand}"`).length - 1;
    expect(bands).toBe(2 * (r1.failsafes.length + r2.failsafes.length) + 1); // + the legend swatch
  });
});

describe('reportHtml', () => {
  const sim = run({ ...preset('dropouts-failsafe'), seed: 3 }, 4_000_000);
  const evil = '<script>alert("x")</script> & \'quotes\'.csv';
  const capture = sscap(usbRecords(sim), { source: 'test', note: 'bench <img src=x onerror=alert(1)>', createdAt: '2026-01-02T03:04:05Z' });
  const report = healthReport(capture, { name: evil });
  const html = reportHtml(report);

  it('is one self-contained document: inline CSS and SVG, no script, no external resource', () => {
    expect(html.startsWith('<!DOCTYPE html>\n<html lang="en">')).toBe(true);
    expect(html.trimEnd().endsWith('</html>')).toBe(true);
    expect(html).toMatch(/<meta charset="utf-8">/);
    expect(html.match(/<svg /g)).toHaveLength(1);
    expect(html.match(/<style>/g)).toHaveLength(1);
    expect(html).not.toMatch(/<script/i);
    expect(html).not.toMatch(/https?:\/\//i);
    // No tag has a src, href or event handler (the note's markup is only text), and CSS loads nothing.
    expect(html).not.toMatch(/<[^>]*\s(src|href|on[a-z]+)=/i);
    expect(html).not.toMatch(/url\(|@import/i);
    expect(tagProblems(html)).toEqual([]);
  });

  it('escapes every text it shows', () => {
    expect(html).toContain('&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &#39;quotes&#39;.csv');
    expect(html).toContain('<title>Link health: &lt;script&gt;');
    expect(html).toContain('bench &lt;img src=x onerror=alert(1)&gt;');
    expect(html).toContain('recorded 2026-01-02T03:04:05Z');
  });

  it('shows the status, the findings, the graphs with failsafe bands and the episodes', () => {
    expect(html).toMatch(/<div class="status poor">Poor<\/div>/);
    for (const f of report.verdict) expect(html).toContain(escapeHtml(f.text));
    expect(html).toContain('lost frames /s');
    expect(html).toContain('fades /s');
    expect(html).toContain(`fill="${DATA_COLORS.light.failsafeBand}"`);
    expect(html).toMatch(/<h3>Failsafe episodes<\/h3>/);
    expect(html).toMatch(/Throttle/);
    expect(html).toMatch(/@page/);
  });

  it('reports a capture with no frames as no data', () => {
    const noise = importRaw(Uint8Array.from({ length: 500 }, (_, i) => (i * 37 + 11) & 0xff));
    const r = healthReport(noise, { name: 'noise.bin' });
    expect(r.status).toBe('no-data');
    expect(r.remotes[0]!.frames).toBe(0);
    expect(r.verdict[0]).toMatchObject({ level: 'problem', code: 'no-frames' });
    const page = reportHtml(r);
    expect(page).toMatch(/No data/);
    expect(tagProblems(page)).toEqual([]);
  });
});

// ---------------------------------------------------------------------------------------------
// The real PX4 captures
// ---------------------------------------------------------------------------------------------

const px4 = resolve(import.meta.dirname, '../../shared/captures/px4');
const px4Present = existsSync(px4);
if (!px4Present) console.warn(`skipping the PX4 report tests: ${px4} is not here`);

describe.skipIf(!px4Present)('healthReport on the real PX4 captures', () => {
  const load = (name: string) => healthReport(importSaleaeCsv(new Uint8Array(readFileSync(join(px4, name)))), { name });

  it('dsm_x_dx9_data.txt: a clean link, 456 frames every 11 ms, no glitches', () => {
    const report = load('dsm_x_dx9_data.txt');
    const r = report.remotes[0]!;
    expect(r.frames).toBe(456);
    expect(r).toMatchObject({ missedFrames: 0, lostRatio: 0, failsafes: [], nominalPeriodUs: 11_000 });
    expect(r.glitches.count).toBe(0);
    expect(r.framePeriod!.p50Us).toBeGreaterThan(10_990);
    expect(r.framePeriod!.p50Us).toBeLessThan(11_010);
    expect(r.framePeriod!.stdDevUs).toBeLessThan(20);
    expect(r.channels.map((c) => c.id)).toEqual([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15]);
    expect(report.status).toBe('good');
    expect(tagProblems(reportHtml(report))).toEqual([]);
  });

  it('dsm_x_data.txt: the truncated frames show as lost frames and line damage; the 00 00 header counts no fades', () => {
    const r = load('dsm_x_data.txt').remotes[0]!;
    // 62 of the 66 full bursts: the one before each truncated burst goes with it.
    expect(r.frames).toBe(62);
    expect(r.decoder.discardedBytes).toBe(49 + 4 * 16);
    expect(r.missedFrames).toBeGreaterThan(0);
    expect(r.fades).toMatchObject({ total: 0, counterMoved: false });
    expect(r.findings.map((f) => f.code)).toEqual(expect.arrayContaining(['line-damage', 'lost-frames', 'fade-rate']));
    expect(r.findings.find((f) => f.code === 'fade-rate')).toMatchObject({ level: 'info' });
  });

  it('dsm_x_dx9_px4_binding_data.txt: an internal remote, system 0xB2, no failsafe', () => {
    const r = load('dsm_x_dx9_px4_binding_data.txt').remotes[0]!;
    expect(r.frames).toBe(455);
    expect(r.system).toEqual({ byte: 0xb2, name: 'DSMX 11 ms 2048', valid: true });
    expect(r.failsafes).toEqual([]);
  });
});

// ---------------------------------------------------------------------------------------------
// satscope report
// ---------------------------------------------------------------------------------------------

describe('satscope report', () => {
  let dir = '';
  const sim = run({ ...preset('dropouts-failsafe'), seed: 3 }, 4_000_000);
  const gaps = sim.truth!.gaps.filter((g) => g.failsafe).length;

  beforeAll(() => {
    dir = mkdtempSync(join(tmpdir(), 'satscope-report-'));
    const writer = new CaptureWriter({ baudRate: 115200, source: 'test' });
    const parts = [writer.header(), ...usbRecords(sim).map((r) => (r.type === 'data' ? writer.data(r.bytes, r.timeUs) : new Uint8Array()))];
    const file = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
    let at = 0;
    for (const p of parts) {
      file.set(p, at);
      at += p.length;
    }
    writeFileSync(join(dir, 'run.sscap'), file);
    writeFileSync(join(dir, 'notes.txt'), 'these are my notes\nnot a capture\n');
    writeFileSync(
      join(dir, 'noise.bin'),
      Uint8Array.from({ length: 500 }, (_, i) => (i * 37 + 11) & 0xff),
    );
  });
  afterAll(() => rmSync(dir, { recursive: true, force: true }));

  it('prints the HTML report to stdout', () => {
    const r = satscope('report', join(dir, 'run.sscap'));
    expect(r.code).toBe(0);
    expect(r.err).toBe('');
    expect(r.out.startsWith('<!DOCTYPE html>')).toBe(true);
    expect(r.out).toContain('<strong>run.sscap</strong>');
    expect(r.out).toMatch(/<svg /);
    expect(tagProblems(r.out)).toEqual([]);
  });

  it("prints the JSON report with --json, the same as the library makes, with the doctor's findings", () => {
    const r = satscope('report', join(dir, 'run.sscap'), '--json');
    expect(r.code).toBe(0);
    const json = JSON.parse(r.out) as HealthReport;
    expect(json.source.name).toBe('run.sscap');
    expect(json.remotes[0]!.failsafes).toHaveLength(gaps);
    const capture = readCapture(new Uint8Array(readFileSync(join(dir, 'run.sscap'))), 'run.sscap');
    expect(json).toEqual(diagnosedHealthReport(capture, { name: 'run.sscap' }));
    expect({ ...json, diagnosis: undefined }).toEqual({ ...healthReport(capture, { name: 'run.sscap' }), diagnosis: undefined });
    expect(json.diagnosis?.map((f) => f.title)).toContain('Port 0: the link is weak: failsafe');
  });

  it('writes the report to --out and prints the findings', () => {
    const out = join(dir, 'run.report.html');
    const r = satscope('report', join(dir, 'run.sscap'), '--out', out);
    expect(r.code).toBe(0);
    expect(r.out).toMatch(
      new RegExp(`^Report written to .*run\\.report\\.html: link poor \\(1 port\\)\\n  PROBLEM  ${gaps} failsafe episode`),
    );
    expect(readFileSync(out, 'utf8')).toBe(satscope('report', join(dir, 'run.sscap')).out);
    const json = join(dir, 'run.report.json');
    expect(satscope('report', join(dir, 'run.sscap'), '--json', '--out', json).code).toBe(0);
    expect(JSON.parse(readFileSync(json, 'utf8')).format).toBe('satscope-health-report');
  });

  it('honours --resolution', () => {
    const json = JSON.parse(satscope('report', join(dir, 'run.sscap'), '--json', '--resolution', '2048').out) as HealthReport;
    expect(json.remotes[0]!.resolution).toMatchObject({ value: 2048, reason: 'override' });
  });

  it('exits 1 for a file without frames or not a capture, 2 for bad usage and unwritable output', () => {
    const noise = satscope('report', join(dir, 'noise.bin'), '--json');
    expect(noise.code).toBe(1);
    expect(noise.err).toMatch(/noise\.bin: no Spektrum frames found in 500 bytes/);
    expect(JSON.parse(noise.out).status).toBe('no-data');
    const text = satscope('report', join(dir, 'notes.txt'));
    expect(text.code).toBe(1);
    expect(text.err).toMatch(/notes\.txt: .*(text|CSV)/i);
    expect(text.out).toBe('');
    expect(satscope('report', join(dir, 'nope.sscap')).code).toBe(2);
    expect(satscope('report').err).toMatch(/no FILE given/);
    const port = satscope('report', join(dir, 'run.sscap'), '--port', '1');
    expect(port.code).toBe(2);
    expect(port.err).toMatch(/report covers every port/);
    expect(satscope('report', join(dir, 'run.sscap'), '--out').err).toMatch(/--out needs a value/);
    expect(satscope('report', join(dir, 'run.sscap'), '--format', 'csv').err).toMatch(/unknown option '--format'/);
    expect(satscope('info', join(dir, 'run.sscap'), '--out', 'x.html').code).toBe(2);
    const unwritable = satscope('report', join(dir, 'run.sscap'), '--out', join(dir, 'missing', 'r.html'));
    expect(unwritable.code).toBe(2);
    expect(unwritable.err).toMatch(/cannot write .*r\.html: no such directory/);
    expect(satscope('--help').out).toMatch(/satscope report FILE \[--out REPORT\.html\] \[--json\]/);
  });
});

describe('the report on breaks the receiver explains', () => {
  it("counts a receiver restart's hold and missed frames, and says it was a restart", () => {
    const quiet = { lossRate: 0, randomRate: 0 };
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), fades: { ...quiet, start: 40 }, seed: 1 }, 2e6);
    const b = simulate({ ...preset('dsmx-11ms-2048-internal'), fades: { ...quiet, start: 0 }, seed: 2 }, 2e6);
    const shift = a.timesUs[a.timesUs.length - 1]! + 496_000 - b.timesUs[0]!;
    const bytes = new Uint8Array([...a.bytes, ...b.bytes]);
    const timesUs = Float64Array.from([...a.timesUs, ...Array.from(b.timesUs, (t) => t + shift)]);
    const r = healthReport(perByteCapture({ bytes, timesUs })).remotes[0]!;
    expect(r.restarts.count).toBe(1);
    expect(r.holds.count).toBe(1);
    expect(r.missedFrames).toBeGreaterThanOrEqual(43);
    expect(r.undeliveredFrames).toBe(r.missedFrames);
    expect(r.findings.find((f) => f.code === 'restarts')?.text).toMatch(
      /1 receiver restart: the fade counter started again from 0 .*the last at 0:02\.\d/,
    );
  });

  it('calls frames an adapter held back and delivered at once delivery stalls, not holds or failsafes', () => {
    const s = simulate({ ...preset('dsmx-11ms-2048-internal'), fades: { lossRate: 0, randomRate: 0 } }, 4e6);
    // 16 ms chunks, those from 1 s to 2.2 s held back and delivered with the next.
    const records: CaptureRecordInput[] = [];
    let held: Uint8Array[] = [];
    for (let t = 16_000, i = 0; i < s.bytes.length; t += 16_000) {
      let j = i;
      while (j < s.bytes.length && s.timesUs[j]! < t) j++;
      held.push(s.bytes.subarray(i, j));
      i = j;
      if (t > 1e6 && t < 2.2e6) continue;
      records.push({ type: 'data', bytes: new Uint8Array(held.flatMap((h) => [...h])), timeUs: t, port: 0 });
      held = [];
    }
    const r = healthReport(readCapture(encodeCapture({ baudRate: 115200, source: 'test' }, records), 'stall.sscap')).remotes[0]!;
    expect(r).toMatchObject({ holds: { count: 0 }, failsafes: [], missedFrames: 0, delivery: { stalls: 1 } });
    // Past a second: the failsafe the silence would have been is withdrawn with its hold.
    expect(r.delivery.longestStallUs).toBeGreaterThan(1_000_000);
    expect(r.findings.find((f) => f.code === 'delivery')?.text).toMatch(/1 delivery stall, the longest 1\.\d s: frames the USB adapter/);
  });
});
