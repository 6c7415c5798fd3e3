/**
 * Frame inspector: the recent stream as the decoder saw it, one row per frame or event. Each
 * frame's 16 bytes are printed in hex, grouped by field and coloured by kind, with a tag under
 * each group and a tooltip saying what it decodes to, and the whole frame decoded beside it.
 * Discarded bytes, resyncs, locks and format changes appear inline at their stream offsets.
 * Meant for someone comparing their own firmware decoder byte by byte.
 *
 * The entries arrive as snapshots (the parent asks the worker); nothing here runs per Spektrum
 * frame. Rows are keyed by stream offset and skip re-rendering when their entry is unchanged,
 * so a refresh while following only draws the new rows; rows out of view are not laid out.
 */
import { Component } from 'preact';
import { useEffect, useLayoutEffect, useRef } from 'preact/hooks';
import type { InspectEntry } from '../../../worker/inspector.js';
import { countSlots, describeFrame } from '../../inspect.js';
import './style.css';

const REASONS: Record<string, string> = {
  'before-lock': 'before lock',
  noise: 'noise',
  'truncated-frame': 'truncated frame',
  'end-of-stream': 'end of stream',
};

/** A user's scroll that leaves the list this far from the bottom pauses following. */
const AWAY_PX = 32;

const time = (us: number) => (Number.isFinite(us) ? (us / 1e6).toFixed(3) : '—');

function hex(bytes: Uint8Array, from = 0, to = bytes.length): string {
  return Array.from(bytes.subarray(from, to), (b) => b.toString(16).toUpperCase().padStart(2, '0')).join(' ');
}

function FrameCells({ e }: { e: InspectEntry }) {
  if (e.bytes === null || e.bytes.length < 16) {
    return (
      <span role="cell" class="wide gone">
        bytes no longer held (older than the raw buffer)
      </span>
    );
  }
  const d = describeFrame(e.bytes, e.resolution ?? 2048, e.remote ?? 'internal', e.headerMode ?? 'fades');
  const b = e.bytes;
  // One element per byte group: its tag is drawn by CSS from data-tag (a third of the elements
  // of a hex span plus a tag span, which matters at a thousand rows).
  return (
    <>
      <span role="cell" class="hexcell hexw">
        {d.header.map((h) => (
          <span key={h.first} class={`g k-header${h.valid ? '' : ' k-invalid'}`} title={h.title} data-tag={h.label}>
            {hex(b, h.first, h.last + 1)}
          </span>
        ))}
        {d.slots.map((s) => (
          <span key={s.first} class={`g k-${s.kind}`} title={s.title} data-tag={s.label}>
            {hex(b, s.first, s.last + 1)}
          </span>
        ))}
      </span>
      {/* One item per value, each unbreakable: a line breaks between values, never inside one. */}
      <span role="cell" class="summary">
        {d.parts.map((p, i) => (
          <span key={i} class="v">
            {p}
          </span>
        ))}
      </span>
    </>
  );
}

function EventCells({ e }: { e: InspectEntry }) {
  switch (e.kind) {
    case 'discarded':
      return (
        <span role="cell" class="wide">
          <strong>
            discarded {e.length} byte{e.length === 1 ? '' : 's'}
          </strong>{' '}
          ({REASONS[e.reason ?? ''] ?? e.reason})
          {e.bytes !== null ? (
            <span class="raw">
              {hex(e.bytes)}
              {e.truncated ? ` … (first ${e.bytes.length} shown)` : ''}
            </span>
          ) : (
            <span class="gone"> bytes no longer held</span>
          )}
        </span>
      );
    case 'resync':
      return (
        <span role="cell" class="wide">
          <strong>resync</strong>: frames continue here (the bytes before did not fit the stream)
        </span>
      );
    case 'locked':
      return (
        <span role="cell" class="wide">
          <strong>locked on</strong>: {e.text ?? ''}
        </span>
      );
    default:
      return (
        <span role="cell" class="wide">
          <strong>format changed</strong>: {e.text ?? ''}
        </span>
      );
  }
}

const ROW_CLASS: Record<InspectEntry['kind'], string> = {
  frame: 'frame',
  discarded: 'discard',
  resync: 'resync',
  locked: 'info',
  'format-changed': 'info',
};

/** Whether two byte copies hold the same bytes (a frame's 16, a discard's first 256 at most). */
function sameBytes(a: Uint8Array | null, b: Uint8Array | null): boolean {
  if (a === null || b === null) return a === b;
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) return false;
  return true;
}

/**
 * One row. A snapshot's entries are new objects each time, but an entry at a given key rarely
 * changes (a discard that grew, bytes that expired, another remote's stream at the same
 * offset): the row redraws only then.
 */
class Row extends Component<{ e: InspectEntry }> {
  override shouldComponentUpdate(next: { e: InspectEntry }): boolean {
    const a = this.props.e;
    const b = next.e;
    return (
      a.kind !== b.kind ||
      a.offset !== b.offset ||
      a.length !== b.length ||
      !Object.is(a.timeUs, b.timeUs) ||
      a.resolution !== b.resolution ||
      a.remote !== b.remote ||
      a.headerMode !== b.headerMode ||
      a.text !== b.text ||
      !sameBytes(a.bytes, b.bytes)
    );
  }

  override render() {
    const { e } = this.props;
    return (
      <div role="row" class={`row ${ROW_CLASS[e.kind]}`}>
        <span role="cell" class="num">
          {time(e.timeUs)}
        </span>
        <span role="cell" class="num">
          {e.offset}
        </span>
        {e.kind === 'frame' ? <FrameCells e={e} /> : <EventCells e={e} />}
      </div>
    );
  }
}

