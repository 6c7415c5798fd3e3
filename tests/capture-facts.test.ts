/**
 * Facts kept with a capture (`captureFact`): its ports, their chunk counts and its span are worked out once, copied when
 * handed out, and worked out again when the capture's columns or events are not the ones they
 * came from.
 */
import { describe, expect, it } from 'vitest';
import { captureSpan } from '../src/report/capture-span.js';
import { captureChunksByPort, captureFact, capturePortIndex, capturePorts, captureTimesInOrder } from '../src/capture/facts.js';
import type { Capture } from '../src/capture/model.js';

function capture(ports: number[], times: number[]): Capture {
  return {
    kind: 'raw',
    meta: {},
    timing: 'per-chunk',
    bytes: new Uint8Array(ports.length),
    chunkEnds: Uint32Array.from(ports, (_, i) => i + 1),
    chunkTimesUs: Float64Array.from(times),
    chunkPorts: Uint8Array.from(ports),
    events: [],
    issues: [],
  };
}

describe('facts kept with a capture', () => {
  it('works a fact out once per capture and name', () => {
    const c = capture([0, 1], [10, 20]);
    let work = 0;
    const count = (): number => ++work;
    expect([captureFact(c, 'n', count), captureFact(c, 'n', count)]).toEqual([1, 1]);
    expect(captureFact(c, 'other', count)).toBe(2);
    expect(captureFact(capture([0, 1], [10, 20]), 'n', count)).toBe(3);
  });

  it('hands out copies: a caller that changes what it got changes nothing for the next', () => {
    const c = capture([2, 0, 2], [10, 20, 30]);
    const ports = capturePorts(c);
    ports.push(9);
    expect(capturePorts(c)).toEqual([0, 2]);
    const counts = captureChunksByPort(c);
    expect([counts.length, counts[0], counts[1], counts[2]]).toEqual([256, 1, 0, 2]);
    counts[2] = 0;
    expect(captureChunksByPort(c)[2]).toBe(2);
    expect(capturePorts(c)).toEqual([0, 2]);
    const span = captureSpan(c);
    span.startUs = -1;
    expect(captureSpan(c)).toEqual({ startUs: 10, endUs: 30 });
  });

  it('tells whether the chunk times never go back: equal times are in order, a step back or a NaN is not', () => {
    expect(captureTimesInOrder(capture([0, 1, 0], [10, 10, 20]))).toBe(true);
    expect(captureTimesInOrder(capture([], []))).toBe(true);
    expect(captureTimesInOrder(capture([0, 1, 0], [10, 30, 20]))).toBe(false);
    expect(captureTimesInOrder(capture([0, 1], [Number.NaN, 20]))).toBe(false);
    expect(captureTimesInOrder(capture([0, 1], [10, Number.NaN]))).toBe(false);
  });

  it('gives each port its chunk numbers in order, none to a port without chunks', () => {
    const index = capturePortIndex(capture([2, 0, 2, 255, 0, 2], [1, 2, 3, 4, 5, 6]));
    expect(index.length).toBe(256);
    expect([index[0], index[1], index[2], index[255]].map((a) => Array.from(a ?? [9]))).toEqual([[1, 4], [], [0, 2, 5], [3]]);
  });

  it('works it out again when the events or a column are no longer the ones it came from', () => {
    const c = capture([0], [100]);
    expect(captureSpan(c)).toEqual({ startUs: 100, endUs: 100 });
    (c.events as Capture['events'][number][]).push({ timeUs: 500, port: 0, text: 'port closed', chunkIndex: 1 });
    expect(captureSpan(c)).toEqual({ startUs: 100, endUs: 500 });
    const moved = Object.assign(c, { chunkPorts: Uint8Array.from([3]) });
    expect(capturePorts(moved)).toEqual([3]);
    const later = Object.assign(c, { chunkTimesUs: Float64Array.from([50]) });
    expect(captureSpan(later)).toEqual({ startUs: 50, endUs: 500 });
  });
});
