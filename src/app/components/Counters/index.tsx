/** Decoder and link counters, written once per animation frame when they change. */
import { useEffect, useRef } from 'preact/hooks';
import { onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { current } from '../../store.js';
import './style.css';

const ROWS = [
  ['frames', 'Frames'],
  ['bytes', 'Bytes'],
  ['resyncs', 'Resyncs'],
  ['discarded', 'Bytes discarded'],
  ['bad', 'Bad frames'],
  ['fades', 'Fades'],
  ['missed', 'Missed frames'],
  ['period', 'Frame period'],
  ['rssi', 'RSSI'],
] as const;

export function Counters() {
  const list = useRef<HTMLDListElement>(null);
  useEffect(() => {
    let version = -1;
    let shown: Live | undefined;
    return onFrame(() => {
      const live = current();
      if ((live === shown && live.version === version) || list.current === null) return;
      version = live.version;
      shown = live;
      const c = live.counters;
      const l = live.link;
      const values: Record<(typeof ROWS)[number][0], string> = {
        frames: String(c.frames),
        bytes: String(c.bytes),
        resyncs: String(c.resyncs),
        discarded: String(c.discardedBytes),
        bad: String(c.badFrames),
        fades: l === null ? '—' : `${l.fades} (${l.fadeRate.toFixed(1)}/s)`,
        missed: l === null ? '—' : String(l.missedFrames),
        period: l === null || !Number.isFinite(l.periodUs) ? '—' : `${(l.periodUs / 1000).toFixed(2)} ms`,
        rssi: l === null || !Number.isFinite(l.rssi) ? '—' : `${l.rssi} dBm`,
      };
      for (const dd of list.current.querySelectorAll<HTMLElement>('dd[data-key]')) {
        const v = values[dd.dataset.key as (typeof ROWS)[number][0]];
        if (dd.textContent !== v) dd.textContent = v;
      }
    });
  }, []);
  return (
    <section class="counters" aria-label="Counters">
      <dl ref={list}>
        {ROWS.map(([key, label]) => [<dt key={`${key}-t`}>{label}</dt>, <dd key={key} data-key={key} data-testid={`count-${key}`}>—</dd>])}
      </dl>
    </section>
  );
}
