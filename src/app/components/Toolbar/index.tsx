/**
 * The toolbar, one row on a laptop, in groups: what feeds the page (connect a receiver, ports
 * granted before, the demo, open a capture, bind), recording, the report, and settings
 * (resolution, theme) behind a menu. On a phone the groups wrap onto rows of their own.
 */
import { computed } from '@preact/signals';
import { useEffect, useState } from 'preact/hooks';
import { chooseAndConnect, connect, portLabel } from '../../serial.js';
import type { SourceStatus } from '../../../worker/protocol.js';
import { recording, replayName, resolutionOverride, send, sources } from '../../store.js';
import { chooseCapture, openCapture, setCaptureInput } from '../../open-file.js';
import { setTheme, theme, themeChoice } from '../../theme.js';
import { plural } from '../../../report/report-text.js';
import { Menu } from '../Menu/index.js';
import { FramesExport } from './frames-export.js';
import './style.css';

function size(bytes: number): string {
  return bytes < 1024 ? `${bytes} B` : bytes < 1 << 20 ? `${(bytes / 1024).toFixed(1)} kB` : `${(bytes / (1 << 20)).toFixed(2)} MB`;
}

function duration(us: number): string {
  const s = Math.floor(us / 1e6);
  return `${Math.floor(s / 60)}:${String(s % 60).padStart(2, '0')}`;
}

/**
 * The status pill: what feeds the page now, in a few words that fit beside the toolbar's
 * buttons (`short`), and in full (`full`: its tooltip, and what a screen reader reads).
 */
function summary(list: SourceStatus[]): { short: string; full: string; tone: string } {
  const first = list[0];
  if (first === undefined) return { short: 'No receiver', full: 'No receiver', tone: 'idle' };
  if (first.kind === 'demo')
    return {
      short: `Demo: ${list.map((x) => x.label).join(', ')}`,
      full: `Demo receiver: ${plural(list.length, 'simulated remote')} (DSMX 11 ms)`,
      tone: 'demo',
    };
  if (first.kind === 'replay') {
    const name = replayName.value ?? 'Replay';
    const state = first.state === 'ended' ? 'end' : first.state === 'paused' ? 'paused' : null;
    return {
      // The capture's name is in the replay bar just below.
      short: state === 'end' ? 'Replay ended' : state === 'paused' ? 'Replay paused' : 'Replaying',
      full: `${name}${state === null ? '' : ` (${state})`}`,
      tone: 'replay',
    };
  }
  const lost = list.some((s) => s.state === 'lost');
  const opening = list.some((s) => s.state === 'opening');
  // The remotes by state: "A, B reading", "A reading · B lost".
  const word = (s: SourceStatus) => (s.state === 'lost' ? 'lost' : s.state === 'opening' ? 'opening' : 'reading');
  const short = [...new Set(list.map(word))]
    .map(
      (w) =>
        `${list
          .filter((x) => word(x) === w)
          .map((x) => x.label)
          .join(', ')} ${w}`,
    )
    .join(' · ');
  const full = list
    .map((s) => `${s.label}: ${s.name}${s.state === 'lost' ? ': device lost' : s.state === 'opening' ? ': opening…' : ''}`)
    .join(' · ');
  return { short, full, tone: lost ? 'serial lost' : opening ? 'serial opening' : 'serial reading' };
}

function Sun() {
  return (
    <svg
      viewBox="0 0 24 24"
      width="18"
      height="18"
      aria-hidden="true"
      fill="none"
      stroke="currentColor"
      stroke-width="2"
      stroke-linecap="round"
    >
      <circle cx="12" cy="12" r="4.5" />
      <path d="M12 2v2.5M12 19.5V22M2 12h2.5M19.5 12H22M4.9 4.9l1.8 1.8M17.3 17.3l1.8 1.8M4.9 19.1l1.8-1.8M17.3 6.7l1.8-1.8" />
    </svg>
  );
}

function Moon() {
  return (
    <svg
      viewBox="0 0 24 24"
      width="18"
      height="18"
      aria-hidden="true"
      fill="none"
      stroke="currentColor"
      stroke-width="2"
      stroke-linejoin="round"
    >
      <path d="M20 14.5A8 8 0 0 1 9.5 4a8 8 0 1 0 10.5 10.5z" />
    </svg>
  );
}

