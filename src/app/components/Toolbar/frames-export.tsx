/**
 * The Report menu's export of decoded frames: the selected remote's frames as CSV or JSONL,
 * the file `satscope decode` writes, of the whole capture or of a span of it (seconds from its
 * start; a live session exports its recording whole).
 */
import { useState } from 'preact/hooks';
import { replay, send, status } from '../../store.js';

/** A span bound typed by the user: seconds from the capture's start, or null (empty: the start or the end). */
function seconds(text: string): number | null | 'bad' {
  if (text.trim() === '') return null;
  const v = Number(text);
  return Number.isFinite(v) && v >= 0 ? v : 'bad';
}

export function FramesExport({ close }: { close(): void }) {
  const [from, setFrom] = useState('');
  const [to, setTo] = useState('');
  const r = replay.value;
  const s = status.value;
  const timed = r?.recordedTiming === true;
  const a = timed ? seconds(from) : null;
  const b = timed ? seconds(to) : null;
  const bad = a === 'bad' || b === 'bad' || (a !== null && b !== null && b < a);
  const go = (format: 'csv' | 'jsonl') => {
    if (bad || s.id < 0) return;
    const start = r?.startUs ?? 0;
    send({
      type: 'export-frames',
      source: s.id,
      format,
      fromUs: a === null ? null : start + a * 1e6,
      toUs: b === null ? null : start + b * 1e6,
    });
    close();
  };
  return (
    <fieldset class="frames-export">
      <legend>Decoded frames of remote {s.label || '—'}</legend>
      {timed ? (
        <div class="span">
          <label>
            from
            <input
              type="text"
              inputMode="decimal"
              placeholder="start"
              value={from}
              onInput={(e) => setFrom(e.currentTarget.value)}
              size={6}
            />
          </label>
          <label>
            to
            <input type="text" inputMode="decimal" placeholder="end" value={to} onInput={(e) => setTo(e.currentTarget.value)} size={6} />s
          </label>
        </div>
      ) : null}
      {bad ? (
        <p class="hint bad" role="alert">
          The span is seconds from the capture's start, the end after the start.
        </p>
      ) : null}
      <div class="formats">
        <button type="button" disabled={bad || s.id < 0} onClick={() => go('csv')}>
          Frames as CSV
        </button>
        <button type="button" disabled={bad || s.id < 0} onClick={() => go('jsonl')}>
          Frames as JSONL
        </button>
      </div>
      <p class="hint">As satscope decode writes them{timed ? '; empty: from the start, to the end.' : ': the whole recording.'}</p>
    </fieldset>
  );
}
