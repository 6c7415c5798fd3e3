/**
 * The flight controller's own view beside what Drive sends: its USB port opened by the worker and
 * asked over MSP (Betaflight, iNav) for its flight stack, receiver setting, channels, whether it
 * is armed and whether it reports the receiver lost. Only what it answered is shown.
 */
import { useState } from 'preact/hooks';
import { chosenPort, identify, portLabel } from '../../serial.js';
import { fc, send } from '../../store.js';

/** The flight controller's channel order (Betaflight and iNav after their channel map). */
const FC_NAMES = ['Roll', 'Pitch', 'Yaw', 'Throttle', 'Aux 1', 'Aux 2', 'Aux 3', 'Aux 4', 'Aux 5', 'Aux 6', 'Aux 7', 'Aux 8'];
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
            Read the flight controller (MSP)
          </button>
        )}
      </div>
      {s === null ? (
        <p class="drive-note">
          Betaflight and iNav answer over MSP on their USB port (close the configurator first). ArduPilot and PX4 (MAVLink) are not read
          yet.
        </p>
      ) : (
        <>
          <p class="drive-note" data-testid="fc-state">
            {s.state === 'reading'
              ? `${STACKS[s.variant ?? ''] ?? s.variant ?? 'A flight controller'} on ${s.port}: ${s.replies} replies.`
              : s.state === 'opening'
                ? `Asking ${s.port}…`
                : s.state === 'silent'
                  ? `${s.port} does not answer MSP (another program has it, or it is no Betaflight or iNav at 115200).`
                  : `Not reading ${s.port}.`}
          </p>
          {s.armed === true ? (
            <p class="drive-armed" role="alert">
              ARMED: the motors can spin.
            </p>
          ) : null}
          <p class="drive-fc-flags">
            Armed: {s.armed === null ? 'not said' : s.armed ? 'yes' : 'no'} · Receiver lost (RXLOSS):{' '}
            {s.rxLoss === null ? 'not said' : s.rxLoss ? 'yes' : 'no'} · Receiver setting: {s.provider ?? 'not said'}
          </p>
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
                  {s.channels.slice(0, FC_NAMES.length).map((us, i) => (
                    <tr key={i}>
                      <th>{FC_NAMES[i]}</th>
                      <td class="num">{us} µs</td>
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
