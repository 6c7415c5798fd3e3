/**
 * The report decodes each port once and feeds the link monitor, the series, its own figures and
 * the doctor from that one decode (src/report/capture-pass.ts). Here the same captures are
 * read the long way, in separate passes built from the library's parts: every port decoded on
 * its own, §8's resolution key applied as written (every port read on its own, then every port
 * that is not an internal remote read again with the key, kept if it reads at least as many
 * frames), and a doctor replayed over the whole capture in arrival order with decoders of its
 * own. Frames, missed frames, holds, failsafes, episodes and the doctor's findings must match.
 */
import { readdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';
import type { LinkEpisode } from '../src/decoder/episode.js';
import { LinkMonitor } from '../src/decoder/link.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import type { Resolution } from '../src/decoder/spec.js';
import { captureChunks, type Capture } from '../src/capture/model.js';
import { capturePorts } from '../src/capture/facts.js';
import { encodeCapture, type CaptureRecordInput } from '../src/capture/writer.js';
import { readCapture } from '../src/capture/sniff.js';
import { Doctor } from '../src/report/doctor.js';
import { captureSpan } from '../src/report/capture-span.js';
import { diagnosedHealthReport } from '../src/report/doctor-report.js';
import { doctorCapture } from '../src/report/doctor-capture.js';
import { doctorEvent } from '../src/report/doctor-events.js';
import { healthReport } from '../src/report/report.js';
import { resolutionKey } from '../src/report/resolution-key.js';
import { summarizeCapture } from '../src/report/summary.js';
import { timingJitterUs } from '../src/report/capture-pass.js';
import { SLICE_BYTES } from '../src/report/capture-pass.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { perByteCapture, usbChunks } from './feeds.js';

/** One port decoded alone with `resolution`: its decoder and its link monitor, finished at the capture's end. */
function decodeAlone(capture: Capture, port: number, resolution: 'auto' | Resolution, from: 'user' | 'internal-remote') {
  const decoder = new SpektrumDecoder({ resolution, resolutionFrom: from });
  const link = new LinkMonitor({ jitterUs: timingJitterUs(capture.timing) });
  for (const chunk of captureChunks(capture, port)) {
    decoder.push(chunk.bytes, chunk.time);
    for (let f = decoder.next(); f; f = decoder.next()) link.frame(f);
  }
  decoder.end();
  for (let f = decoder.next(); f; f = decoder.next()) link.frame(f);
  link.finish(captureSpan(capture).endUs);
  return { decoder, link };
}

/** §8 as written: the resolution each port is read with. */
function resolutions(capture: Capture): Map<number, { resolution: 'auto' | Resolution; from: 'user' | 'internal-remote' }> {
  const ports = capturePorts(capture);
  const own = ports.map((p) => decodeAlone(capture, p, 'auto', 'user'));
  const key = ports.length > 1 ? resolutionKey(own.map((d) => d.decoder.format)) : undefined;
  const out = new Map<number, { resolution: 'auto' | Resolution; from: 'user' | 'internal-remote' }>();
  ports.forEach((p, i) => {
    const mine = own[i]!;
    out.set(p, { resolution: 'auto', from: 'user' });
    if (key === undefined || mine.decoder.format.remote === 'internal') return;
    const keyed = decodeAlone(capture, p, key, 'internal-remote');
    if (keyed.decoder.stats.frames >= mine.decoder.stats.frames) out.set(p, { resolution: key, from: 'internal-remote' });
  });
  return out;
}

const episodeText = (e: LinkEpisode) => ({ kind: e.kind, startUs: e.startUs, endUs: e.endUs, lastFrameUs: e.lastFrameUs });

/** Separate passes: each port alone for the link, and a doctor replayed over the capture in arrival order. */
function separatePasses(capture: Capture) {
  const chosen = resolutions(capture);
  const remotes = capturePorts(capture).map((port) => {
    const { resolution, from } = chosen.get(port)!;
    const { decoder, link } = decodeAlone(capture, port, resolution, from);
    return {
      port,
      frames: decoder.stats.frames,
      missed: link.stats.missedFrames,
      holds: link.stats.holds,
      failsafes: link.stats.failsafes,
      episodes: link.episodes.map(episodeText),
      resolution: decoder.format.resolution,
    };
  });
  const span = captureSpan(capture);
  const doctor = new Doctor({
    timing: capture.timing === 'per-byte' ? 'per-byte' : 'per-chunk',
    memoryUs: Infinity,
    originUs: span.startUs,
  });
  const ports = [...new Set([...capturePorts(capture), ...capture.events.map((e) => e.port)])];
  const sources = new Map(
    ports.map((port) => {
      const { resolution, from } = chosen.get(port) ?? { resolution: 'auto', from: 'user' };
      const source = {
        decoder: new SpektrumDecoder({ resolution, resolutionFrom: from }),
        link: new LinkMonitor({ jitterUs: timingJitterUs(capture.timing) }),
      };
      const name = capture.meta.ports?.[port]?.name;
      doctor.attach(port, { ...source, label: typeof name === 'string' && name !== '' ? name : `Port ${port}` });
      return [port, source];
    }),
  );
  const feed = (port: number, bytes: Uint8Array, time: number | Float64Array | undefined) => {
    const { decoder, link } = sources.get(port)!;
    doctor.bytes(port, bytes, time);
    decoder.push(bytes, time);
    for (let f = decoder.next(); f; f = decoder.next()) {
      link.frame(f);
      doctor.frame(port, f);
    }
  };
  const events = [...capture.events].sort((a, b) => a.chunkIndex - b.chunkIndex);
  let e = 0;
  for (const chunk of captureChunks(capture)) {
    for (; e < events.length && events[e]!.chunkIndex <= chunk.index; e++)
      doctorEvent(doctor, events[e]!.port, events[e]!.text, events[e]!.timeUs);
    if (chunk.byteTimesUs === undefined) feed(chunk.port, chunk.bytes, chunk.time);
    else
      for (let s = 0; s < chunk.bytes.length; s += SLICE_BYTES)
        feed(chunk.port, chunk.bytes.subarray(s, s + SLICE_BYTES), chunk.byteTimesUs.subarray(s, s + SLICE_BYTES));
  }
  for (; e < events.length; e++) doctorEvent(doctor, events[e]!.port, events[e]!.text, events[e]!.timeUs);
  for (const [port, { decoder, link }] of sources) {
    decoder.end();
    for (let f = decoder.next(); f; f = decoder.next()) {
      link.frame(f);
      doctor.frame(port, f);
    }
    link.finish(span.endUs);
  }
  const findings = doctor.findings(span.endUs).map((f) => ({
    severity: f.severity,
    confidence: f.confidence,
    title: f.title,
    evidence: f.evidence.map((x) => ({ text: x.text })),
    todo: f.todo,
    settings: f.settings,
  }));
  return { remotes, findings };
}

/** µs relative to the report's time zero, rounded to 0.1 µs as the report gives them. */
const relative = (origin: number) => (x: number) => Math.round((x - origin) * 10) / 10;

/** The one pass: what `diagnosedHealthReport` says, in the separate passes' terms (episode times relative to time zero). */
function onePass(capture: Capture) {
  const report = diagnosedHealthReport(capture);
  const remotes = report.remotes.map((r) => {
    // The report lists every hold (each failsafe began as one) and the failsafes apart.
    const episodes = [
      ...r.holds.episodes.map((h) => ({ ...h, kind: 'hold' as const })),
      ...r.failsafes.map((f) => ({ ...f, kind: 'failsafe' as const })),
    ]
      .map((x) => ({ kind: x.kind, startUs: x.startUs, endUs: x.ongoing ? null : x.endUs, lastFrameUs: x.lastFrameUs }))
      .sort((a, b) => a.startUs - b.startUs || (a.kind === 'hold' ? -1 : 1));
    return {
      port: r.port,
      frames: r.frames,
      missed: r.missedFrames,
      holds: r.holds.count,
      failsafes: r.failsafes.length,
      episodes,
      resolution: r.resolution.value,
    };
  });
  return { remotes, findings: report.diagnosis };
}

function expectSame(capture: Capture): void {
  const separate = separatePasses(capture);
  const one = onePass(capture);
  const rel = relative(captureSpan(capture).startUs);
  expect(one.remotes).toEqual(
    separate.remotes.map((r) => ({
      ...r,
      episodes: r.episodes.map((e) => ({
        ...e,
        startUs: rel(e.startUs),
        endUs: e.endUs === null ? null : rel(e.endUs),
        lastFrameUs: rel(e.lastFrameUs),
      })),
    })),
  );
  expect(one.findings).toEqual(separate.findings);
  // `satscope info` reads a port with the same decode: the same figures at the resolution the report chose.
  const chosen = resolutions(capture);
  for (const r of separate.remotes) {
    const { resolution, from } = chosen.get(r.port)!;
    const s = summarizeCapture(capture, { port: r.port, resolution, resolutionFrom: from });
    expect({ frames: s.decoder.frames, missed: s.link.missedFrames, holds: s.link.holds, failsafes: s.link.failsafes }).toEqual({
      frames: r.frames,
      missed: r.missed,
      holds: r.holds,
      failsafes: r.failsafes,
    });
    expect(s.episodes.map(episodeText)).toEqual(r.episodes);
  }
}

function usbCapture(streams: { bytes: Uint8Array; timesUs: Float64Array }[], names?: string[]): Capture {
  const records: CaptureRecordInput[] = [];
  streams.forEach((s, port) => {
    for (const c of usbChunks(s.bytes, s.timesUs)) records.push({ type: 'data', bytes: c.bytes, timeUs: c.timeUs, port });
  });
  records.sort((a, b) => (a.timeUs ?? 0) - (b.timeUs ?? 0) || (a.port ?? 0) - (b.port ?? 0));
  return readCapture(
    encodeCapture({ source: 'test', ...(names ? { ports: names.map((name) => ({ name })) } : {}) }, records),
    'test.sscap',
  );
}

const fixtures = join(import.meta.dirname, 'fixtures');
const fixtureNames = readdirSync(fixtures)
  .filter((f) => f.endsWith('.times.f64'))
  .map((f) => f.replace('.times.f64', ''));
const fixture = (name: string) => {
  const bytes = new Uint8Array(readFileSync(join(fixtures, `${name}.bin`)));
  const raw = readFileSync(join(fixtures, `${name}.times.f64`));
  const timesUs = new Float64Array(raw.buffer.slice(raw.byteOffset, raw.byteOffset + raw.byteLength));
  return { bytes, timesUs };
};

describe('the one-pass report agrees with separate passes', () => {
  it.each(fixtureNames)('on fixture %s, per-byte and in USB chunks', (name) => {
    const f = fixture(name);
    expectSame(perByteCapture(f));
    expectSame(usbCapture([f]));
  });

  it.each([
    ['an internal and an external remote', ['dsmx-11ms-2048-internal', 'dsmx-11ms-2048-external']],
    ['the internal remote on the second port', ['dsmx-11ms-2048-external', 'dsmx-11ms-2048-internal']],
    ['a 1024 system of three, internal last', ['dsm2-22ms-1024-external', 'dsm2-22ms-1024-external', 'dsm2-22ms-1024-internal']],
    ['remotes of two systems', ['dsm2-22ms-1024-internal', 'dsmx-11ms-2048-external']],
    ['dropouts and damage beside a clean remote', ['dropouts-and-damage', 'dsmx-11ms-2048-external']],
    ['two external remotes and no internal one', ['dsmx-11ms-2048-external', 'dsmx-11ms-2048-external']],
  ])('on simulated streams: %s', (_, names) => {
    const streams = names.map((n, i) => simulate({ ...preset(n), seed: 7 + i }, 3_000_000));
    expectSame(usbCapture(streams, names));
  });

  it('with recorded events: a port that opened and never sent, and a line error on a port with data', () => {
    const a = simulate(preset('dsmx-11ms-2048-internal'), 2_500_000);
    const records: CaptureRecordInput[] = usbChunks(a.bytes, a.timesUs).map((c) => ({
      type: 'data',
      bytes: c.bytes,
      timeUs: c.timeUs,
      port: 0,
    }));
    const t = records[5]!.timeUs!;
    records.splice(
      5,
      0,
      { type: 'event', text: 'port opened', timeUs: t, port: 2 },
      { type: 'event', text: 'line error: FramingError', timeUs: t, port: 0 },
    );
    const capture = readCapture(encodeCapture({ source: 'test' }, records), 'events.sscap');
    expectSame(capture);
    expect(onePass(capture).findings?.map((f) => f.title)).toContain('Port 2: nothing arrives');
  });

  it('without timing, the diagnosis is the doctor replaying the capture on a clock of its own', () => {
    const raw = readCapture(simulate(preset('dropouts-and-damage'), 3_000_000).bytes, 'dump.bin');
    expect(raw.timing).toBe('none');
    expect(diagnosedHealthReport(raw).diagnosis?.map((f) => f.title)).toEqual(doctorCapture(raw).findings.map((f) => f.title));
    expect(healthReport(raw).remotes[0]!.frames).toBe(decodeAlone(raw, 0, 'auto', 'user').decoder.stats.frames);
  });
});

describe('the frame period statistics', () => {
  /** The ordinary intervals the link monitor saw, every one, sorted: what the report's figures are taken over. */
  function fromEveryInterval(capture: Capture) {
    const decoder = new SpektrumDecoder();
    const link = new LinkMonitor({ jitterUs: timingJitterUs(capture.timing) });
    const intervals: number[] = [];
    const take = () => {
      for (let f = decoder.next(); f; f = decoder.next()) {
        link.frame(f);
        if (Number.isFinite(link.lastIntervalUs)) intervals.push(link.lastIntervalUs);
      }
    };
    for (const chunk of captureChunks(capture)) {
      decoder.push(chunk.bytes, chunk.time);
      take();
    }
    decoder.end();
    take();
    const iv = Float64Array.from(intervals).sort();
    let sum = 0;
    for (const v of iv) sum += v;
    const mean = sum / iv.length;
    let sq = 0;
    for (const v of iv) sq += (v - mean) * (v - mean);
    const r1 = (x: number) => Math.round(x * 10) / 10;
    const rank = (p: number) => iv[Math.min(iv.length - 1, Math.max(0, Math.ceil((p / 100) * iv.length) - 1))]!;
    return {
      intervals: iv.length,
      meanUs: r1(mean),
      stdDevUs: r1(Math.sqrt(sq / iv.length)),
      minUs: r1(iv[0]!),
      maxUs: r1(iv[iv.length - 1]!),
      p50Us: r1(rank(50)),
      p95Us: r1(rank(95)),
      p99Us: r1(rank(99)),
      distinct: new Set(iv).size,
    };
  }

  it('are those of every interval sorted, whether the intervals repeat (USB chunks) or never do (a logic analyser)', () => {
    const sim = simulate(preset('dsmx-11ms-2048-internal'), 70_000_000);
    // Each frame moved by its own fraction of 400 µs: no two intervals alike.
    const jittered = Float64Array.from(sim.timesUs, (t, i) => t + ((Math.floor(i / 16) * 0.6180339887) % 1) * 400);
    for (const capture of [usbCapture([sim]), perByteCapture({ bytes: sim.bytes, timesUs: jittered })]) {
      const { distinct, ...expected } = fromEveryInterval(capture);
      const period = healthReport(capture).remotes[0]!.framePeriod!;
      expect({ ...period, basis: undefined }).toEqual({ ...expected, basis: undefined });
      if (capture.timing === 'per-byte') expect(distinct).toBeGreaterThan(4096);
      else expect(distinct).toBeLessThan(4096);
    }
  });
});
