/**
 * The doctor: from what the wire shows to what the user should change.
 *
 * A push-style analyser, one per session (every port of it). The caller feeds it what it
 * already has: each port's open time, the bytes as they arrive with their times, the read
 * errors the port reports, and the decoded frames (after its own `LinkMonitor` counted them);
 * `findings(nowUs)` returns what is wrong, with evidence, how sure it is and what to do. A
 * finding appears once its evidence is sufficient and goes when it no longer holds: line
 * findings look at the last 3 s, link findings at the last minute (`memoryUs`).
 *
 * Time is always the caller's (µs, one clock for every port); nothing here reads a clock.
 * Feeding costs a few operations per byte and per frame and allocates nothing; `findings()`
 * builds its answer (call it a few times a second at most).
 */
import {
  FRAME_SIZE,
  systemInfo,
  type DecodedFrame,
  type FormatInfo,
  type LinkMonitor,
  type Resolution,
  type SpektrumDecoder,
} from '../decoder/index.js';
import { REPORT_THRESHOLDS } from './report-thresholds.js';
import { plural } from './report-text.js';
import { BurstClock, classifyLine, PACKET_KINDS, PacketScanner, type LineVerdict, type PacketKind } from './doctor-line.js';
import {
  ArduPilotGuess,
  ARDUPILOT_GUESS_FRAMES,
  bindPulses,
  channelSetText,
  foreignSettings,
  PROTOCOL_SETTINGS,
  satelliteSettings,
  type ForeignProtocol,
  type StackSetting,
} from './doctor-stacks.js';

// ---------------------------------------------------------------------------------------------
// Findings
// ---------------------------------------------------------------------------------------------

/** Stable codes, for programs and tests; titles are for people. */
export type DoctorCode =
  // Nothing arrives
  | 'nothing-arrives'
  // Bytes, but not a satellite stream
  | 'inverted-line'
  | 'srxl-v1'
  | 'srxl2'
  | 'ibus'
  | 'sbus'
  | 'crsf'
  | 'wrong-speed'
  | 'noise'
  | 'unknown-stream'
  | 'overrun'
  // A satellite the flight controller will read wrong
  | 'fc-settings'
  | 'bind-mode'
  | 'system-byte-contradicted'
  | 'xplus-channels'
  | 'vtx-frames'
  | 'autopilot-detection'
  // The link is weak
  | 'weak-link'
  | 'weakest-remote'
  | 'fades-together'
  // The setup is wrong
  | 'internal-count'
  | 'resolution-mismatch'
  | 'rebind'
  | 'receiver-restart'
  | 'rssi-receiver';

export type Severity = 'problem' | 'warning' | 'info';
/** How sure: 'certain' (the bytes prove it), 'likely' (the numbers fit it and nothing else known), 'possible' (one of several explanations). */
export type Confidence = 'possible' | 'likely' | 'certain';

/** One number from the stream, as a sentence, with when it was seen (µs, the caller's clock) if it has a time. */
export interface Evidence {
  text: string;
  timeUs: number | null;
}

/** A short listen at another line setting that would confirm a finding (the worker may offer it). */
export interface ConfirmProbe {
  baudRate: number;
  parity: 'none' | 'even' | 'odd';
  stopBits: 1 | 2;
  /** How long to listen, µs. */
  listenUs: number;
  /** Why, and what the adapter must be able to do. */
  note: string;
}

export interface DoctorFinding {
  code: DoctorCode;
  /** The ports it is about, in increasing order (several for a finding about the whole system). */
  ports: number[];
  severity: Severity;
  confidence: Confidence;
  /** A plain title, e.g. "This is FlySky IBUS, not a Spektrum satellite". */
  title: string;
  evidence: Evidence[];
  /** What to do, most likely first. */
  todo: string[];
  /** Flight-stack settings, where there are some ("copy settings"). */
  settings: StackSetting[];
  confirm: ConfirmProbe | null;
  /** When the finding appeared (it has held at every `findings()` call since), µs. */
  sinceUs: number;
}

export interface DoctorOptions {
  /**
   * How byte and error times were taken: 'per-byte' (a logic analyser, the line model), where
   * the gaps between bursts are the sender's; or 'per-chunk' (WebSerial, .sscap), where they
   * are the USB adapter's batching and are not used. Default 'per-chunk'.
   */
  timing?: 'per-byte' | 'per-chunk';
  /** How far back link findings (holds, failsafes, fades, restarts, rebinds) look, µs. Default 60 s; a whole capture: Infinity. */
  memoryUs?: number;
  /**
   * Time zero for the times written in the evidence sentences ("at 12.3 s"), µs on the
   * caller's clock: the session's start, or a capture's first time. Default 0. `Evidence.timeUs`
   * stays on the caller's clock.
   */
  originUs?: number;
}

/** What a port's source gives the doctor to read. */
export interface DoctorPortSource {
  decoder: SpektrumDecoder;
  link: LinkMonitor;
  /** A short name for titles ("A", "Port 1"). Default "Port N". */
  label?: string;
}

// ---------------------------------------------------------------------------------------------
// Thresholds
// ---------------------------------------------------------------------------------------------

/** Silence after the port opened before "nothing arrives": a linked satellite sends every 11 or 22 ms, so 1 s is 45 missed frames. */
export const NOTHING_AFTER_US = 1_000_000;
/** …and after this long it is certain. */
export const NOTHING_CERTAIN_US = 3_000_000;
/** Line findings look at the last 3 one-second bins. */
export const LINE_WINDOW_BINS = 3;
/** A fade-counter drop after a gap this long is a restart, not a wrap. */
const RESTART_MIN_GAP_US = 100_000;
/** Seconds with fades on two remotes or more, out of the seconds with fades on any, above which they fade together. */
const TOGETHER_RATIO = 0.6;
const TOGETHER_MIN_SECONDS = 3;
/** Clean bytes that decode as nothing are judged only after this long (a satellite locks within a few frames). */
const UNKNOWN_AFTER_US = 1_500_000;
/** Fades in the last 10 s before a fade rate is judged. */
const MIN_FADES = 5;
/** Frames a remote must have sent before its format counts for setup findings. */
const SETUP_MIN_FRAMES = 20;
/** Guess decisions before predicting ArduPilot's or PX4's outcome. */
const GUESS_MIN_DECISIONS = 3;

const BIN_COUNT = 64;
const M_BYTES = 0;
const M_FRAME_BYTES = 1;
const M_CHAR_ERRORS = 2;
const M_BREAKS = 3;
const M_OVERRUNS = 4;
const M_FADES = 5;
const M_MISSED = 6;
const M_PACKETS = 7; // + index in PACKET_KINDS
const METRICS = M_PACKETS + PACKET_KINDS.length;

/** Counters in one-second bins, the last 64 seconds. */
class Bins {
  readonly #data = new Float64Array(BIN_COUNT * METRICS);
  readonly #second = new Float64Array(BIN_COUNT).fill(NaN);

