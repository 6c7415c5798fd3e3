/**
 * The flight controller's own view beside what Drive sends: its USB port opened by the worker and
 * read in the protocol it speaks, MSP (Betaflight, iNav) or MAVLink (ArduPilot, PX4): its flight
 * stack, receiver setting (MSP), channels, whether it is armed and whether it reports the
 * receiver lost. Only what it said is shown.
 */
import { useState } from 'preact/hooks';
import { chosenPort, identify, portLabel } from '../../serial.js';
import { fc, send } from '../../store.js';

/** The flight controller's channel order: Betaflight and iNav after their channel map; ArduPilot and PX4 RC1… (their DSM decoder puts throttle on RC3). */
const MSP_NAMES = ['Roll', 'Pitch', 'Yaw', 'Throttle', 'Aux 1', 'Aux 2', 'Aux 3', 'Aux 4', 'Aux 5', 'Aux 6', 'Aux 7', 'Aux 8'];
const MAVLINK_NAMES = ['RC1 roll', 'RC2 pitch', 'RC3 throttle', 'RC4 yaw', ...Array.from({ length: 14 }, (_, i) => `RC${i + 5}`)];
const STACKS: Record<string, string> = { BTFL: 'Betaflight', INAV: 'iNav', CLFL: 'Cleanflight', EMUF: 'EmuFlight' };

export function FcView({ ports, resolution }: { ports: SerialPort[]; resolution: 1024 | 2048 }) {
  const [choice, setChoice] = useState(-1);
  const s = fc.value;
  const open = s !== null && s.state !== 'closed';
  const start = async () => {
    const port = await chosenPort(ports[choice]);
    if (port !== null) send({ type: 'fc-open', port: await identify(port) });
  };
  const expected = resolution === 2048 ? 'SPEKTRUM2048' : 'SPEKTRUM1024';
  const mavlink = s?.protocol === 'mavlink';
  const names = mavlink ? MAVLINK_NAMES : MSP_NAMES;
  return (
    <div class="drive-fc" role="region" aria-label="The flight controller's view">
      <h3>What the flight controller reads</h3>
      <div class="drive-setup">
        <label>
          Its USB port
          <select value={String(choice)} disabled={open} onChange={(e) => setChoice(Number((e.currentTarget as HTMLSelectElement).value))}>
            {ports.map((p, i) => (
              <option key={i} value={String(i)}>
                {portLabel(p)}
              </option>
            ))}
            <option value="-1">Choose when reading…</option>
          </select>
        </label>
        {open ? (
          <button type="button" onClick={() => send({ type: 'fc-close' })}>
            Stop reading
          </button>
        ) : (
          <button type="button" onClick={() => void start()}>
            Read the flight controller
          </button>
        )}
      </div>
      {s === null ? (
        <p class="drive-note">
          Betaflight and iNav are asked over MSP, ArduPilot and PX4 over MAVLink, on their USB port at 115200 (close the configurator or
          ground station first).
        </p>
      ) : (
        <>
          <p class="drive-note" data-testid="fc-state">
            {s.state === 'reading'
              ? `${STACKS[s.variant ?? ''] ?? s.variant ?? 'A flight controller'} on ${s.port} (${mavlink ? 'MAVLink' : 'MSP'}): ${s.replies} ${mavlink ? 'messages' : 'replies'}.`
              : s.state === 'opening'
                ? `Asking ${s.port}…`
                : s.state === 'silent'
                  ? `${s.port} answers neither MSP nor MAVLink (another program has it, or it is no Betaflight, iNav, ArduPilot or PX4 at 115200).`
                  : `Not reading ${s.port}.`}
          </p>
          {s.armed === true ? (
            <p class="drive-armed" role="alert">
              ARMED: the motors can spin.
            </p>
          ) : null}
          {mavlink ? (
            <p class="drive-fc-flags">
              Armed: {s.armed === null ? 'not said' : s.armed ? 'yes' : 'no'} · Receiver lost (SYS_STATUS RC receiver, or no channels):{' '}
              {s.rxLoss === null ? 'not said' : s.rxLoss ? 'yes' : 'no'} · In failsafe (MAV_STATE_CRITICAL):{' '}
              {s.failsafe === null ? 'not said' : s.failsafe ? 'yes' : 'no'} · RSSI: {s.rssi ?? 'not said'}
            </p>
          ) : (
            <p class="drive-fc-flags">
              Armed: {s.armed === null ? 'not said' : s.armed ? 'yes' : 'no'} · Receiver lost (RXLOSS):{' '}
              {s.rxLoss === null ? 'not said' : s.rxLoss ? 'yes' : 'no'} · Receiver setting: {s.provider ?? 'not said'}
            </p>
          )}
          {s.provider !== null && s.provider !== expected ? (
            <p class="drive-warn">
              The flight controller expects {s.provider}, the drive sends {resolution}: set <code>serialrx_provider = {expected}</code> (or
              choose the other receiver).
            </p>
          ) : null}
          {s.channels !== null ? (
            <div class="table-scroll" tabIndex={0} role="region" aria-label="Channels the flight controller decoded">
              <table class="drive-sent">
                <tbody>
                  {s.channels.slice(0, names.length).map((us, i) => (
                    <tr key={i}>
                      <th>{names[i]}</th>
                      <td class="num">{Number.isFinite(us) ? `${us} µs` : 'unused'}</td>
                    </tr>
                  ))}
                </tbody>
              </table>
            </div>
          ) : null}
        </>
      )}
    </div>
  );
}
