/**
 * Binding a satellite from the page (spec §7.2): choose the bind mode (DSMX 11 ms by default,
 * internal or external explained), the line that switches the satellite's power, and the port;
 * see the wiring and the timeline in plain words ("power off", "power on", "9 pulses"), with
 * the exact serial-port calls in a details view for whoever checks them; bind; then watch the
 * bind take in the live view. What it shows is the bind the worker runs on the chosen port
 * (preview.ts): pulses for that adapter's chip, or for the common chips, saying so. Tables
 * scroll inside the panel on a phone.
 */
import { useEffect, useMemo, useState } from 'preact/hooks';
import { BIND_MODES, type PowerLine, type PowerPolarity } from '../../../bind/index.js';
import wiringSvg from '../../../bind/wiring.svg?raw';
import wiringDoc from '../../../../docs/bind-wiring.md?raw';
import { chosenPort, identify, portLabel } from '../../serial.js';
import { bindLog, send } from '../../store.js';
import { bindPreview, plainStep, sincePowerOn } from './preview.js';
import './style.css';

/**
 * The wiring diagram drawn inline, so it takes the page's theme (Bind/style.css colours it): its
 * own style element, dark, is for the docs, and the page's CSP refuses inline styles anyway.
 */
const WIRING = wiringSvg.replace(/<style>[\s\S]*?<\/style>/, '').replace(/<!--[\s\S]*?-->/g, '');

const hex = (v: number) => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;

/** No port chosen yet: the bind asks for one when it starts. */
const ANOTHER = -1;

