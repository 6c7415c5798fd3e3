/**
 * What a recorded capture event tells the doctor and the link: the words the worker's recorder writes
 * ("port opened", "device lost", "line error: FramingError"…) read back as the calls live use
 * makes. The live worker, `doctorCapture` and the report's one pass all go through here, so a
 * recording says what was seen.
 */
import { type AnyCapture, captureWindows } from '../capture/capture-windows.js';
import type { Doctor } from './doctor.js';
import { type Absences, absenceEnds, absenceStarts, absencesUntil, noAbsences } from './absences.js';

/** A capture event's text names a WebSerial read error, e.g. "line error: FramingError". */
const LINE_ERROR = /\b(FramingError|ParityError|BreakError|BufferOverrunError)\b/;
/** "port opened", "device reconnected", optionally "… at 420000 baud". */
const OPENED = /\b(port opened|device reconnected)\b/i;
const CLOSED = /\b(device lost|port closed)\b/i;
const BAUD = /\b(\d{4,7})\s*baud\b/i;

/**
 * Whether a recorded event says the port's source went away ("device lost", "port closed"):
 * its link is then `LinkMonitor.stopped` there, on every surface that reads the recording.
 */
export function stopsPort(text: string): boolean {
  return CLOSED.test(text);
}

/** A recorded stop (`stopsPort`): its port, the capture's chunk it came before, and its time. */
export interface RecordedStop {
  readonly port: number;
  readonly chunkIndex: number;
  readonly timeUs: number;
}

/** The capture's recorded stops in the order they were recorded among its chunks. */
export function recordedStops(capture: AnyCapture): RecordedStop[] {
  return capture.events
    .filter((e) => stopsPort(e.text))
    .map((e) => ({ port: e.port, chunkIndex: e.chunkIndex, timeUs: e.timeUs }))
    .sort((a, b) => a.chunkIndex - b.chunkIndex);
}

/**
 * A cursor over recorded stops by the capture's chunk they came before: a pass over the chunks
 * takes those before each chunk once (nothing allocated: it runs for every chunk fed), and a
 * seek puts it back.
 */
export class StopCursor {
  #next = 0;
  constructor(readonly stops: readonly RecordedStop[]) {}

  /**
   * The next stop recorded before the capture's chunk `chunk` (Infinity: all left) and, with
   * `untilUs`, at or before that time, taken; undefined when none.
   */
  take(chunk: number, untilUs = Number.POSITIVE_INFINITY): RecordedStop | undefined {
    const e = this.stops[this.#next];
    if (e === undefined || e.chunkIndex > chunk || !(e.timeUs <= untilUs || untilUs === Number.POSITIVE_INFINITY)) return undefined;
    this.#next++;
    return e;
  }

  /** Puts the cursor on the first stop recorded before chunk `chunk` or later (a seek feeds from there). */
  seek(chunk: number): void {
    this.#next = 0;
    while ((this.stops[this.#next]?.chunkIndex ?? Number.POSITIVE_INFINITY) < chunk) this.#next++;
  }
}

/** A recording's absences (`Absences`) by port, up to `endUs` (the capture's end); ports without any are left out. */
export function recordedAbsences(capture: AnyCapture, endUs: number): Map<number, Omit<Absences, 'fromUs'>> {
  const stops = recordedStops(capture);
  const out = new Map<number, Omit<Absences, 'fromUs'>>();
  if (stops.length === 0) return out;
  const byPort = new Map<number, Absences>();
  const of = (port: number): Absences => {
    let a = byPort.get(port);
    if (a === undefined) byPort.set(port, (a = noAbsences()));
    return a;
  };
  let s = 0;
  for (const { chunkPorts, chunkTimesUs, firstChunk } of captureWindows(capture)) {
    for (let k = 0; k < chunkPorts.length; k++) {
      const i = firstChunk + k;
      for (let stop = stops[s]; stop !== undefined && stop.chunkIndex <= i; stop = stops[++s]) absenceStarts(of(stop.port), stop.timeUs);
      const a = byPort.get(chunkPorts[k] ?? -1);
      if (a !== undefined) absenceEnds(a, chunkTimesUs[k] ?? Number.NaN);
    }
  }
  for (; s < stops.length; s++) absenceStarts(of(stops[s]!.port), stops[s]!.timeUs);
  for (const [port, a] of byPort) {
    const t = absencesUntil(a, endUs);
    if (t.count > 0) out.set(port, t);
  }
  return out;
}

/**
 * Feeds one recorded event to a doctor: "port opened" / "device reconnected" (optionally
 * "… at 420000 baud") opens the port, "device lost" / "port closed" closes it, and a text that
 * names a WebSerial read error ("line error: FramingError") is that error. Other texts are
 * ignored.
 */
export function doctorEvent(doctor: Doctor, port: number, text: string, timeUs: number): void {
  const error = LINE_ERROR.exec(text);
  if (error?.[1] !== undefined) doctor.lineError(port, error[1], timeUs);
  else if (OPENED.test(text)) {
    const baud = BAUD.exec(text);
    doctor.open(port, timeUs, baud !== null ? { baudRate: Number(baud[1]) } : {});
  } else if (stopsPort(text)) doctor.close(port, timeUs);
}
