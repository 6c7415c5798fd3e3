/**
 * The health report as one self-contained HTML page: inline SVG graphs, no scripts, nothing
 * fetched, one printed page. Rendering only: the figures come from `healthReport`.
 */
import { XPLUS_FIRST, channelName } from '../decoder/spec.js';
import type { ResolutionReason } from '../decoder/types.js';
import { escapeHtml, formatClock, formatDuration, pctText, plural, rate } from './report-text.js';
import type { FindingLevel, HealthReport, RemoteReport, ReportStatus } from './report-types.js';
import { graphsSvg } from './report-svg.js';

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
