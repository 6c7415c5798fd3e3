/**
 * The link-quality health report of a capture: for every serial port (one remote receiver
 * each), how often the link faded, how many frames were lost, how long it held and when it
 * went to failsafe, how regular the frame period was, which channels were seen and whether any
 * of them glitched: a JSON-serialisable object (`healthReport`); report-html.ts renders it as a page.
 *
 * Pure ECMAScript: no DOM, no Node, no clock. Every time in the report is relative to the
 * report's time zero (`timeline.originUs`, the earliest time recorded in the capture on any
 * port), so that the ports of a multi-port capture share one time axis.
 */
import type { Capture, CaptureKind, CaptureTiming } from '../capture/index.js';
import { capturePorts } from '../capture/index.js';
import type { LinkEpisode, MissedBasis } from '../decoder/index.js';
import {
  CHANNEL_COUNT,
  channelResolution,
  channelName,
  servoToMicros,
  servoToPercent,
  systemInfo,
  type Resolution,
  USB_CHUNK_JITTER_US,
} from '../decoder/index.js';
import { captureSpan, decodeCapture } from './capture-pass.js';
import type { Doctor } from './doctor.js';
import { looksInternal, readPorts } from './resolution-key.js';
import type { DecoderStats, FormatInfo, HeaderReading, RemoteKind, ResolutionReason } from '../decoder/index.js';

// ---------------------------------------------------------------------------------------------
// Thresholds
// ---------------------------------------------------------------------------------------------

/** Width of one bin of the per-second series, µs. */
export const REPORT_BIN_US = 1_000_000;

/**
 * Fades per minute above which the fade rate is called high. Spektrum's own rule of thumb
 * for its Flight Log is "about 100 fades per receiver in a 10-minute flight is fine", i.e.
 * 10 a minute; a satellite that fades more often is badly placed, shadowed or far out.
 */
export const FADE_RATE_HIGH_PER_MIN = 10;

/**
 * Lost-frame ratio (missed ÷ expected) worth a warning: 1 %. A healthy link close by loses
 * well under 0.5 % of its frames; above 1 % the flight controller sees stutter.
 */
export const LOST_RATIO_WARN = 0.01;

/** Lost-frame ratio called a problem: 5 %, one frame in twenty (at 11 ms, a 55 ms hole every quarter second on average). */
export const LOST_RATIO_PROBLEM = 0.05;

/**
 * Frame-period jitter (standard deviation of the gap-free inter-frame intervals) worth a
 * warning, as a fraction of the nominal period: 10 %. A receiver sends frames from a crystal
 * clock to within tens of µs; a logic analyser sees that. Only judged with per-byte timing:
 * chunk times carry the USB adapter's batching (16 ms), not the receiver's jitter.
 */
export const JITTER_WARN_FRACTION = 0.1;

/**
 * Lowest RSSI (SPM4649T, dBm) worth a warning: −85 dBm, about 10 dB above the ≈ −95 dBm a
 * 2.4 GHz DSM receiver still decodes; below it the link has little margin left.
 */
export const RSSI_LOW_DBM = -85;

/**
 * Bad frames (rejected after lock) as a fraction of all frames above which the line is called
 * damaged: 1 %. Any bad frame is mentioned; a clean wire has none.
 */
export const BAD_FRAME_WARN_RATIO = 0.01;

/**
 * Glitch ("spike") detection, per channel, over three consecutive appearances A, B, C of the
 * channel (consecutive in that channel's own sequence of values): B is a spike when
 *
 *   |B − A| ≥ SPIKE_MIN_JUMP_PERCENT  and  |B − C| ≥ SPIKE_MIN_JUMP_PERCENT,
 *   B lies on the same side of A and of C,
 *   |C − A| ≤ SPIKE_RETURN_PERCENT,
 *   and C came at most SPIKE_WINDOW_US after A (SPIKE_WINDOW_FRAMES decoded frames without timing).
 *
 * Values are in % travel (`servoToPercent`: ±100 % is the normal throw, ±150 % the full range).
 *
 * Why this shape and not any large step: a switch or a fast stick legitimately moves a channel
 * by 100 % or more from one frame to the next and stays there, so a step alone proves nothing.
 * A value that leaves by a quarter of the throw and is back within a few % on the very next
 * appearance, all inside 100 ms, is not something a human on a stick or switch produces
 * (a flick out and back takes well over 100 ms); it is what a corrupted word that passed the
 * decoder's checks looks like (a flipped bit in a position moves it by 2^n steps for one frame).
 * A wrong value that lasts two appearances or more is not detected.
 */
export const SPIKE_MIN_JUMP_PERCENT = 25;
/**
 * How close C must come back to A, % travel. 5 % covers what the fastest normal stick motion
 * moves in the window (about 200 %/s × 0.044 s ≈ 9 % over a whole swing, half that typically)
 * and the 9-bit resolution of X-Plus channels (0.6 % a step).
 */
export const SPIKE_RETURN_PERCENT = 5;
/**
 * Longest A→C span that still counts, µs: three appearances of a channel span 22–44 ms on
 * 11 ms systems and up to 88 ms on 22 ms systems that split channels across two frames; 100 ms
 * leaves room for chunk-timing jitter and stays below a deliberate flick out and back.
 */
export const SPIKE_WINDOW_US = 100_000;
/** The same window in decoded frames, for captures without timing. */
export const SPIKE_WINDOW_FRAMES = 9;
/**
 * Recorded in the report's thresholds for readers of older reports: the decoder now judges
 * fade-counter jumps itself (a rise of 8 or more outside a confirmed chain counts nothing).
 */
export const FADE_DELTA_SLACK = 3;
/** At most this many glitches are listed (all are counted). */
export const MAX_LISTED_GLITCHES = 200;
/** At most this many hold episodes are listed (all are counted). */
export const MAX_LISTED_HOLDS = 200;

