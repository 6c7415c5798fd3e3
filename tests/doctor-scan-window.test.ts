/**
 * A whole capture's diagnosis (the report's doctor, asked once at the end) scans for foreign
 * packets only from where they can still count: the findings are those of a doctor that scanned
 * every byte, on captures whose foreign packets sit anywhere, and the bytes left out are most of
 * a long capture.
 */
import { describe, expect, it } from 'vitest';
import { captureSpan } from '../src/report/capture-span.js';
import { decodeCapture } from '../src/report/capture-pass.js';
import { Doctor } from '../src/report/doctor.js';
import type { DoctorFinding } from '../src/report/doctor-types.js';
// Not part of the package's surface: where the scan starts, to check it does leave bytes out.
import { firstScanned } from '../src/report/capture-pass.js';
import { CaptureWriter } from '../src/capture/writer.js';
import { readCapture } from '../src/capture/sniff.js';
import type { Capture } from '../src/capture/model.js';
import { crsfStream, ibusStream, srxl2Stream, srxlV1Stream } from '../src/simulator/protocols.js';
import { preset } from '../src/simulator/presets.js';
import { receiveAs } from '../src/simulator/line.js';
import { simulate } from '../src/simulator/simulator.js';
import { concatBytes } from './bytes.js';
import { usbChunks } from './feeds.js';

const SECOND = 1_000_000;
type Stream = { bytes: Uint8Array; timesUs: Float64Array };

/** Streams one after another on one line, each `gapUs` after the last ended. */
function oneAfterAnother(streams: Stream[], gapUs = 20_000): Stream {
  const times: number[] = [];
  let offset = 0;
  for (const s of streams) {
    const t0 = s.timesUs[0] ?? 0;
    for (const t of s.timesUs) times.push(offset + t - t0);
    offset = (times.at(-1) ?? 0) + gapUs;
  }
  return { bytes: concatBytes(streams.map((s) => s.bytes)), timesUs: Float64Array.from(times) };
}

/**
 * Streams of several ports recorded as the page records them (16 ms USB chunks, in time order),
 * with `events` on port 0 where their times put them ("port opened" at 0 when none are given).
 */
function recording(ports: Stream[], events: [string, number][] = [['port opened', 0]]): Capture {
  const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
  const records = [
    ...events.map(([text, timeUs]) => ({ timeUs, port: 0, order: 0, record: w.event(text, timeUs, 0) })),
    ...ports.flatMap((p, port) =>
      usbChunks(p.bytes, p.timesUs).map((c) => ({ timeUs: c.timeUs, port, order: 1, record: w.data(c.bytes, c.timeUs, port) })),
    ),
  ];
  records.sort((a, b) => a.timeUs - b.timeUs || a.order - b.order || a.port - b.port);
  return readCapture(concatBytes([w.header(), ...records.map((r) => r.record)]), 'scan.sscap');
}

/** Bytes that start candidates and checksummed packets' markers, densely: the scanner's worst case. */
function dense(durationUs: number, seed: number): Stream {
  const n = Math.floor(durationUs / 100);
  const bytes = new Uint8Array(n);
  let s = seed;
  for (let i = 0; i < n; i++) {
    s = (s * 1103515245 + 12345) >>> 0;
    bytes[i] = [0xa5, 0xa6, 0xc8, 0xee, 0xea, 0x20, 0x40, 0x0f, s & 0xff][s % 9] ?? 0;
  }
  return { bytes, timesUs: Float64Array.from(bytes, (_, i) => 1000 + i * 100) };
}

/** The findings at the capture's end of a doctor fed every port's decode, its scan limited or not. */
function findingsAtEnd(capture: Capture, doctorJudgedAtEnd: boolean): DoctorFinding[] {
  const span = captureSpan(capture);
  const doctor = new Doctor({ memoryUs: Infinity, originUs: span.startUs });
  const ports = [...new Set(capture.chunkPorts)].sort((a, b) => a - b);
  for (const port of ports)
    decodeCapture(capture, { port, doctor, doctorJudgedAtEnd, originUs: span.startUs, endUs: span.endUs }, () => {});
  return doctor.findings(span.endUs);
}

