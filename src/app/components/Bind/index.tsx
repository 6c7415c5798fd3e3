/**
 * Binding a satellite from the page (spec §7.2): choose the bind mode (DSMX 11 ms by default,
 * internal or external explained), the line that switches the satellite's power, and the port;
 * see the wiring and the timeline in plain words ("power off", "power on", "9 pulses"), with
 * the exact serial-port calls in a details view for whoever checks them; bind; then watch the
 * bind take in the live view. Tables scroll inside the panel on a phone.
 */
import { useMemo, useState } from 'preact/hooks';
import { BIND_MODES, bindTimeline, planPulses, type BindStep, type PowerLine, type PowerPolarity } from '../../../bind/index.js';
import wiring from '../../../bind/wiring.svg';
import { identify, pickPort, portLabel, serialUnavailable } from '../../serial.js';
import { bindLog, notify, send } from '../../store.js';
import './style.css';

const hex = (v: number) => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;

const at = (ms: number) => (ms >= 0 ? `t0 + ${ms.toFixed(0)} ms` : `t0 − ${(-ms).toFixed(0)} ms`);

/** A step as a hobbyist says it: what to call it, and what happens to the satellite. */
function plain(step: BindStep, steps: readonly BindStep[], pulses: number): { name: string; what: string } {
  switch (step.action) {
    case 'open':
      return { name: 'Open the adapter', what: `The adapter is set up to draw the pulses (${step.baudRate} baud).` };
    case 'power-off': {
      const on = steps.find((x) => x.action === 'power-on');
      const offMs = on === undefined ? 0 : on.atMs - step.atMs;
      return { name: 'Power off', what: `The satellite is switched off for ${offMs.toFixed(0)} ms, so it starts afresh.` };
    }
    case 'power-on':
      return { name: 'Power on', what: 'The satellite is switched on. The time of every later step counts from here (t0).' };
    case 'write':
      return {
        name: `${pulses} pulses`,
        what: `${pulses} short pulses on the DATA wire, ${(step.durationUs / 1000).toFixed(1)} ms in all: the satellite enters bind mode and its light blinks fast.`,
      };
    case 'reopen':
      return { name: 'Back to reading', what: 'The adapter goes back to reading frames. Now put the transmitter in bind mode; frames appear once the bind takes.' };
  }
}

