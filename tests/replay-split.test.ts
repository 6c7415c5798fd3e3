/**
 * A long capture's replay pass split with a helper (replay-split.ts, replay-file-pass.ts): the
 * helper decodes the later half of the ports straight from the file while the worker reads it
 * and decodes the rest. The overview grows as both read and ends as one decode makes it; seeks
 * from the merged checkpoints give the whole capture's counters up to the target. A helper that
 * fails, disagrees, or read a damaged file counts for nothing: the worker decodes its ports.
 */
import { describe, expect, it } from 'vitest';
import type { Capture } from '../src/capture/model.js';
import { capturePortIndex, capturePorts } from '../src/capture/facts.js';
import { parseCapture } from '../src/capture/reader.js';
import { readCapture } from '../src/capture/sniff.js';
import type { SlicedFile } from '../src/capture/record-walk.js';
import { Dispatcher } from '../src/worker/dispatcher.js';
import { overviewOf } from '../src/worker/replay/overview.js';
import type { Overview } from '../src/worker/protocol.js';
import { type FilePassJob, type FilePassReport, passOverFile } from '../src/worker/replay/replay-file-pass.js';
import { ArrivingFile } from '../src/worker/replay/arriving-file.js';
import { HelperRun, type PassHelperMaker } from '../src/worker/replay/replay-helper.js';
import { AHEAD_PIECES, SplitPass } from '../src/worker/replay/replay-split.js';
import { MINUTE, libraryUpTo, longCapture } from './long-capture.js';
import { ReadingClock, fakeHost } from './worker-fakes.js';

const FILE = longCapture();
const PREVIEW = { minBytes: 0, headBytes: 60_000, tailBytes: 20_000, sliceBytes: 16 << 10 };