// The recorder reports about once a second while it records, and only the running length and
// size change then: the toolbar renders from what changes rarely, and that text is a signal
// bound to the DOM.
const recActive = computed(() => recording.value?.active === true);
const recProgress = computed(() => {
  const r = recording.value;
  return r?.active ? `${duration(r.durationUs)} · ${size(r.bytes)}` : '';
});
/** Bytes recorded (so far, or in the finished recording). */
const recHasBytes = computed(() => (recording.value?.bytes ?? 0) > 0);
/** The size of the finished recording that can be exported, or null. */
const recSaved = computed(() => {
  const r = recording.value;
  return r !== null && !r.active && r.bytes > 0 ? size(r.bytes) : null;
});
const recRecovered = computed(() => {
  const x = recording.value?.recovered;
  return x ? `An unfinished recording from ${new Date(x.createdAt).toLocaleString()} (${size(x.bytes)}) was kept.` : null;
});
const recError = computed(() => recording.value?.error ?? null);

export function Toolbar({ granted, onBind, onDrive }: { granted: SerialPort[]; onBind(): void; onDrive(): void }) {
  const [exported, setExported] = useState(false);
  const list = sources.value;
  const kind = list[0]?.kind;
  const active = recActive.value;
  const saved = recSaved.value;
  const recovered = recRecovered.value;
  const error = recError.value;
  const live = kind === 'serial' || kind === 'demo';
  const pill = summary(list);
  const dark = theme.value === 'dark';
  // A report covers a replayed capture or what was recorded.
  const canReport = kind === 'replay' || recHasBytes.value;
  useEffect(() => {
    if (active) setExported(false);
  }, [active]);
  return (
    <header class="toolbar">
      <h1 class="brand">
        <svg viewBox="0 0 64 64" width="26" height="26" aria-hidden="true">
          <path
            d="M10 44h8l5-22 7 30 6-38 6 30h12"
            fill="none"
            stroke="currentColor"
            stroke-width="5"
            stroke-linejoin="round"
            stroke-linecap="round"
          />
        </svg>
        <span>SatScope</span>
      </h1>
      <div class={`pill ${pill.tone}`} role="status" data-testid="source-status" title={pill.full}>
        {pill.short === pill.full ? (
          pill.full
        ) : (
          <>
            <span aria-hidden="true">{pill.short}</span>
            <span class="sr-only">{pill.full}</span>
          </>
        )}
      </div>
      <div class="tb-group source" role="group" aria-label="Source">
        <div class="split">
          <button type="button" class="primary" onClick={() => void chooseAndConnect(true)}>
            {kind === 'serial' ? 'Add receiver' : 'Connect receiver'}
          </button>
          <Menu label={<span class="sr-only">More ways to connect</span>} className="split-more" title="More ways to connect">
            {(close) => (
              <>
                <button
                  type="button"
                  onClick={() => {
                    close();
                    void chooseAndConnect(false);
                  }}
                >
                  Any serial port…
                </button>
                <p class="hint">Connect receiver lists USB-serial adapters (FTDI, CP210x, CH340, PL2303…). This lists every serial port.</p>
                <button
                  type="button"
                  onClick={() => {
                    close();
                    onDrive();
                  }}
                >
                  Drive a flight controller…
                </button>
                <p class="hint">The adapter's TX plays a satellite to a flight controller, and its own reading is graded.</p>
                {kind === 'serial' ? (
                  <button
                    type="button"
                    onClick={() => {
                      close();
                      send({ type: 'close-all' });
                    }}
                  >
                    Disconnect all
                  </button>
                ) : null}
              </>
            )}
          </Menu>
        </div>
        {granted.map((port, i) => (
          <button
            key={i}
            type="button"
            onClick={() => void connect(port)}
            title="A port this page was allowed before: connect it (several can run side by side)"
          >
            {portLabel(port)}
          </button>
        ))}
        {kind === 'demo' ? (
          <button type="button" onClick={() => send({ type: 'demo-stop' })}>
            Stop demo
          </button>
        ) : (
          <button type="button" onClick={() => send({ type: 'demo-start' })}>
            Demo
          </button>
        )}
        <button type="button" onClick={chooseCapture}>
          Open capture…
        </button>
        <button type="button" onClick={onBind} title="Put a satellite into bind mode through the adapter (spec §7.2)">
          Bind…
        </button>
        <input
          ref={setCaptureInput}
          type="file"
          accept=".sscap,.bin,.csv,.txt"
          hidden
          aria-label="Capture file"
          onChange={(e) => {
            const f = e.currentTarget.files?.[0];
            if (f) void openCapture(f);
            e.currentTarget.value = '';
          }}
        />
      </div>
      <div class="tb-group recorder" role="group" aria-label="Recording">
        {active ? (
          <button type="button" class="rec on" onClick={() => send({ type: 'record-stop' })} aria-label="Stop recording">
            ■ Stop <span class="rec-info">{recProgress}</span>
          </button>
        ) : (
          <button
            type="button"
            class="rec"
            disabled={!live}
            onClick={() => send({ type: 'record-start' })}
            title={live ? 'Record raw bytes with their arrival times' : 'Connect a receiver or start the demo to record'}
          >
            ● Record
          </button>
        )}
        {saved !== null ? (
          <div class="split">
            <button
              type="button"
              onClick={() => {
                send({ type: 'export', what: 'sscap', recording: 'last' });
                setExported(true);
              }}
              title={`Save the recording (${saved}) as .sscap: bytes with their arrival times`}
            >
              Export .sscap
            </button>
            <Menu label={<span class="sr-only">Other export formats</span>} className="split-more" align="end" title="Other export formats">
              {(close) => (
                <>
                  <button
                    type="button"
                    onClick={() => {
                      close();
                      send({ type: 'export', what: 'raw', recording: 'last' });
                      setExported(true);
                    }}
                  >
                    raw .bin
                  </button>
                  <p class="hint">
                    Only the bytes, without times, for other tools: one file per port, as a raw file cannot say which port a byte came from.
                  </p>
                </>
              )}
            </Menu>
          </div>
        ) : null}
        {exported ? <span class="muted saved">saved</span> : null}
      </div>
      <div class="tb-group report" role="group" aria-label="Report">
        <Menu
          label="Report"
          align="end"
          disabled={!canReport}
          title={
            canReport
              ? 'One-page link-quality report, or the decoded frames, of the capture being replayed or of what was recorded live'
              : 'Open a capture or record first: a report covers one of them'
          }
        >
          {(close) => (
            <>
              <button
                type="button"
                onClick={() => {
                  close();
                  send({ type: 'report', format: 'html' });
                }}
              >
                Report as a page (HTML)
              </button>
              <button
                type="button"
                onClick={() => {
                  close();
                  send({ type: 'report', format: 'json' });
                }}
              >
                Report as data (JSON)
              </button>
              <FramesExport close={close} />
            </>
          )}
        </Menu>
      </div>
      <div class="tb-group settings" role="group" aria-label="Settings">
        <button
          type="button"
          class="icon"
          aria-label="Dark theme"
          aria-pressed={dark}
          title={dark ? 'Switch to the light theme' : 'Switch to the dark theme'}
          onClick={() => setTheme(dark ? 'light' : 'dark')}
        >
          {dark ? <Moon /> : <Sun />}
        </button>
        <Menu label="Settings" align="end" title="Resolution and theme">
          {() => (
            <>
              <label>
                Resolution
                <select
                  value={String(resolutionOverride.value)}
                  onChange={(e) => {
                    const v = (e.currentTarget as HTMLSelectElement).value;
                    const r = v === 'auto' ? 'auto' : (Number(v) as 1024 | 2048);
                    resolutionOverride.value = r;
                    send({ type: 'set-resolution', resolution: r });
                  }}
                >
                  <option value="auto">auto</option>
                  <option value="2048">2048</option>
                  <option value="1024">1024</option>
                </select>
              </label>
              <p class="hint">Auto reads it from the system byte or the channel IDs. Force it only for a receiver that reports it wrong.</p>
              <label>
                Theme
                <select
                  value={themeChoice.value ?? 'system'}
                  onChange={(e) => {
                    const v = (e.currentTarget as HTMLSelectElement).value;
                    setTheme(v === 'light' || v === 'dark' ? v : null);
                  }}
                >
                  <option value="system">as the system</option>
                  <option value="light">light</option>
                  <option value="dark">dark</option>
                </select>
              </label>
            </>
          )}
        </Menu>
      </div>
      {recovered !== null ? (
        <div class="recovered" role="alert">
          {recovered}
          <button type="button" onClick={() => send({ type: 'export', what: 'sscap', recording: 'recovered' })}>
            Export .sscap
          </button>
          <button type="button" onClick={() => send({ type: 'export', what: 'raw', recording: 'recovered' })}>
            raw .bin
          </button>
          <button type="button" class="link" onClick={() => send({ type: 'discard-recovered' })}>
            Discard
          </button>
        </div>
      ) : null}
      {error ? (
        <div class="recovered error" role="alert">
          {error}
        </div>
      ) : null}
    </header>
  );
}
