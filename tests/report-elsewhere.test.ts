/**
 * A report whose ports were read on other threads (`readPortMessage`, structured-cloned as a
 * thread boundary clones them, then `adoptPortMessage`) is the report one thread makes, to the
 * byte: figures, episodes, series, and the doctor's findings, which read every port's state
 * together. Readings guessed wrong (another resolution than the report asks for) are not used.
 */
import { describe, expect, it } from 'vitest';
import { diagnosedHealthReport } from '../src/report/doctor-report.js';
import { Doctor } from '../src/report/doctor.js';
import { diagnosedReportJobs } from '../src/report/doctor-report.js';
import { readPortMessage, sameReading, type PortReadingMessage } from '../src/report/report-port-message.js';
import type { Capture } from '../src/capture/model.js';
import { crsfStream, ibusStream, srxlV1Stream } from '../src/simulator/protocols.js';
import { preset } from '../src/simulator/presets.js';
import { receiveAs } from '../src/simulator/line.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { oneAfterAnother, recording, type Stream } from './feeds.js';

const SECOND = 1_000_000;

/** Ports with every byte's time, as a logic analyser records them: a chunk a port. */
function perByte(ports: Stream[]): Capture {
  let end = 0;
  return {
    kind: 'saleae-csv',
    meta: {},
    timing: 'per-byte',
    bytes: concatBytes(ports.map((p) => p.bytes)),
    chunkEnds: Uint32Array.from(ports, (p) => (end += p.bytes.length)),
    chunkTimesUs: Float64Array.from(ports, (p) => p.timesUs[p.timesUs.length - 1] ?? NaN),
    chunkPorts: Uint8Array.from(ports, (_, i) => i),
    byteTimesUs: Float64Array.from(ports.flatMap((p) => [...p.timesUs])),
    events: [],
    issues: [],
  };
}

const CAPTURES: [string, () => Capture][] = [
  [
    'internal and external remote, damaged, with fades and dropouts',
    () =>
      recording([
        simulate(preset('dropouts-and-damage'), 70 * SECOND),
        simulate({ ...preset('dsmx-11ms-2048-external'), damage: { truncateRate: 0.01, bitFlipRate: 0.01 } }, 70 * SECOND),
      ]),
  ],
  [
    'three ports, foreign packets on the second',
    () =>
      recording([
        simulate(preset('fade-wrap-internal'), 6 * SECOND),
        oneAfterAnother([
          simulate(preset('xplus-8'), 2 * SECOND),
          receiveAs(ibusStream({ durationUs: 1.5 * SECOND })),
          simulate(preset('fade-wrap-external'), 2 * SECOND),
          receiveAs(srxlV1Stream({ durationUs: 1 * SECOND })),
        ]),
        simulate(preset('dsm2-22ms-1024-external'), 5 * SECOND),
      ]),
  ],
  [
    'the internal remote changes its resolution after its first bytes',
    () =>
      recording([
        oneAfterAnother([simulate(preset('dsmx-11ms-2048-internal'), 2 * SECOND), simulate(preset('dsm2-22ms-1024-internal'), 4 * SECOND)]),
        simulate(preset('dsm2-22ms-1024-external'), 6 * SECOND),
      ]),
  ],
  [
    'two ports with per-byte times, CRSF at the end of the second',
    () =>
      perByte([
        simulate(preset('dsmx-11ms-2048-internal'), 6 * SECOND),
        oneAfterAnother([simulate(preset('dsmx-11ms-2048-external'), 2 * SECOND), receiveAs(crsfStream({ durationUs: 4 * SECOND }))]),
      ]),
  ],
  [
    'two ports without timing',
    () => recording([simulate(preset('damaged-line'), 4 * SECOND), simulate(preset('xplus-8'), 4 * SECOND)], false),
  ],
];

/** JSON as the CLI prints it. */
const json = (value: unknown): string => `${JSON.stringify(value, null, 2)}\n`;

/** The report with every job's reading made "elsewhere" (cloned across a pretend thread boundary), and how many it used. */
function reportElsewhere(capture: Capture, messages: PortReadingMessage[]): { text: string; used: number } {
  let used = 0;
  const report = diagnosedHealthReport(capture, {}, (port, resolution, from) => {
    const made = messages.find((m) => sameReading(m.job, port, resolution, from));
    if (made !== undefined) used++;
    return made;
  });
  return { text: json(report), used };
}

describe('a report with ports read on other threads', () => {
  for (const [name, make] of CAPTURES) {
    it(`${name}: is the report one thread makes`, () => {
      const capture = make();
      const alone = json(diagnosedHealthReport(capture));
      const jobs = diagnosedReportJobs(capture);
      expect(jobs.length).toBeGreaterThan(0);
      const messages = jobs.map((job) => structuredClone(readPortMessage(capture, job)));
      const { text, used } = reportElsewhere(capture, messages);
      expect(text).toBe(alone);
      if (!name.startsWith('the internal remote changes')) expect(used).toBe(jobs.length);
    });
  }

  it('a reading made with another resolution than the report asks for is not used, and the report is the same', () => {
    const capture = CAPTURES[0]?.[1]() as Capture;
    const alone = json(diagnosedHealthReport(capture));
    const wrong = diagnosedReportJobs(capture).map((job) => ({ ...job, resolution: 1024 as const, from: 'internal-remote' as const }));
    const { text, used } = reportElsewhere(
      capture,
      wrong.map((job) => readPortMessage(capture, job)),
    );
    expect(used).toBe(0);
    expect(text).toBe(alone);
  });

  it('a reading made for another clock, or without the doctor, is not used, and the report is the same', () => {
    const capture = CAPTURES[0]?.[1]() as Capture;
    const alone = json(diagnosedHealthReport(capture));
    const jobs = diagnosedReportJobs(capture);
    const later = jobs.map((job) => readPortMessage(capture, { ...job, endUs: job.endUs + 1_000_000 }));
    const undiagnosed = jobs.map((job) => readPortMessage(capture, { ...job, doctor: null }));
    for (const made of [later, undiagnosed]) {
      const { text, used } = reportElsewhere(capture, made);
      expect(used).toBe(jobs.length); // asked for and handed over, but not adopted
      expect(text).toBe(alone);
    }
  });

  it("a doctor's port state restored into another doctor checkpoints the same again", () => {
    // Chunk times, and per-byte times (the doctor's burst clock runs only on those).
    for (const job of [1, 3].flatMap((i) => {
      const capture = CAPTURES[i]?.[1]() as Capture;
      return diagnosedReportJobs(capture).map((j) => ({ ...j, capture }));
    })) {
      const { capture } = job;
      const message = readPortMessage(capture, job);
      const cp = message.doctor;
      expect(cp).not.toBeNull();
      if (cp === null) continue;
      const other = new Doctor(job.doctor ?? {});
      const again = structuredClone(cp);
      // The restore must copy: a later change in the doctor leaves the checkpoint as it was.
      other.restorePort(job.port, again, { decoder: undefined as never, link: undefined as never });
      expect(other.portCheckpoint(job.port)).toEqual(cp);
      expect(again).toEqual(cp);
    }
  });
});