const spektrum = (name: string, durationUs: number): Stream => simulate({ ...preset(name), durationUs: undefined }, durationUs);

const CASES: [string, () => Capture][] = [
  // IBUS across the window's start: a packet whose first bytes came in the chunk before it counts.
  ...[4.3, 5.1, 6.7].map((s): [string, () => Capture] => [
    `IBUS for the last ${s} s, across the window's start`,
    () =>
      recording([oneAfterAnother([spektrum('dsmx-11ms-2048-internal', 5 * SECOND), receiveAs(ibusStream({ durationUs: s * SECOND }))])]),
  ]),
  [
    'IBUS in the last seconds after a satellite',
    () =>
      recording([oneAfterAnother([spektrum('dsmx-11ms-2048-internal', 20 * SECOND), receiveAs(ibusStream({ durationUs: 2.5 * SECOND }))])]),
  ],
  [
    'SRXL2 ending just before the window',
    () => recording([oneAfterAnother([receiveAs(srxl2Stream({ durationUs: 4 * SECOND })), spektrum('damaged-line', 2.2 * SECOND)])]),
  ],
  [
    'SRXL v1 then a satellite for 2.9 s',
    () =>
      recording([
        oneAfterAnother([receiveAs(srxlV1Stream({ durationUs: 5 * SECOND })), spektrum('dsmx-11ms-2048-external', 2.9 * SECOND)]),
      ]),
  ],
  ['dense candidate bytes up to the end', () => recording([oneAfterAnother([spektrum('xplus-8', 6 * SECOND), dense(4 * SECOND, 3)])])],
  [
    'CRSF and IBUS on two ports',
    () =>
      recording([
        oneAfterAnother([spektrum('dsmx-11ms-2048-internal', 8 * SECOND), crsfStream({ durationUs: 3 * SECOND })]),
        oneAfterAnother([receiveAs(ibusStream({ durationUs: 6 * SECOND })), spektrum('dsmx-11ms-2048-external', 1.5 * SECOND)]),
      ]),
  ],
  [
    'IBUS confirmed by listening at 100000 baud long before the end (a probe counts every packet)',
    () =>
      recording(
        [
          oneAfterAnother(
            [ibusStream({ durationUs: 3 * SECOND }), ibusStream({ durationUs: 3 * SECOND }), ibusStream({ durationUs: 6 * SECOND })],
            0,
          ),
        ],
        [
          ['port opened', 0],
          ['port opened at 100000 baud', 3.05 * SECOND],
          ['port opened', 6.05 * SECOND],
        ],
      ),
  ],
];

describe('the report doctor scans for foreign packets only where they can count', () => {
  for (const [name, make] of CASES) {
    it(`finds what a doctor scanning every byte finds: ${name}`, () => {
      const capture = make();
      const all = findingsAtEnd(capture, false);
      expect(findingsAtEnd(capture, true)).toEqual(all);
    });
  }

  it('names the protocol that fills the last seconds, and leaves most of a long capture unscanned', () => {
    const capture = CASES[3]![1]();
    expect(findingsAtEnd(capture, true).map((f) => f.code)).toContain('ibus');
    const end = captureSpan(capture).endUs;
    const start = firstScanned(capture, 0, (Math.floor(end / 1e6) - 2) * 1e6);
    // The scan starts a little before the line window: at least 127 bytes that start no candidate.
    expect(start.chunk).toBeGreaterThan(capture.chunkEnds.length * 0.8);
    expect(capture.chunkTimesUs[start.chunk]).toBeLessThan((Math.floor(end / 1e6) - 2) * 1e6);
  });

  it('scans a port from its first byte when no 127 bytes in a row before the window are free of candidates', () => {
    const capture = recording([oneAfterAnother([dense(20 * SECOND, 5), spektrum('dsmx-11ms-2048-internal', SECOND)])]);
    const end = captureSpan(capture).endUs;
    expect(firstScanned(capture, 0, (Math.floor(end / 1e6) - 2) * 1e6)).toEqual({ chunk: 0, offset: 0 });
  });
});
