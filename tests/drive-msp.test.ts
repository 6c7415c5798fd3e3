/**
 * MSP as Betaflight and iNav frame it: known requests byte for byte, replies parsed whatever
 * the chunking and whatever noise (CLI text, a broken frame) comes between them, and the
 * status, RC and receiver replies read field by field.
 */
import fc from 'fast-check';
import { describe, expect, it } from 'vitest';
import {
  BF_ARMING_DISABLED_RX_FAILSAFE,
  crc8DvbS2,
  encodeMsp,
  INAV_ARMING_DISABLED_RC_LINK,
  MSP,
  type MspMessage,
  MspParser,
  readBetaflightStatus,
  readFcVariant,
  readInavStatus,
  readRc,
  readSerialRxProvider,
} from '../src/drive/msp.js';

const hex = (b: Uint8Array) => Array.from(b, (x) => x.toString(16).padStart(2, '0')).join(' ');

function parseAll(bytes: Uint8Array, splits: readonly number[] = []): { messages: MspMessage[]; parser: MspParser } {
  const parser = new MspParser();
  const messages: MspMessage[] = [];
  let at = 0;
  for (let k = 0; at < bytes.length; k++) {
    const end = Math.min(bytes.length, at + (splits.length > 0 ? (splits[k % splits.length] as number) : bytes.length));
    parser.push(bytes.subarray(at, end));
    for (let m = parser.next(); m; m = parser.next()) messages.push(m);
    at = end;
  }
  return { messages, parser };
}

describe('MSP framing', () => {
  it('writes the requests Betaflight and iNav expect, byte for byte', () => {
    expect(hex(encodeMsp(MSP.API_VERSION))).toBe('24 4d 3c 00 01 01');
    expect(hex(encodeMsp(MSP.RC))).toBe('24 4d 3c 00 69 69');
    expect(hex(encodeMsp(MSP.STATUS_EX))).toBe('24 4d 3c 00 96 96');
    expect(hex(encodeMsp(MSP.INAV_STATUS))).toBe('24 58 3c 00 00 20 00 00 32');
    expect(hex(encodeMsp(MSP.API_VERSION, undefined, { version: 2 }))).toBe('24 58 3c 00 01 00 00 00 45');
    // The CRC's check value (CRC-8/DVB-S2 of "123456789").
    expect(crc8DvbS2(new TextEncoder().encode('123456789'))).toBe(0xbc);
  });

  it('reads replies back whatever the chunking, with noise, broken frames and text between them', () => {
    fc.assert(
      fc.property(
        fc.array(
          fc.record({
            cmd: fc.integer({ min: 0, max: 0x3000 }),
            payload: fc.uint8Array({ maxLength: 300 }),
            direction: fc.constantFrom<MspMessage['direction']>('reply', 'error', 'request'),
            noise: fc.uint8Array({ maxLength: 12 }).map((b) => b.map((x) => (x === 0x24 ? 0x23 : x))),
          }),
          { maxLength: 8 },
        ),
        fc.array(fc.integer({ min: 1, max: 40 }), { minLength: 1, maxLength: 8 }),
        (frames, splits) => {
          const parts: Uint8Array[] = [];
          const want: { cmd: number; payload: string; direction: string }[] = [];
          for (const f of frames) {
            if (f.direction === 'request' && f.payload.length >= 255 && f.cmd < 255) continue;
            parts.push(f.noise, encodeMsp(f.cmd, f.payload, { direction: f.direction }));
            want.push({ cmd: f.cmd, payload: hex(f.payload), direction: f.direction });
          }
          // A frame cut short, then text: never a message, never blocks the next one.
          parts.push(
            encodeMsp(MSP.RC, Uint8Array.of(1, 2, 3), { direction: 'reply' }).subarray(0, 6),
            new TextEncoder().encode('# Entering CLI\r\n'),
          );
          const bytes = new Uint8Array(parts.reduce((a, p) => a + p.length, 0));
          let at = 0;
          for (const p of parts) {
            bytes.set(p, at);
            at += p.length;
          }
          const { messages, parser } = parseAll(bytes, splits);
          expect(messages.map((m) => ({ cmd: m.cmd, payload: hex(m.payload), direction: m.direction }))).toEqual(want);
          expect(parser.stats.messages).toBe(want.length);
        },
      ),
      { numRuns: 300, seed: 2026_11_29 },
    );
  });

  it('never throws on random bytes, and holds no more than a frame', () => {
    fc.assert(
      fc.property(fc.uint8Array({ maxLength: 3000 }), (bytes) => {
        const { parser } = parseAll(bytes, [7]);
        expect(parser.stats.discardedBytes).toBeLessThanOrEqual(bytes.length);
      }),
      { numRuns: 300, seed: 7 },
    );
  });

  it('refuses a frame whose check fails, and finds the next', () => {
    const good = encodeMsp(MSP.RC, Uint8Array.of(0xdc, 0x05), { direction: 'reply' });
    const bad = good.slice();
    bad[5] = (bad[5] as number) ^ 1;
    const { messages, parser } = parseAll(new Uint8Array([...bad, ...good]));
    expect(messages).toHaveLength(1);
    expect(parser.stats.badChecks).toBe(1);
  });
});

describe('MSP replies read', () => {
  it('reads Betaflight status: armed, the arming-disable flags, RXLOSS', () => {
    // MSP_STATUS_EX as Betaflight 4.5 writes it: 22 bytes with no extra mode bytes.
    const p = new Uint8Array(22);
    const v = new DataView(p.buffer);
    v.setUint32(6, 0, true);
    v.setUint8(15, 0);
    v.setUint8(16, 26);
    v.setUint32(17, BF_ARMING_DISABLED_RX_FAILSAFE | (1 << 25), true);
    expect(readBetaflightStatus(p)).toEqual({ armed: false, armingDisableFlags: 4 | (1 << 25), armingDisableCount: 26, rxLoss: true });
    // With two extra flight-mode bytes the flags move along.
    const q = new Uint8Array(24);
    const w = new DataView(q.buffer);
    w.setUint32(6, 1, true);
    w.setUint8(15, 2);
    w.setUint8(18, 29);
    w.setUint32(19, 0, true);
    expect(readBetaflightStatus(q)).toEqual({ armed: true, armingDisableFlags: 0, armingDisableCount: 29, rxLoss: false });
    expect(readBetaflightStatus(new Uint8Array(10))).toBeNull();
  });

  it('reads iNav status, the RC channels, the variant and the receiver setting', () => {
    const s = new Uint8Array(20);
    new DataView(s.buffer).setUint32(9, INAV_ARMING_DISABLED_RC_LINK, true);
    expect(readInavStatus(s)).toEqual({ armed: false, armingFlags: INAV_ARMING_DISABLED_RC_LINK, rxLoss: true });
    expect(readRc(Uint8Array.of(0xdc, 0x05, 0xe8, 0x03))).toEqual([1500, 1000]);
    expect(readFcVariant(new TextEncoder().encode('BTFL'))).toBe('BTFL');
    expect(readSerialRxProvider(Uint8Array.of(1, 0x6c, 0x07))).toBe(1);
  });
});
