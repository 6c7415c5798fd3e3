/**
 * The flight controller's own view, while Drive sends it a satellite: its USB port, opened in
 * the worker beside the adapter at 115200, and what it decoded read in the protocol it speaks.
 *
 * - MSP (Betaflight, iNav): asked its flight stack and receiver setting once, its status (armed,
 *   and the arming-disable flags that say RX loss) and channels 20 times a second.
 * - MAVLink v2 (ArduPilot, PX4): found by its HEARTBEAT. ArduPilot sends one unasked; PX4's USB
 *   port starts MAVLink once it hears some, so a GCS HEARTBEAT is sent once a second after the
 *   port answered no MSP and said no HEARTBEAT for `PROBE_AFTER_MS` (never to a port that
 *   answered MSP: Betaflight reboots to its bootloader on a stray byte), and on to a PX4; not to
 *   an ArduPilot, which streams what it is asked for without one (a ground station's heartbeats
 *   that stop are its GCS failsafe). Once found, RC_CHANNELS and SYS_STATUS are asked
 *   for 20 times a second (SET_MESSAGE_INTERVAL, and REQUEST_DATA_STREAM for older ArduPilot),
 *   again every few seconds while they do not come. Armed is HEARTBEAT's; the receiver lost is
 *   SYS_STATUS's RC receiver bits once the autopilot has said the receiver present (ArduPilot
 *   clears its health in radio failsafe; PX4's commander drops it as present while RC is lost),
 *   else RC_CHANNELS with no channel (chancount 0), else not said.
 *
 * The page is told what it answered, 4 times a second, and nothing it did not.
 */
import { BAUD_RATE } from '../decoder/spec.js';
import {
  autopilotName,
  DATA_STREAM,
  gcsHeartbeat,
  MAV_AUTOPILOT_INVALID,
  MAV_STATE_CRITICAL,
  MAVLINK,
  MavlinkParser,
  readHeartbeat,
  readRcChannels,
  readRcReceiverHealth,
  requestDataStream,
  requestMessageInterval,
} from '../drive/mavlink.js';
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
/**
 * No MSP reply and no HEARTBEAT for this long: a GCS HEARTBEAT goes out once a second, for a PX4
 * that waits to hear MAVLink, ms. Over ArduPilot's heartbeat period (1 s), so an ArduPilot is
 * heard before it is sent anything.
 */
const PROBE_AFTER_MS = 2500;
/** MAVLink: RC_CHANNELS and SYS_STATUS asked for at this interval, µs, and asked again this often while they do not come, ms. */
const MAVLINK_INTERVAL_US = 50_000;
const MAVLINK_ASK_AGAIN_MS = 3000;

/**
 * Each stack's channel order as receiver channel ids (its channel index → the Spektrum channel id
 * it should follow): Betaflight and iNav with `map TAER1234` read roll, pitch, yaw, throttle;
 * ArduPilot and PX4's DSM decoder moves throttle to channel 3 (RC1 roll, RC2 pitch, RC3
 * throttle, RC4 yaw).
 */
export const MSP_ORDER: readonly number[] = [1, 2, 3, 0];
export const MAVLINK_ORDER: readonly number[] = [1, 2, 0, 3];

/** One MSP_RC answer, with the receiver state it had last said, on the worker's clock (ms). */
export interface FcTimedReading {
  atMs: number;
  channels: number[];
  rxLoss: boolean | null;
}

