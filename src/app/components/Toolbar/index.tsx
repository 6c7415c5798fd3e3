/**
 * Sources and recording: connect a receiver (WebSerial picker, or a port granted before), the
 * demo, open a capture, record, export, and the resolution override.
 */
import { useEffect, useRef, useState } from 'preact/hooks';
import { identify, pickPort, portLabel, serialUnavailable, USB_SERIAL_FILTERS } from '../../serial.js';
import type { SourceStatus } from '../../../worker/protocol.js';
import { notify, recording, replay, resolutionOverride, send, sources } from '../../store.js';
import { openCapture } from '../../open-file.js';
import './style.css';

async function connect(port: SerialPort): Promise<void> {
  send({ type: 'serial-open', port: await identify(port) });
}

async function choose(filtered: boolean): Promise<void> {
  const missing = serialUnavailable();
  if (missing !== null) {
    notify('error', missing.title, missing.detail);
    return;
  }
  const picked = await pickPort(filtered ? USB_SERIAL_FILTERS : []);
  if ('problem' in picked) notify('warning', picked.problem.title, picked.problem.detail);
  else await connect(picked);
}

function size(bytes: number): string {
  return bytes < 1024 ? `${bytes} B` : bytes < 1 << 20 ? `${(bytes / 1024).toFixed(1)} kB` : `${(bytes / (1 << 20)).toFixed(2)} MB`;
}

function duration(us: number): string {
  const s = Math.floor(us / 1e6);
  return `${Math.floor(s / 60)}:${String(s % 60).padStart(2, '0')}`;
}

/** One line for the status pill: what feeds the page now. */
function summary(list: SourceStatus[]): { text: string; tone: string } {
  const first = list[0];
  if (first === undefined) return { text: 'No receiver', tone: 'idle' };
  if (first.kind === 'demo') return { text: `Demo receiver: ${list.length} simulated remotes (DSMX 11 ms)`, tone: 'demo' };
  if (first.kind === 'replay') {
    const r = replay.value;
    const state = first.state === 'ended' ? ' (end)' : first.state === 'paused' ? ' (paused)' : '';
    return { text: `${r?.name ?? 'Replay'}${state}`, tone: 'replay' };
  }
  const lost = list.some((s) => s.state === 'lost');
  const opening = list.some((s) => s.state === 'opening');
  const text = list.map((s) => `${s.label}: ${s.name}${s.state === 'lost' ? ': device lost' : s.state === 'opening' ? ': opening…' : ''}`).join(' · ');
  return { text, tone: lost ? 'serial lost' : opening ? 'serial opening' : 'serial reading' };
}

export function Toolbar({ granted, onBind }: { granted: SerialPort[]; onBind(): void }) {
  const file = useRef<HTMLInputElement>(null);
  const [exported, setExported] = useState(false);
  const list = sources.value;
  const kind = list[0]?.kind;
  const rec = recording.value;
  const live = kind === 'serial' || kind === 'demo';
  const pill = summary(list);
  // A report covers a replayed capture or what was recorded.
  const canReport = kind === 'replay' || (rec !== null && rec.bytes > 0);
  useEffect(() => {
    if (rec?.active) setExported(false);
  }, [rec?.active]);
  return (
    <header class="toolbar">
      <div class="brand">
        <svg viewBox="0 0 64 64" width="26" height="26" aria-hidden="true"><path d="M10 44h8l5-22 7 30 6-38 6 30h12" fill="none" stroke="currentColor" stroke-width="5" stroke-linejoin="round" stroke-linecap="round" /></svg>
        <span>SatScope</span>
      </div>
      <div class={`pill ${pill.tone}`} role="status" data-testid="source-status">
        {pill.text}
      </div>
      <div class="actions">
        <button type="button" class="primary" onClick={() => void choose(true)}>{kind === 'serial' ? 'Add receiver' : 'Connect receiver'}</button>
        <button type="button" class="link" onClick={() => void choose(false)}>any port…</button>
        {granted.map((port, i) => (
          <button key={i} type="button" onClick={() => void connect(port)} title="A port this page was allowed before: connect it (several can run side by side)">
            {portLabel(port)}
          </button>
        ))}
        {kind === 'serial' ? <button type="button" onClick={() => send({ type: 'close-all' })}>Disconnect all</button> : null}
        {kind === 'demo' ? (
          <button type="button" onClick={() => send({ type: 'demo-stop' })}>Stop demo</button>
        ) : (
          <button type="button" onClick={() => send({ type: 'demo-start' })}>Demo</button>
        )}
        <button type="button" onClick={() => file.current?.click()}>Open capture…</button>
        <button type="button" onClick={onBind} title="Put a satellite into bind mode through the adapter (spec §7.2)">Bind…</button>
        <input ref={file} type="file" accept=".sscap,.bin,.csv,.txt" hidden onChange={(e) => {
          const f = (e.currentTarget as HTMLInputElement).files?.[0];
          if (f) void openCapture(f);
          (e.currentTarget as HTMLInputElement).value = '';
        }} />
      </div>
      <div class="recorder">
        {rec?.active ? (
          <button type="button" class="rec on" onClick={() => send({ type: 'record-stop' })} aria-label="Stop recording">
            ■ Stop <span class="rec-info">{duration(rec.durationUs)} · {size(rec.bytes)}</span>
          </button>
        ) : (
          <button type="button" class="rec" disabled={!live} onClick={() => send({ type: 'record-start' })} title={live ? 'Record raw bytes with their arrival times' : 'Connect a receiver or start the demo to record'}>
            ● Record
          </button>
        )}
        {rec !== null && !rec.active && rec.bytes > 0 ? (
          <>
            <button type="button" onClick={() => { send({ type: 'export', what: 'sscap', recording: 'last' }); setExported(true); }}>Export .sscap</button>
            <button type="button" onClick={() => send({ type: 'export', what: 'raw', recording: 'last' })}>raw .bin</button>
            {exported ? <span class="muted">saved</span> : null}
          </>
        ) : null}
      </div>
      <div class="report">
        <button type="button" disabled={!canReport} onClick={() => send({ type: 'report', format: 'html' })} title="One-page link-quality report of the capture being replayed, or of what was recorded live">Report</button>
        <button type="button" class="link" disabled={!canReport} onClick={() => send({ type: 'report', format: 'json' })}>json</button>
      </div>
      <label class="resolution">
        Resolution
        <select value={String(resolutionOverride.value)} onChange={(e) => {
          const v = (e.currentTarget as HTMLSelectElement).value;
          const r = v === 'auto' ? 'auto' : (Number(v) as 1024 | 2048);
          resolutionOverride.value = r;
          send({ type: 'set-resolution', resolution: r });
        }}>
          <option value="auto">auto</option>
          <option value="2048">2048</option>
          <option value="1024">1024</option>
        </select>
      </label>
      {rec?.recovered ? (
        <div class="recovered" role="alert">
          An unfinished recording from {new Date(rec.recovered.createdAt).toLocaleString()} ({size(rec.recovered.bytes)}) was kept.
          <button type="button" onClick={() => send({ type: 'export', what: 'sscap', recording: 'recovered' })}>Export .sscap</button>
          <button type="button" onClick={() => send({ type: 'export', what: 'raw', recording: 'recovered' })}>raw .bin</button>
          <button type="button" class="link" onClick={() => send({ type: 'discard-recovered' })}>Discard</button>
        </div>
      ) : null}
      {rec?.error ? <div class="recovered error" role="alert">{rec.error}</div> : null}
    </header>
  );
}
