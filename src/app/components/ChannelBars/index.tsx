/**
 * Channel bars: one meter per channel with its name, pulse width, raw position and % travel,
 * centre and ±100 % marks. The rows are rendered once; values are written straight to the DOM
 * once per animation frame when they change (no virtual DOM on the 91 Hz path). A channel that
 * stops arriving greys out and shows its age. A scale row names the marks (−100 %, 0, +100 %
 * at 1102, 1500 and 1898 µs). On a narrow screen the raw and % columns go first and the age
 * moves into the track, so the bar itself always keeps its room. Under them, folded, each
 * channel's min / max / last as `satscope info` prints them.
 */
import { useEffect, useRef } from 'preact/hooks';
import { channelName, channelResolution, PULSE_MAX_US, PULSE_MIN_US, servoToMicros, servoToPercent } from '../../../decoder/spec.js';
import { onFrame } from '../../frame-loop.js';
import { current } from '../../store.js';
import { setText } from '../../text.js';
import { ChannelRanges } from './ranges.js';
import './style.css';

/** A channel is stale when it has not come for this long (a few frame pairs). */
const STALE_US = 100_000;
const SPAN_US = PULSE_MAX_US - PULSE_MIN_US;
const left = (us: number) => `${(((us - PULSE_MIN_US) / SPAN_US) * 100).toFixed(3)}%`;
/**
 * The fill from `a` to `b` µs, as a clip of a fill that spans the whole track: a new clip is
 * only painted, where a new left and width would lay the bar out again at 91 Hz.
 */
const span = (a: number, b: number) =>
  `inset(0 ${(((PULSE_MAX_US - b) / SPAN_US) * 100).toFixed(3)}% 0 ${(((a - PULSE_MIN_US) / SPAN_US) * 100).toFixed(3)}% round 2px)`;
const EMPTY = 'inset(0 100% 0 0)';

interface Row {
  root: HTMLElement;
  fill: HTMLElement;
  us: HTMLElement;
  raw: HTMLElement;
  pct: HTMLElement;
  age: HTMLElement;
  shown: string;
  /** The row is a meter (its role and range set) rather than a "no data" image. */
  metered: boolean;
}

export function ChannelBars({ ids, label }: { ids: number[]; label: string }) {
  const list = useRef<HTMLDivElement>(null);
  useEffect(() => {
    const el = list.current;
    if (el === null) return undefined;
    const rows: Row[] = [...el.children].flatMap((root) => {
      const fill = root.querySelector<HTMLElement>('.fill');
      const us = root.querySelector<HTMLElement>('.us');
      const raw = root.querySelector<HTMLElement>('.raw');
      const pct = root.querySelector<HTMLElement>('.pct');
      const age = root.querySelector<HTMLElement>('.age');
      if (!(root instanceof HTMLElement) || fill === null || us === null || raw === null || pct === null || age === null) return [];
      return [{ root, fill, us, raw, pct, age, shown: '', metered: false }];
    });
    return onFrame(() => {
      const live = current();
      const now = live.nowUs();
      ids.forEach((id, i) => {
        const row = rows[i];
        if (row === undefined) return;
        const seen = live.seenUs[id] ?? Number.NaN;
        const resolution = channelResolution(id, live.resolution ?? 2048);
        const pos = live.positions[id] ?? 0;
        const never = Number.isNaN(seen);
        // Seen in data without times (+Infinity): shown, never stale.
        const age = seen === Infinity ? 0 : now - seen;
        const stale = never || age > STALE_US;
        // The key of what is on screen: redraw only when it changes.
        const ageText = never ? 'no data' : stale ? `stale ${(age / 1e6).toFixed(1)} s` : '';
        const key = `${pos}|${resolution}|${ageText}`;
        if (key === row.shown) return;
        row.shown = key;
        row.root.classList.toggle('stale', stale);
        row.root.classList.toggle('never', never);
        setText(row.age, ageText);
        if (never) {
          setText(row.us, '—');
          setText(row.raw, '');
          setText(row.pct, '');
          row.fill.style.clipPath = EMPTY;
          // A meter must have a value: a channel that never came is a labelled image until it does.
          row.root.setAttribute('role', 'img');
          row.root.setAttribute('aria-label', `${channelName(id)}: no data`);
          for (const a of ['aria-valuetext', 'aria-valuenow', 'aria-valuemin', 'aria-valuemax']) row.root.removeAttribute(a);
          row.metered = false;
          return;
        }
        const us = servoToMicros(pos, resolution);
        const pct = servoToPercent(pos, resolution);
        setText(row.us, `${us} µs`);
        setText(row.raw, String(pos));
        setText(row.pct, `${pct >= 0 ? '+' : '−'}${Math.abs(pct).toFixed(1)} %`);
        row.fill.style.clipPath = span(Math.min(us, 1500), Math.max(us, 1500));
        if (!row.metered) {
          // What does not change while the channel comes: set once, not on every frame.
          row.root.setAttribute('role', 'meter');
          row.root.setAttribute('aria-label', channelName(id));
          row.root.setAttribute('aria-valuemin', String(PULSE_MIN_US));
          row.root.setAttribute('aria-valuemax', String(PULSE_MAX_US));
          row.metered = true;
        }
        row.root.setAttribute('aria-valuenow', String(us));
        row.root.setAttribute('aria-valuetext', `${us} µs, ${pct.toFixed(0)} %${stale ? ', stale' : ''}`);
      });
    });
  }, [ids]);

  return (
    <section class="channels" aria-label={label}>
      {/* The scale: the same columns as a bar, labels only over the track. */}
      <div class="bar scale" aria-hidden="true">
        <span class="name" />
        <span class="id" />
        <div class="track-scale">
          <span style={{ left: left(1102) }}>−100 %</span>
          <span style={{ left: left(1500) }}>0</span>
          <span style={{ left: left(1898) }}>+100 %</span>
        </div>
        <span class="us" />
        <span class="raw" />
        <span class="pct" />
        <span class="age" />
      </div>
      <div class="channel-list" ref={list}>
        {ids.map((id) => (
          <div key={id} class="bar never" role="img" aria-label={`${channelName(id)}: no data`}>
            <span class="name">{channelName(id)}</span>
            <span class="id">{id}</span>
            <div class="track">
              <div class="mark" style={{ left: left(1102) }} />
              <div class="mark centre" style={{ left: left(1500) }} />
              <div class="mark" style={{ left: left(1898) }} />
              <div class="fill" />
            </div>
            <span class="us">—</span>
            <span class="raw" />
            <span class="pct" />
            <span class="age">no data</span>
          </div>
        ))}
      </div>
      <ChannelRanges ids={ids} />
    </section>
  );
}
