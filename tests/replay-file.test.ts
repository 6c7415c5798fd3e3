/**
 * A .sscap replayed from its File (capture-file.ts, replay-session.ts): never read whole, played
 * a window of records at a time to the same frames and figures as the capture decoded whole;
 * files the windows cannot play as recorded (damaged, times stepped over) read whole as before;
 * a file cut short or without an index plays once its records are walked, with every port.
 */
import { describe, expect, it } from 'vitest';
import { capturePorts } from '../src/capture/facts.js';
import { captureSpan } from '../src/report/capture-span.js';
import { readCapture } from '../src/capture/sniff.js';
import { encodeCapture } from '../src/capture/writer.js';
import { WINDOW_BYTES } from '../src/worker/replay/capture-file.js';
import { overviewOf } from '../src/worker/replay/overview.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { usbChunks, withoutIndex } from './feeds.js';
import { longCapture, longCaptureWithSeed } from './long-capture.js';
import type { Capture } from '../src/capture/model.js';
import { captureChunks } from '../src/capture/model.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { LinkMonitor } from '../src/decoder/link.js';
import { USB_CHUNK_JITTER_US } from '../src/decoder/spec.js';
import { FakeClock, openReplay } from './worker-fakes.js';

const FILE = longCapture();
/** 45 minutes of the same (15 MB): longer than the walk's slices and many windows. */
const LONGER = longCaptureWithSeed(3, 45);

/** A Blob that counts what is read of it: never the whole at once, for a file replayed from it. */
class CountingBlob extends Blob {
  wholeReads = 0;
  largestSlice = 0;
  override slice(start?: number, end?: number, type?: string): Blob {
    this.largestSlice = Math.max(this.largestSlice, (end ?? this.size) - (start ?? 0));
    return super.slice(start, end, type);
  }
  override arrayBuffer(): Promise<ArrayBuffer> {
    this.wholeReads++;
    return super.arrayBuffer();
  }
}

/** What the library's decoder and link monitor say of `port`, fed all of it and ended, as replay ends. */
function decodedWhole(capture: Capture, port: number) {
  const decoder = new SpektrumDecoder();
  const link = new LinkMonitor({ jitterUs: USB_CHUNK_JITTER_US });
  const drain = () => {
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) link.frame(f);
  };
  for (const c of captureChunks(capture, port)) {
    decoder.push(c.bytes, c.time);
    drain();
  }
  decoder.end();
  drain();
  return { decoder: { ...decoder.stats }, link: { ...link.stats } };
}

/** Opens `bytes`, lets its records be walked, plays it to its end at full speed; what the worker showed. */
async function playToEnd(bytes: Uint8Array | Blob, name = 'long.sscap') {
  const clock = new FakeClock();
  const r = openReplay(clock);
  const file = bytes instanceof Blob ? bytes : new Blob([bytes.slice()]);
  await r.send({ type: 'replay-open', name, file }, { type: 'replay-pause' });
  await r.walked();
  await r.send({ type: 'replay-seek', timeUs: 0 }, { type: 'replay-speed', speed: 0 }, { type: 'replay-play' });
  for (let guard = 0; guard < 100_000 && r.of('replay').at(-1)?.replay?.ended !== true; guard++) {
    clock.advance(10);
    await new Promise((resolve) => setTimeout(resolve, 0));
  }
  expect(r.of('replay').at(-1)?.replay?.ended).toBe(true);
  return r;
}

function expectAsDecodedWhole(r: Awaited<ReturnType<typeof playToEnd>>, bytes: Uint8Array): void {
  const capture = readCapture(bytes);
  for (const port of capturePorts(capture)) {
    const engine = r.worker.registry.get(port)?.engine;
    const want = decodedWhole(capture, port);
    expect({ port, decoder: { ...engine?.decoder.stats } }).toEqual({ port, decoder: want.decoder });
    const l = engine?.link.stats;
    const w = want.link;
    expect({ port, frames: l?.frames, fades: l?.fades, lost: l?.lostFrames }).toEqual({
      port,
      frames: w.frames,
      fades: w.fades,
      lost: w.lostFrames,
    });
  }
  const once = overviewOf(capture, capturePorts(capture), 'auto').overview;
  const last = r.of('overview').at(-1)?.overview;
  expect(last?.complete).toBe(true);
  expect(Array.from(last?.lost ?? [])).toEqual(Array.from(once.lost));
  expect(Array.from(last?.fadeRate ?? [])).toEqual(Array.from(once.fadeRate));
  expect(last?.failsafe).toEqual(once.failsafe);
}