const LEGEND: [string, string][] = [
  ['k-header', 'header (fades / RSSI, system)'],
  ['k-channel', 'channel'],
  ['k-xplus', 'X-Plus'],
  ['k-empty', 'empty 0xFFFF'],
  ['k-vtx', 'VTX'],
  ['k-invalid', 'invalid'],
  ['l-discard', 'discarded bytes'],
  ['l-resync', 'resync'],
  ['l-info', 'lock / format'],
];

export function Inspector({
  entries,
  onRefresh,
  following,
  onFollow,
}: {
  entries: InspectEntry[] | null;
  onRefresh(): void;
  following: boolean;
  onFollow(on: boolean): void;
}) {
  const scroller = useRef<HTMLDivElement>(null);
  /** When the user last wheeled, touched, clicked or keyed in the list (ms). */
  const intent = useRef(-Infinity);
  const follow = useRef({ following, onFollow });
  follow.current = { following, onFollow };

  useLayoutEffect(() => {
    const el = scroller.current;
    if (!following || el === null) return undefined;
    el.scrollTop = el.scrollHeight;
    // Rows out of view are laid out at an estimated height until they come into view: once the
    // newest rows have been drawn at their real height, pin to the bottom again.
    const id = requestAnimationFrame(() => {
      el.scrollTop = el.scrollHeight;
    });
    return () => cancelAnimationFrame(id);
  }, [entries, following]);

  useEffect(() => {
    const el = scroller.current;
    if (el === null) return undefined;
    // Scrolling away from the bottom pauses following, so rows stop moving under the reader;
    // only a scroll the user made, not one from rows coming, going or resizing.
    const mark = () => {
      intent.current = performance.now();
    };
    const scroll = () => {
      const { following: on, onFollow: set } = follow.current;
      if (on && performance.now() - intent.current < 1000 && el.scrollHeight - el.scrollTop - el.clientHeight > AWAY_PX) set(false);
    };
    const events = ['wheel', 'touchmove', 'keydown', 'pointerdown'] as const;
    for (const type of events) el.addEventListener(type, mark, { passive: true });
    el.addEventListener('scroll', scroll, { passive: true });
    return () => {
      for (const type of events) el.removeEventListener(type, mark);
      el.removeEventListener('scroll', scroll);
    };
  }, []);

  // What the snapshot holds: empty slots and VTX frames are easy to miss in a thousand rows.
  let frames = 0;
  let emptySlots = 0;
  let emptyFrames = 0;
  let vtxFrames = 0;
  for (const e of entries ?? []) {
    if (e.kind !== 'frame' || e.bytes === null) continue;
    frames++;
    const c = countSlots(e.bytes);
    emptySlots += c.empty;
    if (c.empty > 0) emptyFrames++;
    if (c.vtx) vtxFrames++;
  }

  let prev = '';
  let dup = 0;
  const rows = entries?.map((e) => {
    // Two entries of one kind at one offset are rare (but possible): keep keys unique.
    let key = `${e.offset}${e.kind}`;
    if (key === prev) key += `#${++dup}`;
    else {
      prev = key;
      dup = 0;
    }
    return <Row key={key} e={e} />;
  });

  return (
    <section class="inspector" aria-label="Frame inspector">
      <div class="insp-head">
        <h2>Frame inspector</h2>
        <span class="insp-state" aria-live="polite">
          {following ? 'Following: newest at the bottom' : 'Paused: scroll through the rows; Refresh to update'}
        </span>
        <div class="insp-actions">
          <button type="button" class={following ? 'on' : ''} aria-pressed={following} onClick={() => onFollow(!following)}>
            Follow
          </button>
          <button type="button" onClick={onRefresh}>
            Refresh
          </button>
        </div>
      </div>
      {frames > 0 ? (
        <p class="insp-counts" data-testid="inspector-counts">
          {frames} frame{frames === 1 ? '' : 's'} shown
          {emptySlots > 0 ? (
            <>
              {' '}
              ·{' '}
              <span class="k-empty-text">
                {emptySlots} empty slot{emptySlots === 1 ? '' : 's'} (0xFFFF) in {emptyFrames} frame{emptyFrames === 1 ? '' : 's'}
              </span>
            </>
          ) : (
            ' · no empty slots'
          )}
          {vtxFrames > 0 ? (
            <>
              {' '}
              ·{' '}
              <span class="k-vtx-text">
                {vtxFrames} VTX frame{vtxFrames === 1 ? '' : 's'}
              </span>
            </>
          ) : null}
        </p>
      ) : null}
      <ul class="insp-legend" aria-label="Colour key">
        {LEGEND.map(([cls, label]) => (
          <li key={cls}>
            <span class={`swatch ${cls}`} aria-hidden="true" />
            {label}
          </li>
        ))}
        <li class="muted">tag “p”: phase bit set · hover a byte group for its decode</li>
      </ul>
      <div class="insp-scroll" ref={scroller} tabIndex={0} role="region" aria-label="Recent frames and decoder events">
        {entries === null ? (
          <p class="insp-empty">No snapshot yet: press Refresh.</p>
        ) : entries.length === 0 ? (
          <p class="insp-empty">Nothing received yet.</p>
        ) : (
          <div role="table" class="insp-table" aria-label="Frames and decoder events, oldest first">
            <div role="rowgroup" class="insp-thead">
              <div role="row" class="row">
                <span role="columnheader" class="num">
                  Time (s)
                </span>
                <span role="columnheader" class="num">
                  Offset
                </span>
                <span role="columnheader" class="hexw">
                  <span class="label">Bytes</span>
                </span>
                <span role="columnheader">Decoded</span>
              </div>
            </div>
            <div role="rowgroup" class="insp-body">
              {rows}
            </div>
          </div>
        )}
      </div>
    </section>
  );
}
