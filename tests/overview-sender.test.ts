/**
 * A long capture's growing overview, sent as it is read (overview-sender.ts): at most once a
 * second, never one that reads less far than the last, nothing after the complete one; and the
 * first with anything read at once, not a second after the empty one that showed the span.
 */
import { describe, expect, it } from 'vitest';
import type { Overview } from '../src/worker/protocol.js';
import { OverviewSender } from '../src/worker/replay/overview-sender.js';
import { fakeHost } from './worker-fakes.js';

/** An overview of `bins` whole seconds from 0, read to their end. */
function overview(bins: number, complete = false): Overview {
  return {
    t: Float64Array.from({ length: bins }, (_, i) => i * 1e6),
    binUs: 1e6,
    fadeRate: new Float32Array(bins),
    lost: new Float32Array(bins),
    failsafe: [],
    readUntilUs: bins * 1e6,
    complete,
  };
}

describe('the growing overview sent to the page', () => {
  it('sends the first with anything read at once, then no more than once a second, never one read less far, nothing after the complete one', () => {
    const { host, clock, of } = fakeHost();
    const sender = new OverviewSender(host);
    const sent = () => of('overview').map((m) => [m.overview.readUntilUs / 1e6, m.overview.complete]);
    expect(sender.due()).toBe(true);
    // One offered before anything is read: the span alone, hatched.
    sender.offer(overview(0));
    clock.advance(250);
    expect(sender.due()).toBe(true);
    sender.offer(overview(3));
    expect(sent()).toEqual([
      [0, false],
      [3, false],
    ]);
    clock.advance(250);
    expect(sender.due()).toBe(false);
    clock.advance(750);
    expect(sender.due()).toBe(true);
    // One read less far (a half catching up) is not sent.
    sender.offer(overview(2));
    expect(sent().length).toBe(2);
    sender.offer(overview(9));
    sender.offer(overview(10, true));
    sender.offer(overview(11, true));
    expect(sent().slice(2)).toEqual([
      [9, false],
      [10, true],
    ]);
    expect(sender.due()).toBe(false);
  });
});
