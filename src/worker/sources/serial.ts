/**
 * The serial source: a port the page was granted, found again in the worker with getPorts()
 * (a SerialPort cannot be posted), opened at 115200 8N1, and read until the user closes it or
 * the device goes away. Line errors (buffer overrun, framing, break, parity) cost a reader, not
 * the session: a fresh reader is taken from the new `port.readable`.
 */
import { BAUD_RATE } from '../../decoder/spec.js';
import { portName } from '../../bind/index.js';
import type { PortIdentity } from '../protocol.js';

/** Errors after which `port.readable` is replaced and reading goes on (WebSerial spec). */
const RECOVERABLE = new Set(['BufferOverrunError', 'FramingError', 'BreakError', 'ParityError']);

/** What the page is told about a port error, with what to do. */
export interface SerialProblem {
  title: string;
  detail: string;
}

export interface SerialEvents {
  data(bytes: Uint8Array, timeUs: number): void;
  /** A line error that was survived. */
  lineError(name: string): void;
  /** The device went away (unplugged): reading stopped, the port is closed. */
  lost(): void;
}

/** Finds a granted port by its identity (USB IDs first, then its place in the list). */
export async function findPort(identity: PortIdentity): Promise<SerialPort | undefined> {
  const ports = await navigator.serial.getPorts();
  const same = (p: SerialPort) => {
    const info = p.getInfo();
    return info.usbVendorId === identity.usbVendorId && info.usbProductId === identity.usbProductId;
  };
  const byIndex = ports[identity.index];
  if (byIndex !== undefined && same(byIndex)) return byIndex;
  return ports.find(same) ?? byIndex;
}

export function describePort(port: SerialPort): string {
  return portName(port.getInfo());
}

/** Explains why `open()` failed, in terms of what the user can do. */
export function openProblem(error: unknown): SerialProblem {
  const name = error instanceof Error ? error.name : '';
  const message = error instanceof Error ? error.message : String(error);
  if (name === 'NetworkError' || /failed to open/i.test(message)) {
    return {
      title: 'The port is busy',
      detail:
        'Another program or browser tab has it open (a serial monitor, a flight-controller configurator, another SatScope tab). Close it, then connect again.',
    };
  }
  if (name === 'SecurityError' || name === 'NotAllowedError') {
    return {
      title: 'Permission refused',
      detail: 'The browser did not allow this page to use the port. Connect again and allow it, or check the site settings.',
    };
  }
  if (name === 'InvalidStateError') {
    return { title: 'The port is already open', detail: 'Disconnect first, then connect again.' };
  }
  return { title: 'Could not open the port', detail: `${name || 'Error'}: ${message}` };
}

export class SerialSource {
  #port: SerialPort | undefined;
  #reader: ReadableStreamDefaultReader<Uint8Array> | undefined;
  #closing = false;
  #done: Promise<void> = Promise.resolve();

  constructor(
    readonly nowUs: () => number,
    readonly events: SerialEvents,
  ) {}

  get port(): SerialPort | undefined {
    return this.#port;
  }

  /**
   * Opens the port and starts reading; `signals` are set at once after opening (after a bind,
   * the line that powers the satellite). `line` is for the doctor's short listen at another
   * setting (default 115200 8N1). @throws the port's own error when it cannot be opened.
   */
  async open(
    port: SerialPort,
    signals?: SerialOutputSignals,
    line: { baudRate?: number; parity?: ParityType; stopBits?: 1 | 2 } = {},
  ): Promise<void> {
    await port.open({
      baudRate: line.baudRate ?? BAUD_RATE,
      dataBits: 8,
      stopBits: line.stopBits ?? 1,
      parity: line.parity ?? 'none',
      flowControl: 'none',
      bufferSize: 1 << 20,
    });
    if (signals !== undefined) {
      try {
        await port.setSignals(signals);
      } catch (error) {
        await port.close().catch(() => undefined);
        throw error;
      }
    }
    this.#port = port;
    this.#closing = false;
    this.#done = this.#readLoop(port);
  }

  async #readLoop(port: SerialPort): Promise<void> {
    while (port.readable !== null && !this.#closing) {
      const reader = port.readable.getReader();
      this.#reader = reader;
      try {
        for (;;) {
          const { value, done } = await reader.read();
          if (done) break;
          if (value !== undefined && value.length > 0) this.events.data(value, this.nowUs());
        }
      } catch (error) {
        const name = error instanceof Error ? error.name : '';
        if (RECOVERABLE.has(name)) {
          this.events.lineError(name);
          continue;
        }
        break; // NetworkError: the device is gone.
      } finally {
        reader.releaseLock();
        this.#reader = undefined;
      }
    }
    if (this.#closing) return;
    try {
      await port.close();
    } catch {
      // Already unusable: nothing more to release.
    }
    this.#port = undefined;
    this.events.lost();
  }

  /** Stops reading and closes the port: cancel the reader, then close. */
  async close(): Promise<void> {
    const port = this.#port;
    if (port === undefined) return;
    this.#closing = true;
    try {
      await this.#reader?.cancel();
    } catch {
      // The reader may already be gone with the device.
    }
    await this.#done;
    try {
      await port.close();
    } catch {
      // Closing a port that was lost throws; it is closed either way.
    }
    this.#port = undefined;
  }
}