/**
 * How late a chunk-timed frame is assumed to arrive from USB batching alone until the link
 * monitor has measured the delivery jitter on the capture itself, µs (`timingJitterUs`). Missed
 * frames, holds and the period statistics all come from `LinkMonitor`; this is its prior.
 */
export const CHUNK_TIMING_ALLOWANCE_US = USB_CHUNK_JITTER_US;

/** Every threshold the report used, as the report records them. */
export interface ReportThresholds {
  binUs: number;
  fadeRateHighPerMin: number;
  lostRatioWarn: number;
  lostRatioProblem: number;
  jitterWarnFraction: number;
  rssiLowDbm: number;
  badFrameWarnRatio: number;
  spikeMinJumpPercent: number;
  spikeReturnPercent: number;
  spikeWindowUs: number;
  spikeWindowFrames: number;
  chunkTimingAllowanceUs: number;
  fadeDeltaSlack: number;
}

export const REPORT_THRESHOLDS: Readonly<ReportThresholds> = Object.freeze({
  binUs: REPORT_BIN_US,
  fadeRateHighPerMin: FADE_RATE_HIGH_PER_MIN,
  lostRatioWarn: LOST_RATIO_WARN,
  lostRatioProblem: LOST_RATIO_PROBLEM,
  jitterWarnFraction: JITTER_WARN_FRACTION,
  rssiLowDbm: RSSI_LOW_DBM,
  badFrameWarnRatio: BAD_FRAME_WARN_RATIO,
  spikeMinJumpPercent: SPIKE_MIN_JUMP_PERCENT,
  spikeReturnPercent: SPIKE_RETURN_PERCENT,
  spikeWindowUs: SPIKE_WINDOW_US,
  spikeWindowFrames: SPIKE_WINDOW_FRAMES,
  chunkTimingAllowanceUs: CHUNK_TIMING_ALLOWANCE_US,
  fadeDeltaSlack: FADE_DELTA_SLACK,
});

// ---------------------------------------------------------------------------------------------
// The report
// ---------------------------------------------------------------------------------------------

/** How bad a finding is. */
export type FindingLevel = 'ok' | 'info' | 'warning' | 'problem';

/** What a finding is about (stable, for programs; `text` is for people). */
export type FindingCode =
  | 'no-frames'
  | 'failsafe'
  | 'holds'
  | 'lost-frames'
  | 'fade-rate'
  | 'rssi'
  | 'jitter'
  | 'glitches'
  | 'line-damage'
  | 'resolution'
  | 'format-changes'
  | 'no-timing'
  | 'chunk-timing'
  | 'file-issues';

/** One plain-English finding. */
export interface ReportFinding {
  level: FindingLevel;
  code: FindingCode;
  /** The port it is about, `null` for the whole capture. */
  port: number | null;
  /** A sentence, e.g. "3 failsafe episodes, longest 2.4 s at 1:02.0". */
  text: string;
}

/** Overall judgement: the worst finding ('problem' → poor, 'warning' → fair), or no frames at all. */
export type ReportStatus = 'good' | 'fair' | 'poor' | 'no-data';

/** A hold or failsafe episode. Times are µs relative to the report's time zero. */
export interface ReportEpisode {
  /** When the state began: the last frame + the hold threshold (hold) or + 1 s (failsafe). */
  startUs: number;
  /** The next frame, the failsafe's start for a hold that became one, or the end of the capture. */
  endUs: number;
  durationUs: number;
  /** The last frame before the silence. */
  lastFrameUs: number;
  /** True when the capture ended in this state (no frame came back). */
  ongoing: boolean;
}

/** Statistics of the gap-free inter-frame intervals, µs. */
export interface ReportPeriodStats {
  /** Intervals measured (gaps of a missed frame or more left out). */
  intervals: number;
  meanUs: number;
  /** Standard deviation: the frame-period jitter. */
  stdDevUs: number;
  minUs: number;
  maxUs: number;
  p50Us: number;
  p95Us: number;
  p99Us: number;
  /** 'per-byte': the receiver's own timing; 'per-chunk': includes the USB adapter's batching. */
  basis: 'per-byte' | 'per-chunk';
}

/** A channel the remote sent, with the pulse widths seen. */
export interface ReportChannel {
  id: number;
  name: string;
  /** Frames that carried it. */
  frames: number;
  minUs: number;
  maxUs: number;
  meanUs: number;
}

/** One glitch: a single-appearance spike on one channel (see `SPIKE_MIN_JUMP_PERCENT`). */
export interface ReportGlitch {
  kind: 'spike';
  /** Time of the frame with the spike, µs relative to time zero; `null` without timing. */
  timeUs: number | null;
  /** The decoder's sequence number of that frame. */
  frameIndex: number;
  channel: number;
  name: string;
  /** Pulse widths of the appearances before, at and after the spike, µs. */
  beforeUs: number;
  spikeUs: number;
  afterUs: number;
  /** Size of the excursion, % travel (signed: positive upwards). */
  jumpPercent: number;
}

/**
 * Per-second series for graphs: entry `i` covers [i × binUs, (i + 1) × binUs) after time zero,
 * for `timeline.bins` bins; the same bins for every port.
 */
export interface ReportSeries {
  /** Frames decoded in each bin. */
  frames: number[];
  /** Fades the receiver counted in each bin; `null` for an RSSI receiver (no fade counter). */
  fades: number[] | null;
  /** Frames missing by the clock, placed at the times they were due. */
  lost: number[];
  /** Mean and lowest RSSI of each bin, dBm (loss reports of −128 left out); `null` without RSSI. */
  rssiMean: (number | null)[] | null;
  rssiMin: (number | null)[] | null;
}

