/**
 * The flight controller's own view, while Drive sends it a satellite: its USB port, opened in
 * the worker beside the adapter, asked over MSP (Betaflight and iNav) what it decoded. It is
 * asked its flight stack and receiver setting once, its status (armed, and the arming-disable
 * flags that say RX loss) and channels 20 times a second; the page is told what it answered,
 * 4 times a second, and nothing it did not. MAVLink (ArduPilot, PX4) is read by the
 * library (src/drive/mavlink.ts) but not asked here yet.
 */
import { BAUD_RATE } from '../decoder/spec.js';
import {
  MSP,
  MspParser,
  encodeMsp,
  readBetaflightStatus,
  readFcVariant,
  readInavStatus,
  readRc,
  readSerialRxProvider,
  SERIALRX_SPEKTRUM1024,
  SERIALRX_SPEKTRUM2048,
} from '../drive/msp.js';
import { type Host, notice } from './host.js';
import type { PortIdentity } from './protocol.js';
import { describePort, openProblem } from './sources/serial.js';

/** How often the flight controller is asked for its status and channels, and the page told, ms. */
const ASK_EVERY_MS = 50;
const POST_EVERY_MS = 250;
/** No reply for this long: the page is told the flight controller is silent, ms. */
const SILENT_MS = 1000;
/** Channel readings kept for grading a drive: 20 minutes of them. */
const MAX_READINGS = 24_000;

/** One MSP_RC answer, with the receiver state it had last said, on the worker's clock (ms). */
export interface FcTimedReading {
  atMs: number;
  channels: number[];
  rxLoss: boolean | null;
}

/** What the flight controller said about itself and its receiver, as the page shows it. */
export interface FcStatus {
  /** 'reading': replies come; 'silent': none for a second (not MSP, or another program has the port); 'closed'. */
  state: 'opening' | 'reading' | 'silent' | 'closed';
  port: string;
  /** The flight stack's four-letter name (MSP_FC_VARIANT: BTFL, INAV…), null until it answers. */
  variant: string | null;
  /** Its serial receiver setting: 'SPEKTRUM1024', 'SPEKTRUM2048', another (by number), or null until it answers. */
  provider: string | null;
  /** The channels it decoded (MSP_RC), µs, in its own order (roll, pitch, yaw, throttle, aux…); null until it answers. */
  channels: number[] | null;
  armed: boolean | null;
  /** It says it has no valid receiver frames (Betaflight RXLOSS, iNav RC_LINK), null until it answers. */
  rxLoss: boolean | null;
  armingDisableFlags: number | null;
  /** Replies read. */
  replies: number;
  /** When it last answered, ms on the worker's clock (NaN: never). */
  lastReplyMs: number;
}

/** Reads one flight controller over MSP. */
export class FcReader {
  #port: SerialPort | undefined;
  #reader: ReadableStreamDefaultReader<Uint8Array> | undefined;
  #writer: WritableStreamDefaultWriter<Uint8Array> | undefined;
  #timers: unknown[] = [];
  #parser = new MspParser();
  #status: FcStatus | null = null;
  #done: Promise<void> = Promise.resolve();
  #openedMs = Number.NaN;
  #readings: FcTimedReading[] = [];

  constructor(
    readonly host: Host,
    readonly find: (identity: PortIdentity) => Promise<SerialPort | undefined>,
  ) {}

