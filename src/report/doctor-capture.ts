/**
 * The doctor over a whole capture, for `satscope doctor` and the report: every port replayed
 * through its own decoder and link monitor in the capture's time order, as live data would
 * arrive, with the capture's events ("port opened", line errors) fed in where they happened.
 * Pure: same capture, same findings.
 */
import { type AnyCapture, captureDataBytes, type CaptureWindow, captureWindows, isStreamed } from '../capture/capture-windows.js';
import { BYTE_TIME_US, type Resolution } from '../decoder/spec.js';
import { LinkMonitor } from '../decoder/link.js';
import { SpektrumDecoder } from '../decoder/decoder.js';
import { capturePorts } from '../capture/facts.js';
import { chunkFirstByteUs, type CaptureKind, type CaptureTiming } from '../capture/model.js';
import { Doctor } from './doctor.js';
import type { DoctorCode, DoctorFinding, Severity } from './doctor-types.js';
import { doctorEvent, stopsPort } from './doctor-events.js';
import { SLICE_BYTES, timingJitterUs } from './capture-pass.js';
import { captureSpan } from './capture-span.js';
import { portResolutions } from './resolution-key.js';

/** How `doctorCapture` reads a capture: the resolution, and the step its timeline is judged at. */
export interface DoctorCaptureOptions {
  /** Resolution override for every port's decoder. Default 'auto'. */
  resolution?: 'auto' | Resolution;
  /** How often the findings are taken for the timeline, µs of capture time. Default 250 ms. */
  stepUs?: number;
}

/** When a finding held during the capture. */
export interface DoctorTimelineEntry {
  code: DoctorCode;
  ports: number[];
  severity: Severity;
  title: string;
  fromUs: number;
  /** `null`: it still held at the end. */
  toUs: number | null;
}

/** What `doctorCapture` returns. JSON-serialisable. */
export interface DoctorReport {
  format: 'satscope-doctor';
  version: 1;
  source: { kind: CaptureKind; timing: CaptureTiming; ports: number[]; bytes: number; startUs: number | null; endUs: number | null };
  /** The findings at the end of the capture, worst first (times on the capture's clock; sentences count from `source.startUs`). */
  findings: DoctorFinding[];
  /** Every finding seen along the way, with when it held, in order of appearance. */
  timeline: DoctorTimelineEntry[];
}

/** One piece of what arrived, as `arrival` hands it over: data (with `bytes`) or an event (with `text`). */
type Visit = (
  port: number,
  /** The time of its last byte (data) or the event's time: for an untimed capture, its place on a clock of the doctor's own. */
  timeUs: number,
  /** The earliest time anything in it can carry: its first byte's (estimated for a chunk). */
  firstUs: number,
  bytes: Uint8Array | null,
  /** The recorded time the decoder is given (undefined: none, as `decodeCapture` gives it). */
  time: number | Float64Array | undefined,
  text: string,
) => void;

interface Piece {
  port: number;
  order: number;
  timeUs: number;
  firstUs: number;
  bytes: Uint8Array | null;
  time: number | Float64Array | undefined;
  text: string;
}

/**
 * Everything a capture holds in arrival order, data and events, walked as often as asked. Chunk
 * timing (and none) is the file's order, read straight from the chunk columns: no object per
 * chunk, so a day-long capture costs nothing here. A per-byte capture holds one chunk per port,
 * cut into slices and put back in time order across ports: held, they are sorted; streamed
 * (whose reader makes sure each port's slices come in time order), each port is walked on its
 * own and the ports' slices merged, earliest first and, at the same time, the lower port's.
 */
