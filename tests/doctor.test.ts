/**
 * The doctor: each finding from a simulated receiver or a foreign protocol put through the line
 * model, fed as a USB adapter would deliver it (chunks of ~16 ms stamped at their end) or with
 * per-byte times, and the finding's appearance and clearing.
 */
import { existsSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import { diagnosedHealthReport } from '../src/report/doctor-report.js';
import { Doctor } from '../src/report/doctor.js';
import { doctorCapture } from '../src/report/doctor-capture.js';
import { doctorEvent } from '../src/report/doctor-events.js';
import { reportHtml } from '../src/report/report-html.js';
import type { DoctorFinding, DoctorOptions } from '../src/report/doctor-types.js';
import { LinkMonitor } from '../src/decoder/link.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { USB_CHUNK_JITTER_US } from '../src/decoder/spec.js';
import { CaptureWriter } from '../src/capture/writer.js';
import { importSaleaeCsv } from '../src/capture/saleae.js';
import { readCapture } from '../src/capture/sniff.js';
import { crsfStream, ibusStream, sbusStream, spektrumTransmission, srxl2Stream, srxlV1Stream } from '../src/simulator/protocols.js';
import { noiseSignal, receiveAs, uartReceive, type UartResult } from '../src/simulator/line.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import type { Scenario } from '../src/simulator/scenario.js';
import { perByteCapture, recording } from './feeds.js';
import { concatBytes } from './bytes.js';

const SECOND = 1_000_000;

/** A doctor with one decoder and link monitor per port, fed like the worker would. */
class Session {
  readonly doctor: Doctor;
  readonly ports = new Map<number, { decoder: SpektrumDecoder; link: LinkMonitor }>();
  constructor(readonly options: DoctorOptions & { chunkUs?: number } = {}) {
    this.doctor = new Doctor(options);
  }

  port(port: number, label?: string): { decoder: SpektrumDecoder; link: LinkMonitor } {
    let p = this.ports.get(port);
    if (p === undefined) {
      p = {
        decoder: new SpektrumDecoder(),
        link: new LinkMonitor({ jitterUs: this.options.timing === 'per-byte' ? 0 : USB_CHUNK_JITTER_US }),
      };
      this.ports.set(port, p);
      this.doctor.attach(port, { ...p, ...(label !== undefined ? { label } : {}) });
    }
    return p;
  }

  /** Feeds what a UART delivered, bytes and errors in time order, in chunks of `chunkUs` (default 16 ms). */
  feed(port: number, r: { bytes: Uint8Array; timesUs: Float64Array; errors?: UartResult['errors'] }): void {
    const p = this.port(port);
    const perByte = this.options.timing === 'per-byte';
    const chunkUs = this.options.chunkUs ?? 16_000;
    const errors = r.errors ?? [];
    let e = 0;
    let start = 0;
    const n = r.bytes.length;
    const flush = (end: number, deadline: number): void => {
      while (e < errors.length && errors[e]!.offset <= end && (errors[e]!.offset < end || errors[e]!.timeUs < deadline)) {
        this.doctor.lineError(port, errors[e]!.kind, perByte ? errors[e]!.timeUs : deadline);
        e++;
      }
      if (end > start) {
        const bytes = r.bytes.subarray(start, end);
        const time = perByte ? r.timesUs.subarray(start, end) : deadline;
        this.doctor.bytes(port, bytes, time);
        p.decoder.push(bytes, time);
        for (let f = p.decoder.next(); f; f = p.decoder.next()) {
          p.link.frame(f);
          this.doctor.frame(port, f);
        }
      }
      start = end;
    };
    let deadline = n > 0 ? Math.floor(r.timesUs[0]! / chunkUs) * chunkUs + chunkUs : 0;
    for (let i = 0; i < n; i++) {
      if (r.timesUs[i]! >= deadline) {
        flush(i, deadline);
        deadline = Math.floor(r.timesUs[i]! / chunkUs) * chunkUs + chunkUs;
      }
    }
    flush(n, deadline);
    while (e < errors.length) {
      this.doctor.lineError(port, errors[e]!.kind, errors[e]!.timeUs);
      e++;
    }
  }

  findings(nowUs: number): DoctorFinding[] {
    for (const p of this.ports.values()) p.link.update(nowUs);
    return this.doctor.findings(nowUs);
  }
}

const codes = (fs: DoctorFinding[]): string[] => fs.map((f) => f.code);
const find = (fs: DoctorFinding[], code: string): DoctorFinding => {
  const f = fs.find((x) => x.code === code);
  if (f === undefined) throw new Error(`no ${code} finding among ${codes(fs).join(', ')}`);
  return f;
};
const settingLines = (f: DoctorFinding, stack: string): string[] => f.settings.find((s) => s.stack === stack)?.lines ?? [];

/** A scenario's bytes as a satellite sends them (per-byte times), optionally shifted in time. */
function satellite(s: Scenario, durationUs: number, startUs = 1000): { bytes: Uint8Array; timesUs: Float64Array } {
  return simulate({ ...s, timing: { ...s.timing, startUs } }, durationUs);
}

describe('nothing arrives', () => {
  it('appears one second after the port opened with nothing on it, certain after three, and clears on the first byte', () => {
    const s = new Session();
    s.port(0);
    s.doctor.open(0, 10 * SECOND);
    expect(codes(s.findings(10.5 * SECOND))).not.toContain('nothing-arrives');
    const early = find(s.findings(11.2 * SECOND), 'nothing-arrives');
    expect(early.confidence).toBe('likely');
    expect(early.severity).toBe('problem');
    expect(early.sinceUs).toBe(11 * SECOND);
    const late = find(s.findings(13.5 * SECOND), 'nothing-arrives');
    expect(late.confidence).toBe('certain');
    expect(late.sinceUs).toBe(11 * SECOND);
    // Ordered by likelihood, each with the LED state that tells it apart.
    expect(late.todo[0]).toMatch(/Transmitter off.*LED off/);
    expect(late.todo[1]).toMatch(/bind mode.*blinking fast/);
    expect(late.todo.join(' ')).toMatch(/grey.*RX/);
    expect(late.todo.join(' ')).toMatch(/GND/);
    expect(late.todo.join(' ')).toMatch(/3\.3 V on orange/);
    s.doctor.bytes(0, Uint8Array.of(0), 13.6 * SECOND);
    expect(codes(s.findings(13.7 * SECOND))).not.toContain('nothing-arrives');
  });

  it('says nothing about a port that was never opened or was closed', () => {
    const s = new Session();
    s.port(0);
    expect(s.findings(5 * SECOND)).toEqual([]);
    s.doctor.open(0, 0);
    s.doctor.close(0);
    expect(codes(s.findings(5 * SECOND))).not.toContain('nothing-arrives');
  });
});

describe('bytes that are not a satellite stream', () => {
  it('names FlySky IBUS at 115200 from its checksums, with the flight-controller setting', () => {
    const s = new Session();
    s.feed(0, receiveAs(ibusStream({ durationUs: 2 * SECOND })));
    const f = find(s.findings(2 * SECOND), 'ibus');
    expect(f.confidence).toBe('certain');
    expect(f.title).toMatch(/IBUS, not a Spektrum satellite/);
    expect(settingLines(f, 'Betaflight')).toContain('set serialrx_provider = IBUS');
    expect(settingLines(f, 'iNav')).toContain('set serialrx_provider = IBUS');
    expect(codes(s.findings(2 * SECOND))).not.toContain('fc-settings');
  });

  it('names SRXL2 (an SPM4651T) from its 0xA6 packets and CRCs', () => {
    const s = new Session();
    s.feed(0, receiveAs(srxl2Stream({ durationUs: 2 * SECOND })));
    const f = find(s.findings(2 * SECOND), 'srxl2');
    expect(f.evidence[0]!.text).toMatch(/0xA6 0xCD/);
    expect(settingLines(f, 'Betaflight')).toContain('set serialrx_provider = SRXL2');
    expect(settingLines(f, 'iNav')).toContain('set serialrx_provider = SRXL2');
    expect(f.todo.join(' ')).toMatch(/half-duplex/);
  });

  it('names SRXL v1 from its 0xA5 packets, and says iNav has no provider for it', () => {
    const s = new Session();
    s.feed(0, receiveAs(srxlV1Stream({ durationUs: 2 * SECOND })));
    const f = find(s.findings(2 * SECOND), 'srxl-v1');
    expect(settingLines(f, 'Betaflight')).toContain('set serialrx_provider = SRXL');
    expect(settingLines(f, 'iNav')).toEqual([]);
    expect(f.settings.find((x) => x.stack === 'iNav')!.note).toMatch(/no Spektrum SRXL \(v1\) provider/);
  });

  it('calls an inverted satellite line inverted, not SBUS, with the frame period from the breaks', () => {
    const s = new Session();
    const sim = simulate(preset('dsmx-11ms-2048-internal'), 3 * SECOND);
    s.feed(0, receiveAs(spektrumTransmission(sim, true)));
    const fs = s.findings(3 * SECOND);
    const f = find(fs, 'inverted-line');
    expect(f.confidence).toBe('likely');
    expect(f.evidence[0]!.text).toMatch(/one every 11\.\d ms/);
    expect(codes(fs)).not.toContain('sbus');
    expect(f.todo.join(' ')).toMatch(/serialrx_inverted = ON/);
  });

  it('recognises SBUS (100000 8E2, inverted) from breaks and the bytes between them, and offers to listen at its speed', () => {
    const s = new Session();
    s.feed(0, receiveAs(sbusStream({ durationUs: 3 * SECOND })));
    const fs = s.findings(3 * SECOND);
    const f = find(fs, 'sbus');
    expect(f.confidence).toBe('likely');
    expect(f.evidence[0]!.text).toMatch(/every 1[3-5]\.\d ms/);
    expect(f.confirm).toMatchObject({ baudRate: 100_000, parity: 'even', stopBits: 2 });
    expect(settingLines(f, 'Betaflight')).toContain('set serialrx_provider = SBUS');
    expect(codes(fs)).not.toContain('inverted-line');
  });

  it('recognises CRSF at 420000 from the bursts when bytes carry their own times', () => {
    const s = new Session({ timing: 'per-byte' });
    s.feed(0, receiveAs(crsfStream({ durationUs: 3 * SECOND })));
    const f = find(s.findings(3 * SECOND), 'crsf');
    expect(f.confidence).toBe('likely');
    expect(f.evidence[0]!.text).toMatch(/250 Hz/);
    expect(settingLines(f, 'Betaflight')).toContain('set serialrx_provider = CRSF');
    expect(f.confirm).toMatchObject({ baudRate: 420_000 });
  });

  it('with chunk times, calls CRSF "another speed", and a probe at 420000 confirms it as CRSF', () => {
    const s = new Session();
    s.doctor.open(0, 0);
    s.feed(0, receiveAs(crsfStream({ durationUs: 2 * SECOND, startUs: 1000 })));
    const before = s.findings(2 * SECOND);
    expect(find(before, 'wrong-speed').confirm).toMatchObject({ baudRate: 420_000, parity: 'none', stopBits: 1 });
    expect(codes(before)).not.toContain('crsf');
    // The worker listens at 420000 for half a second, then returns to 115200.
    s.doctor.open(0, 2 * SECOND, { baudRate: 420_000 });
    s.feed(0, receiveAs(crsfStream({ durationUs: 0.5 * SECOND, startUs: 2 * SECOND + 1000 }), { baudRate: 420_000 }));
    expect(codes(s.findings(2.5 * SECOND)).filter((c) => c !== 'nothing-arrives')).toEqual([]);
    s.doctor.open(0, 2.5 * SECOND);
    s.feed(0, receiveAs(crsfStream({ durationUs: 2 * SECOND, startUs: 2.5 * SECOND + 1000 })));
    const after = s.findings(4.5 * SECOND);
    const f = find(after, 'crsf');
    expect(f.confidence).toBe('certain');
    expect(f.evidence.some((e) => /Confirmed: \d+ valid CRSF .* packets when listening at 420000 baud/.test(e.text))).toBe(true);
    expect(codes(after)).not.toContain('wrong-speed');
  });

  it('says plainly that clean bytes in no known protocol (here GPS sentences) are no satellite stream, and that they are text, after giving a decoder time to lock', () => {
    const s = new Session();
    const sentence = new TextEncoder().encode('$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n');
    const n = 30;
    const bytes = new Uint8Array(sentence.length * n);
    const timesUs = new Float64Array(bytes.length);
    for (let k = 0; k < n; k++) {
      bytes.set(sentence, k * sentence.length);
      for (let j = 0; j < sentence.length; j++) timesUs[k * sentence.length + j] = 1000 + k * 100_000 + j * 86.8;
    }
    s.feed(0, { bytes, timesUs });
    expect(codes(s.findings(1 * SECOND))).not.toContain('no-satellite');
    const f = find(s.findings(3 * SECOND), 'no-satellite');
    expect(f.severity).toBe('problem');
    expect(f.title).toMatch(/no Spektrum satellite stream/);
    expect(f.evidence[1]!.text).toMatch(/100 % of them are printable text: a GPS/);
    expect(codes(s.findings(3 * SECOND))).not.toContain('unknown-stream');
  });

  it('reports bytes lost to buffer overruns, and forgets them after the window', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 2 * SECOND));
    s.doctor.lineError(0, 'BufferOverrunError', 1.5 * SECOND);
    expect(find(s.findings(2 * SECOND), 'overrun').evidence[0]!.text).toMatch(/1 buffer overrun/);
    expect(codes(s.findings(5 * SECOND))).not.toContain('overrun');
  });

  it('calls a line of random levels noise and asks for a ground', () => {
    const s = new Session();
    s.feed(0, uartReceive(noiseSignal({ durationUs: 3 * SECOND })));
    const f = find(s.findings(3 * SECOND), 'noise');
    expect(f.todo[0]).toMatch(/GND/);
  });

  it('never takes a satellite for something else, from its first bytes on, even on a damaged line', () => {
    for (const name of [
      'dsmx-11ms-2048-internal',
      'dsm2-22ms-1024-external',
      'clone-zero-header',
      'damaged-line',
      'dropouts-and-damage',
      'rssi-spm4649t',
    ]) {
      const s = new Session();
      s.doctor.open(0, 0);
      const sim = satellite(preset(name), 3 * SECOND, 20_000);
      for (let t = 50_000; t <= 3 * SECOND; t += 50_000) {
        let end = 0;
        while (end < sim.bytes.length && sim.timesUs[end]! < t) end++;
        const fed = t - 50_000;
        let start = 0;
        while (start < sim.bytes.length && sim.timesUs[start]! < fed) start++;
        s.feed(0, { bytes: sim.bytes.subarray(start, end), timesUs: sim.timesUs.subarray(start, end) });
        const wrong = s
          .findings(t)
          .filter((f) =>
            [
              'inverted-line',
              'srxl-v1',
              'srxl2',
              'ibus',
              'sbus',
              'crsf',
              'wrong-speed',
              'noise',
              'unknown-stream',
              'nothing-arrives',
            ].includes(f.code),
          );
        expect(wrong.map((f) => `${name} at ${t}: ${f.code}`)).toEqual([]);
      }
    }
  });

  it("clears a line finding once the satellite's own frames have filled the window", () => {
    const s = new Session();
    s.feed(0, receiveAs(ibusStream({ durationUs: 2 * SECOND })));
    expect(codes(s.findings(2 * SECOND))).toContain('ibus');
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 4 * SECOND, 2 * SECOND));
    const fs = s.findings(6 * SECOND);
    expect(codes(fs)).not.toContain('ibus');
    expect(codes(fs)).toContain('fc-settings');
  });
});

