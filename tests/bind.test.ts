import { describe, expect, it } from 'vitest';
import {
  BIND_MODES,
  BIND_WINDOW,
  DEFAULT_CHIPS,
  BIND_PULSE_MAX_US,
  BIND_PULSE_MIN_US,
  USB_SERIAL_CHIPS,
  bindMode,
  bindPulsesFor,
  bindTimeline,
  chipBaudRate,
  chipsForUsbId,
  countFallingEdges,
  measurePulses,
  planPulses,
  powerSignals,
  uartWaveform,
  validatePlan,
  type PulsePlan,
  type UsbSerialChip,
} from '../src/bind/index.js';

// ---------------------------------------------------------------------------------------------
// An independent line model: every bit is its own step, nothing merged, gaps in µs.

interface Edge {
  t: number;
  level: 0 | 1;
}

/** Level changes on the TX line (idle high before t = 0), bit by bit. */
function simulateLine(
  bytes: ArrayLike<number>,
  baud: number,
  stopBits: 1 | 2,
  gapAfterUs: (i: number) => number = () => 0,
): { edges: Edge[]; endUs: number } {
  const bitUs = 1e6 / baud;
  const edges: Edge[] = [];
  let level: 0 | 1 = 1;
  let t = 0;
  const bit = (v: 0 | 1) => {
    if (v !== level) {
      edges.push({ t, level: v });
      level = v;
    }
    t += bitUs;
  };
  for (let i = 0; i < bytes.length; i++) {
    const b = bytes[i]!;
    bit(0); // start
    for (let k = 0; k < 8; k++) bit(((b >> k) & 1) as 0 | 1); // LSB first
    for (let k = 0; k < stopBits; k++) bit(1);
    if (i < bytes.length - 1) t += gapAfterUs(i); // idle high: no edge
  }
  return { edges, endUs: t };
}

/** Falling edges, low widths and the high widths between lows, from level changes. */
function pulsesOf(edges: Edge[]): { falls: number; lows: number[]; highs: number[] } {
  const lows: number[] = [];
  const highs: number[] = [];
  let falls = 0;
  let lastFall = NaN;
  let lastRise = NaN;
  for (const e of edges) {
    if (e.level === 0) {
      falls++;
      if (!Number.isNaN(lastRise)) highs.push(e.t - lastRise);
      lastFall = e.t;
    } else {
      lows.push(e.t - lastFall);
      lastRise = e.t;
    }
  }
  return { falls, lows, highs };
}

