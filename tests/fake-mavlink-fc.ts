/**
 * A fake ArduPilot or PX4 on a stand-in USB port, speaking MAVLink v2 as their sources do
 * (ArduPilot GCS_Common.cpp and its vehicles' SYS_STATUS; PX4's mavlink module):
 *
 * - HEARTBEAT once a second, MAV_AUTOPILOT_ARDUPILOTMEGA (3) or MAV_AUTOPILOT_PX4 (12), armed in
 *   base_mode, MAV_STATE_CRITICAL (5) while in failsafe. ArduPilot sends from the start; PX4's
 *   USB port starts MAVLink only once it hears a MAVLink frame (cdcacm autostart).
 * - RC_CHANNELS and SYS_STATUS only once asked (SET_MESSAGE_INTERVAL, or REQUEST_DATA_STREAM
 *   RC_CHANNELS / EXTENDED_STATUS where `acceptsInterval` is false, an older ArduPilot).
 * - ArduPilot: RC_CHANNELS keeps coming in failsafe with the last values and its channel count;
 *   SYS_STATUS has the RC receiver present, healthy unless in radio failsafe (Copter's
 *   `rc_receiver_present && !failsafe.radio`). PX4: RC_CHANNELS only while frames come (its
 *   stream sends on an RC input update); SYS_STATUS has the RC receiver present, enabled and
 *   healthy only while RC is valid (its commander's `setIsPresent(remote_control)`), or never
 *   where `reportsRc` is false.
 *
 * Its receiver is a FakeFc with the DSM decoder ArduPilot and PX4 share. Bytes that are not
 * MAVLink (MSP asked of it first) are ignored.
 */
import { encodeMavlink, MAVLINK, MavlinkParser, SENSOR_RC_RECEIVER } from '../src/drive/mavlink.js';
import { FakeFc } from './fake-fc.js';
import { type FakeClock, StandInPort } from './worker-fakes.js';

export interface FakeMavlinkFcOptions {
  stack: 'ArduPilot' | 'PX4';
  clock: FakeClock;
  resolution?: 1024 | 2048;
  armed?: boolean;
  /** Takes SET_MESSAGE_INTERVAL (default); false: only REQUEST_DATA_STREAM, as an ArduPilot before 4.0. */
  acceptsInterval?: boolean;
  vid?: number;
  /** PX4: SYS_STATUS says the RC receiver while it is valid (default); false: never. */
  reportsRc?: boolean;
}

const SET_MESSAGE_INTERVAL = 511;

export class FakeMavlinkFc {
  readonly uart: FakeFc;
  readonly usb: StandInPort;
  /** What it was asked: MAVLink messages from the page, by id. */
  readonly asked = new Map<number, number>();
  /** Bytes it ignored (not MAVLink). */
  ignored = 0;
  #listening: boolean;
  #rcEveryMs = 0;
  #sysEveryMs = 0;
  #nextRc = 0;
  #nextSys = 0;
  #seq = 0;
  readonly #parser = new MavlinkParser();

