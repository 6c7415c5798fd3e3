/**
 * The health report as one self-contained HTML page: inline SVG graphs, no scripts, nothing
 * fetched, one printed page. Rendering only: the figures come from `healthReport`.
 */
import { XPLUS_FIRST, channelName } from '../decoder/spec.js';
import type { ResolutionReason } from '../decoder/types.js';
import { DATA_COLORS } from './palette.js';
import { RSSI_LOW_DBM } from './report-thresholds.js';
import { formatClock, formatDuration, pctText, plural, rate } from './report-text.js';
import type { FindingLevel, HealthReport, RemoteReport, ReportStatus } from './report-types.js';

/** Escapes text for HTML content and attribute values. */
export function escapeHtml(text: string): string {
  return text.replace(/[&<>"']/g, (c) => (c === '&' ? '&amp;' : c === '<' ? '&lt;' : c === '>' ? '&gt;' : c === '"' ? '&quot;' : '&#39;'));
}

/** The page's light palette (palette.ts), and what only the printed report draws. */
const COLORS = {
  ...DATA_COLORS.light,
  hold: 'rgba(230, 170, 30, 0.45)',
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
  let step = steps[steps.length - 1] ?? NaN;
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
    if (r.series.rssiMean)
      panels.push({
        title: `${prefix}RSSI dBm (mean, lowest)`,
        kind: 'rssi',
        color: COLORS.rssi,
        values: r.series.rssiMean,
        low: r.series.rssiMin ?? undefined,
        remote: r,
      });
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
  parts.push(
    `<svg viewBox="0 0 ${W} ${H}" width="100%" role="img" aria-label="Link quality over time" font-family="Helvetica, Arial, sans-serif" font-size="10">`,
  );
  // Legend.
  const legend: [string, string][] = [['Lost frames', COLORS.lost]];
  if (panels.some((p) => p.color === COLORS.fades)) legend.push(['Fades', COLORS.fades]);
  if (panels.some((p) => p.kind === 'rssi')) legend.push(['RSSI mean', COLORS.rssi], ['RSSI lowest', COLORS.rssiMin]);
  legend.push(['Hold', COLORS.hold], ['Failsafe', COLORS.failsafeBand]);
  let lx = left;
  for (const [name, color] of legend) {
    parts.push(
      `<rect x="${lx}" y="4" width="10" height="10" fill="${color}"/><text x="${lx + 14}" y="13" fill="${COLORS.text}">${escapeHtml(name)}</text>`,
    );
    lx += 24 + name.length * 5.6;
  }
  if (group > 1)
    parts.push(`<text x="${W - right}" y="13" text-anchor="end" fill="${COLORS.axis}">each column: the highest of ${group} s</text>`);
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
      parts.push(`<rect x="${f1(x0)}" y="${top}" width="${f1(Math.max(1.5, x1 - x0))}" height="${panelH}" fill="${COLORS.failsafeBand}"/>`);
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
        parts.push(
          `<line x1="${left}" y1="${f1(y(RSSI_LOW_DBM))}" x2="${left + plotW}" y2="${f1(y(RSSI_LOW_DBM))}" stroke="${COLORS.failsafeEdge}" stroke-dasharray="3 3" stroke-width="0.8"/>`,
        );
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
  override: 'set by the user',
  'system-byte': 'system byte',
  'channel-ids': 'from the channel IDs',
  'internal-remote': 'from the internal remote',
  'system-byte-contradicted': 'system byte contradicted',
  unknown: 'undecided',
};

/** The metrics of one remote as label/value rows; `compact` for the side-by-side table of several remotes. */
function metricRows(r: RemoteReport, timed: boolean, compact: boolean): [string, string][] {
  const rows: [string, string][] = [];
  const sys =
    r.system.byte === null
      ? compact
        ? 'none'
        : 'none (external remote or no system byte)'
      : `${hex2(r.system.byte)} ${r.system.name ?? '(not a valid system byte)'}`;
  rows.push(['System', sys]);
  rows.push([
    'Remote',
    r.remote === null ? '?' : `${r.remote}${r.headerMode === 'rssi' ? (compact ? ', RSSI' : ', RSSI in byte 0 (SPM4649T)') : ''}`,
  ]);
  rows.push(['Resolution', `${r.resolution.value ?? '?'} (${REASON_SHORT[r.resolution.reason] ?? r.resolution.reason})`]);
  rows.push([
    'Duration',
    r.durationUs === null
      ? '–'
      : `${formatDuration(r.durationUs)} (${formatClock(r.firstFrameUs ?? 0)}–${formatClock(r.lastFrameUs ?? 0)})`,
  ]);
  rows.push(['Frames', r.expectedFrames !== null ? `${r.frames} of ${r.expectedFrames}${compact ? '' : ' expected'}` : String(r.frames)]);
  if (timed) rows.push(['Lost frames', r.lostRatio === null ? '–' : `${r.missedFrames} (${pctText(r.lostRatio)})`]);
  rows.push([
    'Fades',
    r.fades === null
      ? '–'
      : `${r.fades.total}${r.fades.perMinute !== null ? ` (${rate(r.fades.perMinute)}/min)` : ''}${r.fades.implausibleJumps ? `; ${plural(r.fades.implausibleJumps, 'counter jump')} ignored` : ''}`,
  ]);
  if (r.rssi || !compact) {
    if (r.rssi)
      rows.push([
        'RSSI',
        r.rssi.minDbm === null
          ? 'no level reported'
          : `${r.rssi.minDbm} / ${r.rssi.meanDbm} / ${r.rssi.maxDbm} dBm${compact ? '' : ' (min / mean / max)'}${r.rssi.lossReports ? `, ${r.rssi.lossReports} loss reports` : ''}`,
      ]);
  } else {
    rows.push(['RSSI', '–']);
  }
  if (timed) {
    const hd = r.holds;
    const became = hd.count - hd.recovered - hd.episodes.filter((h) => h.ongoing).length;
    rows.push([
      'Holds',
      `${hd.count}${became > 0 ? ` (${became} became ${became === 1 ? 'a failsafe' : 'failsafes'})` : ''}${hd.longestUs !== null ? `; longest recovered ${formatDuration(hd.longestUs)} at ${formatClock(hd.longestAtUs ?? 0)}` : ''}`,
    ]);
    rows.push([
      'Failsafes',
      r.failsafes.length === 0 ? '0' : `${r.failsafes.length}, ${formatDuration(r.failsafes.reduce((a, x) => a + x.durationUs, 0))} in all`,
    ]);
    rows.push(['Longest gap', r.longestGapUs === null ? '–' : formatDuration(r.longestGapUs)]);
    const fp = r.framePeriod;
    const chunk = fp?.basis === 'per-chunk' ? ' (USB chunk times)' : '';
    const pcts =
      fp === null
        ? '–'
        : `p50 ${(fp.p50Us / 1000).toFixed(2)} · p95 ${(fp.p95Us / 1000).toFixed(2)} · p99 ${(fp.p99Us / 1000).toFixed(2)} ms`;
    if (compact) {
      rows.push([
        'Frame period',
        fp === null ? '–' : `${(fp.meanUs / 1000).toFixed(3)} ms, jitter ${formatDuration(fp.stdDevUs)}; ${pcts}${chunk}`,
      ]);
    } else {
      rows.push([
        'Frame period',
        fp === null ? '–' : `${(fp.meanUs / 1000).toFixed(3)} ms mean, jitter ${formatDuration(fp.stdDevUs)}${chunk}`,
      ]);
      rows.push(['Intervals', fp === null ? '–' : `${pcts} (${fp.intervals}, gaps excluded)`]);
    }
  }
  const d = r.decoder;
  rows.push([
    'Decoder',
    `${d.bytes} bytes, ${d.discardedBytes} discarded, ${d.resyncs} resyncs, ${d.badFrames} bad frames${d.formatChanges ? `, ${d.formatChanges} format changes` : ''}`,
  ]);
  // Empty (0xFFFF) slots and VTX frames, where they occur: the first says channels the receiver leaves unused.
  if (d.emptySlots > 0 || d.vtxFrames > 0) {
    rows.push([
      'Slots',
      [d.emptySlots > 0 ? `${d.emptySlots} empty (0xFFFF)` : '', d.vtxFrames > 0 ? `${d.vtxFrames} VTX frames` : '']
        .filter(Boolean)
        .join(', '),
    ]);
  }
  rows.push(['Glitches', r.glitches.count === 0 ? 'none' : `${r.glitches.count} spikes in ${r.glitches.frames} frames`]);
  if (compact) rows.push(['Channels', channelList(r)]);
  return rows;
}

/** "0–11, X+1–X+4 (16)": the channel IDs seen, as runs. */
function channelList(r: RemoteReport): string {
  if (r.channels.length === 0) return 'none';
  const runs: string[] = [];
  const ids = r.channels.map((c) => c.id);
  for (let i = 0; i < ids.length; ) {
    let j = i;
    while (j + 1 < ids.length && ids[j + 1] === (ids[j] ?? 0) + 1 && (ids[j + 1] ?? 0) < XPLUS_FIRST === (ids[i] ?? 0) < XPLUS_FIRST) j++;
    const a = ids[i] ?? 0;
    const b = ids[j] ?? 0;
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
  const rows = all
    .slice(0, LIST_ROWS)
    .map(
      ({ r, x }, i) =>
        `<tr>${many ? `<td>${e(r.label)}</td>` : `<td class="n">${i + 1}</td>`}<td class="n">${formatClock(x.lastFrameUs)}</td><td class="n">${formatClock(x.startUs)}</td><td class="n">${x.ongoing ? 'end of capture' : formatClock(x.endUs)}</td><td class="n">${e(formatDuration(x.durationUs))}</td></tr>`,
    )
    .join('');
  return `<div><h3>Failsafe episodes</h3><table class="grid"><thead><tr>${many ? '<th>Port</th>' : '<th class="n">#</th>'}<th class="n">Last frame</th><th class="n">Failsafe from</th><th class="n">Until</th><th class="n">Duration</th></tr></thead><tbody>${rows}</tbody></table>${moreNote(Math.min(LIST_ROWS, all.length), all.length)}</div>`;
}

/** Glitches of every remote. */
function glitchTable(report: HealthReport): string {
  const e = escapeHtml;
  const many = report.remotes.length > 1;
  const all = report.remotes.flatMap((r) => r.glitches.listed.map((g) => ({ r, g })));
  const total = report.remotes.reduce((n, r) => n + r.glitches.count, 0);
  if (total === 0) return '';
  const rows = all
    .slice(0, LIST_ROWS)
    .map(
      ({ r, g }) =>
        `<tr>${many ? `<td>${e(r.label)}</td>` : ''}<td class="n">${g.timeUs === null ? `frame ${g.frameIndex}` : formatClock(g.timeUs)}</td><td>${e(g.name)}</td><td class="n">${g.beforeUs}</td><td class="n">${g.spikeUs}</td><td class="n">${g.afterUs}</td></tr>`,
    )
    .join('');
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
    const kv = metricRows(r, timed, false)
      .map(([k, v]) => `<tr><th>${e(k)}</th><td>${e(v)}</td></tr>`)
      .join('');
    const title = `${r.label}${r.system.name ? ` · ${r.system.name}` : ''}${r.remote ? ` · ${r.remote} remote` : ''}`;
    return `<section class="remote"><h2><span class="badge ${r.status}">${e(STATUS_TEXT[r.status])}</span> ${e(title)}</h2><p class="why">${e(r.resolution.explanation)}</p><div class="cols"><table class="kv">${kv}</table>${channelTable(r)}</div>${extraHtml}</section>`;
  }
  const columns = remotes.map((r) => metricRows(r, timed, true));
  const labels = (columns[0] ?? []).map(([k]) => k);
  const head = remotes.map((r) => `<th>${e(r.label)} <span class="badge ${r.status}">${e(STATUS_TEXT[r.status])}</span></th>`).join('');
  const body = labels.map((k, i) => `<tr><th>${e(k)}</th>${columns.map((c) => `<td>${e(c[i]?.[1] ?? '')}</td>`).join('')}</tr>`).join('');
  const why = remotes.map((r) => `<li>${e(r.label)}: ${e(r.resolution.explanation)}</li>`).join('');
  return (
    `<section class="remote"><h2>Remotes</h2><table class="grid compare"><thead><tr><th></th>${head}</tr></thead><tbody>${body}</tbody></table>` +
    `<ul class="why">${why}</ul>${extraHtml}</section>`
  );
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
    const lines = f.settings
      .filter((s) => s.lines.length > 0)
      .map((s) => `${e(s.stack)}: <code>${s.lines.map(e).join('</code> <code>')}</code>`);
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
  const verdict =
    report.verdict.length === 0
      ? '<p class="muted">Nothing to report.</p>'
      : `<ul class="verdict">${report.verdict.map((f) => `<li class="${f.level}"><span class="mark">${LEVEL_MARK[f.level]}</span>${e(f.text)}</li>`).join('')}</ul>`;
  const svg = graphsSvg(report);
  const graphs =
    svg !== ''
      ? `<section class="graphs">${svg}</section>`
      : report.timeline.bins === 0 && report.remotes.some((r) => r.frames > 0)
        ? '<p class="muted">No timing in this file: no graphs over time.</p>'
        : '';
  const t = report.thresholds;
  const footer =
    `Thresholds: fade rate high above ${t.fadeRateHighPerMin}/min; lost frames warning from ${t.lostRatioWarn * 100} %, problem from ${t.lostRatioProblem * 100} %; ` +
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