/** One remote receiver (one serial port). Times are µs relative to time zero; `null` where unknown. */
export interface RemoteReport {
  port: number;
  /** The port's name from the capture's metadata, else "Port N". */
  label: string;
  status: ReportStatus;
  /** The system byte an internal remote sends (`null` for external remotes), its name and whether it is one of the four valid ones. */
  system: { byte: number | null; name: string | null; valid: boolean };
  remote: RemoteKind | null;
  /** What byte 0 carries: fades or SPM4649T RSSI. */
  headerMode: HeaderReading;
  /** The resolution used, why (the decoder's reason code) and a sentence saying so. */
  resolution: { value: Resolution | null; reason: ResolutionReason; explanation: string };
  firstFrameUs: number | null;
  lastFrameUs: number | null;
  /** First to last frame. */
  durationUs: number | null;
  frames: number;
  /** Frames that were due: `frames + missedFrames`. */
  expectedFrames: number | null;
  /**
   * Frames missed, as the link monitor counts them (`LinkMonitor`): by the receiver's fade
   * counter where it counts, else frames expected against frames received over windows that
   * absorb delivery bursts; frames due in a silence at the end of the capture count too.
   */
  missedFrames: number | null;
  /** What `missedFrames` rests on. */
  missedBasis: MissedBasis;
  /**
   * How late frames reached the recorder against the receiver's own schedule (mean) and the
   * spread of that lateness, µs: the adapter's delivery, not link loss. `null` without timing.
   */
  delivery: { delayUs: number | null; jitterUs: number | null };
  /** missedFrames ÷ expectedFrames. */
  lostRatio: number | null;
  /** 11000 or 22000 µs. */
  nominalPeriodUs: number | null;
  /**
   * The receiver's fade counter: total over the capture and per minute of `durationUs`;
   * `null` for an RSSI receiver. `counterMoved` is false when every frame said 0 (a receiver
   * that does not count, e.g. a clone's 00 00 header, or simply a perfect link).
   * `implausibleJumps` counts the counter jumps the decoder could not attribute to the receiver
   * (`DecoderStats.fadeJumps`): left out of `total`.
   */
  fades: { total: number; perMinute: number | null; counterMoved: boolean; implausibleJumps: number } | null;
  /** SPM4649T RSSI over the frames that carried a level (−128 loss reports counted apart); `null` without RSSI. */
  rssi: { minDbm: number | null; meanDbm: number | null; maxDbm: number | null; frames: number; lossReports: number } | null;
  /**
   * Hold episodes (last values held). Every failsafe starts as a hold, so `count` includes
   * those; `recovered` counts the holds the link came back from before failsafe, and
   * `longestUs`/`longestAtUs` is the longest of those (`null` when there is none: a hold that
   * became a failsafe lasted the hold state's full ~1 s, and is reported as a failsafe). The
   * list holds every hold episode, up to `MAX_LISTED_HOLDS`.
   */
  holds: { count: number; recovered: number; longestUs: number | null; longestAtUs: number | null; episodes: ReportEpisode[] };
  /** Failsafe episodes (over 1 s without a frame), oldest first. */
  failsafes: ReportEpisode[];
  /** Longest silence between two frames, µs. */
  longestGapUs: number | null;
  framePeriod: ReportPeriodStats | null;
  channels: ReportChannel[];
  glitches: { count: number; frames: number; listed: ReportGlitch[] };
  /** The decoder's counters. */
  decoder: {
    bytes: number;
    frames: number;
    discardedBytes: number;
    resyncs: number;
    badFrames: number;
    emptySlots: number;
    vtxFrames: number;
    formatChanges: number;
  };
  series: ReportSeries;
  findings: ReportFinding[];
}

/** The whole report. JSON-serialisable: no NaN, no Infinity, no typed arrays. */
export interface HealthReport {
  format: 'satscope-health-report';
  version: 1;
  source: {
    /** The file name given in the options, else `null`. */
    name: string | null;
    kind: CaptureKind;
    timing: CaptureTiming;
    bytes: number;
    /** Port indices with data, in increasing order. */
    ports: number[];
    /** The capture's descriptive metadata, when present. */
    createdAt: string | null;
    recordedFrom: string | null;
    note: string | null;
    /** Damage the file reader skipped: the count and the first messages. */
    issues: number;
    issueMessages: string[];
  };
  /** The shared time axis: time zero on the capture's clock (µs), the span after it, and the series' bins. */
  timeline: { originUs: number | null; durationUs: number | null; binUs: number; bins: number };
  /** The worst status of any remote. */
  status: ReportStatus;
  /**
   * Every remote's findings, worst first. With several remotes each is prefixed with the
   * port's label, and one that several remotes share word for word is given once, with their
   * labels ("All ports: …") and `port: null`.
   */
  verdict: ReportFinding[];
  remotes: RemoteReport[];
  thresholds: ReportThresholds;
  /**
   * The doctor's findings at the end of the capture, worst first, when the caller added them
   * (`diagnosedHealthReport`; the CLI and the page do): `reportHtml` shows
   * them in a section of their own. The decoder does not compute them: the doctor builds on it.
   */
  diagnosis?: ReportDiagnosis[];
}

/** One finding of the doctor, as the report shows it (a `DoctorFinding` fits). */
export interface ReportDiagnosis {
  severity: 'problem' | 'warning' | 'info';
  confidence: string;
  title: string;
  evidence: readonly { text: string }[];
  todo: readonly string[];
  settings: readonly { stack: string; lines: readonly string[]; note: string }[];
}

export interface HealthReportOptions {
  /** Resolution override for the decoder (default 'auto'). */
  resolution?: 'auto' | Resolution;
  /** The file name to show. */
  name?: string;
}

// ---------------------------------------------------------------------------------------------
// Computation
// ---------------------------------------------------------------------------------------------

