/**
 * A long capture in the worker (replay-pass.ts, replay-session.ts): its overview grows as it is
 * read, never showing what has not been read, and ends equal to the overview made in one go; a
 * seek starts from the nearest checkpoint, with the counters and link figures of the whole
 * capture up to the target, as a decode fed every chunk up to there has them. The file-side
 * cases (windows, damage, a cut, no index) are in replay-file.test.ts.
 */
import { describe, expect, it } from 'vitest';
import { capturePorts } from '../src/capture/facts.js';
import { encodeCapture } from '../src/capture/writer.js';
import { readCapture } from '../src/capture/sniff.js';
import { overviewOf } from '../src/worker/replay/overview.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { usbChunks } from './feeds.js';
import { ReplayPass } from '../src/worker/replay/replay-pass.js';
import { captureSpan } from '../src/report/capture-span.js';
import { healthReport } from '../src/report/report.js';
import type { Overview } from '../src/worker/protocol.js';
import { MINUTE, libraryUpTo, longCapture, longCaptureWithSeed } from './long-capture.js';
import { FakeClock, ReadingClock, openReplay } from './worker-fakes.js';

const FILE = longCapture();
/** 45 minutes of the same (15 MB): walked in several slices, so its overview is sent as it grows. */
const LONGER = longCaptureWithSeed(3, 45);

describe('a long capture in the worker', () => {
  it('draws its overview as it is read: nothing after the part read, each part as the complete one has it, and complete at the end as made in one go', async () => {
    // Each reading of the clock a quarter of a second on: the walk's slices take that long.
    const clock = new ReadingClock(250);
    const { send, of, walked } = openReplay(clock);
    await send({ type: 'replay-open', name: 'long.sscap', file: new Blob([LONGER.slice()]) });
    await walked();
    const all = of('overview').map((m) => m.overview);
    expect(all.length).toBeGreaterThan(2);
    const last = all.at(-1) as Overview;
    expect(last.complete).toBe(true);
    const capture = readCapture(LONGER, 'long.sscap');
    const once = overviewOf(capture, capturePorts(capture), 'auto').overview;
    expect(Array.from(last.t)).toEqual(Array.from(once.t));
    expect(Array.from(last.fadeRate)).toEqual(Array.from(once.fadeRate));
    expect(Array.from(last.lost)).toEqual(Array.from(once.lost));
    expect(last.failsafe).toEqual(once.failsafe);
    expect(once.failsafe.length).toBe(1);
    let before = Number.NEGATIVE_INFINITY;
    for (const o of all.slice(0, -1)) {
      // It grows, and only up to where every port has been read.
      expect(o.readUntilUs).toBeGreaterThanOrEqual(before);
      before = o.readUntilUs;
      expect(o.t.length).toBeLessThanOrEqual(Math.round((o.readUntilUs - (once.t[0] ?? 0)) / o.binUs));
      for (let b = 0; b < o.t.length; b++) {
        expect(o.t[b]).toBe(once.t[b]);
        expect([b, o.fadeRate[b], o.lost[b]]).toEqual([b, once.fadeRate[b], once.lost[b]]);
      }
      for (const f of o.failsafe) expect(f.endUs).toBeLessThanOrEqual(o.readUntilUs);
    }
  });

  it("seeks anywhere from a checkpoint: the counters and link figures are the whole capture's up to the target", async () => {
    const clock = new FakeClock();
    const { send, worker, walked } = openReplay(clock);
    await send({ type: 'replay-open', name: 'long.sscap', file: new Blob([FILE.slice()]) }, { type: 'replay-pause' });
    await walked();
    const capture = readCapture(FILE, 'long.sscap');
    const start = worker.replay?.source.startUs ?? Number.NaN;
    // Past the fresh decode's 10 minutes, before and after the failsafe, backwards and forwards.
    for (const at of [11.2, 3.5, 0.5, 7.25, 10.9, 1.4]) {
      const target = start + at * MINUTE;
      await send({ type: 'replay-seek', timeUs: target });
      for (const port of [0, 1]) {
        const engine = worker.registry.get(port)?.engine;
        const want = libraryUpTo(capture, port, target);
        expect({ at, port, decoder: { ...engine?.decoder.stats } }).toEqual({ at, port, decoder: want.decoder });
        const l = engine?.link.stats;
        const got = {
          frames: l?.frames,
          fades: l?.fades,
          missed: l?.missedFrames,
          lost: l?.lostFrames,
          holds: l?.holds,
          failsafes: l?.failsafes,
        };
        const w = want.link;
        expect({ at, port, ...got }).toEqual({
          at,
          port,
          frames: w.frames,
          fades: w.fades,
          missed: w.missedFrames,
          lost: w.lostFrames,
          holds: w.holds,
          failsafes: w.failsafes,
        });
      }
    }
    // After the failsafe at 5 minutes, it is counted.
    expect(worker.registry.get(0)?.engine.link.stats.failsafes).toBe(0);
    await send({ type: 'replay-seek', timeUs: start + 8 * MINUTE });
    expect(worker.registry.get(0)?.engine.link.stats.failsafes).toBe(1);
  });

  it('draws a failsafe still on when the capture ends to its end, read as it goes, in parts or in one go, as the report has it', () => {
    // The internal remote falls silent 40 s in and never comes back; the external one goes on to the end at 60 s.
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 5, dropouts: [{ atUs: 40e6, durationUs: 100e6 }] }, 60e6);
    const b = simulate({ ...preset('dsmx-11ms-2048-external'), seed: 6 }, 60e6);
    const records = [
      ...usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
      ...usbChunks(b.bytes, b.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs + 3, port: 1 })),
    ].sort((x, y) => x.timeUs - y.timeUs);
    const capture = readCapture(encodeCapture({ baudRate: 115200 }, records));
    const { startUs, endUs } = captureSpan(capture);
    const [episode, ...others] = healthReport(capture).remotes.flatMap((r) => r.failsafes);
    expect(others).toEqual([]);
    expect(episode?.ongoing).toBe(true);
    const asReported = [{ startUs: (episode?.startUs ?? 0) + startUs, endUs: (episode?.endUs ?? 0) + startUs }];
    const near = (got: Overview['failsafe']) => got.map((f) => ({ startUs: Math.round(f.startUs / 10), endUs: Math.round(f.endUs / 10) }));
    expect(near(asReported)[0]?.endUs).toBe(Math.round(endUs / 10));
    // In one go.
    expect(near(overviewOf(capture, [0, 1], 'auto').overview.failsafe)).toEqual(near(asReported));
    // Read as it goes: nothing of it before the reading is past the silence (the overview waits for
    // the silent port's evidence), then all of it, to the end.
    const pass = new ReplayPass(capture, [0, 1], 'auto', startUs, endUs);
    let clock = 0;
    let steps = 0;
    for (; !pass.step(1, () => (clock += 1)); steps++) {
      const o = pass.overview();
      for (const f of o.failsafe) expect(f.endUs).toBeLessThanOrEqual(o.readUntilUs);
    }
    expect(steps).toBeGreaterThan(10);
    expect(near(pass.overview().failsafe)).toEqual(near(asReported));
  });
});

