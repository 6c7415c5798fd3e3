/**
 * Replay controls: play/pause, speed (1×, 4×, as fast as possible) and a timeline of the whole
 * capture (fades and lost frames per second, failsafe episodes) to seek on. While the worker is
 * still reading a long capture the timeline grows: the part not read yet is drawn as such (never
 * as a clean link), and a seek goes no further than what has been read.
 */
import { computed, useComputed, useSignal } from '@preact/signals';
import { useEffect, useRef } from 'preact/hooks';
import uPlot from 'uplot';
import { overview, replay, replayName, replayReading, replaySpanUs, send } from '../../store.js';
import { formatClock } from '../../../report/report-text.js';
import { elapsedAxis } from '../../axes.js';
import { chartColors, theme } from '../../theme.js';
import { overviewColumns } from './columns.js';
import { readingPercent } from './reading.js';
import { Choice } from '../Choice/index.js';
import './style.css';

/** The timeline's height, px: the plot and its time axis. */
const TIMELINE_PX = 78;
/** The narrowest a failsafe band is drawn, px: a short one is still seen. */
const MIN_MARK_PX = 2;

const SPEEDS = [
  [1, '1×'],
  [4, '4×'],
  [0, 'max'],
] as const;

// The replay status comes five times a second and mostly only its position moves: the bar
// renders from the parts that change rarely, and the clock text and the slider's position are
// signals bound straight to the DOM.
const playing = computed(() => replay.value?.playing ?? false);
const speed = computed(() => replay.value?.speed ?? 1);
const startUs = computed(() => replay.value?.startUs ?? 0);
const endUs = computed(() => replay.value?.endUs ?? 0);
const described = computed(() => (replay.value === null ? '' : `${replay.value.kind}, timing ${replay.value.timing}`));
/** While the capture is still being read: how far (µs, the capture's clock), else null. */
const readUntil = computed(() => {
  const o = overview.value;
  return o === null || o.complete || !Number.isFinite(o.readUntilUs) ? null : o.readUntilUs;
});
const readingText = computed(() => {
  const r = replay.value;
  const until = readUntil.value;
  if (r === null) return '';
  if (until !== null) return `Reading the capture: ${readingPercent(until, r.startUs, r.endUs)}`;
  // The overview is whole; the file is still being read into what plays and seeks.
  return r.reading ? 'Preparing playback…' : '';
});
const clockText = computed(() => {
  const r = replay.value;
  return r === null ? '' : `${formatClock(r.positionUs - r.startUs)} / ${formatClock(Math.max(1, r.endUs - r.startUs))}`;
});

