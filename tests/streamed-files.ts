/**
 * Capture files of every kind the CLI streams (an .sscap of one or two ports with events, an
 * untimed one, Saleae CSVs of one and two analysers), written to a folder, and big ones made by
 * repeating simulated streams: for the tests that hold the streamed reading to the whole one
 * (tests/cli-streamed.test.ts) and its memory to a bound (tests/slow/streamed-memory.test.ts).
 */
import { closeSync, openSync, writeFileSync, writeSync } from 'node:fs';
import { join } from 'node:path';
import { CaptureWriter } from '../src/capture/writer.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { recordingFile, type Stream, usbChunks } from './feeds.js';

const SECOND = 1_000_000;

/** A Saleae CSV of the streams: Logic 1 columns for one, Logic 2 (an analyser a stream) for several. */
export function saleaeCsv(streams: Stream[], offsetS = 0): string {
  const rows: [number, number, number][] = [];
  streams.forEach((s, port) => {
    for (let i = 0; i < s.bytes.length; i++) rows.push([s.timesUs[i] ?? 0, port, s.bytes[i] ?? 0]);
  });
  rows.sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  const hex = (v: number): string => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;
  const several = streams.length > 1;
  const lines = [several ? 'name,type,start_time,duration,"data"' : 'Time [s],Value,Parity Error,Framing Error'];
  for (const [t, port, v] of rows) {
    const s = (t / SECOND + offsetS).toFixed(9);
    lines.push(several ? `"port ${port}",data,${s},0.0000868,${hex(v)}` : `${s},${hex(v)},,`);
  }
  return `${lines.join('\n')}\n`;
}

/** An .sscap of two ports with a stop and a return recorded among the data (times that fit it). */
function withStop(a: Stream, b: Stream): Uint8Array {
  const w = new CaptureWriter({ baudRate: 115200, source: 'test', ports: [{ name: 'port 0' }, { name: 'port 1' }] });
  const records = [a, b].flatMap((s, port) => usbChunks(s.bytes, s.timesUs).map((c) => ({ ...c, port })));
  records.sort((x, y) => x.timeUs - y.timeUs || x.port - y.port);
  const parts = [w.header(), w.event('port opened', 0, 0), w.event('port opened', 0, 1)];
  records.forEach((r, i) => {
    parts.push(w.data(r.bytes, r.timeUs, r.port));
    if (i === Math.floor(records.length / 2)) parts.push(w.event('device lost', r.timeUs, 1));
    if (i === Math.floor((records.length * 3) / 4)) parts.push(w.event('device reconnected', r.timeUs, 1));
  });
  return concatBytes(parts);
}

/** The sample files, written to `dir`: their paths. */
export function writeSamples(dir: string): string[] {
  const a = simulate({ ...preset('xplus-8'), seed: 3 }, 12 * SECOND);
  const b = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 4 }, 12 * SECOND);
  const c = simulate({ ...preset('dropouts-and-damage'), seed: 5 }, 12 * SECOND);
  const files: [string, Uint8Array | string][] = [
    ['one.sscap', recordingFile([c])],
    ['two.sscap', withStop(b, a)],
    ['untimed.sscap', recordingFile([a, c], false)],
    ['one.csv', saleaeCsv([c], 9.26)],
    ['two.csv', saleaeCsv([b, a])],
    ['raw.bin', c.bytes],
  ];
  return files.map(([name, data]) => {
    const path = join(dir, name);
    writeFileSync(path, data);
    return path;
  });
}

/**
 * A file of about `bytes` bytes of `kind`, a simulated minute repeated (times going on from one
 * repeat to the next), written a repeat at a time: the test holds no more than the minute.
 */
export function writeBig(path: string, kind: 'raw' | 'sscap' | 'csv', bytes: number): void {
  const minute = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 8 }, 60 * SECOND);
  const span = (minute.timesUs.at(-1) ?? 0) + 11_000;
  const fd = openSync(path, 'w');
  try {
    let written = 0;
    const put = (data: Uint8Array | string): void => {
      written += typeof data === 'string' ? writeSync(fd, data) : writeSync(fd, data);
    };
    if (kind === 'sscap') put(new CaptureWriter({ baudRate: 115200, source: 'test' }).header());
    if (kind === 'csv') put('Time [s],Value,Parity Error,Framing Error\n');
    const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
    const chunks = usbChunks(minute.bytes, minute.timesUs);
    for (let r = 0; written < bytes; r++) {
      const shift = r * span;
      if (kind === 'raw') put(minute.bytes);
      else if (kind === 'sscap') {
        const parts = chunks.map((ch) => w.data(ch.bytes, ch.timeUs + shift, 0));
        put(Buffer.concat(parts));
      } else {
        const times = minute.timesUs.map((t) => t + shift);
        const text = saleaeCsv([{ bytes: minute.bytes, timesUs: times }]);
        put(text.slice(text.indexOf('\n') + 1));
      }
    }
  } finally {
    closeSync(fd);
  }
}
