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
import { FRAME_SIZE } from '../decoder/spec.js';
import type { DecodedFrame } from '../decoder/types.js';
import { absenceEnds, absenceStarts, noAbsences } from './absences.js';
import { BurstClock } from './burst-clock.js';
import { PACKET_KINDS, PacketScanner, type PacketKind } from './doctor-line.js';
import { ArduPilotGuess } from './doctor-stacks.js';
import { adapterAwayFinding, lineFindings, lineVerdict, noSatelliteFinding, nothingFindings } from './doctor-line-rules.js';
import { formatClock } from './report-text.js';
import { satelliteFindings } from './doctor-satellite-rules.js';
import { systemFindings } from './doctor-system-rules.js';
import {
  Bins,
  M_BYTES,
  M_BREAKS,
  M_FF,
  M_TEXT,
  M_ZERO,
  M_CHAR_ERRORS,
  M_FADES,
  M_FRAME_BYTES,
  M_LOST,
  M_MISSED,
  M_OVERRUNS,
  M_PACKETS,
  SETUP_MIN_FRAMES,
  type FormatSnapshot,
  copiedParts,
  type PortCheckpoint,
  type PortState,
} from './doctor-state.js';
import type { AddFinding, Confidence, DoctorFinding, DoctorOptions, DoctorPortSource, RuleContext, Severity } from './doctor-types.js';

/** The census's metrics: 0x00, 0xFF, printable text. */
const CENSUS = [M_ZERO, M_FF, M_TEXT];
/** Bytes of a port kept from its start, for a file's signature. */
const HEAD_BYTES = 8;

const SEVERITY_ORDER: Record<Severity, number> = { problem: 0, warning: 1, info: 2 };
const CONFIDENCE_ORDER: Record<Confidence, number> = { certain: 0, likely: 1, possible: 2 };

/**
 * The doctor for one session. Ports are numbered by the caller (the capture's port indices);
 * call `attach` once per port before its frames, `open` when the port opens (and again when it
 * reopens, e.g. at another speed to confirm a finding), then feed and ask.
 */
export class Doctor {
  readonly #ports = new Map<number, PortState>();
  readonly #precise: boolean;
  readonly #timed: boolean;
  readonly #memoryUs: number;
  readonly #since = new Map<string, number>();
  readonly #originUs: number;
  /** The port state `#port` gave last (forgotten with its port by `detach`). */
  #last: PortState | null = null;

  /** @throws {TypeError} on an option out of range. */
  constructor(options: DoctorOptions = {}) {
    const timing = options.timing ?? 'per-chunk';
    if (timing !== 'per-byte' && timing !== 'per-chunk' && timing !== 'none')
      throw new TypeError(`timing must be 'per-byte', 'per-chunk' or 'none', not ${String(timing)}`);
    const memory = options.memoryUs ?? 60_000_000;
    if (!(memory > 0)) throw new TypeError(`memoryUs must be positive, not ${memory}`);
    const origin = options.originUs ?? 0;
    if (!Number.isFinite(origin)) throw new TypeError(`originUs must be a finite number, not ${origin}`);
    this.#precise = timing === 'per-byte';
    this.#timed = timing !== 'none';
    this.#memoryUs = memory;
    this.#originUs = origin;
  }

  /** A time in a sentence, from the origin, as the health report writes it ("0:02.7"). */
  #at(us: number): string {
    return formatClock(us - this.#originUs);
  }

