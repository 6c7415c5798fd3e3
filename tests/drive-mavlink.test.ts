/**
 * MAVLink as ArduPilot and PX4 frame it: SatScope's requests byte for byte, messages parsed
 * whatever the chunking and whatever else streams between them (messages it does not read,
 * signed frames, noise), and HEARTBEAT, SYS_STATUS and RC_CHANNELS read field by field.
 */
import fc from 'fast-check';
import { describe, expect, it } from 'vitest';
import {
  crc16Mcrf4xx,
  encodeMavlink,
  gcsHeartbeat,
  MAV_STATE_CRITICAL,
  MAVLINK,
  type MavlinkMessage,
  MavlinkParser,
  readHeartbeat,
  readRcChannels,
  readRcReceiverHealth,
  requestDataStream,
  requestMessageInterval,
  SENSOR_RC_RECEIVER,
  autopilotName,
  DATA_STREAM,
} from '../src/drive/mavlink.js';
import { concatBytes } from './bytes.js';

const hex = (b: Uint8Array) => Array.from(b, (x) => x.toString(16).padStart(2, '0')).join(' ');

function parseAll(bytes: Uint8Array, step = bytes.length): { messages: MavlinkMessage[]; parser: MavlinkParser } {
  const parser = new MavlinkParser();
  const messages: MavlinkMessage[] = [];
  for (let i = 0; i < bytes.length; i += step) {
    parser.push(bytes.subarray(i, i + step));
    for (let m = parser.next(); m; m = parser.next()) messages.push(m);
  }
  return { messages, parser };
}

/** RC_CHANNELS as an autopilot sends it (sysid 1, compid 1). */
function rcChannels(us: number[], rssi: number, seq = 0): Uint8Array {
  const p = new Uint8Array(MAVLINK.RC_CHANNELS.length);
  const v = new DataView(p.buffer);
  v.setUint32(0, 123_456, true);
  for (let i = 0; i < 18; i++) v.setUint16(4 + 2 * i, us[i] ?? 0xffff, true);
  v.setUint8(40, us.length);
  v.setUint8(41, rssi);
  return encodeMavlink(MAVLINK.RC_CHANNELS.id, p, { seq, sysid: 1, compid: 1 });
}

