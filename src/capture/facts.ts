/**
 * Facts worked out from a capture's columns (here its ports with their chunk counts, whether its
 * times are in order and each port's chunk numbers; its span in the analysis), kept with the
 * capture: the surfaces that each ask for them (a report and its jobs, a replay's session and its
 * source) then pay one pass over the chunks, not one each; a day-long capture has eleven million.
 *
 * A capture's columns are typed arrays nobody writes once the capture is made. A fact is
 * worked out again when the capture's chunk columns or events are no longer the ones it was
 * worked out from (an object spread with new columns is another capture anyway).
 */
import type { Capture } from './model.js';
import { type AnyCapture, isStreamed, type StreamedCapture } from './capture-windows.js';

interface Kept {
  chunkEnds: Uint32Array;
  chunkTimesUs: Float64Array;
  chunkPorts: Uint8Array;
  byteTimesUs: Float64Array | undefined;
  events: Capture['events'];
  eventCount: number;
  facts: Map<string, unknown>;
}

const kept = new WeakMap<Capture, Kept>();

/** A streamed capture's facts: it has no columns to change. */
const keptStreamed = new WeakMap<StreamedCapture, Map<string, unknown>>();

/** The facts' names (`captureFact`). */
const PORT_CHUNKS = 'port chunks';
const TIMES_IN_ORDER = 'times in order';
const PORT_INDEX = 'port index';

/** The facts kept for `capture`, made afresh when its columns or events are not the ones they came from. */
function factsOf(capture: AnyCapture): Map<string, unknown> {
  if (isStreamed(capture)) {
    let facts = keptStreamed.get(capture);
    if (facts === undefined) keptStreamed.set(capture, (facts = new Map()));
    return facts;
  }
  const { chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs, events } = capture;
  let k = kept.get(capture);
  if (
    k === undefined ||
    k.chunkEnds !== chunkEnds ||
    k.chunkTimesUs !== chunkTimesUs ||
    k.chunkPorts !== chunkPorts ||
    k.byteTimesUs !== byteTimesUs ||
    k.events !== events ||
    k.eventCount !== events.length
  ) {
    k = { chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs, events, eventCount: events.length, facts: new Map() };
    kept.set(capture, k);
  }
  return k.facts;
}

/** `work(capture)`, worked out once per capture and `name` (see above); the caller copies what it hands out. */
export function captureFact<C extends AnyCapture, T>(capture: C, name: string, work: (capture: C) => T): T {
  const facts = factsOf(capture);
  if (facts.has(name)) return facts.get(name) as T;
  const fact = work(capture);
  facts.set(name, fact);
  return fact;
}

/** The port indices that have at least one data chunk, in increasing order (one pass per capture: `captureFact`). */
export function capturePorts(capture: AnyCapture): number[] {
  if (isStreamed(capture)) return [...capture.ports];
  const counts = captureFact(capture, PORT_CHUNKS, chunksByPort);
  const ports: number[] = [];
  for (let p = 0; p < 256; p++) if ((counts[p] ?? 0) > 0) ports.push(p);
  return ports;
}

/** How many data chunks each port (0–255) has (the same pass as `capturePorts`). */
export function captureChunksByPort(capture: Capture): Uint32Array {
  return captureFact(capture, PORT_CHUNKS, chunksByPort).slice();
}

function chunksByPort(capture: Capture): Uint32Array {
  const counts = new Uint32Array(256);
  const chunkPorts = capture.chunkPorts;
  for (let i = 0; i < chunkPorts.length; i++) {
    const p = chunkPorts[i] ?? 0;
    counts[p] = (counts[p] ?? 0) + 1;
  }
  return counts;
}

/**
 * Whether the chunks' recorded times never go back (each at or after the one before it, none
 * NaN), as recorded captures' do: then the first chunk at or after a time is found by bisection.
 * One pass per capture (`captureFact`).
 */
export function captureTimesInOrder(capture: Capture): boolean {
  return captureFact(capture, TIMES_IN_ORDER, timesInOrder);
}

function timesInOrder(capture: Capture): boolean {
  const times = capture.chunkTimesUs;
  if (times.length > 0 && Number.isNaN(times[0] ?? Number.NaN)) return false;
  for (let i = 1; i < times.length; i++) if (!((times[i] ?? Number.NaN) >= (times[i - 1] ?? Number.NaN))) return false;
  return true;
}

/**
 * Each port's chunks (0–255, empty for a port without any): the capture's chunk numbers, in
 * order. One counting sort over the chunks, once per capture (`captureFact`); the arrays are
 * handed out as they are kept: not to be written (a day-long capture's are 44 MB).
 */
export function capturePortIndex(capture: Capture): readonly Uint32Array[] {
  return captureFact(capture, PORT_INDEX, portIndex);
}

function portIndex(capture: Capture): Uint32Array[] {
  return indexByPort(capture.chunkPorts, captureFact(capture, PORT_CHUNKS, chunksByPort));
}

/** Each port's chunk numbers, from each chunk's port and the counts by port: views of one array of every chunk, sorted by port (a counting sort). */
function indexByPort(chunkPorts: Uint8Array, counts: Uint32Array): Uint32Array[] {
  const at = new Uint32Array(256);
  for (let p = 1; p < 256; p++) at[p] = (at[p - 1] ?? 0) + (counts[p - 1] ?? 0);
  const starts = at.slice();
  const all = new Uint32Array(chunkPorts.length);
  for (let i = 0; i < chunkPorts.length; i++) {
    const p = chunkPorts[i] ?? 0;
    const k = at[p] ?? 0;
    all[k] = i;
    at[p] = k + 1;
  }
  return Array.from(starts, (start, p) => all.subarray(start, start + (counts[p] ?? 0)));
}
