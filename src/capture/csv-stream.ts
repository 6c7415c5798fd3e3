/**
 * A Saleae async-serial CSV read a window at a time: the capture `importSaleaeCsv` makes of it
 * (every byte timed, one chunk a port, ports in order), without the file or its columns held. A
 * first pass reads every row (`SaleaeRows`, the importer's own rules) for the ports, their
 * names, the issues and the span; a walk of one port's windows reads the rows again and keeps
 * that port's, a window of `CAPTURE_CUT_BYTES` bytes at a time.
 *
 * Only a file whose times the time rule leaves alone streams so, and whose every port's times
 * never go back (the doctor then merges the ports' slices as the held capture's sort orders
 * them): a logic analyser's are. Anything else gives null: the caller reads the file whole.
 */
import { type ByteFile, PIECE_BYTES } from './byte-file.js';
import { CAPTURE_CUT_BYTES, type CaptureWindow, type StreamedCapture } from './capture-windows.js';
import type { CaptureMeta } from './model.js';
import { bomLength, LF, SaleaeRows } from './saleae.js';
import { timeInLine } from './time-rule.js';

/** Each row of `file` in order (`rows` holds its byte, time and port when `line` says it gave one), a piece at a time: it yields after each. */
function* eachRow(file: ByteFile, rows: SaleaeRows, row: () => void): Generator<void, void, undefined> {
  let size = file.size;
  let buf = new Uint8Array(PIECE_BYTES);
  let at = 0;
  let have = 0;
  let lineNo = 0;
  let first = true;
  while (at + have < size || have > 0) {
    const want = Math.min(buf.length - have, size - at - have);
    if (want > 0) {
      const got = file.read(buf.subarray(have, have + want), at + have);
      // A file that shrank since its size was taken ends where it ends now.
      if (got < want) size = at + have + got;
      have += got;
    }
    const ended = at + have >= size;
    rows.piece(buf, at);
    let pos = first ? bomLength(buf.subarray(0, have)) : 0;
    first = false;
    while (pos < have) {
      const nl = buf.indexOf(LF, pos);
      if ((nl < 0 || nl >= have) && !ended) break;
      const le = nl < 0 || nl >= have ? have : nl;
      lineNo++;
      if (rows.line(pos, le, lineNo)) row();
      pos = le + 1;
    }
    yield;
    if (ended && pos >= have) return;
    // The line not yet whole goes to the front of the buffer (a longer one for a long line): the
    // one buffer serves the whole walk (a row's byte and time are copied out of it).
    const rest = have - Math.min(pos, have);
    if (rest * 2 > buf.length) {
      const next = new Uint8Array(rest * 2);
      next.set(buf.subarray(have - rest, have));
      buf = next;
    } else buf.copyWithin(0, have - rest, have);
    at += have - rest;
    have = rest;
  }
}

/** `file`, a Saleae CSV, as `importSaleaeCsv` reads it, a window at a time; null when it must be read whole (see above). */
export function streamCsv(file: ByteFile): StreamedCapture | null {
  const rows = new SaleaeRows();
  const counts = new Float64Array(256);
  const firstUs = new Float64Array(256).fill(NaN);
  const lastUs = new Float64Array(256).fill(NaN);
  let inOrder = true;
  const walk = eachRow(file, rows, () => {
    const { port, timeUs } = rows;
    const last = lastUs[port] ?? NaN;
    // In line by the rule (plausible, following the last), and never back (the doctor's order).
    if (!timeInLine(last, timeUs) || timeUs < last) inOrder = false;
    if (Number.isNaN(last)) firstUs[port] = timeUs;
    lastUs[port] = timeUs;
    counts[port] = (counts[port] ?? 0) + 1;
  });
  try {
    for (const _ of walk);
  } catch {
    // Not a Saleae CSV: importSaleaeCsv says so.
    return null;
  }
  const portCount = Math.max(1, rows.portNames.size);
  let total = 0;
  for (let p = 0; p < portCount; p++) total += counts[p] ?? 0;
  if (rows.cols === undefined || total === 0 || !inOrder) return null;
  const meta: CaptureMeta = { source: 'saleae-csv' };
  if (rows.portNames.size > 0) meta.ports = [...rows.portNames.keys()].map((name) => ({ name }));
  const ports = Array.from({ length: portCount }, (_, p) => p);
  // The span: per-byte chunks span their first to their last byte (times in order: the port's first and last).
  let startUs = Infinity;
  let endUs = -Infinity;
  for (const p of ports) {
    if ((firstUs[p] ?? NaN) < startUs) startUs = firstUs[p] ?? NaN;
    if ((lastUs[p] ?? NaN) > endUs) endUs = lastUs[p] ?? NaN;
  }
  const counted = ports.map((p) => counts[p] ?? 0);
  return {
    kind: 'saleae-csv',
    meta,
    timing: 'per-byte',
    events: [],
    issues: rows.issues,
    dataBytes: total,
    ports,
    span: startUs <= endUs ? { startUs, endUs } : { startUs: NaN, endUs: NaN },
    windows: (port?: number) => (port === undefined ? allPorts(file, counted) : portWindows(file, counted, port)),
  };
}

/** Every port's windows, port after port (the held capture's order). */
function* allPorts(file: ByteFile, counts: readonly number[]): Generator<CaptureWindow, void, undefined> {
  for (let p = 0; p < counts.length; p++) yield* portWindows(file, counts, p);
}

/** Port `port`'s chunk (chunk `port`), read from the file a window at a time. */
function* portWindows(file: ByteFile, counts: readonly number[], port: number): Generator<CaptureWindow, void, undefined> {
  const total = counts[port] ?? 0;
  let byteOffset = 0;
  for (let p = 0; p < port; p++) byteOffset += counts[p] ?? 0;
  const rows = new SaleaeRows();
  const ready: CaptureWindow[] = [];
  let data = new Uint8Array(CAPTURE_CUT_BYTES);
  let times = new Float64Array(CAPTURE_CUT_BYTES);
  let n = 0;
  let done = 0;
  const close = (): void => {
    if (n === 0) return;
    ready.push({
      bytes: data.subarray(0, n),
      chunkEnds: Uint32Array.of(n),
      chunkTimesUs: Float64Array.of(times[n - 1] ?? NaN),
      chunkPorts: Uint8Array.of(port),
      byteTimesUs: times.subarray(0, n),
      firstChunk: port,
      byteOffset: byteOffset + done,
      headBefore: done,
      tailAfter: total - done - n,
    });
    done += n;
    n = 0;
    data = new Uint8Array(CAPTURE_CUT_BYTES);
    times = new Float64Array(CAPTURE_CUT_BYTES);
  };
  const walk = eachRow(file, rows, () => {
    if (rows.port !== port) return;
    data[n] = rows.value;
    times[n] = rows.timeUs;
    if (++n === CAPTURE_CUT_BYTES) close();
  });
  for (const _ of walk) yield* ready.splice(0);
  close();
  yield* ready.splice(0);
}