  add(metric: number, timeUs: number, n: number): void {
    if (!Number.isFinite(timeUs)) return;
    const s = Math.floor(timeUs / 1e6);
    const slot = ((s % BIN_COUNT) + BIN_COUNT) % BIN_COUNT;
    if (this.#second[slot] !== s) {
      if (s < (this.#second[slot] ?? NaN)) return; // older than the window
      this.#second[slot] = s;
      this.#data.fill(0, slot * METRICS, slot * METRICS + METRICS);
    }
    this.#data[slot * METRICS + metric] = (this.#data[slot * METRICS + metric] ?? 0) + n;
  }

  /** Sum over the seconds fromS…toS (inclusive). */
  sum(metric: number, fromS: number, toS: number): number {
    let total = 0;
    for (let slot = 0; slot < BIN_COUNT; slot++) {
      const s = this.#second[slot] ?? NaN;
      if (s >= fromS && s <= toS) total += this.#data[slot * METRICS + metric] ?? 0;
    }
    return total;
  }

  /** The value of one second. */
  at(metric: number, s: number): number {
    const slot = ((s % BIN_COUNT) + BIN_COUNT) % BIN_COUNT;
    return this.#second[slot] === s ? (this.#data[slot * METRICS + metric] ?? 0) : 0;
  }

  clear(): void {
    this.#second.fill(NaN);
  }
}

interface FormatSnapshot {
  system: number | null;
  resolution: Resolution;
  remote: 'internal' | 'external';
  timeUs: number;
}

interface PortState {
  port: number;
  label: string;
  source: DoctorPortSource | null;
  openUs: number;
  baudRate: number;
  /** First byte or error since the port opened. */
  firstActivityUs: number;
  lastActivityUs: number;
  /** Bytes and errors since the port opened. */
  activity: number;
  /** Time of the latest data: a chunk without a time takes it. */
  lastTimeUs: number;
  bins: Bins;
  scanner: PacketScanner;
  /** Time to book the scanner's packets at (the chunk being scanned). */
  scanTimeUs: number;
  burst: BurstClock;
  /** A protocol recognised at another speed while probing, kept until a satellite shows up. */
  confirmed: { protocol: ForeignProtocol; timeUs: number; packets: number; baudRate: number } | null;
  probePackets: Record<PacketKind, number>;
  // Frames
  frames: number;
  guess: ArduPilotGuess;
  xplusMask: number;
  xplusFirstUs: number;
  vtxFrames: number;
  vtxFirstUs: number;
  prevFades: number | null;
  prevFrameUs: number;
  prevMissed: number;
  /** Decoder's discarded bytes at the last frame, and the frame times that came after a discard (line damage). */
  prevDiscarded: number;
  damagedAtUs: number[];
  first: FormatSnapshot | null;
  changes: { timeUs: number; from: FormatSnapshot; to: FormatSnapshot }[];
  restarts: { timeUs: number; from: number; to: number; gapUs: number }[];
  rssiFrames: number;
}

const SEVERITY_ORDER: Record<Severity, number> = { problem: 0, warning: 1, info: 2 };
const CONFIDENCE_ORDER: Record<Confidence, number> = { certain: 0, likely: 1, possible: 2 };

/** "2.4 s" */
const dur = (us: number): string => `${(us / 1e6).toFixed(1)} s`;

/** Advice from spec §5 for a weak link. */
const LINK_ADVICE = [
  'Give the weak remote line of sight to the transmitter in every attitude; move it away from carbon fibre, metal, batteries and wiring (spec §5).',
  "Add a second remote mounted 90° from the first: each covers the other's blind orientation (spec §5).",
  'Check the antennas: undamaged, not touching carbon or metal, the two elements of a satellite at right angles.',
  'Do a range check with the transmitter in range-test mode before flying again.',
];

const NOTHING_TODO = [
  'Transmitter off, or the satellite not bound to this transmitter and model memory (most common). Satellite LED off: it has power but no link. Turn the transmitter on with the right model; if the LED stays off, bind again.',
  'The satellite is in bind mode. LED blinking fast: bind it now (transmitter in bind), or power-cycle it without bind pulses to leave bind mode.',
  "DATA does not reach the adapter. LED solid (linked) but nothing arrives: grey wire (DATA) to the adapter's RX, not TX; check the connector is not reversed.",
  "No common ground. LED solid, DATA on RX, still nothing: connect black (GND) to the adapter's GND.",
  'No power. LED never lights, not even for a moment at power-up: 3.3 V on orange (pin 1), GND on black; never 5 V on a satellite.',
];

/**
 * The doctor for one session. Ports are numbered by the caller (the capture's port indices);
 * call `attach` once per port before its frames, `open` when the port opens (and again when it
 * reopens, e.g. at another speed to confirm a finding), then feed and ask.
 */
export class Doctor {
  readonly #ports = new Map<number, PortState>();
  readonly #precise: boolean;
  readonly #memoryUs: number;
  readonly #since = new Map<string, number>();
  readonly #originUs: number;

  /** @throws {TypeError} on an option out of range. */
  constructor(options: DoctorOptions = {}) {
    const timing = options.timing ?? 'per-chunk';
    if (timing !== 'per-byte' && timing !== 'per-chunk')
      throw new TypeError(`timing must be 'per-byte' or 'per-chunk', not ${String(timing)}`);
    const memory = options.memoryUs ?? 60_000_000;
    if (!(memory > 0)) throw new TypeError(`memoryUs must be positive, not ${memory}`);
    const origin = options.originUs ?? 0;
    if (!Number.isFinite(origin)) throw new TypeError(`originUs must be a finite number, not ${origin}`);
    this.#precise = timing === 'per-byte';
    this.#memoryUs = memory;
    this.#originUs = origin;
  }

  /** A time in a sentence, from the origin. Durations use `dur`. */
  #at(us: number): string {
    return dur(us - this.#originUs);
  }

  #port(port: number): PortState {
    let p = this.#ports.get(port);
    if (p === undefined) {
      const state: PortState = {
        port,
        label: `Port ${port}`,
        source: null,
        openUs: NaN,
        baudRate: 115_200,
        firstActivityUs: NaN,
        lastActivityUs: NaN,
        activity: 0,
        lastTimeUs: NaN,
        bins: new Bins(),
        scanner: new PacketScanner((kind) => this.#packet(state, kind)),
        scanTimeUs: NaN,
        burst: new BurstClock(),
        confirmed: null,
        probePackets: { ibus: 0, 'srxl-v1': 0, srxl2: 0, crsf: 0, sbus: 0 },
        frames: 0,
        guess: new ArduPilotGuess(),
        xplusMask: 0,
        xplusFirstUs: NaN,
        vtxFrames: 0,
        vtxFirstUs: NaN,
        prevFades: null,
        prevFrameUs: NaN,
        prevMissed: 0,
        prevDiscarded: 0,
        damagedAtUs: [],
        first: null,
        changes: [],
        restarts: [],
        rssiFrames: 0,
      };
      p = state;
      this.#ports.set(port, p);
    }
    return p;
  }

  #packet(p: PortState, kind: PacketKind): void {
    p.bins.add(M_PACKETS + PACKET_KINDS.indexOf(kind), p.scanTimeUs, 1);
    if (p.baudRate !== 115_200) p.probePackets[kind]++;
  }

  /** The decoder and link monitor whose frames `frame()` will get for this port. */
  attach(port: number, source: DoctorPortSource): void {
    const p = this.#port(port);
    p.source = source;
    if (source.label !== undefined) p.label = source.label;
  }

  /**
   * The port was opened (or reopened) at `timeUs`, at `baudRate` (default 115200). Opening at
   * another rate starts a probe: what is recognised there confirms a line finding.
   */
  open(port: number, timeUs: number, options: { baudRate?: number } = {}): void {
    const p = this.#port(port);
    const baud = options.baudRate ?? 115_200;
    if (p.baudRate !== 115_200 && baud === 115_200) this.#endProbe(p, timeUs);
    p.openUs = timeUs;
    p.baudRate = baud;
    p.firstActivityUs = NaN;
    p.activity = 0;
    p.bins.clear();
    p.burst.reset();
    for (const k of PACKET_KINDS) p.probePackets[k] = 0;
  }

  /** The port was closed or lost: no "nothing arrives" for it until it opens again. */
  close(port: number): void {
    this.#port(port).openUs = NaN;
  }

  /**
   * Forgets a port entirely (it was removed, and its number may be given to another remote):
   * nothing it showed carries over to whatever is attached there next.
   */
  detach(port: number): void {
    this.#ports.delete(port);
    for (const key of [...this.#since.keys()]) if (key.split(':')[1]?.split(',').includes(String(port))) this.#since.delete(key);
  }

  #endProbe(p: PortState, timeUs: number): void {
    const found = (['crsf', 'sbus', 'srxl2', 'ibus', 'srxl-v1'] as const).find((k) => p.probePackets[k] >= 3);
    if (found !== undefined) p.confirmed = { protocol: found, timeUs, packets: p.probePackets[found], baudRate: p.baudRate };
  }

  #activity(p: PortState, t: number, n: number): void {
    if (Number.isFinite(t)) {
      if (!Number.isFinite(p.firstActivityUs)) p.firstActivityUs = t;
      if (!(p.lastActivityUs >= t)) p.lastActivityUs = t;
      p.lastTimeUs = t;
    }
    p.activity += n;
  }

  /**
   * Bytes as they arrived: `time` is the chunk's arrival time (its last byte), per-byte times,
   * or nothing (then the last time seen on this port).
   */
  bytes(port: number, bytes: Uint8Array, time?: number | Float64Array): void {
    if (bytes.length === 0) return;
    const p = this.#port(port);
    let t: number;
    if (time instanceof Float64Array) {
      if (time.length !== bytes.length) throw new TypeError(`per-byte times have length ${time.length}, bytes ${bytes.length}`);
      t = time[time.length - 1] ?? NaN;
      if (this.#precise) for (let i = 0; i < time.length; i++) p.burst.event(time[i] ?? NaN);
      // Book per second: bytes of a chunk rarely straddle more than one.
      for (let i = 0; i < time.length; i++) p.bins.add(M_BYTES, time[i] ?? NaN, 1);
      this.#activity(p, time[0] ?? NaN, 0);
    } else {
      t = time ?? p.lastTimeUs;
      p.bins.add(M_BYTES, t, bytes.length);
    }
    this.#activity(p, t, bytes.length);
    p.scanTimeUs = t;
    p.scanner.push(bytes);
  }

  /**
   * A read error the port reported, by its WebSerial name: 'FramingError', 'ParityError',
   * 'BreakError', 'BufferOverrunError' (others are ignored).
   */
  lineError(port: number, name: string, timeUs: number): void {
    const p = this.#port(port);
    const t = Number.isFinite(timeUs) ? timeUs : p.lastTimeUs;
    if (name === 'FramingError' || name === 'ParityError') p.bins.add(M_CHAR_ERRORS, t, 1);
    else if (name === 'BreakError') p.bins.add(M_BREAKS, t, 1);
    else if (name === 'BufferOverrunError') p.bins.add(M_OVERRUNS, t, 1);
    else return;
    if (this.#precise) p.burst.event(t);
    this.#activity(p, t, 1);
  }

  /** A decoded frame of this port, after the port's link monitor has counted it. Borrowed: nothing is kept. */
  frame(port: number, f: DecodedFrame): void {
    const p = this.#port(port);
    const t = f.timeUs;
    p.frames++;
    p.bins.add(M_FRAME_BYTES, t, FRAME_SIZE);
    p.guess.frame(f.bytes);
    for (let i = 0; i < f.count; i++) {
      const id = f.ids[i] ?? 0;
      if (id >= 12) {
        if (p.xplusMask === 0) p.xplusFirstUs = t;
        p.xplusMask |= 1 << (id - 12);
      }
    }
    if (f.vtx !== null) {
      if (p.vtxFrames === 0) p.vtxFirstUs = t;
      p.vtxFrames++;
    }
    if (f.rssi !== null) p.rssiFrames++;
    // Fades and missed frames per second, for "which fades most" and "do they fade together".
    const link = p.source?.link;
    // A frame after discarded bytes ends a gap the line made (the decoder dropped frames with the
    // damage), not the radio link.
    const discarded = p.source?.decoder.stats.discardedBytes ?? 0;
    if (discarded > p.prevDiscarded && p.frames > 1 && Number.isFinite(t)) {
      p.damagedAtUs.push(t);
      if (p.damagedAtUs.length > 256) p.damagedAtUs.shift();
    }
    p.prevDiscarded = discarded;
    if (link !== undefined) {
      const missed = link.stats.lostFrames;
      p.bins.add(M_MISSED, t, missed - p.prevMissed);
      p.prevMissed = missed;
    }
    // A counter that went back down after a gap is a receiver that restarted (power), not a
    // wrap: a wrap after a gap adds about as many fades as frames were missed.
    if (f.fades !== null && p.prevFades !== null && Number.isFinite(t) && Number.isFinite(p.prevFrameUs)) {
      const gap = t - p.prevFrameUs;
      const modulus = f.remote === 'internal' ? 256 : 65536;
      const period = link !== undefined && Number.isFinite(link.stats.nominalPeriodUs) ? link.stats.nominalPeriodUs : 22_000;
      const expected = Math.max(0, Math.round(gap / period) - 1);
      const wrapped = (f.fades - p.prevFades + modulus) % modulus;
      const restarted = f.fades < p.prevFades && gap >= RESTART_MIN_GAP_US && Math.abs(wrapped - expected) > Math.max(8, 0.5 * expected);
      if (restarted) p.restarts.push({ timeUs: t, from: p.prevFades, to: f.fades, gapUs: gap });
      else p.bins.add(M_FADES, t, f.fadesDelta);
    }
    if (f.fades !== null) p.prevFades = f.fades;
    p.prevFrameUs = t;
    // The format a remote was bound in; a change after that is a rebind (or another receiver).
    // (A snapshot is made only when it is kept: nothing is allocated per frame.)
    const ref = p.changes.length > 0 ? (p.changes[p.changes.length - 1] as { to: FormatSnapshot }).to : p.first;
    if (ref === null) {
      if (p.frames >= 2) p.first = { system: f.system, resolution: f.resolution, remote: f.remote, timeUs: t }; // the decoder may revise its first reading once
    } else if (ref.system !== f.system || ref.resolution !== f.resolution || ref.remote !== f.remote) {
      p.changes.push({ timeUs: t, from: ref, to: { system: f.system, resolution: f.resolution, remote: f.remote, timeUs: t } });
    }
  }

  /** The findings at `nowUs`, worst first. */
  findings(nowUs: number): DoctorFinding[] {
    const out: DoctorFinding[] = [];
    const add = (f: Omit<DoctorFinding, 'sinceUs'> & { sinceUs?: number }): void => {
      // JSON-safe: a time that is not known is null, never NaN.
      const evidence = f.evidence.map((e) => (e.timeUs === null || Number.isFinite(e.timeUs) ? e : { ...e, timeUs: null }));
      out.push({ ...f, evidence, sinceUs: f.sinceUs !== undefined && Number.isFinite(f.sinceUs) ? f.sinceUs : nowUs });
    };
    const ports = [...this.#ports.values()].sort((a, b) => a.port - b.port);
    for (const p of ports) {
      this.#nothing(p, nowUs, add);
      const verdict = this.#lineVerdict(p, nowUs);
      this.#line(p, verdict, nowUs, add);
      if (p.source !== null && p.frames > 0 && verdict.kind !== 'packets') this.#satellite(p, nowUs, add);
    }
    this.#system(
      ports.filter((p) => p.source !== null && p.frames >= SETUP_MIN_FRAMES),
      nowUs,
      add,
    );
    // Stable "since": a finding keeps the time it first appeared while it goes on holding.
    const seen = new Set<string>();
    for (const f of out) {
      const key = `${f.code}:${f.ports.join(',')}`;
      seen.add(key);
      const first = this.#since.get(key);
      if (first === undefined || first > nowUs) this.#since.set(key, Math.min(f.sinceUs, nowUs));
      f.sinceUs = this.#since.get(key) ?? f.sinceUs;
    }
    for (const key of [...this.#since.keys()]) if (!seen.has(key)) this.#since.delete(key);
    out.sort(
      (a, b) =>
        SEVERITY_ORDER[a.severity] - SEVERITY_ORDER[b.severity] ||
        CONFIDENCE_ORDER[a.confidence] - CONFIDENCE_ORDER[b.confidence] ||
        (a.ports[0] ?? 0) - (b.ports[0] ?? 0),
    );
    return out;
  }

  // -------------------------------------------------------------------------------------------

  #nothing(p: PortState, now: number, add: (f: Omit<DoctorFinding, 'sinceUs'> & { sinceUs?: number }) => void): void {
    if (!Number.isFinite(p.openUs) || p.activity > 0) return;
    const silent = now - p.openUs;
    if (silent < NOTHING_AFTER_US) return;
    add({
      code: 'nothing-arrives',
      ports: [p.port],
      severity: 'problem',
      confidence: silent >= NOTHING_CERTAIN_US ? 'certain' : 'likely',
      title: `${p.label}: nothing arrives`,
      evidence: [
        {
          text: `No byte and no line error in ${dur(silent)} since the port opened at ${p.baudRate} baud; a satellite with a link sends a frame every 11 or 22 ms, and nothing at all without one (spec §7.1).`,
          timeUs: p.openUs,
        },
      ],
      todo: NOTHING_TODO,
      settings: [],
      confirm: null,
      sinceUs: p.openUs + NOTHING_AFTER_US,
    });
  }

  #lineVerdict(p: PortState, now: number): LineVerdict {
    const toS = Math.floor(now / 1e6);
    const fromS = toS - LINE_WINDOW_BINS + 1;
    const windowStart = Math.max(fromS * 1e6, Number.isFinite(p.firstActivityUs) ? p.firstActivityUs : fromS * 1e6);
    const seconds = Math.max(
      0,
      (Math.min(now, Number.isFinite(p.lastActivityUs) ? Math.max(p.lastActivityUs, windowStart) : now) - windowStart) / 1e6,
    );
    const packets = { ibus: 0, 'srxl-v1': 0, srxl2: 0, crsf: 0, sbus: 0 } as Record<PacketKind, number>;
    PACKET_KINDS.forEach((k, i) => {
      packets[k] = p.bins.sum(M_PACKETS + i, fromS, toS);
    });
    return classifyLine({
      seconds: Math.max(seconds, 0.5),
      bytes: p.bins.sum(M_BYTES, fromS, toS),
      frameBytes: p.bins.sum(M_FRAME_BYTES, fromS, toS),
      characterErrors: p.bins.sum(M_CHAR_ERRORS, fromS, toS),
      breaks: p.bins.sum(M_BREAKS, fromS, toS),
      packets,
      burstPeriodUs: this.#precise ? p.burst.periodUs(fromS * 1e6) : NaN,
    });
  }

  #line(p: PortState, v: LineVerdict, now: number, add: (f: Omit<DoctorFinding, 'sinceUs'> & { sinceUs?: number }) => void): void {
    const toS = Math.floor(now / 1e6);
    const fromS = toS - LINE_WINDOW_BINS + 1;
    const overruns = p.bins.sum(M_OVERRUNS, fromS, toS);
    if (overruns > 0) {
      add({
        code: 'overrun',
        ports: [p.port],
        severity: 'info',
        confidence: 'certain',
        title: `${p.label}: bytes were lost before they reached SatScope`,
        evidence: [{ text: `${plural(overruns, 'buffer overrun')} reported by the port in the last ${LINE_WINDOW_BINS} s.`, timeUs: null }],
        todo: [
          "Close other programs that read the port; use a shorter USB cable or another USB port; gaps in the data around these times are not the satellite's.",
        ],
        settings: [],
        confirm: null,
      });
    }
    if (v.kind === 'satellite') {
      p.confirmed = null;
      return;
    }
    if (p.baudRate !== 115_200) return; // probing: judged when the port returns to 115200
    const window = `in the last ${LINE_WINDOW_BINS} s`;
    const foreign = (
      protocol: ForeignProtocol,
      confidence: Confidence,
      evidence: Evidence[],
      extra: string[] = [],
      confirm: ConfirmProbe | null = null,
    ): void => {
      const name = PROTOCOL_SETTINGS[protocol].name;
      const c = p.confirmed?.protocol === protocol ? 'certain' : confidence;
      const ev =
        p.confirmed?.protocol === protocol
          ? [
              ...evidence,
              {
                text: `Confirmed: ${plural(p.confirmed.packets, `valid ${name} packet`)} when listening at ${p.confirmed.baudRate} baud.`,
                timeUs: p.confirmed.timeUs,
              },
            ]
          : evidence;
      add({
        code: protocol,
        ports: [p.port],
        severity: 'problem',
        confidence: c,
        title: `${p.label}: this is ${name}, not a Spektrum satellite`,
        evidence: ev,
        todo: [
          `Set the flight controller's serial receiver to ${name} (settings below), or connect a Spektrum satellite if that is what you meant to use.`,
          ...extra,
        ],
        settings: foreignSettings(protocol),
        confirm: c === 'certain' ? null : confirm,
      });
    };
    switch (v.kind) {
      case 'too-little':
        return;
      case 'packets': {
        const bytes = p.bins.sum(M_BYTES, fromS, toS);
        const what =
          v.protocol === 'ibus'
            ? '32-byte packets starting 0x20 0x40 with valid checksums'
            : v.protocol === 'srxl2'
              ? `packets starting 0xA6 with valid CRCs${p.scanner.lastSrxl2Type === 0xcd ? ' (channel data, 0xA6 0xCD)' : p.scanner.lastSrxl2Type === 0x21 ? ' (handshakes, 0xA6 0x21)' : ''}`
              : '18-byte packets starting 0xA5 with valid CRCs';
        const extra =
          v.protocol === 'srxl2'
            ? [
                "SRXL2 (e.g. an SPM4651T) is a two-way, single-wire protocol: on the flight controller it goes to a UART's TX pin in half-duplex (Betaflight and iNav set that up for SRXL2).",
              ]
            : v.protocol === 'srxl-v1'
              ? ["SRXL v1 comes from a full Spektrum receiver's SRXL port, not from a satellite."]
              : [];
        foreign(
          v.protocol,
          v.count >= 10 ? 'certain' : 'likely',
          [
            {
              text: `${plural(v.count, 'packet')} ${window}: ${what}, in ${plural(bytes, 'byte')} at 115200 8N1; no Spektrum satellite frames.`,
              timeUs: null,
            },
          ],
          extra,
        );
        return;
      }
      case 'inverted-satellite':
      case 'idle-low': {
        const period =
          v.kind === 'inverted-satellite'
            ? ` one every ${(v.periodUs / 1000).toFixed(1)} ms${v.confident ? ", a satellite's frame period" : ''}`
            : '';
        add({
          code: 'inverted-line',
          ports: [p.port],
          severity: 'problem',
          confidence: v.kind === 'inverted-satellite' ? (v.confident ? 'likely' : 'possible') : 'possible',
          title:
            v.kind === 'inverted-satellite'
              ? `${p.label}: the line is inverted: a satellite seen through an inverter`
              : `${p.label}: the line idles low (inverted)`,
          evidence: [
            {
              text: `${plural(Math.round(v.breaksPerSecond * 10) / 10, 'break condition')} a second (the line held low between packets),${period}; about ${v.bytesPerBreak.toFixed(1)} bytes between breaks, most of them with framing errors. A satellite's line idles high.`,
              timeUs: null,
            },
          ],
          todo: [
            'Connect DATA to an input without an inverter: on many F4 flight controllers the "SBUS" pad or a UART with an SBUS inverter inverts; use another UART\'s RX, or the pad marked for Spektrum/DSM.',
            'If the UART has a switchable inverter, turn it off: Betaflight and iNav `set serialrx_inverted = ON` undoes the inverter for a Spektrum provider (only where the hardware allows it).',
            'On this adapter: a plain 3.3 V USB-serial adapter\'s RX, not an "SBUS" or inverted input.',
          ],
          settings: [],
          confirm: null,
        });
        return;
      }
      case 'sbus':
        foreign(
          'sbus',
          v.confident ? 'likely' : 'possible',
          [
            {
              text: `The line idles low with ${Math.round(v.breaksPerSecond * 10) / 10} breaks a second (one packet every ${(v.periodUs / 1000).toFixed(1)} ms) and about ${v.bytesPerBreak.toFixed(1)} bytes between them: the shape of SBUS's 25-byte packets at 100000 baud 8E2, inverted.`,
              timeUs: null,
            },
          ],
          [
            "SBUS needs an inverted input (the flight controller's SBUS pad); on a flight controller without one, use an SBUS inverter or the receiver's non-inverted output.",
          ],
          {
            baudRate: 100_000,
            parity: 'even',
            stopBits: 2,
            listenUs: 1_000_000,
            note: 'Only through an adapter that inverts its RX (e.g. an FT232R with RXD inverted in its EEPROM): WebSerial cannot invert.',
          },
        );
        return;
      case 'crsf':
        foreign(
          'crsf',
          'likely',
          [
            {
              text: `Framing errors on most characters and bursts every ${(v.periodUs / 1000).toFixed(2)} ms (${Math.round(1e6 / v.periodUs)} Hz, a CRSF packet rate): a faster signal with normal polarity.`,
              timeUs: null,
            },
          ],
          [],
          {
            baudRate: 420_000,
            parity: 'none',
            stopBits: 1,
            listenUs: 500_000,
            note: 'Listen at 420000 8N1 to find CRSF sync bytes (0xC8) and checksums, then return to 115200.',
          },
        );
        return;
      case 'other-speed':
        if (p.confirmed?.protocol === 'crsf') {
          foreign('crsf', 'certain', [
            { text: `${Math.round(v.errorRatio * 100)} % of characters had framing errors at 115200.`, timeUs: null },
          ]);
          return;
        }
        add({
          code: 'wrong-speed',
          ports: [p.port],
          severity: 'problem',
          confidence: 'possible',
          title: `${p.label}: a signal at another speed, not a satellite at 115200`,
          evidence: [
            {
              text: `${Math.round(v.errorRatio * 100)} % of characters had framing errors ${window}, and no breaks: the line idles high like a UART, but its bits are not 115200 baud.`,
              timeUs: null,
            },
          ],
          todo: [
            'CRSF (Crossfire, ExpressLRS) runs at 420000 baud: if that is the receiver, set the flight controller to CRSF (Betaflight/iNav `set serialrx_provider = CRSF`).',
            'A satellite sends at 115200 only; anything else on this wire is another device, or noise from a loose ground.',
          ],
          settings: [],
          confirm: {
            baudRate: 420_000,
            parity: 'none',
            stopBits: 1,
            listenUs: 500_000,
            note: 'Listen at 420000 8N1 for CRSF packets, then return to 115200.',
          },
        });
        return;
      case 'noise':
        add({
          code: 'noise',
          ports: [p.port],
          severity: 'problem',
          confidence: 'likely',
          title: `${p.label}: noise on the line, not data`,
          evidence: [
            {
              text: `${Math.round(v.breaksPerSecond)} break conditions a second at no steady rate and ${Math.round(v.errorRatio * 100)} % framing errors ${window}: levels that change at random, not characters.`,
              timeUs: null,
            },
          ],
          todo: [
            "Connect ground: black (GND) of the satellite to the adapter's GND. An input without a common ground picks up noise.",
            "Check that DATA (grey) is on the adapter's RX and the connector is seated; a floating RX pin reads noise.",
            'Keep the lead away from motor and ESC wiring.',
          ],
          settings: [],
          confirm: null,
        });
        return;
      case 'unknown-115200':
        // A satellite's first frames wait for the decoder's evidence: give it time to lock.
        if (now - p.firstActivityUs < UNKNOWN_AFTER_US || p.source?.decoder.format.locked === true) return;
        add({
          code: 'unknown-stream',
          ports: [p.port],
          severity: 'warning',
          confidence: 'possible',
          title: `${p.label}: clean bytes at 115200, but not Spektrum frames`,
          evidence: [
            {
              text: `${plural(v.bytes, 'byte')} ${window} without line errors, in no known RC packet (Spektrum, SRXL, SRXL2, IBUS).`,
              timeUs: null,
            },
          ],
          todo: [
            "This is another device at 115200 8N1 (a GPS, a telemetry radio, a flight controller's output?). Check which wire is on the adapter: a satellite's grey DATA wire.",
          ],
          settings: [],
          confirm: null,
        });
        return;
    }
  }

  #satellite(p: PortState, now: number, add: (f: Omit<DoctorFinding, 'sinceUs'> & { sinceUs?: number }) => void): void {
    const source = p.source as DoctorPortSource;
    const format: FormatInfo = source.decoder.format;
    const link = source.link;
    if (!format.locked || format.resolution === null || format.remote === null) return;
    const resolution = format.resolution;
    const remote = format.remote;
    const period = link.stats.nominalPeriodUs;
    const info = format.system !== null ? systemInfo(format.system) : undefined;
    const sure: Confidence = format.resolutionReason === 'channel-ids' ? 'likely' : 'certain';
    const protocolText =
      info !== undefined ? info.name : `${resolution}, ${Number.isFinite(period) ? `${period / 1000} ms` : 'period not yet measured'}`;

    // What to set.
    const guessNote = this.#guessNotes(p, resolution);
    add({
      code: 'fc-settings',
      ports: [p.port],
      severity: 'info',
      confidence: sure,
      title: `${p.label}: flight controller settings for this ${protocolText} ${remote} remote`,
      evidence: [{ text: format.explanation, timeUs: null }],
      todo: [`Betaflight / iNav: serialrx_provider = ${resolution === 2048 ? 'SPEK2048' : 'SPEK1024'} (lines below).`],
      settings: [
        ...satelliteSettings({ resolution, periodUs: period, remote, system: format.system }),
        { stack: 'ArduPilot', lines: [], note: guessNote.ardupilot },
        { stack: 'PX4', lines: [], note: guessNote.px4 },
      ],
      confirm: null,
    });

    // The mode it was bound in, against §7.2's recommendation.
    const slow = Number.isFinite(period) && period > 16_500;
    if (resolution === 1024 || slow || (info !== undefined && info.protocol === 'DSM2')) {
      const pulses = bindPulses('DSMX', 11, remote);
      add({
        code: 'bind-mode',
        ports: [p.port],
        severity: resolution === 1024 ? 'warning' : 'info',
        confidence: sure,
        title: `${p.label}: bound in ${protocolText}; DSMX 11 ms is better`,
        evidence: [
          {
            text: `${resolution === 1024 ? 'Servo positions have 1024 steps (DSM2 22 ms, spec §8.1), half the precision of 2048. ' : ''}${slow ? `A frame every ${(link.stats.periodUs / 1000 || period / 1000).toFixed(1)} ms, twice the latency of 11 ms. ` : ''}Spec §7.2 recommends binding DSMX 11 ms: 9 pulses internal, 10 external.`,
            timeUs: null,
          },
        ],
        todo: [
          `Bind again in DSMX 11 ms, ${remote}: ${pulses} pulses (Betaflight/iNav \`set spektrum_sat_bind = ${pulses}\`, save, power-cycle, bind, set it back to 0; or SatScope's Bind panel).`,
          'A DSM2-only satellite (SPM9545) cannot bind DSMX; a DSM2-only transmitter falls back to DSM2 by itself when bound in a DSMX mode (spec §7.2).',
          resolution === 1024
            ? 'Until then the flight controller must use SPEK1024, or every channel reads wrong.'
            : 'Until then SPEK2048 reads it correctly.',
        ],
        settings: [],
        confirm: null,
      });
    }

    if (format.resolutionReason === 'system-byte-contradicted') {
      add({
        code: 'system-byte-contradicted',
        ports: [p.port],
        severity: 'warning',
        confidence: 'certain',
        title: `${p.label}: the system byte names one resolution, the data is in the other`,
        evidence: [{ text: format.explanation, timeUs: null }],
        todo: [
          `Set Betaflight/iNav to ${resolution === 2048 ? 'SPEK2048' : 'SPEK1024'}, what the data is, not what the system byte says.`,
          'ArduPilot and PX4 ignore the system byte and guess the resolution from the channel IDs, so they are not misled by it; stacks or tools that trust byte 1 are.',
          'This is a clone or a misbehaving receiver: a genuine Spektrum remote sends a system byte that matches its data (spec §8.3).',
        ],
        settings: [],
        confirm: null,
      });
    }

    if (p.xplusMask !== 0) {
      const names = [];
      for (let i = 0; i < 8; i++) if ((p.xplusMask >> i) & 1) names.push(`X+${i + 1}`);
      add({
        code: 'xplus-channels',
        ports: [p.port],
        severity: 'warning',
        confidence: 'certain',
        title: `${p.label}: X-Plus channels ${names.join(', ')} are sent; flight controllers drop or mix them`,
        evidence: [
          { text: `X-Plus channels (ID 12 with a sub-ID, spec §8.6) seen since ${this.#at(p.xplusFirstUs)}.`, timeUs: p.xplusFirstUs },
        ],
        todo: [
          'Betaflight and iNav read channel IDs 0–11 only (SPEKTRUM_MAX_SUPPORTED_CHANNEL_COUNT 12): X-Plus channels are dropped.',
          'ArduPilot (AP_RCProtocol_DSM.cpp) takes every X-Plus word as channel 13, whatever its sub-ID, and reports 13 channels as 12. PX4 reads them as channels 13 and up (its tests expect 16 channels from a DX9 with X+1…X+4).',
          'Put functions the flight controller needs on channels 1–12, and turn X-Plus off in the transmitter if nothing uses it.',
        ],
        settings: [],
        confirm: null,
      });
    }

    if (p.vtxFrames > 0) {
      add({
        code: 'vtx-frames',
        ports: [p.port],
        severity: 'info',
        confidence: 'certain',
        title: `${p.label}: the transmitter sends VTX control in the channel slots`,
        evidence: [
          {
            text: `${plural(p.vtxFrames, 'frame')} carried Spektrum VTX control in bytes 12–15 (0xE… 0xE…), first at ${this.#at(p.vtxFirstUs)}.`,
            timeUs: p.vtxFirstUs,
          },
        ],
        todo: [
          "Betaflight (spektrum.c, with USE_SPEKTRUM_VTX_CONTROL) and ArduPilot (AP_RCProtocol_DSM.cpp) take these frames' last two slots out of the channel data and set the VTX from them; a stack or build without Spektrum VTX support reads the two words as channel data.",
          'Turn VTX control off in the transmitter if the flight controller does not use it.',
        ],
        settings: [],
        confirm: null,
      });
    }

    const g = p.guess.outcomes;
    const tries = g[10] + g[11] + g.none;
    const want = resolution === 2048 ? 11 : 10;
    if (tries >= GUESS_MIN_DECISIONS && g[want] < tries / 2) {
      add({
        code: 'autopilot-detection',
        ports: [p.port],
        severity: 'warning',
        confidence: 'likely',
        title: `${p.label}: ArduPilot may not read this stream by itself`,
        evidence: [
          {
            text: `Channel IDs in ${ARDUPILOT_GUESS_FRAMES} frames read as 11-bit: ${channelSetText(p.guess.last11)}; as 10-bit: ${channelSetText(p.guess.last10)}.`,
            timeUs: null,
          },
          { text: guessNote.ardupilot, timeUs: null },
        ],
        todo: [
          'ArduPilot guesses 10- or 11-bit from the channel numbers, not from the system byte, and needs exactly one reading to give channels 0…n−1 (5 to 16 of them). Change the number of channels the transmitter sends, or bind in DSMX 11 ms (2048), which it tells apart easily.',
          "Check the result on ArduPilot's radio calibration page: every stick must move one bar.",
        ],
        settings: [],
        confirm: null,
      });
    }

    // The link.
    const s = link.stats;
    const memoryStart = now - this.#memoryUs;
    const episodes = link.episodes.filter((e) => (e.endUs ?? now) >= memoryStart);
    const failsafes = episodes.filter((e) => e.kind === 'failsafe');
    // Holds that line damage explains (the frame that ended them came after discarded bytes) are
    // the line's, not the link's.
    const byLine = (e: { lastFrameUs: number; endUs: number | null }) =>
      e.endUs !== null && p.damagedAtUs.some((d) => d > e.lastFrameUs && d <= e.endUs! + 50_000);
    const holds = episodes.filter((e) => e.kind === 'hold' && !failsafes.some((f) => f.lastFrameUs === e.lastFrameUs) && !byLine(e));
    const fadesPerMin = s.fadeRate * 60;
    // A rate needs a few fades behind it: one corrupted header is not a weak link.
    const recentFades = p.bins.sum(M_FADES, Math.floor(now / 1e6) - 9, Math.floor(now / 1e6));
    const fadeHigh = format.headerMode === 'fades' && fadesPerMin > REPORT_THRESHOLDS.fadeRateHighPerMin && recentFades >= MIN_FADES;
    const rssiLow = Number.isFinite(s.minRssi) && s.minRssi < REPORT_THRESHOLDS.rssiLowDbm;
    if (failsafes.length > 0 || holds.length > 0 || fadeHigh || rssiLow) {
      const evidence: Evidence[] = [];
      for (const e of failsafes.slice(-5))
        evidence.push({
          text: `Failsafe: no frame for over 1 s after ${this.#at(e.lastFrameUs)}${e.endUs === null ? ', still now' : `, back at ${this.#at(e.endUs)}`} (spec §7.1).`,
          timeUs: e.startUs,
        });
      if (holds.length > 0) {
        const last = holds[holds.length - 1] as (typeof holds)[number];
        evidence.push({
          text: `${plural(holds.length, 'hold')} (frames stopped, last values held, recovered), the last at ${this.#at(last.startUs)}.`,
          timeUs: last.startUs,
        });
      }
      if (fadeHigh)
        evidence.push({
          text: `Fade rate ${fadesPerMin.toFixed(0)} a minute over the last ~500 frames (over ${REPORT_THRESHOLDS.fadeRateHighPerMin} a minute is high).`,
          timeUs: null,
        });
      if (rssiLow)
        evidence.push({
          text: `RSSI down to ${s.minRssi} dBm (below ${REPORT_THRESHOLDS.rssiLowDbm} dBm leaves little margin).`,
          timeUs: null,
        });
      add({
        code: 'weak-link',
        ports: [p.port],
        severity: failsafes.length > 0 ? 'problem' : 'warning',
        confidence: failsafes.length > 0 || fadeHigh || rssiLow || this.#precise ? 'certain' : 'likely',
        title: `${p.label}: the link is weak${failsafes.length > 0 ? ': failsafe' : holds.length > 0 ? ': frames lost' : ''}`,
        evidence,
        todo: LINK_ADVICE,
        settings: [],
        confirm: null,
      });
    }

    // Setup, per remote.
    const changes = p.changes.filter((c) => c.timeUs >= memoryStart);
    if (changes.length > 0) {
      const c = changes[changes.length - 1] as (typeof changes)[number];
      const name = (f: FormatSnapshot): string =>
        `${f.system !== null ? (systemInfo(f.system)?.name ?? `system 0x${f.system.toString(16)}`) : `${f.resolution}`} ${f.remote}`;
      add({
        code: 'rebind',
        ports: [p.port],
        severity: 'warning',
        confidence: 'certain',
        title: `${p.label}: the receiver changed mode mid-session (a rebind?)`,
        evidence: [{ text: `From ${name(c.from)} to ${name(c.to)} at ${this.#at(c.timeUs)}.`, timeUs: c.timeUs }],
        todo: [
          'A satellite changes mode only when it is bound again: check that the flight controller does not send bind pulses at every power-up (Betaflight/iNav: spektrum_sat_bind back to 0, or spektrum_sat_bind_autoreset on).',
          `Set the flight controller for the new mode: ${c.to.resolution === 2048 ? 'SPEK2048' : 'SPEK1024'}.`,
        ],
        settings: [],
        confirm: null,
        sinceUs: c.timeUs,
      });
    }
    const restarts = p.restarts.filter((r) => r.timeUs >= memoryStart);
    if (restarts.length > 0) {
      const r = restarts[restarts.length - 1] as (typeof restarts)[number];
      add({
        code: 'receiver-restart',
        ports: [p.port],
        severity: 'warning',
        confidence: 'likely',
        title: `${p.label}: the receiver restarted (power dip?)`,
        evidence: [
          {
            text: `${plural(restarts.length, 'restart')}: the fade counter went from ${r.from} back to ${r.to} after ${dur(r.gapUs)} without frames, at ${this.#at(r.timeUs)}; a counter only starts again from 0 at power-up.`,
            timeUs: r.timeUs,
          },
        ],
        todo: [
          'Check the 3.3 V supply (orange) under load: a brown-out restarts the satellite; power it from a regulator that does not sag when motors or servos draw current.',
          'Check the connector and wires for an intermittent contact.',
        ],
        settings: [],
        confirm: null,
        sinceUs: r.timeUs,
      });
    }
    if (format.headerMode === 'rssi') {
      add({
        code: 'rssi-receiver',
        ports: [p.port],
        severity: 'info',
        confidence: 'certain',
        title: `${p.label}: byte 0 carries RSSI (SPM4649T), not a fade count`,
        evidence: [
          {
            text: `Byte 0 is a signed dBm value (spec §8.3.1)${Number.isFinite(s.rssi) ? `: now ${s.rssi} dBm, lowest ${s.minRssi} dBm` : ''}; −128 marks a lost frame.`,
            timeUs: null,
          },
        ],
        todo: [
          'Judge this remote by RSSI and lost frames, not by fades: it counts none.',
          'PX4 reads a negative byte 0 as RSSI (dsm.cpp); stacks that read byte 0 as fades, or ignore it, show no RSSI for it.',
        ],
        settings: [],
        confirm: null,
      });
    }
  }

  /** What ArduPilot's guess makes of this remote's frames, and what is known of PX4, as sentences. */
  #guessNotes(p: PortState, resolution: Resolution): { ardupilot: string; px4: string } {
    const d = p.guess.outcomes;
    const want = resolution === 2048 ? 11 : 10;
    const other = want === 11 ? 10 : 11;
    const n = d[10] + d[11] + d.none;
    const where = 'AP_RCProtocol_DSM.cpp, replayed';
    let ardupilot =
      n === 0
        ? `Detects the DSM protocol by itself (${where}: not enough frames yet).`
        : d[want] === n
          ? `Detects it by itself: its 10/11-bit guess settles on ${want}-bit (${resolution}) (${where}).`
          : d.none === n
            ? `Its 10/11-bit guess never settles (${n} tries), so it would output no channels (${where}).`
            : `Its 10/11-bit guess settled on ${want}-bit in ${d[want]} of ${n} tries${d[other] > 0 ? `, on the wrong ${other}-bit reading in ${d[other]}` : ''} (${where}).`;
    if (p.xplusMask !== 0)
      ardupilot +=
        ' It takes every X-Plus word as channel 13 whatever its sub-ID, and reports 13 channels as 12: X-Plus channels are not usable.';
    const px4 = `rc_input detects DSM by itself and guesses the resolution from the channel IDs (src/lib/rc/dsm.cpp)${p.xplusMask !== 0 ? '; its tests expect X-Plus channels as channels 13 and up (rc_tests/RCTest.cpp, 16 channels from a DX9)' : ''}.`;
    return { ardupilot, px4 };
  }

  /** Findings about several remotes together. */
  #system(ports: PortState[], now: number, add: (f: Omit<DoctorFinding, 'sinceUs'> & { sinceUs?: number }) => void): void {
    if (ports.length < 2) return;
    const locked = ports.filter((p) => (p.source as DoctorPortSource).decoder.format.locked);
    const labels = (ps: PortState[]): string => ps.map((p) => p.label).join(', ');
    const all = locked.map((p) => p.port);
    // §7.3: exactly one internal ("A") remote.
    const internal = locked.filter((p) => (p.source as DoctorPortSource).decoder.format.remote === 'internal');
    if (locked.length >= 2 && internal.length !== 1) {
      add({
        code: 'internal-count',
        ports: all,
        severity: 'problem',
        confidence: 'certain',
        title:
          internal.length === 0
            ? 'No internal ("A") remote among these remotes'
            : `${internal.length} internal ("A") remotes: exactly one is allowed`,
        evidence: [
          {
            text:
              internal.length === 0
                ? `${labels(locked)} all send external frames (a 16-bit fade count, no system byte).`
                : `${labels(internal)} each send a system byte in byte 1 (internal frames).`,
            timeUs: null,
          },
        ],
        todo: [
          'Spec §7.3: exactly one remote binds internal ("A"); it negotiates with the transmitter for all. With none, binding fails; with several, "the results cannot be predicted".',
          'Bind all remotes again at the same time: one internal (DSMX 11 ms: 9 pulses), every other one external (10 pulses).',
        ],
        settings: [],
        confirm: null,
      });
    }
    // §8: all remotes 1024 or all 2048.
    const resolutions = new Set(locked.map((p) => (p.source as DoctorPortSource).decoder.format.resolution));
    const periods = new Set(locked.map((p) => (p.source as DoctorPortSource).link.stats.nominalPeriodUs).filter((x) => Number.isFinite(x)));
    if (resolutions.size > 1 || periods.size > 1) {
      add({
        code: 'resolution-mismatch',
        ports: all,
        severity: 'warning',
        confidence: 'likely',
        title: 'The remotes disagree on the format',
        evidence: locked.map((p) => {
          const s = p.source as DoctorPortSource;
          return {
            text: `${p.label}: ${s.decoder.format.resolution ?? '?'} resolution, ${Number.isFinite(s.link.stats.nominalPeriodUs) ? `${s.link.stats.nominalPeriodUs / 1000} ms` : '? ms'} frames (${s.decoder.format.remote ?? '?'}).`,
            timeUs: null,
          };
        }),
        todo: [
          'Spec §8: all remotes of one system are in 1024 mode or all in 2048, and the internal remote sets it. Remotes that differ were bound at different times or to different transmitters.',
          'Bind them again together: one internal, the others external, in DSMX 11 ms.',
        ],
        settings: [],
        confirm: null,
      });
    }
    // Who fades most, and do they fade together (per second over the memory window).
    const toS = Math.floor(now / 1e6);
    const fromS = Math.max(toS - Math.min(BIN_COUNT - 1, Math.ceil(this.#memoryUs / 1e6)), -Infinity);
    // An SPM4649T counts no fades (byte 0 is RSSI): when one is among fade-counting remotes,
    // compare them all by frames lost, the one measure they share.
    const modes = new Set(locked.map((p) => (p.source as DoctorPortSource).decoder.format.headerMode));
    const mixed = modes.size > 1;
    const lossOf = (p: PortState, s: number): number => (mixed ? 0 : p.bins.at(M_FADES, s)) + p.bins.at(M_MISSED, s);
    const totals = locked
      .map((p) => ({ p, loss: (mixed ? 0 : p.bins.sum(M_FADES, fromS, toS)) + p.bins.sum(M_MISSED, fromS, toS) }))
      .sort((a, b) => b.loss - a.loss);
    const top = totals[0];
    const second = totals[1];
    if (top !== undefined && second !== undefined && top.loss >= 10 && top.loss >= 2 * Math.max(1, second.loss)) {
      add({
        code: 'weakest-remote',
        ports: [top.p.port],
        severity: 'warning',
        confidence: 'certain',
        title: `${top.p.label} fades most`,
        evidence: [
          ...totals.map((t) => ({
            text: `${t.p.label}: ${mixed ? plural(t.loss, 'lost frame') : plural(t.loss, 'fade or lost frame', 'fades and lost frames')} in the last ${Math.min(toS - fromS + 1, BIN_COUNT)} s.`,
            timeUs: null,
          })),
          ...(mixed
            ? [{ text: 'Compared by frames lost only: one remote sends RSSI in byte 0 (SPM4649T) and counts no fades.', timeUs: null }]
            : []),
        ],
        todo: [
          `Move or turn ${top.p.label}: 90° from the other remote, away from carbon and metal, with line of sight to the transmitter (spec §5).`,
        ],
        settings: [],
        confirm: null,
      });
    }
    let any = 0;
    let together = 0;
    let firstTogether = NaN;
    for (let s = fromS; s <= toS; s++) {
      let n = 0;
      for (const p of locked) if (lossOf(p, s) > 0) n++;
      if (n >= 1) any++;
      if (n >= 2) {
        together++;
        if (Number.isNaN(firstTogether)) firstTogether = s * 1e6;
      }
    }
    if (locked.length >= 2 && together >= TOGETHER_MIN_SECONDS && together >= TOGETHER_RATIO * any) {
      add({
        code: 'fades-together',
        ports: all,
        severity: 'warning',
        confidence: 'likely',
        title: 'The remotes fade together',
        evidence: [
          {
            text: `In ${together} of the ${any} seconds with fades or lost frames, two remotes or more lost frames in the same second (first at ${this.#at(firstTogether)}).`,
            timeUs: firstTogether,
          },
        ],
        todo: [
          "A cause common to all remotes, not one remote's placement: the transmitter (range, antenna orientation, battery), or something on board that blankets every receiver (a VTX antenna next to them, ESC or motor noise).",
          'A power dip also stops every remote at once: check the 3.3 V supply they share.',
          'Range check with the transmitter in range-test mode; move the VTX antenna away from the satellites.',
        ],
        settings: [],
        confirm: null,
      });
    }
  }
}
