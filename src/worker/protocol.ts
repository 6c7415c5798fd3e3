/**
 * Every message between the page and the worker, both directions, as two discriminated unions.
 * The worker owns the serial port, the decoder, the recorder and replay; the page owns the user
 * gesture (requestPort) and the display. High-rate data crosses as typed arrays in batches, a
 * few per animation frame at most, transferred, never one message per Spektrum frame.
 */
import type { FormatInfo } from '../decoder/types.js';
import type { LinkState, MissedBasis } from '../decoder/link-types.js';
import type { InspectEntry } from './inspector.js';
import type { ConfirmProbe, DoctorFinding } from '../report/doctor-types.js';
import type { DriveRequest, DriveStatus } from './drive.js';
import type { FcStatus } from './fc.js';

/** How the page names a port it was granted: its place in getPorts() and its USB IDs. */
export interface PortIdentity {
  index: number;
  usbVendorId?: number;
  usbProductId?: number;
}

export type SourceKind = 'serial' | 'demo' | 'replay';

/** Remote labels as Spektrum names them (spec §7.3): A is the internal one; B, R, L external. */
export const REMOTE_LABELS = ['A', 'B', 'R', 'L'] as const;

export type ToWorker =
  /** Opens a granted port as one more source (several remotes side by side). */
  | { type: 'serial-open'; port: PortIdentity }
  | { type: 'serial-close'; source: number }
  | { type: 'close-all' }
  | { type: 'demo-start' }
  | { type: 'demo-stop' }
  | { type: 'set-label'; source: number; label: string }
  /** Bind a satellite on this port (spec §7.2), then read it live. */
  | { type: 'bind'; port: PortIdentity; pulses: number; powerLine: 'rts' | 'dtr'; polarity: 'asserted' | 'deasserted' }
  | { type: 'record-start' }
  | { type: 'record-stop' }
  | { type: 'export'; what: 'sscap' | 'raw'; recording: 'last' | 'recovered' }
  /** The frame inspector's view of a remote: its newest `limit` frames, discards and resyncs. */
  | { type: 'inspect'; source: number; limit: number }
  /** A health report of the capture being replayed, or of the live session's recording. */
  | { type: 'report'; format: 'html' | 'json' }
  | { type: 'discard-recovered' }
  /** The worker reads the file itself (and a helper reads half the ports of a long capture from it too). */
  | { type: 'replay-open'; name: string; file: Blob }
  | { type: 'replay-play' }
  | { type: 'replay-pause' }
  /** Playback speed; 0 = as fast as possible. */
  | { type: 'replay-speed'; speed: number }
  | { type: 'replay-seek'; timeUs: number }
  | { type: 'set-resolution'; resolution: 'auto' | 1024 | 2048 }
  /** Listen briefly at a finding's other line setting to confirm it, then return to 115200. */
  | { type: 'diagnosis-confirm'; source: number; probe: ConfirmProbe }
  /** Write a satellite's stream to the port's TX (a flight controller's satellite pad), and read the port as a source. */
  | ({ type: 'drive-start' } & DriveRequest)
  /** Stop writing at once (not queued behind other commands): the flight controller sees the link lost. */
  | { type: 'drive-stop' }
  /** Hold a channel at `percent` travel while driving (null: back to the scenario); not queued. */
  | { type: 'drive-channel'; id: number; percent: number | null }
  /** Read a flight controller's own view over MSP on its USB port (while driving it). */
  | { type: 'fc-open'; port: PortIdentity }
  | { type: 'fc-close' }
  // Exports of what the page shows.
  /**
   * One remote's decoded frames (of the capture being replayed, or of the live session's
   * recording) as `satscope decode` writes them; `fromUs`/`toUs` on the capture's clock, null
   * for its start or end.
   */
  | { type: 'export-frames'; source: number; format: 'csv' | 'jsonl'; fromUs: number | null; toUs: number | null };