const finite = (x: number): number | null => (Number.isFinite(x) ? x : null);
/** µs values in the report: 0.1 µs is far below any timing the capture carries. */
const r1 = (x: number): number => Math.round(x * 10) / 10;
const r1n = (x: number): number | null => (Number.isFinite(x) ? r1(x) : null);
const r3 = (x: number): number => Math.round(x * 1000) / 1000;

/** A growable Float64Array. */
class Column {
  data = new Float64Array(1024);
  length = 0;
  push(v: number): void {
    if (this.length === this.data.length) {
      const next = new Float64Array(this.data.length * 2);
      next.set(this.data);
      this.data = next;
    }
    this.data[this.length++] = v;
  }
  view(): Float64Array {
    return this.data.subarray(0, this.length);
  }
}

/** Nearest-rank percentile of sorted values. */
function percentile(sorted: Float64Array, p: number): number {
  if (sorted.length === 0) return NaN;
  const rank = Math.ceil((p / 100) * sorted.length);
  return sorted[Math.min(sorted.length - 1, Math.max(0, rank - 1))] ?? NaN;
}

/** Statistics of the ordinary frame intervals; sorts `intervals` in place. Null without any. */
function periodStats(intervals: Float64Array, basis: ReportPeriodStats['basis']): ReportPeriodStats | null {
  if (intervals.length === 0) return null;
  const iv = intervals.sort();
  let sum = 0;
  for (const v of iv) sum += v;
  const mean = sum / iv.length;
  let sq = 0;
  for (const v of iv) sq += (v - mean) * (v - mean);
  return {
    intervals: iv.length,
    meanUs: r1(mean),
    stdDevUs: r1(Math.sqrt(sq / iv.length)),
    minUs: r1(iv[0] ?? NaN),
    maxUs: r1(iv[iv.length - 1] ?? NaN),
    p50Us: r1(percentile(iv, 50)),
    p95Us: r1(percentile(iv, 95)),
    p99Us: r1(percentile(iv, 99)),
    basis,
  };
}

type RawGlitch = Omit<ReportGlitch, 'timeUs'> & { absUs: number };

/** What one port's decode leaves for the report: sums, not a record per frame. */
interface PortData {
  port: number;
  remote: ReturnType<typeof decodeCapture>;
  /** Frames seen, and the first and last one's time (µs, capture clock). */
  frames: number;
  firstUs: number;
  lastUs: number;
  /** RSSI over the frames that carried a level, and the loss reports (−128). */
  rssiFrames: number;
  rssiLoss: number;
  rssiLo: number;
  rssiHi: number;
  rssiTotal: number;
  /** The ordinary frame intervals' statistics (the link monitor's `lastIntervalUs`). */
  period: ReportPeriodStats | null;
  channelFrames: Uint32Array;
  channelMin: Float64Array;
  channelMax: Float64Array;
  channelSum: Float64Array;
  glitchesRaw: RawGlitch[];
  glitchCount: number;
  glitchFrames: number;
  formatChanges: number;
  bytes: number;
  /** Whether any frame carried a fade counter other than 0. */
  fadeCounterMoved: boolean;
  /** For `readPorts`: the decoder's reading and counters. */
  format: FormatInfo;
  stats: Readonly<DecoderStats>;
}

/** Where a port's decode starts and ends, and who else listens. */
interface PortPass {
  originUs: number;
  endUs: number;
  doctor: Doctor | undefined;
}