export function BindPanel({ granted, onClose }: { granted: SerialPort[]; onClose(): void }) {
  // Escape closes the panel, unless it is closing a menu (the menu's own Escape) or a select.
  useEffect(() => {
    const key = (e: KeyboardEvent) => {
      if (e.key !== 'Escape' || e.defaultPrevented || document.querySelector('.menu-pop:not([hidden])') !== null) return;
      onClose();
    };
    document.addEventListener('keydown', key);
    return () => document.removeEventListener('keydown', key);
  }, [onClose]);
  const [pulses, setPulses] = useState(9);
  const [powerLine, setPowerLine] = useState<PowerLine>('rts');
  const [polarity, setPolarity] = useState<PowerPolarity>('asserted');
  // Ports chosen in the picker from this panel join the granted ones.
  const [picked, setPicked] = useState<SerialPort[]>([]);
  const ports = useMemo(() => [...granted, ...picked.filter((p) => !granted.includes(p))], [granted, picked]);
  const [choice, setChoice] = useState(granted.length > 0 ? 0 : ANOTHER);
  const port = ports[choice];
  // The preview is the bind the worker will run: the same call, with this port's USB IDs.
  const info = port?.getInfo();
  const vid = info?.usbVendorId;
  const pid = info?.usbProductId;
  const preview = useMemo(
    () => bindPreview(pulses, port === undefined ? null : { usbVendorId: vid, usbProductId: pid }, powerLine, polarity),
    [pulses, port, vid, pid, powerLine, polarity],
  );
  const { plan, steps } = preview;
  const mode = BIND_MODES.find((m) => m.pulses === pulses);
  const labels = ports.map((p) => portLabel(p));
  const optionLabel = (i: number) => (labels.filter((l) => l === labels[i]).length > 1 ? `${labels[i]} (${i + 1})` : labels[i]);

  const start = async () => {
    const chosen = await chosenPort(port);
    if (chosen === null) return;
    if (chosen !== port) {
      // Show this port's plan from now on: it is the one the worker runs.
      const known = ports.indexOf(chosen);
      if (known >= 0) setChoice(known);
      else {
        setPicked([...picked, chosen]);
        setChoice(ports.length);
      }
    }
    send({ type: 'bind', port: await identify(chosen), pulses, powerLine, polarity });
  };

  return (
    <section class="bind panel" aria-label="Bind a satellite">
      <div class="bind-head">
        <h2>Bind a satellite</h2>
        <button type="button" class="link" onClick={onClose}>
          Close
        </button>
      </div>
      <div class="bind-grid">
        <div>
          <div class="table-scroll" tabIndex={0} role="region" aria-label="Bind modes">
            <table class="modes">
              <thead>
                <tr>
                  <th>
                    <span class="sr-only">Choose</span>
                  </th>
                  <th>Pulses</th>
                  <th>Remote</th>
                  <th>Protocol</th>
                  <th>Reports</th>
                </tr>
              </thead>
              <tbody>
                {BIND_MODES.map((m) => (
                  <tr key={m.pulses} class={m.pulses === pulses ? 'on' : ''} onClick={() => setPulses(m.pulses)}>
                    <td>
                      <input
                        type="radio"
                        name="bind-mode"
                        aria-label={`${m.pulses} pulses`}
                        checked={m.pulses === pulses}
                        onChange={() => setPulses(m.pulses)}
                      />
                    </td>
                    <td class="num">{m.pulses}</td>
                    <td>{m.remote}</td>
                    <td>
                      {m.protocol} {m.periodMs} ms{m.recommended ? <em> recommended</em> : null}
                    </td>
                    <td>{m.remote === 'internal' ? `system ${hex(m.systemByte)}` : 'UINT16 fades'}</td>
                  </tr>
                ))}
              </tbody>
            </table>
          </div>
          <p class="explain">
            {mode?.description} Bind exactly one remote as <strong>internal</strong> (the A receiver: it negotiates with the transmitter and
            its system byte tells every remote's format); bind all the others as <strong>external</strong>, at the same time.
          </p>
          <div class="controls">
            <label>
              Power switched by
              <select value={powerLine} onChange={(e) => setPowerLine((e.currentTarget as HTMLSelectElement).value as PowerLine)}>
                <option value="rts">RTS</option>
                <option value="dtr">DTR</option>
              </select>
            </label>
            <label>
              Satellite on when the line is
              <select value={polarity} onChange={(e) => setPolarity((e.currentTarget as HTMLSelectElement).value as PowerPolarity)}>
                <option value="asserted">asserted (pin low, P-MOSFET)</option>
                <option value="deasserted">deasserted (pin high)</option>
              </select>
            </label>
            <label>
              Adapter
              <select value={String(choice)} onChange={(e) => setChoice(Number((e.currentTarget as HTMLSelectElement).value))}>
                {ports.map((_, i) => (
                  <option key={i} value={String(i)}>
                    {optionLabel(i)}
                  </option>
                ))}
                <option value={String(ANOTHER)}>{ports.length > 0 ? 'Another port…' : 'Choose when binding…'}</option>
              </select>
            </label>
          </div>
          <p class="adapter" data-testid="bind-adapter">
            {preview.adapter}
          </p>
          <div class="table-scroll" tabIndex={0} role="region" aria-label="What the bind does">
            <table class="timeline" aria-label="Bind timeline">
              <thead>
                <tr>
                  <th>When</th>
                  <th>Step</th>
                  <th>What happens</th>
                </tr>
              </thead>
              <tbody>
                {steps.map((s) => {
                  const p = plainStep(s, steps, pulses);
                  return (
                    <tr key={s.action}>
                      <td class="num">{sincePowerOn(s.sincePowerOnMs)}</td>
                      <td class="step">{p.name}</td>
                      <td class="note">{p.what}</td>
                    </tr>
                  );
                })}
              </tbody>
            </table>
          </div>
          <details class="technical">
            <summary>Technical details: the serial-port calls</summary>
            <p class="plan" data-testid="bind-plan">
              Pulses: <code>{Array.from(plan.bytes, hex).join(' ')}</code> at {plan.baudRate} baud 8N{plan.stopBits}: each{' '}
              {Math.round(plan.lowUs[0] ?? 0)} µs low, {Math.round(plan.highUs[0] ?? 0)} µs high, {(plan.totalUs / 1000).toFixed(2)} ms in
              all. Planned for {plan.chipRates.map((c) => `${c.chip} (${Math.round(c.baudRate)} baud)`).join(', ')}
              {preview.chipsKnown
                ? ''
                : port === undefined
                  ? ': the default chips, as no port is chosen yet'
                  : ": the default chips, as the port's USB IDs name none"}
              .
            </p>
            <ol class="calls">
              {steps.map((s) => (
                <li key={s.action}>
                  <span class="num">{sincePowerOn(s.sincePowerOnMs)}</span> <code>{s.action}</code>: {s.note}
                </li>
              ))}
            </ol>
          </details>
          <div class="go">
            <button type="button" class="primary" onClick={() => void start()}>
              {port === undefined ? 'Choose a port and bind…' : `Bind on ${optionLabel(choice)}`}
            </button>
          </div>
          {bindLog.value.length > 0 ? (
            <ol class="progress" aria-label="Bind progress" aria-live="polite">
              {bindLog.value.map((p, i) => (
                <li key={i} class={p.step}>
                  <span class="num">
                    {p.sincePowerOnMs === null ? '' : `t0 ${p.sincePowerOnMs >= 0 ? '+' : '−'} ${Math.abs(p.sincePowerOnMs)} ms`}
                  </span>{' '}
                  {p.text}
                </li>
              ))}
            </ol>
          ) : null}
        </div>
        <figure class="wiring">
          {/* The project's own diagram, bundled at build time: no outside markup. */}
          <div class="wiring-scroll" tabIndex={0} role="region" aria-label="Wiring diagram" dangerouslySetInnerHTML={{ __html: WIRING }} />
          <figcaption>
            Wiring for binding. Use a 3.3 V adapter. The wiring and the timeline in detail are in the guide below (docs/bind-wiring.md in
            the source).
          </figcaption>
          <details class="guide">
            <summary>Guide: binding wiring and timeline</summary>
            <pre data-testid="bind-guide">{wiringDoc}</pre>
          </details>
        </figure>
      </div>
    </section>
  );
}
