/**
 * The axes, cursor and legend every live graph shares.
 *
 * x: seconds before now. The window slides with the source clock, so ticks placed by uPlot on
 * round values of the clock land on odd, drifting offsets (−59 s, −54 s…). Here the ticks are
 * counted back from the window's end in round steps: "now", −10 s, −20 s… stay where they are
 * and the data flows past them.
 *
 * y: a range that starts at 0 and ends on a round number (1, 2 or 5 × 10ⁿ) at least a little
 * above the highest value, never collapsing to a single "0" when everything is zero or missing,
 * with 4 or 5 evenly spaced labels.
 */
import type uPlot from 'uplot';
import { chartColors } from './theme.js';

/** Round steps for the time axis, s. */
const TIME_STEPS = [0.1, 0.2, 0.5, 1, 2, 5, 10, 15, 30, 60, 120, 300, 600];
const LONGEST_STEP = 600;
/** Wanted space between two time labels, px. */
const TIME_LABEL_PX = 64;

/** Round steps for a whole capture's time axis, s: those of the graphs, then up to a day. */
const ELAPSED_STEPS = [...TIME_STEPS, 900, 1800, 3600, 7200, 10_800, 21_600, 43_200, 86_400];

/**
 * Time since a capture's start as a label in steps of `step` s: in seconds on an axis stepping
 * below 10 s ("0.25 s", "12 s"), else as a clock ("1:30", "2:05:00").
 */
export function elapsedLabel(seconds: number, step: number): string {
  const s = Math.max(0, seconds);
  if (step < 10) return `${s.toFixed(decimals(step))} s`;
  const whole = Math.round(s);
  const h = Math.floor(whole / 3600);
  const m = Math.floor((whole % 3600) / 60);
  const sec = String(whole % 60).padStart(2, '0');
  return h > 0 ? `${h}:${String(m).padStart(2, '0')}:${sec}` : `${m}:${sec}`;
}

/**
 * The time axis of a whole capture (the replay's timeline): time since `startS` (the capture's
 * start, s of its clock) in round steps counted from there, about one label per TIME_LABEL_PX.
 */
export function elapsedAxis(startS: number): uPlot.Axis {
  const c = chartColors();
  const stepFor = (u: uPlot, min: number, max: number) => {
    const most = Math.max(2, Math.floor(u.bbox.width / devicePixelRatio / TIME_LABEL_PX));
    return ELAPSED_STEPS.find((s) => (max - min) / s <= most) ?? (ELAPSED_STEPS.at(-1) as number);
  };
  return {
    stroke: c.axis,
    grid: { show: false },
    ticks: { stroke: c.grid, width: 1, size: 4 },
    size: 22,
    gap: 2,
    splits: (u, _axis, min, max) => {
      const step = stepFor(u, min, max);
      const out: number[] = [];
      for (let k = Math.ceil((min - startS) / step - 1e-9); startS + k * step <= max + 1e-9; k++) out.push(startS + k * step);
      return out;
    },
    values: (_u, splits) => {
      const step = stepOf(splits);
      return splits.map((v) => elapsedLabel(v - startS, step));
    },
  };
}

/** Seconds before now as a label: "now", "−20 s", or "−2 min" on an axis stepping in minutes. */
export function agoLabel(seconds: number, step = 1): string {
  const s = Math.round(Math.abs(seconds) * 10) / 10;
  if (s === 0) return 'now';
  if (step >= 60 && s % 60 === 0) return `−${s / 60} min`;
  return `−${s} s`;
}

/** The round step that gives about one label per TIME_LABEL_PX over `spanS` at `widthPx`. */
export function timeStep(spanS: number, widthPx: number): number {
  const most = Math.max(2, Math.floor(widthPx / TIME_LABEL_PX));
  return TIME_STEPS.find((s) => spanS / s <= most) ?? LONGEST_STEP;
}

/** The distance between an axis's first two ticks (1 when there are fewer). */
function stepOf(splits: readonly number[]): number {
  const [a, b] = splits;
  return a === undefined || b === undefined ? 1 : b - a;
}