/** Decodes one port, summing what the report needs per frame, and finds spikes as it goes. */
function decodePort(
  capture: Capture,
  port: number,
  resolution: 'auto' | Resolution,
  resolutionFrom: 'user' | 'internal-remote',
  pass: PortPass,
): PortData {
  const intervals = new Column();
  let frames = 0;
  let firstUs = NaN;
  let lastUs = NaN;
  let rssiFrames = 0;
  let rssiLoss = 0;
  let rssiLo = Infinity;
  let rssiHi = -Infinity;
  let rssiTotal = 0;
  const channelFrames = new Uint32Array(CHANNEL_COUNT);
  const channelMin = new Float64Array(CHANNEL_COUNT).fill(Infinity);
  const channelMax = new Float64Array(CHANNEL_COUNT).fill(-Infinity);
  const channelSum = new Float64Array(CHANNEL_COUNT);
  // The last two appearances of each channel: % travel, µs, time, frame index.
  const pct = new Float64Array(CHANNEL_COUNT * 2);
  const us = new Float64Array(CHANNEL_COUNT * 2);
  const at = new Float64Array(CHANNEL_COUNT * 2);
  const idx = new Float64Array(CHANNEL_COUNT * 2);
  const seen = new Uint32Array(CHANNEL_COUNT);
  const glitchesRaw: RawGlitch[] = [];
  let glitchCount = 0;
  let glitchFrames = 0;
  let lastGlitchFrame = -1;
  let formatChanges = 0;
  let fadeCounterMoved = false;
  const remote = decodeCapture(
    capture,
    {
      port,
      resolution,
      resolutionFrom,
      binUs: REPORT_BIN_US,
      originUs: pass.originUs,
      endUs: pass.endUs,
      ...(pass.doctor !== undefined ? { doctor: pass.doctor } : {}),
      onEvent: (e) => {
        if (e.type === 'format-changed') formatChanges++;
      },
    },
    (f, link) => {
      if (frames === 0) firstUs = f.timeUs;
      lastUs = f.timeUs;
      frames++;
      if (Number.isFinite(link.lastIntervalUs)) intervals.push(link.lastIntervalUs);
      const rs = f.rssi;
      if (rs !== null && !Number.isNaN(rs)) {
        if (rs === -128) rssiLoss++;
        else {
          rssiFrames++;
          rssiTotal += rs;
          if (rs < rssiLo) rssiLo = rs;
          if (rs > rssiHi) rssiHi = rs;
        }
      }
      if (f.fades !== null && f.fades !== 0) fadeCounterMoved = true;
      for (let i = 0; i < f.count; i++) {
        const id = f.ids[i] ?? 0;
        const res: Resolution = channelResolution(id, f.resolution);
        const pos = f.positions[i] ?? 0;
        const u = servoToMicros(pos, res);
        const p = servoToPercent(pos, res);
        channelFrames[id] = (channelFrames[id] ?? 0) + 1;
        if (u < (channelMin[id] ?? Infinity)) channelMin[id] = u;
        if (u > (channelMax[id] ?? -Infinity)) channelMax[id] = u;
        channelSum[id] = (channelSum[id] ?? 0) + u;
        const a = 2 * id; // [a] is the older appearance (A), [a + 1] the newer (B); C is this one.
        const n = seen[id] ?? 0;
        if (n >= 2) {
          const pA = pct[a] ?? NaN;
          const pB = pct[a + 1] ?? NaN;
          const atA = at[a] ?? NaN;
          const up = pB - pA;
          const down = pB - p;
          const span =
            Number.isFinite(f.timeUs) && Number.isFinite(atA)
              ? f.timeUs - atA <= SPIKE_WINDOW_US
              : f.index - (idx[a] ?? NaN) <= SPIKE_WINDOW_FRAMES;
          if (
            span &&
            Math.abs(up) >= SPIKE_MIN_JUMP_PERCENT &&
            Math.abs(down) >= SPIKE_MIN_JUMP_PERCENT &&
            Math.sign(up) === Math.sign(down) &&
            Math.abs(p - pA) <= SPIKE_RETURN_PERCENT
          ) {
            glitchCount++;
            const frameIndex = idx[a + 1] ?? NaN;
            if (frameIndex !== lastGlitchFrame) glitchFrames++;
            lastGlitchFrame = frameIndex;
            if (glitchesRaw.length < MAX_LISTED_GLITCHES) {
              glitchesRaw.push({
                kind: 'spike',
                absUs: at[a + 1] ?? NaN,
                frameIndex,
                channel: id,
                name: channelName(id),
                beforeUs: us[a] ?? NaN,
                spikeUs: us[a + 1] ?? NaN,
                afterUs: u,
                jumpPercent: r1(up),
              });
            }
          }
        }
        if (n >= 1) {
          pct[a] = pct[a + 1] ?? NaN;
          us[a] = us[a + 1] ?? NaN;
          at[a] = at[a + 1] ?? NaN;
          idx[a] = idx[a + 1] ?? NaN;
        }
        pct[a + 1] = p;
        us[a + 1] = u;
        at[a + 1] = f.timeUs;
        idx[a + 1] = f.index;
        seen[id] = n + 1;
      }
    },
  );
  const stats = remote.decoder.stats;
  return {
    port,
    remote,
    frames,
    firstUs,
    lastUs,
    rssiFrames,
    rssiLoss,
    rssiLo,
    rssiHi,
    rssiTotal,
    period: periodStats(intervals.view(), capture.timing === 'per-byte' ? 'per-byte' : 'per-chunk'),
    channelFrames,
    channelMin,
    channelMax,
    channelSum,
    glitchesRaw,
    glitchCount,
    glitchFrames,
    formatChanges,
    bytes: stats.bytes,
    fadeCounterMoved,
    format: remote.decoder.format,
    stats,
  };
}

function episodeOf(e: LinkEpisode, origin: number, end: number): ReportEpisode {
  const endAbs = e.endUs ?? end;
  return {
    startUs: r1(e.startUs - origin),
    endUs: r1(endAbs - origin),
    durationUs: r1(Math.max(0, endAbs - e.startUs)),
    lastFrameUs: r1(e.lastFrameUs - origin),
    ongoing: e.endUs === null,
  };
}

/** "1:02.3" (minutes:seconds), "1:02:03" past an hour. */
export function formatClock(us: number): string {
  if (!Number.isFinite(us)) return '?';
  const s = Math.max(0, us / 1e6);
  if (s >= 3600) {
    const h = Math.floor(s / 3600);
    const m = Math.floor((s % 3600) / 60);
    return `${h}:${String(m).padStart(2, '0')}:${String(Math.floor(s % 60)).padStart(2, '0')}`;
  }
  const m = Math.floor(s / 60);
  const rest = s - m * 60;
  let sec = rest.toFixed(1);
  if (sec === '60.0') return `${m + 1}:00.0`;
  if (rest < 10) sec = `0${sec}`;
  return `${m}:${sec}`;
}

/** "2.4 s", "350 ms", "1.20 ms", "6.7 µs". */
export function formatDuration(us: number): string {
  if (!Number.isFinite(us)) return '?';
  if (us < 1000) return `${us < 100 ? (Math.round(us * 10) / 10).toString() : Math.round(us).toString()} µs`;
  if (us >= 1e6) return `${(us / 1e6).toFixed(us >= 100e6 ? 0 : 1)} s`;
  if (us >= 10_000) return `${Math.round(us / 1000)} ms`;
  return `${(us / 1000).toFixed(2)} ms`;
}

export const plural = (n: number, one: string, many = `${one}s`): string => `${n} ${n === 1 ? one : many}`;
export const pctText = (ratio: number): string => `${(ratio * 100).toFixed(ratio < 0.001 && ratio > 0 ? 3 : ratio < 0.1 ? 2 : 1)} %`;
export const rate = (x: number): string => (x === 0 ? '0' : x >= 10 ? x.toFixed(0) : x.toFixed(1));

