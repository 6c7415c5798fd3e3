/**
 * The window's part of WebSerial: checking it exists, asking for a port (requestPort needs a
 * user gesture, so it cannot happen in the worker), and naming granted ports for the worker.
 */
import { USB_SERIAL_VENDORS, portName } from '../bind/index.js';
import type { PortIdentity } from '../worker/protocol.js';
import { notify, send } from './store.js';

/**
 * USB-serial adapters people put on a satellite's DATA line (the one table, src/bind/chips.ts),
 * as picker hints; any port may be chosen.
 */
export const USB_SERIAL_FILTERS: SerialPortFilter[] = USB_SERIAL_VENDORS.map(({ usbVendorId }) => ({ usbVendorId }));

/** Why WebSerial cannot be used here, with what to do, or null when it can. */
export function serialUnavailable(): { title: string; detail: string } | null {
  if (!window.isSecureContext) {
    return {
      title: 'Web Serial needs a secure page',
      detail: 'Open SatScope over https:// or from http://localhost; the browser hides serial ports from plain http pages.',
    };
  }
  if (!('serial' in navigator)) {
    return {
      title: 'This browser has no Web Serial',
      detail:
        'Use Chrome, Edge or Opera on a desktop computer. Firefox and Safari do not support it. Replay of saved captures works everywhere.',
    };
  }
  return null;
}

export async function identify(port: SerialPort): Promise<PortIdentity> {
  const ports = await navigator.serial.getPorts();
  const info = port.getInfo();
  return { index: Math.max(0, ports.indexOf(port)), usbVendorId: info.usbVendorId, usbProductId: info.usbProductId };
}

/**
 * Shows the browser's port picker, listing only `filters` (empty: every port). Returns the
 * reason, for the user, when nothing was picked.
 */
export async function pickPort(filters: SerialPortFilter[]): Promise<SerialPort | { problem: { title: string; detail: string } }> {
  try {
    return await navigator.serial.requestPort({ filters });
  } catch (error) {
    const name = error instanceof Error ? error.name : '';
    if (name === 'NotFoundError') {
      return {
        problem: {
          title: 'No port chosen',
          detail:
            filters.length > 0
              ? 'Pick the USB-serial adapter wired to the satellite\'s DATA line (gray wire). If it is not in the list, choose "Any serial port…" under the arrow beside Connect receiver.'
              : "Pick the USB-serial adapter wired to the satellite's DATA line (gray wire). If it is not listed, check the cable and its driver.",
        },
      };
    }
    if (name === 'SecurityError')
      return {
        problem: {
          title: 'Serial access is blocked',
          detail: "The browser or an administrator policy blocks serial ports for this page. Check the site's permissions.",
        },
      };
    return { problem: { title: 'Could not ask for a port', detail: String(error) } };
  }
}

/**
 * The port a panel's choice names, or (none chosen) the one the user picks now from every port;
 * null, with the reason told the user, when Web Serial is missing or nothing was picked.
 */
export async function chosenPort(port: SerialPort | undefined): Promise<SerialPort | null> {
  const missing = serialUnavailable();
  if (missing !== null) {
    notify('error', missing.title, missing.detail);
    return null;
  }
  if (port !== undefined) return port;
  const answer = await pickPort([]);
  if ('problem' in answer) {
    notify('warning', answer.problem.title, answer.problem.detail);
    return null;
  }
  return answer;
}

export function portLabel(port: SerialPort): string {
  return portName(port.getInfo());
}

/** Reads a port the page was granted as one more source. */
export async function connect(port: SerialPort): Promise<void> {
  send({ type: 'serial-open', port: await identify(port) });
}

/**
 * "Connect receiver": the browser's picker (USB-serial adapters only when `filtered`), then the
 * chosen port; what went wrong, and what to do, as a notice.
 */
export async function chooseAndConnect(filtered: boolean): Promise<void> {
  const missing = serialUnavailable();
  if (missing !== null) {
    notify('error', missing.title, missing.detail);
    return;
  }
  const picked = await pickPort(filtered ? USB_SERIAL_FILTERS : []);
  if ('problem' in picked) notify('warning', picked.problem.title, picked.problem.detail);
  else await connect(picked);
}
