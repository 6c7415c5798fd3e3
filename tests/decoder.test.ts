import { describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { copyFrame, type FrameSnapshot } from '../src/decoder/snapshot.js';
import { decodeStream } from '../src/decoder/stream.js';
import { servoToMicros, servoToPercent, channelName } from '../src/decoder/spec.js';
import type { DecoderEvent } from '../src/decoder/types.js';
import {
  encodeExternalFrame,
  encodeInternalFrame,
  encodeServo1024,
  encodeServo2048,
  encodeXPlus,
  vtxWords,
} from '../src/simulator/encode.js';
import { readFileSync } from 'node:fs';
import { join as joinPath } from 'node:path';
import { concatBytes as join } from './bytes.js';
import { dsmxPair } from './frames.js';

/** Decodes bytes fed in one piece, then end(): owned snapshots. */
function decodeAll(bytes: Uint8Array, decoder = new SpektrumDecoder(), time?: number | Float64Array): FrameSnapshot[] {
  const out: FrameSnapshot[] = [];
  decoder.push(bytes, time);
  decoder.end();
  for (let f = decoder.next(); f; f = decoder.next()) out.push(copyFrame(f));
  return out;
}

const chans = (f: FrameSnapshot) => f.channels.map((c) => [c.id, c.pos]);

/** DSMX 11 ms, 10 channels over a frame pair, as the PX4 capture lays them out. */
function dsmxStream(pairs: number, system = 0xb2, fades = 7): Uint8Array {
  const frames: Uint8Array[] = [];
  for (let i = 0; i < pairs; i++) frames.push(...dsmxPair(fades, system, i / 10));
  return join(frames);
}

/** DSM2 22 ms 1024: seven channels a frame, one layout. */
function dsm2Stream(frames: number, system = 0x01): Uint8Array {
  const out: Uint8Array[] = [];
  for (let i = 0; i < frames; i++) {
    const words = [0, 1, 2, 3, 4, 5, 6].map((id) => encodeServo1024(id, 512 + Math.round(200 * Math.sin(i / 7 + id))));
    out.push(encodeInternalFrame({ fades: 0, system }, words));
  }
  return join(out);
}

describe('internal remote frames', () => {
  it('reads fades, system byte, channel IDs and 11-bit positions of a DSMX 11 ms stream', () => {
    const frames = decodeAll(dsmxStream(4));
    expect(frames).toHaveLength(8);
    const f = frames[0]!;
    expect(f.remote).toBe('internal');
    expect(f.system).toBe(0xb2);
    expect(f.fades).toBe(7);
    expect(f.rssi).toBeNull();
    expect(f.resolution).toBe(2048);
    expect(f.channels.map((c) => c.id)).toEqual([1, 5, 2, 3, 0, 7, 6]);
    expect(f.channels[0]!.pos).toBe(1024 + Math.round(300 * Math.sin(1)));
    expect(frames[1]!.channels.map((c) => c.id)).toEqual([1, 5, 2, 3, 4, 8, 9]);
  });

  it('reports each frame pulse width per spec §9 in 2048 and 1024 mode', () => {
    expect(servoToMicros(0, 2048)).toBe(903);
    expect(servoToMicros(1024, 2048)).toBe(1500);
    expect(servoToMicros(2047, 2048)).toBe(2096);
    expect(servoToMicros(341, 2048)).toBe(1102);
    expect(servoToMicros(1707, 2048)).toBe(1898);
    expect(servoToMicros(512, 1024)).toBe(1500);
    expect(servoToMicros(1023, 1024)).toBe(2096);
    expect(servoToPercent(1707, 2048)).toBeCloseTo(100, 0);
    expect(servoToPercent(341, 2048)).toBeCloseTo(-100, 0);
    expect(servoToPercent(512, 1024)).toBe(0);
    const f = decodeAll(dsmxStream(2))[0]!;
    for (const c of f.channels) expect(c.us).toBe(Math.round(c.pos * 0.583) + 903);
  });

  it('counts UINT8 fades across the wrap', () => {
    // Locked on steady frames first: acquisition only chains counts that barely move.
    const steady = [0, 1, 2].flatMap((t) => dsmxPair(250, 0xb2, t));
    const frames = join([...steady, ...dsmxPair(254, 0xb2, 3), ...dsmxPair(3, 0xb2, 4), ...dsmxPair(3, 0xb2, 5)]);
    const out = decodeAll(frames);
    expect(out.map((f) => f.fadesDelta)).toEqual([0, 0, 0, 0, 0, 0, 4, 0, 5, 0, 0, 0]);
  });

  it('decodes DSM2 22 ms 1024 frames with 10-bit positions and 1.166 µs steps', () => {
    const out = decodeAll(dsm2Stream(6));
    expect(out).toHaveLength(6);
    expect(out[0]!.resolution).toBe(1024);
    expect(out[0]!.system).toBe(0x01);
    expect(out[0]!.channels.map((c) => c.id)).toEqual([0, 1, 2, 3, 4, 5, 6]);
    const pos = 512 + Math.round(200 * Math.sin(0));
    expect(out[0]!.channels[0]).toEqual({ id: 0, pos, us: Math.round(pos * 1.166) + 903 });
  });

  it('reads SPM4649T RSSI in dBm, -128 on loss, instead of fades', () => {
    const frames: Uint8Array[] = [];
    const rssi = [-45, -52, -60, -128, -70, -71, -48, -92];
    for (const [i, r] of rssi.entries()) frames.push(dsmxPair(0, 0xb2, i)[i % 2]!.map((b, k) => (k === 0 ? r & 0xff : b)));
    const out = decodeAll(join(frames));
    expect(out.map((f) => f.rssi)).toEqual(rssi);
    expect(out.every((f) => f.fades === null)).toBe(true);
  });

  it('falls back to fades when byte 0 turns positive (RSSI is never positive)', () => {
    const frames: Uint8Array[] = [];
    // RSSI that wanders (a fall says RSSI), then small positive values: a fade count after all.
    const b0 = [0xc3, 0xc1, 0xc2, 0xc0, 4, 5, 6, 7];
    for (let i = 0; i < 8; i++) frames.push(dsmxPair(0, 0xb2, i)[i % 2]!.map((b, k) => (k === 0 ? b0[i]! : b)));
    const decoder = new SpektrumDecoder();
    const out = decodeAll(join(frames), decoder);
    expect(out).toHaveLength(8);
    expect(out[0]!.rssi).toBe(-61);
    expect(out[4]!.fades).toBe(4);
    expect(decoder.format.headerMode).toBe('fades');
  });
});

describe('external remote frames', () => {
  it('reads UINT16 fades and counts them across the 65535 wrap', () => {
    const frames: Uint8Array[] = [];
    const fades = [65533, 65534, 65535, 1, 1, 2];
    for (const [i, n] of fades.entries()) frames.push(dsmxPair(0, 0, i)[i % 2]!.map((b, k) => (k === 0 ? n >> 8 : k === 1 ? n & 0xff : b)));
    const out = decodeAll(join(frames));
    expect(out.map((f) => f.remote)).toEqual(Array(6).fill('external'));
    expect(out.map((f) => f.fades)).toEqual(fades);
    expect(out.map((f) => f.fadesDelta)).toEqual([0, 1, 1, 2, 0, 1]);
    expect(out[0]!.system).toBeNull();
  });

  it('treats a clone header 00 00 as an external remote and infers 2048 from the channel IDs', () => {
    const decoder = new SpektrumDecoder();
    const out = decodeAll(dsmxStream(4, 0x00, 0), decoder);
    expect(out).toHaveLength(8);
    expect(out[0]!.remote).toBe('external');
    expect(decoder.format.resolutionReason).toBe('channel-ids');
    expect(decoder.format.explanation).toMatch(/inferred from the channel IDs/);
  });

  it('uses external frames encoded by the external layout', () => {
    const words = [encodeServo2048(0, 100), encodeServo2048(1, 2000), encodeServo2048(2, 1024), encodeServo2048(3, 1024)];
    const out = decodeAll(join(Array.from({ length: 6 }, (_, i) => encodeExternalFrame(i, words))));
    expect(out).toHaveLength(6);
    expect(out[5]!.fades).toBe(5);
    expect(out[5]!.channels.map((c) => c.id)).toEqual([0, 1, 2, 3]);
  });
});

describe('slots beyond channels 0–11', () => {
  it('decodes X-Plus channels 12–19 with the phase bit and 9-bit values scaled to 11 bits', () => {
    const frames: Uint8Array[] = [];
    for (let i = 0; i < 8; i++) {
      const x = 12 + i;
      // X+5 … X+8 (phase 1) travel in the phase-1 frame of a pair.
      frames.push(
        encodeInternalFrame({ fades: 0, system: 0xb2 }, [
          encodeServo2048(0, 300, x >= 16),
          encodeServo2048(1, 1024),
          encodeServo2048(2, 1024),
          encodeServo2048(3, 1024),
          encodeServo2048(4, 1706),
          encodeServo2048(5, 1706),
          encodeXPlus(x, 400 + 100 * i),
        ]),
      );
    }
    const out = decodeAll(join(frames));
    expect(out.map((f) => f.channels[6]!.id)).toEqual([12, 13, 14, 15, 16, 17, 18, 19]);
    expect(out.map((f) => f.channels[6]!.pos)).toEqual(Array.from({ length: 8 }, (_, i) => ((400 + 100 * i) >> 2) << 2));
    expect(encodeXPlus(16, 1024)).toBe(0x8000 | (12 << 11) | 256);
  });

  it('skips 0xFFFF slots and counts them', () => {
    const words = [
      encodeServo2048(0, 300),
      encodeServo2048(1, 1024),
      encodeServo2048(2, 1024),
      encodeServo2048(3, 1024),
      encodeServo2048(4, 1706),
    ];
    const decoder = new SpektrumDecoder();
    const out = decodeAll(join(Array.from({ length: 5 }, () => encodeInternalFrame({ fades: 0, system: 0xa2 }, words))), decoder);
    expect(out).toHaveLength(5);
    expect(out[0]!.channels).toHaveLength(5);
    expect(decoder.stats.emptySlots).toBe(10);
  });

  it('reads Spektrum VTX control from the last two slots and never as channels', () => {
    const vtx = { band: 4, channel: 7, power: 3, region: 1, pit: true };
    const base = [
      encodeServo2048(0, 300),
      encodeServo2048(1, 1024),
      encodeServo2048(2, 1024),
      encodeServo2048(3, 1024),
      encodeServo2048(4, 1706),
    ];
    const frames = [0, 1, 2, 3, 4, 5].map((i) =>
      encodeInternalFrame(
        { fades: 0, system: 0xb2 },
        i === 3 ? [...base, ...vtxWords(vtx)] : [...base, encodeServo2048(5, 1024), encodeServo2048(6, 1024)],
      ),
    );
    const decoder = new SpektrumDecoder();
    const out = decodeAll(join(frames), decoder);
    expect(out).toHaveLength(6);
    expect(out[3]!.vtx).toEqual({ raw: (0xe000e000 | (4 << 21) | (7 << 16) | 0x10 | 0x08 | 3) >>> 0, ...vtx });
    expect(out[3]!.channels.map((c) => c.id)).toEqual([0, 1, 2, 3, 4]);
    expect(out[2]!.vtx).toBeNull();
    expect(decoder.stats.vtxFrames).toBe(1);
  });

  it('reads two X+5…X+8 words in a phase-1 frame as channels, not VTX', () => {
    const frames = [0, 1, 2, 3, 4, 5].map(() =>
      encodeInternalFrame({ fades: 0, system: 0xb2 }, [
        encodeServo2048(0, 300, 1),
        encodeServo2048(1, 1024),
        encodeServo2048(2, 1024),
        encodeServo2048(3, 1024),
        encodeServo2048(4, 1706),
        encodeXPlus(16, 1024),
        encodeXPlus(17, 2000),
      ]),
    );
    const out = decodeAll(join(frames));
    expect(out[0]!.vtx).toBeNull();
    expect(out[0]!.channels.slice(5)).toEqual([
      { id: 16, pos: 1024, us: 1500 },
      { id: 17, pos: 2000, us: servoToMicros(2000, 2048) },
    ]);
  });

  it('names channels as the spec does', () => {
    expect([0, 4, 5, 11, 12, 19].map(channelName)).toEqual(['Throttle', 'Gear', 'Aux 1', 'Aux 7', 'X+1', 'X+8']);
  });
});

describe('the system byte is a hint, not a rule', () => {
  it('decodes 10-bit data under a system byte that claims 2048, and says so', () => {
    const decoder = new SpektrumDecoder();
    const out = decodeAll(dsm2Stream(8, 0xb2), decoder);
    expect(out).toHaveLength(8);
    expect(out[0]!.resolution).toBe(1024);
    expect(decoder.format.resolutionReason).toBe('system-byte-contradicted');
    expect(decoder.format.explanation).toMatch(/system byte says 2048/);
  });

  it('decodes 11-bit data under a system byte that claims 1024', () => {
    const decoder = new SpektrumDecoder();
    const out = decodeAll(dsmxStream(4, 0x01), decoder);
    expect(out).toHaveLength(8);
    expect(out[0]!.resolution).toBe(2048);
    expect(decoder.format.resolutionReason).toBe('system-byte-contradicted');
  });

  it('uses the resolution the caller fixes', () => {
    const decoder = new SpektrumDecoder({ resolution: 2048 });
    const out = decodeAll(dsmxStream(3, 0x00), decoder);
    expect(out).toHaveLength(6);
    expect(decoder.format.resolutionReason).toBe('override');
  });

  it('turns an external remote whose fade count looked like a system byte into an external one', () => {
    // UINT16 fades 0x0001 reads as "internal, system 0x01"; then the count moves on.
    const frames: Uint8Array[] = [];
    for (let i = 0; i < 12; i++) frames.push(dsmxPair(0, 0, i)[i % 2]!.map((b, k) => (k === 1 ? (i < 6 ? 1 : 2 + (i >> 2)) : b)));
    const decoder = new SpektrumDecoder();
    const out = decodeAll(join(frames), decoder);
    expect(out).toHaveLength(12);
    expect(out[11]!.remote).toBe('external');
    expect(decoder.format.remote).toBe('external');
  });

  it('rejects options outside their set with a TypeError', () => {
    expect(() => new SpektrumDecoder({ resolution: 512 as never })).toThrow(TypeError);
    expect(() => new SpektrumDecoder({ remote: 'both' as never })).toThrow(/remote must be/);
    expect(() => new SpektrumDecoder({ headerMode: 'dbm' as never })).toThrow(TypeError);
  });
});

describe('finding frames without a sync byte', () => {
  it('starts mid-frame and discards the partial frame before the first lock', () => {
    const events: DecoderEvent[] = [];
    const decoder = new SpektrumDecoder({ onEvent: (e) => events.push(e) });
    const out = decodeAll(dsmxStream(5).subarray(5), decoder);
    expect(out).toHaveLength(9);
    expect(out[0]!.offset).toBe(11);
    expect(events[0]).toMatchObject({ type: 'discarded', offset: 0, length: 11, reason: 'before-lock' });
    expect(decoder.stats.discardedBytes).toBe(11);
  });

  it('drops a truncated frame and resyncs on the next one', () => {
    const good = dsmxStream(6);
    const cut = new Uint8Array([...good.subarray(0, 64 + 5), ...good.subarray(64 + 7)]); // two bytes lost in frame 4
    const decoder = new SpektrumDecoder();
    const out = decodeAll(cut, decoder);
    const reference = decodeAll(good);
    expect(out.map(chans)).toEqual([...reference.slice(0, 4), ...reference.slice(5)].map(chans));
    expect(decoder.stats).toMatchObject({ frames: 11, discardedBytes: 14, badFrames: 1, resyncs: 1, pendingBytes: 0 });
  });

  it('skips noise between frames, drops the frame before it (its end is not told from noise) and counts every byte', () => {
    const good = dsmxStream(6);
    const noise = new Uint8Array([0x12, 0x99, 0xfe, 0x00, 0x37]);
    const decoder = new SpektrumDecoder();
    const out = decodeAll(join([good.subarray(0, 80), noise, good.subarray(80)]), decoder);
    const reference = decodeAll(good);
    expect(out.map(chans)).toEqual([...reference.slice(0, 4), ...reference.slice(5)].map(chans));
    const s = decoder.stats;
    expect(s.frameBytes + s.discardedBytes + s.pendingBytes).toBe(s.bytes);
    expect(s.discardedBytes).toBe(16 + 5);
  });

  it('keeps the frame before a truncated frame whose header survived', () => {
    const good = dsmxStream(6);
    const cut = new Uint8Array([...good.subarray(0, 80 + 9), ...good.subarray(80 + 11)]); // two bytes lost in frame 5, after its header
    const out = decodeAll(cut);
    const reference = decodeAll(good);
    expect(out.map(chans)).toEqual([...reference.slice(0, 5), ...reference.slice(6)].map(chans));
  });

  it('holds a frame until the whole next frame continues it, then emits it: one frame period of latency', () => {
    const decoder = new SpektrumDecoder();
    const stream = dsmxStream(8);
    decoder.push(stream.subarray(0, 224));
    let n = 0;
    while (decoder.next()) n++;
    // Frames 0…12 are confirmed; frame 13 (208…223) waits for the frame after it.
    expect(n).toBe(13);
    decoder.push(stream.subarray(224, 239));
    expect(decoder.next()).toBeUndefined();
    decoder.push(stream.subarray(239, 240));
    expect(decoder.next()?.offset).toBe(208);
    expect(decoder.next()).toBeUndefined();
  });

  it('reuses one frame object (a borrowed view) for every frame', () => {
    const decoder = new SpektrumDecoder();
    decoder.push(dsmxStream(4));
    const first = decoder.next();
    const second = decoder.next();
    expect(first).toBeDefined();
    expect(second).toBe(first);
    expect(second!.index).toBe(1);
  });

  it('refuses push() after end() until reset()', () => {
    const decoder = new SpektrumDecoder();
    decoder.end();
    expect(() => decoder.push(new Uint8Array(1))).toThrow(/after end/);
    decoder.reset();
    decoder.push(dsmxStream(3));
    expect(decoder.stats.bytes).toBe(96);
  });
});

describe('where a frame lies in memory', () => {
  // Frames at a multiple of 4 in the decoder's buffer are read as 32-bit words, others byte by
  // byte: 0–3 stray bytes before a stream (pushed whole, so never moved) put its frames at every
  // alignment, and every one must decode alike.
  it.each(['dsmx-11ms-2048-internal', 'dsm2-22ms-1024-external', 'rssi-spm4649t', 'xplus-dx9', 'vtx', 'dropouts-and-damage'])(
    'decodes fixture %s to the same frames after 0, 1, 2 or 3 stray bytes',
    (name) => {
      const stream = new Uint8Array(readFileSync(joinPath(import.meta.dirname, 'fixtures', `${name}.bin`)));
      const at = (shift: number) => {
        const frames = decodeAll(join([new Uint8Array(shift).fill(0x5a), stream]));
        return frames.map((f) => ({ ...f, offset: f.offset - shift, bytes: Array.from(f.bytes) }));
      };
      const aligned = at(0);
      expect(aligned.length).toBeGreaterThan(50);
      for (const shift of [1, 2, 3]) expect(at(shift), `${shift} stray bytes`).toEqual(aligned);
    },
  );
});

describe('time', () => {
  it('gives each frame its first byte time with per-byte times', () => {
    const stream = dsmxStream(3);
    const times = Float64Array.from(stream, (_, i) => 1000 + Math.floor(i / 16) * 11_000 + (i % 16) * 86.8);
    const out = decodeAll(stream, new SpektrumDecoder(), times);
    expect(out.map((f) => f.timeUs)).toEqual([1000, 12_000, 23_000, 34_000, 45_000, 56_000]);
  });

  it('estimates frame times from a chunk time at 86.8 µs a byte', () => {
    const out = decodeAll(dsmxStream(3), new SpektrumDecoder(), 100_000);
    expect(out[5]!.timeUs).toBeCloseTo(100_000 - 15 * (1e7 / 115_200), 6);
    expect(out[0]!.timeUs).toBeCloseTo(100_000 - 95 * (1e7 / 115_200), 6);
  });

  it('leaves times NaN when none are given', () => {
    expect(decodeAll(dsmxStream(3)).every((f) => Number.isNaN(f.timeUs))).toBe(true);
  });

  it('rejects per-byte times whose length differs from the bytes', () => {
    expect(() => new SpektrumDecoder().push(new Uint8Array(4), new Float64Array(3))).toThrow(TypeError);
  });
});

describe('decodeStream', () => {
  it('pipes raw chunks to owned frame snapshots and flushes at close', async () => {
    const stream = dsmxStream(4);
    const source = new ReadableStream<Uint8Array>({
      start(controller) {
        for (let i = 0; i < stream.length; i += 10) controller.enqueue(stream.slice(i, i + 10));
        controller.close();
      },
    });
    const frames: FrameSnapshot[] = [];
    const reader = source.pipeThrough(decodeStream()).getReader();
    for (let r = await reader.read(); !r.done; r = await reader.read()) frames.push(r.value);
    expect(frames.map(chans)).toEqual(decodeAll(stream).map(chans));
    expect(frames[0]).not.toBe(frames[1]);
  });
});

describe('setResolution', () => {
  it('re-reads the stream at a resolution set while decoding, keeping the counters', () => {
    const decoder = new SpektrumDecoder();
    const stream = dsmxStream(8, 0x00, 0);
    decoder.push(stream.subarray(0, 128));
    while (decoder.next());
    expect(decoder.format.resolutionReason).toBe('channel-ids');
    decoder.setResolution(2048);
    expect(decoder.format.resolutionReason).toBe('override');
    const before = decoder.stats.frames;
    decoder.setResolution(1024);
    decoder.push(stream.subarray(128));
    decoder.end();
    let after = 0;
    while (decoder.next()) after++;
    // 1024 cannot read 11-bit frames: nothing after the switch decodes, and every byte is counted.
    expect(after).toBe(0);
    expect(decoder.format.locked).toBe(false);
    expect(decoder.stats.frames).toBe(before);
    expect(decoder.stats.frameBytes + decoder.stats.discardedBytes).toBe(stream.length);
    expect(() => decoder.setResolution(4096 as never)).toThrow(TypeError);
  });

  it('keeps decoding when the resolution set agrees with the lock', () => {
    const decoder = new SpektrumDecoder();
    const stream = dsmxStream(8);
    decoder.push(stream.subarray(0, 128));
    let n = 0;
    while (decoder.next()) n++;
    decoder.setResolution(2048);
    decoder.push(stream.subarray(128));
    decoder.end();
    while (decoder.next()) n++;
    expect(n).toBe(16);
    expect(decoder.stats.resyncs).toBe(0);
  });
});

describe('resolution from the internal remote', () => {
  it('says when the resolution came from the internal remote of the same system', () => {
    const decoder = new SpektrumDecoder();
    decoder.push(dsmxStream(6, 0x00, 0));
    while (decoder.next());
    decoder.setResolution(2048, 'internal-remote');
    expect(decoder.format.resolutionReason).toBe('internal-remote');
    expect(decoder.format.explanation).toMatch(/from the internal remote/);
    decoder.setResolution('auto');
    expect(decoder.format.resolutionReason).toBe('unknown');
    decoder.push(dsmxStream(6, 0x00, 0));
    decoder.end();
    while (decoder.next());
    expect(decoder.format.resolutionReason).toBe('channel-ids');
  });
});
