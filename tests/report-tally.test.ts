/**
 * The health report's per-channel figures and its glitches against the rule read plainly: every
 * appearance of every channel in stream order, each channel's last three appearances A, B, C
 * compared in % travel as REPORT_THRESHOLDS describes them. The streams are made to sit on the
 * rule's edges: jumps a position step either side of SPIKE_MIN_JUMP_PERCENT, returns either side
 * of SPIKE_RETURN_PERCENT, A→C spans either side of the window, repeats before and after, at
 * 1024 and 2048 resolution and on X-Plus channels, timed and untimed.
 */
import { describe, expect, it } from 'vitest';
import { decodeCapture } from '../src/report/capture-pass.js';
import { healthReport } from '../src/report/report.js';
import { REPORT_THRESHOLDS, SPIKE_MIN_JUMP_PERCENT } from '../src/report/report-thresholds.js';
import { importRaw } from '../src/capture/raw.js';
import type { Capture } from '../src/capture/model.js';
import { channelName, channelResolution, servoToMicros, servoToPercent } from '../src/decoder/spec.js';
import { Prng } from '../src/simulator/prng.js';
import { preset } from '../src/simulator/presets.js';
import { simulate, type SimChunk } from '../src/simulator/simulator.js';
import { SpikeFinder } from '../src/report/spikes.js';
import { perByteCapture } from './feeds.js';

const SECOND = 1_000_000;
const BYTE_US = 86.8;

/** The channel a slot word carries (`null` for an empty slot) and the bits of its position. */
function slotOf(w: number, resolution: 1024 | 2048): { id: number; mask: number; step: number } | null {
  if (w === 0xffff) return null;
  if (resolution === 1024) return { id: (w >> 10) & 0x3f, mask: 0x3ff, step: 1 };
  const id = (w >> 11) & 0xf;
  if (id !== 12) return { id, mask: 0x7ff, step: 1 };
  return { id: 12 + ((w >> 9) & 3) + ((w >> 15) & 1) * 4, mask: 0x1ff, step: 4 }; // X-Plus: 9 bits, ×4 on the 2047 scale
}

/**
 * Rewrites every channel value of `sim` with walks that keep landing on the spike rule's edges,
 * and re-times its frames `periodUs` apart with ±`jitterUs`, so that A→C spans straddle the window.
 */
function onTheEdges(sim: SimChunk, seed: number, periodUs: number, jitterUs: number): SimChunk {
  const rng = new Prng(seed);
  const pick = <T>(xs: readonly T[]): T => xs[Math.floor(rng.next() * xs.length)] as T;
  const state = new Map<number, { a: number; b: number }>();
  const bytes = sim.bytes.slice();
  const timesUs = sim.timesUs.slice();
  let t = 0;
  for (const f of sim.truth?.frames ?? []) {
    t += periodUs + Math.round((rng.next() * 2 - 1) * jitterUs);
    for (let k = 0; k < f.length; k++) timesUs[f.offset + k] = t + k * BYTE_US;
    for (let slot = 0; slot < 7 && 2 + 2 * slot + 1 < f.length; slot++) {
      const at = f.offset + 2 + 2 * slot;
      const w = ((bytes[at] ?? 0) << 8) | (bytes[at + 1] ?? 0);
      const s = slotOf(w, f.resolution);
      if (s === null) continue;
      const top = s.mask * s.step;
      // Position steps for 25 % and 5 % travel at this channel's resolution.
      const jump = channelResolution(s.id, f.resolution) / 12;
      const back = channelResolution(s.id, f.resolution) / 60;
      const v = state.get(s.id) ?? { a: top >> 1, b: top >> 1 };
      let next: number;
      const r = rng.next();
      if (r < 0.3) next = v.b;
      else if (r < 0.5) next = v.b + pick([-2, -1, 1, 2]) * s.step;
      else if (r < 0.75) next = v.b + pick([-1, 1]) * (Math.round(jump) + pick([-2, -1, 0, 1, 2]) * s.step);
      else if (r < 0.95) next = v.a + pick([-1, 0, 1]) * (Math.round(back) + pick([-1, 0, 1]) * s.step);
      else next = Math.floor(rng.next() * top);
      next = Math.max(0, Math.min(top, Math.round(next / s.step) * s.step));
      state.set(s.id, { a: v.b, b: next });
      const word = (w & ~s.mask) | (next / s.step);
      bytes[at] = word >> 8;
      bytes[at + 1] = word & 0xff;
    }
  }
  return { ...sim, bytes, timesUs };
}

interface Appearance {
  pct: number;
  us: number;
  t: number;
  index: number;
}

