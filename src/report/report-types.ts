/**
 * The health report's shape: a JSON-serialisable object (no NaN, no Infinity, no typed arrays)
 * that `healthReport` makes, `reportHtml` renders and `satscope report --json` prints. Times are
 * µs relative to the report's time zero (`timeline.originUs`).
 */
import type { CaptureKind, CaptureTiming } from '../capture/model.js';
import type { HeaderReading, RemoteKind, ResolutionReason } from '../decoder/types.js';
import type { MissedBasis } from '../decoder/link-types.js';
import type { Resolution } from '../decoder/spec.js';
import type { ReportThresholds } from './report-thresholds.js';

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
  | 'restarts'
  | 'delivery'
  | 'file-issues'
  | 'adapter-away';

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
   * Frames due that did not reach the recorder (frames expected against frames received, over
   * windows that absorb delivery bursts), whatever the receiver's counter says: where the
   * receiver counts (`missedBasis` 'fade-counter'), `missedFrames` is what the radio lost and
   * the rest of these were lost on the way (line damage, bytes an adapter dropped). `null`
   * without timing.
   */
  undeliveredFrames: number | null;
  /**
   * How late frames reached the recorder against the receiver's own schedule (mean) and the
   * spread of that lateness, µs; silences that were the adapter holding frames back (`stalls`,
   * the longest `longestStallUs`: not holds, not lost). The adapter's delivery, not link loss;
   * `null` without timing.
   */
  delivery: { delayUs: number | null; jitterUs: number | null; stalls: number | null; longestStallUs: number | null };
  /** Receiver restarts: the fade counter started again from 0 after a silence (a power dip); each such silence is a hold. */
  restarts: { count: number; lastAtUs: number | null };
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

/** How `healthReport` reads a capture (the resolution) and names it; every field is optional. */
export interface HealthReportOptions {
  /** Resolution override for the decoder (default 'auto'). */
  resolution?: 'auto' | Resolution;
  /** The file name to show. */
  name?: string;
}
