/**
 * The worker's parts that run without a browser: the engine's batches (graph buckets, lost
 * frames, episodes) and the wording of port errors.
 */
import { describe, expect, it } from 'vitest';
import { Engine } from '../src/worker/engine.js';
import { openProblem } from '../src/worker/sources/serial.js';
import { preset, simulate } from '../src/simulator/index.js';
import { usbChunks } from './e2e/app-fixture.js';

function run(name: string, seed: number, durationUs: number, tickAfterEndUs = 0) {
  const sim = simulate({ ...preset(name), seed }, durationUs, { truth: true });
  const engine = new Engine({ resolution: 'auto', jitterUs: 20_000 });
  const series = { t: [] as number[], fadeRate: [] as number[], lost: [] as number[], periodMs: [] as number[] };
  const episodes: { id: number; kind: string; endUs: number | null }[] = [];
  const take = (now: number) => {
    const out = engine.batch(now);
    if (out === null) return;
    series.t.push(...out.batch.series.t);
    series.fadeRate.push(...out.batch.series.fadeRate);
    series.lost.push(...out.batch.series.lost);
    series.periodMs.push(...out.batch.series.periodMs);
    episodes.push(...out.batch.episodes);
  };
  const chunks = usbChunks(sim.bytes, sim.timesUs);
  let last = 0;
  for (const c of chunks) {
    // Ticks between chunks, as the worker's idle timer makes them.
    for (let t = last + 50_000; t < c.timeUs; t += 50_000) take(t);
    engine.push(c.bytes, c.timeUs, 0);
    take(c.timeUs);
    last = c.timeUs;
  }
  // Time passing after the last frame closes the open buckets (and counts the silence as lost).
  if (tickAfterEndUs > 0) take(last + tickAfterEndUs);
  return { sim, series, episodes, engine };
}

describe('the engine', () => {
  it('sums frames into 100 ms buckets whose lost frames add up to what the receiver missed', () => {
    const { sim, series } = run('dropouts-failsafe', 3, 3_200_000);
    expect(series.t.every((t, i) => i === 0 || t - (series.t[i - 1] as number) === 100_000)).toBe(true);
    const missed = sim.truth!.gaps.reduce((n, g) => n + g.missedFrames, 0);
    const lost = series.lost.reduce((a, b) => a + b, 0);
    // Buckets round to whole frames: within a frame or two of the truth, never counted twice.
    expect(Math.abs(lost - missed)).toBeLessThanOrEqual(3);
    // Frame spacing leaves the gaps out (longer than 1.5 periods plus USB jitter): about 11 ms,
    // a bucket with one missed frame reads more.
    const periods = series.periodMs.filter(Number.isFinite);
    expect(periods.filter((p) => p > 9 && p < 13).length).toBeGreaterThan(periods.length * 0.8);
    for (const p of periods) {
      expect(p).toBeGreaterThan(5);
      expect(p).toBeLessThan(37);
    }
  });

  it('reports each hold and failsafe once when it starts and once when it ends', () => {
    const { episodes, engine } = run('dropouts-failsafe', 3, 3_200_000);
    const byId = new Map<number, { kind: string; endUs: number | null }[]>();
    for (const e of episodes) byId.set(e.id, [...(byId.get(e.id) ?? []), e]);
    expect(engine.link.stats.failsafes).toBe(1);
    expect(engine.link.stats.holds).toBe(2);
    expect(byId.size).toBe(engine.link.episodes.length);
    for (const reports of byId.values()) {
      expect(reports.length).toBeLessThanOrEqual(2);
      expect(reports.at(-1)?.endUs).not.toBeNull();
    }
  });

  it('shows fades as a rate per second in the bucket they were reported', () => {
    const { series, engine } = run('fade-wrap-internal', 4, 2_000_000, 1_500_000);
    const total = series.fadeRate.reduce((a, b) => a + b * 0.1, 0);
    expect(engine.link.stats.fades).toBeGreaterThan(5);
    expect(Math.round(total)).toBe(engine.link.stats.fades);
  });
});

describe('port errors', () => {
  it('explains a busy port, a refusal and anything else in terms of what to do', () => {
    const busy = new Error('Failed to open serial port.');
    busy.name = 'NetworkError';
    expect(openProblem(busy).title).toBe('The port is busy');
    expect(openProblem(busy).detail).toMatch(/Close it, then connect again/);
    const refused = new Error('denied');
    refused.name = 'SecurityError';
    expect(openProblem(refused).title).toBe('Permission refused');
    expect(openProblem(new TypeError('odd')).detail).toBe('TypeError: odd');
  });
});