export function ReplayBar() {
  const name = replayName.value;
  const chart = useRef<HTMLDivElement>(null);
  /** While the thumb is held: where it is (the position updates must not pull it back). */
  const dragging = useSignal<number | null>(null);
  const position = useComputed(() => dragging.value ?? replay.value?.positionUs ?? 0);
  const o = overview.value;
  const palette = theme.value;
  // The whole capture's span, so that a timeline still growing sits where it belongs.
  const fromS = startUs.value / 1e6;
  const toS = endUs.value / 1e6;
  useEffect(() => {
    const el = chart.current;
    if (el === null || o === null) return undefined;
    const width = Math.max(300, el.clientWidth);
    const spanned = toS > fromS;
    // A column a device pixel, over the capture's span (or, without one, the bins' own).
    const [from, to] = spanned ? [fromS, toS] : [(o.t[0] ?? 0) / 1e6, (o.t[o.t.length - 1] ?? 0) / 1e6 + o.binUs / 1e6];
    const columns = Math.ceil(width * (globalThis.devicePixelRatio || 1));
    const { x, lost, fadeRate } = overviewColumns(o, columns, from, to);
    const binS = o.binUs / 1e6;
    const columnS = (to - from) / columns;
    const bands = o.failsafe;
    const unread = o.complete || !Number.isFinite(o.readUntilUs) ? null : o.readUntilUs / 1e6;
    const c = chartColors(palette);
    const plot = new uPlot(
      {
        width,
        height: TIMELINE_PX,
        legend: { show: false },
        cursor: { show: false },
        // Time since the capture's start; the values need no axis (the graphs below have them).
        axes: [spanned ? elapsedAxis(from) : { show: false }, { show: false }],
        scales: {
          x: { time: false, range: () => [from, to] },
          lost: { range: (_u, _min, max) => [0, Math.max(1, max)] },
        },
        series: [
          {},
          // In the scale only: drawn below, each bar as wide as the time it counts.
          { scale: 'lost', paths: () => null, points: { show: false } },
          { stroke: c.fades, width: 1, points: { show: false } },
        ],
        hooks: {
          drawClear: [
            (u) => {
              const ctx = u.ctx;
              ctx.save();
              // Failsafe episodes as red bands behind the series, as long as they lasted (at
              // least MIN_MARK_PX, so that a short one is still seen).
              ctx.fillStyle = c.failsafeBand;
              for (const b of bands) {
                const a = u.valToPos(b.startUs / 1e6, 'x', true);
                const z = u.valToPos(b.endUs / 1e6, 'x', true);
                ctx.fillRect(a, u.bbox.top, Math.max(MIN_MARK_PX * devicePixelRatio, z - a), u.bbox.height);
              }
              // Lost frames: each column's bar spans the bins it counts (a bin, or a device pixel
              // where bins are narrower), never wider: a 66 ms hold is a 66 ms bar.
              ctx.fillStyle = `${c.lost}aa`;
              const base = u.valToPos(0, 'lost', true);
              for (let i = 0; i < x.length; i++) {
                const n = lost[i] ?? 0;
                if (!(n > 0)) continue;
                const t = x[i] ?? 0;
                const end = Math.min(t + Math.max(binS, columnS), x[i + 1] ?? to, to);
                const a = u.valToPos(t, 'x', true);
                const w = Math.max(devicePixelRatio, u.valToPos(end, 'x', true) - a);
                const top = u.valToPos(n, 'lost', true);
                ctx.fillRect(a, top, w, base - top);
              }
              // Each failsafe's extent also as a line along the top, seen over the lost frames' bars.
              ctx.fillStyle = c.lost;
              for (const b of bands) {
                const a = u.valToPos(b.startUs / 1e6, 'x', true);
                const z = u.valToPos(b.endUs / 1e6, 'x', true);
                ctx.fillRect(a, u.bbox.top, Math.max(MIN_MARK_PX * devicePixelRatio, z - a), 3 * devicePixelRatio);
              }
              if (unread !== null) {
                // Not read yet: hatched, so that it never reads as a clean stretch of link.
                const a = u.valToPos(unread, 'x', true);
                const z = u.bbox.left + u.bbox.width;
                ctx.beginPath();
                ctx.rect(a, u.bbox.top, z - a, u.bbox.height);
                ctx.clip();
                ctx.strokeStyle = c.axis;
                ctx.globalAlpha = 0.35;
                for (let h = a - u.bbox.height; h < z; h += 8) {
                  ctx.moveTo(h, u.bbox.top + u.bbox.height);
                  ctx.lineTo(h + u.bbox.height, u.bbox.top);
                }
                ctx.stroke();
              }
              ctx.restore();
            },
          ],
        },
      },
      [x, lost, fadeRate],
      el,
    );
    return () => plot.destroy();
    // The overview can arrive before the replay status that makes this bar (and its box) appear.
  }, [o, name !== null, palette, fromS, toS]);
  if (name === null) return null;
  const span = Math.max(1, replaySpanUs.value);
  return (
    <section class="replay" aria-label="Replay">
      <div class="replay-row">
        <strong class="name" title={name}>
          {name}
        </strong>
        <span class="muted">{described}</span>
        {playing.value ? (
          <button type="button" class="primary" onClick={() => send({ type: 'replay-pause' })}>
            Pause
          </button>
        ) : (
          <button
            type="button"
            class="primary"
            // It plays by itself once the file is read.
            disabled={replayReading.value}
            onClick={() => {
              // At the end, play starts over.
              const r = replay.peek();
              if (r !== null && r.positionUs >= r.endUs) send({ type: 'replay-seek', timeUs: r.startUs });
              send({ type: 'replay-play' });
            }}
          >
            Play
          </button>
        )}
        <Choice label="Speed" options={SPEEDS} value={speed.value} onChoose={(v) => send({ type: 'replay-speed', speed: v })} />
        <span class="muted" data-testid="replay-reading">
          {readingText}
        </span>
        <span class="time" data-testid="replay-time">
          {clockText}
        </span>
      </div>
      <div
        class="overview"
        ref={chart}
        data-complete={o === null ? undefined : String(o.complete)}
        title={readUntil.value === null ? undefined : 'Hatched: not read yet. Seeking goes as far as the capture has been read.'}
      />
      <p class="overview-key muted" aria-hidden="true">
        <span class="key lost" /> frames lost <span class="key fades" /> fades <span class="key failsafe" /> failsafe
      </p>
      <input
        type="range"
        class="seek"
        aria-label="Seek"
        min={startUs.value}
        max={endUs.value}
        step={Math.max(1, Math.round(span / 2000))}
        value={position}
        onInput={(e) => {
          dragging.value = Number(e.currentTarget.value);
        }}
        onChange={(e) => {
          dragging.value = null;
          // No further than the capture has been read: its counters and link state are known up to there.
          const until = readUntil.peek();
          const to = Number(e.currentTarget.value);
          send({ type: 'replay-seek', timeUs: until === null ? to : Math.min(to, until) });
        }}
      />
    </section>
  );
}
