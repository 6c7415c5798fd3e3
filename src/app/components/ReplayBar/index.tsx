/**
 * Replay controls: play/pause, speed (1×, 4×, as fast as possible) and a timeline of the whole
 * capture (fades and lost frames per second, failsafe episodes) to seek on.
 */
import { useEffect, useRef, useState } from 'preact/hooks';
import uPlot from 'uplot';
import { overview, replay, send } from '../../store.js';
import { chartColors, theme } from '../../theme.js';
import './style.css';

const SPEEDS = [
  [1, '1×'],
  [4, '4×'],
  [0, 'max'],
] as const;

function clock(us: number): string {
  const s = Math.max(0, us / 1e6);
  return `${Math.floor(s / 60)}:${(s % 60).toFixed(1).padStart(4, '0')}`;
}

export function ReplayBar() {
  const r = replay.value;
  const chart = useRef<HTMLDivElement>(null);
  const [dragging, setDragging] = useState<number | null>(null);
  const o = overview.value;
  const palette = theme.value;
  useEffect(() => {
    const el = chart.current;
    if (el === null || o === null || o.t.length === 0) return undefined;
    const x = Array.from(o.t, (t) => t / 1e6);
    const bands = o.failsafe;
    const c = chartColors(palette);
    const plot = new uPlot(
      {
        width: Math.max(300, el.clientWidth),
        height: 56,
        legend: { show: false },
        cursor: { show: false },
        axes: [{ show: false }, { show: false }],
        scales: { x: { time: false } },
        series: [
          {},
          { stroke: c.lost, fill: `${c.lost}66`, paths: uPlot.paths.bars?.({ size: [1, Infinity] }), points: { show: false } },
          { stroke: c.fades, width: 1, points: { show: false } },
        ],
        hooks: {
          drawClear: [
            (u) => {
              // Failsafe episodes as red bands behind the series.
              const ctx = u.ctx;
              ctx.save();
              ctx.fillStyle = c.failsafeBand;
              for (const b of bands) {
                const a = u.valToPos(b.startUs / 1e6, 'x', true);
                const z = u.valToPos(b.endUs / 1e6, 'x', true);
                ctx.fillRect(a, u.bbox.top, Math.max(2, z - a), u.bbox.height);
              }
              ctx.restore();
            },
          ],
        },
      },
      [x, Array.from(o.lost), Array.from(o.fadeRate)],
      el,
    );
    return () => plot.destroy();
    // The overview can arrive before the replay status that makes this bar (and its box) appear.
  }, [o, r !== null, palette]);
  if (r === null) return null;
  const span = Math.max(1, r.endUs - r.startUs);
  return (
    <section class="replay" aria-label="Replay">
      <div class="replay-row">
        <strong class="name" title={r.name}>
          {r.name}
        </strong>
        <span class="muted">
          {r.kind}, timing {r.timing}
        </span>
        {r.playing ? (
          <button type="button" class="primary" onClick={() => send({ type: 'replay-pause' })}>
            Pause
          </button>
        ) : (
          <button
            type="button"
            class="primary"
            onClick={() => {
              // At the end, play starts over.
              if (r.positionUs >= r.endUs) send({ type: 'replay-seek', timeUs: r.startUs });
              send({ type: 'replay-play' });
            }}
          >
            Play
          </button>
        )}
        <div class="window" role="radiogroup" aria-label="Speed">
          {SPEEDS.map(([v, label]) => (
            <button
              key={label}
              type="button"
              role="radio"
              aria-checked={r.speed === v}
              class={r.speed === v ? 'on' : ''}
              onClick={() => send({ type: 'replay-speed', speed: v })}
            >
              {label}
            </button>
          ))}
        </div>
        <span class="time" data-testid="replay-time">
          {clock(r.positionUs - r.startUs)} / {clock(span)}
        </span>
      </div>
      <div class="overview" ref={chart} />
      <input
        type="range"
        class="seek"
        aria-label="Seek"
        min={r.startUs}
        max={r.endUs}
        step={Math.max(1, Math.round(span / 2000))}
        value={dragging ?? r.positionUs}
        // While the thumb is held, the position updates must not pull it back.
        onInput={(e) => setDragging(Number((e.currentTarget as HTMLInputElement).value))}
        onChange={(e) => {
          setDragging(null);
          send({ type: 'replay-seek', timeUs: Number((e.currentTarget as HTMLInputElement).value) });
        }}
      />
    </section>
  );
}
