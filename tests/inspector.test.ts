import { describe, expect, it } from 'vitest';
import { describeFrame } from '../src/app/inspect.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { copyFrame, type FrameSnapshot } from '../src/decoder/snapshot.js';
import { servoToMicros } from '../src/decoder/spec.js';
import {
  encodeExternalFrame,
  encodeInternalFrame,
  encodeServo1024,
  encodeServo2048,
  encodeXPlus,
  vtxWords,
} from '../src/simulator/encode.js';
import { DISCARD_BYTES_CAP, InspectorLog, type InspectEntry } from '../src/worker/inspector.js';
import { concatBytes as join } from './bytes.js';
import { dsmxPair } from './frames.js';

/** A DSMX 11 ms frame pair: phase bit on the first slot of the first frame. */
function frames(pairs: number, from = 0): Uint8Array[] {
  const out: Uint8Array[] = [];
  for (let i = 0; i < pairs; i++) out.push(...dsmxPair(3, 0xb2, (from + i) / 10));
  return out;
}

/** Bytes that never read as a channel word at any alignment or resolution (ID 15 / 31 / 63). */
function noise(n: number): Uint8Array {
  const out = new Uint8Array(n);
  for (let i = 0; i < n; i++) out[i] = i % 3 === 0 ? 0xfe : 0x7f;
  return out;
}

/**
 * Feeds `stream` the way the worker's Engine does: each chunk to the decoder, then every frame
 * next() gives to the log, the decoder's events to the log as they fire. The log sees no bytes
 * but those the decoder hands it.
 */
function run(stream: Uint8Array, log = new InspectorLog(), chunk = 37, chunkTimes = true) {
  const decoder = new SpektrumDecoder({ onEvent: (e) => log.onEvent(e) });
  const decoded: FrameSnapshot[] = [];
  const drain = () => {
    for (let f = decoder.next(); f; f = decoder.next()) {
      log.onFrame(f);
      decoded.push(copyFrame(f));
    }
  };
  for (let at = 0; at < stream.length; at += chunk) {
    const c = stream.subarray(at, Math.min(stream.length, at + chunk));
    // A chunk arrives when its last byte does: 1000 µs plus 86.8 µs a byte.
    const time = chunkTimes ? 1000 + (at + c.length) * 86.8 : undefined;
    decoder.push(c, time);
    drain();
  }
  decoder.end();
  drain();
  return { decoder, log, decoded };
}

const bytesOf = (e: InspectEntry) => (e.bytes === null ? null : Array.from(e.bytes));

