/**
 * Several remotes side by side (spec §5, §7.3): one row per remote with its label (A, B, R, L),
 * failsafe state, fades and fade rate, frames, and below them every remote's fade rate and
 * hold/failsafe episodes on one time axis, so a user can see which antenna drops when. Clicking
 * a row, or its remote's button from the keyboard, shows that remote in the views below. The
 * table scrolls inside the panel on a narrow screen.
 */
import { type Signal, useComputed } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import { REMOTE_LABELS, type SourceStatus } from '../../../worker/protocol.js';
import { layeredChart } from '../../axes-layer.js';
import { chartTurn, onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { allLives, select, selected, send, sources, windowEnd } from '../../store.js';
import { setText } from '../../text.js';
import { drawEpisodes } from '../../timeline.js';
import { AlignedColumns } from './columns.js';
import { agoAxis, hoverCursor, keyboardCursor, legendTimeAt, legendValue, showNewest, valueAxis, valueScale } from '../../axes.js';
import { chartColors, theme } from '../../theme.js';
import './style.css';

/** Fade rate in the chart: at least 0–1 /s, so an all-zero window still has labelled ticks. */
const FADE_SCALE = { floor: 1 };

function stateOf(live: Live | undefined): string {
  return live?.link?.state ?? 'waiting';
}

/**
 * One remote's row. Whether it is the one shown below is a signal bound to the row's class and
 * its button's aria-pressed, so choosing another remote touches two attributes per row and
 * re-renders nothing.
 */
function RemoteRow({ source: s, color }: { source: SourceStatus; color: string }) {
  const shown = useComputed(() => selected.value === s.id);
  const rowClass = useComputed(() => (shown.value ? 'on' : ''));
  return (
    <tr class={rowClass} onClick={() => select(s.id)} data-testid={`remote-${s.label}`}>
      <td class="remote-cell">
        <span class="swatch" aria-hidden="true" style={{ background: color }} />
        <select
          aria-label={`Label of ${s.name}`}
          value={s.label}
          onClick={(e) => e.stopPropagation()}
          onChange={(e) => send({ type: 'set-label', source: s.id, label: e.currentTarget.value })}
        >
          {[...new Set([...REMOTE_LABELS, s.label])].map((l) => (
            <option key={l} value={l}>
              {l}
            </option>
          ))}
        </select>
        <span class="kind">{s.format.remote === 'internal' ? 'internal' : s.format.remote === 'external' ? 'external' : ''}</span>
      </td>
      <td class="state-cell">
        <span data-cell="state" class="state-chip waiting">
          waiting
        </span>
      </td>
      <td data-cell="fades" data-label="Fades" class="num">
        0
      </td>
      <td data-cell="rate" data-label="Fade rate" class="num">
        —
      </td>
      <td data-cell="episodes" data-label="Holds / failsafes" class="num">
        0 / 0
      </td>
      <td data-cell="frames" data-label="Frames" class="num">
        0
      </td>
      <td class="name">
        {/* The row's keyboard way in: a real button, so Tab reaches it and Enter or Space shows the remote. */}
        <button
          type="button"
          class="show"
          aria-pressed={shown}
          title={`Show remote ${s.label} in the views below`}
          onClick={(e) => {
            e.stopPropagation();
            select(s.id);
          }}
        >
          {s.name}
        </button>
      </td>
      <td class="action-cell">
        {s.kind === 'serial' ? (
          <button
            type="button"
            class="link"
            onClick={(e) => {
              e.stopPropagation();
              send({ type: 'serial-close', source: s.id });
            }}
          >
            Disconnect
          </button>
        ) : null}
      </td>
    </tr>
  );
}

export function Remotes({ windowUs }: { windowUs: Signal<number> }) {
  const list = sources.value;
  const table = useRef<HTMLTableSectionElement>(null);
  const chart = useRef<HTMLDivElement>(null);
  const lanes = useRef<HTMLDivElement>(null);
  const ids = list.map((s) => s.id).join(',');
  const palette = theme.value;
  const colors = chartColors(palette).remotes;

  useEffect(() => {
    const box = chart.current;
    if (box === null || list.length < 2) return undefined;
    const order = list.map((s) => s.id);
    const plot = layeredChart(
      () => ({
        width: Math.max(200, box.clientWidth),
        height: 120,
        legend: { show: true, live: true },
        cursor: hoverCursor(),
        scales: { x: { time: false }, y: valueScale(FADE_SCALE) },
        axes: [agoAxis(windowEnd), valueAxis('Fades /s', FADE_SCALE)],
        series: [
          { label: 'Time', value: legendTimeAt(windowEnd) },
          ...order.map((id, i) => ({
            label: list[i]?.label ?? String(id),
            stroke: colors[i % colors.length],
            width: 1.5,
            points: { show: false },
            value: legendValue('/s', 1),
          })),
        ],
      }),
      [[], ...order.map(() => [])],
      box,
    );
    const keys = keyboardCursor(plot, box);
    const resize = new ResizeObserver(() => plot.setSize({ width: Math.max(200, box.clientWidth), height: 120 }));
    resize.observe(box);
    const aligned = new AlignedColumns(order.length);
    let drawnAt = 0;
    const stop = onFrame((nowMs) => {
      // Not in the same frame as the graphs' redraw.
      if (nowMs - drawnAt < 200 || !chartTurn()) return;
      drawnAt = nowMs;
      const lives = allLives();
      const first = order[0] === undefined ? undefined : lives.get(order[0]);
      if (first === undefined) return;
      const end = first.nowUs() / 1e6;
      if (!Number.isFinite(end)) return;
      const start = end - windowUs.value / 1e6;
      aligned.update(order.map((id) => lives.get(id)?.series));
      // The whole grid: uPlot draws the part its x scale shows.
      plot.batch(() => {
        plot.setData([aligned.x, ...aligned.columns], false);
        plot.setScale('x', { min: start, max: end });
      });
      showNewest(plot, aligned.x.length);
      // Episode lanes, one per remote, on the same window.
      const el = lanes.current;
      if (el === null) return;
      order.forEach((id, i) => {
        const lane = el.children[i]?.querySelector('.lane-strip');
        const live = lives.get(id);
        if (!(lane instanceof HTMLElement) || live === undefined) return;
        drawEpisodes(lane, live.episodes.values(), live.nowUs(), windowUs.value);
      });
    });
    return () => {
      stop();
      resize.disconnect();
      keys();
      plot.destroy();
    };
  }, [ids, windowUs, palette]);

  useEffect(() => {
    // What each row shows, by the remote's data it was written from: a row is rewritten only
    // when its remote has a new batch (or is a new source on that id).
    const shown = list.map(() => ({ live: undefined as Live | undefined, version: -1 }));
    return onFrame(() => {
      const body = table.current;
      if (body === null) return;
      const lives = allLives();
      list.forEach((s, i) => {
        const live = lives.get(s.id);
        const last = shown[i];
        const row = body.children[i];
        if (last === undefined || !(row instanceof HTMLElement)) return;
        if (last.live === live && last.version === (live?.version ?? -1)) return;
        last.live = live;
        last.version = live?.version ?? -1;
        const l = live?.link;
        const values: Record<string, string> = {
          state: stateOf(live),
          frames: String(live?.counters.frames ?? 0),
          fades: String(l?.fades ?? 0),
          rate: l === null || l === undefined ? '—' : `${(l.fadeRate * 60).toFixed(0)}/min`,
          episodes: `${l?.holds ?? 0} / ${l?.failsafes ?? 0}`,
        };
        for (const c of row.querySelectorAll<HTMLElement>('[data-cell]')) {
          const v = values[c.dataset.cell ?? ''] ?? '';
          setText(c, v);
          if (c.dataset.cell === 'state' && c.className !== `state-chip ${v}`) c.className = `state-chip ${v}`;
        }
      });
    });
  }, [ids]);

  if (list.length < 2) return null;
  return (
    <section class="remotes" aria-label="Remotes">
      <h2>Remotes side by side</h2>
      <div class="table-scroll" tabIndex={0} role="region" aria-label="Remotes table">
        <table class="remote-table">
          <thead>
            <tr>
              <th>Remote</th>
              <th>State</th>
              <th>Fades</th>
              <th>Fade rate</th>
              <th>Holds / failsafes</th>
              <th>Frames</th>
              <th>Source</th>
              <th>
                <span class="sr-only">Actions</span>
              </th>
            </tr>
          </thead>
          <tbody ref={table}>
            {list.map((s, i) => (
              <RemoteRow key={s.id} source={s} color={colors[i % colors.length] ?? ''} />
            ))}
          </tbody>
        </table>
      </div>
      <div
        class="remote-chart"
        ref={chart}
        role="figure"
        aria-label="Fade rate of every remote over time: hover, or the arrow keys, for the values"
      />
      <div class="lanes" ref={lanes} role="group" aria-label="Hold and failsafe episodes per remote">
        {list.map((s, i) => (
          <div key={s.id} class="lane">
            <span class="lane-label" style={{ color: colors[i % colors.length] }} title={s.label}>
              {s.label}
            </span>
            <div class="lane-strip" />
          </div>
        ))}
      </div>
    </section>
  );
}