/** Tick positions (source clock, s) counted back from `end` in steps of `step`. */
export function agoSplits(start: number, end: number, step: number): number[] {
  const out: number[] = [];
  for (let k = Math.floor((end - start) / step + 1e-9); k >= 0; k--) out.push(end - k * step);
  return out;
}

/**
 * What the end of a live graph's window is called: "now" live; "0 s" in a replay (store.ts
 * `windowEnd`), whose window ends at the replay's position, which is not now. A word that
 * changes only with the source: uPlot does not redraw an axis for a label alone.
 */
export type WindowEnd = () => string;

/** The x axis of the live graphs: seconds before the window's end, in round steps that stay put. */
export function agoAxis(end: WindowEnd): uPlot.Axis {
  const c = chartColors();
  return {
    stroke: c.axis,
    grid: { stroke: c.grid, width: 1 },
    ticks: { stroke: c.grid, width: 1 },
    splits: (u, _axis, min, max) => agoSplits(min, max, timeStep(max - min, u.bbox.width / devicePixelRatio)),
    values: (u, splits) => {
      const last = u.scales.x?.max ?? 0;
      const step = stepOf(splits);
      return splits.map((v) => {
        const label = agoLabel(v - last, step);
        return label === 'now' ? end() : label;
      });
    },
  };
}

/** The top of a range from 0 that holds `max` with some room: 1, 2 or 5 × 10ⁿ, at least `floor`. */
export function niceTop(max: number | null | undefined, floor = 1): number {
  const want = max !== null && max !== undefined && Number.isFinite(max) && max > 0 ? max * 1.1 : 0;
  if (want <= floor) return floor;
  const p = 10 ** Math.floor(Math.log10(want));
  for (const m of [1, 2, 5, 10]) if (m * p >= want) return m * p;
  return 10 * p;
}

/**
 * Even steps from 0 to `top` that divide it (1, 2, 2.5 or 5 × 10ⁿ), as many as fit `most`
 * labels (5 for a tall chart); whole numbers only when `integer`.
 */
export function niceSplits(top: number, integer = false, most = 5): number[] {
  const p = 10 ** Math.floor(Math.log10(top));
  const candidates = [0.1, 0.2, 0.25, 0.5, 1, 2, 2.5, 5, 10].map((m) => m * p);
  const divides = (step: number) => Math.abs(top / step - Math.round(top / step)) < 1e-9;
  const step = candidates.find((c) => divides(c) && top / c <= Math.max(1, most) && (!integer || Number.isInteger(c))) ?? top;
  const out: number[] = [];
  for (let i = 0; i * step <= top + step / 1000; i++) out.push(Math.round(i * step * 1e6) / 1e6);
  return out;
}

/** How many intervals fit a chart's plot height with room for each label. */
function labelsFor(u: uPlot): number {
  return Math.max(1, Math.min(5, Math.floor(u.bbox.height / devicePixelRatio / 18)));
}

/** The decimals that write every multiple of `step` exactly (0.25 → 2, 0.5 → 1, 5 → 0). */
export function decimals(step: number): number {
  let d = 0;
  while (d < 4 && Math.abs(step * 10 ** d - Math.round(step * 10 ** d)) > 1e-6) d++;
  return d;
}

export interface ValueScale {
  /** A fixed range and its labels, e.g. period 0–30 ms every 10 ms. */
  fixed?: { min: number; max: number; step: number };
  /** The smallest top of an automatic range (default 1). */
  floor?: number;
  /** Counts: only whole-number labels. */
  integer?: boolean;
}

/** A y scale for uPlot from a ValueScale. */
export function valueScale(v: ValueScale): uPlot.Scale {
  if (v.fixed !== undefined) {
    const { min, max } = v.fixed;
    return { range: () => [min, max] };
  }
  return { range: (_u, _min, max) => [0, niceTop(max, v.floor ?? 1)] };
}

