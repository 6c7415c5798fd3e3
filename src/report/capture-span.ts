/**
 * A capture's span: the earliest and latest time recorded in it on any port (data bytes and
 * events), on the capture's clock, µs. Every surface starts and ends a capture here: the
 * report's time zero, replay's timeline, the end at which the link's state is judged. Worked
 * out once per capture from its columns (`captureSpan`), or from the earliest and latest
 * time found as its records are walked (a capture replayed from its File), by the same rule
 * (`SpanTally`).
 */
import { chunkFirstByteUs } from '../capture/model.js';
import { captureFact } from '../capture/facts.js';
import { type AnyCapture, type CaptureWindow, captureWindows, isStreamed } from '../capture/capture-windows.js';
import { BYTE_TIME_US } from '../decoder/spec.js';

export interface CaptureSpan {
  startUs: number;
  endUs: number;
}

/** The fact's name (`captureFact`). */
const SPAN = 'span';

/**
 * The span's rule, a chunk or an event at a time: a chunk starts at its first byte's time and
 * ends at its last's; a chunk timed by its arrival (its last byte) has its first byte dated back
 * at line rate, as the decoder dates it. No time at all (NaN for both): no span.
 */
export class SpanTally {
  // The earliest and latest so far, kept in a typed array rather than two fields or locals:
  // Chromium 150 keeps a loop's double locals boxed until the loop is optimised, a heap number a
  // chunk of a pass that runs once, cold, over eleven million chunks (three times the time, measured).
  readonly #at = new Float64Array([Infinity, -Infinity]);

  /** A chunk whose first and last bytes were recorded at `firstUs` and `lastUs`. */
  bytes(firstUs: number, lastUs: number): void {
    const at = this.#at;
    if (firstUs < (at[0] ?? NaN)) at[0] = firstUs;
    if (lastUs > (at[1] ?? NaN)) at[1] = lastUs;
  }

  /** A chunk of `count` bytes (at least one) that arrived at `arrivalUs` (chunk timing). */
  chunk(arrivalUs: number, count: number): void {
    this.bytes(chunkFirstByteUs(arrivalUs, count, BYTE_TIME_US), arrivalUs);
  }

  /** An event recorded at `timeUs`. */
  event(timeUs: number): void {
    this.bytes(timeUs, timeUs);
  }

  get span(): CaptureSpan {
    return spanBetween(this.#at[0] ?? NaN, this.#at[1] ?? NaN);
  }
}

/** The span from the earliest to the latest time found: NaN for both when nothing was timed. */
function spanBetween(earliestUs: number, latestUs: number): CaptureSpan {
  return earliestUs <= latestUs ? { startUs: earliestUs, endUs: latestUs } : { startUs: NaN, endUs: NaN };
}

/** The capture's span, NaN for both without timing: one pass over its chunk columns, once per capture (`captureFact`). */
export function captureSpan(capture: AnyCapture): CaptureSpan {
  const { startUs, endUs } = isStreamed(capture)
    ? (capture.span ?? captureFact(capture, SPAN, spanOf))
    : captureFact(capture, SPAN, spanOf);
  return { startUs, endUs };
}

function spanOf(capture: AnyCapture): CaptureSpan {
  const tally = new SpanTally();
  // Untimed, only the events have times: no window needs reading.
  if (capture.timing !== 'none') for (const w of captureWindows(capture)) spanOfWindow(w, tally);
  for (const e of capture.events) tally.event(e.timeUs);
  return tally.span;
}

/**
 * The span's rule over one window of chunks. A chunk timed by its arrival is never cut between
 * windows; one timed per byte is, and its parts' first and last bytes span what it does.
 */
export function spanOfWindow(w: CaptureWindow, tally: SpanTally): void {
  const { chunkEnds, chunkTimesUs, byteTimesUs } = w;
  let from = 0;
  for (let i = 0; i < chunkEnds.length; i++) {
    const to = chunkEnds[i] ?? from;
    if (to > from) {
      if (byteTimesUs !== undefined) tally.bytes(byteTimesUs[from] ?? NaN, byteTimesUs[to - 1] ?? NaN);
      else tally.chunk(chunkTimesUs[i] ?? NaN, to - from);
    }
    from = to;
  }
}