  #port(port: number): PortState {
    // Bytes and frames come a port at a time: the last one asked for is usually asked for again.
    const last = this.#last;
    if (last !== null && last.port === port) return last;
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
        bytes: 0,
        head: [],
        ended: false,
        away: noAbsences(),
        lastTimeUs: NaN,
        bins: new Bins(),
        scanner: new PacketScanner((kind) => this.#packet(state, kind)),
        scanTimeUs: NaN,
        burst: new BurstClock(),
        confirmed: null,
        probePackets: { ibus: 0, 'srxl-v1': 0, srxl2: 0, crsf: 0, sbus: 0, fport: 0, ghst: 0 },
        packetsEver: { ibus: 0, 'srxl-v1': 0, srxl2: 0, crsf: 0, sbus: 0, fport: 0, ghst: 0 },
        frames: 0,
        guess: new ArduPilotGuess(),
        xplusMask: 0,
        xplusFirstUs: NaN,
        vtxFrames: 0,
        vtxFirstUs: NaN,
        firstFrameUs: NaN,
        prevFrameUs: NaN,
        prevMissed: 0,
        prevLost: 0,
        prevDiscarded: 0,
        damagedAtUs: [],
        first: null,
        changes: [],
        rssiFrames: 0,
      };
      p = state;
      this.#ports.set(port, p);
    }
    this.#last = p;
    return p;
  }

  #packet(p: PortState, kind: PacketKind): void {
    p.bins.add(M_PACKETS + PACKET_KINDS.indexOf(kind), p.scanTimeUs, 1);
    if (p.baudRate !== 115_200) p.probePackets[kind]++;
    p.packetsEver[kind]++;
  }

  /** The decoder and link monitor whose frames `frame()` will get for this port. */
  attach(port: number, source: DoctorPortSource): void {
    const p = this.#port(port);
    p.source = source;
    if (source.label !== undefined) p.label = source.label;
  }

  /**
   * The port's decoder and link monitor were restored (a replay seeking to a checkpoint): their
   * counters already hold what came before, none of it in this doctor's time, so the per-second
   * missed frames and damage count from where the counters stand now.
   */
  restored(port: number): void {
    const p = this.#port(port);
    p.prevMissed = p.source?.link?.stats.missedFrames ?? 0;
    p.prevLost = p.source?.link?.stats.lostFrames ?? 0;
    p.prevDiscarded = p.source?.decoder.stats.discardedBytes ?? 0;
  }

  /**
   * Everything this doctor holds of `port` (undefined when it holds nothing), as plain data no
   * later call changes: `restorePort` puts it into another doctor (a port decoded on another
   * thread), where it answers exactly as if that doctor had been fed the port itself. What the
   * doctor holds across ports (when each finding first held) is not in it.
   */
  portCheckpoint(port: number): PortCheckpoint | undefined {
    const p = this.#ports.get(port);
    if (p === undefined) return undefined;
    const { source: _source, bins, scanner, burst, guess, ...plain } = p;
    return {
      ...plain,
      ...copiedParts(p),
      bins: bins.checkpoint(),
      scanner: scanner.checkpoint(),
      burst: burst.checkpoint(),
      guess: guess.checkpoint(),
    };
  }

  /**
   * `port` as `cp` has it (from `portCheckpoint`, of this doctor or another), reading `source`'s
   * decoder and link monitor from now on: those must be at the same point of the stream (restored
   * from their own checkpoints of that moment). Whatever this doctor held of the port is replaced.
   */
  restorePort(port: number, cp: PortCheckpoint, source: DoctorPortSource): void {
    this.detach(port);
    const p = this.#port(port);
    const { bins, scanner, burst, guess, ...plain } = cp;
    Object.assign(p, plain, copiedParts(cp), { port, source });
    p.bins.restore(bins);
    p.scanner.restore(scanner);
    p.burst.restore(burst);
    p.guess.restore(guess);
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
    p.ended = false;
    p.firstActivityUs = NaN;
    p.activity = 0;
    p.bins.clear();
    p.burst.reset();
    for (const k of PACKET_KINDS) p.probePackets[k] = 0;
  }

  /**
   * The port's stream is over (the end of a capture, a replay that ended): it is judged on all
   * it held, however short (bytes without a frame: no satellite), until it opens again.
   */
  ended(port: number): void {
    this.#port(port).ended = true;
  }

  /** The port was closed or lost: no "nothing arrives" for it until it opens again. */
  close(port: number, timeUs = Number.NaN): void {
    const p = this.#port(port);
    p.openUs = NaN;
    absenceStarts(p.away, timeUs);
  }

  /**
   * Forgets a port entirely (it was removed, and its number may be given to another remote):
   * nothing it showed carries over to whatever is attached there next.
   */
  detach(port: number): void {
    this.#ports.delete(port);
    if (this.#last?.port === port) this.#last = null;
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
   * or nothing (then the last time seen on this port). The first `unscanned` of them are counted
   * but not scanned for foreign packets (`PacketScanner.pass`): for a caller that takes findings
   * only at one time and knows those bytes cannot change them (see `decodeCapture`). `start` and
   * `end`: only those bytes of `bytes` (and of per-byte times, indexed alike) arrived.
   */
  bytes(port: number, bytes: Uint8Array, time?: number | Float64Array, unscanned = 0, start = 0, end = bytes.length): void {
    const n = end - start;
    if (n <= 0) return;
    const p = this.#port(port);
    let t: number;
    if (time instanceof Float64Array) {
      if (time.length !== bytes.length) throw new TypeError(`per-byte times have length ${time.length}, bytes ${bytes.length}`);
      t = time[end - 1] ?? NaN;
      if (this.#precise) for (let i = start; i < end; i++) p.burst.event(time[i] ?? NaN);
      // Book per second: bytes of a chunk rarely straddle more than one.
      for (let i = start; i < end; i++) p.bins.add(M_BYTES, time[i] ?? NaN, 1);
      this.#activity(p, time[start] ?? NaN, 0);
    } else {
      t = time ?? p.lastTimeUs;
      p.bins.add(M_BYTES, t, n);
    }
    this.#activity(p, t, n);
    absenceEnds(p.away, time instanceof Float64Array ? (time[start] ?? NaN) : t);
    if (p.frames === 0) this.#census(p, bytes, start, end, time);
    p.bytes += n;
    p.scanTimeUs = t;
    if (unscanned <= 0) p.scanner.push(bytes, start, end);
    else {
      p.scanner.pass(Math.min(unscanned, n));
      if (unscanned < n) p.scanner.push(bytes, start + unscanned, end);
    }
  }

  /**
   * What bytes are, while the port has shown no frame: its first ones, and 0x00, 0xFF and text
   * per second, each byte booked where `bytes()` books it (per-byte times: its own).
   */
  #census(p: PortState, bytes: Uint8Array, start: number, end: number, time: number | Float64Array | undefined): void {
    for (let i = start; i < end && p.head.length < HEAD_BYTES; i++) p.head.push(bytes[i] as number);
    const counts = [0, 0, 0]; // 0x00, 0xFF, text
    for (let i = start; i < end; i++) {
      const b = bytes[i] as number;
      const kind = b === 0 ? 0 : b === 0xff ? 1 : (b >= 0x20 && b < 0x7f) || b === 0x0a || b === 0x0d || b === 0x09 ? 2 : -1;
      if (kind < 0) continue;
      if (time instanceof Float64Array) p.bins.add(CENSUS[kind] as number, time[i] ?? NaN, 1);
      else counts[kind] = (counts[kind] as number) + 1;
    }
    if (time instanceof Float64Array) return;
    const t = time ?? p.lastTimeUs;
    for (let k = 0; k < 3; k++) if ((counts[k] as number) > 0) p.bins.add(CENSUS[k] as number, t, counts[k] as number);
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
    // The bin every counter of this frame goes in, found once (a frame without a time: where
    // the bytes it came in were booked).
    const slot = Number.isNaN(t) ? p.bins.slotAt(p.lastTimeUs) : p.bins.slotOf(f);
    p.frames++;
    p.bins.addTo(slot, M_FRAME_BYTES, FRAME_SIZE);
    p.guess.frame(f.words);
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
      const { missedFrames, lostFrames } = link.stats;
      p.bins.addTo(slot, M_MISSED, missedFrames - p.prevMissed);
      p.bins.addTo(slot, M_LOST, lostFrames - p.prevLost);
      p.prevMissed = missedFrames;
      p.prevLost = lostFrames;
    }
    // Fades per second (a restarted counter's fall is none: the decoder gives it no delta).
    if (f.fadesDelta > 0) p.bins.addTo(slot, M_FADES, f.fadesDelta);
    if (p.frames === 1) p.firstFrameUs = t;
    p.prevFrameUs = t;
    // The format a remote was bound in; a change after that is a rebind (or another receiver).
    // (A snapshot is made only when it is kept: nothing is allocated per frame.)
    const ref = p.changes.length > 0 ? (p.changes[p.changes.length - 1] as { to: FormatSnapshot }).to : p.first;
    const ambiguous = p.source?.decoder.format.remoteAmbiguous ?? false;
    const snapshot = (): FormatSnapshot => ({ system: f.system, resolution: f.resolution, remote: f.remote, ambiguous, timeUs: t });
    if (ref === null) {
      if (p.frames >= 2) p.first = snapshot(); // the decoder may revise its first reading once
    } else if (ref.ambiguous && ref.remote === 'internal' && f.remote === 'external' && ref.resolution === f.resolution) {
      // The decoder re-read a header that read both ways: the same remote, read right from here.
      Object.assign(ref, snapshot());
    } else if (ref.system !== f.system || ref.resolution !== f.resolution || ref.remote !== f.remote) {
      p.changes.push({ timeUs: t, from: ref, to: snapshot() });
    } else if (ref.ambiguous && !ambiguous) {
      ref.ambiguous = false; // byte 0 moved: internal after all
    }
  }

  /** The findings at `nowUs`, worst first. */
  findings(nowUs: number): DoctorFinding[] {
    const out: DoctorFinding[] = [];
    const add: AddFinding = (f) => {
      // JSON-safe: a time that is not known is null, never NaN.
      const evidence = f.evidence.map((e) => (e.timeUs === null || Number.isFinite(e.timeUs) ? e : { ...e, timeUs: null }));
      out.push({ ...f, evidence, sinceUs: f.sinceUs !== undefined && Number.isFinite(f.sinceUs) ? f.sinceUs : nowUs });
    };
    const ctx: RuleContext = {
      at: (us) => this.#at(us),
      when: (word, us) => (this.#timed && Number.isFinite(us) ? ` ${word} ${this.#at(us)}` : ''),
      precise: this.#precise,
      timed: this.#timed,
      memoryUs: this.#memoryUs,
    };
    const ports = [...this.#ports.values()].sort((a, b) => a.port - b.port);
    for (const p of ports) {
      nothingFindings(p, nowUs, add);
      adapterAwayFinding(p, nowUs, ctx, add);
      const verdict = lineVerdict(p, nowUs, ctx);
      lineFindings(p, verdict, nowUs, ctx, add);
      noSatelliteFinding(p, verdict, nowUs, ctx, add);
      if (p.source !== null && p.frames > 0 && verdict.kind !== 'packets') satelliteFindings(p, nowUs, ctx, add);
    }
    systemFindings(
      ports.filter((p) => p.source !== null && p.frames >= SETUP_MIN_FRAMES),
      nowUs,
      ctx,
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
}