describe('a satellite stream the flight controller will read wrong', () => {
  it('gives SPEK2048 and the DSMX 11 ms bind numbers for a DSMX 11 ms internal remote, and nothing alarming', () => {
    const s = new Session();
    // A fade now and then: byte 0 moves, which proves it internal (without one, `00 B2` reads as
    // well as an external count of 178: tests/doctor-ambiguous.test.ts).
    s.feed(0, satellite({ ...preset('dsmx-11ms-2048-internal'), fades: { lossRate: 0, randomRate: 0.01 } }, 3 * SECOND));
    const fs = s.findings(3 * SECOND);
    const f = find(fs, 'fc-settings');
    expect(f.confidence).toBe('certain');
    expect(settingLines(f, 'Betaflight')).toEqual(['set serialrx_provider = SPEK2048', 'save']);
    expect(settingLines(f, 'iNav')).toEqual(['set receiver_type = SERIAL', 'set serialrx_provider = SPEK2048', 'save']);
    expect(f.settings.find((x) => x.stack === 'Betaflight')!.note).toMatch(/DSMX 11 ms 2048 internal \(9 pulses\).*spektrum_sat_bind = 9/);
    expect(f.settings.find((x) => x.stack === 'ArduPilot')!.note).toMatch(/settles on 11-bit/);
    expect(fs.filter((x) => x.severity !== 'info')).toEqual([]);
  });

  it('asks for SPEK1024 on a DSM2 22 ms stream and to bind again in DSMX 11 ms', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsm2-22ms-1024-internal'), 3 * SECOND));
    const fs = s.findings(3 * SECOND);
    expect(settingLines(find(fs, 'fc-settings'), 'Betaflight')).toContain('set serialrx_provider = SPEK1024');
    const bind = find(fs, 'bind-mode');
    expect(bind.severity).toBe('warning');
    expect(bind.todo[0]).toMatch(/spektrum_sat_bind = 9/);
  });

  it('names the bind pulses of the mode it is in now (DSM2 22 ms internal: 3)', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsm2-22ms-1024-internal'), 3 * SECOND));
    expect(find(s.findings(3 * SECOND), 'fc-settings').settings.find((x) => x.stack === 'Betaflight')!.note).toMatch(
      /bound now as DSM2 22 ms 1024 internal \(3 pulses\)/,
    );
  });

  it('suggests 11 ms for a DSMX 22 ms stream, as information: SPEK2048 already reads it right', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsmx-22ms-2048-internal'), 3 * SECOND));
    const fs = s.findings(3 * SECOND);
    const bind = find(fs, 'bind-mode');
    expect(bind.severity).toBe('info');
    expect(bind.evidence[0]!.text).toMatch(/A frame every 22\.0 ms/);
    expect(find(fs, 'fc-settings').settings.find((x) => x.stack === 'Betaflight')!.note).toMatch(/DSMX 22 ms 2048 internal \(7 pulses\)/);
  });

  it('gives the external bind number (10) for an external remote', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsm2-22ms-1024-external'), 3 * SECOND));
    expect(find(s.findings(3 * SECOND), 'bind-mode').todo[0]).toMatch(/external: 10 pulses.*spektrum_sat_bind = 10/);
  });

  it('warns when the system byte says 2048 but the data is 1024, and asks for SPEK1024', () => {
    const s = new Session();
    s.feed(0, satellite(preset('lying-b2-with-1024-data'), 3 * SECOND));
    const fs = s.findings(3 * SECOND);
    const f = find(fs, 'system-byte-contradicted');
    expect(f.todo[0]).toMatch(/SPEK1024/);
    expect(f.todo[1]).toMatch(/ArduPilot and PX4 ignore the system byte/);
    expect(settingLines(find(fs, 'fc-settings'), 'Betaflight')).toContain('set serialrx_provider = SPEK1024');
  });

  it('warns that X-Plus channels are dropped or mixed by the flight stacks', () => {
    const s = new Session();
    s.feed(0, satellite(preset('xplus-dx9'), 3 * SECOND));
    const f = find(s.findings(3 * SECOND), 'xplus-channels');
    expect(f.title).toMatch(/X\+1, X\+2, X\+3, X\+4/);
    expect(f.todo[0]).toMatch(/Betaflight and iNav read channel IDs 0–11 only/);
  });

  it('notes VTX control frames', () => {
    const s = new Session();
    s.feed(0, satellite(preset('vtx'), 3 * SECOND));
    expect(find(s.findings(3 * SECOND), 'vtx-frames').evidence[0]!.text).toMatch(/bytes 12–15/);
  });

  it("predicts that ArduPilot's guess never settles on 1024 frames of 10 channels, whose 11-bit reading also looks right", () => {
    const s = new Session();
    s.feed(0, satellite({ ...preset('dsm2-22ms-1024-internal'), channels: 10 }, 3 * SECOND));
    const f = find(s.findings(3 * SECOND), 'autopilot-detection');
    expect(f.evidence[0]!.text).toMatch(/as 11-bit: 0–4; as 10-bit: 0–9/);
    expect(f.evidence[1]!.text).toMatch(/never settles/);
  });

  it('predicts that ArduPilot settles on 11-bit for 2048 streams of 10 and 12 channels, with X-Plus and VTX', () => {
    for (const name of ['dsmx-11ms-2048-internal', 'empty-slots-12ch', 'xplus-dx9', 'vtx', 'dsmx-11ms-2048-external']) {
      const s = new Session();
      s.feed(0, satellite(preset(name), 3 * SECOND));
      const fs = s.findings(3 * SECOND);
      expect(codes(fs)).not.toContain('autopilot-detection');
      expect(find(fs, 'fc-settings').settings.find((x) => x.stack === 'ArduPilot')!.note).toMatch(/settles on 11-bit/);
    }
  });
});

