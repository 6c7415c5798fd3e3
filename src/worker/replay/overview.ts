/**
 * The replay timeline's overview of a whole capture: every port on one time axis in 1 s bins,
 * the library's binned link series (the report's) with fades and lost frames summed over the
 * ports, and the failsafe episodes; also the frame period to pace a capture without timing at.
 * Each port's bytes are decoded once, when the capture opens.
 */
import { FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US, FRAME_SIZE, systemInfo } from '../../decoder/spec.js';
import type { FormatInfo } from '../../decoder/types.js';
import { episodeEndAt, type LinkEpisode } from '../../decoder/episode.js';
import type { Capture } from '../../capture/model.js';
import type { LinkSeries } from '../../report/series.js';
import { captureSpan } from '../../report/capture-span.js';
import { decodeCapture } from '../../report/capture-pass.js';
import type { Overview } from '../protocol.js';

/** The overview's widest bins: one second (a long capture's). */
export const BIN_US = 1_000_000;
/**
 * The bin widths an overview takes, µs: round ones, from 20 ms (a frame or two of an 11 ms
 * system is due in each, so a run of lost frames is a run of bars, not a comb) to BIN_US.
 */
const BIN_WIDTHS_US = [20_000, 50_000, 100_000, 200_000, 500_000, BIN_US];
/** Bins at most across a capture: two a pixel of a timeline about a thousand pixels wide. */
const MOST_BINS = 2000;

/** Wider bins, for a capture longer than MOST_SECOND_BINS seconds. */
const LONG_WIDTHS_US = [2_000_000, 5_000_000, 10_000_000, 30_000_000, 60_000_000];
/**
 * One-second bins at most, about three days of them: a longer capture's bins are wider, so that
 * its overview, and the series the worker keeps to make it, stay a few megabytes however long it
 * is (a week's 1 s bins held 67 MB a port in the worker).
 */
const MOST_SECOND_BINS = 1 << 18;

/**
 * The bins of a capture `spanUs` long: the narrowest round width that keeps it to MOST_BINS, so
 * that a short capture's timeline draws a hold or a lost frame as long as it was (a 0.74 s
 * capture in 20 ms bins, not in one bin of a second that the whole timeline would stand for);
 * BIN_US for a long capture, and for one whose span is unknown; wider for one over three days.
 */
export function overviewBinUs(spanUs: number): number {
  const short = BIN_WIDTHS_US.find((w) => spanUs / w <= MOST_BINS);
  if (short !== undefined || !(spanUs / BIN_US > MOST_SECOND_BINS)) return short ?? BIN_US;
  return LONG_WIDTHS_US.find((w) => spanUs / w <= MOST_SECOND_BINS) ?? (LONG_WIDTHS_US.at(-1) as number);
}

/** The frame period a decoder's format implies (its system byte, or 1024 resolution: 22 ms), NaN when it implies none. */
function periodOf(format: FormatInfo): number {
  const info = format.system === null ? undefined : systemInfo(format.system);
  if (info !== undefined) return info.periodUs;
  return format.resolution === 1024 ? FRAME_PERIOD_22MS_US : Number.NaN;
}

/**
 * Decodes each of `ports` of `capture` once. Without recorded timing, the fades and the
 * receiver's missed frames go on the paced clock replay plays at (a frame every period from the
 * first byte): where in the file, not when.
 */
