/**
 * One truth: the same bytes tell the same story on every surface. For each real capture in
 * ../shared/captures and simulator scenarios with dropouts and line damage, these agree on
 * frames, missed frames, holds, failsafes, episode times, resolution and where it came from:
 *
 * - `summarizeCapture` (what `satscope info` prints) and `decodeCapture`;
 * - `healthReport` (`satscope report` and the page's report);
 * - the worker's replay source driving the worker's engine, on a simulated clock, at 1×, 4× and
 *   as fast as possible, and after seeking;
 * - the live engine fed the bytes in 16 ms USB chunks at the capture's pace (per-byte times
 *   hidden, as a browser sees them), within the batching for episode times.
 */
import { existsSync, readdirSync, readFileSync, statSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import type { FormatInfo, LinkEpisode, LinkStats } from '../src/decoder/index.js';
import { encodeCapture, importRaw, readCapture, type Capture, type CaptureRecordInput } from '../src/capture/index.js';
import { captureSpan, healthReport, summarizeCapture, timingJitterUs } from '../src/analysis/index.js';
import { preset, simulate } from '../src/simulator/index.js';
import { Engine } from '../src/worker/engine.js';
import { ReplaySource } from '../src/worker/sources/replay.js';
import { usbChunks, perByteCapture } from './feeds.js';
import { SimulatedClock } from './worker-fakes.js';

const CAPTURES = resolve(import.meta.dirname, '../../shared/captures');
const present = existsSync(CAPTURES);
if (!present) console.warn(`skipping the real captures in the agreement test: ${CAPTURES} is not here`);

/** Every capture file under the shared folder (not its README). */
function captureFiles(dir: string): string[] {
  const out: string[] = [];
  for (const name of readdirSync(dir).sort()) {
    const path = join(dir, name);
    if (statSync(path).isDirectory()) out.push(...captureFiles(path));
    else if (!/\.md$/i.test(name)) out.push(path);
  }
  return out;
}

function sscap(chunks: { bytes: Uint8Array; timeUs: number }[]): Capture {
  const records: CaptureRecordInput[] = chunks.map((c) => ({ type: 'data', bytes: c.bytes, timeUs: c.timeUs, port: 0 }));
  return readCapture(encodeCapture({ baudRate: 115200, source: 'test' }, records), 'test.sscap');
}

/** What every surface is compared on. */
interface Story {
  frames: number;
  missedFrames: number | null;
  holds: number;
  failsafes: number;
  episodes: { kind: string; startUs: number; endUs: number | null; lastFrameUs: number }[];
  resolution: FormatInfo['resolution'];
  reason: FormatInfo['resolutionReason'];
}

function story(stats: Readonly<LinkStats>, episodes: readonly LinkEpisode[], format: FormatInfo, timed: boolean): Story {
  return {
    frames: stats.frames,
    missedFrames: timed || stats.missedBasis === 'fade-counter' ? stats.missedFrames : null,
    holds: stats.holds,
    failsafes: stats.failsafes,
    episodes: episodes.map((e) => ({ kind: e.kind, startUs: e.startUs, endUs: e.endUs, lastFrameUs: e.lastFrameUs })),
    resolution: format.resolution,
    reason: format.resolutionReason,
  };
}

function fromSummary(capture: Capture): Story {
  const s = summarizeCapture(capture);
  return story(s.link, s.episodes, s.format, capture.timing !== 'none');
}

function fromReport(capture: Capture): Story {
  const report = healthReport(capture);
  const r = report.remotes[0]!;
  const origin = report.timeline.originUs ?? 0;
  // Every failsafe began as a hold, which ends where the failsafe starts.
  const episodes = [
    ...r.holds.episodes.map((e) => ({
      kind: 'hold',
      startUs: e.startUs + origin,
      endUs: e.ongoing ? null : e.endUs + origin,
      lastFrameUs: e.lastFrameUs + origin,
    })),
    ...r.failsafes.map((e) => ({
      kind: 'failsafe',
      startUs: e.startUs + origin,
      endUs: e.ongoing ? null : e.endUs + origin,
      lastFrameUs: e.lastFrameUs + origin,
    })),
  ].sort((a, b) => a.startUs - b.startUs || (a.kind === 'hold' ? -1 : 1));
  return {
    frames: r.frames,
    missedFrames: r.missedFrames,
    holds: r.holds.count,
    failsafes: r.failsafes.length,
    episodes,
    resolution: r.resolution.value,
    reason: r.resolution.reason,
  };
}

/**
 * The worker's replay, wired as worker.ts wires it: one engine per port, batches at each tick on
 * the link clock the replay gives, and at the end every engine judged at the capture's end.
 * `seekAtUs`: after playing to there, seek back to the start of the capture's second quarter
 * with fresh engines (as the worker does) and play on.
 */
function fromReplay(capture: Capture, speed: number, seekAtUs?: number): Story {
  const clock = new SimulatedClock();
  let engine = new Engine({ resolution: 'auto', jitterUs: timingJitterUs(capture.timing) });
  let ended = false;
  const r: ReplaySource = new ReplaySource(
    capture,
    (_port, bytes, time) => engine.push(bytes, time, 0),
    () => {
      engine.batch(r.linkNowUs(0));
    },
    () => {
      engine.end(r.recordedTiming ? r.endUs : Number.NaN);
      engine.batch(r.linkNowUs(0));
      ended = true;
    },
    { clock },
  );
  r.setSpeed(speed);
  r.play();
  if (seekAtUs !== undefined) {
    clock.run(() => ended || r.positionUs >= seekAtUs);
    engine = new Engine({ resolution: 'auto', jitterUs: timingJitterUs(capture.timing) });
    r.seek(r.startUs + (r.endUs - r.startUs) / 4);
    r.play();
  }
  clock.run(() => ended);
  expect(ended).toBe(true);
  expect(r.positionUs).toBe(r.endUs);
  return story(engine.link.stats, engine.link.episodes, engine.decoder.format, capture.timing !== 'none');
}

/**
 * Chunks held back by a loaded host: now and then (seeded) a chunk is late by up to `maxUs`,
 * and the ones due meanwhile come with it.
 */
function stalled(chunks: { bytes: Uint8Array; timeUs: number }[], maxUs: number, seed = 7): { bytes: Uint8Array; timeUs: number }[] {
  let x = seed;
  const random = () => (x = (x * 1_103_515_245 + 12_345) % 2_147_483_648) / 2_147_483_648;
  let last = 0;
  return chunks.map((c) => {
    const at = Math.max(last, c.timeUs + (random() < 0.05 ? random() * maxUs : 0));
    last = at;
    return { bytes: c.bytes, timeUs: at };
  });
}

/** The live engine: the bytes in 16 ms USB chunks at the capture's pace, the page's ticks between them. */
function fromLive(capture: Capture, stallUs = 0): { story: Story; holdAfterUs: number } {
  const times = capture.byteTimesUs!;
  const engine = new Engine({ resolution: 'auto', jitterUs: timingJitterUs('per-chunk') });
  const chunks = stallUs > 0 ? stalled(usbChunks(capture.bytes, times), stallUs) : usbChunks(capture.bytes, times);
  let last = chunks[0]?.timeUs ?? 0;
  for (const c of chunks) {
    for (let t = last + 50_000; t < c.timeUs; t += 50_000) engine.batch(t);
    engine.push(c.bytes, c.timeUs, 0);
    engine.batch(c.timeUs);
    last = c.timeUs;
  }
  engine.end(captureSpan(capture).endUs);
  engine.batch(Infinity);
  return { story: story(engine.link.stats, engine.link.episodes, engine.decoder.format, true), holdAfterUs: engine.link.holdAfterUs };
}

/** Two stories agree: counts exactly, episode times within `toleranceUs`. */
function expectAgree(actual: Story, expected: Story, toleranceUs: number): void {
  const { episodes: ae, ...a } = actual;
  const { episodes: ee, ...e } = expected;
  expect(a).toEqual(e);
  expect(ae.map((x) => x.kind)).toEqual(ee.map((x) => x.kind));
  ae.forEach((x, i) => {
    const y = ee[i]!;
    expect(Math.abs(x.startUs - y.startUs)).toBeLessThanOrEqual(toleranceUs);
    if (y.endUs === null) expect(x.endUs).toBeNull();
    else expect(Math.abs(x.endUs! - y.endUs)).toBeLessThanOrEqual(toleranceUs);
  });
}

interface Case {
  name: string;
  capture: () => Capture;
  /** Whether the live engine can be fed from it (it has per-byte times to chunk). */
  live: boolean;
  /** What the truth says, where there is one. */
  expect?: Partial<Story>;
}

const sim = (name: string, seed: number, durationUs: number) => simulate({ ...preset(name), seed }, durationUs, { truth: true });

const CASES: Case[] = [
  {
    name: 'simulator dropouts-failsafe (per-byte times)',
    capture: () => perByteCapture(sim('dropouts-failsafe', 3, 4_000_000)),
    live: true,
    expect: { holds: 2, failsafes: 1 },
  },
  {
    name: 'simulator dropouts-and-damage (per-byte times)',
    capture: () => perByteCapture(sim('dropouts-and-damage', 5, 4_000_000)),
    live: true,
    expect: { holds: 2, failsafes: 1 },
  },
  {
    name: 'simulator damaged-line, 00 00 header: missed frames by count (per-byte times)',
    capture: () => perByteCapture(sim('damaged-line', 7, 4_000_000)),
    live: true,
    expect: { failsafes: 0 },
  },
  {
    name: 'simulator dsm2-22ms-1024-external (per-byte times)',
    capture: () => perByteCapture(sim('dsm2-22ms-1024-external', 9, 3_000_000)),
    live: true,
    expect: { holds: 0, failsafes: 0 },
  },
  {
    name: 'simulator dropouts-failsafe recorded through a USB adapter (.sscap, chunk times)',
    capture: () => {
      const s = sim('dropouts-failsafe', 3, 4_000_000);
      return sscap(usbChunks(s.bytes, s.timesUs));
    },
    live: false,
    expect: { holds: 2, failsafes: 1 },
  },
  {
    name: 'simulator dropouts-failsafe as a raw .bin (no timing)',
    capture: () => importRaw(sim('dropouts-failsafe', 3, 4_000_000).bytes),
    live: false,
    expect: { holds: 0, failsafes: 0, episodes: [] },
  },
];

if (present) {
  for (const path of captureFiles(CAPTURES)) {
    const name = path.slice(CAPTURES.length + 1);
    // The PX4 DX9 captures are clean links (0 gaps, 0 fades): nothing may be made up from their timing.
    const clean = /dx9/.test(name) ? { holds: 0, failsafes: 0, missedFrames: 0 } : undefined;
    CASES.push({
      name: `real capture ${name}`,
      capture: () => readCapture(new Uint8Array(readFileSync(path)), path),
      live: true,
      expect: clean,
    });
  }
}

describe('every surface tells the same story about the same bytes', () => {
  for (const c of CASES) {
    describe(c.name, () => {
      const capture = c.capture();
      const reference = fromSummary(capture);
      const timed = capture.timing !== 'none';

      it('decodes frames, and the truth where known, in summarizeCapture (satscope info)', () => {
        expect(reference.frames).toBeGreaterThan(50);
        if (c.expect) expect(reference).toMatchObject(c.expect);
      });

      it('healthReport agrees', () => {
        expectAgree(fromReport(capture), reference, 0.1);
      });

      it.each([
        ['1×', 1],
        ['4×', 4],
        ['full speed', 0],
      ])("replay at %s agrees, on the capture's clock", (_label, speed) => {
        expectAgree(fromReplay(capture, speed), reference, 0);
      });

      it.runIf(timed)('replay agrees after seeking back mid-way', () => {
        const span = captureSpan(capture);
        expectAgree(fromReplay(capture, 4, span.startUs + (span.endUs - span.startUs) / 2), reference, 0);
      });

      it.runIf(c.live)('the live engine fed in 16 ms USB chunks agrees, episode times within the batching', () => {
        const { story: live, holdAfterUs } = fromLive(capture);
        // A silence shorter than the USB delivery jitter explains is no hold through an adapter
        // (on a logic analyser it is): those, and only those, the live view may not show.
        const unseen = reference.episodes.filter(
          (e) =>
            e.kind === 'hold' &&
            e.endUs !== null &&
            e.endUs - e.lastFrameUs <= holdAfterUs + 16_000 &&
            !reference.episodes.some((f) => f.kind === 'failsafe' && f.lastFrameUs === e.lastFrameUs),
        );
        if (unseen.length > 0) {
          const shown = live.episodes.filter((e) => !unseen.some((u) => Math.abs(u.lastFrameUs - e.lastFrameUs) <= 20_000));
          expect(live.holds).toBeGreaterThanOrEqual(reference.holds - unseen.length);
          reference.episodes = reference.episodes.filter((e) => !unseen.includes(e));
          reference.holds -= unseen.length;
          live.episodes = shown;
          live.holds = shown.filter((e) => e.kind === 'hold').length;
        }
        if (summarizeCapture(capture).link.missedBasis === 'frame-count') {
          // Without a fade counter the count rests on the schedule the first frames set: a frame
          // missed among them, through 16 ms of batching, can hide in the first frames' lateness.
          expect(Math.abs(live.missedFrames! - reference.missedFrames!)).toBeLessThanOrEqual(1);
          live.missedFrames = reference.missedFrames;
        }
        expectAgree(live, reference, 20_000);
      });

      it.runIf(c.live && c.expect?.holds === 0)(
        'on a loaded host (chunks held back up to 80 ms now and then), the live engine still shows no hold and no missed frame that is not there',
        () => {
          const { story: live } = fromLive(capture, 80_000);
          expect(live).toMatchObject({ holds: 0, failsafes: 0, missedFrames: reference.missedFrames, episodes: [] });
        },
      );
    });
  }
});
