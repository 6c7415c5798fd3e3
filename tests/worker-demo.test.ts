/**
 * The demo receiver in the worker, on a fake clock: its simulated remotes keep their own time,
 * so a worker starved of its timers neither loses frames nor shows a hold or failsafe that the
 * scenario does not have.
 */
import { describe, expect, it } from 'vitest';
import { Dispatcher } from '../src/worker/dispatcher.js';
import type { Batch } from '../src/worker/protocol.js';
import { fakeHost } from './worker-fakes.js';

/** Runs the demo for `ms` of wall time, `stall` (start and length, ms) starving the worker; each remote's last batch. */
async function runDemo(ms: number, stall?: { atMs: number; forMs: number }): Promise<Map<number, Batch>> {
  const fake = fakeHost();
  const worker = new Dispatcher(fake.host, { makeReport: async () => ({ data: new ArrayBuffer(0) }) });
  worker.receive({ type: 'demo-start' });
  await worker.queue.idle();
  if (stall === undefined) fake.clock.advance(ms);
  else {
    fake.clock.advance(stall.atMs);
    fake.clock.stall(stall.forMs);
    fake.clock.advance(ms - stall.atMs - stall.forMs);
  }
  worker.batcher.flush();
  const last = new Map<number, Batch>();
  for (const { source, batch } of fake.batches()) last.set(source, batch);
  worker.receive({ type: 'demo-stop' });
  await worker.queue.idle();
  return last;
}

const figures = (b: Batch | undefined) =>
  b === undefined
    ? undefined
    : {
        frames: b.counters.frames,
        holds: b.link.holds,
        failsafes: b.link.failsafes,
        missed: b.link.missedFrames,
        fades: b.link.fades,
        state: b.link.state,
      };

describe('the demo receiver', () => {
  it('delivers the frames a starved worker owes at their simulated times: no hold, failsafe or missed frame', async () => {
    // The scenario's first dropout is at 4 s (remote A): 3.5 s are clean on both remotes.
    const clean = await runDemo(3500);
    const starved = await runDemo(3500, { atMs: 1000, forMs: 1500 });
    expect(clean.size).toBe(2);
    for (const id of [0, 1]) {
      expect(figures(clean.get(id))).toMatchObject({ holds: 0, failsafes: 0, state: 'live' });
      expect(figures(starved.get(id))).toEqual(figures(clean.get(id)));
    }
    expect(clean.get(0)?.counters.frames).toBeGreaterThan(300);
  });

  it("still shows the scenario's own dropouts, stall or not", async () => {
    // Remote A drops out at 4 s for 0.25 s: one hold, whether or not the worker starves over it.
    const clean = await runDemo(5000);
    const starved = await runDemo(5000, { atMs: 3900, forMs: 800 });
    expect(clean.get(0)?.link.holds).toBe(1);
    expect(figures(starved.get(0))).toEqual(figures(clean.get(0)));
  });

  it('pauses its simulation over a stall too long to catch up, and counts nothing for the pause', async () => {
    // A minute starved: 10 s of it are caught up, the other 50 s the simulation stood still, so
    // 63.5 s of wall time are 13.5 s of simulation, dropouts (A at 4 s, B at 12 s) and all.
    const clean = await runDemo(13_500);
    const starved = await runDemo(63_500, { atMs: 500, forMs: 60_000 });
    expect(clean.get(1)?.link.holds).toBe(1);
    for (const id of [0, 1]) expect(figures(starved.get(id))).toEqual(figures(clean.get(id)));
  });
});
