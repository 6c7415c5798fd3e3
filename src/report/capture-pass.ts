/**
 * One decoding pass over one port of a capture: the bytes go once through the port's decoder,
 * and each frame, once, to everything that reads it (the link monitor, its binned series, the
 * caller's own reading, and the doctor when one listens). `satscope info`, `satscope report`,
 * the report's diagnosis and the page's replay overview all decode through here, so a port's
 * frames, missed frames and episodes are the same on every surface, and a report decodes each
 * port once.
 *
 * Chunks are read straight from the capture's columns (no object per chunk), and the capture's
 * span (`captureSpan`) is one pass over its chunk times, taken once by the caller.
 */
import type { Capture, CaptureEvent, CaptureTiming } from '../capture/model.js';
import { type AnyCapture, captureWindows, isStreamed } from '../capture/capture-windows.js';
import { SpektrumDecoder, type DecoderOptions } from '../decoder/decoder.js';
import { USB_CHUNK_JITTER_US } from '../decoder/spec.js';
import type { DecodedFrame } from '../decoder/types.js';
import type { LinkMonitor } from '../decoder/link.js';
import type { Doctor } from './doctor.js';
import { doctorEvent, stopsPort } from './doctor-events.js';
import { SCAN_MEMORY, startsCandidate } from './doctor-line.js';
import { lineWindow } from './doctor-state.js';
import { LinkSeries, monitorWithSeries } from './series.js';
import { captureSpan } from './capture-span.js';

/** How `decodeCapture` reads a port: decoder options, the port, the series' bins, where the span starts and ends, and a doctor to listen. */
export interface DecodeCaptureOptions extends DecoderOptions {
  /** Which serial port of a multi-port capture to decode. Default 0. */
  port?: number;
  /** Width of the bins of the returned `series`, µs. Default 1 s. */
  binUs?: number;
  /** Start of the series' bin 0, µs. Default: the capture's first recorded time (`captureSpan`). */
  originUs?: number;
  /** Where the capture ends, µs: the link is finished there. Default: the capture's last recorded time (`captureSpan`). */
  endUs?: number;
  /**
   * A doctor to feed this port to as well (its bytes, its recorded events, its frames after the
   * link monitor counted them), attached under the port's name from the metadata. A timed
   * capture only: without timing the doctor needs a clock of its own (`doctorCapture`).
   */
  doctor?: Doctor;
  /**
   * The doctor's findings will be taken only at `endUs` (a whole capture's diagnosis). Then the
   * foreign packets it could find before its line window at that time (`lineWindow`) cannot
   * count, and the bytes that could only show those are not scanned (`firstScanned`): the same
   * findings for less work.
   */
  doctorJudgedAtEnd?: boolean;
}

/** The delivery jitter to assume for a capture's timing until it is measured: USB batching for chunk times, none for a logic analyser's. */
export function timingJitterUs(timing: CaptureTiming): number {
  return timing === 'per-chunk' ? USB_CHUNK_JITTER_US : 0;
}

/**
 * Bytes of a per-byte chunk pushed at once: about 20 ms of a satellite stream, as a USB adapter
 * would deliver it. The decoder's frames do not depend on it; the doctor books what it scans at
 * the time of each piece's last byte, so the doctor's own replay (`doctorCapture`) cuts the same.
 */
export const SLICE_BYTES = 256;

/**
 * Bytes of an untimed chunk pushed at once. A timed chunk is pushed whole: its time is its last
 * byte's, and a piece of it would stamp its earlier bytes with that. (Untimed chunks go to no
 * doctor: `decodeCapture` takes one only with a timed capture, where no chunk is untimed.)
 */
const UNTIMED_PIECE_BYTES = 1 << 16;

