/**
 * Checkpoints (src/decoder/checkpoint.ts): a decoder and a link monitor restored from a
 * checkpoint taken anywhere in a stream, on fresh instances, and fed the rest, give exactly
 * what the originals gave from there: every frame, event, counter, state, episode and missed
 * frame, then the same format and the same end. Streams: simulated receivers of every kind,
 * damaged ones, dropouts that make holds and failsafes, the real PX4 captures when they are
 * here; fed whole with per-byte times, in chunks with chunk times, and without times.
 */
import { existsSync, readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { describe, expect, it } from 'vitest';
import type { DecodedFrame, DecoderEvent } from '../src/decoder/types.js';
import { type DecoderOptions, SpektrumDecoder } from '../src/decoder/decoder.js';
import { LinkMonitor } from '../src/decoder/link.js';
import type { LinkOptions } from '../src/decoder/link-types.js';
import { importSaleaeCsv } from '../src/capture/saleae.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { damagedStream, type Feed, feed, type Push } from './decoder-streams.js';

/** One call on the pair: a push, a next() (with the link fed its frame), a resolution set, the end. */
type Step =
  | { kind: 'push'; push: Push }
  | { kind: 'next' }
  | { kind: 'resolution'; to: 'auto' | 1024 | 2048 }
  | { kind: 'end'; endUs: number };

interface Pair {
  decoder: SpektrumDecoder;
  link: LinkMonitor;
  events: string[];
}

const LINK_OPTIONS: LinkOptions = { jitterUs: 2000, maxEpisodes: 3 };
/** Every episode kept: the checkpoints then share the settled ones (episode-log.ts). */
const ALL_EPISODES: LinkOptions = { jitterUs: 2000 };

function pair(options: DecoderOptions, link = LINK_OPTIONS): Pair {
  const events: string[] = [];
  const asJson = (e: DecoderEvent) => JSON.stringify(e, (_k, v: unknown) => (v instanceof Uint8Array ? Array.from(v) : v));
  const missed: string[] = events;
  return {
    decoder: new SpektrumDecoder({ ...options, onEvent: (e) => events.push(asJson(e)) }),
    link: new LinkMonitor({ ...link, onMissed: (from, to, n, p) => missed.push(`missed ${from} ${to} ${n} ${p}`) }),
    events,
  };
}

function shownFrame(f: DecodedFrame): string {
  return JSON.stringify({
    ...f,
    ids: Array.from(f.ids.subarray(0, f.count)),
    positions: Array.from(f.positions.subarray(0, f.count)),
    words: Array.from(f.words),
    bytes: Array.from(f.bytes),
  });
}

/**
 * Runs `step` on `p` and says what it did: the frame, events and missed frames it gave, and the
 * decoder's and link's counters, state and episodes after it. Returns whether a next() gave a frame.
 */
function run(p: Pair, step: Step): { out: string; frame: boolean } {
  let frame = false;
  let what = '';
  switch (step.kind) {
    case 'push': {
      p.decoder.push(step.push.bytes, step.push.time);
      const t = step.push.time;
      if (typeof t === 'number') what = `state ${p.link.update(t)}`;
      break;
    }
    case 'next': {
      const f = p.decoder.next();
      if (f !== undefined) {
        p.link.frame(f);
        what = shownFrame(f);
        frame = true;
      }
      break;
    }
    case 'resolution':
      p.decoder.setResolution(step.to, 'internal-remote');
      break;
    case 'end':
      p.decoder.end();
      what = `finish ${p.link.finish(step.endUs)}`;
      break;
  }
  const out = [
    what,
    ...p.events.splice(0),
    JSON.stringify(p.decoder.stats),
    JSON.stringify(p.link.stats),
    p.link.state,
    JSON.stringify(p.link.episodes),
    String(p.link.takeRetracted()),
    String(p.link.lastFrameUs),
    String(p.link.lastIntervalUs),
  ].join('\n');
  return { out, frame };
}

/** The steps of feeding `pushes`: each push, then next() until it gives nothing; at the end the same after end(). */
function* stepsOf(pushes: Iterable<Push>, endUs: number, setAt = -1): Generator<Step> {
  let k = 0;
  for (const push of pushes) {
    if (k++ === setAt) yield { kind: 'resolution', to: 2048 };
    yield { kind: 'push', push };
    yield { kind: 'next' };
  }
  yield { kind: 'end', endUs };
  yield { kind: 'next' };
}

/**
 * Feeds the steps to an original pair, taking checkpoints at `points` random steps (also
 * inside a drain, between two frames), and to a fresh pair restored from each: its own
 * checkpoint must be the one restored, and every step must say the same for the next
 * `HORIZON` steps; from every eighth checkpoint, to the end, and again after a second restore
 * from it (restoring leaves it as it was). Linear in the steps: a state the checkpoint forgot
 * shows in the checkpoint compared, or soon after; one both forgot, in the runs to the end.
 */
/** Steps a restored pair is run for (from every eighth checkpoint: to the end). */
const HORIZON = 400;

function expectRestoredSame(
  label: string,
  steps: Step[],
  options: DecoderOptions,
  points: number,
  seed: number,
  link = LINK_OPTIONS,
): void {
  // next() steps repeat until no frame: expand them as the original ran them.
  const original = pair(options, link);
  const flat: Step[] = [];
  const outs: string[] = [];
  const taken = new Map<number, { decoder: ReturnType<SpektrumDecoder['checkpoint']>; link: ReturnType<LinkMonitor['checkpoint']> }>();
  let s = seed;
  const rand = (n: number) => {
    s = (Math.imul(s, 1103515245) + 12345) >>> 0;
    return (s >>> 8) % n;
  };
  // Which of the (about) steps.length × 2 flat steps get a checkpoint.
  const every = Math.max(1, Math.floor((steps.length * 2) / points));
  let next = rand(every);
  const take = () => {
    if (flat.length - 1 === next) {
      taken.set(flat.length - 1, { decoder: original.decoder.checkpoint(), link: original.link.checkpoint() });
      next += 1 + rand(2 * every);
    }
  };
  for (const step of steps) {
    if (step.kind !== 'next') {
      flat.push(step);
      outs.push(run(original, step).out);
      take();
      continue;
    }
    for (;;) {
      flat.push(step);
      const r = run(original, step);
      outs.push(r.out);
      take();
      if (!r.frame) break;
    }
  }
  expect(taken.size, `${label}: checkpoints taken`).toBeGreaterThan(points / 3);
  const format = JSON.stringify(original.decoder.format);
  let j = 0;
  for (const [at, cp] of taken) {
    const whole = j++ % 8 === 0;
    const to = whole ? flat.length : Math.min(flat.length, at + 1 + HORIZON);
    for (let round = 0; round < (whole ? 2 : 1); round++) {
      const copy = pair(options, link);
      copy.decoder.restore(cp.decoder);
      copy.link.restore(cp.link);
      // Every field the checkpoint holds was put back: a restore line forgotten shows here even
      // where no later frame would show it.
      if (round === 0) {
        expect(plain(copy.decoder.checkpoint()), `${label}: decoder restored at step ${at}`).toEqual(plain(cp.decoder));
        expect(plain(copy.link.checkpoint()), `${label}: link restored at step ${at}`).toEqual(plain(cp.link));
      }
      for (let i = at + 1; i < to; i++) {
        const step = flat[i]!;
        const out = run(copy, step).out;
        if (out !== outs[i])
          expect(out, `${label}, ${JSON.stringify(options)}: restored at step ${at} of ${flat.length}, step ${i}`).toBe(outs[i]);
      }
      if (whole) expect(JSON.stringify(copy.decoder.format), `${label}: format`).toBe(format);
    }
  }
}

/** A checkpoint as plain data (typed arrays as arrays), to compare two. */
function plain(x: unknown): unknown {
  return JSON.parse(JSON.stringify(x, (_k, v: unknown) => (ArrayBuffer.isView(v) ? Array.from(v as Uint8Array) : v)));
}

const FEEDS: Feed[] = ['whole, per-byte times', '64-byte chunks, chunk times', 'random splits, no times', 'USB chunks'];

/** Per-byte times come in slices (as a capture's are fed), so that there are points between them. */
function* sliced(pushes: Iterable<Push>): Generator<Push> {
  for (const p of pushes) {
    if (!(p.time instanceof Float64Array)) {
      yield p;
      continue;
    }
    for (let i = 0; i < p.bytes.length; i += 200) yield { bytes: p.bytes.subarray(i, i + 200), time: p.time.subarray(i, i + 200) };
  }
}

function lastTime(times: Float64Array): number {
  return (times[times.length - 1] ?? 0) + 50_000;
}

describe('a decoder and link monitor restored from a checkpoint', () => {
  const cases: [string, DecoderOptions][] = [
    ['dsmx-11ms-2048-internal', {}],
    ['dsm2-22ms-1024-external', {}],
    ['rssi-spm4649t', {}],
    ['xplus-dx9', {}],
    ['vtx', {}],
    ['fade-wrap-external', {}],
    ['clone-zero-header', {}],
    ['lying-b2-with-1024-data', {}],
    ['dropouts-failsafe', {}],
    ['dropouts-and-damage', {}],
    ['damaged-line', { resolution: 2048 }],
    ['dsm2-22ms-1024-external', { resolution: 2048 }],
  ];
  for (const [name, options] of cases) {
    it(`${name} ${JSON.stringify(options)}: gives from any point what the original gave, in every feed`, () => {
      const sim = simulate(preset(name));
      for (const how of FEEDS) {
        const steps = [...stepsOf(sliced(feed(sim.bytes, sim.timesUs, how)), lastTime(sim.timesUs))];
        expectRestoredSame(`${name}, ${how}`, steps, options, 40, sim.bytes.length);
      }
    });
  }

  it('every episode kept (settled ones shared between checkpoints): the same from any point', () => {
    for (const name of ['dropouts-failsafe', 'dropouts-and-damage']) {
      const sim = simulate(preset(name));
      for (const how of FEEDS) {
        const steps = [...stepsOf(sliced(feed(sim.bytes, sim.timesUs, how)), lastTime(sim.timesUs))];
        expectRestoredSame(`${name}, ${how}, all episodes`, steps, {}, 40, sim.bytes.length, ALL_EPISODES);
      }
    }
    const { bytes, times } = damagedStream('dsmx-11ms-2048-internal', 41, 8_000_000);
    const steps = [...stepsOf(feed(bytes, times, 'USB chunks'), lastTime(times))];
    expectRestoredSame('damaged, all episodes', steps, {}, 60, 9, ALL_EPISODES);
  });

  it('a day of holds stays linear: settled episodes are shared, never copied into each checkpoint', () => {
    // 20 minutes with a dropout every 2 s, each tenth a failsafe: two full blocks of the log and more
    // (an external remote read in 64-byte chunks, 88 ms of frames each: no batch is a hold).
    const dropouts = Array.from({ length: 600 }, (_, k) => ({ atUs: 1e6 + k * 2e6, durationUs: k % 10 === 0 ? 1_200_000 : 300_000 }));
    const sim = simulate({ ...preset('dsm2-22ms-1024-external'), dropouts }, 1_201_000_000);
    const decoder = new SpektrumDecoder();
    const link = new LinkMonitor({ jitterUs: 2000 });
    const taken: { cp: ReturnType<LinkMonitor['checkpoint']>; episodes: string; fed: number }[] = [];
    let nextUs = 10e6;
    let fed = 0;
    for (const push of feed(sim.bytes, sim.timesUs, '64-byte chunks, chunk times')) {
      const t = push.time as number;
      if (t >= nextUs) {
        taken.push({ cp: link.checkpoint(), episodes: JSON.stringify(link.episodes), fed });
        nextUs += 10e6;
      }
      decoder.push(push.bytes, t);
      for (let f = decoder.next(); f !== undefined; f = decoder.next()) link.frame(f);
      fed++;
    }
    expect(link.episodes.length).toBeGreaterThan(2 * 256);
    // Each checkpoint copies only the episodes still open to change (at most 64 holds wait to be
    // judged, and the silence still open), however many came before; full blocks are the same objects.
    const objects = new Set<object>();
    for (const { cp } of taken) {
      expect(cp.graph.episodes.length).toBeLessThanOrEqual(66);
      for (const block of cp.settled) for (const e of block) objects.add(e);
    }
    expect(objects.size).toBeLessThanOrEqual(link.episodes.length);
    const last = taken.at(-1)!.cp;
    expect(last.settled.length).toBeGreaterThanOrEqual(2);
    expect(taken[taken.length - 2]!.cp.settled[1]).toBe(last.settled[1]);
    // Restored (also after a structured clone, as a checkpoint crosses workers), a fresh monitor has
    // the episodes the original had there, and goes on to the same end.
    const final = JSON.stringify(link.episodes);
    const pushes = [...feed(sim.bytes, sim.timesUs, '64-byte chunks, chunk times')];
    for (const k of [3, 40, 77, taken.length - 1]) {
      const { cp, episodes, fed: at } = taken[k]!;
      const copy = new LinkMonitor({ jitterUs: 2000 });
      copy.restore(k % 2 === 0 ? cp : structuredClone(cp));
      expect(JSON.stringify(copy.episodes), `checkpoint ${k}`).toBe(episodes);
      expect(JSON.stringify(copy.checkpoint()), `checkpoint ${k} taken again`).toBe(JSON.stringify(cp));
      const d = new SpektrumDecoder();
      // The link alone is restored: a fresh decoder fed from a few chunks before gives the same frames from there.
      const lastUs = copy.lastFrameUs;
      for (const push of pushes.slice(Math.max(0, at - 4))) {
        d.push(push.bytes, push.time as number);
        for (let f = d.next(); f !== undefined; f = d.next()) if (f.timeUs > lastUs) copy.frame(f);
      }
      expect(JSON.stringify(copy.episodes), `checkpoint ${k}, fed to the end`).toBe(final);
    }
  });

  it('damaged streams (lost, stray, repeated bytes, flipped bits): the same from any point', () => {
    for (const [k, name] of ['dsmx-11ms-2048-internal', 'dsm2-22ms-1024-external', 'rssi-spm4649t', 'xplus-8'].entries()) {
      const { bytes, times } = damagedStream(name, 31 + k, 8_000_000);
      for (const how of ['USB chunks', 'random splits, no times'] as const) {
        const steps = [...stepsOf(feed(bytes, times, how), lastTime(times))];
        expectRestoredSame(`damaged ${name}, ${how}`, steps, {}, 60, 7 + k);
      }
    }
  });

  it("an external remote given the internal remote's resolution midway: the setting is part of the state", () => {
    const sim = simulate(preset('dsm2-22ms-1024-external'));
    const steps = [...stepsOf(feed(sim.bytes, sim.timesUs, 'USB chunks'), lastTime(sim.timesUs), 40)];
    expectRestoredSame('resolution set midway', steps, {}, 40, 5);
  });

  const px4 = resolve(import.meta.dirname, '../../shared/captures/px4');
  it.skipIf(!existsSync(px4))('the real PX4 captures, per-byte times and USB chunks: the same from any point', () => {
    for (const name of ['dsm_x_data.txt', 'dsm_x_dx9_data.txt', 'dsm_x_dx9_px4_binding_data.txt']) {
      const capture = importSaleaeCsv(new Uint8Array(readFileSync(join(px4, name))));
      const times = capture.byteTimesUs!;
      for (const how of ['whole, per-byte times', 'USB chunks'] as const) {
        const steps = [...stepsOf(sliced(feed(capture.bytes, times, how)), lastTime(times))];
        expectRestoredSame(`${name}, ${how}`, steps, {}, 40, 3);
      }
    }
  });

  it('a checkpoint is a few kilobytes: the bytes still undecided, never the stream before', () => {
    const sim = simulate(preset('dsmx-11ms-2048-internal'), 30_000_000);
    const p = pair({});
    for (const push of feed(sim.bytes, sim.timesUs, 'USB chunks')) {
      run(p, { kind: 'push', push });
      while (run(p, { kind: 'next' }).frame);
    }
    const cp = p.decoder.checkpoint();
    expect(p.decoder.stats.bytes).toBeGreaterThan(20_000);
    // Opaque, but plain data: what it costs to keep or post is its structured clone.
    const size = new TextEncoder().encode(
      JSON.stringify(cp, (_k, v: unknown) => (ArrayBuffer.isView(v) ? Array.from(v as Uint8Array) : v)),
    ).length;
    expect(size).toBeLessThan(8_000);
    expect(structuredClone(cp)).toEqual(cp);
  });
});