describe('a weak link', () => {
  it('reports failsafes with their times, as a problem, and gives the spec §5 advice', () => {
    const s = new Session({ timing: 'per-byte' });
    s.feed(0, satellite(preset('dropouts-failsafe'), 3.2 * SECOND));
    const fs = s.findings(3.2 * SECOND);
    const f = find(fs, 'weak-link');
    expect(fs[0]).toBe(f); // worst first
    expect(f.severity).toBe('problem');
    expect(f.evidence[0]!.text).toMatch(/Failsafe: no frame for over 1 s after 0:01\.\d, back at 0:02\.5/);
    expect(f.todo.join(' ')).toMatch(/90°/);
    expect(f.todo.join(' ')).toMatch(/carbon/);
  });

  it('reports a high fade rate as a warning, and clears once the memory has passed with a clean link', () => {
    const s = new Session({ memoryUs: 5 * SECOND });
    s.feed(0, satellite({ ...preset('dsmx-11ms-2048-internal'), fades: { lossRate: 0.03 } }, 6 * SECOND));
    const f = find(s.findings(6 * SECOND), 'weak-link');
    expect(f.severity).toBe('warning');
    expect(f.evidence.some((e) => /Fade rate \d+ a minute/.test(e.text))).toBe(true);
    s.feed(0, satellite({ ...preset('dsmx-11ms-2048-internal'), fades: { lossRate: 0, randomRate: 0 }, seed: 9 }, 12 * SECOND, 6 * SECOND));
    expect(codes(s.findings(18 * SECOND))).not.toContain('weak-link');
  });

  it('with two remotes, names the one that fades most', () => {
    const s = new Session();
    s.port(0, 'A');
    s.port(1, 'B');
    s.feed(0, satellite({ ...preset('dsmx-11ms-2048-internal'), fades: { lossRate: 0.002, randomRate: 0 } }, 10 * SECOND));
    s.feed(1, satellite({ ...preset('dsmx-11ms-2048-external'), fades: { start: 0, lossRate: 0.05 } }, 10 * SECOND));
    const f = find(s.findings(10 * SECOND), 'weakest-remote');
    expect(f.title).toBe('B fades most');
    expect(f.ports).toEqual([1]);
  });

  it('compares an SPM4649T (RSSI, no fades) with a fade-counting remote by lost frames only', () => {
    const s = new Session({ timing: 'per-byte' });
    s.port(0, 'A');
    s.port(1, 'B');
    // A: an RSSI receiver that loses frames now and then; B: counts many fades but loses nothing.
    const drops = [1, 2, 3, 4, 5, 6, 7, 8].map((at) => ({ atUs: at * SECOND, durationUs: 0.1 * SECOND }));
    s.feed(0, satellite({ ...preset('rssi-spm4649t'), fades: { lossRate: 0, randomRate: 0 }, dropouts: drops }, 10 * SECOND));
    s.feed(1, satellite({ ...preset('dsmx-11ms-2048-external'), fades: { start: 0, lossRate: 0, randomRate: 0.05 } }, 10 * SECOND));
    const f = find(s.findings(10 * SECOND), 'weakest-remote');
    expect(f.title).toBe('A fades most');
    expect(f.evidence.at(-1)!.text).toMatch(/frames that did not arrive.*SPM4649T/);
  });

  it('with two remotes that lose frames in the same seconds, says they fade together', () => {
    const s = new Session();
    const dropouts = [1, 2.5, 4, 5.5, 7].map((at) => ({ atUs: at * SECOND, durationUs: 0.1 * SECOND }));
    s.feed(0, satellite({ ...preset('dsmx-11ms-2048-internal'), dropouts, fades: { lossRate: 0, randomRate: 0 } }, 8 * SECOND));
    s.feed(1, satellite({ ...preset('dsmx-11ms-2048-external'), dropouts, fades: { lossRate: 0, randomRate: 0 } }, 8 * SECOND));
    const f = find(s.findings(8 * SECOND), 'fades-together');
    expect(f.ports).toEqual([0, 1]);
    expect(f.todo[0]).toMatch(/common to all remotes/);
  });

  it('does not say remotes fade together when one also fades often on its own', () => {
    const s = new Session();
    const shared = [1, 3, 5].map((at) => ({ atUs: at * SECOND, durationUs: 0.1 * SECOND }));
    const alone = [0.5, 1.6, 2.2, 2.6, 3.6, 4.2, 4.6, 5.6, 6.2, 6.6, 7.2].map((at) => ({ atUs: at * SECOND, durationUs: 0.1 * SECOND }));
    s.feed(
      0,
      satellite(
        { ...preset('dsmx-11ms-2048-internal'), dropouts: [...shared, ...alone], fades: { lossRate: 0, randomRate: 0 } },
        8 * SECOND,
      ),
    );
    s.feed(1, satellite({ ...preset('dsmx-11ms-2048-external'), dropouts: shared, fades: { lossRate: 0, randomRate: 0 } }, 8 * SECOND));
    expect(codes(s.findings(8 * SECOND))).not.toContain('fades-together');
    expect(find(s.findings(8 * SECOND), 'weakest-remote').ports).toEqual([0]);
  });

  it('does not say remotes fade together when they fade at different times', () => {
    const s = new Session();
    s.feed(
      0,
      satellite(
        {
          ...preset('dsmx-11ms-2048-internal'),
          dropouts: [1, 3, 5].map((at) => ({ atUs: at * SECOND, durationUs: 0.1 * SECOND })),
          fades: { lossRate: 0, randomRate: 0 },
        },
        8 * SECOND,
      ),
    );
    s.feed(
      1,
      satellite(
        {
          ...preset('dsmx-11ms-2048-external'),
          dropouts: [2, 4, 6].map((at) => ({ atUs: at * SECOND, durationUs: 0.1 * SECOND })),
          fades: { lossRate: 0, randomRate: 0 },
        },
        8 * SECOND,
      ),
    );
    expect(codes(s.findings(8 * SECOND))).not.toContain('fades-together');
  });
});

