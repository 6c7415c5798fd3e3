/**
 * Graphs over a chosen window: fade rate (or RSSI in dBm on an SPM4649T), frame period and
 * lost frames, drawn with uPlot from the columnar buckets (100 ms each) with one setData per
 * animation frame when new buckets arrived. The x axis is seconds before now, in round steps
 * (axes.ts); hovering a graph shows every graph's value at that time in its legend (the
 * cursors are synced). The charts are rebuilt when the theme changes: canvas colours are not CSS.
 */
import type { Signal } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import uPlot from 'uplot';
import 'uplot/dist/uPlot.min.css';
import { layeredChart } from '../../axes-layer.js';
import { chartTurn, onFrame } from '../../frame-loop.js';
import type { Live, SeriesBuffer } from '../../live.js';
import { current, status, windowEnd } from '../../store.js';
import {
  agoAxis,
  hoverCursor,
  keyboardCursor,
  legendTimeAt,
  legendValue,
  showNewest,
  valueAxis,
  valueScale,
  type ValueScale,
} from '../../axes.js';
import { chartColors, theme } from '../../theme.js';
import { Choice } from '../Choice/index.js';
import './style.css';

/** The windows offered, shortest first (the first that holds a capture is chosen for it). */
export const WINDOWS = [
  [1e6, '1 s'],
  [10e6, '10 s'],
  [60e6, '1 min'],
  [600e6, '10 min'],
] as const;

/** Each chart's height, px: room for 4–6 labelled ticks on the y axis. */
const HEIGHT = 140;

interface ChartSpec {
  key: 'fadeRate' | 'rssi' | 'periodMs' | 'lost';
  title: string;
  unit: string;
  color: string;
  scale: ValueScale;
  /** Decimals in the hover legend. */
  digits: number;
  bars?: boolean;
}

function specs(rssi: boolean): ChartSpec[] {
  const c = chartColors();
  return [
    rssi
      ? { key: 'rssi', title: 'RSSI', unit: 'dBm', color: c.rssi, scale: { fixed: { min: -100, max: -30, step: 10 } }, digits: 0 }
      : { key: 'fadeRate', title: 'Fades', unit: '/s', color: c.fades, scale: { floor: 1 }, digits: 1 },
    { key: 'periodMs', title: 'Period', unit: 'ms', color: c.period, scale: { fixed: { min: 0, max: 30, step: 10 } }, digits: 2 },
    { key: 'lost', title: 'Lost', unit: '/100 ms', color: c.lost, scale: { floor: 2, integer: true }, digits: 0, bars: true },
  ];
}

function makeChart(el: HTMLElement, spec: ChartSpec, width: number, sync: uPlot.SyncPubSub): uPlot {
  const opts = (): uPlot.Options => ({
    width,
    height: HEIGHT,
    cursor: hoverCursor(sync.key),
    legend: { show: true, live: true },
    scales: { x: { time: false }, y: valueScale(spec.scale) },
    axes: [agoAxis(windowEnd), valueAxis(`${spec.title} ${spec.unit}`, spec.scale)],
    series: [
      { label: 'Time', value: legendTimeAt(windowEnd) },
      {
        label: spec.title,
        stroke: spec.color,
        width: 1.5,
        fill: spec.bars ? `${spec.color}88` : undefined,
        paths: spec.bars ? uPlot.paths.bars?.({ size: [1, Infinity] }) : undefined,
        points: { show: false },
        spanGaps: false,
        value: legendValue(spec.unit, spec.digits),
      },
    ],
  });
  return layeredChart(opts, [[], []], el);
}

export function Graphs({ windowUs }: { windowUs: Signal<number> }) {
  const host = useRef<HTMLDivElement>(null);
  const rssi = status.value.format.headerMode === 'rssi';
  const palette = theme.value;
  useEffect(() => {
    const el = host.current;
    if (el === null) return undefined;
    const sync = uPlot.sync('satscope');
    const list = specs(rssi);
    const width = () => Math.max(200, el.clientWidth - 4);
    // Measured once for all the panes: read after each one is appended, it laid the page out
    // again each time (33 ms when a capture opens). The observer below follows any change.
    const first = width();
    const panes = list.map((spec) => {
      const box = document.createElement('div');
      box.className = 'chart';
      box.setAttribute('role', 'figure');
      box.setAttribute('aria-label', `${spec.title} over time: hover, or the arrow keys, for the values`);
      box.dataset.chart = spec.key;
      el.append(box);
      return { key: spec.key, box, chart: makeChart(box, spec, first, sync) };
    });
    const charts = panes.map((p) => p.chart);
    const cursors = panes.map((p) => keyboardCursor(p.chart, p.box));
    const resize = new ResizeObserver(() =>
      charts.forEach((c) => {
        c.setSize({ width: width(), height: HEIGHT });
      }),
    );
    resize.observe(el);
    let appended = -1;
    let epoch = -1;
    let drawnAt = 0;
    let drawn: Live | undefined;
    const stop = onFrame((nowMs) => {
      const live = current();
      const s: SeriesBuffer = live.series;
      // New buckets come ten times a second; between them the axis slides with time, redrawn
      // five times a second. Other batches (every few ms) change nothing the graphs show.
      if (live === drawn && s.epoch === epoch && s.appended === appended && nowMs - drawnAt < 200) return;
      // Not in the same frame as the remotes' chart (the three graphs redraw together).
      if (!chartTurn()) return;
      drawn = live;
      epoch = s.epoch;
      appended = s.appended;
      drawnAt = nowMs;
      const end = live.nowUs() / 1e6;
      if (!Number.isFinite(end)) {
        // A new source with no data yet: show nothing rather than the last source's curves.
        for (const chart of charts) chart.setData([[], []]);
        return;
      }
      const start = end - windowUs.value / 1e6;
      // The remote's own growing columns, whole: uPlot draws the part its x scale shows.
      for (const { chart, key } of panes) {
        chart.batch(() => {
          chart.setData([s.t, s[key]], false);
          chart.setScale('x', { min: start, max: end });
        });
        showNewest(chart, s.length);
      }
    });
    return () => {
      stop();
      resize.disconnect();
      cursors.forEach((off) => {
        off();
      });
      charts.forEach((c) => {
        c.destroy();
      });
      el.replaceChildren();
    };
  }, [rssi, windowUs, palette]);

  return (
    <section class="graphs" aria-label="Graphs">
      <div class="graph-head">
        <h2>Link over time</h2>
        <Choice
          label="Window"
          options={WINDOWS}
          value={windowUs.value}
          onChoose={(us) => {
            windowUs.value = us;
          }}
        />
      </div>
      <div class="chart-host" ref={host} />
    </section>
  );
}
