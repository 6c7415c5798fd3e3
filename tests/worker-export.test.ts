/**
 * Raw export of a recording: a .bin has no room to say which port a byte came from, so a
 * recording of several ports is exported one file per port, each a stream that decodes alone.
 */
import { describe, expect, it } from 'vitest';
import { encodeCapture, parseCapture } from '../src/capture/index.js';
import { SpektrumDecoder } from '../src/decoder/index.js';
import { preset, simulate } from '../src/simulator/index.js';
import { rawFiles } from '../src/worker/recorder.js';
import { usbChunks } from './feeds.js';

function decodeAll(bytes: Uint8Array) {
  const d = new SpektrumDecoder();
  d.push(bytes);
  d.end();
  let frames = 0;
  while (d.next() !== undefined) frames++;
  return { frames, discarded: d.stats.discardedBytes };
}

describe('raw export', () => {
  const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 1 }, 2_000_000);
  const b = simulate({ ...preset('dsmx-11ms-2048-external'), seed: 2 }, 2_000_000);

  it('writes one file per port of a two-port recording, each exactly that port’s bytes', () => {
    const records = [
      ...usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
      ...usbChunks(b.bytes, b.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs + 3, port: 1 })),
    ].sort((x, y) => x.timeUs - y.timeUs);
    const capture = parseCapture(encodeCapture({ baudRate: 115200 }, records));
    // The mixture a single file would hold does not decode.
    expect(decodeAll(capture.bytes).discarded).toBeGreaterThan(capture.bytes.length / 4);
    const files = rawFiles(capture, 'rec');
    expect(files.map((f) => f.name)).toEqual(['rec-port0.bin', 'rec-port1.bin']);
    expect(Buffer.from(files[0]!.data).equals(Buffer.from(a.bytes))).toBe(true);
    expect(Buffer.from(files[1]!.data).equals(Buffer.from(b.bytes))).toBe(true);
    for (const f of files) {
      const r = decodeAll(new Uint8Array(f.data));
      expect(r.discarded).toBe(0);
      expect(r.frames).toBeGreaterThan(170);
    }
  });

  it('writes one file, named as the recording, for a single port', () => {
    const capture = parseCapture(
      encodeCapture(
        { baudRate: 115200 },
        usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
      ),
    );
    const files = rawFiles(capture, 'rec');
    expect(files.map((f) => f.name)).toEqual(['rec.bin']);
    expect(Buffer.from(files[0]!.data).equals(Buffer.from(a.bytes))).toBe(true);
  });
});
