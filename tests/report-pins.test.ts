/**
 * What `satscope report --json`, `info --json` and `doctor --json` say about the real PX4
 * captures and about damaged simulator captures, pinned whole: work that makes the analysis
 * cheaper must not change one figure or finding. The pins (tests/fixtures/pin.*.json) were written
 * by vitest (`npx vitest run tests/report-pins.test.ts -u`) from the code before that work, and
 * are never edited by hand; a change of behaviour that is meant updates them in its own commit.
 */
import { existsSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { diagnosedHealthReport, doctorCapture, summarizeCapture } from '../src/analysis/index.js';
import { CaptureWriter, importSaleaeCsv, readCapture, type Capture } from '../src/capture/index.js';
import { ibusStream, preset, receiveAs, simulate, srxlV1Stream } from '../src/simulator/index.js';
import { concatBytes } from './bytes.js';
import { perByteCapture, usbChunks } from './feeds.js';

const SECOND = 1_000_000;
const px4 = resolve(import.meta.dirname, '../../shared/captures/px4');

/** Streams of several ports recorded as the page records them: 16 ms USB chunks, merged in time order. */
function recording(ports: { bytes: Uint8Array; timesUs: Float64Array }[]): Capture {
  const w = new CaptureWriter({ baudRate: 115200, source: 'test', ports: ports.map((_, i) => ({ name: `port ${i}` })) });
  const records = ports.flatMap((p, port) => usbChunks(p.bytes, p.timesUs).map((c) => ({ ...c, port })));
  records.sort((a, b) => a.timeUs - b.timeUs || a.port - b.port);
  const parts = [w.header(), ...ports.map((_, port) => w.event('port opened', 0, port))];
  for (const r of records) parts.push(w.data(r.bytes, r.timeUs, r.port));
  return readCapture(concatBytes(parts), 'pinned.sscap');
}

/** Streams one after another on one line, each shifted to start 20 ms after the last ended. */
function oneAfterAnother(streams: { bytes: Uint8Array; timesUs: Float64Array }[]): { bytes: Uint8Array; timesUs: Float64Array } {
  const times: number[] = [];
  let offset = 0;
  for (const s of streams) {
    const t0 = s.timesUs[0] ?? 0;
    for (const t of s.timesUs) times.push(offset + t - t0);
    offset = (times.at(-1) ?? 0) + 20_000;
  }
  return { bytes: concatBytes(streams.map((s) => s.bytes)), timesUs: Float64Array.from(times) };
}

const SIMULATED: [string, () => Capture][] = [
  [
    'damaged-two-ports',
    () =>
      recording([
        simulate(preset('damaged-line'), 8 * SECOND),
        simulate({ ...preset('xplus-8'), damage: { truncateRate: 0.02, bitFlipRate: 0.01 } }, 8 * SECOND),
      ]),
  ],
  ['dropouts-per-byte', () => perByteCapture(simulate(preset('dropouts-and-damage'), 3 * SECOND))],
  [
    'foreign-between-frames',
    () =>
      recording([
        oneAfterAnother([
          simulate(preset('dsmx-11ms-2048-internal'), 2 * SECOND),
          receiveAs(ibusStream({ durationUs: 1.5 * SECOND })),
          simulate(preset('fade-wrap-internal'), 2 * SECOND),
          receiveAs(srxlV1Stream({ durationUs: 4 * SECOND })),
        ]),
      ]),
  ],
];

/** JSON as the CLI prints it. */
const json = (value: unknown): string => `${JSON.stringify(value, null, 2)}\n`;

function pin(name: string, capture: Capture): void {
  it(`${name}: the report, the summary and the doctor's findings are as pinned`, async () => {
    await expect(json(diagnosedHealthReport(capture, { name }))).toMatchFileSnapshot(`fixtures/pin.${name}.report.json`);
    await expect(json(summarizeCapture(capture))).toMatchFileSnapshot(`fixtures/pin.${name}.info.json`);
    await expect(json(doctorCapture(capture))).toMatchFileSnapshot(`fixtures/pin.${name}.doctor.json`);
  });
}

describe('pinned analysis of simulated captures', () => {
  for (const [name, make] of SIMULATED) pin(name, make());
});

describe.skipIf(!existsSync(px4))('pinned analysis of the real PX4 captures', () => {
  for (const file of ['dsm_x_data.txt', 'dsm_x_dx9_data.txt', 'dsm_x_dx9_px4_binding_data.txt'])
    pin(file.replace('.txt', ''), importSaleaeCsv(new Uint8Array(readFileSync(join(px4, file)))));
});