describe('InspectorLog', () => {
  it("logs frames, discards and resyncs in stream order with the frames' bytes", () => {
    const good = frames(10); // 20 frames
    const truncated = (good[3] as Uint8Array).subarray(0, 11);
    const stream = join([noise(40), ...good.slice(0, 6), noise(21), ...good.slice(6), truncated, ...frames(6, 10)]);
    const { decoder, log, decoded } = run(stream);
    const entries = log.snapshot(1000);
    expect(log.streamBytes).toBe(stream.length);

    // Stream order, and every byte either in a frame or discarded, back to back.
    let end = 0;
    for (const e of entries) {
      if (e.kind === 'frame' || e.kind === 'discarded') {
        expect(e.offset).toBe(end);
        end = e.offset + e.length;
      } else {
        expect(e.offset).toBe(end);
      }
    }
    expect(end).toBe(stream.length);

    const kinds = entries.map((e) => e.kind);
    expect(kinds[0]).toBe('discarded');
    expect(entries[0]).toMatchObject({ offset: 0, length: 40, reason: 'before-lock' });
    expect(bytesOf(entries[0] as InspectEntry)).toEqual(Array.from(noise(40)));
    expect(kinds[1]).toBe('locked');
    expect(entries[1]?.text).toMatch(/2048/);
    expect(entries[1]).toMatchObject({ resolution: 2048, remote: 'internal', headerMode: 'fades', system: 0xb2 });

    // The noise after frame 6 takes frame 6 with it (its end cannot be told from the noise):
    // discarded, then the resync where frames continue, then the frame.
    const noiseAt = 40 + 6 * 16;
    const n = entries.findIndex((e) => e.kind === 'discarded' && e.offset === noiseAt - 16);
    expect(n).toBeGreaterThan(0);
    expect(entries[n]).toMatchObject({ length: 16 + 21, reason: 'noise' });
    expect(entries[n - 1]?.kind).toBe('frame');
    expect(entries[n + 1]).toMatchObject({ kind: 'resync', offset: noiseAt + 21 });
    expect(entries[n + 2]).toMatchObject({ kind: 'frame', offset: noiseAt + 21 });

    // The truncated frame: discarded as such, a resync, the next frame.
    const truncAt = 40 + 20 * 16 + 21;
    const t = entries.findIndex((e) => e.kind === 'discarded' && e.offset === truncAt);
    expect(entries[t]).toMatchObject({ length: 11, reason: 'truncated-frame' });
    expect(bytesOf(entries[t] as InspectEntry)).toEqual(Array.from(truncated));
    expect(entries[t + 1]).toMatchObject({ kind: 'resync', offset: truncAt + 11 });
    expect(entries[t + 2]).toMatchObject({ kind: 'frame', offset: truncAt + 11 });
    expect(kinds.filter((k) => k === 'resync')).toHaveLength(decoder.stats.resyncs);

    // Frames: as the decoder gave them, with their bytes from the raw ring.
    const fr = entries.filter((e) => e.kind === 'frame');
    expect(fr).toHaveLength(decoded.length);
    expect(fr).toHaveLength(31);
    fr.forEach((e, i) => {
      const d = decoded[i] as FrameSnapshot;
      expect(e.offset).toBe(d.offset);
      expect(e.timeUs).toBe(d.timeUs);
      expect(e).toMatchObject({ length: 16, resolution: 2048, remote: 'internal', headerMode: 'fades', system: 0xb2 });
      expect(bytesOf(e)).toEqual(Array.from(d.bytes));
      expect(bytesOf(e)).toEqual(Array.from(stream.subarray(e.offset, e.offset + 16)));
    });

    // Events are timed like frames: a resync at a frame's first byte has the frame's time.
    for (const e of entries) expect(Number.isFinite(e.timeUs)).toBe(true);
    expect(entries[n + 1]?.timeUs).toBe(entries[n + 2]?.timeUs);
    expect(entries[t + 1]?.timeUs).toBe(entries[t + 2]?.timeUs);

    // The newest few, still in stream order.
    const last = log.snapshot(3);
    expect(last.map((e) => e.offset)).toEqual(entries.slice(-3).map((e) => e.offset));
    expect(log.snapshot(0)).toEqual([]);
  });

  it('shows a frame that noise follows discarded with the noise, in stream order', () => {
    // A frame with a layout not seen before, then noise: nothing confirms where it ends.
    const odd = encodeInternalFrame({ fades: 3, system: 0xb2 }, [
      encodeServo2048(10, 500),
      encodeServo2048(11, 600),
      encodeServo2048(0, 700),
      0xffff,
      0xffff,
      0xffff,
      0xffff,
    ]);
    const stream = join([...frames(6), odd, noise(21), ...frames(6, 6)]);
    const log = new InspectorLog();
    const decoder = new SpektrumDecoder({ onEvent: (e) => log.onEvent(e) });
    decoder.push(stream, 5000);
    decoder.end();
    for (let f = decoder.next(); f; f = decoder.next()) log.onFrame(f);
    const o = 12 * 16;
    const entries = log.snapshot(100);
    const i = entries.findIndex((e) => e.offset === o && e.kind === 'discarded');
    expect(entries.slice(i, i + 3).map((e) => [e.kind, e.offset])).toEqual([
      ['discarded', o],
      ['resync', o + 37],
      ['frame', o + 37],
    ]);
    expect(bytesOf(entries[i] as InspectEntry)?.slice(0, 16)).toEqual(Array.from(odd));
  });

  it('gives the same entries however the bytes are chunked', () => {
    const stream = join([noise(23), ...frames(8), noise(7), ...frames(8, 8)]);
    const strip = (es: InspectEntry[]) => es.map((e) => ({ ...e, timeUs: 0, bytes: bytesOf(e) }));
    const a = strip(run(stream, new InspectorLog(), 1, false).log.snapshot(500));
    const b = strip(run(stream, new InspectorLog(), 64, false).log.snapshot(500));
    const c = strip(run(stream, new InspectorLog(), stream.length, false).log.snapshot(500));
    expect(b).toEqual(a);
    expect(c).toEqual(a);
  });

  it('times events NaN without chunk times, or as the decoder gives them', () => {
    const { log } = run(join([noise(20), ...frames(4)]), new InspectorLog(), 16, false);
    const [discard] = log.snapshot(100);
    expect(discard?.kind).toBe('discarded');
    expect(discard?.timeUs).toBeNaN();
    log.onEvent({ type: 'resync', offset: log.streamBytes - 1, timeUs: 1234 });
    expect(log.snapshot(1)[0]).toMatchObject({ kind: 'resync', timeUs: 1234, bytes: null, length: 0 });
  });

  it('drops the oldest entries, and the bytes of the oldest, when its entries or its byte store overflow', () => {
    const stream = join(frames(10)); // 20 frames
    const log = new InspectorLog(8, 64);
    run(stream, log, 5);
    expect(log.size).toBe(8);
    const entries = log.snapshot(100);
    expect(entries).toHaveLength(8);
    // The newest eight frames; only the last 64 bytes (four frames) are still held.
    expect(entries.map((e) => e.offset)).toEqual([12, 13, 14, 15, 16, 17, 18, 19].map((i) => i * 16));
    entries.forEach((e, i) => {
      if (i < 4) expect(e.bytes).toBeNull();
      else expect(bytesOf(e)).toEqual(Array.from(stream.subarray(e.offset, e.offset + 16)));
    });
  });

  it('keeps a long run of discarded bytes as one entry with its first bytes', () => {
    const junk = noise(1000);
    const { log } = run(join([junk, ...frames(6)]), new InspectorLog(), 100);
    const [d, locked] = log.snapshot(100);
    expect(d).toMatchObject({ kind: 'discarded', offset: 0, length: 1000, reason: 'before-lock', truncated: true });
    expect(d?.bytes?.length).toBe(DISCARD_BYTES_CAP);
    expect(bytesOf(d as InspectEntry)).toEqual(Array.from(junk.subarray(0, DISCARD_BYTES_CAP)));
    expect(locked).toMatchObject({ kind: 'locked', offset: 1000 });
  });

  it("a huge chunk keeps only the byte store's worth of frames' bytes; reset() starts over", () => {
    const stream = join(frames(20));
    const log = new InspectorLog(4096, 128);
    run(stream, log, stream.length);
    const entries = log.snapshot(1000);
    expect(entries.filter((e) => e.bytes !== null).map((e) => e.offset)).toEqual([32, 33, 34, 35, 36, 37, 38, 39].map((i) => i * 16));
    expect(bytesOf(entries.at(-1) as InspectEntry)).toEqual(Array.from(stream.subarray(stream.length - 16)));
    log.reset();
    expect(log.size).toBe(0);
    expect(log.streamBytes).toBe(0);
    run(join(frames(3)), log);
    expect(
      log
        .snapshot(100)
        .filter((e) => e.kind === 'frame')
        .map((e) => e.offset),
    ).toEqual([0, 16, 32, 48, 64, 80]);
  });

  it("logs an external remote's and an RSSI remote's frames with their header mode", () => {
    const ext: Uint8Array[] = [];
    for (let i = 0; i < 8; i++)
      ext.push(encodeExternalFrame(300 + i, [encodeServo2048(0, 1000 + i), encodeServo2048(1, 900), encodeServo2048(2, 800)]));
    const e = run(join(ext))
      .log.snapshot(100)
      .filter((x) => x.kind === 'frame');
    expect(e[0]).toMatchObject({ remote: 'external', headerMode: 'fades', system: null, resolution: 2048 });
    const rssi: Uint8Array[] = [];
    for (let i = 0; i < 8; i++)
      rssi.push(encodeInternalFrame({ rssi: -60 - (i % 3), system: 0xb2 }, [encodeServo2048(0, 1000 + i), encodeServo2048(1, 900)]));
    const r = run(join(rssi))
      .log.snapshot(100)
      .filter((x) => x.kind === 'frame');
    expect(r[0]).toMatchObject({ remote: 'internal', headerMode: 'rssi', system: 0xb2 });
  });

  it('keeps copies of what the decoder lends it, and joins a discard run even when an entry came in between out of order', () => {
    const log = new InspectorLog();
    const lent = Uint8Array.from({ length: 20 }, (_, i) => i);
    log.onEvent({ type: 'discarded', offset: 100, length: 20, timeUs: 5, reason: 'noise', bytes: lent });
    lent.fill(0xee); // the decoder's buffer moves on
    // Decided later, earlier in the stream: it sorts before, though its bytes were stored after.
    log.onEvent({ type: 'discarded', offset: 60, length: 16, timeUs: 1, reason: 'truncated-frame', bytes: new Uint8Array(16).fill(7) });
    log.onEvent({ type: 'discarded', offset: 120, length: 3, timeUs: 9, reason: 'noise', bytes: Uint8Array.of(50, 51, 52) });
    const entries = log.snapshot(10);
    expect(entries.map((e) => [e.offset, e.length, e.timeUs])).toEqual([
      [60, 16, 1],
      [100, 23, 5],
    ]);
    expect(bytesOf(entries[0] as InspectEntry)).toEqual(Array(16).fill(7));
    expect(bytesOf(entries[1] as InspectEntry)).toEqual([...Array.from({ length: 20 }, (_, i) => i), 50, 51, 52]);
    expect(log.streamBytes).toBe(123);
  });

  it('rejects a capacity or byte store it cannot hold', () => {
    expect(() => new InspectorLog(0)).toThrow(RangeError);
    expect(() => new InspectorLog(16, 8)).toThrow(RangeError);
  });
});

