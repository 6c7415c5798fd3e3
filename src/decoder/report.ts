/**
 * The link-quality health report of a capture: for every serial port (one remote receiver
 * each), how often the link faded, how many frames were lost, how long it held and when it
 * went to failsafe, how regular the frame period was, which channels were seen and whether any
 * of them glitched; as a JSON-serialisable object (`healthReport`) and as one self-contained
 * HTML page with its graphs drawn in inline SVG (`reportHtml`).
 *
 * Pure ECMAScript: no DOM, no Node, no clock. Every time in the report is relative to the
 * report's time zero (`timeline.originUs`, the earliest time recorded in the capture on any
 * port), so that the ports of a multi-port capture share one time axis.
 */
import type { Capture, CaptureKind, CaptureTiming } from '../capture/index.js';
import { captureChunks, capturePorts } from '../capture/index.js';
import type { LinkEpisode, MissedBasis } from './link.js';
import { CHANNEL_COUNT, channelResolution, XPLUS_FIRST, channelName, servoToMicros, servoToPercent, systemInfo, type Resolution, USB_CHUNK_JITTER_US } from './spec.js';
import { captureSpan, decodeCapture, resolutionKey } from './summary.js';
import type { HeaderReading, RemoteKind, ResolutionReason } from './types.js';

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
  | 'no-frames' | 'failsafe' | 'holds' | 'lost-frames' | 'fade-rate' | 'rssi' | 'jitter'
  | 'glitches' | 'line-damage' | 'resolution' | 'format-changes' | 'no-timing' | 'chunk-timing' | 'file-issues';

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
    bytes: number; frames: number; discardedBytes: number; resyncs: number; badFrames: number;
    emptySlots: number; vtxFrames: number; formatChanges: number;
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
   * (`satscope/doctor`'s `diagnosedHealthReport`; the CLI and the page do): `reportHtml` shows
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
  return sorted[Math.min(sorted.length - 1, Math.max(0, rank - 1))] as number;
}

type RawGlitch = Omit<ReportGlitch, 'timeUs'> & { absUs: number };

/** What one port's decode leaves for the report. */
interface PortData {
  port: number;
  /** Per frame: time (µs, capture clock), RSSI (NaN when none). */
  times: Float64Array;
  rssi: Float64Array;
  /** The ordinary frame intervals (the link monitor's `lastIntervalUs`), µs. */
  intervals: Float64Array;
  remote: ReturnType<typeof decodeCapture>;
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
}