export function BindPanel({ granted, onClose }: { granted: SerialPort[]; onClose(): void }) {
  const [pulses, setPulses] = useState(9);
  const [powerLine, setPowerLine] = useState<PowerLine>('rts');
  const [polarity, setPolarity] = useState<PowerPolarity>('asserted');
  const plan = useMemo(() => planPulses(pulses), [pulses]);
  const steps = useMemo(() => bindTimeline(pulses, { powerLine, polarity, plan }), [pulses, powerLine, polarity, plan]);
  const mode = BIND_MODES.find((m) => m.pulses === pulses);

  const start = async (port: SerialPort | null) => {
    const missing = serialUnavailable();
    if (missing !== null) {
      notify('error', missing.title, missing.detail);
      return;
    }
    let chosen = port;
    if (chosen === null) {
      const picked = await pickPort([]);
      if ('problem' in picked) {
        notify('warning', picked.problem.title, picked.problem.detail);
        return;
      }
      chosen = picked;
    }
    send({ type: 'bind', port: await identify(chosen), pulses, powerLine, polarity });
  };

  return (
    <section class="bind panel" aria-label="Bind a satellite">
      <div class="bind-head">
        <h2>Bind a satellite</h2>
        <button type="button" class="link" onClick={onClose}>Close</button>
      </div>
      <div class="bind-grid">
        <div>
          <div class="table-scroll" tabIndex={0} role="region" aria-label="Bind modes">
          <table class="modes">
            <thead><tr><th><span class="sr-only">Choose</span></th><th>Pulses</th><th>Remote</th><th>Protocol</th><th>Reports</th></tr></thead>
            <tbody>
              {BIND_MODES.map((m) => (
                <tr key={m.pulses} class={m.pulses === pulses ? 'on' : ''} onClick={() => setPulses(m.pulses)}>
                  <td><input type="radio" name="bind-mode" aria-label={`${m.pulses} pulses`} checked={m.pulses === pulses} onChange={() => setPulses(m.pulses)} /></td>
                  <td class="num">{m.pulses}</td>
                  <td>{m.remote}</td>
                  <td>{m.protocol} {m.periodMs} ms{m.recommended ? <em> recommended</em> : null}</td>
                  <td>{m.remote === 'internal' ? `system ${hex(m.systemByte)}` : 'UINT16 fades'}</td>
                </tr>
              ))}
            </tbody>
          </table>
          </div>
          <p class="explain">
            {mode?.description} Bind exactly one remote as <strong>internal</strong> (the A receiver: it negotiates
            with the transmitter and its system byte tells every remote's format); bind all the others
            as <strong>external</strong>, at the same time.
          </p>
          <div class="controls">
            <label>Power switched by
              <select value={powerLine} onChange={(e) => setPowerLine((e.currentTarget as HTMLSelectElement).value as PowerLine)}>
                <option value="rts">RTS</option>
                <option value="dtr">DTR</option>
              </select>
            </label>
            <label>Satellite on when the line is
              <select value={polarity} onChange={(e) => setPolarity((e.currentTarget as HTMLSelectElement).value as PowerPolarity)}>
                <option value="asserted">asserted (pin low, P-MOSFET)</option>
                <option value="deasserted">deasserted (pin high)</option>
              </select>
            </label>
          </div>
          <div class="table-scroll" tabIndex={0} role="region" aria-label="What the bind does">
          <table class="timeline" aria-label="Bind timeline">
            <thead><tr><th>When</th><th>Step</th><th>What happens</th></tr></thead>
            <tbody>
              {steps.map((s) => {
                const p = plain(s, steps, pulses);
                return (
                  <tr key={s.action}>
                    <td class="num">{at(s.sincePowerOnMs)}</td>
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
            <p class="plan">
              Pulses: {pulses} × <code>{hex(plan.bytes[0] ?? 0)}</code> at {plan.baudRate} baud 8N{plan.stopBits}: each {Math.round(plan.lowUs[0] ?? 0)} µs low,
              {' '}{Math.round(plan.highUs[0] ?? 0)} µs high, {(plan.totalUs / 1000).toFixed(2)} ms in all.
            </p>
            <ol class="calls">
              {steps.map((s) => (
                <li key={s.action}><span class="num">{at(s.sincePowerOnMs)}</span> <code>{s.action}</code>: {s.note}</li>
              ))}
            </ol>
          </details>
          <div class="go">
            {granted.map((port, i) => (
              <button key={i} type="button" class="primary" onClick={() => void start(port)}>Bind on {portLabel(port)}</button>
            ))}
            <button type="button" class={granted.length === 0 ? 'primary' : ''} onClick={() => void start(null)}>Bind on a port…</button>
          </div>
          {bindLog.value.length > 0 ? (
            <ol class="progress" aria-label="Bind progress" aria-live="polite">
              {bindLog.value.map((p, i) => (
                <li key={i} class={p.step}>
                  <span class="num">{p.sincePowerOnMs === null ? '' : `t0 ${p.sincePowerOnMs >= 0 ? '+' : '−'} ${Math.abs(p.sincePowerOnMs)} ms`}</span> {p.text}
                </li>
              ))}
            </ol>
          ) : null}
        </div>
        <figure class="wiring">
          <img src={wiring} alt="Wiring: adapter TX through a diode and 470 Ω to the satellite's DATA, RX straight to DATA, RTS or DTR switching the satellite's 3.3 V through a P-MOSFET, grounds joined." />
          <figcaption>Wiring for binding (details in docs/bind-wiring.md). Use a 3.3 V adapter.</figcaption>
        </figure>
      </div>
    </section>
  );
}
