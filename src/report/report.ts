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
import { type AnyCapture, captureDataBytes } from '../capture/capture-windows.js';
import { capturePorts } from '../capture/facts.js';
import { CHANNEL_COUNT, channelName, systemInfo, type Resolution } from '../decoder/spec.js';
import { becameFailsafe, episodeEndAt, type LinkEpisode } from '../decoder/episode.js';
import { captureSpan } from './capture-span.js';
import type { Doctor } from './doctor.js';
import { looksInternal, readPorts } from './resolution-key.js';
import { decodePort, type PortPass } from './report-port.js';
import { adoptPortMessage, type PortReadingMessage } from './report-port-message.js';
import { LEVEL_ORDER, remoteFindings, statusOf } from './report-findings.js';
import { fadesPerMinute, MAX_LISTED_HOLDS, REPORT_BIN_US, REPORT_THRESHOLDS } from './report-thresholds.js';
import { finite, formatClock, formatDuration, plural, r1, r1n, r3 } from './report-text.js';
import { recordedAbsences } from './doctor-events.js';
import type {
  HealthReport,
  HealthReportOptions,
  RemoteReport,
  ReportChannel,
  ReportEpisode,
  ReportFinding,
  ReportStatus,
} from './report-types.js';

function episodeOf(e: LinkEpisode, origin: number, end: number): ReportEpisode {
  const endAbs = episodeEndAt(e, end);
  return {
    startUs: r1(e.startUs - origin),
    endUs: r1(endAbs - origin),
    durationUs: r1(Math.max(0, endAbs - e.startUs)),
    lastFrameUs: r1(e.lastFrameUs - origin),
    ongoing: e.endUs === null,
  };
}

/**
 * The health report of every port of a capture (one remote receiver per port). Decodes each
 * port once where it can (`readPorts`); never throws on the capture's content.
 */
export function healthReport(capture: AnyCapture, options: HealthReportOptions = {}): HealthReport {
  return healthReportFeeding(capture, options, undefined);
}

/**
 * A port's final reading made elsewhere (another thread, `readPortMessage`), or undefined when
 * nobody made that one: the report then decodes the port itself.
 */
export type ReadingsElsewhere = (
  port: number,
  resolution: 'auto' | Resolution,
  from: 'user' | 'internal-remote',
) => PortReadingMessage | undefined;

/**
 * `healthReport`, with `doctor` (when given, for a timed capture) fed every port's bytes, events
 * and frames from the same decode: `diagnosedHealthReport` asks it for its findings after.
 * `span` is the capture's `captureSpan`, when the caller has it already; `elsewhere` gives
 * readings made on other threads.
 */
export function healthReportFeeding(
  capture: AnyCapture,
  options: HealthReportOptions,
  doctor: Doctor | undefined,
  span: { startUs: number; endUs: number } = captureSpan(capture),
  elsewhere?: ReadingsElsewhere,
): HealthReport {
  const ports = capturePorts(capture);
  const timed = capture.timing !== 'none';
  // The shared clock (span): from the earliest to the latest time recorded on any port (each
  // port's series bins from the same origin and its link ends there).
  const pass: PortPass = { originUs: span.startUs, endUs: span.endUs, doctor };
  // §8: the internal remote holds the key for every remote; external ports take its resolution.
  const read = readPorts(
    ports,
    options.resolution ?? 'auto',
    (port) => looksInternal(capture, port),
    (port, resolution, from, final) => {
      const made = final ? elsewhere?.(port, resolution, from) : undefined;
      // Made for this very pass (the same clock, a doctor when this report has one), or not used.
      if (
        made !== undefined &&
        Object.is(made.job.originUs, pass.originUs) &&
        Object.is(made.job.endUs, pass.endUs) &&
        (made.doctor === null) === (doctor === undefined)
      )
        return adoptPortMessage(capture, made, doctor);
      return decodePort(capture, port, resolution, from, final ? pass : { ...pass, doctor: undefined });
    },
  );
  const decoded = ports.flatMap((p) => read.get(p) ?? []);

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
    const recovered = holdEpisodes.filter((h) => !h.ongoing && !becameFailsafe(h.lastFrameUs, failsafes));
    let longestHold: ReportEpisode | null = null;
    for (const e of recovered) if (longestHold === null || e.durationUs > longestHold.durationUs) longestHold = e;

    const channels: ReportChannel[] = [];
    for (let id = 0; id < CHANNEL_COUNT; id++) {
      const c = d.channelFrames[id] ?? 0;
      if (c > 0) {
        channels.push({
          id,
          name: channelName(id),
          frames: c,
          minUs: d.channelMin[id] ?? NaN,
          maxUs: d.channelMax[id] ?? NaN,
          meanUs: r1((d.channelSum[id] ?? NaN) / c),
        });
      }
    }

    const durationUs = hasClock && n > 0 ? last - first : NaN;
    const sys = format.system === null ? undefined : systemInfo(format.system);
    const duration = Number.isFinite(durationUs) ? durationUs : NaN;
    const fadeRate = hasClock && n > 0 ? fadesPerMinute(fadesTotal, first, last) : null;
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
      undeliveredFrames: havePeriod ? ls.lostFrames : null,
      delivery: {
        delayUs: hasClock ? r1n(ls.deliveryDelayUs) : null,
        jitterUs: hasClock ? r1n(ls.deliveryJitterUs) : null,
        stalls: hasClock ? ls.stalls : null,
        longestStallUs: hasClock && ls.stalls > 0 ? r1(ls.longestStallUs) : null,
      },
      restarts: {
        count: ls.restarts,
        lastAtUs: hasClock && link.restarts.length > 0 ? r1((link.restarts.at(-1)?.timeUs ?? NaN) - origin) : null,
      },
      lostRatio: haveMissed ? Math.round((missed / Math.max(1, stats.frames + missed)) * 1e6) / 1e6 : null,
      nominalPeriodUs: havePeriod ? period : null,
      fades: rssiMode
        ? null
        : {
            total: fadesTotal,
            perMinute: fadeRate === null ? null : r3(fadeRate),
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
  // A recorded unplug: the link counts nothing for it (LinkMonitor.stopped); the report says where it was.
  const away = hasClock ? recordedAbsences(capture, span.endUs) : new Map();
  for (const [port, a] of away) {
    const label = remotes.find((r) => r.port === port)?.label ?? `Port ${port}`;
    verdict.push({
      level: 'info',
      code: 'adapter-away',
      port,
      text: `${label}: the adapter was unplugged ${plural(a.count, 'time')} (${formatDuration(a.totalUs)} in all, from ${formatClock(a.firstUs - origin)}); nothing is counted for that time`,
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
      bytes: captureDataBytes(capture),
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
