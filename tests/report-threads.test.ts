/**
 * `satscope` on two threads (src/cli/report-threads.ts and input.ts, run from the built package
 * as the command runs them): the report is byte for byte the one-thread report, its second port
 * really read by the worker thread; an .sscap read with `shared` has its columns in shared memory
 * (what the worker reads without a copy) and the same content; a big capture read in two parts
 * on two threads is the capture `readCapture` makes, and a damaged one is salvaged the same.
 */
import { createHash } from 'node:crypto';
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { afterAll, describe, expect, it } from 'vitest';
import { diagnosedHealthReport, diagnosedReportJobs } from '../src/report/doctor-report.js';
import { parseCapture } from '../src/capture/reader.js';
import { readCapture } from '../src/capture/sniff.js';
import type { Capture } from '../src/capture/model.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { recordingFile } from './feeds.js';

const SECOND = 1_000_000;
const built = resolve(import.meta.dirname, '../dist/cli/report-threads.js');

/** Two remotes recorded as the page records them (16 ms USB chunks), as the bytes of an .sscap. */
function file(): Uint8Array {
  const ports = [
    simulate(preset('dropouts-and-damage'), 20 * SECOND),
    simulate({ ...preset('dsmx-11ms-2048-external'), damage: { truncateRate: 0.01, bitFlipRate: 0.01 } }, 20 * SECOND),
  ];
  return recordingFile(ports);
}

describe('satscope report on two threads', () => {
  const bytes = file();

  it('an .sscap read with `shared` has its columns in shared memory and the same content', () => {
    const plain = readCapture(bytes, 'two.sscap');
    const shared = readCapture(bytes, 'two.sscap', { shared: true });
    for (const column of ['bytes', 'chunkEnds', 'chunkTimesUs', 'chunkPorts'] as const) {
      expect(shared[column].buffer).toBeInstanceOf(SharedArrayBuffer);
      expect(plain[column].buffer).not.toBeInstanceOf(SharedArrayBuffer);
      expect(shared[column]).toEqual(plain[column]);
    }
  });

  it('makes the one-thread report, the second port read on the worker thread', async () => {
    const { threadedReport } = (await import(built)) as {
      threadedReport: (c: Capture, o: object, minBytes?: number) => { report: unknown; fromWorker: number };
    };
    const capture = readCapture(bytes, 'two.sscap', { shared: true });
    const alone = JSON.stringify(diagnosedHealthReport(capture, { name: 'two.sscap' }));
    expect(diagnosedReportJobs(capture)).toHaveLength(1);
    const threaded = threadedReport(capture, { name: 'two.sscap' }, 0);
    expect(threaded.fromWorker).toBe(1);
    expect(JSON.stringify(threaded.report)).toBe(alone);
    // Under the size at which a second thread pays, the same report, on one thread.
    const small = threadedReport(capture, { name: 'two.sscap' });
    expect(small.fromWorker).toBe(0);
    expect(JSON.stringify(small.report)).toBe(alone);
  });
});

