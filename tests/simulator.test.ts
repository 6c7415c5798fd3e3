/**
 * The receiver simulator: bit layouts, frame timing, determinism, fades, RSSI, dropouts, line
 * damage, and ground truth checked against the bytes with a small reference decoding written
 * here from the spec (§8.1, §8.2, §8.6), independent of the production decoder.
 */
import { readFileSync, readdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { PRESET_NAMES, demoScenario, preset, presets } from '../src/simulator/presets.js';
import { Simulator, simulate, type SimChunk } from '../src/simulator/simulator.js';
import { channelLayout, describeLayout } from '../src/simulator/layouts.js';
import {
  encodeExternalFrame,
  encodeInternalFrame,
  encodeServo1024,
  encodeServo2048,
  encodeVtx,
  encodeXPlus,
  vtxControl,
  vtxWords,
  xplusPosition,
} from '../src/simulator/encode.js';
import { resolveScenario, type Scenario } from '../src/simulator/scenario.js';
import { toFixtureFrame, type TruthFrame } from '../src/simulator/truth.js';

// ---------------------------------------------------------------------------------------------
// Reference decoding, straight from the spec.

interface RefChannel {
  id: number;
  pos: number;
}
interface RefFrame {
  words: number[];
  channels: RefChannel[];
  vtx: { raw: number; band: number; channel: number; power: number; region: number; pit: boolean } | null;
}

/** §8.6 sample code, transcribed. */
function servoPosition(rfData: number, phase: number): RefChannel | null {
  let chan = (rfData >> 11) & 0x0f;
  if (chan < 12) return { id: chan, pos: rfData & 0x07ff };
  if (chan === 12) {
    chan += (rfData >> 9) & 0x03;
    if (phase) chan += 4;
    return { id: chan, pos: (rfData & 0x01ff) << 2 };
  }
  return null;
}

function refDecode(bytes: Uint8Array, at: number, resolution: 1024 | 2048): RefFrame {
  const words: number[] = [];
  for (let s = 0; s < 7; s++) words.push((bytes[at + 2 + 2 * s]! << 8) | bytes[at + 3 + 2 * s]!);
  const raw = ((words[5]! << 16) | words[6]!) >>> 0;
  let vtx: RefFrame['vtx'] = null;
  let n = 7;
  if ((raw & 0xf000f000) >>> 0 === 0xe000e000 && (words[0]! & 0x8000) === 0) {
    vtx = {
      raw,
      band: (raw >> 21) & 7,
      channel: (raw >> 16) & 15,
      power: raw & 7,
      region: (raw >> 3) & 1,
      pit: ((raw >> 4) & 1) === 1,
    };
    n = 5;
  }
  const channels: RefChannel[] = [];
  for (let s = 0; s < n; s++) {
    const w = words[s]!;
    if (w === 0xffff) continue;
    if (resolution === 1024) channels.push({ id: w >> 10, pos: w & 0x03ff });
    else {
      const c = servoPosition(w, w >> 15);
      if (c) channels.push(c);
    }
  }
  return { words, channels, vtx };
}

function run(s: Scenario, durationUs?: number): { sim: Simulator; chunk: SimChunk; frames: TruthFrame[] } {
  const sim = new Simulator(s, { truth: true });
  const chunk = sim.generate(sim.scenario.timing.startUs + (durationUs ?? sim.scenario.durationUs));
  return { sim, chunk, frames: chunk.truth!.frames };
}

const intact = (frames: TruthFrame[]) => frames.filter((f) => f.damage === null);
const hex = (w: number) => `0x${w.toString(16).toUpperCase().padStart(4, '0')}`;

// ---------------------------------------------------------------------------------------------

describe('frame encoding', () => {
  it('puts phase, channel ID and position where §8.2 says (2048 mode)', () => {
    // 1 << 15 | 1 << 11 | 1024 = 0x8000 + 0x0800 + 0x0400: the first word of dsm_x_data.txt.
    expect(hex(encodeServo2048(1, 1024, 1))).toBe('0x8C00');
    // Aux 1 at 1706 = 5 << 11 | 0x6AA, as in the PX4 captures.
    expect(hex(encodeServo2048(5, 1706))).toBe('0x2EAA');
    expect(hex(encodeServo2048(0, 352, true))).toBe('0x8160');
    expect(hex(encodeServo2048(15, 2047))).toBe('0x7FFF');
  });

  it('puts channel ID and position where §8.1 says (1024 mode)', () => {
    // 3 << 10 | 512 = 0x0C00 + 0x0200.
    expect(hex(encodeServo1024(3, 512))).toBe('0x0E00');
    expect(hex(encodeServo1024(11, 1023))).toBe('0x2FFF');
    expect(hex(encodeServo1024(0, 0))).toBe('0x0000');
  });

  it('encodes X-Plus channels as ID 12 with a sub-ID, the phase bit for X+5…X+8 and a 9-bit value (§8.6)', () => {
    // X+4 (channel 15), value 1024: 0x6000 | 3 << 9 | 1024 >> 2 = 0x6000 + 0x0600 + 0x0100 (DX9 capture).
    expect(hex(encodeXPlus(15, 1024))).toBe('0x6700');
    // X+1 (channel 12) at 1024: 0x6000 | 0 | 0x100 (DX9 capture).
    expect(hex(encodeXPlus(12, 1024))).toBe('0x6100');
    // X+5 (channel 16) at 1024: phase 0x8000 | 0x6000 | sub 0 | 0x100.
    expect(hex(encodeXPlus(16, 1024))).toBe('0xE100');
    // X+8 (channel 19) at 2047: 0x8000 | 0x6000 | 3 << 9 | 511.
    expect(hex(encodeXPlus(19, 2047))).toBe('0xE7FF');
    // X+6 (channel 17) at 341: 0x8000 | 0x6000 | 1 << 9 | 85 = 0xE255; decoders report 85 << 2 = 340.
    expect(hex(encodeXPlus(17, 341))).toBe('0xE255');
    expect(xplusPosition(341)).toBe(340);
  });

  it('encodes VTX control with both top nibbles 0xE and band, channel, pit, region and power in place', () => {
    const v = { band: 4, channel: 5, power: 3, region: 1, pit: true };
    // 0xE000E000 | 4 << 21 (0x800000) | 5 << 16 (0x50000) | 0x10 | 0x08 | 3.
    expect(encodeVtx(v)).toBe(0xe085e01b);
    expect(vtxWords(v).map(hex)).toEqual(['0xE085', '0xE01B']);
    expect(vtxControl(v)).toEqual({ raw: 0xe085e01b, ...v });
    expect(encodeVtx({ band: 0, channel: 0, power: 0, region: 0, pit: false })).toBe(0xe000e000);
  });

  it('reproduces a real internal-remote frame byte for byte (PX4 DX9 binding capture)', () => {
    const words = [0x0bff, 0x2c00, 0x13ff, 0x2156, 0x36aa, 0x5400, 0x6100];
    const frame = encodeInternalFrame({ fades: 0x3e, system: 0xb2 }, words);
    expect(Array.from(frame)).toEqual([0x3e, 0xb2, 0x0b, 0xff, 0x2c, 0x00, 0x13, 0xff, 0x21, 0x56, 0x36, 0xaa, 0x54, 0x00, 0x61, 0x00]);
  });

  it('writes RSSI as a signed byte and external fades as a big-endian UINT16', () => {
    expect(encodeInternalFrame({ rssi: -61, system: 0xb2 }, [])[0]).toBe(0xc3);
    expect(encodeInternalFrame({ rssi: -128, system: 0xb2 }, [])[0]).toBe(0x80);
    const ext = encodeExternalFrame(0x1234, [0x8c00]);
    expect(Array.from(ext.subarray(0, 4))).toEqual([0x12, 0x34, 0x8c, 0x00]);
  });

  it('fills slots without a word with 0xFFFF and writes at an offset into a given buffer', () => {
    const buf = new Uint8Array(20);
    encodeExternalFrame(0, [0x0400], buf, 4);
    expect(Array.from(buf.subarray(0, 4))).toEqual([0, 0, 0, 0]);
    expect(Array.from(buf.subarray(8, 20)).every((b) => b === 0xff)).toBe(true);
  });

  it('rejects values the format cannot carry with RangeError', () => {
    expect(() => encodeServo2048(16, 0)).toThrow(RangeError);
    expect(() => encodeServo2048(1, 2048)).toThrow(RangeError);
    expect(() => encodeServo1024(1, 1024)).toThrow(RangeError);
    expect(() => encodeXPlus(11, 0)).toThrow(RangeError);
    expect(() => encodeXPlus(20, 0)).toThrow(RangeError);
    expect(() => encodeVtx({ band: 8, channel: 0, power: 0, region: 0, pit: false })).toThrow(RangeError);
    expect(() => encodeInternalFrame({ fades: 256, system: 0xb2 }, [])).toThrow(RangeError);
    expect(() => encodeExternalFrame(0, [1, 2, 3, 4, 5, 6, 7, 8])).toThrow(RangeError);
    expect(() => encodeExternalFrame(0, [], new Uint8Array(16), 1)).toThrow(RangeError);
  });
});

describe('channel layouts', () => {
  it('spreads 10 channels over a pair like the PX4 dsm_x_data capture', () => {
    expect(describeLayout(channelLayout(2048, 11, 10))).toBe('1p 5 2 3 0 7 6 / 1 5 2 3 4 8 9');
  });

  it('spreads 12 channels + X-Plus like the DX9 capture, with X-Plus in the 7th word', () => {
    expect(describeLayout(channelLayout(2048, 11, 12, true))).toBe('0p 7 3 8 9 11 X / 1 5 2 4 6 10 X');
  });

  it('fills the unused slot of each frame of a 12-channel pair with 0xFFFF', () => {
    expect(describeLayout(channelLayout(2048, 11, 12))).toBe('0p 7 3 8 9 11 -- / 1 5 2 4 6 10 --');
  });

  it('sends one frame shape with ascending IDs on 22 ms links of up to 7 channels, and no phase bit in 1024 mode', () => {
    expect(describeLayout(channelLayout(2048, 22, 5))).toBe('0 1 2 3 4 -- --');
    expect(describeLayout(channelLayout(1024, 22, 8))).toBe('1 5 2 3 0 7 6 / 1 5 2 3 4 -- --');
  });

  it('carries every channel at least once per pair for 1–12 channels', () => {
    for (let n = 1; n <= 12; n++) {
      for (const [res, ms] of [
        [2048, 11],
        [2048, 22],
        [1024, 22],
      ] as const) {
        const ids = new Set(channelLayout(res, ms, n).flatMap((f) => f.slots.filter((s) => typeof s === 'number')));
        expect([...ids].sort((a, b) => a - b)).toEqual(Array.from({ length: n }, (_, i) => i));
      }
    }
  });

  it('refuses X-Plus in 1024 mode or where no slot is free', () => {
    expect(() => channelLayout(1024, 22, 6, true)).toThrow(RangeError);
    expect(() => channelLayout(2048, 11, 8, true)).toThrow(RangeError);
  });
});

describe('scenarios', () => {
  it('rejects options the simulator cannot honour with TypeError', () => {
    const base: Scenario = { system: 0xb2 };
    expect(() => new Simulator({ system: 0x33 })).toThrow(TypeError);
    expect(() => new Simulator({ ...base, system: 0x01, xplus: 2 })).toThrow(TypeError);
    expect(() => new Simulator({ ...base, remote: 'external', headerMode: 'rssi' })).toThrow(TypeError);
    expect(() => new Simulator({ ...base, systemByte: 0x55 })).toThrow(TypeError);
    expect(() => new Simulator({ ...base, remote: 'external', systemByte: 0x01 })).toThrow(TypeError);
    expect(() => new Simulator({ ...base, channels: 13 })).toThrow(TypeError);
    expect(() => new Simulator({ ...base, damage: { truncateMaxBytes: 16 } })).toThrow(TypeError);
  });

  it('has presets for every system type on internal and external remotes', () => {
    const seen = new Set(presets().map((p) => `${resolveScenario(p).system}/${p.remote ?? 'internal'}`));
    for (const sys of [0x01, 0x12, 0xa2, 0xb2]) {
      expect(seen.has(`${sys}/internal`)).toBe(true);
      expect(seen.has(`${sys}/external`)).toBe(true);
    }
    expect(PRESET_NAMES.length).toBe(new Set(PRESET_NAMES).size);
  });

  it('hands out presets as fresh copies', () => {
    const a = preset('vtx');
    a.channels = 1;
    expect(preset('vtx').channels).toBe(10);
    expect(() => preset('no-such-thing')).toThrow(RangeError);
  });
});

describe('frame timing', () => {
  it('spaces bytes 86.8 µs apart and starts frames every 11 ms with a little jitter', () => {
    const { chunk, frames } = run(preset('dsmx-11ms-2048-internal'), 1_000_000);
    const t = chunk.timesUs;
    for (const f of frames) {
      for (let i = 1; i < 16; i++) expect(t[f.offset + i]! - t[f.offset + i - 1]!).toBeCloseTo(86.806, 1);
    }
    for (let i = 1; i < frames.length; i++) {
      const d = frames[i]!.timeUs - frames[i - 1]!.timeUs;
      const slots = frames[i]!.slot - frames[i - 1]!.slot;
      expect(Math.abs(d - 11_000 * slots)).toBeLessThanOrEqual(16);
    }
    // The idle gap between frames is about 9.7 ms.
    const gap = frames[1]!.timeUs - (frames[0]!.timeUs + 15 * 86.806);
    expect(gap).toBeGreaterThan(9_600);
    expect(gap).toBeLessThan(9_720);
  });

  it('starts frames every 22 ms on 22 ms systems', () => {
    for (const name of ['dsm2-22ms-1024-internal', 'dsmx-22ms-2048-external']) {
      const { frames } = run(preset(name), 1_000_000);
      const d = frames[1]!.timeUs - frames[0]!.timeUs;
      expect(Math.abs(d - 22_000 * (frames[1]!.slot - frames[0]!.slot))).toBeLessThanOrEqual(16);
    }
  });

  it('spaces bytes 88.6 µs apart for a clone that runs slow', () => {
    const { chunk } = run(preset('clone-zero-header'), 100_000);
    expect(chunk.timesUs[1]! - chunk.timesUs[0]!).toBeCloseTo(88.6, 1);
  });

  it('keeps byte times strictly increasing, noise and damage included', () => {
    for (const name of ['damaged-line', 'dropouts-and-damage', 'fade-wrap-external']) {
      const { chunk } = run(preset(name));
      for (let i = 1; i < chunk.timesUs.length; i++) expect(chunk.timesUs[i]!).toBeGreaterThan(chunk.timesUs[i - 1]!);
    }
  });
});

describe('determinism', () => {
  it('gives the same bytes and times for the same seed', () => {
    const a = simulate(preset('damaged-line'));
    const b = simulate(preset('damaged-line'));
    expect(a.bytes).toEqual(b.bytes);
    expect(a.timesUs).toEqual(b.timesUs);
  });

  it('gives different bytes for a different seed', () => {
    const a = simulate({ ...preset('damaged-line'), seed: 1 });
    const b = simulate({ ...preset('damaged-line'), seed: 2 });
    expect(a.bytes).not.toEqual(b.bytes);
  });

  it('gives the same stream however the output is chunked', () => {
    const whole = simulate(preset('dropouts-and-damage'));
    const sim = new Simulator(preset('dropouts-and-damage'));
    const bytes = new Uint8Array(whole.bytes.length);
    const times = new Float64Array(whole.bytes.length);
    let n = 0;
    const end = sim.scenario.timing.startUs + sim.scenario.durationUs;
    // Tiny buffers (7 bytes) split frames; the time limit advances in odd steps.
    const small = new Uint8Array(7);
    const smallT = new Float64Array(7);
    for (let until = sim.scenario.timing.startUs; n < bytes.length; until = Math.min(end, until + 3_777)) {
      const k = sim.generateInto(small, smallT, until);
      bytes.set(small.subarray(0, k), n);
      times.set(smallT.subarray(0, k), n);
      n += k;
      if (k === 0 && until === end) break;
    }
    expect(n).toBe(whole.bytes.length);
    expect(bytes).toEqual(whole.bytes);
    expect(times).toEqual(whole.timesUs);
    // The iterator agrees too.
    const parts = [...new Simulator(preset('dropouts-and-damage')).chunks(50_000, end)];
    expect(parts.reduce((s, p) => s + p.bytes.length, 0)).toBe(whole.bytes.length);
    expect(parts.every((p) => p.truth === null)).toBe(true);
  });

  it('leaves stick motion alone when line damage is switched on', () => {
    const clean = run({ ...preset('damaged-line'), damage: {} }).frames;
    const damaged = run(preset('damaged-line')).frames;
    const bySlot = new Map(clean.map((f) => [f.slot, f.channels]));
    for (const f of damaged) expect(f.channels).toEqual(bySlot.get(f.slot));
  });
});

describe('ground truth', () => {
  const names = [...PRESET_NAMES, 'demo'];

  it.each(names)('matches the bytes of every undamaged frame (%s)', (name) => {
    const { chunk, frames } = run(preset(name), name === 'demo' ? 12_000_000 : undefined);
    expect(intact(frames).length).toBeGreaterThan(50);
    for (const f of intact(frames)) {
      expect(f.length).toBe(16);
      const b = chunk.bytes;
      expect(Array.from(b.subarray(f.offset, f.offset + 16))).toEqual(Array.from(f.bytes));
      const ref = refDecode(b, f.offset, f.resolution);
      expect(ref.words).toEqual(f.words);
      expect(ref.channels).toEqual(f.channels);
      expect(ref.vtx).toEqual(f.vtx);
      expect(chunk.timesUs[f.offset]).toBe(f.timeUs);
      expect(f.words[0]! >> 15).toBe(f.resolution === 2048 ? f.phase : 0);
      // Header.
      const b0 = b[f.offset]!;
      const b1 = b[f.offset + 1]!;
      if (f.remote === 'external') {
        expect(f.system).toBeNull();
        expect(f.fades).toBe((b0 << 8) | b1);
      } else {
        expect(f.system).toBe(b1);
        if (f.headerMode === 'rssi') expect(f.rssi).toBe(b0 > 127 ? b0 - 256 : b0);
        else expect(f.fades).toBe(b0);
      }
    }
  });

  it.each(names)('accounts for every byte as a frame or noise, in order (%s)', (name) => {
    const { chunk } = run(preset(name), name === 'demo' ? 3_000_000 : undefined);
    const { frames, noise } = chunk.truth!;
    const pieces = [...frames.map((f) => [f.offset, f.length]), ...noise.map((x) => [x.offset, x.length])].sort((a, b) => a[0]! - b[0]!);
    let at = 0;
    for (const [off, len] of pieces) {
      expect(off).toBe(at);
      at += len!;
    }
    expect(at).toBe(chunk.bytes.length);
  });

  it('keeps positions within range, with sticks moving and switches at ±100 % (341/1707)', () => {
    const frames = intact(run(preset('dsmx-11ms-2048-internal'), 12_000_000).frames);
    const all = frames.flatMap((f) => f.channels);
    expect(all.every((c) => c.pos >= 0 && c.pos <= 2047)).toBe(true);
    const of = (id: number) => all.filter((c) => c.id === id).map((c) => c.pos);
    expect(new Set(of(4))).toEqual(new Set([341, 1707])); // gear
    expect(of(7).every((p) => p === 341)).toBe(true);
    expect(of(8).every((p) => p === 1707)).toBe(true);
    expect(Math.min(...of(6))).toBe(0); // full-range sweep reaches both ends
    expect(Math.max(...of(6))).toBe(2047);
    expect(Math.max(...of(1)) - Math.min(...of(1))).toBeGreaterThan(800);
    const f1024 = intact(run(preset('dsm2-22ms-1024-internal'), 6_000_000).frames).flatMap((f) => f.channels);
    expect(f1024.every((c) => c.pos >= 0 && c.pos <= 1023)).toBe(true);
    expect(new Set(f1024.filter((c) => c.id === 4).map((c) => c.pos))).toEqual(new Set([171, 853]));
  });

  it('marks damaged frames and records what was removed or flipped', () => {
    const { chunk, frames } = run(preset('damaged-line'), 10_000_000);
    const truncated = frames.filter((f) => f.damage?.kind === 'truncated');
    const flipped = frames.filter((f) => f.damage?.kind === 'bit-flip');
    expect(truncated.length).toBeGreaterThan(5);
    expect(flipped.length).toBeGreaterThan(2);
    expect(chunk.truth!.noise.length).toBeGreaterThan(5);
    // The stream starts mid-frame: the first frame lost its first three bytes.
    expect(frames[0]!.damage).toEqual({ kind: 'truncated', removed: [0, 1, 2] });
    for (const f of truncated) {
      const d = f.damage;
      if (d?.kind !== 'truncated') continue;
      const full = encodeExternalFrame(0, f.words); // this preset's header is 00 00
      const kept = Array.from(full).filter((_, i) => !d.removed.includes(i));
      expect(f.length).toBe(16 - d.removed.length);
      expect(Array.from(chunk.bytes.subarray(f.offset, f.offset + f.length))).toEqual(kept);
    }
    for (const f of flipped) {
      if (f.damage?.kind !== 'bit-flip') continue;
      const full = encodeExternalFrame(0, f.words);
      full[f.damage.byte] = full[f.damage.byte]! ^ (1 << f.damage.bit);
      expect(Array.from(chunk.bytes.subarray(f.offset, f.offset + 16))).toEqual(Array.from(full));
    }
  });

  it('places noise bursts in the idle gap between frames', () => {
    const { chunk, frames } = run(preset('damaged-line'), 10_000_000);
    for (const n of chunk.truth!.noise) {
      const before = frames.filter((f) => f.offset < n.offset).at(-1)!;
      expect(n.timeUs - before.timeUs).toBeGreaterThan(16 * 86.8);
      expect(chunk.timesUs[n.offset]).toBe(n.timeUs);
    }
  });

  it('records nothing and still returns bytes when ground truth is off', () => {
    const sim = new Simulator(preset('vtx'));
    const c = sim.generateFor(100_000);
    expect(c.truth).toBeNull();
    expect(c.bytes.length).toBe(10 * 16);
    expect(sim.takeTruth().frames).toEqual([]);
  });
});

describe('headers', () => {
  it('sends 00 00 in bytes 0–1 of every frame of a clone, reported as an external remote with no fades', () => {
    const { chunk, frames } = run(preset('clone-zero-header'));
    for (const f of frames) {
      expect(chunk.bytes[f.offset]).toBe(0);
      expect(chunk.bytes[f.offset + 1]).toBe(0);
      expect(f).toMatchObject({ remote: 'external', system: null, fades: 0, fadesDelta: 0 });
    }
  });

  it('sends 0xB2 while the data is 1024-format when the system byte lies', () => {
    const frames = intact(run(preset('lying-b2-with-1024-data')).frames);
    for (const f of frames) {
      expect(f.system).toBe(0xb2);
      expect(f.resolution).toBe(1024);
      expect(f.bytes[1]).toBe(0xb2);
      // Under a 1024 reading every slot holds channels 0–6.
      for (const w of f.words) expect(w === 0xffff || w >> 10 <= 6).toBe(true);
    }
  });

  it('sends 0x01 while the data is 2048-format when the system byte lies the other way', () => {
    const frames = intact(run(preset('lying-01-with-2048-data')).frames);
    expect(frames.every((f) => f.system === 0x01 && f.resolution === 2048 && f.bytes[1] === 0x01)).toBe(true);
    expect(frames.some((f) => f.words[0]! & 0x8000)).toBe(true); // phase bits: 2048 data
  });
});

describe('fades', () => {
  it('wraps an internal remote’s UINT8 fade counter and reports the delta across the wrap', () => {
    const frames = intact(run(preset('fade-wrap-internal')).frames);
    const fades = frames.map((f) => f.fades!);
    expect(fades[0]).toBeGreaterThanOrEqual(250);
    expect(fades.every((x) => x >= 0 && x <= 255)).toBe(true);
    const wrapAt = fades.findIndex((x, i) => i > 0 && x < fades[i - 1]!);
    expect(wrapAt).toBeGreaterThan(0);
    const f = frames[wrapAt]!;
    expect(f.fadesDelta).toBe((f.fades! - frames[wrapAt - 1]!.fades! + 256) % 256);
    expect(f.fadesDelta).toBeGreaterThan(0);
  });

  it('wraps an external remote’s UINT16 fade counter through 65535 to 0', () => {
    const frames = intact(run(preset('fade-wrap-external')).frames);
    const fades = frames.map((f) => f.fades!);
    expect(fades[0]).toBeGreaterThanOrEqual(65530);
    expect(fades.some((x) => x < 100)).toBe(true);
    for (let i = 1; i < frames.length; i++) {
      expect(frames[i]!.fadesDelta).toBe((fades[i]! - fades[i - 1]! + 65536) % 65536);
    }
  });

  it('counts every silent slot as a fade and sometimes counts one without a gap', () => {
    const { chunk, frames } = run(preset('fade-wrap-external'), 10_000_000);
    const gaps = chunk.truth!.gaps;
    expect(gaps.length).toBeGreaterThan(0);
    let randomFades = 0;
    for (let i = 1; i < frames.length; i++) {
      const missed = frames[i]!.slot - frames[i - 1]!.slot - 1;
      expect(frames[i]!.fadesDelta - missed).toBeGreaterThanOrEqual(0);
      expect(frames[i]!.fadesDelta - missed).toBeLessThanOrEqual(1);
      if (missed === 0 && frames[i]!.fadesDelta === 1) randomFades++;
    }
    expect(randomFades).toBeGreaterThan(0);
  });
});

describe('RSSI mode', () => {
  it('sends signed dBm between -92 and -42 that wanders, and -128 on the first frame after a loss', () => {
    const frames = run(preset('rssi-spm4649t'), 10_000_000).frames;
    expect(frames.every((f) => f.fades === null && f.rssi !== null)).toBe(true);
    for (let i = 1; i < frames.length; i++) {
      const f = frames[i]!;
      const afterLoss = f.slot - frames[i - 1]!.slot > 1;
      if (afterLoss) expect(f.rssi).toBe(-128);
      else {
        expect(f.rssi!).toBeGreaterThanOrEqual(-92);
        expect(f.rssi!).toBeLessThanOrEqual(-42);
      }
    }
    expect(frames.some((f) => f.rssi === -128)).toBe(true);
    expect(new Set(frames.map((f) => f.rssi)).size).toBeGreaterThan(5);
  });
});

describe('dropouts', () => {
  it('sends nothing during a dropout and reports the gaps, the one over a second as failsafe', () => {
    const { sim, chunk, frames } = run(preset('dropouts-failsafe'));
    const start = sim.scenario.timing.startUs;
    for (const w of sim.scenario.dropouts) {
      // No frame starts inside; a frame that started just before may still be finishing.
      expect(frames.filter((f) => f.timeUs > start + w.atUs + 20 && f.timeUs < start + w.atUs + w.durationUs - 20)).toEqual([]);
      const inside = Array.from(chunk.timesUs).filter((t) => t >= start + w.atUs + 1_400 && t < start + w.atUs + w.durationUs - 20);
      expect(inside).toEqual([]);
    }
    const gaps = chunk.truth!.gaps.filter((g) => g.cause === 'dropout');
    expect(gaps.map((g) => g.failsafe)).toEqual([false, true]);
    expect(gaps[1]!.endUs - gaps[1]!.lastFrameUs!).toBeGreaterThan(1_000_000);
    expect(gaps[1]!.missedFrames).toBeGreaterThanOrEqual(Math.floor(1_300_000 / 11_000));
    // Frames resume after the long dropout.
    expect(frames.at(-1)!.timeUs).toBeGreaterThan(start + 2_500_000);
    const longest = Math.max(...frames.slice(1).map((f, i) => f.timeUs - frames[i]!.timeUs));
    expect(longest).toBeGreaterThan(1_300_000);
  });
});

describe('X-Plus and VTX', () => {
  it('rotates all eight X-Plus channels through the 7th slot, X+5…X+8 with the phase bit', () => {
    const frames = intact(run(preset('xplus-8')).frames);
    const xs = frames.flatMap((f) => f.channels.filter((c) => c.id >= 12));
    expect(new Set(xs.map((c) => c.id))).toEqual(new Set([12, 13, 14, 15, 16, 17, 18, 19]));
    expect(xs.every((c) => c.pos % 4 === 0 && c.pos <= 2044)).toBe(true);
    for (const f of frames) {
      const w = f.words[6]!;
      expect((w >> 11) & 0xf).toBe(12);
      const id = f.channels.at(-1)!.id;
      expect(w >> 15).toBe(id >= 16 ? 1 : 0);
    }
  });

  it('sends VTX control in bursts, only in frames whose first slot has phase 0', () => {
    const { frames } = run(preset('vtx'), 2_000_000);
    const vtx = frames.filter((f) => f.vtx !== null);
    expect(vtx.length).toBe(9); // bursts at 0.5, 1.0 and 1.5 s, three frames each
    for (const f of vtx) {
      expect(f.phase).toBe(0);
      expect(f.words[0]! & 0x8000).toBe(0);
      expect((((f.words[5]! << 16) | f.words[6]!) & 0xf000f000) >>> 0).toBe(0xe000e000);
      expect(f.channels).toHaveLength(5);
    }
    expect(vtx[3]!.vtx).toEqual(vtxControl({ band: 4, channel: 7, power: 5, region: 1, pit: true }));
  });
});

describe('demo scenario', () => {
  it('moves sticks, shows X-Plus for a while, fails safe and recovers, and repeats every cycle', () => {
    const sim = new Simulator(demoScenario(), { truth: true });
    const cycle = sim.scenario.cycleUs!;
    const start = sim.scenario.timing.startUs;
    const one = sim.generate(start + cycle).truth!;
    const two = sim.generate(start + 2 * cycle).truth!;
    for (const t of [one, two]) {
      expect(t.gaps.filter((g) => g.failsafe)).toHaveLength(1);
      expect(t.frames.some((f) => f.channels.some((c) => c.id >= 12))).toBe(true);
      expect(t.frames.some((f) => f.vtx !== null)).toBe(true);
      expect(t.frames.some((f) => f.fadesDelta > 0)).toBe(true);
    }
    const failsafeAt = (t: typeof one) => t.gaps.find((g) => g.failsafe)!.startUs;
    // 40 s is not a whole number of 11 ms slots, so the slot grid shifts by under a slot per cycle.
    expect(Math.abs(failsafeAt(two) - failsafeAt(one) - cycle)).toBeLessThan(sim.scenario.periodUs);
    // X-Plus only inside its window.
    const xw = sim.scenario.xplus.window!;
    for (const f of one.frames) {
      const hasX = f.channels.some((c) => c.id >= 12);
      const tau = f.slot * sim.scenario.periodUs;
      expect(hasX).toBe(tau >= xw.atUs && tau < xw.atUs + xw.durationUs);
    }
  });

  it('keeps going: a long bench-style run without ground truth is cheap', () => {
    const sim = new Simulator(demoScenario());
    const c = sim.generate((60 * 60 * 1_000_000) / 12); // five minutes
    // 27,272 slots, less lost frames and two dropouts per 40 s.
    expect(c.bytes.length).toBeGreaterThan(25_000 * 16);
    expect(sim.framesGenerated).toBe(c.bytes.length / 16);
  });
});

describe('golden fixtures', () => {
  const dir = resolve(import.meta.dirname, 'fixtures');
  const names = readdirSync(dir)
    .filter((f) => f.endsWith('.expected.json'))
    .map((f) => f.slice(0, -'.expected.json'.length));

  it('exist for every important scenario', () => {
    for (const n of [
      'dsm2-22ms-1024-internal',
      'dsmx-11ms-2048-external',
      'clone-zero-header',
      'rssi-spm4649t',
      'xplus-dx9',
      'vtx',
      'dropouts-and-damage',
    ]) {
      expect(names).toContain(n);
    }
  });

  it.each(names)('are what the simulator produces today (%s; if not, run `npm run fixtures` and review the diff)', (name) => {
    const expected = JSON.parse(readFileSync(join(dir, `${name}.expected.json`), 'utf8')) as {
      preset: string;
      durationUs: number;
      bytes: number;
      frames: unknown[];
    };
    const bin = new Uint8Array(readFileSync(join(dir, `${name}.bin`)));
    const raw = readFileSync(join(dir, `${name}.times.f64`));
    const view = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
    const times = Float64Array.from({ length: raw.byteLength / 8 }, (_, i) => view.getFloat64(i * 8, true));

    const sim = new Simulator(preset(expected.preset), { truth: true });
    const chunk = sim.generate(sim.scenario.timing.startUs + expected.durationUs);
    expect(bin.length).toBe(expected.bytes);
    expect(chunk.bytes).toEqual(bin);
    expect(chunk.timesUs).toEqual(times);
    expect(JSON.parse(JSON.stringify(chunk.truth!.frames.map(toFixtureFrame)))).toEqual(expected.frames);
  });
});
