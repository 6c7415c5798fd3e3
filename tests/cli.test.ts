/**
 * The satscope command, run as a user would (node dist/cli/main.js), on captures of each kind
 * made from the simulator. Needs `npm run build:lib` first (`npm test` does it).
 */
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { CaptureWriter } from '../src/capture/writer.js';
import { readCapture } from '../src/capture/sniff.js';
import { formatClock } from '../src/report/report-text.js';
import { summarizeCapture } from '../src/report/summary.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';
import { satscope, satscopeWith } from './built-cli.js';

let dir = '';
const sim = simulate({ ...preset('dropouts-failsafe'), seed: 3 }, 4_000_000, { truth: true });
const intact = sim.truth!.frames.filter((f) => f.damage === null);

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-cli-'));
  const writer = new CaptureWriter({ baudRate: 115200, source: 'test' });
  const parts = [writer.header()];
  // As a USB adapter delivers them: what arrived in each 16 ms window, stamped at its end.
  for (const c of usbChunks(sim.bytes, sim.timesUs)) parts.push(writer.data(c.bytes, c.timeUs));
  const file = concatBytes(parts);
  writeFileSync(join(dir, 'run.sscap'), file);
  writeFileSync(join(dir, 'cut.sscap'), file.subarray(0, file.length - 30));
  writeFileSync(join(dir, 'run.bin'), sim.bytes);
  const csv = [
    'Time [s],Value,Parity Error,Framing Error',
    ...Array.from(sim.bytes, (b, i) => `${(sim.timesUs[i]! / 1e6).toFixed(9)},0x${b.toString(16).toUpperCase().padStart(2, '0')},,`),
  ];
  writeFileSync(join(dir, 'run.csv'), csv.join('\n'));
  // The same bytes with one bit of the header's metadata length flipped.
  const damaged = file.slice();
  damaged[13]! ^= 0x04;
  writeFileSync(join(dir, 'damaged-header.sscap'), damaged);
  // Two satellites on ports 1 and 2, none on port 0.
  const two = new CaptureWriter({ source: 'test' });
  writeFileSync(
    join(dir, 'two.sscap'),
    concatBytes([two.header(), two.data(sim.bytes, NaN, 1), two.data(sim.bytes.subarray(0, 800), NaN, 2)]),
  );
  writeFileSync(join(dir, '-dash.bin'), sim.bytes);
  writeFileSync(join(dir, 'notes.txt'), 'these are my notes\nnot a capture\n');
  writeFileSync(join(dir, 'empty.bin'), new Uint8Array(0));
  writeFileSync(
    join(dir, 'noise.bin'),
    Uint8Array.from({ length: 500 }, (_, i) => (i * 37 + 11) & 0xff),
  );
});

afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe('satscope decode', () => {
  it('prints one JSONL line per intact frame, in the documented shape, from a .sscap', () => {
    const r = satscope('decode', join(dir, 'run.sscap'));
    expect(r.code).toBe(0);
    const lines = r.out.trim().split('\n');
    expect(lines).toHaveLength(intact.length);
    expect(lines[0]).toMatch(
      /^\{"t": [\d.]+, "remote": "internal", "system": 178, "resolution": 2048, "fades": \d+, "rssi": null, "channels": \[\{"id": \d+, "pos": \d+, "us": \d+\}/,
    );
    const first = JSON.parse(lines[0]!);
    expect(Object.keys(first)).toEqual(['t', 'remote', 'system', 'resolution', 'fades', 'rssi', 'channels']);
    expect(first.channels.map((c: { id: number; pos: number }) => [c.id, c.pos])).toEqual(intact[0]!.channels.map((c) => [c.id, c.pos]));
    // Chunk-timed: estimated from the chunk's arrival less 86.8 µs a byte after it, so never
    // early, and late by at most the 16 ms batching plus an idle gap.
    const late = lines.map((l, i) => JSON.parse(l).t * 1e6 - intact[i]!.timeUs);
    expect(Math.min(...late)).toBeGreaterThan(-1);
    expect(Math.max(...late)).toBeLessThan(27_000);
  });

  it('decodes the same frames from a raw .bin (t is null) and a Saleae CSV (exact t)', () => {
    const fromSscap = satscope('decode', join(dir, 'run.sscap'))
      .out.trim()
      .split('\n')
      .map((l) => JSON.parse(l));
    const bin = satscope('decode', join(dir, 'run.bin'))
      .out.trim()
      .split('\n')
      .map((l) => JSON.parse(l));
    const csv = satscope('decode', join(dir, 'run.csv'))
      .out.trim()
      .split('\n')
      .map((l) => JSON.parse(l));
    expect(bin.map((f) => f.channels)).toEqual(fromSscap.map((f) => f.channels));
    expect(csv.map((f) => f.channels)).toEqual(fromSscap.map((f) => f.channels));
    expect(bin.every((f) => f.t === null)).toBe(true);
    expect(csv.map((f) => Math.round(f.t * 1e6))).toEqual(intact.map((f) => Math.round(f.timeUs)));
  });

  it('writes CSV with a header and one µs column per channel', () => {
    const r = satscope('decode', join(dir, 'run.bin'), '--format', 'csv');
    const [header, row] = r.out.split('\n');
    expect(header).toBe(`t,remote,system,resolution,fades,rssi,${Array.from({ length: 20 }, (_, i) => `ch${i}_us`).join(',')}`);
    expect(row!.split(',')).toHaveLength(26);
  });

  it('honours --resolution and says how many bytes it dropped', () => {
    const r = satscope('decode', join(dir, 'run.bin'), '--resolution', '2048');
    expect(r.code).toBe(0);
    expect(JSON.parse(r.out.split('\n')[0]!).resolution).toBe(2048);
  });

  it('keeps every intact record of a truncated capture and reports the cut', () => {
    const r = satscope('decode', join(dir, 'cut.sscap'));
    expect(r.code).toBe(0);
    expect(r.err).toMatch(/cut\.sscap: the file ends inside a record .*cut off/);
    const cut = r.out.trim().split('\n');
    const full = satscope('decode', join(dir, 'run.sscap')).out.trim().split('\n');
    // The last record (one 16 ms batch) is lost: at most its two frames and the one it splits.
    expect(cut.length).toBeGreaterThanOrEqual(full.length - 3);
    expect(cut).toEqual(full.slice(0, cut.length));
  });

  it('rejects a text file, an empty file, a missing file and noise with a clear message', () => {
    const text = satscope('decode', join(dir, 'notes.txt'));
    expect(text.code).toBe(1);
    expect(text.err).toMatch(/notes\.txt: .*(text|CSV)/i);
    const empty = satscope('decode', join(dir, 'empty.bin'));
    expect(empty.code).toBe(1);
    expect(empty.err).toMatch(/empty/i);
    const missing = satscope('decode', join(dir, 'nope.sscap'));
    expect(missing.code).toBe(2);
    expect(missing.err).toMatch(/cannot read .*nope\.sscap: no such file/);
    const noise = satscope('decode', join(dir, 'noise.bin'));
    expect(noise.code).toBe(1);
    expect(noise.err).toMatch(/no Spektrum frames found in 500 bytes/);
  });

  it('keeps every frame of a capture whose header is damaged, and says what was damaged', () => {
    const r = satscope('decode', join(dir, 'damaged-header.sscap'));
    expect(r.code).toBe(0);
    expect(r.err).toMatch(/damaged-header\.sscap: damaged header: its metadata length \(\d+, not \d+\) is wrong; repaired/);
    expect(r.out).toBe(satscope('decode', join(dir, 'run.sscap')).out);
    const info = satscope('info', join(dir, 'damaged-header.sscap'));
    expect(info.code).toBe(0);
    expect(info.out).toMatch(/File issues\s+1 \(bad-header: what was damaged or skipped is listed above\)/);
  });

  it('says which ports have data when the port asked for has none', () => {
    const one = satscope('decode', join(dir, 'run.sscap'), '--port', '3');
    expect(one.code).toBe(1);
    expect(one.err).toMatch(/run\.sscap: port 3 has no data; this capture has data on port 0\n/);
    expect(one.out).toBe('');
    const two = satscope('decode', join(dir, 'two.sscap'));
    expect(two.code).toBe(1);
    expect(two.err).toMatch(/port 0 has no data; this capture has data on ports 1, 2 \(choose one with --port 1\)/);
    // info, with no port chosen, sums up every port that has data, each naming the others.
    const info = satscope('info', join(dir, 'two.sscap'));
    expect(info.code).toBe(0);
    expect(info.out).toMatch(/Port {10}1, \d+ bytes \(the capture also has port 2\)/);
    expect(info.out).toMatch(/Port {10}2, 800 bytes \(the capture also has port 1\)/);
    expect(info.out).not.toMatch(/Port {10}0/);
    const chosen = satscope('decode', join(dir, 'two.sscap'), '--port', '1');
    expect(chosen.code).toBe(0);
    expect(chosen.out.trim().split('\n')).toHaveLength(intact.length);
  });

  it('takes FILE after --, also a FILE whose name starts with -', () => {
    const plain = satscope('decode', join(dir, 'run.bin')).out;
    expect(satscope('decode', '--', join(dir, 'run.bin'))).toMatchObject({ code: 0, out: plain });
    const dashed = satscopeWith({ cwd: dir }, 'decode', '--format', 'csv', '--', '-dash.bin');
    expect(dashed.code).toBe(0);
    expect(dashed.out.trim().split('\n')).toHaveLength(intact.length + 1);
  });

  it('refuses options a command does not take, missing and repeated values, with exit code 2', () => {
    const cases: [string[], RegExp][] = [
      [
        ['info', 'x', '--format', 'csv'],
        /unknown option '--format' for info: info prints a summary; --format \(jsonl or csv\) is for decode/,
      ],
      [['decode', 'x', '--json'], /unknown option '--json' for decode: .*--json is for info and report/],
      [['report', 'x', '--port', '1'], /report covers every port/],
      [['decode', 'x', '--out', 'y'], /unknown option '--out' for decode \(decode takes --format, --resolution, --port\)/],
      [['decode', 'x', '--frobnicate'], /unknown option '--frobnicate'/],
      [['decode', 'x', '--format'], /--format needs a value/],
      [['decode', 'x', '--format', '--port', '1'], /--format needs a value, not the option '--port'/],
      [['decode', 'x', '--format', 'csv', '--format', 'jsonl'], /--format is given more than once/],
      [['info', 'x', '--json=yes'], /--json takes no value/],
      [['decode', 'x', '--port', '256'], /--port must be an integer 0–255, not '256'/],
      [['decode', 'x', '--port', '1.5'], /--port must be an integer 0–255/],
      [['decode', 'x', '--resolution', '4096'], /--resolution must be auto, 1024 or 2048/],
      [['decode', 'x', 'y'], /unexpected argument 'y' \(decode takes one FILE\)/],
      [['info', '--', 'x', '--json'], /unexpected argument '--json'/],
      [[], /no command given/],
    ];
    for (const [args, message] of cases) {
      const r = satscope(...args);
      expect(r.code, args.join(' ')).toBe(2);
      expect(r.err, args.join(' ')).toMatch(message);
      expect(r.err, args.join(' ')).toMatch(/Usage:/);
      expect(r.out, args.join(' ')).toBe('');
    }
  });

  it('explains bad usage', () => {
    expect(satscope('decode').err).toMatch(/no FILE given/);
    expect(satscope('decode', 'x', '--format', 'xml').err).toMatch(/--format must be jsonl or csv/);
    expect(satscope('frobnicate', 'x').code).toBe(2);
    expect(satscope('--help').out).toMatch(/satscope info FILE/);
  });
});

interface Ep {
  startUs: number;
  endUs: number;
}

/** "1 hold", "2 holds": the count as the summary words it. */
const counted = (n: number, word: string): string => `${n} ${word}${n === 1 ? '' : 's'}`;

describe('satscope info', () => {
  it('sums up system, remote, resolution and why, channels, period, gaps and failsafe episodes', () => {
    const r = satscope('info', join(dir, 'run.csv'));
    expect(r.code).toBe(0);
    expect(r.out).toMatch(/System\s+0xB2 DSMX 11 ms 2048/);
    expect(r.out).toMatch(/Remote\s+internal \(byte 0 = UINT8 fades\)/);
    expect(r.out).toMatch(/Resolution\s+2048 — 2048 resolution from the system byte/);
    expect(r.out).toMatch(new RegExp(`Frames\\s+${intact.length} `));
    expect(r.out).toMatch(/Frame period\s+11\.0\d ms measured \(11\.00 ms nominal\)/);
    const gaps = sim.truth!.gaps.filter((g) => g.failsafe).length;
    expect(gaps).toBeGreaterThan(0);
    expect(r.out).toMatch(new RegExp(`Failsafe\\s+\\d+ holds?, ${counted(gaps, 'failsafe')}\n`));
    // Each episode dated as the report dates it: from the capture's start, on the report's clock.
    const report = JSON.parse(satscope('report', join(dir, 'run.csv'), '--json').out);
    const remote = report.remotes[0];
    const dated = [...remote.holds.episodes.map((e: Ep) => ['hold', e]), ...remote.failsafes.map((e: Ep) => ['failsafe', e])]
      .sort((a, b) => a[1].startUs - b[1].startUs || (a[0] === 'hold' ? -1 : 1))
      .map(([kind, e]) => `  ${kind.padEnd(8)} from ${formatClock(e.startUs)} until ${formatClock(e.endUs)}`);
    expect(dated.length).toBeGreaterThan(1);
    expect(r.out.split('\n').filter((l) => /^ {2}(hold|failsafe) /.test(l))).toEqual(dated);
    expect(r.out).toMatch(/ 0 Throttle/);
  });

  it("prints the summary as JSON with --json: the library's summary, and the figures the text shows", () => {
    const r = satscope('info', join(dir, 'run.csv'), '--json');
    expect(r.code).toBe(0);
    const s = JSON.parse(r.out);
    expect(s.kind).toBe('saleae-csv');
    expect(s.decoder.frames).toBe(intact.length);
    expect(s.format.resolution).toBe(2048);
    const file = join(dir, 'run.csv');
    expect(s).toEqual(JSON.parse(JSON.stringify(summarizeCapture(readCapture(readFileSync(file), file)))));
    const text = satscope('info', file).out;
    expect(text).toMatch(new RegExp(`Frames\\s+${s.decoder.frames} \\(${counted(s.decoder.discardedBytes, 'byte')} discarded`));
    expect(text).toMatch(new RegExp(`Failsafe\\s+${counted(s.link.holds, 'hold')}, ${counted(s.link.failsafes, 'failsafe')}\n`));
    expect(text).toMatch(new RegExp(`Gaps\\s+${counted(s.link.missedFrames, 'missed frame')},`));
  });
});