/** Low-rate state of one source (one remote), sent when it changes. */
export interface SourceStatus {
  /** The source's id: also its port number in recordings and multi-port captures. */
  id: number;
  /** A, B, R, L… */
  label: string;
  kind: SourceKind;
  /** 'opening', 'reading', 'lost' (device gone), 'playing', 'paused', 'ended'. */
  state: string;
  /** What it is, e.g. "USB 0403:6001 at 115200 baud". */
  name: string;
  /** How the source clock advances against wall time: 1 live, the speed in replay, 0 paused. */
  clockRate: number;
  format: FormatInfo;
}

/**
 * Buckets of the graph series: the worker sums frames into 100 ms buckets, so a 10-minute
 * window is 6000 points whatever the frame rate.
 */
export const BUCKET_US = 100_000;

/** What changed since the last batch. All times are µs in the source's clock. */
export interface Batch {
  /** The source clock when the batch was made. */
  nowUs: number;
  /** performance.timeOrigin + performance.now() when the newest bytes in this batch arrived (ms), for latency measurement. */
  arrivedMs: number;
  /** Frames decoded since the last batch. */
  frames: number;
  /** Latest position of each channel 0–19 (X-Plus on the 2047 scale). */
  positions: Uint16Array;
  /** Time each channel was last seen, NaN if never, +Infinity when seen in data without times. */
  seenUs: Float64Array;
  resolution: 1024 | 2048 | null;
  link: {
    state: LinkState;
    lastFrameUs: number;
    holds: number;
    failsafes: number;
    periodUs: number;
    nominalPeriodUs: number;
    fades: number;
    fadeRate: number;
    /** Frames missed (LinkMonitor): by the fade counter where the receiver counts, else by count. */
    missedFrames: number;
    missedBasis: MissedBasis;
    rssi: number;
    /** How late frames reach us against the receiver's schedule, and the spread of it, µs (NaN until measured): the adapter, not the link. */
    deliveryDelayUs: number;
    deliveryJitterUs: number;
  };
  /**
   * While a forced resolution matches no frame: the resolution the stream looks like (the link
   * counts nothing meanwhile); else null.
   */
  mismatch: 1024 | 2048 | null;
  /** The source has ended (a replay at its end): the state shown is the last one, frozen. */
  ended: boolean;
  counters: {
    bytes: number;
    frames: number;
    resyncs: number;
    discardedBytes: number;
    badFrames: number;
    emptySlots: number;
    vtxFrames: number;
  };
  /**
   * Graph buckets not sent before: start time, fades/s, mean RSSI (NaN without), mean frame
   * interval ms (NaN if <2 frames), lost frames. The first `settled` are final; the rest are the
   * buckets still open up to `nowUs`, as counted so far, which the next batch's replace.
   */
  series: { settled: number; t: Float64Array; fadeRate: Float32Array; rssi: Float32Array; periodMs: Float32Array; lost: Float32Array };
  /** Hold and failsafe episodes that started, ended or were re-dated since the last batch. */
  episodes: { id: number; kind: 'hold' | 'failsafe'; startUs: number; endUs: number | null }[];
  /** Ids of holds withdrawn: a silence the frames after it showed was the adapter holding bytes back. */
  retracted: number[];
  /** Every timed frame's channel values since the last batch, and the glitches found (the channel traces). */
  traces: TraceBatch;
  // What `satscope info` prints per channel, over the frames this decode saw.
  /**
   * Each channel's frames, lowest, highest and last pulse width (µs), by channel id, as
   * `ChannelRanges` counts them; `sinceUs`: NaN when they cover the stream from its start, else
   * the time they start from (a replay's seek restores the decode there).
   */
  channels: { frames: Uint32Array; minUs: Float64Array; maxUs: Float64Array; lastUs: Float64Array; sinceUs: number };
}

export interface RecordingStatus {
  active: boolean;
  bytes: number;
  records: number;
  durationUs: number;
  /** A recording from an earlier session that was never finished (page closed, crash, unplug). */
  recovered: { name: string; bytes: number; createdAt: string } | null;
  /** Storage problems (quota, no OPFS): the user is told. */
  error: string | null;
}

