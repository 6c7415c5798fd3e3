/**
 * Several remotes side by side (spec §5, §7.3): one row per remote with its label (A, B, R, L),
 * failsafe state, fades and fade rate, frames, and below them every remote's fade rate and
 * hold/failsafe episodes on one time axis, so a user can see which antenna drops when. Clicking
 * a row, or its remote's button from the keyboard, shows that remote in the views below. The
 * table scrolls inside the panel on a narrow screen.
 */
import type { Signal } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import uPlot from 'uplot';
import { BUCKET_US, REMOTE_LABELS } from '../../../worker/protocol.js';
import { onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { allLives, select, selected, send, sources } from '../../store.js';
import { drawEpisodes } from '../../timeline.js';
import { agoAxis, hoverCursor, keyboardCursor, legendTime, legendValue, showNewest, valueAxis, valueScale } from '../../axes.js';
import { chartColors, theme } from '../../theme.js';
import './style.css';

/** The worker's graph buckets, in seconds of the source's clock (uPlot's x). */
const BUCKET_S = BUCKET_US / 1e6;
/** Fade rate in the chart: at least 0–1 /s, so an all-zero window still has labelled ticks. */
const FADE_SCALE = { floor: 1 };

function stateOf(live: Live | undefined): string {
  return live?.link?.state ?? 'waiting';
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
    const plot = new uPlot(
      {
        width: Math.max(200, box.clientWidth),
        height: 120,
        legend: { show: true, live: true },
        cursor: hoverCursor(),
        scales: { x: { time: false }, y: valueScale(FADE_SCALE) },
        axes: [agoAxis(), valueAxis('Fades /s', FADE_SCALE)],
        series: [
          { label: 'Time', value: legendTime },
          ...order.map((id, i) => ({
            label: list[i]?.label ?? String(id),
            stroke: colors[i % colors.length],
            width: 1.5,
            points: { show: false },
            value: legendValue('/s', 1),
          })),
        ],
      },
      [[], ...order.map(() => [])],
      box,
    );
    const keys = keyboardCursor(plot, box);
    const resize = new ResizeObserver(() => plot.setSize({ width: Math.max(200, box.clientWidth), height: 120 }));
    resize.observe(box);
    const x: number[] = [];
    const columns: (number | null)[][] = order.map(() => []);
    let drawnAt = 0;
    const stop = onFrame((nowMs) => {
      if (nowMs - drawnAt < 200) return;
      drawnAt = nowMs;
      const lives = allLives();
      // One x axis: the union of the remotes' bucket times (they share the clock and the grid).
      const first = lives.get(order[0] as number);
      if (first === undefined) return;
      const end = first.nowUs() / 1e6;
      if (!Number.isFinite(end)) return;
      const start = end - windowUs.value / 1e6;
      // The remotes' buckets share one 100 ms grid on one clock: the x axis is that grid, and
      // each column is filled in place (no union, no sort, no new arrays per redraw).
      const k0 = Math.ceil(start / BUCKET_S - 1e-6);
      const n = Math.max(0, Math.floor(end / BUCKET_S + 1e-6) - k0 + 1);
      x.length = n;
      for (let i = 0; i < n; i++) x[i] = (k0 + i) * BUCKET_S;
      order.forEach((id, r) => {
        const col = columns[r] as (number | null)[];
        col.length = n;
        col.fill(null);
        const s = lives.get(id)?.series;
        if (s === undefined) return;
        for (let i = s.indexAt(start); i < s.length; i++) {
          const k = Math.round((s.t[i] as number) / BUCKET_S) - k0;
          if (k >= 0 && k < n) col[k] = s.fadeRate[i] as number;
        }
      });
      plot.batch(() => {
        plot.setData([x, ...columns] as uPlot.AlignedData, false);
        plot.setScale('x', { min: start, max: end });
      });
      showNewest(plot, x.length);
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
    let shown = '';
    return onFrame(() => {
      const body = table.current;
      if (body === null) return;
      const lives = allLives();
      const text = list
        .map((s) => {
          const live = lives.get(s.id);
          const l = live?.link;
          return [
            stateOf(live),
            live?.counters.frames ?? 0,
            l?.fades ?? 0,
            l === null || l === undefined ? '—' : (l.fadeRate * 60).toFixed(0),
            l?.holds ?? 0,
            l?.failsafes ?? 0,
          ].join('|');
        })
        .join(';');
      if (text === shown) return;
      shown = text;
      list.forEach((s, i) => {
        const row = body.children[i];
        const live = lives.get(s.id);
        if (!(row instanceof HTMLElement)) return;
        const cells = row.querySelectorAll<HTMLElement>('[data-cell]');
        const l = live?.link;
        const values: Record<string, string> = {
          state: stateOf(live),
          frames: String(live?.counters.frames ?? 0),
          fades: String(l?.fades ?? 0),
          rate: l === null || l === undefined ? '—' : `${(l.fadeRate * 60).toFixed(0)}/min`,
          episodes: `${l?.holds ?? 0} / ${l?.failsafes ?? 0}`,
        };
        for (const c of cells) {
          const v = values[c.dataset.cell as string] ?? '';
          if (c.textContent !== v) c.textContent = v;
          if (c.dataset.cell === 'state') c.className = `state-chip ${v}`;
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
              <tr key={s.id} class={selected.value === s.id ? 'on' : ''} onClick={() => select(s.id)} data-testid={`remote-${s.label}`}>
                <td class="remote-cell">
                  <span class="swatch" aria-hidden="true" style={{ background: colors[i % colors.length] }} />
                  <select
                    aria-label={`Label of ${s.name}`}
                    value={s.label}
                    onClick={(e) => e.stopPropagation()}
                    onChange={(e) => send({ type: 'set-label', source: s.id, label: (e.currentTarget as HTMLSelectElement).value })}
                  >
                    {[...new Set([...REMOTE_LABELS, s.label])].map((l) => (
                      <option key={l} value={l}>
                        {l}
                      </option>
                    ))}
                  </select>
                  <span class="kind">{s.format.remote === 'internal' ? 'internal' : s.format.remote === 'external' ? 'external' : ''}</span>
                </td>
                <td>
                  <span data-cell="state" class="state-chip waiting">
                    waiting
                  </span>
                </td>
                <td data-cell="fades" class="num">
                  0
                </td>
                <td data-cell="rate" class="num">
                  —
                </td>
                <td data-cell="episodes" class="num">
                  0 / 0
                </td>
                <td data-cell="frames" class="num">
                  0
                </td>
                <td class="name">
                  {/* The row's keyboard way in: a real button, so Tab reaches it and Enter or Space shows the remote. */}
                  <button
                    type="button"
                    class="show"
                    aria-pressed={selected.value === s.id}
                    title={`Show remote ${s.label} in the views below`}
                    onClick={(e) => {
                      e.stopPropagation();
                      select(s.id);
                    }}
                  >
                    {s.name}
                  </button>
                </td>
                <td>
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
            <span class="lane-label" style={{ color: colors[i % colors.length] }}>
              {s.label}
            </span>
            <div class="lane-strip" />
          </div>
        ))}
      </div>
    </section>
  );
}
