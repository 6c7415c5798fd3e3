/**
 * Drive a flight controller: the adapter's TX wired to the FC's satellite pad, SatScope sends a
 * satellite's stream (a built-in scenario for the receiver chosen, the user's own JSON, or the
 * page's sticks) and shows what it is sending now, where the scenario is, and how the writes
 * were timed. With the adapter's TX also wired to its own RX (the loopback self-test), the
 * frames it read back are decoded as any receiver's and compared with those written.
 *
 * Safety: nothing is sent before the user says the propellers are off; the throttle never goes
 * past the ceiling set here; Escape or Space stops at once (so does closing the tab or
 * unplugging the adapter): the flight controller sees its link lost, as in the air.
 */
import { useEffect, useMemo, useRef, useState } from 'preact/hooks';
import { builtinScenarios, type DriveReceiver, manualScenario } from '../../../drive/builtins.js';
import {
  CHANNEL_NAMES,
  SYSTEM_DSM2_11MS_2048,
  SYSTEM_DSM2_22MS_1024,
  SYSTEM_DSMX_11MS_2048,
  SYSTEM_DSMX_22MS_2048,
  systemInfo,
} from '../../../decoder/spec.js';
import { chosenPort, identify, portLabel } from '../../serial.js';
import { codeSpans, type DriveReport, driveReportHtml, fixFor } from '../../../drive/report.js';
import { download, drive, fc, liveOf, send } from '../../store.js';
import { FcView } from './fc.js';
import { StickSources } from './inputs.js';
import './style.css';

const SYSTEMS = [SYSTEM_DSMX_11MS_2048, SYSTEM_DSMX_22MS_2048, SYSTEM_DSM2_11MS_2048, SYSTEM_DSM2_22MS_1024];
/** The user's own scenario, pasted or loaded. */
const MINE = 'mine';
const ms = (us: number) => `${(us / 1000).toFixed(1)} ms`;
const clock = (us: number) => {
  const s = Math.max(0, us) / 1e6;
  return `${Math.floor(s / 60)}:${(s % 60).toFixed(1).padStart(4, '0')}`;
};

/** What to change where a check failed (nothing where it did not). */
function Fix({ text }: { text: string | null }) {
  return text === null ? null : (
    <div class="drive-fix">{codeSpans(text).map((p, i) => (p.code ? <code key={i}>{p.text}</code> : p.text))}</div>
  );
}

/** Saves the conformance report of a drive that stopped, with what the flight controller said of itself. */
function save(status: NonNullable<typeof drive.value>, format: 'html' | 'json'): void {
  const f = fc.peek();
  const report: DriveReport = {
    date: new Date().toISOString(),
    scenario: { name: status.name, title: status.title },
    receiver: status.receiver,
    timing: status.timing,
    fc: f === null ? null : { variant: f.variant, provider: f.provider },
    checks: status.checks ?? [],
    notes: status.gradeNote === null ? [] : [status.gradeNote],
  };
  const text = format === 'html' ? driveReportHtml(report) : `${JSON.stringify(report, null, 2)}\n`;
  const data = new TextEncoder().encode(text).buffer as ArrayBuffer;
  download(`satscope-drive-${status.name}.${format}`, format === 'html' ? 'text/html' : 'application/json', data);
}

