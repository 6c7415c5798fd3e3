/**
 * What a link monitor is given and what it tells: its options, its state, its figures and the
 * restarts it saw (link.ts has the monitor and its rules).
 */
/** The link as the receiver's failsafe rule (§7.1) sees it: no frame yet, frames arriving, a silence (hold), or failsafe after 1 s of it. */
export type LinkState = 'waiting' | 'live' | 'hold' | 'failsafe';

/** A receiver that started again: its fade counter fell from `from` to `to` after a silence of `gapUs`, at `timeUs` (the first frame after). */
export interface LinkRestart {
  timeUs: number;
  from: number;
  to: number;
  gapUs: number;
}

/** Where the missed-frame count comes from. */
export type MissedBasis =
  /** The receiver's fade counter (it has been seen counting). */
  | 'fade-counter'
  /** Frames received against frames expected, over windows that absorb delivery bursts. */
  | 'frame-count'
  /** Neither yet: no timing, or no period known. */
  | 'none';

/** How a `LinkMonitor` judges silences (hold and failsafe thresholds, delivery jitter) and what it keeps; every field is optional. */
export interface LinkOptions {
  /** Gap after the last frame before the link counts as "hold", µs. Default: see `holdThresholdUs`. */
  holdAfterUs?: number;
  /** Gap before failsafe, µs. Default 1 s (§7.1). */
  failsafeAfterUs?: number;
  /**
   * Episodes kept in `episodes` (the oldest go first); the counts in `stats` keep counting.
   * Default: all of them. A live view that runs for days sets a bound.
   */
  maxEpisodes?: number;
  /**
   * The delivery jitter to assume until it has been measured on the stream, µs
   * (`USB_CHUNK_JITTER_US` for chunk-timed data, 0 for a logic analyser). Default 0.
   */
  jitterUs?: number;
  /**
   * Called when frames are found missing: `count` frames that were due from `fromUs` on,
   * one period apart, none after `toUs`. For binned series (`LinkSeries`).
   */
  onMissed?: (fromUs: number, toUs: number, count: number, periodUs: number) => void;
}

/** What a `LinkMonitor` has measured so far (`stats`). */
export interface LinkStats {
  frames: number;
  /** Sum of the receiver's fade deltas (frames it reported missing). */
  fades: number;
  /** Frames missed: by the fade counter where the receiver counts, else by frames expected against received. */
  missedFrames: number;
  missedBasis: MissedBasis;
  /**
   * Frames expected but not received, counted over windows that absorb delivery bursts,
   * whatever the receiver's counter says: the one measure every receiver shares (an SPM4649T
   * has no fade counter), and what the flight controller did not get. `missedFrames` equals it
   * where the receiver gives no counter.
   */
  lostFrames: number;
  /** Hold episodes (each failsafe began as a hold). */
  holds: number;
  failsafes: number;
  /** Receiver restarts (`LinkRestart`): each ended a silence its counter does not account for. */
  restarts: number;
  /**
   * Silences that were the adapter holding frames back (a delivery stall: the receiver sent
   * them, as its counter or the burst after showed), not counted as holds, and the longest, µs.
   */
  stalls: number;
  longestStallUs: number;
  /** Measured frame period over the last 32 frames without a gap, µs; NaN until known. */
  periodUs: number;
  /** 11000 or 22000: the system byte's period, else the measured one snapped (`nominalPeriodOf`). */
  nominalPeriodUs: number;
  /** Fades per second over the last ~512 frames. */
  fadeRate: number;
  /** Longest gap between two frames, µs. */
  longestGapUs: number;
  /** Last RSSI (dBm) and lowest seen, NaN without RSSI. */
  rssi: number;
  minRssi: number;
  /**
   * How late frames reach us on average against the receiver's own schedule (the most punctual
   * frame of the last window), µs: the adapter's and the host's delay. NaN until measured.
   */
  deliveryDelayUs: number;
  /** The spread of that lateness over the last few windows, µs: what a gap must exceed to mean anything. NaN until measured. */
  deliveryJitterUs: number;
}
