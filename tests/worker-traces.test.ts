/**
 * The channel traces' data as the worker hands it to the page: every timed frame's channel values
 * in µs, a break after each silence the link monitor calls a hold, and the glitches the report's
 * own rule finds, the same ones `satscope report` lists.
 */
import { describe, expect, it } from 'vitest';
import { healthReport } from '../src/report/report.js';
import { CHANNEL_COUNT, channelResolution, servoToMicros } from '../src/decoder/spec.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { preset } from '../src/simulator/presets.js';
import { simulate, type SimChunk } from '../src/simulator/simulator.js';
import { Engine } from '../src/worker/engine.js';
import type { TraceBatch } from '../src/worker/protocol.js';
import { MAX_TRACE_ROWS, TraceLog } from '../src/worker/traces.js';
import { perByteCapture, withSpikes } from './feeds.js';

/** Every batch of traces an engine hands out, fed `sim` in chunks of `chunk` bytes with a batch after each. */
function traced(sim: SimChunk, chunk = 64): TraceBatch[] {
  const engine = new Engine({ resolution: 'auto', jitterUs: 0 });
  const out: TraceBatch[] = [];
  for (let i = 0; i < sim.bytes.length; i += chunk) {
    const end = Math.min(sim.bytes.length, i + chunk);
    engine.push(sim.bytes.subarray(i, end), sim.timesUs.subarray(i, end), 0);
    const b = engine.batch(sim.timesUs[end - 1] ?? 0);
    if (b !== null) out.push(b.batch.traces);
  }
  engine.end(sim.timesUs[sim.timesUs.length - 1]);
  const last = engine.batch(Number.POSITIVE_INFINITY);
  if (last !== null) out.push(last.batch.traces);
  return out;
}

describe('the channel traces in the worker', () => {
  const sim = withSpikes(simulate(preset('dropouts-failsafe'), 3_200_000, { truth: true }), [30, 90, 140]);

  it("hands every frame's time and channel values in µs, what the decoder reads, across batches", () => {
    const batches = traced(sim);
    const t = batches.flatMap((b) => [...b.t]);
    const us = batches.flatMap((b) => [...b.us]);
    const decoder = new SpektrumDecoder();
    decoder.push(sim.bytes, sim.timesUs);
    decoder.end();
    const want: number[] = [];
    const wantUs: number[] = [];
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) {
      want.push(f.timeUs);
      const row = new Array<number>(CHANNEL_COUNT).fill(Number.NaN);
      for (let i = 0; i < f.count; i++)
        row[f.ids[i] ?? 0] = servoToMicros(f.positions[i] ?? 0, channelResolution(f.ids[i] ?? 0, f.resolution));
      wantUs.push(...row);
    }
    expect(want.length).toBeGreaterThan(100);
    expect(t).toEqual(want);
    expect(us).toEqual(wantUs);
  });

  it('marks a break before the first frame and after each dropout, and nowhere else', () => {
    const batches = traced(sim);
    const t = batches.flatMap((b) => [...b.t]);
    const gaps = batches.flatMap((b) => [...b.gap]).flatMap((g, i) => (g === 1 ? [t[i] ?? 0] : []));
    // The preset's dropouts: 0.2 s at 0.5 s and 1.3 s at 1.2 s.
    expect(gaps.length).toBe(3);
    expect(gaps[1]).toBeGreaterThan(0.7e6);
    expect(gaps[1]).toBeLessThan(0.75e6);
    expect(gaps[2]).toBeGreaterThan(2.5e6);
    expect(gaps[2]).toBeLessThan(2.55e6);
  });

  it('marks the glitches the health report counts, at their time, on their channel, with the wrong value', () => {
    const batches = traced(sim);
    const spikes = batches.flatMap((b) => [...b.spikes.t].map((t, i) => ({ t, channel: b.spikes.channel[i], us: b.spikes.us[i] })));
    const report = healthReport(perByteCapture(sim)).remotes[0];
    expect(spikes.length).toBe(3);
    expect(spikes.length).toBe(report?.glitches.count);
    expect(spikes.map((s) => ({ channel: s.channel, us: s.us }))).toEqual(
      report?.glitches.listed.map((g) => ({ channel: g.channel, us: g.spikeUs })),
    );
    for (const [i, k] of [30, 90, 140].entries()) {
      const f = sim.truth?.frames[k];
      expect(Math.abs((spikes[i]?.t ?? 0) - (f?.timeUs ?? 0))).toBeLessThan(2_000);
    }
  });

  it('keeps at most MAX_TRACE_ROWS frames between two batches, the newest, and marks the break before them', () => {
    const log = new TraceLog();
    const long = simulate(preset('dsmx-11ms-2048-internal'), 800_000_000);
    const decoder = new SpektrumDecoder();
    decoder.push(long.bytes, long.timesUs);
    decoder.end();
    let frames = 0;
    let lastUs = 0;
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) {
      log.frame(f, 40_000);
      frames++;
      lastUs = f.timeUs;
    }
    const out = log.take();
    expect(frames).toBeGreaterThan(MAX_TRACE_ROWS);
    expect(out.t.length).toBeLessThanOrEqual(MAX_TRACE_ROWS);
    expect(out.t.length).toBeGreaterThanOrEqual(MAX_TRACE_ROWS / 2);
    expect(out.t[out.t.length - 1]).toBe(lastUs);
    expect(out.gap[0]).toBe(1);
    expect(out.gap.subarray(1).every((g) => g === 0)).toBe(true);
    // And the next batch starts empty.
    expect(log.take().t.length).toBe(0);
  });
});