describe('describeFrame', () => {
  it('reads an internal remote with fades and a DSMX system byte', () => {
    const f = encodeInternalFrame({ fades: 62, system: 0xb2 }, [encodeServo2048(1, 1023, 1), encodeServo2048(5, 1024)]);
    const d = describeFrame(f, 2048, 'internal', 'fades');
    expect(d.header).toHaveLength(2);
    expect(d.header[0]).toMatchObject({ field: 'fades', first: 0, last: 0, value: 62, text: 'fades 62' });
    expect(d.header[1]).toMatchObject({ field: 'system', first: 1, last: 1, value: 0xb2, valid: true, text: '0xB2 DSMX 11 ms' });
    expect(d.header[1]?.title).toMatch(/DSMX 11 ms 2048/);
    expect(d.phase).toBe(1);
    expect(d.slots).toHaveLength(7);
    expect(d.slots[0]).toMatchObject({
      index: 0,
      first: 2,
      last: 3,
      word: 0x8bff,
      hex: '8BFF',
      kind: 'channel',
      phase: 1,
      id: 1,
      channel: 1,
      position: 1023,
      us: servoToMicros(1023, 2048),
      name: 'Aileron',
      label: '1p',
      problem: null,
    });
    expect(d.slots[1]).toMatchObject({ kind: 'channel', phase: 0, channel: 5, position: 1024, name: 'Aux 1', label: '5' });
    expect(d.slots.slice(2).every((s) => s.kind === 'empty' && s.word === 0xffff && s.label === 'empty')).toBe(true);
    expect(d.summary).toBe(
      `fades 62 · 0xB2 DSMX 11 ms · 1p Aileron 1023 ${servoToMicros(1023, 2048)}\u00a0µs · 5 Aux 1 1024 ${servoToMicros(1024, 2048)}\u00a0µs · 5 empty`,
    );
    expect(d.vtx).toBeNull();
  });

  it('reads SPM4649T RSSI as a signed dBm value, -128 being loss', () => {
    const f = encodeInternalFrame({ rssi: -128, system: 0xa2 }, [encodeServo2048(0, 100)]);
    const d = describeFrame(f, 2048, 'internal', 'rssi');
    expect(d.header[0]).toMatchObject({ field: 'rssi', raw: 0x80, value: -128, text: 'RSSI -128\u00a0dBm (loss)' });
    expect(d.header[1]).toMatchObject({ text: '0xA2 DSMX 22 ms', valid: true });
    const g = describeFrame(encodeInternalFrame({ rssi: -56, system: 0xa2 }, [encodeServo2048(0, 100)]), 2048, 'internal', 'rssi');
    expect(g.header[0]).toMatchObject({ value: -56, text: 'RSSI -56\u00a0dBm' });
  });

  it("reads an external remote's bytes 0–1 as one UINT16 fade count", () => {
    const f = encodeExternalFrame(0x1234, [encodeServo2048(2, 2047)]);
    const d = describeFrame(f, 2048, 'external', 'fades');
    expect(d.header).toHaveLength(1);
    expect(d.header[0]).toMatchObject({ field: 'fades', first: 0, last: 1, value: 0x1234, text: 'fades 4660' });
    expect(d.slots[0]).toMatchObject({ channel: 2, position: 2047, name: 'Elevator', us: servoToMicros(2047, 2048) });
    expect(d.summary.startsWith('fades 4660 · 2 Elevator 2047')).toBe(true);
  });

  it('reads 1024 mode: 6-bit IDs, no phase bit, X-Plus ID invalid', () => {
    const f = encodeInternalFrame({ fades: 0, system: 0x01 }, [encodeServo1024(3, 700), encodeServo1024(0, 1023), encodeServo1024(12, 5)]);
    const d = describeFrame(f, 1024, 'internal', 'fades');
    expect(d.header[1]).toMatchObject({ text: '0x01 DSM2 22 ms', valid: true });
    expect(d.phase).toBeNull();
    expect(d.slots[0]).toMatchObject({
      kind: 'channel',
      phase: null,
      id: 3,
      channel: 3,
      position: 700,
      us: servoToMicros(700, 1024),
      name: 'Rudder',
      label: '3',
    });
    expect(d.slots[1]).toMatchObject({ kind: 'channel', channel: 0, position: 1023, name: 'Throttle' });
    expect(d.slots[2]).toMatchObject({ kind: 'invalid', id: 12, channel: null, label: '!' });
    expect(d.slots[2]?.problem).toMatch(/does not exist/);
  });

  it('reads X-Plus X+1 and X+8 (sub-ID, phase, 9 bits scaled to 11)', () => {
    // Phase-1 frame: the X+8 and X+5 words start with 0xE but are not VTX.
    const f = encodeInternalFrame({ fades: 1, system: 0xb2 }, [
      encodeServo2048(0, 1000, 1),
      encodeXPlus(12, 1001),
      encodeServo2048(1, 900),
      encodeServo2048(2, 900),
      encodeServo2048(3, 900),
      encodeXPlus(19, 2047),
      encodeXPlus(16, 4),
    ]);
    const d = describeFrame(f, 2048, 'internal', 'fades');
    expect(d.vtx).toBeNull();
    expect(d.slots[1]).toMatchObject({
      kind: 'xplus',
      phase: 0,
      id: 12,
      subId: 0,
      value9: 250,
      channel: 12,
      position: 1000,
      name: 'X+1',
      label: 'X+1',
      us: servoToMicros(1000, 2048),
    });
    expect(d.slots[5]).toMatchObject({ kind: 'xplus', phase: 1, id: 12, subId: 3, value9: 511, channel: 19, position: 2044, name: 'X+8' });
    expect(d.slots[6]).toMatchObject({ kind: 'xplus', phase: 1, subId: 0, channel: 16, position: 4, name: 'X+5' });
    expect(d.slots[5]?.title).toMatch(/\+ 4 for phase 1/);
    expect(d.summary).toContain('X+1 1000');
    expect(d.summary).toContain('X+8 2044');
  });

  it('reads VTX control from bytes 12–15 in a phase-0 frame', () => {
    const [hi, lo] = vtxWords({ band: 2, channel: 5, power: 3, region: 1, pit: true });
    const f = encodeInternalFrame({ fades: 0, system: 0xb2 }, [
      encodeServo2048(0, 1000),
      encodeServo2048(1, 1000),
      0xffff,
      0xffff,
      0xffff,
      hi,
      lo,
    ]);
    const d = describeFrame(f, 2048, 'internal', 'fades');
    expect(d.vtx).toMatchObject({ band: 2, channel: 5, power: 3, region: 1, pit: true });
    expect(d.slots[5]).toMatchObject({ kind: 'vtx', first: 12, label: 'VTX', channel: null });
    expect(d.slots[6]).toMatchObject({ kind: 'vtx', first: 14, label: 'VTX', text: '' });
    expect(d.slots[5]?.title).toMatch(/band 2, channel 5, power 3, region EU, pit mode on/);
    expect(d.slots[6]?.title).toMatch(/^bytes 14–15, slot 7, word 0xE01B: .*band 2, channel 5, power 3, region EU, pit mode on/);
    expect(d.summary).toBe(
      `fades 0 · 0xB2 DSMX 11 ms · 0 Throttle 1000 ${servoToMicros(1000, 2048)}\u00a0µs · 1 Aileron 1000 ${servoToMicros(1000, 2048)}\u00a0µs · VTX band 2 ch 5 power 3 EU pit · 3 empty`,
    );
    // The same words in a phase-1 frame are not VTX (they read as X-Plus words, or invalid).
    const g = encodeInternalFrame({ fades: 0, system: 0xb2 }, [
      encodeServo2048(0, 1000, 1),
      encodeServo2048(1, 1000),
      0xffff,
      0xffff,
      0xffff,
      hi,
      lo,
    ]);
    expect(describeFrame(g, 2048, 'internal', 'fades').vtx).toBeNull();
  });

  it('marks impossible channel IDs, repeated channels and bad system bytes', () => {
    const f = encodeInternalFrame({ fades: 0, system: 0x55 }, [
      encodeServo2048(0, 10),
      encodeServo2048(14, 100),
      encodeServo2048(0, 20),
      0x7fff,
    ]);
    const d = describeFrame(f, 2048, 'internal', 'fades');
    expect(d.header[1]).toMatchObject({ valid: false, value: 0x55, text: '0x55 not a valid system byte' });
    expect(d.header[1]?.title).toMatch(/not a valid system byte/);
    expect(d.slots[1]).toMatchObject({
      kind: 'invalid',
      id: 14,
      channel: null,
      position: null,
      label: '!',
      text: 'invalid 0x7064 (ID 14)',
    });
    expect(d.slots[1]?.problem).toMatch(/channel ID 14 does not exist/);
    expect(d.slots[2]).toMatchObject({ kind: 'invalid', channel: 0, position: 20, text: 'invalid 0x0014 (Throttle again)' });
    expect(d.slots[2]?.problem).toMatch(/Throttle again \(slot 1 has it\)/);
    expect(d.slots[3]).toMatchObject({ kind: 'invalid', id: 15 });
    // A system byte that names the other resolution says so.
    const g = describeFrame(encodeInternalFrame({ fades: 0, system: 0x01 }, [encodeServo2048(0, 10)]), 2048, 'internal', 'fades');
    expect(g.header[1]?.title).toMatch(/read at 2048, not 1024/);
    expect(() => describeFrame(new Uint8Array(15), 2048, 'internal', 'fades')).toThrow(RangeError);
  });
});