export interface ReplayStatus {
  name: string;
  kind: string;
  timing: string;
  startUs: number;
  endUs: number;
  positionUs: number;
  playing: boolean;
  speed: number;
  frames: number;
  issues: string[];
  /** False for a capture without timing (raw .bin): it plays at the receiver's pace, and nothing is measured from that clock. */
  recordedTiming: boolean;
  /** The replay reached the end: the clock stops there and every state is frozen as it was. */
  ended: boolean;
  /**
   * The file is still being read (a long capture, its span known from its start and end): nothing
   * is played, no link state or finding exists yet, and commands wait until it is read.
   */
  reading: boolean;
}

/**
 * Whole-capture series for the replay timeline, made when a capture opens: sent as it grows
 * (each message the whole of it so far) while the capture is decoded, then once complete.
 */
export interface Overview {
  /** Each bin's start, µs (the capture's clock; without timing, where in the file). */
  t: Float64Array;
  /** The bins' width, µs: narrower for a short capture (overviewBinUs), so what is drawn keeps its proportions. */
  binUs: number;
  fadeRate: Float32Array;
  lost: Float32Array;
  failsafe: { startUs: number; endUs: number }[];
  /** Every port is decoded up to here (µs, the capture's clock; NaN without timing): what lies after is not read yet. */
  readUntilUs: number;
  /** The whole capture is read. */
  complete: boolean;
}

/** One step of a bind as it happened. */
export interface BindProgress {
  step: 'open' | 'power-off' | 'power-on' | 'write' | 'reopen' | 'live' | 'failed';
  text: string;
  /** ms since the bind started. */
  atMs: number;
  /** ms since the satellite was powered on, null before. */
  sincePowerOnMs: number | null;
}

export type FromWorker =
  /** Every source, whenever any of them changes (a handful at most). */
  | { type: 'sources'; sources: SourceStatus[] }
  /**
   * What changed in each source that changed since the last flush, in one message: one task on
   * the page, every source as it was at the same moment.
   */
  | { type: 'batches'; batches: { source: number; batch: Batch }[] }
  /** A source's decode started over (or all of them when `source` is undefined). */
  | { type: 'reset'; source?: number }
  | { type: 'notice'; level: 'info' | 'warning' | 'error'; title: string; detail: string }
  | { type: 'recording'; recording: RecordingStatus }
  | { type: 'export-ready'; name: string; mime: string; data: ArrayBuffer }
  | { type: 'replay'; replay: ReplayStatus | null }
  | { type: 'overview'; overview: Overview }
  | { type: 'bind'; progress: BindProgress }
  | { type: 'inspection'; source: number; entries: InspectEntry[] }
  | { type: 'diagnosis'; diagnosis: DiagnosisStatus }
  | { type: 'drive'; drive: DriveStatus }
  | { type: 'fc'; fc: FcStatus };

/** The doctor's findings (src/report), sent when they change, at most 4× a second. */
export interface DiagnosisStatus {
  /** 'live': about the session now; 'replay': at the replay position, on the capture's clock. */
  mode: 'live' | 'replay';
  /** Worst first. */
  findings: DoctorFinding[];
  /** Sources whose port can be reopened at another speed to confirm a finding (live serial ports). */
  probeable: number[];
  /** A listen at another speed under way. */
  probing: { source: number; baudRate: number } | null;
}

// The channel traces (src/worker/traces.ts, src/app/traces.ts).

/**
 * Timed frames decoded since the last batch, as columns: `t` each frame's time (µs), `us` its
 * channel values in µs, CHANNEL_COUNT a frame (NaN: a channel the frame did not carry), `gap` 1
 * where a silence the link monitor would call a hold came before the frame (or frames were
 * dropped before it), and the glitches found (the library's spike rule): each spike's time, its
 * channel and its wrong value in µs.
 */
export interface TraceBatch {
  t: Float64Array;
  us: Float32Array;
  gap: Uint8Array;
  spikes: { t: Float64Array; channel: Uint8Array; us: Float32Array };
}