describe('a wrong setup', () => {
  it('finds two internal remotes (spec §7.3: exactly one)', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 2 * SECOND));
    s.feed(1, satellite({ ...preset('dsmx-11ms-2048-internal'), seed: 5 }, 2 * SECOND));
    const f = find(s.findings(2 * SECOND), 'internal-count');
    expect(f.title).toMatch(/2 internal/);
    expect(f.todo[1]).toMatch(/one internal.*9 pulses.*external \(10 pulses\)/);
  });

  it('finds no internal remote among several external ones', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsmx-11ms-2048-external'), 2 * SECOND));
    s.feed(1, satellite({ ...preset('dsmx-11ms-2048-external'), seed: 6 }, 2 * SECOND));
    expect(find(s.findings(2 * SECOND), 'internal-count').title).toMatch(/No internal/);
  });

  it('finds remotes that disagree on resolution', () => {
    const s = new Session();
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 2 * SECOND));
    s.feed(1, satellite(preset('dsm2-22ms-1024-external'), 2 * SECOND));
    const f = find(s.findings(2 * SECOND), 'resolution-mismatch');
    expect(f.evidence.map((e) => e.text).join(' ')).toMatch(/2048 resolution.*1024 resolution/);
  });

  it('finds a rebind mid-session, with its time, and the new settings', () => {
    const s = new Session({ timing: 'per-byte' });
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 2 * SECOND));
    s.feed(0, satellite({ ...preset('dsm2-22ms-1024-internal'), fades: { start: 0 } }, 2 * SECOND, 2.4 * SECOND));
    const fs = s.findings(4.4 * SECOND);
    const f = find(fs, 'rebind');
    expect(f.evidence[0]!.text).toMatch(/From DSMX 11 ms 2048 internal to DSM2 22 ms 1024 internal at 0:02\.4/);
    expect(f.sinceUs).toBeCloseTo(2.4 * SECOND, -3);
    expect(f.todo[1]).toMatch(/SPEK1024/);
  });

  it('finds a receiver restart from a fade counter that starts again from 0 after a gap', () => {
    const s = new Session({ timing: 'per-byte' });
    s.feed(0, satellite({ ...preset('dsmx-11ms-2048-internal'), fades: { start: 40, lossRate: 0.01 } }, 2 * SECOND));
    s.feed(0, satellite({ ...preset('dsmx-11ms-2048-internal'), fades: { start: 0, lossRate: 0 }, seed: 3 }, 2 * SECOND, 2.3 * SECOND));
    const fs = s.findings(4.3 * SECOND);
    expect(find(fs, 'receiver-restart').evidence[0]!.text).toMatch(/went from \d+ back to 0 after 3\d\d ms without frames/);
    expect(codes(fs)).not.toContain('rebind');
  });

  it('does not take a fade counter that wraps during a dropout for a restart', () => {
    const s = new Session({ timing: 'per-byte' });
    // 120 + ~164 missed frames: the 8-bit counter wraps to ~28 while nothing is sent.
    s.feed(
      0,
      satellite(
        {
          ...preset('dsmx-11ms-2048-internal'),
          fades: { start: 120, lossRate: 0, randomRate: 0 },
          dropouts: [{ atUs: 1 * SECOND, durationUs: 1.8 * SECOND }],
        },
        4 * SECOND,
      ),
    );
    const last = s.ports.get(0)!.decoder;
    expect(last.format.headerMode).toBe('fades');
    expect(codes(s.findings(4 * SECOND))).not.toContain('receiver-restart');
  });

  it("explains an SPM4649T's RSSI byte", () => {
    const s = new Session();
    s.feed(0, satellite(preset('rssi-spm4649t'), 3 * SECOND));
    const f = find(s.findings(3 * SECOND), 'rssi-receiver');
    expect(f.evidence[0]!.text).toMatch(/lowest -\d+ dBm/);
  });
});

