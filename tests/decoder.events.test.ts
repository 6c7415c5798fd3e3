/**
 * What the decoder's events carry for a log or an inspector: the time of the byte at their
 * offset (by the rule a frame's time follows) and, for a discard, the discarded bytes.
 */
import { describe, expect, it } from 'vitest';
import { BYTE_TIME_US } from '../src/decoder/spec.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import type { DecoderEvent } from '../src/decoder/types.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';

/** An event as plain data, its bytes copied while they were valid. */
type Seen =
  | Exclude<DecoderEvent, { type: 'discarded' }>
  | (Omit<Extract<DecoderEvent, { type: 'discarded' }>, 'bytes'> & { bytes: number[] });

/** A damaged line from a mid-frame start: a discard before the lock, the lock, noise, truncated frames and resyncs. */
function damaged(): { bytes: Uint8Array; times: Float64Array } {
  const sim = simulate({ ...preset('damaged-line'), seed: 21 }, 3_000_000);
  return { bytes: sim.bytes.subarray(5), times: sim.timesUs.subarray(5) };
}

type Feed = 'none' | 'chunk' | 'per-byte';

/**
 * Decodes `bytes` pushed `chunk` bytes at a time with no time, each chunk's last byte time, or
 * per-byte times; returns the events (bytes copied in the callback) and each frame's offset and time.
 */
function decode(bytes: Uint8Array, times: Float64Array, chunk: number, feed: Feed) {
  const events: Seen[] = [];
  const frames = new Map<number, number>();
  const decoder = new SpektrumDecoder({
    onEvent: (e) => {
      if (e.type === 'discarded') events.push({ ...e, bytes: Array.from(e.bytes) });
      else events.push({ ...e });
    },
  });
  const drain = (): void => {
    for (let f = decoder.next(); f; f = decoder.next()) frames.set(f.offset, f.timeUs);
  };
  for (let at = 0; at < bytes.length; at += chunk) {
    const end = Math.min(bytes.length, at + chunk);
    const piece = bytes.subarray(at, end);
    if (feed === 'none') decoder.push(piece);
    else if (feed === 'chunk') decoder.push(piece, times[end - 1]!);
    else decoder.push(piece, times.subarray(at, end));
    drain();
  }
  decoder.end();
  drain();
  return { events, frames };
}

describe('decoder events', () => {
  const { bytes, times } = damaged();

  it('come in every kind a damaged line causes', () => {
    const { events } = decode(bytes, times, 64, 'chunk');
    const kinds = new Set(events.map((e) => e.type));
    for (const kind of ['discarded', 'resync', 'locked']) expect(kinds).toContain(kind);
    expect(events.filter((e) => e.type === 'discarded').length).toBeGreaterThan(3);
  });

  it('carry the exact time of the byte at their offset with per-byte times', () => {
    const { events } = decode(bytes, times, 64, 'per-byte');
    for (const e of events) expect(e.timeUs, `${e.type} at ${e.offset}`).toBe(times[e.offset]);
  });

  it("with chunk times, carry the chunk's time less a byte time for each byte after theirs, as frames do", () => {
    const chunk = 64;
    const { events, frames } = decode(bytes, times, chunk, 'chunk');
    for (const e of events) {
      const end = Math.min(bytes.length, (Math.floor(e.offset / chunk) + 1) * chunk);
      const expected = times[end - 1]! - (end - 1 - e.offset) * BYTE_TIME_US;
      expect(e.timeUs, `${e.type} at ${e.offset}`).toBeCloseTo(expected, 6);
      // Where frames resume (a resync, a lock), the event has the frame's time.
      const frameUs = frames.get(e.offset);
      if (frameUs !== undefined && e.type !== 'discarded') expect(e.timeUs).toBe(frameUs);
    }
  });

  it('carry NaN without times', () => {
    const { events } = decode(bytes, times, 64, 'none');
    expect(events.length).toBeGreaterThan(0);
    for (const e of events) expect(e.timeUs).toBeNaN();
  });

  it("hand a discard its bytes: the stream's bytes at its offset, every discarded byte once", () => {
    const { events } = decode(bytes, times, 64, 'chunk');
    const discards = events.filter((e) => e.type === 'discarded');
    let total = 0;
    for (const d of discards) {
      expect(d.bytes).toEqual(Array.from(bytes.subarray(d.offset, d.offset + d.length)));
      total += d.length;
    }
    const decoder = new SpektrumDecoder();
    decoder.push(bytes);
    decoder.end();
    while (decoder.next()) {
      // Drained for the count.
    }
    expect(total).toBe(decoder.stats.discardedBytes);
  });

  it('are the same however the bytes are chunked (and so are their times, with per-byte times)', () => {
    const whole = decode(bytes, times, bytes.length, 'per-byte').events;
    for (const chunk of [1, 7, 64, 1000]) {
      expect(decode(bytes, times, chunk, 'per-byte').events, `${chunk}-byte chunks`).toEqual(whole);
      const untimed = decode(bytes, times, chunk, 'none').events;
      expect(untimed.map((e) => ({ ...e, timeUs: 0 }))).toEqual(whole.map((e) => ({ ...e, timeUs: 0 })));
    }
  });
});