/**
 * Where the doctor's packet scan of `port` must start (a chunk and a byte in it) for the packets
 * it books from `fromUs` on to be exactly those a scan of every byte books, when nothing else of
 * the scan is read. Packets are booked at the time of the chunk their last byte came in, so
 * chunks before the first one timed `fromUs` or later (or untimed: booked at an earlier chunk's
 * time) book only before `fromUs`. The scanner's state at that chunk depends only on the bytes
 * before it back to the last `SCAN_MEMORY` of them without a `startsCandidate` byte, so the scan
 * starts there (or at the port's first byte when there is no such stretch).
 */
export function firstScanned(capture: Capture, port: number, fromUs: number): { chunk: number; offset: number } {
  const { bytes, chunkEnds, chunkTimesUs, chunkPorts } = capture;
  let first = chunkEnds.length;
  for (let i = 0; i < chunkEnds.length; i++) {
    if (chunkPorts[i] === port && !((chunkTimesUs[i] ?? NaN) < fromUs)) {
      first = i;
      break;
    }
  }
  // Back from there through the port's earlier bytes, for SCAN_MEMORY in a row that start nothing.
  let clean = 0;
  for (let i = first - 1; i >= 0; i--) {
    if (chunkPorts[i] !== port) continue;
    const from = i > 0 ? (chunkEnds[i - 1] ?? 0) : 0;
    for (let b = (chunkEnds[i] ?? 0) - 1; b >= from; b--) {
      if (startsCandidate(bytes[b] ?? 0)) clean = 0;
      else if (++clean === SCAN_MEMORY) return { chunk: i, offset: b - from };
    }
  }
  return { chunk: 0, offset: 0 };
}

/**
 * `firstScanned` of a capture read a window at a time, walking forward to where the backward walk
 * starts: the place it finds is the start of the last `SCAN_MEMORY` bytes of the port's last
 * stretch of `SCAN_MEMORY` or more that start nothing, before the first chunk timed `fromUs` or
 * later. The port's last `SCAN_MEMORY` bytes' places are kept in a ring to say where that is.
 */
export function firstScannedStreamed(capture: AnyCapture, port: number, fromUs: number): { chunk: number; offset: number } {
  const ringChunk = new Float64Array(SCAN_MEMORY);
  const ringOffset = new Float64Array(SCAN_MEMORY);
  let found = { chunk: 0, offset: 0 };
  let clean = 0;
  let k = 0;
  for (const w of captureWindows(capture, port)) {
    const { bytes, chunkEnds, chunkTimesUs, chunkPorts } = w;
    let from = 0;
    for (let i = 0; i < chunkEnds.length; i++) {
      const to = chunkEnds[i] ?? from;
      if (chunkPorts[i] === port) {
        if (!((chunkTimesUs[i] ?? NaN) < fromUs)) return found;
        const chunk = w.firstChunk + i;
        const head = i === 0 ? w.headBefore : 0;
        for (let b = from; b < to; b++) {
          ringChunk[k] = chunk;
          ringOffset[k] = b - from + head;
          k = (k + 1) % SCAN_MEMORY;
          if (startsCandidate(bytes[b] ?? 0)) clean = 0;
          else if (++clean >= SCAN_MEMORY) found = { chunk: ringChunk[k] ?? 0, offset: ringOffset[k] ?? 0 };
        }
      }
      from = to;
    }
  }
  return found;
}

/** The capture's events on `port`, in the order they were recorded among the chunks. */
function portEvents(capture: AnyCapture, port: number): CaptureEvent[] {
  return capture.events.filter((e) => e.port === port).sort((a, b) => a.chunkIndex - b.chunkIndex);
}

/**
 * Feeds one port of a capture through a decoder and a link monitor, chunk by chunk with the
 * chunk's recorded time, as live data would arrive, and ends the link at the capture's end
 * (`captureSpan`), as replay does. `onFrame` gets each borrowed frame and the link monitor,
 * which has already counted it (and so has the doctor, when one listens). `series` holds the
 * link's binned series.
 */