describe('a capture replayed from its file', () => {
  it('plays a window at a time, never reading the file whole, to the frames and figures of the capture decoded whole', async () => {
    expect(LONGER.length).toBeGreaterThan(12 * WINDOW_BYTES);
    const blob = new CountingBlob([LONGER.slice()]);
    const r = await playToEnd(blob);
    expect(blob.wholeReads).toBe(0);
    // The walk's slices (4 MB) are the largest reads.
    expect(blob.largestSlice).toBeLessThanOrEqual(4 << 20);
    expect(r.worker.replay?.of()).toEqual({ file: blob });
    expectAsDecodedWhole(r, LONGER);
    expect(r.of('replay').at(-1)?.replay?.issues).toEqual([]);
  });

  it('plays a file without an index once its records are walked, every port found', async () => {
    const bare = withoutIndex(FILE);
    expect(bare.length).toBeLessThan(FILE.length);
    const r = await playToEnd(bare);
    expect(r.of('replay').find((m) => m.replay !== null)?.replay?.reading).toBe(true);
    expect(r.worker.registry.list().map((s) => s.id)).toEqual([0, 1]);
    expectAsDecodedWhole(r, bare);
  });

  it('plays a recording cut off inside a record from its file, and says it was cut', async () => {
    const cut = FILE.slice(0, FILE.length - 20_000);
    const r = await playToEnd(cut);
    expect('file' in (r.worker.replay?.of() ?? {})).toBe(true);
    expect(r.of('replay').at(-1)?.replay?.issues).toEqual([expect.stringContaining('the recording was cut off')]);
    expectAsDecodedWhole(r, cut);
  });

  it("keeps judging an external remote's link when it takes the internal remote's resolution", async () => {
    // Three internal remotes with gaps of their own beside an external remote that starts later:
    // the external one is given the internal remote's key at whatever moment the first batch is
    // sent (a window's end here); its decoder stays locked, so its link must go on uninterrupted.
    const S = 1e6;
    const port = (p: number, seed: number, kind: string, fromUs: number, toUs: number, gaps: [number, number][] = []) => {
      const a = simulate({ ...preset(kind as never), seed }, toUs - fromUs);
      return usbChunks(a.bytes, a.timesUs)
        .map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs + fromUs, port: p }))
        .filter((c) => !gaps.some(([x, y]) => c.timeUs >= x && c.timeUs < y));
    };
    const records = [
      ...port(0, 1, 'dsmx-11ms-2048-internal', 0, 180 * S, [[100 * S, 170 * S]]),
      ...port(1, 2, 'dsmx-11ms-2048-external', 30 * S, 180 * S),
      ...port(2, 3, 'dsmx-11ms-2048-internal', 0, 180 * S, [[60 * S, 90 * S]]),
      ...port(3, 4, 'dsmx-11ms-2048-internal', 0, 180 * S, [[120 * S, 150 * S]]),
    ].sort((x, y) => x.timeUs - y.timeUs || x.port - y.port);
    const bytes = encodeCapture({ baudRate: 115200 }, records);
    const r = await playToEnd(bytes, 'four.sscap');
    expect('file' in (r.worker.replay?.of() ?? {})).toBe(true);
    expect(decodedWhole(readCapture(bytes), 1).link.lostFrames).toBeGreaterThan(0);
    expectAsDecodedWhole(r, bytes);
  });

  it('reads a damaged file whole, every intact record kept, the damage said', async () => {
    const damaged = FILE.slice();
    const at = Math.floor(damaged.length / 2);
    damaged[at] = (damaged[at] ?? 0) ^ 0x5a;
    const r = await playToEnd(damaged);
    expect('capture' in (r.worker.replay?.of() ?? {})).toBe(true);
    expect(r.of('replay').at(-1)?.replay?.issues.length).toBeGreaterThan(0);
    expect(r.of('notice').some((n) => n.title.includes('damaged part'))).toBe(true);
    const once = overviewOf(readCapture(damaged), [0, 1], 'auto').overview;
    expect(r.of('overview').at(-1)?.overview.failsafe).toEqual(once.failsafe);
    expect(Array.from(r.of('overview').at(-1)?.overview.lost ?? [])).toEqual(Array.from(once.lost));
  });

  it('reads whole a file whose clock stepped back (its times are stepped over as every reader does)', async () => {
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 2 }, 20e6);
    const records = usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 }));
    // Half way the recorder's clock goes back 30 s, and on from there.
    const half = records.length >> 1;
    const stepped = records.map((c, i) => (i < half ? c : { ...c, timeUs: c.timeUs - 30e6 }));
    const bytes = encodeCapture({ baudRate: 115200 }, stepped);
    const r = await playToEnd(bytes, 'stepped.sscap');
    expect('capture' in (r.worker.replay?.of() ?? {})).toBe(true);
    const capture = readCapture(bytes);
    expect(capture.issues.map((i) => i.kind)).toEqual(['bad-time']);
    expect({ ...r.worker.registry.get(0)?.engine.decoder.stats }).toEqual(decodedWhole(capture, 0).decoder);
  });
});

