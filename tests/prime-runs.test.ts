/**
 * A record walk's per-run methods are called empty before their first run (prime-runs.ts), so
 * that the engine compiles their loop with feedback for what follows it. The calls must be more
 * than the engine waits for, and must change nothing.
 */
import { describe, expect, it, vi } from 'vitest';
import { CaptureBuilder } from '../src/capture/capture-builder.js';
import { RecordTally } from '../src/capture/record-tally.js';
import { primeRuns } from '../src/capture/prime-runs.js';

describe('primeRuns', () => {
  it('calls the run more than eight times (V8 keeps type feedback from about the ninth call), each on an empty range', () => {
    const calls: [number, number, number, number][] = [];
    primeRuns((bytes, view, from, to) => calls.push([bytes.length, view.byteLength, from, to]));
    expect(calls.length).toBeGreaterThan(8);
    for (const call of calls) expect(call).toEqual([0, 0, 0, 0]);
  });

  it('is what a new capture builder and a new record tally do first', () => {
    for (const Walker of [CaptureBuilder, RecordTally]) {
      const records = vi.spyOn(Walker.prototype, 'records');
      new Walker(86.8);
      expect(records.mock.calls.length).toBeGreaterThan(8);
      records.mockRestore();
    }
  });

  it('leaves a new capture builder and a new record tally with nothing recorded', () => {
    const capture = new CaptureBuilder().capture({ meta: {}, version: 1, headerLength: 16 });
    expect([capture.bytes.length, capture.chunkEnds.length, capture.events.length, capture.timing]).toEqual([0, 0, 0, 'none']);
    const facts = new RecordTally(86.8).facts();
    expect(facts.chunksByPort.every((n) => n === 0)).toBe(true);
    expect([facts.timesInOrder, facts.firstUs, facts.lastUs]).toEqual([true, Number.POSITIVE_INFINITY, Number.NEGATIVE_INFINITY]);
  });
});
