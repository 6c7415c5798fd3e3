/**
 * The health report's plain-English findings for one remote, from its figures, judged by the
 * report's thresholds; and the status they add up to.
 */
import type { CaptureTiming } from '../capture/model.js';
import {
  BAD_FRAME_WARN_RATIO,
  FADE_RATE_HIGH_PER_MIN,
  JITTER_WARN_FRACTION,
  LOST_RATIO_PROBLEM,
  LOST_RATIO_WARN,
  RSSI_LOW_DBM,
  SPIKE_MIN_JUMP_PERCENT,
} from './report-thresholds.js';
import { formatClock, formatDuration, pctText, plural, rate } from './report-text.js';
import type { FindingCode, FindingLevel, RemoteReport, ReportEpisode, ReportFinding, ReportStatus } from './report-types.js';

export function remoteFindings(r: RemoteReport, timing: CaptureTiming): ReportFinding[] {
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
    if (r.restarts.count > 0)
      add(
        'warning',
        'restarts',
        `${plural(r.restarts.count, 'receiver restart')}: the fade counter started again from 0 after a silence${r.restarts.lastAtUs !== null ? ` (the last at ${formatClock(r.restarts.lastAtUs)})` : ''}, a power dip or a loose contact; the hold is counted`,
      );
    if (r.delivery.stalls !== null && r.delivery.stalls > 0 && r.delivery.longestStallUs !== null)
      add(
        'info',
        'delivery',
        `${plural(r.delivery.stalls, 'delivery stall')}, the longest ${formatDuration(r.delivery.longestStallUs)}: frames the USB adapter or the computer held back and delivered at once, not counted as holds or lost frames`,
      );
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

export const LEVEL_ORDER: Record<FindingLevel, number> = { problem: 0, warning: 1, info: 2, ok: 3 };

export function statusOf(findings: readonly ReportFinding[], frames: number): ReportStatus {
  if (frames === 0) return 'no-data';
  if (findings.some((f) => f.level === 'problem')) return 'poor';
  if (findings.some((f) => f.level === 'warning')) return 'fair';
  return 'good';
}
