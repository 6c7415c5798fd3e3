/**
 * `satscope report` on two threads (src/cli/report-threads.ts, run from the built package as
 * the command runs it): the report is byte for byte the one-thread report, its second port
 * really read by the worker thread; an .sscap read with `shared` has its columns in shared memory
 * (what the worker reads without a copy) and the same content.
 */
import { resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { diagnosedHealthReport, diagnosedReportJobs } from '../src/analysis/index.js';
import { CaptureWriter, readCapture, type Capture } from '../src/capture/index.js';
import { preset, simulate } from '../src/simulator/index.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';

const SECOND = 1_000_000;
const built = resolve(import.meta.dirname, '../dist/cli/report-threads.js');

/** Two remotes recorded as the page records them (16 ms USB chunks), as the bytes of an .sscap. */
function file(): Uint8Array {
  const ports = [
    simulate(preset('dropouts-and-damage'), 20 * SECOND),
    simulate({ ...preset('dsmx-11ms-2048-external'), damage: { truncateRate: 0.01, bitFlipRate: 0.01 } }, 20 * SECOND),
  ];
  const w = new CaptureWriter({ baudRate: 115200, source: 'test', ports: ports.map((_, i) => ({ name: `port ${i}` })) });
  const records = ports.flatMap((p, port) => usbChunks(p.bytes, p.timesUs).map((c) => ({ ...c, port })));
  records.sort((a, b) => a.timeUs - b.timeUs || a.port - b.port);
  const parts = [w.header(), ...ports.map((_, port) => w.event('port opened', 0, port))];
  for (const r of records) parts.push(w.data(r.bytes, r.timeUs, r.port));
  return concatBytes(parts);
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