/** Decodes one port, keeping what the report needs per frame, and finds spikes as it goes. */
function decodePort(capture: Capture, port: number, resolution: 'auto' | Resolution, resolutionFrom: 'user' | 'internal-remote' = 'user'): PortData {
  const times = new Column();
  const intervals = new Column();
  const rssi = new Column();
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
  const remote = decodeCapture(capture, {
    port,
    resolution,
    resolutionFrom,
    binUs: REPORT_BIN_US,
    onEvent: (e) => {
      if (e.type === 'format-changed') formatChanges++;
    },
  }, (f, link) => {
    times.push(f.timeUs);
    if (Number.isFinite(link.lastIntervalUs)) intervals.push(link.lastIntervalUs);
    rssi.push(f.rssi ?? NaN);
    if (f.fades !== null && f.fades !== 0) fadeCounterMoved = true;
    for (let i = 0; i < f.count; i++) {
      const id = f.ids[i] as number;
      const res: Resolution = channelResolution(id, f.resolution);
      const pos = f.positions[i] as number;
      const u = servoToMicros(pos, res);
      const p = servoToPercent(pos, res);
      channelFrames[id] = (channelFrames[id] as number) + 1;
      if (u < (channelMin[id] as number)) channelMin[id] = u;
      if (u > (channelMax[id] as number)) channelMax[id] = u;
      channelSum[id] = (channelSum[id] as number) + u;
      const a = 2 * id; // [a] is the older appearance (A), [a + 1] the newer (B); C is this one.
      const n = seen[id] as number;
      if (n >= 2) {
        const pA = pct[a] as number;
        const pB = pct[a + 1] as number;
        const up = pB - pA;
        const down = pB - p;
        const span = Number.isFinite(f.timeUs) && Number.isFinite(at[a] as number)
          ? f.timeUs - (at[a] as number) <= SPIKE_WINDOW_US
          : f.index - (idx[a] as number) <= SPIKE_WINDOW_FRAMES;
        if (span && Math.abs(up) >= SPIKE_MIN_JUMP_PERCENT && Math.abs(down) >= SPIKE_MIN_JUMP_PERCENT &&
          Math.sign(up) === Math.sign(down) && Math.abs(p - pA) <= SPIKE_RETURN_PERCENT) {
          glitchCount++;
          const frameIndex = idx[a + 1] as number;
          if (frameIndex !== lastGlitchFrame) glitchFrames++;
          lastGlitchFrame = frameIndex;
          if (glitchesRaw.length < MAX_LISTED_GLITCHES) {
            glitchesRaw.push({
              kind: 'spike', absUs: at[a + 1] as number, frameIndex, channel: id, name: channelName(id),
              beforeUs: us[a] as number, spikeUs: us[a + 1] as number, afterUs: u, jumpPercent: r1(up),
            });
          }
        }
      }
      if (n >= 1) {
        pct[a] = pct[a + 1] as number;
        us[a] = us[a + 1] as number;
        at[a] = at[a + 1] as number;
        idx[a] = idx[a + 1] as number;
      }
      pct[a + 1] = p;
      us[a + 1] = u;
      at[a + 1] = f.timeUs;
      idx[a + 1] = f.index;
      seen[id] = n + 1;
    }
  });
  let bytes = 0;
  for (const chunk of captureChunks(capture, port)) bytes += chunk.bytes.length;
  return {
    port, times: times.view(), rssi: rssi.view(), intervals: intervals.view(), remote,
    channelFrames, channelMin, channelMax, channelSum, glitchesRaw, glitchCount, glitchFrames, formatChanges, bytes, fadeCounterMoved,
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

const plural = (n: number, one: string, many = `${one}s`): string => `${n} ${n === 1 ? one : many}`;
const pctText = (ratio: number): string => `${(ratio * 100).toFixed(ratio < 0.001 && ratio > 0 ? 3 : ratio < 0.1 ? 2 : 1)} %`;
const rate = (x: number): string => (x === 0 ? '0' : x >= 10 ? x.toFixed(0) : x.toFixed(1));

function remoteFindings(r: RemoteReport, timing: CaptureTiming): ReportFinding[] {
  const out: ReportFinding[] = [];
  const add = (level: FindingLevel, code: FindingCode, text: string): void => {
    out.push({ level, code, port: r.port, text });
  };
  if (r.frames === 0) {
    add('problem', 'no-frames', `No Spektrum frames found in ${plural(r.decoder.bytes, 'byte')} (is this the satellite's DATA line at 115200 baud?)`);
    return out;
  }
  const timed = timing !== 'none';
  if (timed) {
    if (r.failsafes.length > 0) {
      let longest = r.failsafes[0] as ReportEpisode;
      for (const e of r.failsafes) if (e.durationUs > longest.durationUs) longest = e;
      const n = r.failsafes.length;
      const ongoing = r.failsafes.some((e) => e.ongoing) ? '; the capture ends in failsafe' : '';
      const outage = longest.ongoing ? '' : ` (${formatDuration(longest.endUs - longest.lastFrameUs)} without frames from ${formatClock(longest.lastFrameUs)})`;
      add('problem', 'failsafe', `${plural(n, 'failsafe episode')}, ${n > 1 ? 'longest ' : ''}${formatDuration(longest.durationUs)} at ${formatClock(longest.startUs)}${outage}${ongoing}`);
    } else {
      add('ok', 'failsafe', 'No failsafe');
    }
    const h = r.holds;
    if (h.recovered > 0 && h.longestUs !== null && h.longestAtUs !== null) {
      add('warning', 'holds', `${plural(h.recovered, 'hold')} (last values held, recovered before failsafe), ${h.recovered > 1 ? 'longest ' : ''}${formatDuration(h.longestUs)} at ${formatClock(h.longestAtUs)}`);
    }
    if (r.lostRatio !== null && r.missedFrames !== null && r.expectedFrames !== null) {
      const level: FindingLevel = r.lostRatio >= LOST_RATIO_PROBLEM ? 'problem' : r.lostRatio >= LOST_RATIO_WARN ? 'warning' : 'ok';
      const judged = level === 'problem' ? ' is high' : level === 'warning' ? ' is more than a healthy link loses' : '';
      add(level, 'lost-frames', `${pctText(r.lostRatio)} of frames lost (${r.missedFrames} of ${r.expectedFrames})${judged}`);
    }
    if (r.fades !== null && !r.fades.counterMoved && (r.missedFrames ?? 0) > 0) {
      add('info', 'fade-rate', `The fade counter stayed at 0 although ${plural(r.missedFrames ?? 0, 'frame was', 'frames were')} lost: this receiver does not seem to count fades (a 00 00 header?)`);
    } else if (r.fades !== null && r.fades.perMinute !== null) {
      const high = r.fades.perMinute > FADE_RATE_HIGH_PER_MIN;
      add(high ? 'warning' : 'ok', 'fade-rate', `Fade rate ${rate(r.fades.perMinute)}/min${high ? ` is high (over ${FADE_RATE_HIGH_PER_MIN}/min)` : ''} (${plural(r.fades.total, 'fade')})`);
    }
    if (r.framePeriod !== null && r.nominalPeriodUs !== null) {
      const fp = r.framePeriod;
      if (fp.basis === 'per-byte') {
        const high = fp.stdDevUs > JITTER_WARN_FRACTION * r.nominalPeriodUs;
        add(high ? 'warning' : 'ok', 'jitter', `Frame period ${formatDuration(fp.meanUs)}, jitter ${formatDuration(fp.stdDevUs)}${high ? ` (over ${JITTER_WARN_FRACTION * 100} % of the period)` : ''}`);
      } else {
        add('info', 'chunk-timing', 'Frame times are USB chunk arrival times: the jitter shown is mostly the adapter\'s batching, and a single missed frame cannot be told from it');
      }
    }
  } else {
    add('info', 'no-timing', `No timing in this file: no rates, holds, failsafes or jitter${r.missedFrames === null ? ', and no lost frames' : ''}`);
    if (r.fades !== null) add('info', 'fade-rate', `${plural(r.fades.total, 'fade')} counted by the receiver${r.missedFrames !== null ? ' (its count of frames lost)' : ''}`);
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
    add('warning', 'glitches', `${plural(r.fades.implausibleJumps, 'implausible jump')} of the fade counter left out (corrupted frame headers)`);
  }
  if (r.glitches.count > 0) {
    const first = r.glitches.listed[0];
    const where = first ? ` (first on ${first.name}${first.timeUs !== null ? ` at ${formatClock(first.timeUs)}` : ''})` : '';
    add('warning', 'glitches', `${plural(r.glitches.count, 'glitch', 'glitches')}: single-frame spikes of ${SPIKE_MIN_JUMP_PERCENT} % travel or more that return the next time${where}`);
  }
  const d = r.decoder;
  if (d.badFrames > 0 || d.resyncs > 0) {
    const ratio = d.badFrames / Math.max(1, d.frames + d.badFrames);
    add(ratio > BAD_FRAME_WARN_RATIO ? 'warning' : 'info', 'line-damage', `Line damage: ${plural(d.badFrames, 'bad frame')}, ${plural(d.resyncs, 'resync')}, ${plural(d.discardedBytes, 'byte')} discarded`);
  }
  if (r.resolution.reason === 'system-byte-contradicted') add('warning', 'resolution', r.resolution.explanation);
  if (d.formatChanges > 0) add('info', 'format-changes', `The decoder changed its reading of the format ${plural(d.formatChanges, 'time')}`);
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
 * port with `decodeCapture`; never throws on the capture's content.
 */
export function healthReport(capture: Capture, options: HealthReportOptions = {}): HealthReport {
  const ports = capturePorts(capture);
  const timed = capture.timing !== 'none';
  let decoded = ports.map((p) => decodePort(capture, p, options.resolution ?? 'auto'));
  // §8: the internal remote holds the key for every remote; external ports take its resolution.
  if ((options.resolution ?? 'auto') === 'auto' && ports.length > 1) {
    const key = resolutionKey(decoded.map((d) => d.remote.decoder.format));
    if (key !== undefined) {
      decoded = decoded.map((d, i) => {
        if (d.remote.decoder.format.remote === 'internal') return d;
        // Kept only if it reads at least as many frames: a port of another system (or a
        // capture put together from unrelated receivers) keeps its own reading.
        const keyed = decodePort(capture, ports[i] as number, key, 'internal-remote');
        return keyed.remote.decoder.stats.frames >= d.remote.decoder.stats.frames ? keyed : d;
      });
    }
  }

  // The shared clock: from the earliest to the latest time recorded on any port (decodeCapture
  // bins from the same origin and ends each link there).
  const span = captureSpan(capture);
  const hasClock = timed && Number.isFinite(span.startUs) && Number.isFinite(span.endUs);
  const origin = hasClock ? span.startUs : NaN;
  const end = hasClock ? span.endUs : NaN;
  const bins = hasClock ? Math.max(1, Math.ceil((end - origin) / REPORT_BIN_US)) : 0;

  const remotes: RemoteReport[] = decoded.map((d) => {
    const { decoder, link, series } = d.remote;
    const stats = decoder.stats;
    const format = decoder.format;
    const ls = link.stats;
    const n = d.times.length;
    const first = n > 0 ? (d.times[0] as number) : NaN;
    const last = n > 0 ? (d.times[n - 1] as number) : NaN;
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
    let rssiFrames = 0;
    let rssiLoss = 0;
    let rssiLo = Infinity;
    let rssiHi = -Infinity;
    let rssiTotal = 0;
    for (let i = 0; i < n; i++) {
      const rs = d.rssi[i] as number;
      if (Number.isNaN(rs)) continue;
      if (rs === -128) rssiLoss++;
      else {
        rssiFrames++;
        rssiTotal += rs;
        if (rs < rssiLo) rssiLo = rs;
        if (rs > rssiHi) rssiHi = rs;
      }
    }
    const fadesTotal = ls.fades;
    const fadeJumps = stats.fadeJumps;
    const intervals = d.intervals;

    let framePeriod: ReportPeriodStats | null = null;
    if (havePeriod && intervals.length > 0) {
      const iv = intervals.slice().sort();
      let sum = 0;
      for (const v of iv) sum += v;
      const mean = sum / iv.length;
      let sq = 0;
      for (const v of iv) sq += (v - mean) * (v - mean);
      framePeriod = {
        intervals: iv.length,
        meanUs: r1(mean),
        stdDevUs: r1(Math.sqrt(sq / iv.length)),
        minUs: r1(iv[0] as number),
        maxUs: r1(iv[iv.length - 1] as number),
        p50Us: r1(percentile(iv, 50)),
        p95Us: r1(percentile(iv, 95)),
        p99Us: r1(percentile(iv, 99)),
        basis: capture.timing === 'per-byte' ? 'per-byte' : 'per-chunk',
      };
    }

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
          id, name: channelName(id), frames: c, minUs: d.channelMin[id] as number, maxUs: d.channelMax[id] as number,
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
      fades: rssiMode ? null : {
        total: fadesTotal,
        perMinute: Number.isFinite(duration) && duration > 0 ? r3(fadesTotal / (duration / 60e6)) : null,
        counterMoved: d.fadeCounterMoved,
        implausibleJumps: fadeJumps,
      },
      rssi: rssiMode || rssiFrames > 0 ? {
        minDbm: finite(rssiLo), maxDbm: finite(rssiHi), meanDbm: rssiFrames > 0 ? Math.round((rssiTotal / rssiFrames) * 10) / 10 : null,
        frames: rssiFrames, lossReports: rssiLoss,
      } : null,
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
        bytes: d.bytes, frames: stats.frames, discardedBytes: stats.discardedBytes, resyncs: stats.resyncs,
        badFrames: stats.badFrames, emptySlots: stats.emptySlots, vtxFrames: stats.vtxFrames, formatChanges: d.formatChanges,
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
    verdict.push({ level: 'info', code: 'file-issues', port: null, text: `The file is damaged: ${plural(capture.issues.length, 'part')} skipped (${capture.issues[0]?.message ?? ''})` });
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

// ---------------------------------------------------------------------------------------------
// HTML
// ---------------------------------------------------------------------------------------------

/** Escapes text for HTML content and attribute values. */
export function escapeHtml(text: string): string {
  return text.replace(/[&<>"']/g, (c) => (c === '&' ? '&amp;' : c === '<' ? '&lt;' : c === '>' ? '&gt;' : c === '"' ? '&quot;' : '&#39;'));
}

const COLORS = {
  fades: '#2f6fb7',
  lost: '#d9822b',
  rssi: '#2e8b57',
  rssiMin: '#9ccfb1',
  hold: 'rgba(230, 170, 30, 0.45)',
  failsafe: 'rgba(214, 40, 40, 0.28)',
  failsafeEdge: '#d62828',
  grid: '#e3e3e3',
  axis: '#777',
  text: '#333',
};

/** Up to this many columns per graph: longer series are pooled (the maximum of each group). */
const MAX_PLOT_COLUMNS = 600;

/** A round number ≥ x: 1, 2, 5 × 10^n. */
function niceCeil(x: number): number {
  if (!(x > 0)) return 1;
  const e = 10 ** Math.floor(Math.log10(x));
  for (const m of [1, 2, 5, 10]) if (m * e >= x) return m * e;
  return 10 * e;
}

const f1 = (x: number): string => (Math.round(x * 10) / 10).toString();

interface Panel {
  title: string;
  kind: 'bars' | 'rssi';
  color: string;
  values: (number | null)[];
  low?: (number | null)[];
  remote: RemoteReport;
}

/** Pools a series to at most MAX_PLOT_COLUMNS columns with `pick` (max for counts, min/mean for RSSI). */
function pool(values: readonly (number | null)[], group: number, pick: (a: number, b: number) => number): (number | null)[] {
  if (group <= 1) return values.slice();
  const out: (number | null)[] = [];
  for (let i = 0; i < values.length; i += group) {
    let v: number | null = null;
    for (let j = i; j < Math.min(values.length, i + group); j++) {
      const x = values[j];
      if (x === null || x === undefined) continue;
      v = v === null ? x : pick(v, x);
    }
    out.push(v);
  }
  return out;
}

function timeTicks(durationUs: number): number[] {
  const s = durationUs / 1e6;
  const steps = [0.5, 1, 2, 5, 10, 15, 30, 60, 120, 300, 600, 900, 1800, 3600, 7200, 14_400, 28_800];
  let step = steps[steps.length - 1] as number;
  for (const c of steps) {
    if (s / c <= 10) {
      step = c;
      break;
    }
  }
  const ticks: number[] = [];
  for (let t = 0; t <= s + 1e-9; t += step) ticks.push(t * 1e6);
  return ticks;
}

function tickLabel(us: number, durationUs: number): string {
  const s = us / 1e6;
  if (durationUs < 60e6) return `${f1(s)} s`;
  return formatClock(us).replace(/\.\d$/, '');
}

/** The graphs: one panel per series per remote, stacked over one shared time axis. */
function graphsSvg(report: HealthReport): string {
  const { bins, binUs } = report.timeline;
  const duration = report.timeline.durationUs ?? 0;
  if (bins === 0 || duration <= 0) return '';
  const panels: Panel[] = [];
  for (const r of report.remotes) {
    if (r.frames === 0) continue;
    const prefix = report.remotes.length > 1 ? `${r.label}: ` : '';
    panels.push({ title: `${prefix}lost frames /s`, kind: 'bars', color: COLORS.lost, values: r.series.lost, remote: r });
    if (r.series.fades) panels.push({ title: `${prefix}fades /s`, kind: 'bars', color: COLORS.fades, values: r.series.fades, remote: r });
    if (r.series.rssiMean) panels.push({ title: `${prefix}RSSI dBm (mean, lowest)`, kind: 'rssi', color: COLORS.rssi, values: r.series.rssiMean, low: r.series.rssiMin ?? undefined, remote: r });
  }
  if (panels.length === 0) return '';
  const W = 720;
  const left = 44;
  const right = 12;
  const legendH = 18;
  const panelH = panels.length <= 2 ? 62 : panels.length <= 4 ? 46 : 40;
  const gapH = 8;
  const axisH = 22;
  const plotW = W - left - right;
  const H = legendH + panels.length * (panelH + gapH) + axisH;
  const x = (us: number): number => left + (Math.min(Math.max(us, 0), duration) / duration) * plotW;
  const group = Math.max(1, Math.ceil(bins / MAX_PLOT_COLUMNS));
  const colUs = binUs * group;
  const ticks = timeTicks(duration);
  const parts: string[] = [];
  parts.push(`<svg viewBox="0 0 ${W} ${H}" width="100%" role="img" aria-label="Link quality over time" font-family="Helvetica, Arial, sans-serif" font-size="10">`);
  // Legend.
  const legend: [string, string][] = [['Lost frames', COLORS.lost]];
  if (panels.some((p) => p.color === COLORS.fades)) legend.push(['Fades', COLORS.fades]);
  if (panels.some((p) => p.kind === 'rssi')) legend.push(['RSSI mean', COLORS.rssi], ['RSSI lowest', COLORS.rssiMin]);
  legend.push(['Hold', COLORS.hold], ['Failsafe', COLORS.failsafe]);
  let lx = left;
  for (const [name, color] of legend) {
    parts.push(`<rect x="${lx}" y="4" width="10" height="10" fill="${color}"/><text x="${lx + 14}" y="13" fill="${COLORS.text}">${escapeHtml(name)}</text>`);
    lx += 24 + name.length * 5.6;
  }
  if (group > 1) parts.push(`<text x="${W - right}" y="13" text-anchor="end" fill="${COLORS.axis}">each column: the highest of ${group} s</text>`);
  panels.forEach((p, k) => {
    const top = legendH + k * (panelH + gapH);
    const bottom = top + panelH;
    parts.push(`<g>`);
    parts.push(`<rect x="${left}" y="${top}" width="${plotW}" height="${panelH}" fill="#fafafa" stroke="${COLORS.grid}"/>`);
    for (const t of ticks) parts.push(`<line x1="${f1(x(t))}" y1="${top}" x2="${f1(x(t))}" y2="${bottom}" stroke="${COLORS.grid}"/>`);
    // Hold and failsafe bands (at least 1.5 px wide so that a short hold shows).
    for (const e of p.remote.holds.episodes) {
      const x0 = x(e.startUs);
      parts.push(`<rect x="${f1(x0)}" y="${top}" width="${f1(Math.max(1.5, x(e.endUs) - x0))}" height="${panelH}" fill="${COLORS.hold}"/>`);
    }
    for (const e of p.remote.failsafes) {
      const x0 = x(e.startUs);
      const x1 = x(e.endUs);
      parts.push(`<rect x="${f1(x0)}" y="${top}" width="${f1(Math.max(1.5, x1 - x0))}" height="${panelH}" fill="${COLORS.failsafe}"/>`);
      parts.push(`<line x1="${f1(x0)}" y1="${top}" x2="${f1(x0)}" y2="${bottom}" stroke="${COLORS.failsafeEdge}" stroke-width="1"/>`);
    }
    const pad = 12; // room for the title
    const h = panelH - pad - 2;
    if (p.kind === 'bars') {
      const vals = pool(p.values, group, Math.max);
      let max = 0;
      for (const v of vals) if (v !== null && v > max) max = v;
      const top2 = niceCeil(Math.max(max, 1));
      let d = '';
      const colW = (colUs / duration) * plotW;
      vals.forEach((v, i) => {
        if (v === null || v <= 0) return;
        const bh = (v / top2) * h;
        const bx = x(i * colUs);
        d += `M${f1(bx)} ${f1(bottom - bh)}h${f1(Math.max(0.8, Math.min(colW, x(duration) - bx) * (group > 1 ? 1 : 0.85)))}V${bottom}H${f1(bx)}Z`;
      });
      if (d !== '') parts.push(`<path d="${d}" fill="${p.color}"/>`);
      parts.push(`<text x="${left - 4}" y="${top + pad + 4}" text-anchor="end" fill="${COLORS.axis}">${top2}</text>`);
      parts.push(`<text x="${left - 4}" y="${bottom}" text-anchor="end" fill="${COLORS.axis}">0</text>`);
    } else {
      const mean = pool(p.values, group, Math.min);
      const low = p.low ? pool(p.low, group, Math.min) : [];
      let lo = Infinity;
      let hi = -Infinity;
      for (const v of [...mean, ...low]) {
        if (v === null) continue;
        if (v < lo) lo = v;
        if (v > hi) hi = v;
      }
      if (!Number.isFinite(lo)) {
        lo = -100;
        hi = -40;
      }
      lo = Math.floor(lo / 10) * 10;
      hi = Math.max(lo + 10, Math.ceil(hi / 10) * 10);
      const y = (v: number): number => bottom - ((v - lo) / (hi - lo)) * h;
      const line = (vals: (number | null)[]): string => {
        let d = '';
        let pen = false;
        vals.forEach((v, i) => {
          if (v === null) {
            pen = false;
            return;
          }
          const px = x((i + 0.5) * colUs);
          d += `${pen ? 'L' : 'M'}${f1(px)} ${f1(y(v))}`;
          pen = true;
        });
        return d;
      };
      const dl = line(low);
      if (dl !== '') parts.push(`<path d="${dl}" fill="none" stroke="${COLORS.rssiMin}" stroke-width="1.2"/>`);
      const dm = line(mean);
      if (dm !== '') parts.push(`<path d="${dm}" fill="none" stroke="${p.color}" stroke-width="1.6"/>`);
      if (RSSI_LOW_DBM > lo && RSSI_LOW_DBM < hi) {
        parts.push(`<line x1="${left}" y1="${f1(y(RSSI_LOW_DBM))}" x2="${left + plotW}" y2="${f1(y(RSSI_LOW_DBM))}" stroke="${COLORS.failsafeEdge}" stroke-dasharray="3 3" stroke-width="0.8"/>`);
      }
      parts.push(`<text x="${left - 4}" y="${top + pad + 4}" text-anchor="end" fill="${COLORS.axis}">${hi}</text>`);
      parts.push(`<text x="${left - 4}" y="${bottom}" text-anchor="end" fill="${COLORS.axis}">${lo}</text>`);
    }
    parts.push(`<rect x="${left + 1}" y="${top + 1}" width="${f1(8 + p.title.length * 5.4)}" height="12" fill="#fff" fill-opacity="0.8"/>`);
    parts.push(`<text x="${left + 4}" y="${top + 10}" fill="${COLORS.text}" font-weight="bold">${escapeHtml(p.title)}</text>`);
    parts.push(`</g>`);
  });
  // The shared time axis.
  const axisY = legendH + panels.length * (panelH + gapH) - gapH;
  parts.push(`<line x1="${left}" y1="${axisY}" x2="${left + plotW}" y2="${axisY}" stroke="${COLORS.axis}"/>`);
  for (const t of ticks) {
    const tx = f1(x(t));
    parts.push(`<line x1="${tx}" y1="${axisY}" x2="${tx}" y2="${axisY + 4}" stroke="${COLORS.axis}"/>`);
    parts.push(`<text x="${tx}" y="${axisY + 14}" text-anchor="middle" fill="${COLORS.axis}">${escapeHtml(tickLabel(t, duration))}</text>`);
  }
  parts.push('</svg>');
  return parts.join('');
}

const STATUS_TEXT: Record<ReportStatus, string> = { good: 'Good', fair: 'Fair', poor: 'Poor', 'no-data': 'No data' };
const LEVEL_MARK: Record<FindingLevel, string> = { problem: '✖', warning: '▲', info: 'ℹ', ok: '✔' };

const hex2 = (v: number): string => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;

/** Short forms of the decoder's resolution reasons (the reason code itself for any other). */
const REASON_SHORT: Partial<Record<ResolutionReason, string>> = {
  override: 'set by the user', 'system-byte': 'system byte', 'channel-ids': 'from the channel IDs',
  'internal-remote': 'from the internal remote',
  'system-byte-contradicted': 'system byte contradicted', unknown: 'undecided',
};

/** The metrics of one remote as label/value rows; `compact` for the side-by-side table of several remotes. */
function metricRows(r: RemoteReport, timed: boolean, compact: boolean): [string, string][] {
  const rows: [string, string][] = [];
  const sys = r.system.byte === null ? (compact ? 'none' : 'none (external remote or no system byte)') : `${hex2(r.system.byte)} ${r.system.name ?? '(not a valid system byte)'}`;
  rows.push(['System', sys]);
  rows.push(['Remote', r.remote === null ? '?' : `${r.remote}${r.headerMode === 'rssi' ? (compact ? ', RSSI' : ', RSSI in byte 0 (SPM4649T)') : ''}`]);
  rows.push(['Resolution', `${r.resolution.value ?? '?'} (${REASON_SHORT[r.resolution.reason] ?? r.resolution.reason})`]);
  rows.push(['Duration', r.durationUs === null ? '–' : `${formatDuration(r.durationUs)} (${formatClock(r.firstFrameUs ?? 0)}–${formatClock(r.lastFrameUs ?? 0)})`]);
  rows.push(['Frames', r.expectedFrames !== null ? `${r.frames} of ${r.expectedFrames}${compact ? '' : ' expected'}` : String(r.frames)]);
  if (timed) rows.push(['Lost frames', r.lostRatio === null ? '–' : `${r.missedFrames} (${pctText(r.lostRatio)})`]);
  rows.push(['Fades', r.fades === null ? '–' : `${r.fades.total}${r.fades.perMinute !== null ? ` (${rate(r.fades.perMinute)}/min)` : ''}${r.fades.implausibleJumps ? `; ${plural(r.fades.implausibleJumps, 'counter jump')} ignored` : ''}`]);
  if (r.rssi || !compact) {
    if (r.rssi) rows.push(['RSSI', r.rssi.minDbm === null ? 'no level reported' : `${r.rssi.minDbm} / ${r.rssi.meanDbm} / ${r.rssi.maxDbm} dBm${compact ? '' : ' (min / mean / max)'}${r.rssi.lossReports ? `, ${r.rssi.lossReports} loss reports` : ''}`]);
  } else {
    rows.push(['RSSI', '–']);
  }
  if (timed) {
    const hd = r.holds;
    const became = hd.count - hd.recovered - hd.episodes.filter((h) => h.ongoing).length;
    rows.push(['Holds', `${hd.count}${became > 0 ? ` (${became} became ${became === 1 ? 'a failsafe' : 'failsafes'})` : ''}${hd.longestUs !== null ? `; longest recovered ${formatDuration(hd.longestUs)} at ${formatClock(hd.longestAtUs ?? 0)}` : ''}`]);
    rows.push(['Failsafes', r.failsafes.length === 0 ? '0' : `${r.failsafes.length}, ${formatDuration(r.failsafes.reduce((a, x) => a + x.durationUs, 0))} in all`]);
    rows.push(['Longest gap', r.longestGapUs === null ? '–' : formatDuration(r.longestGapUs)]);
    const fp = r.framePeriod;
    const chunk = fp?.basis === 'per-chunk' ? ' (USB chunk times)' : '';
    const pcts = fp === null ? '–' : `p50 ${(fp.p50Us / 1000).toFixed(2)} · p95 ${(fp.p95Us / 1000).toFixed(2)} · p99 ${(fp.p99Us / 1000).toFixed(2)} ms`;
    if (compact) {
      rows.push(['Frame period', fp === null ? '–' : `${(fp.meanUs / 1000).toFixed(3)} ms, jitter ${formatDuration(fp.stdDevUs)}; ${pcts}${chunk}`]);
    } else {
      rows.push(['Frame period', fp === null ? '–' : `${(fp.meanUs / 1000).toFixed(3)} ms mean, jitter ${formatDuration(fp.stdDevUs)}${chunk}`]);
      rows.push(['Intervals', fp === null ? '–' : `${pcts} (${fp.intervals}, gaps excluded)`]);
    }
  }
  const d = r.decoder;
  rows.push(['Decoder', `${d.bytes} bytes, ${d.discardedBytes} discarded, ${d.resyncs} resyncs, ${d.badFrames} bad frames${d.formatChanges ? `, ${d.formatChanges} format changes` : ''}`]);
  rows.push(['Glitches', r.glitches.count === 0 ? 'none' : `${r.glitches.count} spikes in ${r.glitches.frames} frames`]);
  if (compact) rows.push(['Channels', channelList(r)]);
  return rows;
}

/** "0–11, X+1–X+4 (16)": the channel IDs seen, as runs. */
function channelList(r: RemoteReport): string {
  if (r.channels.length === 0) return 'none';
  const runs: string[] = [];
  const ids = r.channels.map((c) => c.id);
  for (let i = 0; i < ids.length;) {
    let j = i;
    while (j + 1 < ids.length && ids[j + 1] === (ids[j] as number) + 1 && ((ids[j + 1] as number) < XPLUS_FIRST) === ((ids[i] as number) < XPLUS_FIRST)) j++;
    const a = ids[i] as number;
    const b = ids[j] as number;
    const name = (id: number): string => (id >= XPLUS_FIRST ? channelName(id) : String(id));
    runs.push(a === b ? name(a) : `${name(a)}–${name(b)}`);
    i = j + 1;
  }
  return `${runs.join(', ')} (${ids.length})`;
}

/** Rows listed per table in the page; the JSON has them all. */
const LIST_ROWS = 5;

function moreNote(shown: number, total: number): string {
  return total > shown ? `<p class="muted">and ${total - shown} more (see the JSON report)</p>` : '';
}

/** Failsafe episodes of every remote (a Port column when there are several). */
function failsafeTable(report: HealthReport): string {
  const e = escapeHtml;
  const many = report.remotes.length > 1;
  const all = report.remotes.flatMap((r) => r.failsafes.map((x) => ({ r, x }))).sort((a, b) => a.x.startUs - b.x.startUs);
  if (all.length === 0) return '';
  const rows = all.slice(0, LIST_ROWS).map(({ r, x }, i) => `<tr>${many ? `<td>${e(r.label)}</td>` : `<td class="n">${i + 1}</td>`}<td class="n">${formatClock(x.lastFrameUs)}</td><td class="n">${formatClock(x.startUs)}</td><td class="n">${x.ongoing ? 'end of capture' : formatClock(x.endUs)}</td><td class="n">${e(formatDuration(x.durationUs))}</td></tr>`).join('');
  return `<div><h3>Failsafe episodes</h3><table class="grid"><thead><tr>${many ? '<th>Port</th>' : '<th class="n">#</th>'}<th class="n">Last frame</th><th class="n">Failsafe from</th><th class="n">Until</th><th class="n">Duration</th></tr></thead><tbody>${rows}</tbody></table>${moreNote(Math.min(LIST_ROWS, all.length), all.length)}</div>`;
}

/** Glitches of every remote. */
function glitchTable(report: HealthReport): string {
  const e = escapeHtml;
  const many = report.remotes.length > 1;
  const all = report.remotes.flatMap((r) => r.glitches.listed.map((g) => ({ r, g })));
  const total = report.remotes.reduce((n, r) => n + r.glitches.count, 0);
  if (total === 0) return '';
  const rows = all.slice(0, LIST_ROWS).map(({ r, g }) => `<tr>${many ? `<td>${e(r.label)}</td>` : ''}<td class="n">${g.timeUs === null ? `frame ${g.frameIndex}` : formatClock(g.timeUs)}</td><td>${e(g.name)}</td><td class="n">${g.beforeUs}</td><td class="n">${g.spikeUs}</td><td class="n">${g.afterUs}</td></tr>`).join('');
  return `<div><h3>Glitches</h3><table class="grid"><thead><tr>${many ? '<th>Port</th>' : ''}<th class="n">Time</th><th>Channel</th><th class="n">Before</th><th class="n">Spike</th><th class="n">After µs</th></tr></thead><tbody>${rows}</tbody></table>${moreNote(Math.min(LIST_ROWS, all.length), total)}</div>`;
}

/** The channels one remote sent, with frames and pulse widths. */
function channelTable(r: RemoteReport): string {
  const e = escapeHtml;
  if (r.channels.length === 0) return '<p class="muted">No channels.</p>';
  return `<table class="grid"><thead><tr><th>Ch</th><th>Name</th><th class="n">Frames</th><th class="n">Min µs</th><th class="n">Mean</th><th class="n">Max</th></tr></thead><tbody>${r.channels.map((c) => `<tr><td class="n">${c.id}</td><td>${e(c.name)}</td><td class="n">${c.frames}</td><td class="n">${c.minUs}</td><td class="n">${Math.round(c.meanUs)}</td><td class="n">${c.maxUs}</td></tr>`).join('')}</tbody></table>`;
}

/** Everything below the graphs: one remote's metrics beside its channels, or several remotes side by side (channel ranges are in the JSON). */
function detailsHtml(report: HealthReport): string {
  const e = escapeHtml;
  const timed = report.timeline.bins > 0;
  const remotes = report.remotes;
  if (remotes.length === 0) return '';
  const extra = [failsafeTable(report), glitchTable(report)].filter((x) => x !== '');
  const extraHtml = extra.length === 0 ? '' : `<div class="cols">${extra.join('')}</div>`;
  if (remotes.length === 1) {
    const r = remotes[0] as RemoteReport;
    const kv = metricRows(r, timed, false).map(([k, v]) => `<tr><th>${e(k)}</th><td>${e(v)}</td></tr>`).join('');
    const title = `${r.label}${r.system.name ? ` · ${r.system.name}` : ''}${r.remote ? ` · ${r.remote} remote` : ''}`;
    return `<section class="remote"><h2><span class="badge ${r.status}">${e(STATUS_TEXT[r.status])}</span> ${e(title)}</h2><p class="why">${e(r.resolution.explanation)}</p><div class="cols"><table class="kv">${kv}</table>${channelTable(r)}</div>${extraHtml}</section>`;
  }
  const columns = remotes.map((r) => metricRows(r, timed, true));
  const labels = (columns[0] ?? []).map(([k]) => k);
  const head = remotes.map((r) => `<th>${e(r.label)} <span class="badge ${r.status}">${e(STATUS_TEXT[r.status])}</span></th>`).join('');
  const body = labels.map((k, i) => `<tr><th>${e(k)}</th>${columns.map((c) => `<td>${e(c[i]?.[1] ?? '')}</td>`).join('')}</tr>`).join('');
  const why = remotes.map((r) => `<li>${e(r.label)}: ${e(r.resolution.explanation)}</li>`).join('');
  return `<section class="remote"><h2>Remotes</h2><table class="grid compare"><thead><tr><th></th>${head}</tr></thead><tbody>${body}</tbody></table>` +
    `<ul class="why">${why}</ul>${extraHtml}</section>`;
}

const CSS = `
@page { size: auto; margin: 8mm; }
* { box-sizing: border-box; }
html { background: #eee; }
body { margin: 0; font: 8.5pt/1.3 Helvetica, Arial, sans-serif; color: #222; -webkit-print-color-adjust: exact; print-color-adjust: exact; }
main { background: #fff; max-width: 190mm; margin: 8mm auto; padding: 8mm; }
header { display: flex; align-items: flex-start; justify-content: space-between; gap: 4mm; border-bottom: 2px solid #222; padding-bottom: 2mm; margin-bottom: 3mm; }
h1 { font-size: 15pt; margin: 0 0 1mm; }
h2 { font-size: 10.5pt; margin: 2.5mm 0 1mm; }
h3 { font-size: 9.5pt; margin: 2mm 0 1mm; }
.file { margin: 0; color: #555; overflow-wrap: anywhere; }
.status { font-size: 13pt; font-weight: bold; padding: 1.5mm 4mm; border-radius: 2mm; white-space: nowrap; }
.good { background: #dff3e4; color: #17602c; }
.fair { background: #fff1cc; color: #7a5300; }
.poor { background: #fbdcdc; color: #8f1414; }
.no-data { background: #e6e6e6; color: #444; }
.badge { font-size: 8pt; padding: 0.3mm 1.5mm; border-radius: 1mm; vertical-align: 1px; }
ul.verdict { list-style: none; margin: 0; padding: 0; columns: 1; }
ul.verdict li { padding: 0.25mm 0 0.25mm 5mm; text-indent: -5mm; }
ul.verdict .mark, ul.diagnosis .mark { display: inline-block; width: 5mm; text-indent: 0; font-weight: bold; }
li.problem .mark { color: #c01818; } li.warning .mark { color: #c07a00; } li.info .mark { color: #2f6fb7; } li.ok .mark { color: #2e8b57; }
li.problem { font-weight: bold; }
ul.diagnosis { list-style: none; margin: 0; padding: 0; }
ul.diagnosis > li { padding: 0.4mm 0 0.4mm 5mm; text-indent: -5mm; break-inside: avoid; }
ul.diagnosis p { text-indent: 0; margin: 0.2mm 0 0; color: #444; font-weight: normal; }
ul.diagnosis code { font-size: 7.5pt; background: #f1f1f1; padding: 0 1mm; border-radius: 0.6mm; }
.graphs { margin: 3mm 0 1mm; }
.graphs svg { display: block; }
.cols { display: grid; grid-template-columns: 1fr 1fr; gap: 4mm; align-items: start; }
table { border-collapse: collapse; width: 100%; }
table.kv th { text-align: left; font-weight: normal; color: #666; padding: 0.15mm 2mm 0.15mm 0; vertical-align: top; white-space: nowrap; }
table.kv td { padding: 0.15mm 0; }
table.grid { font-size: 7.5pt; line-height: 1.25; }
.why { margin: 0 0 1.5mm; padding: 0; list-style: none; color: #555; font-size: 7.5pt; }
table.grid th { text-align: left; border-bottom: 1px solid #999; padding: 0.3mm 1mm; font-weight: bold; }
table.grid td { border-bottom: 1px solid #eee; padding: 0.1mm 1mm; }
table.grid .n { text-align: right; font-variant-numeric: tabular-nums; }
table.compare th, table.compare td { vertical-align: top; }
table.compare tbody th { font-weight: normal; color: #666; white-space: nowrap; border-bottom: 1px solid #eee; }
.muted { color: #777; margin: 1mm 0; }
footer { margin-top: 3mm; border-top: 1px solid #ccc; padding-top: 1.5mm; color: #777; font-size: 7.5pt; }
section.remote { break-inside: avoid; }
@media print { html { background: #fff; } main { margin: 0; padding: 0; max-width: none; } }
`;

/** The doctor's findings: title, first evidence, what to do first, and the lines to paste. */
function diagnosisHtml(report: HealthReport): string {
  const d = report.diagnosis;
  if (d === undefined || d.length === 0) return '';
  const e = escapeHtml;
  const items = d.map((f) => {
    const evidence = f.evidence[0] !== undefined ? `<p>${e(f.evidence[0].text)}</p>` : '';
    const todo = f.todo[0] !== undefined ? `<p>→ ${e(f.todo[0])}</p>` : '';
    const lines = f.settings.filter((s) => s.lines.length > 0).map((s) => `${e(s.stack)}: <code>${s.lines.map(e).join('</code> <code>')}</code>`);
    return `<li class="${f.severity}"><span class="mark">${LEVEL_MARK[f.severity]}</span>${e(f.title)} <span class="muted">(${e(f.confidence)})</span>${evidence}${todo}${lines.length > 0 ? `<p>${lines.join(' · ')}</p>` : ''}</li>`;
  });
  return `<h2>Diagnosis</h2>\n<ul class="diagnosis">${items.join('')}</ul>`;
}

/**
 * The report as one self-contained HTML document: inline CSS and SVG, no scripts, no external
 * resources, laid out to print on one A4 or Letter page for a capture of one or two remotes.
 */
export function reportHtml(report: HealthReport): string {
  const e = escapeHtml;
  const s = report.source;
  const name = s.name ?? 'capture';
  const facts: string[] = [s.kind, `timing ${s.timing}`, `${s.bytes} bytes`, plural(s.ports.length, 'port')];
  if (report.timeline.durationUs !== null) facts.push(formatDuration(report.timeline.durationUs));
  if (s.createdAt) facts.push(`recorded ${s.createdAt}`);
  if (s.recordedFrom && s.recordedFrom !== s.kind) facts.push(`from ${s.recordedFrom}`);
  const verdict = report.verdict.length === 0 ? '<p class="muted">Nothing to report.</p>'
    : `<ul class="verdict">${report.verdict.map((f) => `<li class="${f.level}"><span class="mark">${LEVEL_MARK[f.level]}</span>${e(f.text)}</li>`).join('')}</ul>`;
  const svg = graphsSvg(report);
  const graphs = svg !== '' ? `<section class="graphs">${svg}</section>`
    : report.timeline.bins === 0 && report.remotes.some((r) => r.frames > 0) ? '<p class="muted">No timing in this file: no graphs over time.</p>' : '';
  const t = report.thresholds;
  const footer = `Thresholds: fade rate high above ${t.fadeRateHighPerMin}/min; lost frames warning from ${t.lostRatioWarn * 100} %, problem from ${t.lostRatioProblem * 100} %; ` +
    `jitter warning above ${t.jitterWarnFraction * 100} % of the period (per-byte timing only); RSSI low below ${t.rssiLowDbm} dBm; ` +
    `glitch = a channel value ${t.spikeMinJumpPercent} % travel or more away from both neighbouring appearances, which come back within ${t.spikeReturnPercent} % of each other inside ${t.spikeWindowUs / 1000} ms. ` +
    `Times are m:ss.s from the start of the capture. Made by SatScope (satscope report).`;
  return `<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>Link health: ${e(name)}</title>
<style>${CSS}</style>
</head>
<body>
<main>
<header><div><h1>Link health report</h1><p class="file"><strong>${e(name)}</strong> · ${e(facts.join(' · '))}</p>${s.note ? `<p class="file">${e(s.note)}</p>` : ''}</div><div class="status ${report.status}">${e(STATUS_TEXT[report.status])}</div></header>
<h2>Findings</h2>
${verdict}
${diagnosisHtml(report)}
${graphs}
${detailsHtml(report)}
<footer>${e(footer)}</footer>
</main>
</body>
</html>
`;
}