export function decodeCapture(
  capture: AnyCapture,
  options: DecodeCaptureOptions,
  onFrame: (frame: DecodedFrame, link: LinkMonitor) => void,
): { decoder: SpektrumDecoder; link: LinkMonitor; series: LinkSeries } {
  const { port = 0, binUs = 1_000_000, originUs, endUs, doctor, doctorJudgedAtEnd = false, ...decoderOptions } = options;
  const span = originUs === undefined || endUs === undefined ? captureSpan(capture) : { startUs: originUs, endUs };
  const end = endUs ?? span.endUs;
  const decoder = new SpektrumDecoder(decoderOptions);
  const series = new LinkSeries(binUs, originUs ?? span.startUs);
  const link = monitorWithSeries({ jitterUs: timingJitterUs(capture.timing) }, series);
  if (doctor !== undefined && capture.timing === 'none')
    throw new TypeError('decodeCapture: a doctor needs a timed capture (doctorCapture gives an untimed one a clock)');
  const events = portEvents(capture, port);
  let nextEvent = 0;
  /** This port's events recorded before chunk `upTo` (all that are left: Infinity), to the link and the doctor. */
  const eventsBefore = (upTo: number): void => {
    for (let e = events[nextEvent]; e !== undefined && e.chunkIndex <= upTo; e = events[++nextEvent]) {
      if (stopsPort(e.text)) link.stopped(e.timeUs);
      if (doctor !== undefined) doctorEvent(doctor, port, e.text, e.timeUs);
    }
  };
  if (doctor !== undefined) {
    const label = capture.meta.ports?.[port]?.name;
    doctor.detach(port);
    doctor.attach(port, { decoder, link, label: typeof label === 'string' && label !== '' ? label : `Port ${port}` });
  }
  const drain = (): void => {
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) {
      link.frame(f);
      series.frame(f, link);
      doctor?.frame(port, f);
      onFrame(f, link);
    }
  };
  // The doctor's packet scan starts at chunk `scan.chunk`, byte `scan.offset` in it, when its
  // findings are taken only at the end and nothing else reads the scan: a port opened at another
  // speed counts packets for the probe (events naming a baud rate), so such a port is scanned whole.
  const judged =
    doctor !== undefined &&
    doctorJudgedAtEnd &&
    capture.timing === 'per-chunk' &&
    Number.isFinite(end) &&
    !events.some((e) => /baud/i.test(e.text));
  const fromUs = lineWindow(end).fromS * 1e6;
  const scan = !judged
    ? { chunk: 0, offset: 0 }
    : isStreamed(capture)
      ? firstScannedStreamed(capture, port, fromUs)
      : firstScanned(capture, port, fromUs);
  for (const w of captureWindows(capture, port)) {
    const { bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs, firstChunk } = w;
    /** Bytes [from, to) of the window, as they arrived (no view made: `pushRange`). */
    const push = (from: number, to: number, time: number | Float64Array | undefined, unscanned: number): void => {
      doctor?.bytes(port, bytes, time, unscanned, from, to);
      decoder.pushRange(bytes, from, to, time);
      drain();
    };
    let from = 0;
    for (let k = 0; k < chunkEnds.length; k++) {
      const to = chunkEnds[k] ?? from;
      const i = firstChunk + k;
      if (chunkPorts[k] === port) {
        eventsBefore(i);
        if (byteTimesUs !== undefined) {
          for (let s = from; s < to; s += SLICE_BYTES) push(s, Math.min(s + SLICE_BYTES, to), byteTimesUs, 0);
        } else {
          const t = chunkTimesUs[k] ?? NaN;
          if (Number.isNaN(t)) {
            // Untimed (a raw dump is one chunk): pushed in pieces, so the decoder never copies the whole of it.
            for (let s = from; s < to; s += UNTIMED_PIECE_BYTES) push(s, Math.min(s + UNTIMED_PIECE_BYTES, to), undefined, 0);
          } else push(from, to, t, i < scan.chunk ? to - from : i === scan.chunk ? scan.offset : 0);
        }
      }
      from = to;
    }
  }
  eventsBefore(Infinity);
  decoder.end();
  drain();
  link.finish(end);
  series.extendTo(end);
  return { decoder, link, series };
}
