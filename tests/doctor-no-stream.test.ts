/**
 * A file or a line without a Spektrum stream is never called healthy: the doctor (its CLI, the
 * report's diagnosis, a live or replayed session) says plainly that no satellite stream was
 * found, and what the bytes look like instead, naming the RC protocols it knows from their bytes
 * alone (as a logic analyser's export or a raw dump holds them): SBUS, CRSF, FPort, GHST, IBUS,
 * SRXL v1 and SRXL2.
 */
import { mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';
import { Doctor } from '../src/report/doctor.js';
import { diagnosedHealthReport } from '../src/report/doctor-report.js';
import { doctorCapture, type DoctorReport } from '../src/report/doctor-capture.js';
import { importRaw } from '../src/capture/raw.js';
import type { Capture } from '../src/capture/model.js';
import { LinkMonitor } from '../src/decoder/link.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { doctorCommand } from '../src/cli/doctor.js';
import { crsfStream, ibusStream, sbusStream, srxl2Stream, srxlV1Stream } from '../src/simulator/protocols.js';
import { PRESET_NAMES, preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import type { Transmission } from '../src/simulator/line.js';
import { perByteCapture, recording } from './feeds.js';

const SECOND = 1_000_000;

function seeded(seed: number): () => number {
  let x = seed;
  return () => (x = (x * 1_103_515_245 + 12_345) % 2_147_483_648) / 2_147_483_648;
}

function randomBytes(n: number, seed: number): Uint8Array {
  const random = seeded(seed);
  return Uint8Array.from({ length: n }, () => Math.floor(random() * 256));
}

/** A PNG's signature and header chunk, then compressed-looking bytes. */
function png(n: number, seed: number): Uint8Array {
  const b = randomBytes(n, seed);
  b.set([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0, 13, 0x49, 0x48, 0x44, 0x52]);
  return b;
}

const codes = (r: DoctorReport): string[] => r.findings.map((f) => f.code);

/** CRC-8/DVB-S2 (poly 0xD5), as CRSF and GHST use it. */
function crc8(bytes: ArrayLike<number>): number {
  let crc = 0;
  for (let i = 0; i < bytes.length; i++) {
    crc ^= bytes[i]!;
    for (let k = 0; k < 8; k++) crc = crc & 0x80 ? ((crc << 1) ^ 0xd5) & 0xff : (crc << 1) & 0xff;
  }
  return crc;
}

/** Packets every `periodUs`, bytes back to back at `byteUs` within a packet. */
function packets(make: (i: number) => number[], count: number, periodUs: number, byteUs: number): Transmission {
  const bytes: number[] = [];
  const times: number[] = [];
  for (let i = 0; i < count; i++) {
    const p = make(i);
    p.forEach((b, j) => {
      bytes.push(b);
      times.push(1000 + i * periodUs + j * byteUs);
    });
  }
  return {
    format: { baudRate: 115_200, dataBits: 8, parity: 'none', stopBits: 1, inverted: false },
    bytes: Uint8Array.from(bytes),
    timesUs: Float64Array.from(times),
  };
}

/**
 * FrSky FPort control frames: 0x7E, length 0x19, type 0x00, 16 channels of 11 bits in 22 bytes,
 * flags, RSSI, checksum (0xFF less the folded sum), 0x7E; 0x7E and 0x7D in between escaped.
 */
function fportStream(count: number, seed: number): Transmission {
  const random = seeded(seed);
  return packets(
    () => {
      const body = [0x19, 0x00];
      for (let k = 0; k < 22; k++) body.push(Math.floor(random() * 256));
      body.push(0x00, 100);
      let sum = 0;
      for (const b of body) sum += b;
      while (sum > 0xff) sum = (sum & 0xff) + (sum >> 8);
      body.push(0xff - sum);
      const out = [0x7e];
      for (const b of body) out.push(...(b === 0x7e || b === 0x7d ? [0x7d, b ^ 0x20] : [b]));
      out.push(0x7e);
      return out;
    },
    count,
    9_000,
    8.7,
  );
}

/** ImmersionRC Ghost channel packets: address 0x82 (the flight controller), length 12, type 0x10, 10 bytes, CRC-8 over type and payload. */
function ghstStream(count: number, seed: number): Transmission {
  const random = seeded(seed);
  return packets(
    () => {
      const body = [0x10];
      for (let k = 0; k < 10; k++) body.push(Math.floor(random() * 256));
      return [0x82, body.length + 1, ...body, crc8(body)];
    },
    count,
    4_000,
    23.8,
  );
}

const FOREIGN: { code: string; stream: () => Transmission }[] = [
  { code: 'sbus', stream: () => sbusStream({ durationUs: 2 * SECOND }) },
  { code: 'crsf', stream: () => crsfStream({ durationUs: 2 * SECOND }) },
  { code: 'fport', stream: () => fportStream(200, 3) },
  { code: 'ghst', stream: () => ghstStream(400, 4) },
  { code: 'ibus', stream: () => ibusStream({ durationUs: 2 * SECOND }) },
  { code: 'srxl-v1', stream: () => srxlV1Stream({ durationUs: 2 * SECOND }) },
  { code: 'srxl2', stream: () => srxl2Stream({ durationUs: 2 * SECOND }) },
];

describe('a file without a Spektrum stream', () => {
  const files: { name: string; capture: () => Capture; look: RegExp }[] = [
    { name: 'a PNG image', capture: () => importRaw(png(40_000, 1)), look: /begin like a PNG image/ },
    { name: 'a short PNG image', capture: () => importRaw(png(900, 2)), look: /begin like a PNG image/ },
    { name: 'all 0x00', capture: () => importRaw(new Uint8Array(50_000)), look: /Every byte is 0x00/ },
    { name: 'a few 0x00', capture: () => importRaw(new Uint8Array(40)), look: /Every byte is 0x00/ },
    {
      name: 'all 0x00 from a logic analyser (per-byte times across seconds)',
      capture: () =>
        perByteCapture({ bytes: new Uint8Array(40_000), timesUs: Float64Array.from({ length: 40_000 }, (_, i) => 400_000 + i * 86.8) }),
      look: /Every byte is 0x00/,
    },
    {
      name: 'text',
      capture: () =>
        importRaw(new TextEncoder().encode('$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n'.repeat(300))),
      look: /printable text/,
    },
    ...[1, 2, 3, 4, 5, 6, 7, 8].map((seed) => ({
      name: `random bytes (seed ${seed})`,
      capture: () => importRaw(randomBytes(5_000 + seed * 7_000, seed)),
      look: /in no known RC packet \(Spektrum, SRXL, SRXL2, IBUS, SBUS, CRSF, FPort, GHST\)/,
    })),
  ];
  for (const f of files)
    it(`says plainly that ${f.name} holds no Spektrum stream, as a problem, and what the bytes look like`, () => {
      const capture = f.capture();
      const report = doctorCapture(capture);
      const finding = report.findings.find((x) => x.code === 'no-satellite');
      expect(finding, JSON.stringify(codes(report))).toBeDefined();
      expect(finding!.severity).toBe('problem');
      expect(finding!.title).toMatch(/no Spektrum satellite stream/);
      expect(finding!.evidence.map((e) => e.text).join(' ')).toMatch(f.look);
      // No time, rate or window an untimed file does not have.
      if (capture.timing === 'none') expect(finding!.evidence.map((e) => e.text).join(' ')).not.toMatch(/last \d+ s|a minute/);
      // The report's diagnosis says the same.
      expect(diagnosedHealthReport(capture).diagnosis!.map((d) => d.title)).toContain(finding!.title);
    });

  it('makes satscope doctor exit 1 and print it', () => {
    const dir = mkdtempSync(join(tmpdir(), 'satscope-no-stream-'));
    try {
      writeFileSync(join(dir, 'picture.png'), png(30_000, 9));
      let out = '';
      const code = doctorCommand([join(dir, 'picture.png')], { out: (t) => (out += t), err: () => {} });
      expect(code).toBe(1);
      expect(out).toMatch(/PROBLEM {2}Port 0: no Spektrum satellite stream/);
      expect(out).not.toMatch(/No findings/);
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  });

  it('is said of a live or replayed port once a satellite has had time to lock, or at the end of its stream', () => {
    const doctor = new Doctor();
    const decoder = new SpektrumDecoder();
    const link = new LinkMonitor();
    doctor.attach(0, { decoder, link });
    doctor.open(0, 0);
    const bytes = png(2_000, 3);
    doctor.bytes(0, bytes, 100_000);
    decoder.push(bytes, 100_000);
    expect(decoder.next()).toBeUndefined();
    expect(doctor.findings(500_000).map((f) => f.code)).not.toContain('no-satellite');
    expect(doctor.findings(1_700_000).map((f) => f.code)).toContain('no-satellite');
    const short = new Doctor();
    short.attach(0, { decoder: new SpektrumDecoder(), link: new LinkMonitor() });
    short.bytes(0, new Uint8Array(100), 10_000);
    expect(short.findings(20_000).map((f) => f.code)).not.toContain('no-satellite');
    short.ended(0);
    expect(short.findings(20_000).map((f) => f.code)).toContain('no-satellite');
  });
  it('names what a live port carried once its bytes have stopped, past the line window', () => {
    const doctor = new Doctor();
    const decoder = new SpektrumDecoder();
    doctor.attach(0, { decoder, link: new LinkMonitor() });
    doctor.open(0, 0);
    const ibus = ibusStream({ durationUs: 2 * SECOND });
    // Byte by byte at its own time, as a live port delivers it.
    for (let i = 0; i < ibus.bytes.length; i += 32) doctor.bytes(0, ibus.bytes.subarray(i, i + 32), ibus.timesUs[i]!);
    expect(doctor.findings(2 * SECOND).map((f) => f.code)).toContain('ibus');
    const later = doctor.findings(100 * SECOND); // silent far past the 64 s the bins keep
    expect(later.map((f) => f.code)).not.toContain('ibus');
    const none = later.find((f) => f.code === 'no-satellite');
    expect(none?.evidence.map((e) => e.text).join(' ')).toMatch(/They were \d+ FlySky IBUS packets, and the line has been silent since/);
  });
});

describe("another protocol's bytes in a raw file or a logic analyser's export", () => {
  for (const p of FOREIGN) {
    it(`are named ${p.code}, as a problem, in a raw file and with per-byte times`, () => {
      const t = p.stream();
      for (const capture of [importRaw(t.bytes), perByteCapture(t)]) {
        const report = doctorCapture(capture);
        const finding = report.findings.find((f) => f.code === p.code);
        expect(finding, `${capture.kind}: ${JSON.stringify(codes(report))}`).toBeDefined();
        expect(finding!.severity).toBe('problem');
        expect(codes(report)).not.toContain('unknown-stream');
        expect(codes(report)).not.toContain('fc-settings');
      }
    });
  }

  it('are not made up from random bytes: no protocol named in 40 random files', () => {
    const named = [];
    for (let seed = 100; seed < 140; seed++) {
      const report = doctorCapture(importRaw(randomBytes(40_000, seed)));
      named.push(...codes(report).filter((c) => FOREIGN.some((p) => p.code === c)));
    }
    expect(named).toEqual([]);
  });
});

describe('a resolution forced that fits no frame', () => {
  it('is the setting to change, never "no satellite" and wiring advice', () => {
    for (const [name, forced] of [
      ['dsm2-22ms-1024-internal', 2048],
      ['dsmx-11ms-2048-internal', 1024],
    ] as const) {
      const s = simulate({ ...preset(name), seed: 5 }, 2 * SECOND);
      const found = doctorCapture(importRaw(s.bytes), { resolution: forced }).findings;
      expect(
        found.map((f) => f.code),
        name,
      ).toEqual(['forced-option']);
      expect(found[0]?.evidence[0]?.text).toMatch(new RegExp(`they are ${forced === 2048 ? 1024 : 2048}-resolution frames`));
    }
  });
});

describe('a Spektrum stream', () => {
  it('is never said to be missing: every preset, raw, per-byte and recorded', () => {
    const said: string[] = [];
    for (const name of PRESET_NAMES) {
      const s = simulate({ ...preset(name), seed: 5 }, 2 * SECOND);
      for (const capture of [importRaw(s.bytes), perByteCapture(s), recording([s])])
        if (codes(doctorCapture(capture)).includes('no-satellite')) said.push(`${name} ${capture.kind}`);
    }
    expect(said).toEqual([]);
  });
});