/** mulberry32: a small seeded PRNG, so failures reproduce. */
function prng(seed: number): () => number {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

const NS = [3, 4, 5, 6, 7, 8, 9, 10];
const hex = (p: PulsePlan) => [...p.bytes].map((b) => `0x${b.toString(16).padStart(2, '0')}`).join(' ');

/** Every plan the planner makes that a driver could end up using. */
function plansFor(n: number): { label: string; plan: PulsePlan }[] {
  const out = [{ label: 'default chips', plan: planPulses(n) }];
  for (const chip of USB_SERIAL_CHIPS) out.push({ label: chip, plan: planPulses(n, { chips: [chip] }) });
  for (const [vid, pid] of [
    [0x0403, 0x6001],
    [0x10c4, 0xea60],
    [0x1a86, 0x7523],
    [0x067b, 0x2303],
    [0x067b, 0x23a3],
    [0x2341, 0x0043],
  ] as const) {
    out.push({ label: `usb ${vid.toString(16)}:${pid.toString(16)}`, plan: planPulses(n, { chips: chipsForUsbId(vid, pid) }) });
  }
  out.push({
    label: 'one pulse per byte, ft232r+ch340+pl2303',
    plan: planPulses(n, { chips: ['ft232r', 'ch340', 'pl2303'], maxPulsesPerByte: 1 }),
  });
  out.push({ label: 'forced 9600 (several pulses per byte)', plan: planPulses(n, { baudRates: [9600] }) });
  out.push({
    label: 'forced 45833 8N2 (5 bits low, 6 high)',
    plan: planPulses(n, { baudRates: [45833], stopBits: [2], chips: ['ft232r'] }),
  });
  return out;
}

// ---------------------------------------------------------------------------------------------

describe('§7.2 bind modes', () => {
  it('match the spec tables', () => {
    const spec: [number, 'internal' | 'external', 'DSM2' | 'DSMX', 11 | 22][] = [
      [3, 'internal', 'DSM2', 22],
      [4, 'external', 'DSM2', 22],
      [5, 'internal', 'DSM2', 11],
      [6, 'external', 'DSM2', 11],
      [7, 'internal', 'DSMX', 22],
      [8, 'external', 'DSMX', 22],
      [9, 'internal', 'DSMX', 11],
      [10, 'external', 'DSMX', 11],
    ];
    expect(BIND_MODES.map((m) => [m.pulses, m.remote, m.protocol, m.periodMs])).toEqual(spec);
    // "we recommend that 11ms DSMX be used (9 ("internal") or 10 ("external") pulses)"
    expect(BIND_MODES.filter((m) => m.recommended).map((m) => m.pulses)).toEqual([9, 10]);
    expect(BIND_MODES.map((m) => m.systemByte)).toEqual([0x01, 0x01, 0x12, 0x12, 0xa2, 0xa2, 0xb2, 0xb2]);
    for (const m of BIND_MODES) {
      expect(bindMode(m.pulses)).toBe(m);
      expect(bindPulsesFor(m.remote, m.protocol, m.periodMs)).toBe(m.pulses);
      expect(m.description).toContain(`${m.pulses} pulses`);
    }
    expect(bindPulsesFor('internal')).toBe(9);
    expect(bindPulsesFor('external')).toBe(10);
  });

  it('rejects pulse counts outside 3–10 with RangeError', () => {
    for (const bad of [0, 1, 2, 11, 12, -3, 3.5, 9.000001, NaN, Infinity, -Infinity]) {
      expect(() => bindMode(bad)).toThrow(RangeError);
      expect(() => planPulses(bad)).toThrow(RangeError);
      expect(() => bindTimeline(bad, { powerLine: 'rts' })).toThrow(RangeError);
    }
    expect(validatePlan(planPulses(9), 11).ok).toBe(false);
  });
});

describe('USB-serial chip baud rates', () => {
  it('model each chip as its driver quantizes', () => {
    expect(chipBaudRate('ft232r', 38400)).toBe(38400);
    expect(chipBaudRate('ft232r', 41667)).toBeCloseTo(41666.667, 2); // 3 MHz / 72
    expect(chipBaudRate('ft232r', 16000)).toBe(16000); // 3 MHz / 187.5: an eighth divisor
    expect(chipBaudRate('cp2102', 38400)).toBe(38400);
    expect(chipBaudRate('cp2102', 41667)).toBe(51200); // AN205 table 1: 38602–51558 → 51200
    expect(chipBaudRate('cp2102', 8333)).toBe(9600);
    expect(chipBaudRate('cp2102', 115200)).toBe(115200);
    expect(chipBaudRate('cp2102n', 41667)).toBeCloseTo(41666.667, 2);
    expect(chipBaudRate('ch340', 38400)).toBeCloseTo(38461.54, 1); // 48 MHz / (8 · 156)
    expect(chipBaudRate('ch340', 41667)).toBeCloseTo(41666.667, 2); // 48 MHz / (8 · 144)
    expect(chipBaudRate('ch340', 115200)).toBeCloseTo(115384.6, 0);
    expect(chipBaudRate('pl2303', 38400)).toBe(38400); // direct
    expect(chipBaudRate('pl2303', 41667)).toBe(41958); // 384 MHz / (143 · 4³)
    expect(chipBaudRate('pl2303ta', 41667)).toBe(41702);
    expect(chipBaudRate('pl2303g', 41667)).toBe(41667);
    expect(() => chipBaudRate('ft232r', 0)).toThrow(RangeError);
    expect(() => chipBaudRate('ft232r', 38400.5)).toThrow(RangeError);
  });

  it('maps USB IDs to chips', () => {
    expect(chipsForUsbId(0x0403, 0x6001)).toEqual(['ft232r']);
    expect(chipsForUsbId(0x10c4, 0xea60)).toEqual(['cp2102', 'cp2102n']);
    expect(chipsForUsbId(0x1a86, 0x7523)).toEqual(['ch340']);
    expect(chipsForUsbId(0x067b, 0x2303)).toEqual(['pl2303', 'pl2303ta']);
    expect(chipsForUsbId(0x067b, 0x23a3)).toEqual(['pl2303g']);
    expect(chipsForUsbId(undefined, undefined)).toEqual(DEFAULT_CHIPS);
  });
});

describe('the UART line model', () => {
  it('draws start, LSB-first data and stop bits', () => {
    // 0x55 = 01010101: LSB first after the start bit, the line alternates every bit.
    const w = uartWaveform([0x55], 9600);
    expect(w.map((s) => s.level)).toEqual([0, 1, 0, 1, 0, 1, 0, 1, 0, 1]);
    expect(countFallingEdges(w)).toBe(5);
    // 0x00: start + 8 zeros = 9 bits low, then the stop bit.
    const z = uartWaveform([0x00], 10_000, 2, 50, 70);
    expect(z).toEqual([
      { level: 1, durationUs: 50 },
      { level: 0, durationUs: 900 },
      { level: 1, durationUs: 270 },
    ]);
    // 0xFF: only the start bit is low.
    expect(measurePulses(uartWaveform([0xff], 10_000)).lowUs).toEqual([100]);
    // 0xF0: five bits low, five high.
    const f = uartWaveform([0xf0, 0xf0], 38400);
    expect(f.map((s) => s.level)).toEqual([0, 1, 0, 1]);
    expect(f.map((s) => s.durationUs)).toEqual([5, 5, 5, 5].map((b) => (b * 1e6) / 38400));
    // A line that was low before starts without a falling edge.
    expect(countFallingEdges(uartWaveform([0x00], 9600), 0)).toBe(0);
    expect(() => uartWaveform([256], 9600)).toThrow(RangeError);
    expect(() => uartWaveform([1], 0)).toThrow(RangeError);
    expect(() => uartWaveform([1, 2], 9600, 1, 0, 0, [-1])).toThrow(RangeError);
  });

  it('agrees with the bit-by-bit simulation, gaps included', () => {
    const rnd = prng(7);
    for (let trial = 0; trial < 200; trial++) {
      const bytes = Array.from({ length: 1 + Math.floor(rnd() * 6) }, () => Math.floor(rnd() * 256));
      const gaps = bytes.map(() => (rnd() < 0.5 ? 0 : rnd() * 300));
      const stop = rnd() < 0.5 ? 1 : 2;
      const baud = [9600, 19200, 38400, 41667][Math.floor(rnd() * 4)]!;
      const m = measurePulses(uartWaveform(bytes, baud, stop, 0, 0, gaps));
      const s = pulsesOf(simulateLine(bytes, baud, stop, (i) => gaps[i]!).edges);
      expect(m.edges).toBe(s.falls);
      expect(m.lowUs.length).toBe(s.lows.length);
      m.lowUs.forEach((w, i) => {
        expect(w).toBeCloseTo(s.lows[i]!, 6);
      });
      m.highUs.forEach((w, i) => {
        expect(w).toBeCloseTo(s.highs[i]!, 6);
      });
    }
  });
});

describe('planPulses', () => {
  it('picks 38400 baud 8N1, one 0xF0 per pulse, for the four common chips', () => {
    for (const n of NS) {
      const p = planPulses(n);
      expect(p.baudRate).toBe(38400);
      expect(p.stopBits).toBe(1);
      expect([...p.bytes]).toEqual(new Array(n).fill(0xf0));
      expect(p.pulsesPerByte).toBe(1);
      for (const w of [...p.lowUs, ...p.highUs]) expect(w).toBeCloseTo(5e6 / 38400, 9); // 130.2 µs
      expect(p.highUs).toHaveLength(n - 1);
      expect(p.totalUs).toBeCloseTo((n * 10e6) / 38400, 6);
      expect(p.worstDeviation).toBeCloseTo(5e6 / 38400 / 120 - 1, 9); // +8.5 %
      for (const c of p.chipRates) expect(Math.abs(c.error)).toBeLessThanOrEqual(0.02);
    }
    // 41667 baud would be exact, but a CP2102 makes 51200 of it.
    expect(Math.abs(chipBaudRate('cp2102', 41667) / 41667 - 1)).toBeGreaterThan(0.02);
  });

  it('gives exact 120 µs phases where every chip can make 41667 baud', () => {
    for (const chips of [['ft232r'], ['ch340'], ['cp2102n'], ['ft232r', 'ch340']] as UsbSerialChip[][]) {
      const p = planPulses(9, { chips });
      expect(p.baudRate).toBe(41667);
      expect([...p.bytes]).toEqual(new Array(9).fill(0xf0));
      for (const w of p.lowUs) expect(w).toBeCloseTo(120, 1);
    }
  });

  for (const n of NS) {
    it(`${n} pulses: every plan draws exactly ${n} falling edges of the right widths, in the window`, () => {
      for (const { label, plan } of plansFor(n)) {
        const where = `${label}: ${plan.baudRate} 8N${plan.stopBits} ${hex(plan)}`;
        expect(plan.pulses, where).toBe(n);
        expect(plan.edges, where).toBe(n);
        // At the requested rate and at the rate each chip really makes.
        const rates = [plan.baudRate, ...plan.chipRates.map((c) => c.baudRate)];
        for (const baud of rates) {
          const { edges, endUs } = simulateLine(plan.bytes, baud, plan.stopBits);
          const { falls, lows, highs } = pulsesOf(edges);
          expect(falls, `${where} at ${baud}`).toBe(n);
          expect(lows, where).toHaveLength(n);
          expect(highs, where).toHaveLength(n - 1);
          for (const w of [...lows, ...highs]) {
            expect(w, `${where} at ${baud}`).toBeGreaterThanOrEqual(BIND_PULSE_MIN_US);
            expect(w, `${where} at ${baud}`).toBeLessThanOrEqual(BIND_PULSE_MAX_US);
          }
          expect(edges[edges.length - 1]!.level, where).toBe(1); // ends idle high
          expect(endUs).toBeCloseTo((plan.bytes.length * plan.frameBits * 1e6) / baud, 6);
        }
        // The plan's own numbers are the nominal (requested-rate) simulation.
        const nominal = pulsesOf(simulateLine(plan.bytes, plan.baudRate, plan.stopBits).edges);
        plan.lowUs.forEach((w, i) => {
          expect(w).toBeCloseTo(nominal.lows[i]!, 6);
        });
        plan.highUs.forEach((w, i) => {
          expect(w).toBeCloseTo(nominal.highs[i]!, 6);
        });
        expect(plan.totalUs).toBeCloseTo((plan.bytes.length * plan.frameBits * 1e6) / plan.baudRate, 6);

        // In the window: after power-on, the last pulse done well before 200 ms.
        const timeline = bindTimeline(n, { powerLine: 'rts', plan });
        const on = timeline.find((s) => s.action === 'power-on')!;
        const write = timeline.find((s) => s.action === 'write')!;
        const startMs = write.atMs - on.atMs;
        expect(startMs).toBeGreaterThanOrEqual(BIND_WINDOW.earliestMs);
        expect(startMs + plan.totalUs / 1000).toBeLessThanOrEqual(BIND_WINDOW.latestMs);
        const check = validatePlan(plan, n, { timeline });
        expect(check.problems, where).toEqual([]);
        expect(check.ok).toBe(true);
      }
    });

    it(`${n} pulses: random idle gaps of 0–200 µs between bytes keep the count and the low widths`, () => {
      const rnd = prng(1000 + n);
      for (const { label, plan } of plansFor(n)) {
        const nominal = pulsesOf(simulateLine(plan.bytes, plan.baudRate, plan.stopBits).edges);
        for (let trial = 0; trial < 40; trial++) {
          const gaps = Array.from({ length: plan.bytes.length }, () => rnd() * 200);
          const { edges } = simulateLine(plan.bytes, plan.baudRate, plan.stopBits, (i) => gaps[i]!);
          const { falls, lows, highs } = pulsesOf(edges);
          expect(falls, label).toBe(n);
          lows.forEach((w, i) => {
            expect(w, label).toBeCloseTo(nominal.lows[i]!, 9);
          });
          // Gaps only lengthen highs, each by at most one gap.
          highs.forEach((w, i) => {
            expect(w).toBeGreaterThanOrEqual(nominal.highs[i]! - 1e-9);
            expect(w).toBeLessThanOrEqual(nominal.highs[i]! + 200 + 1e-9);
          });
          // The library's own waveform says the same.
          const m = measurePulses(uartWaveform(plan.bytes, plan.baudRate, plan.stopBits, 0, 0, gaps));
          expect(m.edges).toBe(n);
          m.lowUs.forEach((w, i) => {
            expect(w).toBeCloseTo(lows[i]!, 6);
          });
        }
      }
    });
  }

  it('reports what it cannot do', () => {
    // At 115200 a frame (86.8 µs) cannot hold a 120 µs low; 19200 gives 104 µs lows with 156 µs highs.
    expect(() => planPulses(9, { baudRates: [115200] })).toThrow(RangeError);
    expect(() => planPulses(9, { baudRates: [19200] })).toThrow(RangeError);
    // A CP2102 turns 41667 into 51200.
    expect(() => planPulses(9, { baudRates: [41667], chips: ['cp2102'] })).toThrow(RangeError);
    // 8N2 at 8333: every byte ends with two stop bits, so highs between bytes are 240 µs.
    expect(() => planPulses(9, { baudRates: [8333], stopBits: [2], chips: ['ft232r'] })).toThrow(RangeError);
  });
});

describe('validatePlan', () => {
  it('catches wrong counts, widths and windows', () => {
    const good = planPulses(9);
    expect(validatePlan(good, 9).ok).toBe(true);
    expect(validatePlan(good, 10).problems.join()).toContain('9 falling edges, not 10');

    // 19200 baud can only make 104 µs lows with 156 µs highs (or worse).
    const slow = planPulses(9, { baudRates: [19200], maxDeviation: Infinity });
    const s = validatePlan(slow, 9);
    expect(s.ok).toBe(false);
    expect(s.problems.join()).toMatch(/outside 90–150/);

    // A hand-made plan: 0x00 bytes are 9 bits low and 1 bit high.
    const bad: PulsePlan = { ...good, bytes: new Uint8Array(9) };
    expect(validatePlan(bad, 9).problems.join()).toMatch(/low 1 is 234\.4 µs/);

    const early = bindTimeline(9, { powerLine: 'dtr', settleMs: 5 });
    expect(validatePlan(good, 9, { timeline: early }).problems.join()).toContain('before 20 ms');
    expect(validatePlan(good, 9, { timeline: bindTimeline(9, { powerLine: 'dtr', settleMs: 197 }) }).ok).toBe(true); // ends at 199.3 ms
    const late = bindTimeline(9, { powerLine: 'dtr' }).map((s) => (s.action === 'write' ? { ...s, atMs: s.atMs + 150 } : s));
    expect(validatePlan(good, 9, { timeline: late }).problems.join()).toContain('after 200 ms');
    const wrongBytes = bindTimeline(9, { powerLine: 'dtr', plan: planPulses(9, { chips: ['ft232r'] }) });
    expect(validatePlan(good, 9, { timeline: wrongBytes }).ok).toBe(false);
  });
});

describe('bindTimeline', () => {
  it('power-cycles, writes in the window and reopens at 115200', () => {
    const plan = planPulses(9);
    const steps = bindTimeline(9, { powerLine: 'rts' });
    expect(steps.map((s) => s.action)).toEqual(['open', 'power-off', 'power-on', 'write', 'reopen']);
    const [open, off, on, write, reopen] = steps;
    expect(open).toMatchObject({ atMs: 0, baudRate: 38400, stopBits: 1, dataBits: 8, parity: 'none', flowControl: 'none' });
    expect(off).toMatchObject({ atMs: 0, signals: { requestToSend: false } });
    expect(on).toMatchObject({ atMs: 500, sincePowerOnMs: 0, signals: { requestToSend: true } });
    expect(write).toMatchObject({ atMs: 560, sincePowerOnMs: 60 });
    expect(write?.action === 'write' && [...write.bytes]).toEqual([...plan.bytes]);
    expect(reopen).toMatchObject({ baudRate: 115200, signals: { requestToSend: true } });
    expect(reopen!.atMs).toBeGreaterThanOrEqual(write!.atMs + plan.totalUs / 1000);
    for (let i = 1; i < steps.length; i++) expect(steps[i]!.atMs).toBeGreaterThanOrEqual(steps[i - 1]!.atMs);
    expect(on!.atMs - off!.atMs).toBeGreaterThanOrEqual(200);

    const dtr = bindTimeline(10, { powerLine: 'dtr', offMs: 300, settleMs: 80, polarity: 'deasserted', holdTxLowWhileOff: true });
    expect(dtr[1]).toMatchObject({ atMs: 0, signals: { dataTerminalReady: true, break: true } });
    expect(dtr[2]).toMatchObject({ atMs: 300, signals: { dataTerminalReady: false, break: false } });
    expect(dtr[3]).toMatchObject({ atMs: 380 });
  });

  it('maps the power line to setSignals: asserted is the pin low', () => {
    expect(powerSignals('rts', true)).toEqual({ requestToSend: true });
    expect(powerSignals('rts', false)).toEqual({ requestToSend: false });
    expect(powerSignals('dtr', true)).toEqual({ dataTerminalReady: true });
    expect(powerSignals('dtr', true, 'deasserted')).toEqual({ dataTerminalReady: false });
  });

  it('refuses timelines outside the spec', () => {
    expect(() => bindTimeline(9, { powerLine: 'rts', offMs: 150 })).toThrow(RangeError);
    expect(() => bindTimeline(9, { powerLine: 'rts', settleMs: 199 })).toThrow(RangeError);
    expect(() => bindTimeline(9, { powerLine: 'rts', settleMs: -1 })).toThrow(RangeError);
    expect(() => bindTimeline(9, { powerLine: 'rts', plan: planPulses(10) })).toThrow(RangeError);
    expect(() => bindTimeline(9, { powerLine: 'cts' as 'rts' })).toThrow(RangeError);
  });
});