/** Turns for reading the file: each read waits for the next, so that both halves and the test take turns. */
class Turns {
  #waiting: (() => void)[] = [];
  wait(): Promise<void> {
    return new Promise((resolve) => this.#waiting.push(resolve));
  }
  give(): void {
    const waiting = this.#waiting;
    this.#waiting = [];
    for (const go of waiting) go();
  }
}

/** Reads of a whole file (the file read again to be parsed), counted by slowFile. */
let wholeReads = 0;

/**
 * `bytes` as a File whose every read waits for a turn: a slice's arrayBuffer(), and each read of
 * its byte stream (16 kB at most) unless `stream` is false (a browser without one).
 */
function slowFile(bytes: Uint8Array, stream = true): Blob {
  const blob = new Blob([bytes.slice()]);
  const slow = (b: Blob): SlicedFile & { arrayBuffer(): Promise<ArrayBuffer>; stream?: () => ReadableStream } => ({
    size: b.size,
    slice: (start, end) => slow(b.slice(start, end)),
    arrayBuffer: async () => {
      if (b.size === bytes.length) wholeReads++;
      await turns.wait();
      return b.arrayBuffer();
    },
    ...(stream
      ? {
          stream: () => {
            let at = 0;
            return new ReadableStream({
              type: 'bytes',
              async pull(controller) {
                await turns.wait();
                const request = controller.byobRequest;
                const n = Math.min(16 << 10, bytes.length - at, request?.view?.byteLength ?? Number.POSITIVE_INFINITY);
                if (n <= 0) {
                  controller.close();
                  request?.respond(0);
                } else if (request?.view) {
                  new Uint8Array(request.view.buffer, request.view.byteOffset, n).set(bytes.subarray(at, at + n));
                  request.respond(n);
                } else controller.enqueue(bytes.slice(at, at + n));
                at += Math.max(0, n);
              },
            });
          },
        }
      : {}),
  });
  return slow(blob) as unknown as Blob;
}

/** A clock whose zero-delay timers wait 1 ms: one slice of the worker's decode a millisecond. */
class SlicingClock extends ReadingClock {
  override after(ms: number, fn: () => void): number {
    return super.after(Math.max(1, ms), fn);
  }
}

const turns = new Turns();

/**
 * The helper on this thread: the same code; `change` alters what it reports; each of its reads
 * waits for `turnsPerRead` turns (2: it walks at half the pace the worker reads).
 */
function helperHere(change: (r: FilePassReport) => FilePassReport = (r) => r, turnsPerRead = 0) {
  const jobs: FilePassJob[] = [];
  /** dropped: stopped other than once when done (the pass drops a helper by stopping it). */
  const runs = { reports: 0, done: false, stops: 0, dropped: false, fed: 0, walkedTo: 0, mostAhead: 0, givenBack: [] as ArrayBuffer[] };
  const make: PassHelperMaker = (job, onReport) => {
    jobs.push(job);
    let stopped = false;
    let t = 0;
    // What it is fed arrives as in the helper worker: each piece transferred, so that the worker
    // can no longer read it (a worker that did would find it empty).
    const file = new ArrivingFile(job.size, true);
    const paced: SlicedFile = {
      size: file.size,
      slice: (start, end) => ({
        arrayBuffer: async () => {
          for (let k = 0; k < turnsPerRead; k++) await turns.wait();
          return file.slice(start, end).arrayBuffer();
        },
      }),
    };
    void passOverFile(
      job,
      paced,
      (r) => {
        if (stopped) return;
        runs.reports++;
        if (r.type === 'done') runs.done = true;
        if (r.type === 'walked') {
          runs.walkedTo = r.to;
          // Given back as the helper worker does, transferred: the helper can no longer read them.
          const spare = structuredClone(r.spare, { transfer: r.spare });
          runs.givenBack.push(...spare);
          onReport(change({ ...r, spare }));
        } else onReport(change(r));
      },
      // 100 ms a read of the clock: a report about every other slice.
      () => (t += 100),
      () => stopped,
      (to) => file.passed(to),
    );
    return {
      feed: (piece) => {
        runs.fed += piece.length;
        runs.mostAhead = Math.max(runs.mostAhead, runs.fed - runs.walkedTo);
        file.push(structuredClone(piece, { transfer: [piece.buffer] }));
      },
      fail: (why) => file.fail(new Error(why)),
      stop: () => {
        runs.stops++;
        runs.dropped = runs.stops > (runs.done ? 1 : 0);
        stopped = true;
      },
    };
  };
  return { make, jobs, runs };
}

/** The offset of the first record of `file` from its middle on whose type byte and port `match` says yes. */
function recordFromMiddle(file: Uint8Array, match: (type: number, port: number) => boolean): number {
  const view = new DataView(file.buffer, file.byteOffset, file.byteLength);
  let p = parseCapture(file).headerLength;
  while (p < file.length >> 1 || !match(file[p + 2] ?? -1, file[p + 3] ?? -1)) p += 20 + view.getUint32(p + 4, true);
  return p;
}

/** FILE with its first data record on `port` from the middle on dated 5 s later: its CRC no longer matches. */
function redated(port: number): Uint8Array {
  const file = FILE.slice();
  const view = new DataView(file.buffer);
  const p = recordFromMiddle(file, (type, on) => type === 1 && on === port);
  view.setFloat64(p + 8, view.getFloat64(p + 8, true) + 5e6, true);
  return file;
}

/** Opens `file` in a worker with `make` as its helper and runs both until the overview is complete. */
async function openSplit(file: Uint8Array, make: PassHelperMaker | null, previewSizes = PREVIEW, stream = true) {
  const clock = new SlicingClock();
  const fake = fakeHost(clock);
  wholeReads = 0;
  const worker = new Dispatcher(fake.host, { previewSizes, passHelper: make });
  worker.receive({ type: 'replay-open', name: 'long.sscap', file: slowFile(file, stream) });
  // The helper's turns go on while the file is opened: its half is drawn from before that ends.
  let opened = false;
  const opening = worker.queue.idle().then(() => {
    opened = true;
  });
  for (let guard = 0; guard < 20_000 && !(opened && fake.of('overview').at(-1)?.overview.complete); guard++) {
    // A slice of the worker's decode, and a turn for the helper's.
    clock.advance(1);
    turns.give();
    await new Promise((resolve) => setTimeout(resolve, 0));
  }
  await opening;
  const overviews = fake.of('overview').map((m) => m.overview);
  const send = async (...messages: Parameters<Dispatcher['receive']>[0][]): Promise<void> => {
    for (const m of messages) worker.receive(m);
    await worker.queue.idle();
  };
  return { worker, overviews, send, wholeReads };
}

/** The capture the replay plays is the one the reader reads from `file` (columns, events, issues). */
function expectCaptureAsRead(split: Awaited<ReturnType<typeof openSplit>>, file: Uint8Array): void {
  const plain = (c: Capture) => ({
    ...c,
    bytes: Buffer.from(c.bytes).toString('base64'),
    chunkEnds: Array.from(c.chunkEnds),
    chunkTimesUs: Array.from(c.chunkTimesUs),
    chunkPorts: Array.from(c.chunkPorts),
  });
  const capture = split.worker.replay?.source.capture;
  expect(capture === undefined ? undefined : plain(capture)).toEqual(plain(readCapture(file, 'long.sscap')));
}

function expectOverviewsAsOneDecode(overviews: Overview[], file: Uint8Array): void {
  const capture = readCapture(file, 'long.sscap');
  const once = overviewOf(capture, capturePorts(capture), 'auto').overview;
  const last = overviews.at(-1) as Overview;
  expect(last.complete).toBe(true);
  expect([Array.from(last.t), Array.from(last.fadeRate), Array.from(last.lost), last.failsafe]).toEqual([
    Array.from(once.t),
    Array.from(once.fadeRate),
    Array.from(once.lost),
    once.failsafe,
  ]);
  let before = Number.NEGATIVE_INFINITY;
  for (const o of overviews.slice(0, -1)) {
    // It grows, and shows only what every port has been read up to, as the whole decode has it.
    expect(o.complete).toBe(false);
    expect(o.readUntilUs).toBeGreaterThan(before);
    before = o.readUntilUs;
    // Every bin before readUntilUs drawn, none after it (the bins are whole seconds from the start).
    expect(o.readUntilUs).toBe((once.t[0] ?? 0) + o.t.length * o.binUs);
    for (let b = 0; b < o.t.length; b++)
      expect([b, o.t[b], o.fadeRate[b], o.lost[b]]).toEqual([b, once.t[b], once.fadeRate[b], once.lost[b]]);
    // The failsafes the whole decode has, as far as they are read.
    const until = o.readUntilUs;
    expect(o.failsafe).toEqual(
      once.failsafe.filter((f) => f.startUs < until).map((f) => ({ startUs: f.startUs, endUs: Math.min(f.endUs, until) })),
    );
  }
}

/** Seeks back and forth: both remotes' counters are those of a decode fed everything up to the target. */
async function expectSeeksExact(split: Awaited<ReturnType<typeof openSplit>>, file: Uint8Array): Promise<void> {
  const capture = readCapture(file, 'long.sscap');
  const start = split.worker.replay?.source.startUs ?? Number.NaN;
  await split.send({ type: 'replay-pause' });
  for (const at of [11.2, 3.5, 7.25, 0.5, 10.9]) {
    const target = start + at * MINUTE;
    await split.send({ type: 'replay-seek', timeUs: target });
    for (const port of [0, 1]) {
      const engine = split.worker.registry.get(port)?.engine;
      const want = libraryUpTo(capture, port, target);
      expect({ at, port, decoder: { ...engine?.decoder.stats } }).toEqual({ at, port, decoder: want.decoder });
      const l = engine?.link.stats;
      expect({ at, port, fades: l?.fades, missed: l?.missedFrames, lost: l?.lostFrames, failsafes: l?.failsafes }).toEqual({
        at,
        port,
        fades: want.link.fades,
        missed: want.link.missedFrames,
        lost: want.link.lostFrames,
        failsafes: want.link.failsafes,
      });
    }
  }
}

describe('a long capture decoded on two workers', () => {
  it('gives the helper the later port, draws the merged overview as it grows, ends as one decode, and seeks from merged checkpoints', async () => {
    const helper = helperHere();
    const split = await openSplit(FILE, helper.make);
    expect(helper.jobs.map((j) => j.ports)).toEqual([[1]]);
    expect(helper.runs.done).toBe(true);
    expect(helper.runs.dropped).toBe(false);
    expect(helper.runs.reports).toBeGreaterThan(3);
    // A helper at half the worker's pace is sent no more than a few pieces ahead of where it has
    // got (the file is 3.9 MB, the pieces 16 kB), and the result is the same.
    // The worker reads each piece into a buffer the helper gave back (its byte stream's reads
    // take the buffer over): all but the last few, which the file's end leaves unused.
    expect(helper.runs.givenBack.length).toBeGreaterThan(100);
    expect(helper.runs.givenBack.filter((b) => b.byteLength > 0).length).toBeLessThanOrEqual(AHEAD_PIECES + 1);
    // Read a slice at a time (a browser without a byte stream), the result is the same.
    const slow = helperHere(undefined, 2);
    const paced = await openSplit(FILE, slow.make, PREVIEW, false);
    expect(slow.runs.dropped).toBe(false);
    expect(slow.runs.mostAhead).toBeGreaterThan(2 * PREVIEW.sliceBytes);
    expect(slow.runs.mostAhead).toBeLessThanOrEqual((AHEAD_PIECES + 2) * PREVIEW.sliceBytes);
    expectOverviewsAsOneDecode(paced.overviews, FILE);
    expect(split.overviews.length).toBeGreaterThan(3);
    expectOverviewsAsOneDecode(split.overviews, FILE);
    // The capture played is the one the worker's half kept as it walked: the file is not read again.
    expect([split.wholeReads, paced.wholeReads]).toEqual([0, 0]);
    expectCaptureAsRead(split, FILE);
    // The helper made room for it before its walk, as much as the file's index counts, and did
    // not grow it on the way.
    const played = split.worker.replay?.source.capture as Capture;
    const expected = helper.jobs[0]?.expected ?? { records: 0, dataBytes: 0, chunksByPort: [] };
    expect(expected.records).toBe(played.chunkEnds.length);
    expect(expected.dataBytes).toBe(played.bytes.length);
    expect(played.bytes.buffer.byteLength / played.bytes.length).toBeLessThan(1.08);
    // So did this worker's half for each port's chunk numbers (the port index it finds).
    const index = capturePortIndex(played);
    for (const p of capturePorts(played)) {
      const room = (index[p]?.buffer.byteLength ?? 0) / 4;
      expect(room / (index[p]?.length ?? 0)).toBeGreaterThanOrEqual(1);
      expect(room / (index[p]?.length ?? 0)).toBeLessThan(1.08);
      expect(expected.chunksByPort[p]).toBe(room);
    }
    await expectSeeksExact(split, FILE);
  });

  it('decodes the helper’s ports itself when the helper fails, and the result is the same', async () => {
    const helper = helperHere((r) => (r.type === 'done' ? { type: 'failed', why: 'the helper ran out of memory' } : r));
    const split = await openSplit(FILE, helper.make);
    expect(helper.runs.done).toBe(true);
    expectOverviewsAsOneDecode(split.overviews, FILE);
    // Without the helper's word that its records are intact, the file is read again and parsed.
    expect(split.wholeReads).toBe(1);
    expectCaptureAsRead(split, FILE);
    await expectSeeksExact(split, FILE);
  });

  it('drops a helper whose checkpoints fall on other chunks, or who walked other records', async () => {
    const moved = helperHere((r) =>
      r.type === 'failed' || r.type === 'walked' ? r : { ...r, checkpoints: r.checkpoints.map((c) => ({ ...c, chunk: c.chunk + 1 })) },
    );
    const a = await openSplit(FILE, moved.make);
    expect(moved.runs.dropped).toBe(true);
    expectOverviewsAsOneDecode(a.overviews, FILE);
    await expectSeeksExact(a, FILE);
    const miscounted = helperHere((r) => (r.type === 'done' ? { ...r, chunks: r.chunks - 1 } : r));
    const b = await openSplit(FILE, miscounted.make);
    expectOverviewsAsOneDecode(b.overviews, FILE);
    await expectSeeksExact(b, FILE);
    // A capture kept without its last chunk is not the one this worker walked: the file is parsed.
    const short = helperHere((r) =>
      r.type === 'done' && r.kept !== undefined
        ? { ...r, kept: { ...r.kept, chunkEnds: r.kept.chunkEnds.subarray(0, -1), chunkTimesUs: r.kept.chunkTimesUs.subarray(0, -1) } }
        : r,
    );
    const c = await openSplit(FILE, short.make);
    expect(c.wholeReads).toBe(1);
    expectCaptureAsRead(c, FILE);
    await expectSeeksExact(c, FILE);
  });

  it('does not use the helper for a damaged file, and starts none for a file read whole at once', async () => {
    // Halfway through, the time of a record of port 0 moved 5 s on (its CRC no longer matches):
    // the reader drops that record; decoded, its frames would be a silence that never happened.
    const damaged = redated(0);
    expect(readCapture(damaged, 'long.sscap').issues.length).toBeGreaterThan(0);
    const helper = helperHere();
    const split = await openSplit(damaged, helper.make);
    expect(helper.jobs.length).toBe(1);
    expect(helper.runs.dropped).toBe(true);
    expectOverviewsAsOneDecode(split.overviews, damaged);
    // Parsed, salvaged: the damaged record is dropped and said to be.
    expect(split.wholeReads).toBe(1);
    expectCaptureAsRead(split, damaged);
    // The same on the helper's port: the helper finds it, and is dropped.
    const theirs = redated(1);
    const helperPort = helperHere();
    const caught = await openSplit(theirs, helperPort.make);
    expect(helperPort.runs.dropped).toBe(true);
    expectOverviewsAsOneDecode(caught.overviews, theirs);
    expectCaptureAsRead(caught, theirs);
    // A port byte flipped (port 0 → 1) halfway: the helper's half would take that record for its own.
    const moved = FILE.slice();
    moved[recordFromMiddle(moved, (_, port) => port === 0) + 3] = 1;
    const flipped = await openSplit(moved, helperHere().make);
    expectOverviewsAsOneDecode(flipped.overviews, moved);
    expect(flipped.wholeReads).toBe(1);
    expectCaptureAsRead(flipped, moved);
    // Cut off inside its last record (a recording that stopped): every record before the cut is
    // intact, so both halves count; the file is parsed for playback, and the cut is said.
    const cut = FILE.subarray(0, FILE.length - 7);
    expect(readCapture(cut, 'long.sscap').issues.map((i) => i.kind)).toEqual(['truncated-record']);
    const whole = helperHere();
    const cutOff = await openSplit(cut, whole.make);
    expect(whole.runs.dropped).toBe(false);
    expectOverviewsAsOneDecode(cutOff.overviews, cut);
    expect(cutOff.wholeReads).toBe(1);
    expectCaptureAsRead(cutOff, cut);
    await expectSeeksExact(cutOff, cut);
    const none = helperHere();
    const alone = await openSplit(FILE, none.make, { ...PREVIEW, minBytes: FILE.length + 1 });
    expect(none.jobs.length).toBe(0);
    expectOverviewsAsOneDecode(alone.overviews, FILE);
  });
});

describe('the split pass says its overview is complete without making it', () => {
  /** An overview of no bins, read to `readUntilUs`, complete or not. */
  const overview = (complete: boolean): Overview => ({
    t: new Float64Array(0),
    binUs: 1e6,
    fadeRate: new Float32Array(0),
    lost: new Float32Array(0),
    failsafe: [],
    readUntilUs: complete ? 10 * MINUTE : MINUTE,
    complete,
  });

  /** Two runs whose reports the test makes, and their pass. */
  function twoRuns() {
    const report: ((r: FilePassReport) => void)[] = [];
    const make: PassHelperMaker = (_job, onReport) => {
      report.push(onReport);
      return { feed: () => {}, fail: () => {}, stop: () => {} };
    };
    const job = (ports: number[]): FilePassJob => ({
      size: 1000,
      ports,
      alsoChecked: [],
      resolution: 'auto',
      originUs: 0,
      endUs: 10 * MINUTE,
    });
    const runs = [HelperRun.start(make, job([0])), HelperRun.start(make, job([1]))].filter((r) => r !== null);
    const pass = new SplitPass(runs, 'auto', 0, 10 * MINUTE, () => {});
    const done = (complete: boolean): FilePassReport => ({
      type: 'done',
      overview: overview(complete),
      checkpoints: [],
      chunks: 0,
      dataBytes: 0,
    });
    return { report, pass, done };
  }

  it('as overview() judges it, as the runs report', () => {
    const { report, pass, done } = twoRuns();
    const seen: boolean[] = [];
    const check = (): void => {
      expect(pass.overviewComplete).toBe(pass.overview().complete);
      seen.push(pass.overviewComplete);
    };
    check();
    report[0]?.({ type: 'progress', overview: overview(false), checkpoints: [] });
    check();
    report[0]?.(done(true));
    check();
    report[1]?.({ type: 'progress', overview: overview(false), checkpoints: [] });
    check();
    report[1]?.(done(true));
    check();
    expect(seen).toEqual([false, false, false, false, true]);
  });

  it('and not when a run that failed leaves its ports to be decoded here', () => {
    const { report, pass, done } = twoRuns();
    report[0]?.(done(true));
    report[1]?.({ type: 'failed', why: 'the helper failed' });
    expect(pass.overviewComplete).toBe(false);
    expect(pass.overview().complete).toBe(false);
  });
});