describe('MAVLink framing', () => {
  it("writes SatScope's requests as ArduPilot and PX4 expect them, byte for byte", () => {
    expect(crc16Mcrf4xx(new TextEncoder().encode('123456789'))).toBe(0x6f91);
    expect(hex(gcsHeartbeat(0))).toBe('fd 09 00 00 00 ff be 00 00 00 00 00 00 00 06 08 00 00 03 5c 2b');
    // SET_MESSAGE_INTERVAL for RC_CHANNELS at 20 Hz, its trailing zero (confirmation) dropped.
    expect(hex(requestMessageInterval(65, 50_000))).toBe(
      `fd 20 00 00 00 ff be 4c 00 00 00 00 82 42 00 50 43 47 ${'00 '.repeat(20)}ff 01 01 01 d2 13`,
    );
    // REQUEST_DATA_STREAM (66, CRC_EXTRA 148) for RC_CHANNELS at 20 Hz, start: the CRC worked out apart from this code.
    expect(hex(requestDataStream(DATA_STREAM.RC_CHANNELS, 20))).toBe('fd 06 00 00 00 ff be 42 00 00 14 00 01 01 03 01 d4 8b');
    expect([autopilotName(3), autopilotName(12), autopilotName(0)]).toEqual(['ArduPilot', 'PX4', 'MAV_AUTOPILOT 0']);
  });

  it('reads the messages it knows whatever the chunking, among others, signed frames and noise', () => {
    fc.assert(
      fc.property(
        fc.array(fc.integer({ min: 900, max: 2100 }), { minLength: 1, maxLength: 18 }),
        fc.integer({ min: 1, max: 50 }),
        fc.uint8Array({ maxLength: 40 }),
        (us, step, noise) => {
          // An ATTITUDE (30) frame, which this reader has no CRC_EXTRA for, and a signed HEARTBEAT.
          const attitude = Uint8Array.of(0xfd, 4, 0, 0, 9, 1, 1, 30, 0, 0, 1, 2, 3, 4, 0x11, 0x22);
          const hb = encodeMavlink(MAVLINK.HEARTBEAT.id, Uint8Array.of(4, 0, 0, 0, 2, 3, 0x81, MAV_STATE_CRITICAL, 3), {
            sysid: 1,
            compid: 1,
          });
          const signed = new Uint8Array(hb.length + 13);
          signed.set(hb);
          // Signed: the flag byte is under the CRC, so it is worked out again; the 13 signature bytes are not.
          signed[2] = 1;
          const crc = crc16Mcrf4xx(signed, 1, hb.length - 2);
          const extra = ((): number => {
            let t = (MAVLINK.HEARTBEAT.crcExtra ^ crc) & 0xff;
            t = (t ^ (t << 4)) & 0xff;
            return ((crc >> 8) ^ (t << 8) ^ (t << 3) ^ (t >> 4)) & 0xffff;
          })();
          signed[hb.length - 2] = extra & 0xff;
          signed[hb.length - 1] = extra >> 8;
          const bytes = concatBytes([
            noise.map((b) => (b === 0xfd || b === 0xfe ? 0 : b)),
            attitude,
            rcChannels(us, 200),
            signed,
            rcChannels(us, 255, 1),
          ]);
          const { messages } = parseAll(bytes, step);
          expect(messages.map((m) => m.msgid)).toEqual([65, 0, 65]);
          const rc = readRcChannels(messages[0] as MavlinkMessage);
          expect(rc.channels.slice(0, us.length)).toEqual(us);
          expect(rc.channels.slice(us.length).every((c) => c === null)).toBe(true);
          expect([rc.count, rc.rssi]).toEqual([us.length, 200]);
          expect(readRcChannels(messages[2] as MavlinkMessage).rssi).toBeNull();
          expect(readHeartbeat(messages[1] as MavlinkMessage)).toEqual({
            customMode: 4,
            type: 2,
            autopilot: 3,
            armed: true,
            systemStatus: MAV_STATE_CRITICAL,
          });
        },
      ),
      { numRuns: 200, seed: 29 },
    );
  });

  it('never throws on random bytes, and refuses a frame whose check fails', () => {
    fc.assert(
      fc.property(fc.uint8Array({ maxLength: 3000 }), (bytes) => {
        const { parser } = parseAll(bytes, 13);
        expect(parser.stats.discardedBytes).toBeLessThanOrEqual(bytes.length);
      }),
      { numRuns: 300, seed: 3 },
    );
    const bad = rcChannels([1500], 10);
    bad[12] = (bad[12] as number) ^ 4;
    const { messages, parser } = parseAll(concatBytes([bad, rcChannels([1500], 10)]));
    expect(messages).toHaveLength(1);
    expect(parser.stats.badChecks).toBe(1);
  });

  it("reads SYS_STATUS's RC receiver health, its payload zero-filled where the sender cut it", () => {
    const p = new Uint8Array(MAVLINK.SYS_STATUS.length);
    const v = new DataView(p.buffer);
    v.setUint32(0, SENSOR_RC_RECEIVER, true);
    v.setUint32(4, SENSOR_RC_RECEIVER, true);
    const lost = parseAll(encodeMavlink(MAVLINK.SYS_STATUS.id, p)).messages[0] as MavlinkMessage;
    expect(lost.payload).toHaveLength(MAVLINK.SYS_STATUS.length);
    expect(readRcReceiverHealth(lost)).toEqual({ present: true, healthy: false });
    v.setUint32(8, SENSOR_RC_RECEIVER, true);
    expect(readRcReceiverHealth(parseAll(encodeMavlink(MAVLINK.SYS_STATUS.id, p)).messages[0] as MavlinkMessage)).toEqual({
      present: true,
      healthy: true,
    });
  });
});