/** What the rule says of a capture's port 0, read plainly from every decoded frame. */
function plainReading(capture: Capture, originUs: number | null) {
  const seen = new Map<number, Appearance[]>();
  const glitches: object[] = [];
  let glitchFrames = 0;
  let lastGlitchFrame = -1;
  const { spikeReturnPercent, spikeWindowUs, spikeWindowFrames } = REPORT_THRESHOLDS;
  decodeCapture(capture, {}, (f) => {
    for (let i = 0; i < f.count; i++) {
      const id = f.ids[i] ?? -1;
      const pos = f.positions[i] ?? -1;
      const res = channelResolution(id, f.resolution);
      const list = seen.get(id) ?? [];
      seen.set(id, list);
      const c = { pct: servoToPercent(pos, res), us: servoToMicros(pos, res), t: f.timeUs, index: f.index };
      const a = list.at(-2);
      const b = list.at(-1);
      list.push(c);
      if (a === undefined || b === undefined) continue;
      const up = b.pct - a.pct;
      const down = b.pct - c.pct;
      const inWindow = Number.isFinite(c.t) && Number.isFinite(a.t) ? c.t - a.t <= spikeWindowUs : c.index - a.index <= spikeWindowFrames;
      if (
        inWindow &&
        Math.abs(up) >= SPIKE_MIN_JUMP_PERCENT &&
        Math.abs(down) >= SPIKE_MIN_JUMP_PERCENT &&
        Math.sign(up) === Math.sign(down) &&
        Math.abs(c.pct - a.pct) <= spikeReturnPercent
      ) {
        if (b.index !== lastGlitchFrame) glitchFrames++;
        lastGlitchFrame = b.index;
        glitches.push({
          kind: 'spike',
          frameIndex: b.index,
          channel: id,
          name: channelName(id),
          beforeUs: a.us,
          spikeUs: b.us,
          afterUs: c.us,
          jumpPercent: Math.round(up * 10) / 10,
          timeUs: originUs === null ? null : Math.round((b.t - originUs) * 10) / 10,
        });
      }
    }
  });
  const channels = [...seen]
    .sort((x, y) => x[0] - y[0])
    .map(([id, list]) => ({
      id,
      name: channelName(id),
      frames: list.length,
      minUs: Math.min(...list.map((x) => x.us)),
      maxUs: Math.max(...list.map((x) => x.us)),
      meanUs: Math.round((list.reduce((s, x) => s + x.us, 0) / list.length) * 10) / 10,
    }));
  // Candidates the rule turned down: B a jump of 25 % or more from A, not a spike.
  let turnedDown = 0;
  for (const list of seen.values())
    for (let k = 2; k < list.length; k++)
      if (Math.abs((list[k - 1]?.pct ?? 0) - (list[k - 2]?.pct ?? 0)) >= SPIKE_MIN_JUMP_PERCENT) turnedDown++;
  return { channels, glitches, glitchFrames, turnedDown: turnedDown - glitches.length };
}

const STREAMS: [string, () => SimChunk][] = [
  [
    'DSMX 22 ms 2048, 7 channels a frame',
    () => onTheEdges(simulate(preset('dsmx-22ms-2048-internal'), 20 * SECOND, { truth: true }), 1, 50_000, 300),
  ],
  ['DSM2 22 ms 1024', () => onTheEdges(simulate(preset('dsm2-22ms-1024-internal'), 20 * SECOND, { truth: true }), 2, 50_000, 300)],
  ['DSMX 11 ms with 8 X-Plus channels', () => onTheEdges(simulate(preset('xplus-8'), 10 * SECOND, { truth: true }), 3, 25_000, 200)],
  [
    'DSMX 11 ms, 10 channels over two frames',
    () => onTheEdges(simulate(preset('dsmx-11ms-2048-internal'), 10 * SECOND, { truth: true }), 4, 25_000, 200),
  ],
];

describe("the report tally on the spike rule's edges", () => {
  for (const [name, make] of STREAMS) {
    const sim = make();
    it(`${name}: the channels and every glitch are what the rule says, timed`, () => {
      const report = healthReport(perByteCapture(sim));
      const r = report.remotes[0];
      const plain = plainReading(perByteCapture(sim), report.timeline.originUs);
      expect(r?.channels).toEqual(plain.channels);
      expect(r?.glitches.count).toBe(plain.glitches.length);
      expect(r?.glitches.frames).toBe(plain.glitchFrames);
      expect(r?.glitches.listed).toEqual(plain.glitches.slice(0, r?.glitches.listed.length));
      // The streams do sit on the edges: spikes found, and jumps of 25 % or more that are none.
      expect(plain.glitches.length).toBeGreaterThan(20);
      expect(plain.turnedDown).toBeGreaterThan(plain.glitches.length);
    });
    it(`${name}: the page's SpikeFinder, fed frame by frame, finds every glitch the report lists, timed and untimed`, () => {
      for (const capture of [perByteCapture(sim), importRaw(sim.bytes)]) {
        const found: { channel: number; frameIndex: number; beforeUs: number; spikeUs: number; afterUs: number }[] = [];
        const finder = new SpikeFinder();
        decodeCapture(capture, {}, (f) =>
          finder.frame(f, (s) =>
            found.push({ channel: s.channel, frameIndex: s.frameIndex, beforeUs: s.beforeUs, spikeUs: s.spikeUs, afterUs: s.afterUs }),
          ),
        );
        const r = healthReport(capture).remotes[0];
        expect(found.length).toBe(r?.glitches.count);
        expect(found.length).toBeGreaterThan(20);
        const listed = r?.glitches.listed.map((g) => ({
          channel: g.channel,
          frameIndex: g.frameIndex,
          beforeUs: g.beforeUs,
          spikeUs: g.spikeUs,
          afterUs: g.afterUs,
        }));
        expect(found.slice(0, listed?.length)).toEqual(listed);
      }
    });
    it(`${name}: the same without timing (the window in frames)`, () => {
      const r = healthReport(importRaw(sim.bytes)).remotes[0];
      const plain = plainReading(importRaw(sim.bytes), null);
      expect(r?.channels).toEqual(plain.channels);
      expect(r?.glitches.count).toBe(plain.glitches.length);
      expect(r?.glitches.frames).toBe(plain.glitchFrames);
      expect(r?.glitches.listed).toEqual(plain.glitches.slice(0, r?.glitches.listed.length));
      expect(plain.glitches.length).toBeGreaterThan(20);
    });
  }
});