describe('doctorCapture', () => {
  it('finds "nothing arrives" in a recording of a port that opened and stayed silent', () => {
    const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
    const file = concatBytes([w.header(), w.event('port opened', 0, 0), w.event('device lost', 4 * SECOND, 0)]);
    const r = doctorCapture(readCapture(file, 'silent.sscap'));
    expect(r.timeline.map((e) => e.code)).toContain('nothing-arrives');
    const entry = r.timeline.find((e) => e.code === 'nothing-arrives')!;
    expect(entry.fromUs).toBe(1 * SECOND);
  });

  it('finds IBUS in a recording and keeps when each finding held', () => {
    const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
    const ibus = receiveAs(ibusStream({ durationUs: 3 * SECOND }));
    const parts = [w.header(), w.event('port opened', 0, 0)];
    for (let i = 0; i < ibus.bytes.length; i += 64)
      parts.push(w.data(ibus.bytes.subarray(i, i + 64), ibus.timesUs[Math.min(i + 63, ibus.bytes.length - 1)]!));
    const r = doctorCapture(readCapture(concatBytes(parts), 'ibus.sscap'));
    expect(r.findings.map((f) => f.code)).toContain('ibus');
    expect(r.timeline.find((e) => e.code === 'ibus')).toMatchObject({ toUs: null });
    expect(JSON.parse(JSON.stringify(r))).toEqual(r);
  });

  it('reads line errors recorded as events', () => {
    const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
    const sbus = receiveAs(sbusStream({ durationUs: 3 * SECOND }));
    const parts = [w.header(), w.event('port opened', 0, 0)];
    let e = 0;
    for (let i = 0; i < sbus.bytes.length; i++) {
      for (; e < sbus.errors.length && sbus.errors[e]!.offset <= i; e++)
        parts.push(w.event(`line error: ${sbus.errors[e]!.kind}`, sbus.errors[e]!.timeUs, 0));
      parts.push(w.data(sbus.bytes.subarray(i, i + 1), sbus.timesUs[i]!));
    }
    const r = doctorCapture(readCapture(concatBytes(parts), 'sbus.sscap'));
    expect(r.findings.map((f) => f.code)).toContain('sbus');
  });
});