/** The labelled y axis for a ValueScale. */
export function valueAxis(label: string, v: ValueScale = {}): uPlot.Axis {
  const c = chartColors();
  return {
    stroke: c.axis,
    grid: { stroke: c.grid, width: 1 },
    ticks: { stroke: c.grid, width: 1 },
    size: 50,
    label,
    labelSize: 18,
    splits: (u, _axis, min, max) => {
      if (v.fixed !== undefined) {
        const out: number[] = [];
        for (let y = v.fixed.min; y <= v.fixed.max + 1e-9; y += v.fixed.step) out.push(y);
        return out;
      }
      return niceSplits(max > min ? max : 1, v.integer, labelsFor(u));
    },
    values: (_u, splits) => {
      const d = decimals(Math.abs(stepOf(splits)));
      return splits.map((y) => y.toFixed(d).replace('-', '−'));
    },
  };
}

/** The hover legend's time: seconds before the window's end, to a tenth; the end as `end` calls it. */
export function legendTimeAt(end: WindowEnd): (u: uPlot, v: number | null) => string {
  return (u, v) => {
    if (v === null || !Number.isFinite(v)) return '—';
    const s = Math.max(0, (u.scales.x?.max ?? v) - v);
    return s < 0.05 ? end() : `−${s.toFixed(1)} s`;
  };
}

/** A legend value with its unit, or a dash where the series has no value. */
export function legendValue(unit: string, digits: number): (u: uPlot, v: number | null) => string {
  return (_u, v) => (v === null || !Number.isFinite(v) ? '—' : `${v.toFixed(digits).replace('-', '−')} ${unit}`);
}

/**
 * The cursor of the live graphs: a vertical line, no zoom by dragging, shared by `syncKey`.
 * The legend is for reading only: uPlot's click-to-hide-a-series on its labels would be a
 * control only a mouse can reach, so it is not bound.
 */
export function hoverCursor(syncKey?: string): uPlot.Cursor {
  return {
    y: false,
    drag: { x: false, y: false },
    bind: { click: () => null },
    points: { size: 7 },
    ...(syncKey === undefined ? {} : { sync: { key: syncKey } }),
  };
}

/** Without a cursor on the chart, its legend shows the newest values instead of dashes. */
export function showNewest(u: uPlot, points: number): void {
  const left = u.cursor.left ?? -1;
  if (left < 0 && points > 0) u.setLegend({ idx: points - 1 }, false);
}

/** uPlot's setCursor also takes whether to publish to the synced charts (not in its typings). */
type SetCursor = (opts: { left: number; top: number }, fire?: boolean, publish?: boolean) => void;

/**
 * The keyboard's way to what hovering shows: the chart takes focus (Tab), the arrow keys move
 * the cursor a bucket at a time (with Shift, ten), Home and End jump to the ends, and the legend
 * reads the values there, in every synced chart. Leaving the chart hides the cursor again.
 * Returns the function that removes the listeners.
 */
export function keyboardCursor(u: uPlot, el: HTMLElement): () => void {
  el.tabIndex = 0;
  const setCursor = u.setCursor as unknown as SetCursor;
  const key = (e: KeyboardEvent) => {
    const xs = u.data[0];
    if (xs === undefined || xs.length === 0) return;
    // The buckets in view (a chart may hold more than its window shows).
    const first = u.series[0]?.idxs?.[0] ?? 0;
    const last = u.series[0]?.idxs?.[1] ?? xs.length - 1;
    // From where the cursor is now (the data slides under it), or from the newest bucket.
    const at = (u.cursor.left ?? -1) >= 0 ? u.cursor.idx : null;
    let i = at === null || at === undefined ? last : Math.min(Math.max(at, first), last);
    const step = e.shiftKey ? 10 : 1;
    if (e.key === 'ArrowLeft') i = Math.max(first, i - step);
    else if (e.key === 'ArrowRight') i = Math.min(last, i + step);
    else if (e.key === 'Home') i = first;
    else if (e.key === 'End') i = last;
    else return;
    const x = xs[i];
    if (x === undefined) return;
    e.preventDefault();
    setCursor.call(u, { left: u.valToPos(x, 'x'), top: u.bbox.height / devicePixelRatio / 2 }, true, true);
  };
  const blur = () => {
    setCursor.call(u, { left: -10, top: -10 }, true, true);
  };
  el.addEventListener('keydown', key);
  el.addEventListener('blur', blur);
  return () => {
    el.removeEventListener('keydown', key);
    el.removeEventListener('blur', blur);
  };
}