describe("a recording's unplug in the overview", () => {
  it('draws no failsafe for the time the adapter was away ("device lost"), in one go, read as it goes and walked from the file', async () => {
    const fromFile = async (file: Uint8Array): Promise<number> => {
      const { send, of, walked } = openReplay(new FakeClock());
      await send({ type: 'replay-open', name: 'unplug.sscap', file: new Blob([file.slice()]) });
      await walked();
      return of('overview').at(-1)?.overview.failsafe.length ?? -1;
    };
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 5, fades: { lossRate: 0, randomRate: 0 } }, 8e6);
    const chunks = usbChunks(a.bytes, a.timesUs);
    const before = chunks.filter((c) => c.timeUs < 3e6);
    const after = chunks.filter((c) => c.timeUs >= 5.5e6);
    const make = (events: boolean) =>
      encodeCapture({ baudRate: 115200 }, [
        ...before.map((c) => ({ type: 'data' as const, ...c, port: 0 })),
        ...(events ? [{ type: 'event' as const, text: 'device lost', timeUs: before.at(-1)!.timeUs + 300, port: 0 }] : []),
        ...after.map((c) => ({ type: 'data' as const, ...c, port: 0 })),
      ]);
    const failsafes = async (file: Uint8Array): Promise<number[]> => {
      const capture = readCapture(file);
      const { startUs, endUs } = captureSpan(capture);
      const pass = new ReplayPass(capture, [0], 'auto', startUs, endUs);
      let clock = 0;
      while (!pass.step(1, () => (clock += 1)));
      return [overviewOf(capture, [0], 'auto').overview.failsafe.length, pass.overview().failsafe.length, await fromFile(file)];
    };
    expect(await failsafes(make(false))).toEqual([1, 1, 1]);
    expect(await failsafes(make(true))).toEqual([0, 0, 0]);
  });
});