function arrival(capture: AnyCapture): { each: (visit: Visit) => void; bytes: number } {
  const timed = capture.timing !== 'none';
  const events = [...capture.events].sort((a, b) => a.chunkIndex - b.chunkIndex);
  const walk = (visit: Visit, windows: Iterable<CaptureWindow> = captureWindows(capture)): void => {
    let e = 0;
    const eventsBefore = (upTo: number): void => {
      for (let ev = events[e]; ev !== undefined && ev.chunkIndex <= upTo; ev = events[++e])
        visit(ev.port, ev.timeUs, ev.timeUs, null, undefined, ev.text);
    };
    for (const w of windows) {
      const { bytes, chunkEnds, chunkTimesUs, chunkPorts, byteTimesUs, firstChunk, byteOffset } = w;
      const last = chunkEnds.length - 1;
      let from = 0;
      for (let k = 0; k < chunkEnds.length; k++) {
        eventsBefore(firstChunk + k);
        const to = chunkEnds[k] ?? from;
        const port = chunkPorts[k] ?? 0;
        if (byteTimesUs !== undefined) {
          for (let s = from; s < to; s += SLICE_BYTES) {
            const end = Math.min(s + SLICE_BYTES, to);
            const times = byteTimesUs.subarray(s, end);
            visit(port, times[times.length - 1] ?? NaN, times[0] ?? NaN, bytes.subarray(s, end), times, '');
          }
        } else {
          const chunkTime = chunkTimesUs[k] ?? NaN;
          // A chunk cut between windows (untimed only) is placed as a whole: where it ends, how long it is.
          const after = k === last ? w.tailAfter : 0;
          const length = to - from + (k === 0 ? w.headBefore : 0) + after;
          // Untimed: as if the bytes came back to back at 115200.
          const t = timed ? chunkTime : (byteOffset + to + after) * BYTE_TIME_US;
          // A decoder dates a chunk's frames back from its arrival at 115200: none is earlier than this.
          const first = chunkFirstByteUs(t, length, BYTE_TIME_US);
          visit(port, t, first, bytes.subarray(from, to), timed && !Number.isNaN(chunkTime) ? chunkTime : undefined, '');
        }
        from = to;
      }
    }
    eventsBefore(Infinity);
  };
  const bytes = captureDataBytes(capture);
  if (capture.timing !== 'per-byte') return { each: (visit) => walk(visit), bytes };
  // A streamed per-byte capture (a CSV) has no events: its reader says so.
  if (isStreamed(capture)) return { each: (visit) => mergedPorts(capture.ports, (port) => capture.windows(port), visit), bytes };
  const pieces: Piece[] = [];
  walk((port, timeUs, firstUs, data, time, text) => {
    pieces.push({ port, order: pieces.length, timeUs, firstUs, bytes: data, time, text });
  });
  pieces.sort((a, b) => (Number.isFinite(a.timeUs) && Number.isFinite(b.timeUs) ? a.timeUs - b.timeUs : 0) || a.order - b.order);
  return {
    each: (visit) => {
      for (const p of pieces) visit(p.port, p.timeUs, p.firstUs, p.bytes, p.time, p.text);
    },
    bytes,
  };
}

/**
 * Each port's data pieces merged into one time order: the earliest next piece of any port first,
 * the lower port's at the same time, as the held capture's sort puts them when each port's
 * pieces come in time order (the streamed reader makes sure they do). Every port is walked at
 * once, a walk of its own windows each, holding one window of each.
 */
function mergedPorts(ports: readonly number[], windowsOf: (port: number) => Iterable<CaptureWindow>, visit: Visit): void {
  const streams = ports.map((port) => slicesOf(windowsOf(port)));
  const heads = streams.map((s) => s.next());
  for (;;) {
    let best: Piece | undefined;
    let at = -1;
    for (let i = 0; i < heads.length; i++) {
      const h = heads[i];
      if (h === undefined || h.done === true) continue;
      if (best === undefined || h.value.timeUs < best.timeUs) {
        best = h.value;
        at = i;
      }
    }
    if (best === undefined) return;
    visit(best.port, best.timeUs, best.firstUs, best.bytes, best.time, best.text);
    heads[at] = streams[at]?.next() ?? { done: true, value: undefined };
  }
}

/** The slices of per-byte chunks in windows, as `arrival` cuts them. */
function* slicesOf(windows: Iterable<CaptureWindow>): Generator<Piece, void, undefined> {
  let order = 0;
  for (const { bytes, chunkEnds, chunkPorts, byteTimesUs } of windows) {
    if (byteTimesUs === undefined) continue;
    let from = 0;
    for (let k = 0; k < chunkEnds.length; k++) {
      const to = chunkEnds[k] ?? from;
      const port = chunkPorts[k] ?? 0;
      for (let s = from; s < to; s += SLICE_BYTES) {
        const end = Math.min(s + SLICE_BYTES, to);
        const times = byteTimesUs.subarray(s, end);
        yield {
          port,
          order: order++,
          timeUs: times[times.length - 1] ?? NaN,
          firstUs: times[0] ?? NaN,
          bytes: bytes.subarray(s, end),
          time: times,
          text: '',
        };
      }
      from = to;
    }
  }
}

/**
 * Runs the doctor over every port of a capture and returns the findings at its end and the
 * timeline of findings along the way. Never throws on the capture's content.
 */
