/**
 * Channel values over time, as flight-stack tools show stick traces: each chosen channel in a
 * lane of its own (903–2097 µs, the centre line 1500 µs), so that twelve channels or more stay
 * readable, on the same time axis and window as the link graphs (their cursors are synced), live
 * and in replay. Glitches (a value that jumps and comes back, the health report's rule) are
 * marked where they happened. The user picks the channels; by default, every channel 0–11 the
 * remote sends. Drawn from the remote's trace columns (traces.ts) once per animation frame when
 * something changed, or five times a second as the window slides, and only while on screen.
 */
import { type Signal, signal, useSignal } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import type uPlot from 'uplot';
import { SPIKE_MIN_JUMP_PERCENT, SPIKE_RETURN_PERCENT } from '../../../report/report-thresholds.js';
import { CHANNEL_COUNT, channelName } from '../../../decoder/spec.js';
import { layeredChart } from '../../axes-layer.js';
import { agoAxis, hoverCursor, keyboardCursor, legendTimeAt, showNewest } from '../../axes.js';
import { chartTurn, onFrame, wake } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { current, windowEnd } from '../../store.js';
import { setText } from '../../text.js';
import { chartColors, theme } from '../../theme.js';
import { laneUs, laneY, traceView } from '../../traces.js';
import './style.css';

/** Height of one channel's lane, px. */
const LANE_PX = 34;
/** Below the lanes: the time axis. */
const AXIS_PX = 34;
const STICKS = [0, 1, 2, 3];
const NORMAL = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11];
const ALL = Array.from({ length: CHANNEL_COUNT }, (_, id) => id);

/** The channels the user picked (null: the default, every channel 0–11 the remote sends). */
const picked = signal<number[] | null>(null);

function seenIds(seen: number, among: readonly number[]): number[] {
  return among.filter((id) => (seen & (1 << id)) !== 0);
}

/** The lane axis: each channel's name at its lane's centre line (1500 µs). */
function laneAxis(channels: readonly number[]): uPlot.Axis {
  const c = chartColors();
  const lanes = channels.length;
  return {
    stroke: c.axis,
    grid: { stroke: c.grid, width: 1 },
    ticks: { show: false },
    size: 74,
    gap: 6,
    // Bottom lane first: ascending.
    splits: () => channels.map((_, k) => laneY(1500, lanes - 1 - k, lanes)),
    values: (_u, splits) => splits.map((_, i) => channelName(channels[lanes - 1 - i] ?? 0)),
  };
}

function makeChart(el: HTMLElement, channels: readonly number[], width: number, marks: () => void): uPlot {
  const c = chartColors();
  const lanes = channels.length;
  return layeredChart(
    () => ({
      width,
      height: lanes * LANE_PX + AXIS_PX,
      cursor: hoverCursor('satscope'),
      legend: { show: true, live: true },
      scales: { x: { time: false }, y: { range: () => [0, lanes] } },
      axes: [agoAxis(windowEnd), laneAxis(channels)],
      series: [
        { label: 'Time', value: legendTimeAt(windowEnd) },
        ...channels.map((id, k) => ({
          label: channelName(id),
          stroke: c.traces[k % c.traces.length],
          width: 1.25,
          points: { show: false },
          spanGaps: false,
          value: (_u: uPlot, v: number | null) => (v === null || !Number.isFinite(v) ? '—' : `${Math.round(laneUs(v, k, lanes))} µs`),
        })),
      ],
      hooks: {
        // Every other lane shaded, so that a line near its lane's edge is read in its own lane.
        drawClear: [
          (u: uPlot) => {
            const ctx = u.ctx;
            ctx.save();
            ctx.fillStyle = c.lane;
            for (let k = 1; k < lanes; k += 2) {
              const top = u.valToPos(lanes - k, 'y', true);
              const bottom = u.valToPos(lanes - 1 - k, 'y', true);
              ctx.fillRect(u.bbox.left, top, u.bbox.width, bottom - top);
            }
            ctx.restore();
          },
        ],
        draw: [marks],
      },
    }),
    [[], ...channels.map(() => [])],
    el,
  );
}

