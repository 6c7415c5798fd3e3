/**
 * The channel traces on the page: values held from one appearance to the next but never across
 * a break, memory bounded however long a session runs, and the view of a window that keeps a
 * one-frame glitch visible when frames outnumber pixels, at a cost that follows the width.
 */
import { describe, expect, it } from 'vitest';
import { CHANNEL_COUNT, PULSE_MAX_US, PULSE_MIN_US } from '../src/decoder/spec.js';
import { TRACE_ROWS, TraceBuffer, laneUs, laneY, traceView } from '../src/app/traces.js';
import type { TraceBatch } from '../src/worker/protocol.js';

/** A batch of frames `periodUs` apart from `t0`, each carrying the channels `values(i)` gives (others NaN). */
function batch(t0: number, n: number, periodUs: number, values: (i: number) => Record<number, number>, gaps: number[] = []): TraceBatch {
  const us = new Float32Array(n * CHANNEL_COUNT).fill(Number.NaN);
  const t = new Float64Array(n);
  const gap = new Uint8Array(n);
  for (let i = 0; i < n; i++) {
    t[i] = t0 + i * periodUs;
    for (const [c, v] of Object.entries(values(i))) us[i * CHANNEL_COUNT + Number(c)] = v;
  }
  for (const g of gaps) gap[g] = 1;
  return { t, us, gap, spikes: { t: new Float64Array(0), channel: new Uint8Array(0), us: new Float32Array(0) } };
}

describe('the trace buffer', () => {
  it('holds a channel sent every other frame from one appearance to the next, and drops it at a break', () => {
    const b = new TraceBuffer();
    // Channel 0 in even frames, channel 5 in odd ones; a break before frame 6.
    b.append(batch(0, 10, 11_000, (i): Record<number, number> => (i % 2 === 0 ? { 0: 1000 + i } : { 5: 2000 - i }), [0, 6]));
    const at = (i: number, c: number) => b.us[i * CHANNEL_COUNT + c];
    expect(b.length).toBe(10);
    expect(at(0, 5)).toBeNaN();
    expect(at(1, 0)).toBe(1000);
    expect(at(1, 5)).toBe(1999);
    expect(at(5, 0)).toBe(1004);
    // After the break, channel 5 has no value until it comes again.
    expect(at(6, 0)).toBe(1006);
    expect(at(6, 5)).toBeNaN();
    expect(at(7, 5)).toBe(1993);
    expect(b.seen).toBe((1 << 0) | (1 << 5));
  });

  it('keeps at most TRACE_ROWS frames over a session of any length, the newest, and breaks the line where it cut', () => {
    const b = new TraceBuffer();
    let t = 0;
    for (let k = 0; k < 200; k++) {
      b.append(batch(t, 1000, 11_000, () => ({ 0: 1500 })));
      t += 1000 * 11_000;
      expect(b.length).toBeLessThanOrEqual(TRACE_ROWS);
    }
    expect(b.t[b.length - 1]).toBe(t - 11_000);
    expect(b.length).toBeGreaterThan(TRACE_ROWS / 2);
    expect(b.gap[0]).toBe(1);
    expect(b.t.length).toBeLessThanOrEqual(TRACE_ROWS);
  });
});

describe('the traces view', () => {
  it('maps µs into lanes and back, the top lane first, 1500 µs on each lane centre', () => {
    for (const lane of [0, 3, 11])
      for (const us of [PULSE_MIN_US, 1500, PULSE_MAX_US]) expect(laneUs(laneY(us, lane, 12), lane, 12)).toBeCloseTo(us, 6);
    expect(laneY(1500, 0, 12)).toBeCloseTo(11.5, 9);
    expect(laneY(1500, 11, 12)).toBeCloseTo(0.5, 9);
    expect(laneY(PULSE_MAX_US, 1, 12)).toBeLessThan(laneY(PULSE_MIN_US, 0, 12));
  });

  it('draws every frame in a window with few, and breaks the line at a break', () => {
    const b = new TraceBuffer();
    b.append(batch(0, 20, 11_000, (i) => ({ 2: 1000 + i * 10 }), [0, 10]));
    const [x, y] = traceView(b, [2], 0, 1e6, 800);
    // 20 frames and the empty point of the break.
    expect(x?.length).toBe(21);
    expect(y?.filter((v) => v === null).length).toBe(1);
    expect(y?.[10]).toBeNull();
    expect(laneUs(y?.[0] ?? 0, 0, 1)).toBeCloseTo(1000, 3);
  });

  it('keeps a one-frame glitch in view when frames outnumber the columns, at two points a column', () => {
    const b = new TraceBuffer();
    // Ten minutes at 11 ms, one frame at 2000 µs in the middle.
    const n = 54_000;
    b.append(batch(0, n, 11_000, (i) => ({ 0: i === 27_123 ? 2000 : 1500 })));
    const [x, y] = traceView(b, [0], 0, n * 11_000, 1000);
    expect(x?.length).toBeLessThanOrEqual(2 * 1001);
    const top = Math.max(...(y ?? []).map((v) => (v === null ? -1 : laneUs(v, 0, 1))));
    expect(top).toBeCloseTo(2000, 2);
    expect((y ?? []).filter((v) => v !== null && Math.abs(laneUs(v, 0, 1) - 2000) < 0.01).length).toBe(1);
  });
});
