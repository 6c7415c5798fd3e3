/**
 * `satscope doctor` (`doctorCapture`, every port replayed side by side) and the diagnosis in
 * `satscope report` (the doctor listening to the report's decode, a port at a time) say the same
 * about the same capture: the same findings, as sure, with the same evidence. In particular an
 * external remote is read with the internal remote's resolution on both (§8), so a finding that
 * rests on its resolution is as certain in one as in the other.
 */
import { describe, expect, it } from 'vitest';
import { diagnosedHealthReport } from '../src/report/doctor-report.js';
import { doctorCapture } from '../src/report/doctor-capture.js';
import type { Capture } from '../src/capture/model.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { recording } from './feeds.js';

const SECOND = 1_000_000;

const CAPTURES: [string, () => Capture][] = [
  [
    'DSMX 11 ms 2048, internal and external',
    () => recording([simulate(preset('dsmx-11ms-2048-internal'), 8 * SECOND), simulate(preset('dsmx-11ms-2048-external'), 8 * SECOND)]),
  ],
  [
    'DSM2 22 ms 1024, internal and external',
    () => recording([simulate(preset('dsm2-22ms-1024-internal'), 8 * SECOND), simulate(preset('dsm2-22ms-1024-external'), 8 * SECOND)]),
  ],
  [
    'external first, then the internal remote',
    () => recording([simulate(preset('fade-wrap-external'), 8 * SECOND), simulate(preset('dropouts-and-damage'), 8 * SECOND)]),
  ],
];

/** What both say of a finding (the report keeps these of the doctor's). */
const said = (f: { severity: string; confidence: string; title: string; evidence: readonly { text: string }[] }) => ({
  severity: f.severity,
  confidence: f.confidence,
  title: f.title,
  evidence: f.evidence.map((e) => e.text),
});

describe('satscope doctor and the report agree', () => {
  for (const [name, make] of CAPTURES) {
    it(name, () => {
      const capture = make();
      const report = (diagnosedHealthReport(capture).diagnosis ?? []).map(said);
      const doctor = doctorCapture(capture).findings.map(said);
      expect(report.length).toBeGreaterThan(0);
      expect(doctor).toEqual(report);
    });
  }
});
