/**
 * Decoder and link counters, written once per animation frame when they change. Each says what
 * it means on hover; the ones that point at a problem are marked when they are not zero. Empty
 * (0xFFFF) slots and VTX frames are listed once the worker reports them, and only where they
 * occur: most links have neither.
 */
import { useEffect, useRef } from 'preact/hooks';
import { onFrame } from '../../frame-loop.js';
import type { Live } from '../../live.js';
import { current } from '../../store.js';
import { fadesPerMinute, setText } from '../../text.js';
import './style.css';

type Key = 'frames' | 'bytes' | 'resyncs' | 'discarded' | 'bad' | 'empty' | 'vtx' | 'fades' | 'missed' | 'period' | 'rssi';

/** Key, label, what it means (and what to do), and whether a non-zero value is a warning. */
const ROWS: readonly (readonly [Key, string, string, boolean])[] = [
  ['frames', 'Frames', 'Frames decoded.', false],
  ['bytes', 'Bytes', 'Bytes read from the port or the capture.', false],
  [
    'resyncs',
    'Resyncs',
    'Times the decoder lost its place in the stream and found it again. Often: a loose DATA or ground wire, or the wrong baud rate.',
    true,
  ],
  ['discarded', 'Bytes discarded', 'Bytes that were not part of a frame: noise, or cut-off frames. Check the wiring and the ground.', true],
  ['bad', 'Bad frames', 'Frames with channel IDs that cannot be: noise on the line, or the wrong resolution forced in Settings.', true],
  [
    'empty',
    'Empty slots',
    'Slots sent as 0xFFFF: the transmitter has fewer channels than the frame has room for. Normal with 6- or 7-channel setups.',
    false,
  ],
  ['vtx', 'VTX frames', 'Frames carrying video-transmitter control instead of the last two channels (Spektrum VTX).', false],
  [
    'fades',
    'Fades',
    'Frames the receiver missed on the radio side (its own count), and their rate per minute now; a rising rate means a weak or blocked antenna.',
    false,
  ],
  ['missed', 'Missed frames', 'Frames that should have arrived on the serial line and did not.', true],
  ['period', 'Frame period', 'Time between frames as measured.', false],
  ['rssi', 'RSSI', 'Signal strength the receiver reports (SPM4649T).', false],
];

type Counts = Live['counters'];

export function Counters() {
  const list = useRef<HTMLDListElement>(null);
  useEffect(() => {
    const dl = list.current;
    if (dl === null) return undefined;
    // Each row's term and value, found once (the rows never change), with whether a non-zero value warns.
    const cells = ROWS.flatMap(([key, , , warns]) => {
      const dd = dl.querySelector<HTMLElement>(`:scope > dd[data-key="${key}"]`);
      const dt = dd?.previousElementSibling;
      return dd !== null && dt instanceof HTMLElement ? [{ key, warns, dd, dt }] : [];
    });
    let version = -1;
    let shown: Live | undefined;
    return onFrame(() => {
      const live = current();
      if (live === shown && live.version === version) return;
      version = live.version;
      shown = live;
      const c: Counts = live.counters;
      const l = live.link;
      const values: Record<Key, string | null> = {
        frames: String(c.frames),
        bytes: String(c.bytes),
        resyncs: String(c.resyncs),
        discarded: String(c.discardedBytes),
        bad: String(c.badFrames),
        // Shown only where they occur.
        empty: c.emptySlots ? String(c.emptySlots) : null,
        vtx: c.vtxFrames ? String(c.vtxFrames) : null,
        fades: l === null ? '—' : `${l.fades} (${fadesPerMinute(l.fadeRate)})`,
        missed: l === null ? '—' : String(l.missedFrames),
        period: l === null || !Number.isFinite(l.periodUs) ? '—' : `${(l.periodUs / 1000).toFixed(2)} ms`,
        rssi: l === null || !Number.isFinite(l.rssi) ? '—' : `${l.rssi} dBm`,
      };
      for (const { key, warns, dd, dt } of cells) {
        const v = values[key];
        const hidden = v === null;
        if (dd.hidden !== hidden) dd.hidden = dt.hidden = hidden;
        if (v !== null) setText(dd, v);
        const warn = warns && v !== null && /^[1-9]/.test(v);
        if (dd.classList.contains('warn') !== warn) dd.classList.toggle('warn', warn);
      }
    });
  }, []);
  return (
    <section class="counters" aria-label="Counters">
      <dl ref={list}>
        {ROWS.map(([key, label, help]) => [
          <dt key={`${key}-t`} title={help} hidden={key === 'empty' || key === 'vtx'}>
            {label}
          </dt>,
          <dd key={key} data-key={key} data-testid={`count-${key}`} title={help} hidden={key === 'empty' || key === 'vtx'}>
            —
          </dd>,
        ])}
      </dl>
      <details class="help">
        <summary>What these mean</summary>
        <dl>{ROWS.map(([key, label, help]) => [<dt key={`${key}-t`}>{label}</dt>, <dd key={key}>{help}</dd>])}</dl>
      </details>
    </section>
  );
}
