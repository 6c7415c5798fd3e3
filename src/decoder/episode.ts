/**
 * An episode of the link: a stretch without frames (a hold, or the failsafe it became), and the
 * one rule for reading one that is still on at a given time.
 */

/** A stretch without frames. `endUs` is null while it lasts. */
export interface LinkEpisode {
  /** 0, 1, 2, … in the order the episodes began (stays with an episode when older ones are dropped). */
  id: number;
  kind: 'hold' | 'failsafe';
  /** When the hold (the last frame + one period: the next frame was due) or the failsafe (last frame + 1 s) began, µs. */
  startUs: number;
  endUs: number | null;
  /** Time of the last frame before the gap, µs. */
  lastFrameUs: number;
}

/**
 * When an episode ends as read at `atUs` (the end of a capture, or as far as a replay has read):
 * its end, or `atUs` while it is still on; never before it began. Every surface that shows an
 * episode (the report, the replay overview) cuts it here.
 */
export function episodeEndAt(e: Pick<LinkEpisode, 'startUs' | 'endUs'>, atUs: number): number {
  return Math.max(e.startUs, Math.min(e.endUs ?? atUs, atUs));
}

/**
 * Whether a hold (or any silence, given by the frame before it) became a failsafe: one of
 * `failsafes` follows the same last frame, as the monitor opens one when a hold passes
 * FAILSAFE_TIMEOUT_US. Every surface that tells holds from failsafes asks this.
 */
export function becameFailsafe(lastFrameUs: number, failsafes: readonly { readonly lastFrameUs: number }[]): boolean {
  return failsafes.some((f) => f.lastFrameUs === lastFrameUs);
}