/** What the flight controller said about itself and its receiver, as the page shows it. */
export interface FcStatus {
  /** 'reading': replies come; 'silent': none for a second (neither MSP nor MAVLink, or another program has the port); 'closed'. */
  state: 'opening' | 'reading' | 'silent' | 'closed';
  port: string;
  /** What it speaks: MSP (Betaflight, iNav) or MAVLink (ArduPilot, PX4); null until it answers either. */
  protocol: 'msp' | 'mavlink' | null;
  /** The flight stack: MSP_FC_VARIANT's four letters (BTFL, INAV…), or HEARTBEAT's autopilot ('ArduPilot', 'PX4'); null until said. */
  variant: string | null;
  /** Its serial receiver setting: 'SPEKTRUM1024', 'SPEKTRUM2048', another (by number), or null until it answers. */
  provider: string | null;
  /**
   * The channels it decoded, µs, in its own order (MSP_RC: roll, pitch, yaw, throttle, aux…;
   * RC_CHANNELS: RC1 roll, RC2 pitch, RC3 throttle, RC4 yaw, RC5…, up to its channel count); null until it answers.
   */
  channels: number[] | null;
  armed: boolean | null;
  /** It says it has no valid receiver frames (Betaflight RXLOSS, iNav RC_LINK, MAVLink RC receiver unhealthy or no channels), null until it says. */
  rxLoss: boolean | null;
  /** MAVLink: HEARTBEAT's MAV_STATE is CRITICAL (a failsafe of any kind is on), null where not said. */
  failsafe: boolean | null;
  /** MAVLink: RC_CHANNELS' RSSI (0–254), null where not said. */
  rssi: number | null;
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
  #mavlink = new MavlinkParser();
  /** The autopilot MAVLink came from (sysid, compid), and the sequence of what is sent to it. */
  #target: { sysid: number; compid: number } | null = null;
  #seq = 0;
  #lastRcMs = Number.NaN;
  #askedMs = Number.NaN;
  /** SYS_STATUS has said the RC receiver is there: from then on, present and healthy is the receiver state. */
  #rcPresent = false;

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
    this.#mavlink = new MavlinkParser();
    this.#target = null;
    this.#seq = 0;
    this.#lastRcMs = Number.NaN;
    this.#askedMs = Number.NaN;
    this.#rcPresent = false;
    this.#readings = [];
    this.#status = {
      state: 'opening',
      port: describePort(port),
      protocol: null,
      variant: null,
      provider: null,
      channels: null,
      armed: null,
      rxLoss: null,
      armingDisableFlags: null,
      failsafe: null,
      rssi: null,
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
        // MAVLink streams unasked once asked; MSP answers each question.
        if (this.#status?.protocol === 'mavlink') return;
        // Its status as often as its channels: when it says the receiver lost is timed to that.
        this.#ask(this.#status?.variant === 'INAV' ? MSP.INAV_STATUS : MSP.STATUS_EX);
        this.#ask(MSP.RC);
      }),
      clock.every(POST_EVERY_MS, () => {
        const s = this.#status;
        if (s?.protocol === null && s.variant === null) this.#ask(MSP.FC_VARIANT);
        this.#post();
      }),
      clock.every(1000, () => this.#mavlinkTick()),
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

  #sendMavlink(bytes: Uint8Array): void {
    this.#writer?.write(bytes).catch(() => undefined);
  }

  /**
   * Once a second: no MSP answer for `PROBE_AFTER_MS`, a GCS HEARTBEAT (PX4's USB port starts
   * MAVLink when it hears some; an autopilot streams to a GCS it hears); with an autopilot found,
   * RC_CHANNELS and SYS_STATUS asked for again while they do not come.
   */
  #mavlinkTick(): void {
    const s = this.#status;
    if (s === null || s.protocol === 'msp') return;
    const now = this.host.clock.now();
    if (s.protocol === null && now - this.#openedMs < PROBE_AFTER_MS) return;
    if (s.variant !== 'ArduPilot') this.#sendMavlink(gcsHeartbeat(this.#seq++ & 0xff));
    if (this.#target !== null && !(now - this.#lastRcMs < 1000) && !(now - this.#askedMs < MAVLINK_ASK_AGAIN_MS)) this.#askStreams();
  }

  /** Asks the autopilot for RC_CHANNELS and SYS_STATUS 20 times a second, both ways it may take it. */
  #askStreams(): void {
    const t = this.#target;
    if (t === null) return;
    this.#askedMs = this.host.clock.now();
    for (const m of [MAVLINK.RC_CHANNELS.id, MAVLINK.SYS_STATUS.id])
      this.#sendMavlink(requestMessageInterval(m, MAVLINK_INTERVAL_US, t, this.#seq++ & 0xff));
    const hz = Math.round(1e6 / MAVLINK_INTERVAL_US);
    for (const stream of [DATA_STREAM.RC_CHANNELS, DATA_STREAM.EXTENDED_STATUS])
      this.#sendMavlink(requestDataStream(stream, hz, t, this.#seq++ & 0xff));
  }

  /** The order the flight controller's channels should follow the receiver's in (its channel index → receiver channel id), by the stack it speaks. */
  get expectedOrder(): readonly number[] {
    return this.#status?.protocol === 'mavlink' ? MAVLINK_ORDER : MSP_ORDER;
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
    if (s.protocol !== 'msp') this.#takeMavlink(s, bytes);
    if (s.protocol === 'mavlink') return;
    this.#parser.push(bytes);
    for (let m = this.#parser.next(); m !== undefined; m = this.#parser.next()) {
      if (m.direction !== 'reply') continue;
      s.protocol = 'msp';
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

  #takeMavlink(s: FcStatus, bytes: Uint8Array): void {
    this.#mavlink.push(bytes);
    for (let m = this.#mavlink.next(); m !== undefined; m = this.#mavlink.next()) {
      if (m.msgid === MAVLINK.HEARTBEAT.id) {
        const hb = readHeartbeat(m);
        // Another ground station's heartbeat, or a component's (a camera, a gimbal): not the autopilot.
        if (hb.autopilot === MAV_AUTOPILOT_INVALID) continue;
        if (this.#target === null || this.#target.sysid !== m.sysid) {
          this.#target = { sysid: m.sysid, compid: m.compid };
          s.protocol = 'mavlink';
          this.#askStreams();
        }
        s.variant = autopilotName(hb.autopilot);
        s.armed = hb.armed;
        s.failsafe = hb.systemStatus === MAV_STATE_CRITICAL;
      } else if (this.#target === null || m.sysid !== this.#target.sysid) continue;
      s.replies++;
      s.lastReplyMs = this.host.clock.now();
      if (m.msgid === MAVLINK.SYS_STATUS.id) {
        // ArduPilot keeps the receiver present once seen and clears its health in radio failsafe;
        // PX4's commander says it present only while RC is valid. Either way: once said present,
        // a SYS_STATUS without it present and healthy says the receiver lost.
        const rc = readRcReceiverHealth(m);
        if (rc.present) this.#rcPresent = true;
        if (this.#rcPresent) s.rxLoss = !rc.healthy;
      } else if (m.msgid === MAVLINK.RC_CHANNELS.id) {
        const rc = readRcChannels(m);
        this.#lastRcMs = s.lastReplyMs;
        s.rssi = rc.rssi;
        if (!this.#rcPresent) s.rxLoss = rc.count === 0 ? true : null;
        const channels = rc.channels.slice(0, rc.count).map((us) => us ?? Number.NaN);
        if (rc.count > 0) s.channels = channels;
        if (this.#readings.length === MAX_READINGS) this.#readings.splice(0, MAX_READINGS / 2);
        this.#readings.push({ atMs: s.lastReplyMs, channels, rxLoss: s.rxLoss });
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