describe('a big capture read on two threads', () => {
  const bytes = file();
  const dir = mkdtempSync(join(tmpdir(), 'satscope-parts-'));
  afterAll(() => rmSync(dir, { recursive: true, force: true }));
  const load = async (name: string, content: Uint8Array) => {
    const path = join(dir, name);
    writeFileSync(path, content);
    const { loadCapture } = (await import(resolve(import.meta.dirname, '../dist/cli/input.js'))) as {
      loadCapture: (
        file: string,
        options: object,
        partsMinBytes?: number,
      ) => { capture?: Capture; bytesThere?: number; partsThere?: number; error?: string };
    };
    return loadCapture(path, {}, 0);
  };
  /** A capture's content, comparable across shared and plain memory. */
  const content = (c: Capture | undefined) =>
    c && { ...c, bytes: [...c.bytes], chunkEnds: [...c.chunkEnds], chunkTimesUs: [...c.chunkTimesUs], chunkPorts: [...c.chunkPorts] };

  /** The same for a big capture: its columns as SHA-256 digests (comparing 64 MB element by element takes minutes). */
  const digest = (c: Capture | undefined) => {
    const sha = (a: ArrayBufferView) =>
      createHash('sha256')
        .update(new Uint8Array(a.buffer, a.byteOffset, a.byteLength))
        .digest('hex');
    return (
      c && { ...c, bytes: sha(c.bytes), chunkEnds: sha(c.chunkEnds), chunkTimesUs: sha(c.chunkTimesUs), chunkPorts: sha(c.chunkPorts) }
    );
  };

  it('an intact .sscap: the capture readCapture makes, its columns in shared memory', async () => {
    const loaded = await load('intact.sscap', bytes);
    expect(loaded.capture?.bytes.buffer).toBeInstanceOf(SharedArrayBuffer);
    expect(content(loaded.capture)).toEqual(content(readCapture(bytes, 'intact.sscap')));
  });

  it('a file of 64 MB: both threads take parts, and the capture is the one readCapture makes, damaged or not', async () => {
    // The records of the small file again and again (their times step back at each copy, which the
    // reader dates and reports as bad times, keeping every byte): big
    // enough that the other thread is up and takes parts before this one has read them all.
    const headerLength = parseCapture(bytes).headerLength;
    const records = bytes.subarray(headerLength);
    const copies = Math.ceil((64 << 20) / records.length);
    const big = new Uint8Array(headerLength + copies * records.length);
    big.set(bytes.subarray(0, headerLength));
    for (let k = 0; k < copies; k++) big.set(records, headerLength + k * records.length);
    const loaded = await load('big.sscap', big);
    // The other thread read the file's second half, then took parts.
    expect(loaded.bytesThere).toBe(big.length - (big.length >> 1));
    expect(loaded.partsThere).toBeGreaterThan(0);
    expect(loaded.partsThere).toBeLessThan(16);
    expect(digest(loaded.capture)).toEqual(digest(readCapture(big, 'big.sscap')));
    // A bit flipped three quarters in, in whichever thread's part: salvaged as readCapture salvages it.
    const at = Math.floor(big.length * 0.75);
    big[at] = (big[at] ?? 0) ^ 0x40;
    const damaged = await load('big-damaged.sscap', big);
    expect(damaged.partsThere).toBe(0);
    // One damaged record (the copies' times, which step back at every copy, are bad-time issues of their own).
    expect(damaged.capture?.issues.filter((i) => i.kind !== 'bad-time').length).toBe(1);
    expect(digest(damaged.capture)).toEqual(digest(readCapture(big, 'big-damaged.sscap')));
  });

  it('a damaged one is salvaged as readCapture salvages it, and a file that is no capture is refused as ever', async () => {
    const damaged = bytes.slice();
    const at = Math.floor(bytes.length * 0.75);
    damaged[at] = (damaged[at] ?? 0) ^ 0x40;
    const loaded = await load('damaged.sscap', damaged);
    expect(loaded.capture?.issues.length).toBeGreaterThan(0);
    expect(content(loaded.capture)).toEqual(content(readCapture(damaged, 'damaged.sscap')));
    const text = await load('notes.txt', new TextEncoder().encode('{"not": "a capture"}\n'));
    expect(text.error).toMatch(/not a Saleae/);
    // An empty file: nothing for either thread to read.
    const empty = await load('empty.sscap', new Uint8Array(0));
    expect(empty.error).toMatch(/empty/);
  });
});

describe('waiting for a worker thread', () => {
  it('a worker that ends without its result does not leave this thread waiting: the result is undefined', async () => {
    const dir = mkdtempSync(join(tmpdir(), 'satscope-worker-'));
    try {
      const side = pathToFileURL(resolve(import.meta.dirname, '../dist/cli/waited-worker.js')).href;
      const boom = join(dir, 'boom.mjs');
      writeFileSync(boom, `import { workerSide } from '${side}';\nworkerSide();\nthrow new Error('boom');\n`);
      const { WaitedWorker } = (await import(side)) as {
        WaitedWorker: new (url: URL, data: object) => { result: (i: number) => unknown; close: () => void };
      };
      const worker = new WaitedWorker(pathToFileURL(boom), {});
      expect(worker.result(0)).toBeUndefined();
      worker.close();
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  });
});