function remoteFindings(r: RemoteReport, timing: CaptureTiming): ReportFinding[] {
  const out: ReportFinding[] = [];
  const add = (level: FindingLevel, code: FindingCode, text: string): void => {
    out.push({ level, code, port: r.port, text });
  };
  if (r.frames === 0) {
    add(
      'problem',
      'no-frames',
      `No Spektrum frames found in ${plural(r.decoder.bytes, 'byte')} (is this the satellite's DATA line at 115200 baud?)`,
    );
    return out;
  }
  const timed = timing !== 'none';
  if (timed) {
    if (r.failsafes.length > 0) {
      let longest = r.failsafes[0] as ReportEpisode;
      for (const e of r.failsafes) if (e.durationUs > longest.durationUs) longest = e;
      const n = r.failsafes.length;
      const ongoing = r.failsafes.some((e) => e.ongoing) ? '; the capture ends in failsafe' : '';
      const outage = longest.ongoing
        ? ''
        : ` (${formatDuration(longest.endUs - longest.lastFrameUs)} without frames from ${formatClock(longest.lastFrameUs)})`;
      add(
        'problem',
        'failsafe',
        `${plural(n, 'failsafe episode')}, ${n > 1 ? 'longest ' : ''}${formatDuration(longest.durationUs)} at ${formatClock(longest.startUs)}${outage}${ongoing}`,
      );
    } else {
      add('ok', 'failsafe', 'No failsafe');
    }
    const h = r.holds;
    if (h.recovered > 0 && h.longestUs !== null && h.longestAtUs !== null) {
      add(
        'warning',
        'holds',
        `${plural(h.recovered, 'hold')} (last values held, recovered before failsafe), ${h.recovered > 1 ? 'longest ' : ''}${formatDuration(h.longestUs)} at ${formatClock(h.longestAtUs)}`,
      );
    }
    if (r.lostRatio !== null && r.missedFrames !== null && r.expectedFrames !== null) {
      const level: FindingLevel = r.lostRatio >= LOST_RATIO_PROBLEM ? 'problem' : r.lostRatio >= LOST_RATIO_WARN ? 'warning' : 'ok';
      const judged = level === 'problem' ? ' is high' : level === 'warning' ? ' is more than a healthy link loses' : '';
      add(level, 'lost-frames', `${pctText(r.lostRatio)} of frames lost (${r.missedFrames} of ${r.expectedFrames})${judged}`);
    }
    if (r.fades !== null && !r.fades.counterMoved && (r.missedFrames ?? 0) > 0) {
      add(
        'info',
        'fade-rate',
        `The fade counter stayed at 0 although ${plural(r.missedFrames ?? 0, 'frame was', 'frames were')} lost: this receiver does not seem to count fades (a 00 00 header?)`,
      );
    } else if (r.fades !== null && r.fades.perMinute !== null) {
      const high = r.fades.perMinute > FADE_RATE_HIGH_PER_MIN;
      add(
        high ? 'warning' : 'ok',
        'fade-rate',
        `Fade rate ${rate(r.fades.perMinute)}/min${high ? ` is high (over ${FADE_RATE_HIGH_PER_MIN}/min)` : ''} (${plural(r.fades.total, 'fade')})`,
      );
    }
    if (r.framePeriod !== null && r.nominalPeriodUs !== null) {
      const fp = r.framePeriod;
      if (fp.basis === 'per-byte') {
        const high = fp.stdDevUs > JITTER_WARN_FRACTION * r.nominalPeriodUs;
        add(
          high ? 'warning' : 'ok',
          'jitter',
          `Frame period ${formatDuration(fp.meanUs)}, jitter ${formatDuration(fp.stdDevUs)}${high ? ` (over ${JITTER_WARN_FRACTION * 100} % of the period)` : ''}`,
        );
      } else {
        add(
          'info',
          'chunk-timing',
          "Frame times are USB chunk arrival times: the jitter shown is mostly the adapter's batching, and a single missed frame cannot be told from it",
        );
      }
    }
  } else {
    add(
      'info',
      'no-timing',
      `No timing in this file: no rates, holds, failsafes or jitter${r.missedFrames === null ? ', and no lost frames' : ''}`,
    );
    if (r.fades !== null)
      add(
        'info',
        'fade-rate',
        `${plural(r.fades.total, 'fade')} counted by the receiver${r.missedFrames !== null ? ' (its count of frames lost)' : ''}`,
      );
  }
  if (r.rssi !== null) {
    if (r.rssi.minDbm !== null && r.rssi.minDbm < RSSI_LOW_DBM) {
      add('warning', 'rssi', `RSSI down to ${r.rssi.minDbm} dBm (below ${RSSI_LOW_DBM} dBm)`);
    } else if (r.rssi.minDbm !== null) {
      add('ok', 'rssi', `RSSI ${r.rssi.minDbm}…${r.rssi.maxDbm ?? '?'} dBm, mean ${r.rssi.meanDbm ?? '?'} dBm`);
    }
    if (r.rssi.lossReports > 0) add('info', 'rssi', `${plural(r.rssi.lossReports, 'frame')} reported a loss (RSSI −128)`);
  }
  if (r.fades !== null && r.fades.implausibleJumps > 0) {
    add(
      'warning',
      'glitches',
      `${plural(r.fades.implausibleJumps, 'implausible jump')} of the fade counter left out (corrupted frame headers)`,
    );
  }
  if (r.glitches.count > 0) {
    const first = r.glitches.listed[0];
    const where = first ? ` (first on ${first.name}${first.timeUs !== null ? ` at ${formatClock(first.timeUs)}` : ''})` : '';
    add(
      'warning',
      'glitches',
      `${plural(r.glitches.count, 'glitch', 'glitches')}: single-frame spikes of ${SPIKE_MIN_JUMP_PERCENT} % travel or more that return the next time${where}`,
    );
  }
  const d = r.decoder;
  if (d.badFrames > 0 || d.resyncs > 0) {
    const ratio = d.badFrames / Math.max(1, d.frames + d.badFrames);
    add(
      ratio > BAD_FRAME_WARN_RATIO ? 'warning' : 'info',
      'line-damage',
      `Line damage: ${plural(d.badFrames, 'bad frame')}, ${plural(d.resyncs, 'resync')}, ${plural(d.discardedBytes, 'byte')} discarded`,
    );
  }
  if (r.resolution.reason === 'system-byte-contradicted') add('warning', 'resolution', r.resolution.explanation);
  if (d.formatChanges > 0)
    add('info', 'format-changes', `The decoder changed its reading of the format ${plural(d.formatChanges, 'time')}`);
  return out;
}