  constructor(readonly options: FakeMavlinkFcOptions) {
    this.uart = new FakeFc({
      resolution: options.resolution ?? 2048,
      decoder: 'dsm',
      // ArduPilot's RC failsafe after RC_FS_TIMEOUT (1 s), cleared by the first good frame.
      signalTimeoutMs: options.stack === 'ArduPilot' ? 1000 : 500,
      recoveryMs: 0,
    });
    this.#listening = options.stack === 'ArduPilot';
    this.usb = new StandInPort(options.vid ?? 0x1209, (bytes) => this.#heard(bytes));
    const clock = options.clock;
    clock.every(1000, () => {
      if (this.#listening) this.#send(MAVLINK.HEARTBEAT.id, this.#heartbeat());
    });
    clock.every(1, () => this.#streams());
  }

  /** The adapter's bytes on the flight controller's satellite pad. */
  rx(bytes: Uint8Array): void {
    this.uart.write(bytes, this.#nowUs());
  }

  #nowUs(): number {
    return this.options.clock.now() * 1000;
  }

  #heard(bytes: Uint8Array): void {
    const before = this.#parser.stats.discardedBytes;
    this.#parser.push(bytes);
    this.ignored += this.#parser.stats.discardedBytes - before;
    for (let m = this.#parser.next(); m !== undefined; m = this.#parser.next()) {
      this.#listening = true;
      this.asked.set(m.msgid, (this.asked.get(m.msgid) ?? 0) + 1);
      const v = new DataView(m.payload.buffer, m.payload.byteOffset, m.payload.byteLength);
      if (m.msgid === MAVLINK.COMMAND_LONG.id && v.getUint16(28, true) === SET_MESSAGE_INTERVAL) {
        if (this.options.acceptsInterval === false) continue;
        const id = v.getFloat32(0, true);
        const ms = v.getFloat32(4, true) / 1000;
        if (id === MAVLINK.RC_CHANNELS.id) this.#rcEveryMs = ms;
        if (id === MAVLINK.SYS_STATUS.id) this.#sysEveryMs = ms;
      } else if (m.msgid === MAVLINK.REQUEST_DATA_STREAM.id) {
        const hz = v.getUint16(0, true);
        const stream = v.getUint8(4);
        const ms = v.getUint8(5) === 1 && hz > 0 ? 1000 / hz : 0;
        if (stream === 3) this.#rcEveryMs = ms;
        if (stream === 2) this.#sysEveryMs = ms;
      }
    }
  }

  #streams(): void {
    const now = this.options.clock.now();
    const state = this.uart.state(this.#nowUs());
    if (this.#rcEveryMs > 0 && now >= this.#nextRc) {
      this.#nextRc = now + this.#rcEveryMs;
      // PX4 sends RC_CHANNELS when its RC input updates: none while the frames are gone.
      if (!(this.options.stack === 'PX4' && state.rxLoss)) this.#send(MAVLINK.RC_CHANNELS.id, this.#rcChannels(state.channels));
    }
    if (this.#sysEveryMs > 0 && now >= this.#nextSys) {
      this.#nextSys = now + this.#sysEveryMs;
      const p = new Uint8Array(MAVLINK.SYS_STATUS.length);
      const v = new DataView(p.buffer);
      if (this.options.stack === 'ArduPilot') {
        v.setUint32(0, SENSOR_RC_RECEIVER | 0x3, true);
        v.setUint32(4, SENSOR_RC_RECEIVER | 0x3, true);
        v.setUint32(8, (state.rxLoss ? 0 : SENSOR_RC_RECEIVER) | 0x3, true);
      } else {
        const rc = this.options.reportsRc !== false && !state.rxLoss ? SENSOR_RC_RECEIVER : 0;
        v.setUint32(0, rc | 0x3, true);
        v.setUint32(4, rc | 0x3, true);
        v.setUint32(8, rc | 0x3, true);
      }
      this.#send(MAVLINK.SYS_STATUS.id, p);
    }
  }

  #heartbeat(): Uint8Array {
    const p = new Uint8Array(MAVLINK.HEARTBEAT.length);
    const failsafe = this.uart.state(this.#nowUs()).rxLoss && this.options.stack === 'ArduPilot';
    p[4] = 2; // MAV_TYPE_QUADROTOR
    p[5] = this.options.stack === 'ArduPilot' ? 3 : 12;
    p[6] = (this.options.armed ? 0x80 : 0) | 0x01;
    p[7] = failsafe ? 5 : 3;
    p[8] = 3;
    return p;
  }

  #rcChannels(us: number[]): Uint8Array {
    const p = new Uint8Array(MAVLINK.RC_CHANNELS.length);
    const v = new DataView(p.buffer);
    v.setUint32(0, this.options.clock.now() & 0xffffffff, true);
    for (let i = 0; i < 18; i++)
      v.setUint16(4 + 2 * i, i < us.length ? (us[i] as number) : this.options.stack === 'PX4' ? 0xffff : 0, true);
    v.setUint8(40, us.length);
    v.setUint8(41, 255);
    return p;
  }

  #send(msgid: number, payload: Uint8Array): void {
    this.usb.reply(encodeMavlink(msgid, payload, { seq: this.#seq++ & 0xff, sysid: 1, compid: 1 }));
  }
}