/**
 * Glitch marks over the traces: a ring at the wrong value (the trace itself shows the jump, which
 * nothing is drawn over) and a small triangle on the lane's top edge, so that a glitch is found
 * at a glance on a long window.
 */
function drawGlitches(u: uPlot, live: Live, channels: readonly number[], startUs: number, endUs: number, color: string): number {
  const b = live.traces;
  const lanes = channels.length;
  const ctx = u.ctx;
  const dpr = devicePixelRatio || 1;
  let shown = 0;
  ctx.save();
  ctx.strokeStyle = color;
  ctx.fillStyle = color;
  ctx.lineWidth = 1.5 * dpr;
  for (let i = b.indexAt(startUs, true); i < b.spikes && (b.spikeT[i] ?? Number.POSITIVE_INFINITY) <= endUs; i++) {
    const lane = channels.indexOf(b.spikeChannel[i] ?? -1);
    if (lane < 0) continue;
    shown++;
    const x = u.valToPos((b.spikeT[i] ?? 0) / 1e6, 'x', true);
    const y = u.valToPos(laneY(b.spikeUs[i] ?? 0, lane, lanes), 'y', true);
    const top = u.valToPos(lanes - lane, 'y', true);
    const r = 4 * dpr;
    ctx.beginPath();
    ctx.moveTo(x - r, top);
    ctx.lineTo(x + r, top);
    ctx.lineTo(x, top + 1.5 * r);
    ctx.closePath();
    ctx.fill();
    ctx.beginPath();
    ctx.arc(x, y, r, 0, 2 * Math.PI);
    ctx.stroke();
  }
  ctx.restore();
  return shown;
}

function ChannelPicker({ lanes, seen }: { lanes: readonly number[]; seen: number }) {
  const xplus = seenIds(seen, ALL.slice(12));
  const offered = [...NORMAL, ...xplus];
  const choose = (ids: number[]) => {
    picked.value = ids;
  };
  return (
    <div class="trace-picker" role="group" aria-label="Channels shown">
      <button type="button" class="preset" onClick={() => choose(STICKS)}>
        Sticks
      </button>
      <button type="button" class="preset" onClick={() => choose(seenIds(seen, ALL))}>
        All sent
      </button>
      {offered.map((id) => {
        const on = lanes.includes(id);
        return (
          <button
            key={id}
            type="button"
            aria-pressed={on}
            class={`${on ? 'on' : ''}${(seen & (1 << id)) === 0 ? ' unsent' : ''}`}
            title={(seen & (1 << id)) === 0 ? `${channelName(id)}: not sent by this remote` : undefined}
            onClick={() => choose(on ? lanes.filter((x) => x !== id) : [...lanes, id].sort((a, b) => a - b))}
          >
            {id}
            <span class="name"> {channelName(id)}</span>
          </button>
        );
      })}
    </div>
  );
}