const LEVEL_ORDER: Record<FindingLevel, number> = { problem: 0, warning: 1, info: 2, ok: 3 };

function statusOf(findings: readonly ReportFinding[], frames: number): ReportStatus {
  if (frames === 0) return 'no-data';
  if (findings.some((f) => f.level === 'problem')) return 'poor';
  if (findings.some((f) => f.level === 'warning')) return 'fair';
  return 'good';
}

/**
 * The health report of every port of a capture (one remote receiver per port). Decodes each
 * port once where it can (`readPorts`); never throws on the capture's content.
 */
export function healthReport(capture: Capture, options: HealthReportOptions = {}): HealthReport {
  return healthReportFeeding(capture, options, undefined);
}

/**
 * `healthReport`, with `doctor` (when given, for a timed capture) fed every port's bytes, events
 * and frames from the same decode: `diagnosedHealthReport` asks it for its findings after.
 */
export function healthReportFeeding(capture: Capture, options: HealthReportOptions, doctor: Doctor | undefined): HealthReport {
  const ports = capturePorts(capture);
  const timed = capture.timing !== 'none';
  // The shared clock: from the earliest to the latest time recorded on any port (each port's
  // series bins from the same origin and its link ends there).
  const span = captureSpan(capture);
  const pass: PortPass = { originUs: span.startUs, endUs: span.endUs, doctor };
  // §8: the internal remote holds the key for every remote; external ports take its resolution.
  const read = readPorts(
    ports,
    options.resolution ?? 'auto',
    (port) => looksInternal(capture, port),
    (port, resolution, from, final) => decodePort(capture, port, resolution, from, final ? pass : { ...pass, doctor: undefined }),
  );
  const decoded = ports.map((p) => read.get(p) as PortData);

  const hasClock = timed && Number.isFinite(span.startUs) && Number.isFinite(span.endUs);
  const origin = hasClock ? span.startUs : NaN;
  const end = hasClock ? span.endUs : NaN;
  const bins = hasClock ? Math.max(1, Math.ceil((end - origin) / REPORT_BIN_US)) : 0;

  const remotes: RemoteReport[] = decoded.map((d) => {
    const { decoder, link, series } = d.remote;
    const stats = decoder.stats;
    const format = decoder.format;
    const ls = link.stats;
    const n = d.frames;
    const first = d.firstUs;
    const last = d.lastUs;
    const period = ls.nominalPeriodUs;
    const havePeriod = hasClock && Number.isFinite(period) && n > 0;
    // The receiver's own count needs no clock: a file without timing still has it.
    const haveMissed = havePeriod || (ls.missedBasis === 'fade-counter' && n > 0);
    const missed = ls.missedFrames;
    const rssiMode = format.headerMode === 'rssi';

    // The link monitor's series, on the report's bins.
    const framesS = new Array<number>(bins).fill(0);
    const lostS = new Array<number>(bins).fill(0);
    const fadesS = rssiMode ? null : new Array<number>(bins).fill(0);
    const rssiMeanS = new Array<number | null>(bins).fill(null);
    const rssiMinS = new Array<number | null>(bins).fill(null);
    for (let b = 0; b < bins; b++) {
      framesS[b] = series.frames(b);
      lostS[b] = series.lost(b);
      if (fadesS) fadesS[b] = series.fades(b);
      const mean = series.rssiMean(b);
      rssiMeanS[b] = Number.isNaN(mean) ? null : Math.round(mean * 10) / 10;
      const low = series.rssiMin(b);
      rssiMinS[b] = Number.isNaN(low) ? null : low;
    }
    const { rssiFrames, rssiLoss, rssiLo, rssiHi, rssiTotal } = d;
    const fadesTotal = ls.fades;
    const fadeJumps = stats.fadeJumps;
    const framePeriod = havePeriod ? d.period : null;

    const episodes = link.episodes;
    const failsafes = hasClock ? episodes.filter((e) => e.kind === 'failsafe').map((e) => episodeOf(e, origin, end)) : [];
    const holdEpisodes = hasClock ? episodes.filter((e) => e.kind === 'hold').map((e) => episodeOf(e, origin, end)) : [];
    // A hold that became a failsafe ends where the failsafe starts, after the same last frame;
    // one still open at the end of the capture did not recover either.
    const recovered = holdEpisodes.filter((h) => !h.ongoing && !failsafes.some((f) => f.lastFrameUs === h.lastFrameUs));
    let longestHold: ReportEpisode | null = null;
    for (const e of recovered) if (longestHold === null || e.durationUs > longestHold.durationUs) longestHold = e;

    const channels: ReportChannel[] = [];
    for (let id = 0; id < CHANNEL_COUNT; id++) {
      const c = d.channelFrames[id] as number;
      if (c > 0) {
        channels.push({
          id,
          name: channelName(id),
          frames: c,
          minUs: d.channelMin[id] as number,
          maxUs: d.channelMax[id] as number,
          meanUs: r1((d.channelSum[id] as number) / c),
        });
      }
    }

    const durationUs = hasClock && n > 0 ? last - first : NaN;
    const sys = format.system === null ? undefined : systemInfo(format.system);
    const duration = Number.isFinite(durationUs) ? durationUs : NaN;
    const label = capture.meta.ports?.[d.port]?.name;
    const report: RemoteReport = {
      port: d.port,
      label: typeof label === 'string' && label !== '' ? label : `Port ${d.port}`,
      status: 'good',
      system: { byte: format.system, name: sys?.name ?? null, valid: sys !== undefined },
      remote: format.remote,
      headerMode: format.headerMode,
      resolution: { value: format.resolution, reason: format.resolutionReason, explanation: format.explanation },
      firstFrameUs: hasClock && n > 0 ? r1(first - origin) : null,
      lastFrameUs: hasClock && n > 0 ? r1(last - origin) : null,
      durationUs: r1n(duration),
      frames: stats.frames,
      expectedFrames: haveMissed ? stats.frames + missed : null,
      missedFrames: haveMissed ? missed : null,
      missedBasis: ls.missedBasis,
      delivery: { delayUs: hasClock ? r1n(ls.deliveryDelayUs) : null, jitterUs: hasClock ? r1n(ls.deliveryJitterUs) : null },
      lostRatio: haveMissed ? Math.round((missed / Math.max(1, stats.frames + missed)) * 1e6) / 1e6 : null,
      nominalPeriodUs: havePeriod ? period : null,
      fades: rssiMode
        ? null
        : {
            total: fadesTotal,
            perMinute: Number.isFinite(duration) && duration > 0 ? r3(fadesTotal / (duration / 60e6)) : null,
            counterMoved: d.fadeCounterMoved,
            implausibleJumps: fadeJumps,
          },
      rssi:
        rssiMode || rssiFrames > 0
          ? {
              minDbm: finite(rssiLo),
              maxDbm: finite(rssiHi),
              meanDbm: rssiFrames > 0 ? Math.round((rssiTotal / rssiFrames) * 10) / 10 : null,
              frames: rssiFrames,
              lossReports: rssiLoss,
            }
          : null,
      holds: {
        count: holdEpisodes.length,
        recovered: recovered.length,
        longestUs: longestHold?.durationUs ?? null,
        longestAtUs: longestHold?.startUs ?? null,
        episodes: holdEpisodes.slice(0, MAX_LISTED_HOLDS),
      },
      failsafes,
      longestGapUs: hasClock && n > 1 ? r1(ls.longestGapUs) : null,
      framePeriod,
      channels,
      glitches: {
        count: d.glitchCount,
        frames: d.glitchFrames,
        listed: d.glitchesRaw.map(({ absUs, ...g }) => ({ ...g, timeUs: hasClock ? r1n(absUs - origin) : null })),
      },
      decoder: {
        bytes: d.bytes,
        frames: stats.frames,
        discardedBytes: stats.discardedBytes,
        resyncs: stats.resyncs,
        badFrames: stats.badFrames,
        emptySlots: stats.emptySlots,
        vtxFrames: stats.vtxFrames,
        formatChanges: d.formatChanges,
      },
      series: {
        frames: framesS,
        fades: fadesS,
        lost: lostS,
        rssiMean: rssiMode ? rssiMeanS : null,
        rssiMin: rssiMode ? rssiMinS : null,
      },
      findings: [],
    };
    report.findings = remoteFindings(report, hasClock ? capture.timing : 'none');
    report.status = statusOf(report.findings, report.frames);
    return report;
  });

  const verdict: ReportFinding[] = [];
  if (capture.issues.length > 0) {
    verdict.push({
      level: 'info',
      code: 'file-issues',
      port: null,
      text: `The file is damaged: ${plural(capture.issues.length, 'part')} skipped (${capture.issues[0]?.message ?? ''})`,
    });
  }
  if (ports.length === 0) {
    verdict.push({ level: 'problem', code: 'no-frames', port: null, text: 'The capture holds no data' });
  }
  if (remotes.length > 1) {
    // A finding several remotes share word for word (e.g. the timing note) is said once, for all of them.
    const done = new Set<string>();
    for (const r of remotes) {
      for (const f of r.findings) {
        const key = `${f.level}|${f.code}|${f.text}`;
        if (done.has(key)) continue;
        done.add(key);
        const same = remotes.filter((x) => x.findings.some((g) => g.level === f.level && g.code === f.code && g.text === f.text));
        const who = same.length === remotes.length ? 'All ports' : same.map((x) => x.label).join(', ');
        verdict.push({ ...f, port: same.length === 1 ? f.port : null, text: `${who}: ${f.text}` });
      }
    }
  } else {
    for (const r of remotes) verdict.push(...r.findings);
  }
  verdict.sort((a, b) => LEVEL_ORDER[a.level] - LEVEL_ORDER[b.level]);
  const order: ReportStatus[] = ['no-data', 'poor', 'fair', 'good'];
  let status: ReportStatus = remotes.length === 0 ? 'no-data' : 'good';
  for (const r of remotes) if (order.indexOf(r.status) < order.indexOf(status)) status = r.status;

  const meta = capture.meta;
  return {
    format: 'satscope-health-report',
    version: 1,
    source: {
      name: options.name ?? null,
      kind: capture.kind,
      timing: capture.timing,
      bytes: capture.bytes.length,
      ports,
      createdAt: typeof meta.createdAt === 'string' ? meta.createdAt : null,
      recordedFrom: typeof meta.source === 'string' ? meta.source : null,
      note: typeof meta.note === 'string' ? meta.note : null,
      issues: capture.issues.length,
      issueMessages: capture.issues.slice(0, 10).map((i) => i.message),
    },
    timeline: { originUs: hasClock ? r1(origin) : null, durationUs: hasClock ? r1(end - origin) : null, binUs: REPORT_BIN_US, bins },
    status,
    verdict,
    remotes,
    thresholds: { ...REPORT_THRESHOLDS },
  };
}
