/**
 * The health report's graphs as inline SVG: one panel per series per remote, stacked over one
 * shared time axis, drawn in the page's palette (report-html.ts puts them in the page).
 */
import { DATA_COLORS } from './palette.js';
import { RSSI_LOW_DBM } from './report-thresholds.js';
import { escapeHtml, formatClock } from './report-text.js';
import type { HealthReport, RemoteReport } from './report-types.js';

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
export function graphsSvg(report: HealthReport): string {
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
