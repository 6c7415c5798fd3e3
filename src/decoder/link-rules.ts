/**
 * The link's timing rules as plain functions: which period a stream runs at, which interval is an
 * ordinary one, and how long a silence must last to be a hold. The link monitor judges with
 * these; nothing else restates them.
 */
import { FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US } from './spec.js';

/** §7.1 has no hold threshold: a gap shorter than this (and 2.5 periods) is never a hold. */
export const HOLD_MIN_US = 40_000;
/** Mean intervals below this are an 11 ms system, above a 22 ms one. */
export const PERIOD_SNAP_US = 16_500;
/** 11 or 22 ms: the system period a mean frame interval belongs to. */
export function nominalPeriodOf(meanIntervalUs: number): number {
  return meanIntervalUs < PERIOD_SNAP_US ? FRAME_PERIOD_11MS_US : FRAME_PERIOD_22MS_US;
}

/**
 * Whether an interval between two frames is an ordinary one (no frame missing in it as far as
 * timing can tell): at most 1.5 periods plus the delivery jitter. Period statistics use only these.
 */
export function isFrameInterval(intervalUs: number, nominalPeriodUs: number, jitterUs: number): boolean {
  return intervalUs <= 1.5 * nominalPeriodUs + jitterUs;
}

/** The gap after which the link is in hold: `HOLD_MIN_US` or 2.5 periods, whichever is longer, plus the delivery jitter. */
export function holdThresholdUs(nominalPeriodUs: number, jitterUs: number): number {
  const base = Number.isFinite(nominalPeriodUs) ? Math.max(HOLD_MIN_US, 2.5 * nominalPeriodUs) : HOLD_MIN_US;
  return base + (Number.isFinite(jitterUs) ? jitterUs : 0);
}
