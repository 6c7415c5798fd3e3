/**
 * Raw export of a recording: a .bin has no room to say which port a byte came from, so a
 * recording of several ports is exported one file per port, each a stream that decodes alone.
 * Decoded frames: the page's file is the one `satscope decode` prints, of the whole or a span.
 */
import { spawnSync } from 'node:child_process';
import { mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';
import { encodeCapture } from '../src/capture/writer.js';
import { parseCapture } from '../src/capture/reader.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { type FramesExport, framesFile } from '../src/worker/frames-export.js';
import { rawFiles } from '../src/worker/recorder.js';
import { CLI } from './built-cli.js';
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

describe('decoded frames export', () => {
  const dir = mkdtempSync(join(tmpdir(), 'satscope-frames-'));
  const a = simulate({ ...preset('dropouts-and-damage'), seed: 3 }, 2_500_000);
  const b = simulate({ ...preset('dsmx-11ms-2048-external'), seed: 4 }, 2_500_000);
  const records = [
    ...usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
    ...usbChunks(b.bytes, b.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs + 3, port: 1 })),
  ].sort((x, y) => x.timeUs - y.timeUs);
  const file = encodeCapture({ baudRate: 115200 }, records);
  const path = join(dir, 'two.sscap');
  writeFileSync(path, file);
  const capture = parseCapture(file);
  const text = (o: Partial<FramesExport>) =>
    new TextDecoder().decode(framesFile(capture, { port: 0, format: 'csv', fromUs: null, toUs: null, resolution: 'auto', ...o }).data);

  for (const format of ['csv', 'jsonl'] as const)
    for (const port of [0, 1])
      it(`is byte for byte what satscope decode --format ${format} --port ${port} prints`, () => {
        const cli = spawnSync(process.execPath, [CLI, 'decode', path, '--format', format, '--port', String(port)], { encoding: 'utf8' });
        expect(cli.status).toBe(0);
        expect(cli.stdout.split('\n').length).toBeGreaterThan(80);
        expect(text({ port, format })).toBe(cli.stdout);
      });

  it('keeps the frames whose time falls in the span, and nothing else', () => {
    const all = text({ format: 'jsonl' }).trimEnd().split('\n');
    const t = (line: string) => (JSON.parse(line) as { t: number }).t * 1e6;
    const fromUs = t(all[20]!);
    const toUs = t(all[70]!);
    const span = text({ format: 'jsonl', fromUs, toUs }).trimEnd().split('\n');
    expect(span).toEqual(all.filter((l) => t(l) >= fromUs && t(l) <= toUs));
    expect(span.length).toBe(51);
    // CSV keeps its header whatever the span.
    expect(text({ fromUs, toUs }).split('\n')[0]).toMatch(/^t,remote,system,resolution,fades,rssi,ch0_us,/);
  });
});