describe('what the worker and the report take from the doctor', () => {
  it('reads recorded events the way doctorCapture does: opened (at a speed), lost, line errors', () => {
    const s = new Session();
    s.port(0);
    doctorEvent(s.doctor, 0, 'port opened', 0);
    expect(codes(s.findings(1.5 * SECOND))).toContain('nothing-arrives');
    doctorEvent(s.doctor, 0, 'device lost', 1.6 * SECOND);
    expect(codes(s.findings(2 * SECOND))).not.toContain('nothing-arrives');
    doctorEvent(s.doctor, 0, 'device reconnected', 3 * SECOND);
    doctorEvent(s.doctor, 0, 'line error: FramingError', 3.1 * SECOND);
    doctorEvent(s.doctor, 0, 'a note that is no event', 3.2 * SECOND);
    expect(codes(s.findings(4.5 * SECOND))).not.toContain('nothing-arrives');
  });

  it('names an adapter that went away, until its data came back, as the live worker tells it; a checkpoint keeps it', () => {
    const s = new Session();
    s.port(0, 'A');
    s.doctor.open(0, 0);
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 2 * SECOND));
    expect(codes(s.findings(2 * SECOND))).not.toContain('adapter-away');
    s.doctor.close(0, 2.1 * SECOND);
    // Still away: counted to now.
    const away = find(s.findings(3 * SECOND), 'adapter-away');
    expect(away?.title).toBe('A: the USB adapter went away 1 time');
    expect(away?.evidence[0]?.text).toMatch(/^The adapter was lost 1 time \(900 ms in all, the first at 0:02\.1\)/);
    s.doctor.open(0, 3.5 * SECOND);
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 1 * SECOND, 3.6 * SECOND));
    s.doctor.close(0, 5 * SECOND);
    s.doctor.close(0, 5.2 * SECOND);
    s.doctor.open(0, 5.9 * SECOND);
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 0.5 * SECOND, 6 * SECOND));
    const twice = find(s.findings(7 * SECOND), 'adapter-away');
    expect(twice?.evidence[0]?.text).toMatch(/^The adapter was lost 2 times \(2\.5 s in all, the first at 0:02\.1\)/);
    expect(twice?.sinceUs).toBe(2.1 * SECOND);
    const other = new Doctor();
    other.restorePort(0, s.doctor.portCheckpoint(0)!, { ...s.port(0), label: 'A' });
    expect(find(other.findings(7 * SECOND), 'adapter-away')?.evidence).toEqual(twice?.evidence);
    // Untimed, nothing to count.
    const raw = new Doctor({ timing: 'none' });
    raw.close(0, Number.NaN);
    expect(raw.findings(SECOND)).toEqual([]);
  });

  it('forgets a detached port, so a remote given its number later starts clean', () => {
    const s = new Session();
    s.port(0, 'A');
    s.doctor.open(0, 0);
    expect(codes(s.findings(2 * SECOND))).toEqual(['nothing-arrives']);
    s.doctor.detach(0);
    expect(s.findings(3 * SECOND)).toEqual([]);
    s.ports.delete(0);
    s.feed(0, satellite(preset('dsmx-11ms-2048-internal'), 2 * SECOND, 3 * SECOND));
    expect(codes(s.findings(5 * SECOND))).toEqual(['fc-settings']);
  });

  it("puts its findings into the health report, and the report's HTML shows them with the lines to paste", () => {
    const w = new CaptureWriter({ baudRate: 115200, source: 'test' });
    const ibus = receiveAs(ibusStream({ durationUs: 2 * SECOND }));
    const parts = [w.header(), w.event('port opened', 0, 0)];
    for (let i = 0; i < ibus.bytes.length; i += 64)
      parts.push(w.data(ibus.bytes.subarray(i, i + 64), ibus.timesUs[Math.min(i + 63, ibus.bytes.length - 1)]!));
    const capture = readCapture(concatBytes(parts), 'ibus.sscap');
    const report = diagnosedHealthReport(capture, { name: 'ibus.sscap' });
    expect(report.diagnosis?.map((f) => f.title)).toEqual(doctorCapture(capture).findings.map((f) => f.title));
    expect(report.diagnosis?.[0]).toMatchObject({ severity: 'problem', title: expect.stringMatching(/FlySky IBUS/) });
    expect(JSON.parse(JSON.stringify(report))).toEqual(report);
    const html = reportHtml(report);
    expect(html).toContain('<h2>Diagnosis</h2>');
    expect(html).toContain('set serialrx_provider = IBUS');
    // Without the doctor's findings the report has no such section.
    expect(reportHtml({ ...report, diagnosis: undefined })).not.toContain('<h2>Diagnosis</h2>');
  });
});