  /** Opens the flight controller's port and starts asking it. */
  async open(identity: PortIdentity): Promise<void> {
    await this.close();
    const port = await this.find(identity);
    if (port === undefined) {
      notice(this.host, 'error', 'The port is not available', 'It may have been unplugged. Plug it in and choose it again.');
      return;
    }
    try {
      await port.open({ baudRate: BAUD_RATE, dataBits: 8, stopBits: 1, parity: 'none', flowControl: 'none' });
    } catch (error) {
      const problem = openProblem(error);
      notice(this.host, 'error', `Flight controller: ${problem.title}`, problem.detail);
      return;
    }
    if (port.writable === null || port.readable === null) {
      await port.close().catch(() => undefined);
      notice(
        this.host,
        'error',
        'The flight controller cannot be read',
        'The browser opened its port but gives no way to read and write it.',
      );
      return;
    }
    this.#port = port;
    this.#writer = port.writable.getWriter();
    this.#parser = new MspParser();
    this.#readings = [];
    this.#status = {
      state: 'opening',
      port: describePort(port),
      variant: null,
      provider: null,
      channels: null,
      armed: null,
      rxLoss: null,
      armingDisableFlags: null,
      replies: 0,
      lastReplyMs: Number.NaN,
    };
    this.#openedMs = this.host.clock.now();
    this.#done = this.#read(port.readable.getReader());
    this.#ask(MSP.FC_VARIANT);
    this.#ask(MSP.RX_CONFIG);
    const clock = this.host.clock;
    this.#timers.push(
      clock.every(ASK_EVERY_MS, () => {
        // Its status as often as its channels: when it says the receiver lost is timed to that.
        this.#ask(this.#status?.variant === 'INAV' ? MSP.INAV_STATUS : MSP.STATUS_EX);
        this.#ask(MSP.RC);
      }),
      clock.every(POST_EVERY_MS, () => {
        if (this.#status?.variant === null) this.#ask(MSP.FC_VARIANT);
        this.#post();
      }),
    );
    this.#post();
  }

  /** The channel readings answered from `sinceMs` on (the worker's clock), oldest first. */
  readingsSince(sinceMs: number): FcTimedReading[] {
    return this.#readings.filter((r) => r.atMs >= sinceMs);
  }

  /** Stops asking and closes the port. */
  async close(): Promise<void> {
    const port = this.#port;
    if (port === undefined) return;
    this.#port = undefined;
    for (const t of this.#timers) this.host.clock.cancel(t);
    this.#timers = [];
    try {
      await this.#reader?.cancel();
    } catch {
      // Gone with the device.
    }
    await this.#done;
    this.#writer?.releaseLock();
    this.#writer = undefined;
    await port.close().catch(() => undefined);
    if (this.#status !== null) this.#status.state = 'closed';
    this.#post();
  }

  #ask(cmd: number): void {
    this.#writer?.write(encodeMsp(cmd)).catch(() => undefined);
  }

  async #read(reader: ReadableStreamDefaultReader<Uint8Array>): Promise<void> {
    this.#reader = reader;
    try {
      for (;;) {
        const { value, done } = await reader.read();
        if (done) break;
        if (value !== undefined) this.#take(value);
      }
    } catch {
      // The device is gone, or a line error: reading stops; the page sees it silent.
    } finally {
      reader.releaseLock();
      this.#reader = undefined;
    }
  }

  #take(bytes: Uint8Array): void {
    const s = this.#status;
    if (s === null) return;
    this.#parser.push(bytes);
    for (let m = this.#parser.next(); m !== undefined; m = this.#parser.next()) {
      if (m.direction !== 'reply') continue;
      s.replies++;
      s.lastReplyMs = this.host.clock.now();
      switch (m.cmd) {
        case MSP.FC_VARIANT:
          s.variant = readFcVariant(m.payload);
          break;
        case MSP.RX_CONFIG: {
          const p = readSerialRxProvider(m.payload);
          s.provider =
            p === SERIALRX_SPEKTRUM1024
              ? 'SPEKTRUM1024'
              : p === SERIALRX_SPEKTRUM2048
                ? 'SPEKTRUM2048'
                : p === null
                  ? null
                  : `provider ${p}`;
          break;
        }
        case MSP.RC:
          s.channels = readRc(m.payload);
          if (this.#readings.length === MAX_READINGS) this.#readings.splice(0, MAX_READINGS / 2);
          this.#readings.push({ atMs: s.lastReplyMs, channels: s.channels, rxLoss: s.rxLoss });
          break;
        case MSP.STATUS_EX: {
          const st = readBetaflightStatus(m.payload);
          if (st !== null) {
            s.armed = st.armed;
            s.rxLoss = st.rxLoss;
            s.armingDisableFlags = st.armingDisableFlags;
          }
          break;
        }
        case MSP.INAV_STATUS: {
          const st = readInavStatus(m.payload);
          if (st !== null) {
            s.armed = st.armed;
            s.rxLoss = st.rxLoss;
            s.armingDisableFlags = st.armingFlags;
          }
          break;
        }
      }
    }
  }

  #post(): void {
    const s = this.#status;
    if (s === null) return;
    if (s.state !== 'closed') {
      const now = this.host.clock.now();
      s.state = now - s.lastReplyMs < SILENT_MS ? 'reading' : now - this.#openedMs < SILENT_MS ? 'opening' : 'silent';
    }
    this.host.post({ type: 'fc', fc: { ...s, channels: s.channels === null ? null : [...s.channels] } });
  }
}
