/**
 * `readFrameFields` (what the frame inspector shows) reads every frame exactly as the decoder
 * did: the same channels, positions, VTX control, header and validity, on every clean simulator
 * preset; and names what is wrong with a slot the decoder rejects.
 */
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { readFrameFields } from '../src/decoder/fields.js';
import type { DecodedFrame } from '../src/decoder/types.js';
import { encodeInternalFrame, encodeServo2048 } from '../src/simulator/encode.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { CLEAN_PRESETS } from './damage.js';

function frames(bytes: Uint8Array): { frame: DecodedFrame; fields: ReturnType<typeof readFrameFields> }[] {
  const d = new SpektrumDecoder();
  d.push(bytes);
  d.end();
  const out = [];
  for (let f = d.next(); f !== undefined; f = d.next()) {
    const mode = f.rssi !== null ? 'rssi' : 'fades';
    out.push({
      frame: { ...f, ids: f.ids.slice(), positions: f.positions.slice(), vtx: f.vtx && { ...f.vtx } },
      fields: readFrameFields(f.bytes, f.resolution, f.remote, mode),
    });
  }
  return out;
}

describe('readFrameFields reads a frame as the decoder does', () => {
  it.each(CLEAN_PRESETS)('%s', (name) => {
    const all = frames(simulate(preset(name), 3_000_000).bytes);
    expect(all.length).toBeGreaterThan(100);
    let vtx = 0;
    for (const { frame, fields } of all) {
      const carried = fields.slots.filter((s) => s.kind === 'channel' || s.kind === 'xplus');
      expect(fields.valid).toBe(true);
      expect(carried.map((s) => s.channel)).toEqual([...frame.ids.subarray(0, frame.count)]);
      expect(carried.map((s) => s.position)).toEqual([...frame.positions.subarray(0, frame.count)]);
      expect(fields.vtx).toEqual(frame.vtx);
      if (frame.vtx !== null) vtx++;
      expect(fields.system).toBe(frame.system);
      if (frame.fades !== null) expect(fields.fades).toBe(frame.fades);
      if (frame.rssi !== null) expect(fields.rssi).toBe(frame.rssi);
      expect(fields.emptySlots).toBe(fields.slots.filter((s) => s.word === 0xffff).length);
    }
    if (/vtx/.test(name)) expect(vtx).toBeGreaterThan(0);
  });

  it('names an ID that does not exist and a channel sent twice, as the decoder rejects both', () => {
    const good = [0, 1, 2, 3, 4, 5, 6].map((ch) => encodeServo2048(ch, 1024));
    const unknown = encodeInternalFrame({ fades: 0, system: 0xb2 }, [...good.slice(0, 6), (14 << 11) | 5]);
    const u = readFrameFields(unknown, 2048, 'internal', 'fades');
    expect(u.valid).toBe(false);
    expect(u.slots[6]).toMatchObject({
      kind: 'invalid',
      id: 14,
      problem: 'channel ID 14 does not exist (2048 mode: 0–11, or 12 for X-Plus)',
    });

    const twice = encodeInternalFrame({ fades: 0, system: 0xb2 }, [...good.slice(0, 6), encodeServo2048(1, 700)]);
    const t = readFrameFields(twice, 2048, 'internal', 'fades');
    expect(t.valid).toBe(false);
    expect(t.slots[1]?.kind).toBe('channel');
    expect(t.slots[6]).toMatchObject({
      kind: 'invalid',
      channel: 1,
      position: 700,
      problem: 'Aileron again (slot 2 has it): a frame carries each channel once',
    });
    expect(readFrameFields(encodeInternalFrame({ fades: 0, system: 0xb2 }, good), 2048, 'internal', 'fades').valid).toBe(true);
  });

  it('refuses fewer than 16 bytes', () => {
    expect(() => readFrameFields(new Uint8Array(15), 2048, 'internal', 'fades')).toThrow(RangeError);
  });
});