describe('a recorded unplug in a replay at 1x', () => {
  it('shows no failsafe for the time the adapter was away, however long before its next chunk the stop was recorded', async () => {
    // Port 0's data stops at 10 s; the adapter is lost half a second later and back 30 s on.
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 8, fades: { lossRate: 0, randomRate: 0 } }, 50e6);
    const chunks = usbChunks(a.bytes, a.timesUs);
    const start = chunks[0]?.timeUs ?? 0;
    const data = chunks
      .filter((c) => c.timeUs < start + 10e6 || c.timeUs >= start + 40e6)
      .map((c) => ({ type: 'data' as const, ...c, port: 0 }));
    const events = [
      { type: 'event' as const, text: 'device lost', timeUs: start + 10.5e6, port: 0 },
      { type: 'event' as const, text: 'port opened', timeUs: start + 39.9e6, port: 0 },
    ];
    const bytes = encodeCapture(
      { baudRate: 115200 },
      [...data, ...events].sort((x, y) => x.timeUs - y.timeUs),
    );
    for (const indexed of [true, false]) {
      const clock = new FakeClock();
      const r = openReplay(clock);
      // Played at once (its index gives its port), and once walked (without one).
      const file = new Blob([(indexed ? bytes : withoutIndex(bytes)).slice()]);
      await r.send({ type: 'replay-open', name: 'unplug.sscap', file });
      await r.walked();
      await r.send({ type: 'replay-seek', timeUs: start }, { type: 'replay-play' });
      for (let guard = 0; guard < 6000 && r.of('replay').at(-1)?.replay?.ended !== true; guard++) {
        clock.advance(10);
        if (guard % 50 === 0) await new Promise((resolve) => setTimeout(resolve, 0));
      }
      expect(r.of('replay').at(-1)?.replay?.ended).toBe(true);
      const failsafes = r.batches().flatMap((b) => b.batch.episodes.filter((e) => e.kind === 'failsafe'));
      expect({ indexed, failsafes }).toEqual({ indexed, failsafes: [] });
    }
  });
});

/** Plays on (the fake clock) until the replay says it ended. */
async function playOn(r: ReturnType<typeof openReplay>, clock: FakeClock): Promise<void> {
  for (let guard = 0; guard < 10_000 && r.of('replay').at(-1)?.replay?.ended !== true; guard++) {
    clock.advance(10);
    await new Promise((resolve) => setTimeout(resolve, 0));
  }
  expect(r.of('replay').at(-1)?.replay?.ended).toBe(true);
}

/** Reads from `failFrom` (up to `failTo`) on fail once `armed` (the file gone while it plays); `readTo`: the furthest read since. */
class FailingBlob extends Blob {
  armed = false;
  readTo = 0;
  constructor(
    parts: BlobPart[],
    readonly failFrom: number,
    readonly failTo = Number.POSITIVE_INFINITY,
  ) {
    super(parts);
  }
  override slice(start?: number, end?: number, type?: string): Blob {
    const inner = super.slice(start, end, type);
    const failing = this.armed && (start ?? 0) >= this.failFrom && (start ?? 0) < this.failTo;
    if (this.armed && !failing) this.readTo = Math.max(this.readTo, end ?? this.size);
    if (!failing) return inner;
    return Object.assign(inner, { arrayBuffer: () => Promise.reject(new Error('NotReadableError')) });
  }
}

