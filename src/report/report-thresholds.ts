/**
 * Every threshold the health report judges a link by, each with where it comes from, and the
 * record of them a report carries (`REPORT_THRESHOLDS`). The doctor judges by the same ones.
 */
import { USB_CHUNK_JITTER_US } from '../decoder/spec.js';

/** Width of one bin of the per-second series, µs. */
export const REPORT_BIN_US = 1_000_000;

/**
 * Fades per minute above which the fade rate is called high. Spektrum's own rule of thumb
 * for its Flight Log is "about 100 fades per receiver in a 10-minute flight is fine", i.e.
 * 10 a minute; a satellite that fades more often is badly placed, shadowed or far out.
 */
export const FADE_RATE_HIGH_PER_MIN = 10;

/**
 * A capture's fade rate: its fades per minute from its first frame to its last, the one figure
 * the report and the doctor state for a whole capture; null without that span (no timing, one frame).
 */
export function fadesPerMinute(fades: number, firstFrameUs: number, lastFrameUs: number): number | null {
  const span = lastFrameUs - firstFrameUs;
  return Number.isFinite(span) && span > 0 ? fades / (span / 60e6) : null;
}

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
