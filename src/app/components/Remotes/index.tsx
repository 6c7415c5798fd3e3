/**
 * Several remotes side by side (spec §5, §7.3): one row per remote with its label (A, B, R, L),
 * failsafe state, frames, fades and fade rate, and below them every remote's fade rate and
 * hold/failsafe episodes on one time axis, so a user can see which antenna drops when. Clicking
 * a row shows that remote in the views below.
 */
import type { Signal } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import uPlot from 'uplot';
import { REMOTE_LABELS } from '../../../worker/protocol.js';
import { onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { allLives, select, selected, send, sources } from '../../store.js';
import { drawEpisodes, SECONDS_BEFORE_NOW_AXIS, valueAxis } from '../../timeline.js';
import './style.css';

const COLORS = ['#4fd1a5', '#f0b429', '#7cc4ff', '#ff8fab', '#c3a6ff'];

function stateOf(live: Live | undefined): string {
  return live?.link?.state ?? 'waiting';
}

export function Remotes({ windowUs }: { windowUs: Signal<number> }) {
  const list = sources.value;
  const table = useRef<HTMLTableSectionElement>(null);
  const chart = useRef<HTMLDivElement>(null);
  const lanes = useRef<HTMLDivElement>(null);
  const ids = list.map((s) => s.id).join(',');

  useEffect(() => {
    const box = chart.current;
    if (box === null || list.length < 2) return undefined;
    const order = list.map((s) => s.id);
    const plot = new uPlot({
      width: Math.max(300, box.clientWidth),
      height: 110,
      legend: { show: false },
      cursor: { drag: { x: false, y: false } },
      scales: { x: { time: false }, y: { range: (_u, _min, max) => [0, Math.max(1, max * 1.15)] } },
      axes: [
        SECONDS_BEFORE_NOW_AXIS,
        valueAxis('Fades /s'),
      ],
      series: [{}, ...order.map((id, i) => ({ label: list[i]?.label ?? String(id), stroke: COLORS[i % COLORS.length], width: 1.5, points: { show: false } }))],
    }, [[], ...order.map(() => [])], box);
    const resize = new ResizeObserver(() => plot.setSize({ width: Math.max(300, box.clientWidth), height: 110 }));
    resize.observe(box);
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
      const times = new Set<number>();
      for (const id of order) {
        const s = lives.get(id)?.series;
        if (s !== undefined) for (let i = s.indexAt(start); i < s.length; i++) times.add(s.t[i] as number);
      }
      const x = Float64Array.from([...times].sort((a, b) => a - b));
      const columns = order.map((id) => {
        const s = lives.get(id)?.series;
        const col = new Array<number | null>(x.length).fill(null);
        if (s === undefined) return col;
        let j = 0;
        for (let i = s.indexAt(start); i < s.length; i++) {
          const t = s.t[i] as number;
          while (j < x.length && (x[j] as number) < t) j++;
          if (x[j] === t) col[j] = s.fadeRate[i] as number;
        }
        return col;
      });
      plot.batch(() => {
        plot.setData([x as unknown as number[], ...columns] as uPlot.AlignedData, false);
        plot.setScale('x', { min: start, max: end });
      });
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
      plot.destroy();
    };
  }, [ids, windowUs]);

  useEffect(() => {
    let shown = '';
    return onFrame(() => {
      const body = table.current;
      if (body === null) return;
      const lives = allLives();
      const text = list.map((s) => {
        const live = lives.get(s.id);
        const l = live?.link;
        return [stateOf(live), live?.counters.frames ?? 0, l?.fades ?? 0, l === null || l === undefined ? '—' : (l.fadeRate * 60).toFixed(0), l?.holds ?? 0, l?.failsafes ?? 0].join('|');
      }).join(';');
      if (text === shown) return;
      shown = text;
      list.forEach((s, i) => {
        const row = body.children[i];
        const live = lives.get(s.id);
        if (!(row instanceof HTMLElement)) return;
        const cells = row.querySelectorAll<HTMLElement>('[data-cell]');
        const l = live?.link;
        const values: Record<string, string> = {
          state: stateOf(live), frames: String(live?.counters.frames ?? 0), fades: String(l?.fades ?? 0),
          rate: l === null || l === undefined ? '—' : `${(l.fadeRate * 60).toFixed(0)}/min`, episodes: `${l?.holds ?? 0} / ${l?.failsafes ?? 0}`,
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
      <table>
        <thead>
          <tr><th>Remote</th><th>Source</th><th>State</th><th>Frames</th><th>Fades</th><th>Fade rate</th><th>Holds / failsafes</th><th /></tr>
        </thead>
        <tbody ref={table}>
          {list.map((s, i) => (
            <tr key={s.id} class={selected.value === s.id ? 'on' : ''} onClick={() => select(s.id)} data-testid={`remote-${s.label}`}>
              <td>
                <span class="swatch" style={{ background: COLORS[i % COLORS.length] }} />
                <select aria-label={`Label of ${s.name}`} value={s.label} onClick={(e) => e.stopPropagation()} onChange={(e) => send({ type: 'set-label', source: s.id, label: (e.currentTarget as HTMLSelectElement).value })}>
                  {[...new Set([...REMOTE_LABELS, s.label])].map((l) => <option key={l} value={l}>{l}</option>)}
                </select>
                <span class="kind">{s.format.remote === 'internal' ? 'internal' : s.format.remote === 'external' ? 'external' : ''}</span>
              </td>
              <td class="name" title={s.name}>{s.name}</td>
              <td><span data-cell="state" class="state-chip waiting">waiting</span></td>
              <td data-cell="frames" class="num">0</td>
              <td data-cell="fades" class="num">0</td>
              <td data-cell="rate" class="num">—</td>
              <td data-cell="episodes" class="num">0 / 0</td>
              <td>{s.kind === 'serial' ? <button type="button" class="link" onClick={(e) => { e.stopPropagation(); send({ type: 'serial-close', source: s.id }); }}>Disconnect</button> : null}</td>
            </tr>
          ))}
        </tbody>
      </table>
      <div class="remote-chart" ref={chart} role="img" aria-label="Fade rate of every remote over time" />
      <div class="lanes" ref={lanes} aria-label="Hold and failsafe episodes per remote">
        {list.map((s, i) => (
          <div key={s.id} class="lane">
            <span class="lane-label" style={{ color: COLORS[i % COLORS.length] }}>{s.label}</span>
            <div class="lane-strip" />
          </div>
        ))}
      </div>
    </section>
  );
}