export function overviewOf(
  capture: Capture,
  ports: readonly number[],
  resolution: 'auto' | 1024 | 2048,
): { overview: Overview; periodUs: number } {
  const untimed = capture.timing === 'none';
  const all: LinkSeries[] = [];
  const failsafe: Overview['failsafe'] = [];
  let periodUs = Number.NaN;
  // Untimed: each frame's stream offset, fades and missed frames, as columns.
  const marks: { offset: number[]; fades: number[]; missed: number[] } = { offset: [], fades: [], missed: [] };
  // One walk of the chunks for where the capture starts and ends, not one per port.
  const { startUs: originUs, endUs } = captureSpan(capture);
  const binUs = overviewBinUs(endUs - originUs);
  for (const port of ports) {
    let missed = 0;
    const { link, series, decoder } = decodeCapture(capture, { resolution, port, binUs, originUs, endUs }, (f, l) => {
      // Read only where it is used: reading the stats works out what the monitor owes (link.ts).
      if (untimed) {
        const now = l.stats.missedFrames;
        marks.offset.push(f.offset);
        marks.fades.push(l.lastFades);
        marks.missed.push(now - missed);
        missed = now;
      }
    });
    all.push(series);
    failsafe.push(...failsafeAsRead(failsafesOf(link.episodes), endUs, true));
    if (Number.isNaN(periodUs)) periodUs = periodOf(decoder.format);
  }
  if (Number.isNaN(periodUs)) periodUs = FRAME_PERIOD_11MS_US;
  if (untimed) {
    const usPerByte = periodUs / FRAME_SIZE;
    // The paced clock's span: where the last frame ends (a loop: a long file has millions of frames).
    let lastOffset = 0;
    for (const offset of marks.offset) if (offset > lastOffset) lastOffset = offset;
    const binUs = overviewBinUs((lastOffset + FRAME_SIZE) * usPerByte);
    const binOf = (offset: number): number => Math.floor(((offset + FRAME_SIZE) * usPerByte) / binUs);
    let bins = 0;
    for (const offset of marks.offset) bins = Math.max(bins, binOf(offset) + 1);
    const t = Float64Array.from({ length: bins }, (_, b) => b * binUs);
    const fades = new Float32Array(bins);
    const lost = new Float32Array(bins);
    marks.offset.forEach((offset, k) => {
      const b = binOf(offset);
      fades[b] = (fades[b] ?? 0) + (marks.fades[k] ?? 0);
      lost[b] = (lost[b] ?? 0) + (marks.missed[k] ?? 0);
    });
    return { overview: { t, binUs, fadeRate: fades, lost, failsafe: [], readUntilUs: Number.NaN, complete: true }, periodUs };
  }
  return { overview: sumOverview(all, failsafe, undefined, endUs, true), periodUs };
}

/**
 * The ports' series summed bin by bin (fades and lost frames), `bins` of them (default: as many
 * as the longest series has), read up to `readUntilUs`.
 */
export function sumOverview(
  all: readonly LinkSeries[],
  failsafe: Overview['failsafe'],
  bins: number | undefined,
  readUntilUs: number,
  complete: boolean,
): Overview {
  const n = bins ?? Math.max(0, ...all.map((x) => x.bins));
  const origin = all[0]?.originUs ?? Number.NaN;
  const binUs = all[0]?.binUs ?? BIN_US;
  const t = new Float64Array(Number.isNaN(origin) ? 0 : n);
  const fades = new Float32Array(t.length);
  const lost = new Float32Array(t.length);
  for (let b = 0; b < t.length; b++) t[b] = origin + b * binUs;
  // Port by port, each over every bin (the long loop inside: optimised code entered in the middle
  // of a short inner loop left it at every bin). The sums are whole counts, exact in the 32-bit
  // floats they are added up in.
  for (const x of all) {
    for (let b = 0; b < t.length; b++) {
      fades[b] = (fades[b] ?? 0) + x.fades(b);
      lost[b] = (lost[b] ?? 0) + x.lost(b);
    }
  }
  return { t, binUs, fadeRate: fades, lost, failsafe: inTimeOrder(failsafe), readUntilUs, complete };
}

/**
 * The rule for the failsafe episodes an overview draws, one for every surface of it (a decode
 * in one go, one read as it goes, parts added up): read up to `readUntilUs`, those begun before
 * it, one still on lasting to there; `complete` (`readUntilUs` is the capture's end), every one,
 * and one still on when the capture ends lasting to its end, as the report has it (`ongoing`).
 */
export function failsafeAsRead(
  failsafes: Iterable<{ startUs: number; endUs: number | null }>,
  readUntilUs: number,
  complete: boolean,
): Overview['failsafe'] {
  const out: Overview['failsafe'] = [];
  for (const e of failsafes) if (complete || e.startUs < readUntilUs) out.push({ startUs: e.startUs, endUs: episodeEndAt(e, readUntilUs) });
  return out;
}

/** The failsafe episodes among a link monitor's episodes. */
export function failsafesOf(episodes: readonly LinkEpisode[]): LinkEpisode[] {
  return episodes.filter((e) => e.kind === 'failsafe');
}

/** Failsafe episodes by start (then end), whatever order the ports gave them in. */
function inTimeOrder(failsafe: Overview['failsafe']): Overview['failsafe'] {
  return failsafe.sort((a, b) => a.startUs - b.startUs || a.endUs - b.endUs);
}
