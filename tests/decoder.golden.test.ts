/**
 * The decoder's output as it stands, kept in tests/golden/: every fixture, every port of every
 * real capture in ../shared/captures and damaged simulator streams of every preset, under every
 * option and however the bytes come, decode to the frames (every field), the events (in order),
 * the counters and the format recorded there. One digest a case, and the default case's
 * counters and format in the clear, to show what moved when one fails.
 *
 * A restructuring of the decoder must leave these as they are. `npm run golden` writes them
 * again: only for a change of output that is meant, said in its commit.
 */
import { createHash } from 'node:crypto';
import { readdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import { describe, expect, it } from 'vitest';
import { CAPTURE_DIR, filesUnder } from './shared-captures.js';
import { captureChunks } from '../src/capture/model.js';
import { capturePorts } from '../src/capture/facts.js';
import { readCapture } from '../src/capture/sniff.js';
import type { DecodedFrame, DecoderEvent } from '../src/decoder/types.js';
import { type DecoderOptions, SpektrumDecoder } from '../src/decoder/decoder.js';
import { CLEAN_PRESETS } from './damage.js';
import { damagedStream, FEEDS, feed, OPTIONS, type Push } from './decoder-streams.js';

/** A frame as one line of text: every field a caller may read. */
function frameLine(f: DecodedFrame): string {
  const vtx = f.vtx === null ? '' : JSON.stringify(f.vtx);
  return [
    f.index,
    f.offset,
    Object.is(f.timeUs, -0) ? '-0' : String(f.timeUs),
    f.remote,
    f.system,
    f.resolution,
    f.fades,
    f.fadesDelta,
    f.rssi,
    f.count,
    Array.from(f.ids.subarray(0, f.count)).join(','),
    Array.from(f.positions.subarray(0, f.count)).join(','),
    Array.from(f.words).join(','),
    Array.from(f.bytes).join(','),
    vtx,
  ].join(' ');
}

interface Outcome {
  frames: number;
  /** sha-256 (first 16 hex digits) of every frame, event and counter line in order, and the format. */
  digest: string;
  stats: unknown;
  format: unknown;
}

/** Decodes `pushes` under `options`: what came out, digested. */
function outcome(pushes: Iterable<Push>, options: DecoderOptions): Outcome {
  const hash = createHash('sha256');
  const asJson = (e: DecoderEvent) => JSON.stringify(e, (_k, v: unknown) => (v instanceof Uint8Array ? Array.from(v) : v));
  const decoder = new SpektrumDecoder({ ...options, onEvent: (e) => hash.update(`event ${asJson(e)}\n`) });
  let frames = 0;
  const drain = () => {
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) {
      hash.update(`${frameLine(f)}\n`);
      frames++;
    }
    hash.update(`stats ${JSON.stringify(decoder.stats)}\n`);
  };
  for (const p of pushes) {
    decoder.push(p.bytes, p.time);
    drain();
  }
  decoder.end();
  drain();
  const format = JSON.parse(JSON.stringify(decoder.format)) as unknown;
  hash.update(`format ${JSON.stringify(format)}\n`);
  return { frames, digest: hash.digest('hex').slice(0, 16), stats: { ...decoder.stats }, format };
}

const key = (o: DecoderOptions): string => `${o.resolution ?? 'auto'} ${o.remote ?? 'auto'} ${o.headerMode ?? 'auto'}`;

/** `options` and feeds of one stream: `{ "<options> | <feed>": "<frames> <digest>" }`, and the default case in the clear. */
function golden(cases: { feed: string; pushes: () => Iterable<Push> }[], every: readonly DecoderOptions[] = OPTIONS): string {
  const out: Record<string, unknown> = {};
  for (const c of cases) {
    for (const options of every) {
      const o = outcome(c.pushes(), options);
      out[`${key(options)} | ${c.feed}`] = `${o.frames} ${o.digest}`;
      if (key(options) === 'auto auto auto' && c === cases[0]) out.default = { stats: o.stats, format: o.format };
    }
  }
  return `${JSON.stringify(out, null, 2)}\n`;
}

const file = (name: string) => join(import.meta.dirname, 'golden', `${name.replace(/[^\w.-]+/g, '_')}.json`);

const fixtureDir = join(import.meta.dirname, 'fixtures');
const fixtures = readdirSync(fixtureDir)
  .filter((f) => f.endsWith('.bin'))
  .map((f) => f.replace('.bin', ''));

const captures = filesUnder(CAPTURE_DIR).filter((f) => !/\.md$/i.test(f) && !/readme/i.test(f));

describe("the decoder's output is what tests/golden/ holds", () => {
  it.each(fixtures)('fixture %s, every option, every feed', async (name) => {
    const bytes = new Uint8Array(readFileSync(join(fixtureDir, `${name}.bin`)));
    const raw = readFileSync(join(fixtureDir, `${name}.times.f64`));
    const times = new Float64Array(raw.buffer.slice(raw.byteOffset, raw.byteOffset + raw.byteLength));
    await expect(golden(FEEDS.map((how) => ({ feed: how, pushes: () => feed(bytes, times, how) })))).toMatchFileSnapshot(
      file(`fixture-${name}`),
    );
  });

  if (captures.length === 0) console.warn(`skipping the real captures in the golden test: ${CAPTURE_DIR} is not here`);
  it.skipIf(captures.length === 0).each(captures)('real capture %s, every port, every option, as recorded', async (name) => {
    let capture: ReturnType<typeof readCapture>;
    try {
      capture = readCapture(new Uint8Array(readFileSync(join(CAPTURE_DIR, name))), name);
    } catch {
      return; // a note, not a capture (the fast-path test checks which)
    }
    const cases = capturePorts(capture).map((port) => ({ feed: `port ${port} as recorded`, pushes: () => captureChunks(capture, port) }));
    await expect(golden(cases)).toMatchFileSnapshot(file(`capture-${name}`));
  });

  it.each(CLEAN_PRESETS)('damaged 30 s simulator stream %s, seeds 1 and 2, every feed, auto and forced', async (name) => {
    const cases = [1, 2].flatMap((seed) => {
      const { bytes, times } = damagedStream(name, seed, 30_000_000);
      return FEEDS.map((how) => ({ feed: `seed ${seed}, ${how}`, pushes: () => feed(bytes, times, how) }));
    });
    const forced: DecoderOptions = { resolution: name.includes('1024') ? 1024 : 2048 };
    await expect(golden(cases, [{}, forced])).toMatchFileSnapshot(file(`damaged-${name}`));
  });
});
