/**
 * The serial ports as a driver: each granted port the page asks for is one source, read on its
 * own (serial.ts). An adapter that is unplugged leaves its source 'lost', and it is tried again
 * every RECONNECT_MS and on the browser's 'connect' event, so a replugged adapter comes back as
 * the same remote (same label, same port in the recording) without a prompt.
 */
import { USB_CHUNK_JITTER_US } from '../../decoder/spec.js';
import type { Batcher } from '../batcher.js';
import type { Diagnosis } from '../diagnosis.js';
import { type Host, notice, nowUs } from '../host.js';
import type { LiveSink } from '../live.js';
import type { PortIdentity } from '../protocol.js';
import type { Recorder } from '../recorder.js';
import type { Driver, Source, SourceRegistry } from '../registry.js';
import { SerialSource, describePort, findPort, openProblem } from './serial.js';

/** After a device is lost, try its port again this often (Chromium does not always fire 'connect'). */
export const RECONNECT_MS = 1000;

/** Whether two identities name the same adapter. */
export function sameAdapter(a: PortIdentity | undefined, b: PortIdentity): boolean {
  if (a === undefined) return false;
  // USB IDs survive a replug (the place in getPorts() may not); without them, the place it is.
  if (a.usbVendorId !== undefined || b.usbVendorId !== undefined)
    return a.usbVendorId === b.usbVendorId && a.usbProductId === b.usbProductId;
  return a.index === b.index;
}

export interface SerialPortsParts {
  host: Host;
  registry: SourceRegistry;
  recorder: Recorder;
  diagnosis: Diagnosis;
  batcher: Batcher;
  sink: LiveSink;
  /** Runs a task in the worker's queue (reconnects wait for the command under way). */
  enqueue(task: () => Promise<void>): void;
  /** Finds a granted port (getPorts()); a stand-in in tests. */
  findPort?: (identity: PortIdentity) => Promise<SerialPort | undefined>;
}

export class SerialPorts implements Driver {
  readonly kind = 'serial';
  readonly #p: SerialPortsParts;
  readonly #find: (identity: PortIdentity) => Promise<SerialPort | undefined>;
  #reconnectTimer: unknown;

  constructor(parts: SerialPortsParts) {
    this.#p = parts;
    this.#find = parts.findPort ?? findPort;
  }

  clockUs(): number {
    return nowUs(this.#p.host);
  }

  clockRate(): number {
    return 1;
  }

  linkNowUs(): number {
    return nowUs(this.#p.host);
  }

  /** A port the browser says was connected: a lost adapter may be back. */
  connected(): void {
    this.#p.enqueue(() => this.reconnectLost());
  }

  /** Finds a granted port. */
  find(identity: PortIdentity): Promise<SerialPort | undefined> {
    return this.#find(identity);
  }

  /**
   * Opens a granted port as a source (or again, for a source whose adapter was lost). `signals`
   * are set right after opening (after a bind: the line that powers the satellite), and kept for
   * later reconnects. Returns whether the port is being read.
   */
  async open(identity: PortIdentity, signals?: SerialOutputSignals): Promise<boolean> {
    const { host, registry, recorder, diagnosis, batcher, sink } = this.#p;
    await registry.use(this);
    const port = await this.#find(identity);
    if (port === undefined) {
      notice(host, 'error', 'The port is not available', 'It may have been unplugged. Plug it in and connect again.');
      return false;
    }
    for (const s of registry.list()) {
      if (s.serial?.port === port) {
        notice(host, 'info', 'Already connected', `${describePort(port)} is remote ${s.label}.`);
        return true;
      }
    }
    // A lost remote's adapter, connected by hand: that remote comes back (same label, same port
    // in the recording) instead of a second row.
    const lost = registry.list().find((s) => s.state === 'lost' && sameAdapter(s.identity, identity));
    if (lost !== undefined) {
      if (signals !== undefined) lost.signals = signals;
      return this.#reopen(lost, port);
    }
    const id = registry.freeId();
    const source = registry.add('serial', id, describePort(port), USB_CHUNK_JITTER_US);
    source.identity = identity;
    source.signals = signals;
    const now = (): number => nowUs(host);
    const serial = new SerialSource(now, {
      data: (bytes, timeUs) => sink(id, bytes, timeUs),
      lineError: (name) => {
        // Recorded, so a recording keeps what the doctor judged the line by.
        recorder.event(`line error: ${name}`, now(), id);
        diagnosis.lineError(id, name, now());
        notice(host, 'warning', `Line error on ${source.label}`, `${name}: some bytes may be lost; reading goes on.`);
      },
      lost: () => {
        if (registry.get(id) !== source) return;
        recorder.event('device lost', now(), id);
        // No frame can arrive: the silence from here on is the adapter's, not the link's.
        source.engine.interrupt(now());
        diagnosis.close(id, now());
        registry.setState(source, 'lost');
        notice(
          host,
          'error',
          `Remote ${source.label}: the adapter was unplugged`,
          'Reading stopped; everything recorded so far is kept. Plug it back in and it reconnects by itself.',
        );
        if (this.#reconnectTimer === undefined)
          this.#reconnectTimer = host.clock.every(RECONNECT_MS, () => this.#p.enqueue(() => this.reconnectLost()));
      },
    });
    source.serial = serial;
    registry.send();
    try {
      await serial.open(port, signals);
    } catch (error) {
      registry.discard(id);
      const problem = openProblem(error);
      notice(host, 'error', problem.title, problem.detail);
      return false;
    }
    recorder.event('port opened', now(), id);
    diagnosis.open(id, now());
    registry.setState(source, 'reading', `${describePort(port)} at 115200 baud`);
    batcher.startTicks();
    return true;
  }

  /** Opens a lost source's adapter again; its decode, graphs and recording port carry on. */
  async #reopen(s: Source, port: SerialPort): Promise<boolean> {
    const { host, registry, recorder, diagnosis } = this.#p;
    const serial = s.serial;
    if (serial === undefined) return false;
    try {
      await serial.open(port, s.signals);
    } catch {
      return false;
    }
    // Closed while the port was opening: let it go again.
    if (registry.get(s.id) !== s) {
      await serial.close();
      return false;
    }
    recorder.event('device reconnected', nowUs(host), s.id);
    diagnosis.open(s.id, nowUs(host));
    registry.setState(s, 'reading', `${describePort(port)} at 115200 baud`);
    notice(host, 'info', `Remote ${s.label} reconnected`, 'The adapter is back; reading again.');
    return true;
  }

  /** Tries the ports of lost sources again: a replugged adapter comes back without a prompt. */
  async reconnectLost(): Promise<void> {
    const { registry } = this.#p;
    if (registry.driver !== this) return this.#stopReconnecting();
    for (const s of registry.list()) {
      if (s.state !== 'lost' || s.identity === undefined) continue;
      const port = await this.#find(s.identity);
      if (port !== undefined && registry.get(s.id) === s && s.state === 'lost') await this.#reopen(s, port);
    }
    if (!registry.list().some((s) => s.state === 'lost')) this.#stopReconnecting();
  }

  #stopReconnecting(): void {
    this.#p.host.clock.cancel(this.#reconnectTimer);
    this.#reconnectTimer = undefined;
  }

  async release(source: Source): Promise<void> {
    await source.serial?.close();
  }

  /** Closes every port this driver read. */
  async stop(sources: readonly Source[]): Promise<void> {
    this.#stopReconnecting();
    for (const s of sources) await s.serial?.close();
  }
}
