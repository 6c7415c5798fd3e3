/**
 * `satscope doctor`: the command's output and exit codes on captures made from the simulator
 * and the line model, called in-process and, once, as a user would (node dist/cli/main.js;
 * needs `npm run build:lib` first, as tests/cli.test.ts does).
 */
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { doctorCommand } from '../src/cli/doctor.js';
import { CaptureWriter } from '../src/capture/writer.js';
import { ibusStream } from '../src/simulator/protocols.js';
import { preset } from '../src/simulator/presets.js';
import { receiveAs } from '../src/simulator/line.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';
import { satscope } from './built-cli.js';

const SECOND = 1_000_000;
let dir = '';

function run(...args: string[]): { code: number; out: string; err: string } {
  let out = '';
  let err = '';
  const code = doctorCommand(args, { out: (t) => (out += t), err: (t) => (err += t) });
  return { code, out, err };
}

/** A recording as the page makes it: "port opened", then 16 ms USB chunks stamped at their end. */
function recording(bytes: Uint8Array, timesUs: Float64Array): Uint8Array {
  const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
  const parts = [w.header(), w.event('port opened', 0, 0)];
  for (const c of usbChunks(bytes, timesUs)) parts.push(w.data(c.bytes, c.timeUs));
  return concatBytes(parts);
}

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), 'satscope-doctor-'));
  const ibus = receiveAs(ibusStream({ durationUs: 3 * SECOND, startUs: 50_000 }));
  writeFileSync(join(dir, 'ibus.sscap'), recording(ibus.bytes, ibus.timesUs));
  writeFileSync(join(dir, 'ibus.bin'), ibus.bytes);
  const dsm2 = simulate(
    { ...preset('dsm2-22ms-1024-internal'), fades: { lossRate: 0, randomRate: 0.01 }, timing: { startUs: 50_000 } },
    3 * SECOND,
  );
  writeFileSync(join(dir, 'dsm2.sscap'), recording(dsm2.bytes, dsm2.timesUs));
  const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
  writeFileSync(join(dir, 'silent.sscap'), concatBytes([w.header(), w.event('port opened', 0, 0), w.event('device lost', 5 * SECOND, 0)]));
  writeFileSync(join(dir, 'notes.txt'), 'these are my notes\nnot a capture\n');
});

afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe('satscope doctor', () => {
  it('names IBUS, says what to set, and exits 1 for a problem', () => {
    const r = run(join(dir, 'ibus.sscap'));
    expect(r.code).toBe(1);
    expect(r.out).toMatch(/^satscope doctor: ibus\.sscap \(sscap, a time per chunk, 1 port, \d+ bytes, 3\.\d s\)/);
    expect(r.out).toMatch(/PROBLEM {2}Port 0: this is FlySky IBUS, not a Spektrum satellite {2}\[certain, since 0:00\.\d\]/);
    expect(r.out).toMatch(/Betaflight: .*\n {6}set serialrx_provider = IBUS/);
    expect(r.err).toBe('');
  });

  it('names IBUS in a raw byte dump too (no times: as if the bytes came back to back)', () => {
    const r = run(join(dir, 'ibus.bin'));
    expect(r.code).toBe(1);
    expect(r.out).toMatch(/^satscope doctor: ibus\.bin \(raw, no times, 1 port/);
    expect(r.out).toMatch(/this is FlySky IBUS/);
  });

  it('gives the flight-controller lines for a DSM2 22 ms stream and exits 0 when nothing is a problem', () => {
    const r = run(join(dir, 'dsm2.sscap'));
    expect(r.code).toBe(0);
    expect(r.out).toMatch(/WARNING {2}Port 0: bound in DSM2 22 ms 1024; DSMX 11 ms is better/);
    expect(r.out).toMatch(/set serialrx_provider = SPEK1024/);
    expect(r.out).toMatch(/spektrum_sat_bind = 9/);
  });

  it('prints the same report as JSON with --json', () => {
    const r = run(join(dir, 'dsm2.sscap'), '--json');
    const report = JSON.parse(r.out) as { format: string; findings: { code: string }[]; timeline: unknown[] };
    expect(report.format).toBe('satscope-doctor');
    expect(report.findings.map((f) => f.code)).toEqual(expect.arrayContaining(['bind-mode', 'fc-settings']));
  });

  it('finds that nothing arrived on a port that opened and stayed silent', () => {
    const r = run(join(dir, 'silent.sscap'));
    expect(r.code).toBe(0); // the port was lost at the end: nothing is wrong any more…
    expect(r.out).toMatch(/Seen earlier in the capture, cleared by its end:\n {2}problem: Port 0: nothing arrives \(0:01\.0–0:05\.0\)/);
  });

  it('exits 1 with a message for a file that is not a capture, and 2 for bad usage', () => {
    const notCapture = run(join(dir, 'notes.txt'));
    expect(notCapture.code).toBe(1);
    expect(notCapture.err).toMatch(/notes\.txt/);
    expect(run().code).toBe(2);
    expect(run(join(dir, 'ibus.sscap'), '--resolution', '4096').err).toMatch(/--resolution must be auto, 1024 or 2048/);
    expect(run(join(dir, 'ibus.sscap'), '--frobnicate').code).toBe(2);
    expect(run(join(dir, 'missing.sscap')).err).toMatch(/no such file/);
  });

  it('runs as `satscope doctor` from the built command line', () => {
    const r = satscope('doctor', join(dir, 'ibus.sscap'));
    expect(r.err).toBe('');
    expect(r.code).toBe(1);
    expect(r.out).toMatch(/this is FlySky IBUS/);
  });
});