const px4 = resolve(import.meta.dirname, '../../shared/captures/px4');
describe.skipIf(!existsSync(px4))('the real PX4 captures', () => {
  it('find only what is true of them: the settings, and X-Plus on the DX9 ones; no weak link, nothing foreign', () => {
    const expected: Record<string, string[]> = {
      'dsm_x_data.txt': ['fc-settings'],
      'dsm_x_dx9_data.txt': ['xplus-channels', 'fc-settings'],
      'dsm_x_dx9_px4_binding_data.txt': ['xplus-channels', 'fc-settings'],
    };
    for (const [name, want] of Object.entries(expected)) {
      const capture = importSaleaeCsv(new Uint8Array(readFileSync(join(px4, name))));
      const r = doctorCapture(capture);
      expect([name, ...r.timeline.map((e) => e.code)]).toEqual([name, ...want]);
      // The same bytes as a USB adapter delivers them: 16 ms chunks stamped at their end.
      const s = new Session();
      s.feed(0, { bytes: capture.bytes, timesUs: capture.byteTimesUs! });
      const end = capture.byteTimesUs![capture.byteTimesUs!.length - 1]!;
      expect([name, ...s.findings(end).map((f) => f.code)]).toEqual([name, ...want]);
    }
  });
});

describe('gaps the receiver did not lose', () => {
  it('on a logic analyser are no USB adapter: damage or a cut capture, said so', () => {
    // 200 ms cut out of a clean per-byte capture whose counter stands still.
    const s = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 4, fades: { start: 40, lossRate: 0, randomRate: 0 } }, 5e6);
    const keep: number[] = [];
    s.timesUs.forEach((t, i) => {
      if (t < 2e6 || t >= 2.2e6) keep.push(i);
    });
    const bytes = Uint8Array.from(keep, (i) => s.bytes[i] as number);
    const timesUs = Float64Array.from(keep, (i) => s.timesUs[i] as number);
    const wire = doctorCapture(perByteCapture({ bytes, timesUs })).findings.find((f) => f.code === 'delivery-stall');
    expect(wire?.title).toMatch(/gaps in the frames read that the link did not lose/);
    expect(JSON.stringify(wire)).not.toMatch(/USB|adapter or the computer/);
    // Through an adapter the same gap is one it may have held back.
    const adapter = doctorCapture(recording([{ bytes, timesUs }])).findings.find((f) => f.code === 'delivery-stall');
    expect(adapter?.title).toMatch(/reached the computer late/);
  });
});