export function DrivePanel({ granted, onClose }: { granted: SerialPort[]; onClose(): void }) {
  const status = drive.value;
  const driving = status?.state === 'driving';
  // A start asked for and not answered yet: Escape or Space stops it too.
  const starting = useRef(false);
  if (status !== null) starting.current = false;
  // Escape or Space stops a drive at once, wherever the focus is; Escape otherwise closes the
  // panel when the focus is in it (or nowhere), not a menu or another panel's field.
  useEffect(() => {
    const key = (e: KeyboardEvent) => {
      if ((drive.peek()?.state === 'driving' || starting.current) && (e.key === 'Escape' || e.key === ' ')) {
        e.preventDefault();
        starting.current = false;
        send({ type: 'drive-stop' });
        return;
      }
      const at = document.activeElement;
      const here = at === null || at === document.body || at.closest('.drive') !== null;
      if (e.key === 'Escape' && here && document.querySelector('.menu-pop:not([hidden])') === null) onClose();
    };
    document.addEventListener('keydown', key, true);
    return () => document.removeEventListener('keydown', key, true);
  }, [onClose]);

  const [receiver, setReceiver] = useState<DriveReceiver>({ system: SYSTEM_DSMX_11MS_2048, remote: 'internal', channels: 8 });
  const scenarios = useMemo(() => [manualScenario(receiver), ...builtinScenarios(receiver)], [receiver]);
  const [scenario, setScenario] = useState('manual');
  const [mine, setMine] = useState('');
  const [ceiling, setCeiling] = useState(-60);
  const [propsOff, setPropsOff] = useState(false);
  const [picked, setPicked] = useState<SerialPort[]>([]);
  const ports = useMemo(() => [...granted, ...picked.filter((p) => !granted.includes(p))], [granted, picked]);
  const [choice, setChoice] = useState(granted.length > 0 ? 0 : -1);
  const [held, setHeld] = useState<Record<number, number>>({});
  const chosen = scenarios.find((s) => s.name === scenario);

  const start = async () => {
    const port = await chosenPort(ports[choice]);
    if (port === null) return;
    if (!ports.includes(port)) {
      setPicked([...picked, port]);
      setChoice(ports.length);
    }
    // The sticks the user holds go with the new drive from its first frame.
    drive.value = null;
    starting.current = true;
    setPropsOff(false);
    send({
      type: 'drive-start',
      port: await identify(port),
      receiver,
      scenario: scenario === MINE ? mine : scenario,
      throttleCeilingPercent: ceiling,
      held,
    });
  };

  // The sticks held now, for the keyboard and gamepad loop (several may change in one frame).
  const heldNow = useRef(held);
  heldNow.current = held;
  const hold = (id: number, percent: number | null) => {
    const next = { ...heldNow.current };
    if (percent === null) delete next[id];
    else next[id] = percent;
    heldNow.current = next;
    setHeld(next);
    send({ type: 'drive-channel', id, percent });
  };

  const info = systemInfo(receiver.system);
  const loop = status?.source !== null && status?.source !== undefined ? liveOf(status.source) : null;
  const t = status?.timing;
  return (
    <section class="drive panel" aria-label="Drive a flight controller">
      <div class="drive-head">
        <h2>Drive a flight controller</h2>
        <button type="button" class="link" onClick={onClose} disabled={driving} title={driving ? 'Stop the drive first' : undefined}>
          Close
        </button>
      </div>
      <p class="drive-warn" role="note">
        <strong>Propellers off.</strong> The flight controller reads this as its receiver: it may arm and spin the motors. Wire the
        adapter's TX to the flight controller's satellite RX pad, GND to GND, 3.3 V only. Escape or Space stops sending at once; the flight
        controller then sees its link lost.
      </p>
      <div class="drive-setup">
        <label>
          Receiver
          <select
            value={String(receiver.system)}
            disabled={driving}
            onChange={(e) => setReceiver({ ...receiver, system: Number((e.currentTarget as HTMLSelectElement).value) })}
          >
            {SYSTEMS.map((s) => (
              <option key={s} value={String(s)}>
                {systemInfo(s)?.name}
              </option>
            ))}
          </select>
        </label>
        <label>
          Remote
          <select
            value={receiver.remote}
            disabled={driving}
            onChange={(e) => setReceiver({ ...receiver, remote: (e.currentTarget as HTMLSelectElement).value as 'internal' | 'external' })}
          >
            <option value="internal">internal (system byte)</option>
            <option value="external">external (UINT16 fades)</option>
          </select>
        </label>
        <label>
          Channels
          <input
            type="number"
            min={1}
            max={12}
            value={receiver.channels}
            disabled={driving}
            onChange={(e) => {
              const n = Math.round(Number((e.currentTarget as HTMLInputElement).value));
              if (n >= 1 && n <= 12) setReceiver({ ...receiver, channels: n });
            }}
          />
        </label>
        <label>
          Throttle ceiling
          <input
            type="number"
            min={-100}
            max={100}
            step={5}
            value={ceiling}
            disabled={driving}
            aria-describedby="drive-ceiling-note"
            onChange={(e) => {
              const v = Number((e.currentTarget as HTMLInputElement).value);
              if (Number.isFinite(v)) setCeiling(Math.max(-100, Math.min(100, v)));
            }}
          />
          %
        </label>
        <label>
          Adapter
          <select
            value={String(choice)}
            disabled={driving}
            onChange={(e) => setChoice(Number((e.currentTarget as HTMLSelectElement).value))}
          >
            {ports.map((p, i) => (
              <option key={i} value={String(i)}>
                {portLabel(p)}
              </option>
            ))}
            <option value="-1">{ports.length > 0 ? 'Another port…' : 'Choose when starting…'}</option>
          </select>
        </label>
      </div>
      <p class="drive-note" id="drive-ceiling-note">
        Throttle (channel 0) never goes past {ceiling} % of travel, whatever the scenario or the sticks ask. {info?.name}: {info?.periodMs}{' '}
        ms frames, {info?.resolution} resolution.
      </p>
      <div class="drive-scenario">
        <label>
          Scenario
          <select value={scenario} disabled={driving} onChange={(e) => setScenario((e.currentTarget as HTMLSelectElement).value)}>
            {scenarios.map((s) => (
              <option key={s.name} value={s.name}>
                {s.name}
              </option>
            ))}
            <option value={MINE}>my own (JSON)…</option>
          </select>
        </label>
        <span class="drive-note">{scenario === MINE ? 'Paste a scenario: name, title and steps (see the README).' : chosen?.title}</span>
      </div>
      {scenario === MINE ? (
        <textarea
          class="drive-json"
          aria-label="Scenario as JSON"
          rows={6}
          value={mine}
          disabled={driving}
          placeholder='{"name": "mine", "title": "…", "steps": [{"note": "…", "durationUs": 2000000, "receiver": {"system": 178, "remote": "internal", "channels": 8}}]}'
          onInput={(e) => setMine((e.currentTarget as HTMLTextAreaElement).value)}
        />
      ) : null}
      <div class="drive-go">
        {driving ? (
          <button type="button" class="primary stop" onClick={() => send({ type: 'drive-stop' })}>
            ■ Stop (Esc)
          </button>
        ) : (
          <>
            <label class="props">
              <input type="checkbox" checked={propsOff} onChange={(e) => setPropsOff((e.currentTarget as HTMLInputElement).checked)} />
              The propellers are off
            </label>
            <button type="button" class="primary" disabled={!propsOff} onClick={() => void start()}>
              ▶ Start driving
            </button>
          </>
        )}
      </div>
      {status !== null ? (
        <div class="drive-now" aria-live="polite">
          <p class="drive-state" data-testid="drive-state">
            {status.state === 'driving'
              ? `Sending “${status.name}”: ${clock(status.positionUs)} of ${clock(status.durationUs)}`
              : `Stopped: ${status.reason ?? ''} (“${status.name}” at ${clock(status.positionUs)})`}
          </p>
          <ol class="drive-steps" aria-label="Scenario timeline">
            {status.steps.map((s, i) => (
              <li key={i} class={i === status.step && driving ? 'on' : i < status.step ? 'done' : ''}>
                <span class="num">{clock(s.startUs)}</span> {s.note}
              </li>
            ))}
          </ol>
          {status.sent !== null ? (
            <>
              <p class="drive-note">
                {driving ? 'Sending now' : 'Last sent'}:{' '}
                {status.sent.remote === 'internal'
                  ? `internal remote, system byte 0x${(status.sent.system ?? 0).toString(16).toUpperCase()}`
                  : 'external remote'}
                , {status.sent.resolution} resolution
              </p>
              <div class="table-scroll" tabIndex={0} role="region" aria-label="Channels being sent">
                <table class="drive-sent">
                  <tbody>
                    {status.sent.us.map((us, id) =>
                      Number.isNaN(us) ? null : (
                        <tr key={id}>
                          <th>{CHANNEL_NAMES[id]}</th>
                          <td class="num">{us.toFixed(0)} µs</td>
                        </tr>
                      ),
                    )}
                  </tbody>
                </table>
              </div>
            </>
          ) : null}
          {t !== undefined ? (
            <p class="drive-timing" data-testid="drive-timing">
              Written: {t.frames} frames
              {t.interval !== null
                ? `, intervals ${ms(t.interval.p1)} / ${ms(t.interval.p50)} / ${ms(t.interval.p99)} (1st, median, 99th percentile)`
                : ''}
              {Number.isFinite(t.minSilenceUs) ? `, shortest silence before a frame ${ms(t.minSilenceUs)}` : ''}; {t.skipped} skipped,{' '}
              {t.delayed} delayed (sent late to keep the silence before them).
            </p>
          ) : null}
          {loop !== null && loop.counters.frames > 0 ? (
            <p class="drive-loop" data-testid="drive-loopback">
              Loopback: the adapter read back {loop.counters.frames} frames
              {loop.link !== null && Number.isFinite(loop.link.periodUs) ? `, period ${ms(loop.link.periodUs)}` : ''}
              {loop.link !== null && Number.isFinite(loop.link.deliveryJitterUs)
                ? `, delivery jitter ${ms(loop.link.deliveryJitterUs)}`
                : ''}
              ; {loop.counters.badFrames} broken, {loop.counters.resyncs} resyncs, {loop.counters.discardedBytes} bytes between frames.
            </p>
          ) : null}
        </div>
      ) : null}
      {status !== null && status.state !== 'driving' && (status.checks !== null || status.gradeNote !== null) ? (
        <div class="drive-grade" role="region" aria-label="Conformance">
          <h3>How the flight controller read it</h3>
          {status.gradeNote !== null ? <p class="drive-note">{status.gradeNote}</p> : null}
          {status.checks !== null ? (
            <>
              <div class="table-scroll" tabIndex={0} role="region" aria-label="Checks">
                <table class="drive-checks">
                  <thead>
                    <tr>
                      <th>Check</th>
                      <th>What it should do</th>
                      <th>What it did</th>
                      <th>Verdict</th>
                    </tr>
                  </thead>
                  <tbody>
                    {status.checks.map((c) => (
                      <tr key={c.id} class={c.verdict}>
                        <th>{c.id}</th>
                        <td data-label="Should">{c.expects}</td>
                        <td data-label="Did">
                          {c.found}
                          <Fix text={fixFor(c, { receiver: status.receiver, fc: fc.value })} />
                        </td>
                        <td class="verdict">{c.verdict}</td>
                      </tr>
                    ))}
                  </tbody>
                </table>
              </div>
              <div class="drive-go">
                <button type="button" onClick={() => save(status, 'html')}>
                  Save report (HTML)
                </button>
                <button type="button" onClick={() => save(status, 'json')}>
                  Save report (JSON)
                </button>
              </div>
            </>
          ) : null}
        </div>
      ) : null}
      <FcView ports={ports} resolution={info?.resolution ?? 2048} />
      <fieldset class="drive-sticks" disabled={!driving}>
        <legend>Sticks (held while set; the scenario moves the others)</legend>
        {Array.from({ length: receiver.channels }, (_, id) => (
          <label key={id}>
            <span>{CHANNEL_NAMES[id]}</span>
            <input
              type="range"
              min={-100}
              max={100}
              value={id === 0 ? Math.min(held[id] ?? -100, ceiling) : (held[id] ?? 0)}
              aria-label={`${CHANNEL_NAMES[id]} stick, %`}
              onInput={(e) => hold(id, Number((e.currentTarget as HTMLInputElement).value))}
            />
            <span class="num">{held[id] === undefined ? 'scenario' : `${id === 0 ? Math.min(held[id] ?? 0, ceiling) : held[id]} %`}</span>
            {held[id] !== undefined ? (
              <button type="button" class="link" onClick={() => hold(id, null)}>
                release
              </button>
            ) : null}
          </label>
        ))}
      </fieldset>
      <StickSources channels={receiver.channels} driving={driving} held={heldNow} ceiling={ceiling} onHold={hold} />
    </section>
  );
}
