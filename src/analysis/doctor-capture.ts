/**
 * The doctor over a whole capture, for `satscope doctor` and the report: every port replayed
 * through its own decoder and link monitor in the capture's time order, as live data would
 * arrive, with the capture's events ("port opened", line errors) fed in where they happened.
 * Pure: same capture, same findings.
 */
import { BYTE_TIME_US, LinkMonitor, SpektrumDecoder, USB_CHUNK_JITTER_US, type Resolution } from '../decoder/index.js';
import { captureChunks, capturePorts, type Capture, type CaptureKind, type CaptureTiming } from '../capture/index.js';
import { Doctor, type DoctorCode, type DoctorFinding, type Severity } from './doctor.js';
import { doctorEvent } from './doctor-events.js';
import { SLICE_BYTES } from './capture-pass.js';

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

interface Piece {
  kind: 'data' | 'event';
  port: number;
  order: number;
  /** The time of its last byte (data) or the event's time. */
  timeUs: number;
  /** The earliest time anything in it can carry: its first byte's (estimated for a chunk). */
  firstUs: number;
  bytes?: Uint8Array;
  time?: number | Float64Array;
  text?: string;
}

/**
 * Runs the doctor over every port of a capture and returns the findings at its end and the
 * timeline of findings along the way. Never throws on the capture's content.
 */
export function doctorCapture(capture: Capture, options: DoctorCaptureOptions = {}): DoctorReport {
  const step = options.stepUs ?? 250_000;
  if (!(step > 0)) throw new TypeError(`stepUs must be positive, not ${step}`);
  const timed = capture.timing !== 'none';
  const ports = new Set(capturePorts(capture));
  for (const e of capture.events) ports.add(e.port);
  const sorted = [...ports].sort((a, b) => a - b);

  // Everything in arrival order: data pieces and events.
  const pieces: Piece[] = [];
  let order = 0;
  let offset = 0;
  let events = 0;
  const evs = [...capture.events].sort((a, b) => a.chunkIndex - b.chunkIndex);
  const pushEvents = (upTo: number): void => {
    while (events < evs.length && (evs[events] as (typeof evs)[number]).chunkIndex <= upTo) {
      const e = evs[events++] as (typeof evs)[number];
      pieces.push({ kind: 'event', port: e.port, order: order++, timeUs: e.timeUs, firstUs: e.timeUs, text: e.text });
    }
  };
  let bytes = 0;
  for (const chunk of captureChunks(capture)) {
    pushEvents(chunk.index);
    bytes += chunk.bytes.length;
    if (chunk.byteTimesUs !== undefined) {
      for (let s = 0; s < chunk.bytes.length; s += SLICE_BYTES) {
        const times = chunk.byteTimesUs.subarray(s, s + SLICE_BYTES);
        pieces.push({
          kind: 'data',
          port: chunk.port,
          order: order++,
          timeUs: times[times.length - 1] ?? NaN,
          firstUs: times[0] ?? NaN,
          bytes: chunk.bytes.subarray(s, s + SLICE_BYTES),
          time: times,
        });
      }
    } else {
      // Untimed: as if the bytes came back to back at 115200.
      offset += chunk.bytes.length;
      const t = timed ? chunk.timeUs : offset * BYTE_TIME_US;
      // A decoder dates a chunk's frames back from its arrival at 115200: none is earlier than this.
      const first = t - (chunk.bytes.length - 1) * BYTE_TIME_US;
      pieces.push({
        kind: 'data',
        port: chunk.port,
        order: order++,
        timeUs: t,
        firstUs: first,
        bytes: chunk.bytes,
        time: timed ? chunk.time : t,
      });
    }
  }
  pushEvents(Infinity);
  // Per-byte captures hold one chunk per port: put the ports' slices back in time order.
  if (capture.timing === 'per-byte')
    pieces.sort((a, b) => (Number.isFinite(a.timeUs) && Number.isFinite(b.timeUs) ? a.timeUs - b.timeUs : 0) || a.order - b.order);

  // Time zero of the evidence sentences: the capture's first time, as in the health report.
  let origin = Infinity;
  for (const piece of pieces) if (piece.firstUs < origin) origin = piece.firstUs;
  const doctor = new Doctor({
    timing: capture.timing === 'per-byte' ? 'per-byte' : 'per-chunk',
    memoryUs: Infinity,
    originUs: Number.isFinite(origin) ? origin : 0,
  });
  const names = capture.meta.ports;
  const sources = new Map<number, { decoder: SpektrumDecoder; link: LinkMonitor }>();
  for (const port of sorted) {
    const decoder = new SpektrumDecoder({ resolution: options.resolution ?? 'auto' });
    const link = new LinkMonitor({ jitterUs: capture.timing === 'per-chunk' ? USB_CHUNK_JITTER_US : 0 });
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
  for (const piece of pieces) {
    const t = piece.timeUs;
    if (Number.isFinite(t)) {
      if (Number.isNaN(start)) {
        start = t;
        nextSample = Math.floor(piece.firstUs / step) * step + step;
      }
      // Take the findings at each step this piece starts after: everything before it has been
      // fed, so no link monitor is advanced past a frame it has not seen yet.
      while (piece.firstUs >= nextSample) {
        for (const s of sources.values()) s.link.update(nextSample);
        sample(nextSample);
        nextSample += step;
      }
      if (!(now >= t)) now = t;
    }
    if (piece.kind === 'event') {
      doctorEvent(doctor, piece.port, piece.text ?? '', t);
      continue;
    }
    const source = sources.get(piece.port) as { decoder: SpektrumDecoder; link: LinkMonitor };
    const data = piece.bytes as Uint8Array;
    doctor.bytes(piece.port, data, piece.time);
    source.decoder.push(data, piece.time);
    for (let f = source.decoder.next(); f !== undefined; f = source.decoder.next()) {
      source.link.frame(f);
      doctor.frame(piece.port, f);
    }
  }
  for (const [port, s] of sources) {
    s.decoder.end();
    for (let f = s.decoder.next(); f !== undefined; f = s.decoder.next()) {
      s.link.frame(f);
      doctor.frame(port, f);
    }
  }
  const end = Number.isFinite(now) ? now : 0;
  for (const s of sources.values()) s.link.update(end);
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
