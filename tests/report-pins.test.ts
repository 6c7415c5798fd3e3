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
import { diagnosedHealthReport } from '../src/report/doctor-report.js';
import { doctorCapture } from '../src/report/doctor-capture.js';
import { summarizeCapture } from '../src/report/summary.js';
import { importSaleaeCsv } from '../src/capture/saleae.js';
import type { Capture } from '../src/capture/model.js';
import { ibusStream, srxlV1Stream } from '../src/simulator/protocols.js';
import { preset } from '../src/simulator/presets.js';
import { receiveAs } from '../src/simulator/line.js';
import { simulate } from '../src/simulator/simulator.js';
import { oneAfterAnother, perByteCapture, recording } from './feeds.js';

const SECOND = 1_000_000;
const px4 = resolve(import.meta.dirname, '../../shared/captures/px4');

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
  // A skipped suite's body still runs as the tests are collected: without ../shared, nothing to read.
  if (!existsSync(px4)) return;
  for (const file of ['dsm_x_data.txt', 'dsm_x_dx9_data.txt', 'dsm_x_dx9_px4_binding_data.txt'])
    pin(file.replace('.txt', ''), importSaleaeCsv(new Uint8Array(readFileSync(join(px4, file)))));
});