/** The long capture opened and walked from a FailingBlob, then armed: its reads from `failFrom` on fail. */
async function failingReplay(failFrom: number, failTo?: number) {
  const blob = new FailingBlob([FILE.slice()], failFrom, failTo);
  const clock = new FakeClock();
  const r = openReplay(clock);
  await r.send({ type: 'replay-open', name: 'gone.sscap', file: blob }, { type: 'replay-pause' });
  await r.walked();
  blob.armed = true;
  return { blob, clock, r };
}

describe('a file that cannot be read on', () => {
  it('ends the replay with the windows read, each fed once', async () => {
    const failFrom = 2 * WINDOW_BYTES;
    const { blob, clock, r } = await failingReplay(failFrom);
    await r.send({ type: 'replay-seek', timeUs: 0 }, { type: 'replay-speed', speed: 0 }, { type: 'replay-play' });
    await playOn(r, clock);
    // What the windows read hold, port by port: fed once, nothing after.
    expect(blob.readTo).toBeGreaterThanOrEqual(failFrom);
    const readable = readCapture(FILE.slice(0, blob.readTo));
    for (const port of capturePorts(readable)) {
      const fed = r.worker.registry.get(port)?.engine.decoder.stats.bytes ?? 0;
      const held = [...captureChunks(readable, port)].reduce((n, c) => n + c.bytes.length, 0);
      expect(fed).toBeGreaterThan(0);
      expect(fed).toBeLessThanOrEqual(held);
    }
    // What follows the last record read is not known: no silence is judged there, and the user is told.
    const lastReadUs = r.worker.replay?.source.playsToUs ?? Number.NaN;
    expect(lastReadUs).toBeLessThanOrEqual(captureSpan(readable).endUs);
    expect(lastReadUs).toBeLessThan(captureSpan(readCapture(FILE)).endUs - 60e6);
    const late = r.batches().flatMap((b) => b.batch.episodes.filter((e) => !(e.startUs < lastReadUs)));
    expect(late).toEqual([]);
    expect(r.of('replay').at(-1)?.replay?.issues).toEqual([expect.stringContaining('could not be read past')]);
    expect(r.of('notice').map((n) => n.title)).toContain('gone.sscap: the file could not be read on');
  });

  it('reads the file again on a seek, plays on to its end, and no longer says it could not', async () => {
    const { blob, clock, r } = await failingReplay(2 * WINDOW_BYTES);
    await r.send({ type: 'replay-seek', timeUs: 0 }, { type: 'replay-speed', speed: 0 }, { type: 'replay-play' });
    await playOn(r, clock);
    const source = r.worker.replay?.source;
    expect(source?.playsToUs).toBeLessThan(source?.endUs ?? 0);
    // The file is readable again: a seek reads it.
    blob.armed = false;
    await r.send({ type: 'replay-seek', timeUs: 0 }, { type: 'replay-play' });
    await playOn(r, clock);
    expect(source?.playsToUs).toBe(source?.endUs);
    expect(r.of('replay').at(-1)?.replay?.issues).toEqual([]);
  });

  it('leaves neither the clock nor a link past the last record read when a read fails inside a seek', async () => {
    const { clock, r } = await failingReplay(2 * WINDOW_BYTES, 3 * WINDOW_BYTES);
    // Another resolution than the walk's: the seek starts afresh, its history read window by window.
    await r.send({ type: 'set-resolution', resolution: 2048 });
    const from = r.batches().length;
    await r.send({ type: 'replay-seek', timeUs: 11 * 60e6 });
    const lastReadUs = r.worker.replay?.source.playsToUs ?? Number.NaN;
    expect(lastReadUs).toBeLessThan(11 * 60e6);
    // Paused, a batch is sent (the resolution already in force chosen again).
    await r.send({ type: 'set-resolution', resolution: 2048 });
    clock.advance(1000);
    await new Promise((resolve) => setTimeout(resolve, 0));
    expect(r.of('replay').at(-1)?.replay?.positionUs).toBeLessThanOrEqual(lastReadUs);
    const judged = r
      .batches(from)
      .map((b) => b.batch.nowUs)
      .filter(Number.isFinite);
    expect(Math.max(...judged)).toBeLessThanOrEqual(lastReadUs);
    expect(r.batches(from).flatMap((b) => b.batch.episodes.filter((e) => !(e.startUs < lastReadUs)))).toEqual([]);
    expect(r.of('notice').map((n) => n.title)).toEqual(['gone.sscap: the file could not be read on']);
  });
});
