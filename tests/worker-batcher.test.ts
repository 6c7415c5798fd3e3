/**
 * The batcher in Node with a fake clock: at most one batch per source every MIN_BATCH_MS however
 * often bytes come, the last change always delivered, idle ticks while live sources are quiet.
 */
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { Batcher, IDLE_TICK_MS, MIN_BATCH_MS } from '../src/worker/batcher.js';
import { Diagnosis } from '../src/worker/diagnosis.js';
import type { FromWorker } from '../src/worker/protocol.js';
import { SourceRegistry } from '../src/worker/registry.js';
import { usbChunks } from './feeds.js';
import { fakeHost } from './worker-fakes.js';

function setup() {
  const fake = fakeHost();
  const diagnosis = new Diagnosis(
    (m) => fake.host.post(m),
    () => 0,
    () => [],
    fake.clock,
  );
  const registry = new SourceRegistry(fake.host, diagnosis, { closing: async () => undefined, empty: () => undefined });
  let flushes = 0;
  const batcher = new Batcher(fake.host, registry, () => flushes++);
  const source = registry.add('demo', 0, 'Demo', 0);
  const sim = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 4 }, 2_000_000);
  const chunks = usbChunks(sim.bytes, sim.timesUs, 1_000);
  return { ...fake, registry, batcher, source, chunks, flushes: () => flushes };
}

describe('the batcher', () => {
  it('sends at most one batch per MIN_BATCH_MS however often bytes come, and the last change always', () => {
    const { clock, batcher, source, chunks, of, flushes } = setup();
    let k = 0;
    // A chunk every 1 ms for 200 ms, each followed by schedule(), as live data does.
    for (let ms = 0; ms < 200; ms++) {
      const c = chunks[k++]!;
      source.engine.push(c.bytes, c.timeUs, 0);
      batcher.schedule();
      clock.advance(1);
    }
    const batches = of('batches');
    expect(batches.length).toBeLessThanOrEqual(Math.ceil(200 / MIN_BATCH_MS) + 1);
    expect(batches.length).toBeGreaterThanOrEqual(Math.floor(200 / MIN_BATCH_MS) - 1);
    expect(flushes()).toBe(batches.length);
    // One more change after the last batch: it goes out once the window is over, not never.
    const c = chunks[k++]!;
    source.engine.push(c.bytes, c.timeUs, 0);
    batcher.schedule();
    clock.advance(MIN_BATCH_MS);
    const after = of('batches');
    expect(after.length).toBe(batches.length + 1);
    expect(after.at(-1)?.batches[0]?.batch.counters.bytes).toBe(source.engine.decoder.stats.bytes);
    // Nothing changed since: no timer waits, nothing more is sent.
    clock.advance(100);
    expect(of('batches')).toHaveLength(after.length);
    expect(clock.pending).toBe(0);
  });

  it("hands every frame's channel traces in the flush's one message, their arrays transferred, none twice", () => {
    const { clock, registry, source, chunks, host } = setup();
    const sent: { message: FromWorker; transfer: Transferable[] }[] = [];
    const batcher = new Batcher({ ...host, post: (message, transfer = []) => sent.push({ message, transfer }) }, registry, () => undefined);
    for (let k = 0; k < 300; k++) {
      const c = chunks[k]!;
      source.engine.push(c.bytes, c.timeUs, 0);
      batcher.schedule();
      clock.advance(1);
    }
    clock.advance(MIN_BATCH_MS);
    const times: number[] = [];
    for (const { message, transfer } of sent) {
      if (message.type !== 'batches') continue;
      for (const { batch } of message.batches) {
        times.push(...batch.traces.t);
        for (const a of [
          batch.traces.t,
          batch.traces.us,
          batch.traces.gap,
          batch.traces.spikes.t,
          batch.traces.spikes.channel,
          batch.traces.spikes.us,
        ])
          expect(transfer).toContain(a.buffer);
      }
      expect(new Set(transfer).size).toBe(transfer.length);
    }
    // Every frame decoded, once, in order: what a decoder fed the same bytes gives.
    const decoder = new SpektrumDecoder();
    for (const c of chunks.slice(0, 300)) decoder.push(c.bytes, c.timeUs);
    const want: number[] = [];
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) want.push(f.timeUs);
    expect(want.length).toBeGreaterThan(100);
    expect(times).toEqual(want);
    expect(sent.length).toBeLessThan(300 / MIN_BATCH_MS + 2);
  });

  it('flushes at once when the last batch is old enough', () => {
    const { clock, batcher, source, chunks, of } = setup();
    clock.advance(100);
    const c = chunks[0]!;
    source.engine.push(c.bytes, c.timeUs, 0);
    batcher.schedule();
    expect(of('batches')).toHaveLength(1);
  });

  it('ticks every IDLE_TICK_MS while live sources are quiet, and not after stop()', () => {
    const { clock, batcher, flushes } = setup();
    batcher.startTicks();
    batcher.startTicks(); // once is enough
    clock.advance(IDLE_TICK_MS * 4);
    expect(flushes()).toBe(4);
    batcher.stop();
    clock.advance(IDLE_TICK_MS * 4);
    expect(flushes()).toBe(4);
    expect(clock.pending).toBe(0);
  });

  it("judges each source at its own link time, as the registry's driver gives it", async () => {
    const { batcher, registry, source, chunks, of } = setup();
    await registry.use({
      kind: 'replay',
      clockUs: () => 0,
      clockRate: () => 1,
      linkNowUs: (id) => 5_000_000 + id * 1_000,
      stop: async () => undefined,
      release: async () => undefined,
    });
    const a = registry.add('replay', 0, 'A', 0);
    const b = registry.add('replay', 1, 'B', 0);
    expect(source.engine).not.toBe(a.engine);
    for (const s of [a, b]) s.engine.push(chunks[0]!.bytes, chunks[0]!.timeUs, 0);
    batcher.flush();
    // Both sources' batches in one message: the page applies them in one task.
    expect(of('batches').map((m) => m.batches.map((b) => [b.source, b.batch.nowUs]))).toEqual([
      [
        [0, 5_000_000],
        [1, 5_001_000],
      ],
    ]);
  });
});