export function Traces({ windowUs }: { windowUs: Signal<number> }) {
  const host = useRef<HTMLDivElement>(null);
  const note = useRef<HTMLParagraphElement>(null);
  const count = useRef<HTMLSpanElement>(null);
  /** The channels the selected remote has sent, one bit each (the default lanes and the picker follow it). */
  const seen = useSignal(0);
  const palette = theme.value;
  const lanes = picked.value ?? seenIds(seen.value, NORMAL);
  const key = lanes.join(',');

  // What the remote has sent, followed as it changes (a new remote, a reset, an X-Plus channel);
  // with or without times (frames without any still have channels, shown as lanes with a note).
  useEffect(
    () =>
      onFrame(() => {
        const seenUs = current().seenUs;
        let s = 0;
        for (let id = 0; id < CHANNEL_COUNT; id++) if (!Number.isNaN(seenUs[id] ?? Number.NaN)) s |= 1 << id;
        if (s !== seen.peek()) seen.value = s;
      }),
    [],
  );

  useEffect(() => {
    const el = host.current;
    if (el === null || lanes.length === 0) return undefined;
    const width = () => Math.max(200, el.clientWidth - 4);
    const box = document.createElement('div');
    box.className = 'chart';
    box.setAttribute('role', 'figure');
    box.setAttribute('aria-label', 'Channel values over time: hover, or the arrow keys, for the values');
    box.dataset.chart = 'traces';
    el.append(box);
    let live: Live = current();
    let span: [number, number] = [0, 0];
    let glitches = 0;
    const color = chartColors(palette).glitch;
    const chart = makeChart(box, lanes, width(), () => {
      glitches = drawGlitches(chart, live, lanes, span[0], span[1], color);
    });
    const keys = keyboardCursor(chart, box);
    const resize = new ResizeObserver(() => chart.setSize({ width: width(), height: lanes.length * LANE_PX + AXIS_PX }));
    resize.observe(el);
    let drawn: Live | undefined;
    let version = -1;
    let drawnAt = 0;
    // Drawn only while on screen: below the fold, or folded away on a phone, it costs nothing
    // (it is drawn at once when scrolled to).
    let onScreen = false;
    const seen = new IntersectionObserver((entries) => {
      onScreen = entries.some((e) => e.isIntersecting);
      if (onScreen) {
        drawn = undefined;
        wake();
      }
    });
    seen.observe(box);
    const stop = onFrame((nowMs) => {
      if (!onScreen) return;
      live = current();
      const b = live.traces;
      if (live === drawn && b.version === version && nowMs - drawnAt < 200) return;
      if (!chartTurn()) return;
      drawn = live;
      version = b.version;
      drawnAt = nowMs;
      const endUs = live.nowUs();
      const untimed = b.length === 0 && live.counters.frames > 0;
      if (note.current !== null)
        setText(note.current, untimed ? 'These frames carry no times (a capture without timing): traces need a time axis.' : '');
      // Without times, no empty lanes that would read as channels that sent nothing.
      if (box.hidden !== untimed) box.hidden = untimed;
      if (!Number.isFinite(endUs)) {
        chart.setData([[], ...lanes.map(() => [])]);
        if (count.current !== null) setText(count.current, '');
        return;
      }
      span = [endUs - windowUs.value, endUs];
      const columns = Math.ceil(chart.bbox.width || width() * (devicePixelRatio || 1));
      const data = traceView(b, lanes, span[0], span[1], columns);
      chart.batch(() => {
        chart.setData(data as uPlot.AlignedData, false);
        chart.setScale('x', { min: span[0] / 1e6, max: span[1] / 1e6 });
      });
      showNewest(chart, data[0]?.length ?? 0);
      if (count.current !== null) {
        const inView = b.indexAt(span[1] + 1e-6) - b.indexAt(span[0]);
        setText(count.current, inView === 0 ? '' : glitches === 1 ? '1 glitch in view' : `${glitches} glitches in view`);
        count.current.classList.toggle('found', glitches > 0);
      }
    });
    return () => {
      stop();
      seen.disconnect();
      resize.disconnect();
      keys();
      chart.destroy();
      el.replaceChildren();
    };
  }, [key, windowUs, palette]);

  return (
    <section class="traces" aria-label="Channel traces">
      <div class="graph-head">
        <h2>Channels over time</h2>
        <span class="glitch-count" ref={count} data-testid="glitch-count" />
      </div>
      <ChannelPicker lanes={lanes} seen={seen.value} />
      <p class="muted trace-note" ref={note} />
      {lanes.length === 0 ? <p class="muted">No channel chosen: pick one above.</p> : null}
      <div class="trace-host" ref={host} />
      <p class="muted trace-key">
        <span class="glitch-mark" aria-hidden="true" /> glitch: a value {SPIKE_MIN_JUMP_PERCENT} % travel or more away that is back within{' '}
        {SPIKE_RETURN_PERCENT} % the next time (the health report's rule)
      </p>
    </section>
  );
}