export function doctorCapture(capture: AnyCapture, options: DoctorCaptureOptions = {}): DoctorReport {
  const step = options.stepUs ?? 250_000;
  if (!(step > 0)) throw new TypeError(`stepUs must be positive, not ${step}`);
  const timed = capture.timing !== 'none';
  const ports = new Set(capturePorts(capture));
  for (const e of capture.events) ports.add(e.port);
  const sorted = [...ports].sort((a, b) => a - b);

  // Everything in arrival order: data pieces and events.
  const pieces = arrival(capture);
  const bytes = pieces.bytes;
  // Time zero of the evidence sentences: the capture's first time, as in the health report.
  let origin = Infinity;
  pieces.each((_port, _t, firstUs) => {
    if (firstUs < origin) origin = firstUs;
  });
  const doctor = new Doctor({
    timing: capture.timing,
    memoryUs: Infinity,
    originUs: Number.isFinite(origin) ? origin : 0,
  });
  const names = capture.meta.ports;
  const sources = new Map<number, { decoder: SpektrumDecoder; link: LinkMonitor }>();
  // §8 as the health report applies it, so that the doctor reads each remote as the report does.
  const settings = portResolutions(capture, options.resolution ?? 'auto');
  for (const port of sorted) {
    const setting = settings.get(port);
    const decoder = new SpektrumDecoder({
      resolution: setting?.resolution ?? options.resolution ?? 'auto',
      resolutionFrom: setting?.from ?? 'user',
    });
    const link = new LinkMonitor({ jitterUs: timingJitterUs(capture.timing) });
    sources.set(port, { decoder, link });
    const label = names?.[port]?.name;
    doctor.attach(port, { decoder, link, label: typeof label === 'string' && label !== '' ? label : `Port ${port}` });
  }

  const timeline: DoctorTimelineEntry[] = [];
  const open = new Map<string, DoctorTimelineEntry>();
  const sample = (t: number): DoctorFinding[] => {
    const found = doctor.findings(t);
    const seen = new Set<string>();
    for (const f of found) {
      const key = `${f.code}:${f.ports.join(',')}`;
      seen.add(key);
      const entry = open.get(key);
      if (entry === undefined) {
        const e: DoctorTimelineEntry = {
          code: f.code,
          ports: f.ports,
          severity: f.severity,
          title: f.title,
          fromUs: f.sinceUs,
          toUs: null,
        };
        open.set(key, e);
        timeline.push(e);
      } else {
        entry.title = f.title;
        if (SEVERITY_RANK[f.severity] < SEVERITY_RANK[entry.severity]) entry.severity = f.severity;
      }
    }
    for (const [key, e] of open) {
      if (!seen.has(key)) {
        e.toUs = t;
        open.delete(key);
      }
    }
    return found;
  };

  let start = NaN;
  let now = NaN;
  let nextSample = NaN;
  pieces.each((port, t, firstUs, data, time, text) => {
    if (Number.isFinite(t)) {
      if (Number.isNaN(start)) {
        start = t;
        nextSample = Math.floor(firstUs / step) * step + step;
      }
      // Take the findings at each step this piece starts after: everything before it has been
      // fed. The link monitors are not advanced to the step: a decoder holds its last frame until
      // the next confirms it, so the silence a monitor would see there is not the link's (the
      // monitors count exactly as `decodeCapture`'s, which every other surface reads).
      while (firstUs >= nextSample) {
        sample(nextSample);
        nextSample += step;
      }
      if (!(now >= t)) now = t;
    }
    if (data === null) {
      if (stopsPort(text)) sources.get(port)?.link.stopped(t);
      doctorEvent(doctor, port, text, t);
      return;
    }
    const source = sources.get(port);
    if (source === undefined) return;
    // Untimed, the doctor's line windows run on the clock of the bytes; the decoder, as in
    // `decodeCapture`, gets no time, and so the link monitor claims no period, gap or rate.
    doctor.bytes(port, data, time ?? t);
    source.decoder.push(data, time);
    for (let f = source.decoder.next(); f !== undefined; f = source.decoder.next()) {
      source.link.frame(f);
      doctor.frame(port, f);
    }
  });
  for (const [port, s] of sources) {
    s.decoder.end();
    for (let f = s.decoder.next(); f !== undefined; f = s.decoder.next()) {
      s.link.frame(f);
      doctor.frame(port, f);
    }
  }
  const end = Number.isFinite(now) ? now : 0;
  // The links end where the capture does, as `decodeCapture` ends them (untimed: nowhere).
  const linkEnd = timed ? captureSpan(capture).endUs : NaN;
  for (const s of sources.values()) s.link.finish(linkEnd);
  for (const port of sorted) doctor.ended(port);
  const findings = sample(end);
  // Times are real when the capture has timing, or holds only events (which always have times).
  const real = timed || bytes === 0;
  return {
    format: 'satscope-doctor',
    version: 1,
    source: {
      kind: capture.kind,
      timing: capture.timing,
      ports: sorted,
      bytes,
      startUs: Number.isFinite(origin) && real ? origin : null,
      endUs: Number.isFinite(now) && real ? now : null,
    },
    findings,
    timeline,
  };
}

const SEVERITY_RANK: Record<Severity, number> = { problem: 0, warning: 1, info: 2 };
