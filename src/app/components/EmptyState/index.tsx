/**
 * What the page shows with nothing to show: how to wire a satellite to a USB-serial adapter,
 * and the three ways to start (a receiver, a capture, the demo), instead of empty bars that
 * say "no data" twelve times.
 */
import { chooseAndConnect, serialUnavailable } from '../../serial.js';
import { chooseCapture } from '../../open-file.js';
import { send } from '../../store.js';
import './style.css';

/** The three wires of a satellite's lead, where each goes on the adapter, and its height in the drawing. */
const WIRES = [
  { cls: 'orange', wire: 'orange', what: 'power, 3.3 V', pin: '3.3 V', y: 40 },
  { cls: 'black', wire: 'black', what: 'ground', pin: 'GND', y: 80 },
  { cls: 'grey', wire: 'grey', what: 'DATA (serial out)', pin: 'RX', y: 120 },
] as const;

/** The adapter on the left, the satellite on the right, one line per wire. */
function Wiring() {
  return (
    <svg class="wiring-svg" viewBox="0 0 340 186" role="img" aria-labelledby="wiring-title">
      <title id="wiring-title">Adapter 3.3 V to the orange wire, GND to the black wire, RX to the grey DATA wire. TX stays free.</title>
      <rect class="box" x="6" y="14" width="104" height="158" rx="8" />
      <text class="box-title" x="58" y="32" text-anchor="middle">
        USB-serial
      </text>
      <text class="box-sub" x="58" y="164" text-anchor="middle">
        set to 3.3 V
      </text>
      <rect class="box" x="236" y="14" width="98" height="158" rx="8" />
      <text class="box-title" x="285" y="32" text-anchor="middle">
        Satellite
      </text>
      {WIRES.map((w) => (
        <g key={w.cls}>
          <text class="pin" x="100" y={w.y + 18} text-anchor="end">
            {w.pin}
          </text>
          <circle class="pad" cx="110" cy={w.y + 14} r="4" />
          <path class={`wire-edge`} d={`M110 ${w.y + 14} C 170 ${w.y + 14}, 180 ${w.y + 14}, 236 ${w.y + 14}`} />
          <path class={`wire ${w.cls}`} d={`M110 ${w.y + 14} C 170 ${w.y + 14}, 180 ${w.y + 14}, 236 ${w.y + 14}`} />
          <text class="pin" x="246" y={w.y + 18}>
            {w.wire}
          </text>
        </g>
      ))}
    </svg>
  );
}

export function EmptyState({ onBind }: { onBind(): void }) {
  const noSerial = serialUnavailable();
  return (
    <section class="empty panel" aria-labelledby="empty-title" data-testid="empty-state">
      <h2 id="empty-title" class="empty-title">
        Connect a Spektrum satellite
      </h2>
      <div class="empty-grid">
        <div class="empty-text">
          <ol class="steps">
            <li>
              <strong>Wire it</strong> to a <strong>3.3 V</strong> USB-serial adapter (FTDI, CP2102, CH340…):
              <table class="wires">
                <caption class="sr-only">Wiring</caption>
                <thead>
                  <tr>
                    <th scope="col">Satellite wire</th>
                    <th scope="col">Adapter pin</th>
                  </tr>
                </thead>
                <tbody>
                  {WIRES.map((w) => (
                    <tr key={w.cls}>
                      <td>
                        <span class={`dot ${w.cls}`} aria-hidden="true" />
                        {w.wire}: {w.what}
                      </td>
                      <td>
                        <strong>{w.pin}</strong>
                      </td>
                    </tr>
                  ))}
                </tbody>
              </table>
              <p class="warning" role="note">
                <strong>Never 5 V.</strong> The satellite runs on 3.3 V: 5 V on the orange wire or on DATA can destroy it. The adapter's TX
                stays free (it is only used to bind).
              </p>
            </li>
            <li>
              <strong>Connect receiver</strong> and pick the adapter. Bars appear as soon as frames arrive.
              {noSerial !== null ? (
                <span class="note">
                  {' '}
                  {noSerial.title}: {noSerial.detail}
                </span>
              ) : null}
            </li>
            <li>
              Nothing arrives? A new satellite must be bound to the transmitter first:{' '}
              <button type="button" class="link inline" onClick={onBind}>
                bind it from here
              </button>
              .
            </li>
          </ol>
          <div class="empty-actions">
            <button type="button" class="primary" onClick={() => void chooseAndConnect(true)}>
              Connect receiver
            </button>
            <button type="button" onClick={chooseCapture}>
              Open capture…
            </button>
            <button type="button" onClick={() => send({ type: 'demo-start' })}>
              Start demo
            </button>
          </div>
          <p class="muted small">
            No receiver at hand? <strong>Start demo</strong> simulates two remotes; <strong>Open capture</strong> replays a recording
            (.sscap, raw .bin or a Saleae CSV export), or drop the file anywhere on the page.
          </p>
        </div>
        <figure class="empty-figure">
          <Wiring />
          <figcaption class="muted small">Only three wires. Check the adapter's voltage jumper before plugging in.</figcaption>
        </figure>
      </div>
    </section>
  );
}
