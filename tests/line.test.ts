/**
 * The simulator's line model: bytes put on a wire at one setting and read by a UART at
 * another, with the errors a real UART reports.
 */
import { describe, expect, it } from 'vitest';
import {
  CRSF_FORMAT,
  SBUS_FORMAT,
  crsfStream,
  ibusStream,
  sbusStream,
  spektrumTransmission,
  srxl2Stream,
} from '../src/simulator/protocols.js';
import {
  UART_115200_8N1,
  characterTimeUs,
  lineSignal,
  noiseSignal,
  receiveAs,
  uartReceive,
  type Transmission,
} from '../src/simulator/line.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';

const count = (r: ReturnType<typeof uartReceive>, kind: string): number => r.errors.filter((e) => e.kind === kind).length;

/** Every byte value once, back to back from t = 1000 µs. */
function everyByte(format = UART_115200_8N1): Transmission {
  const bytes = Uint8Array.from({ length: 256 }, (_, i) => i);
  const c = characterTimeUs(format);
  return { format, bytes, timesUs: Float64Array.from(bytes, (_, i) => 1000 + i * c) };
}

describe('the line model', () => {
  it('reads back every byte value sent at 115200 8N1, with its start time, and no errors', () => {
    const tx = everyByte();
    const r = receiveAs(tx);
    expect(r.errors).toEqual([]);
    expect(Array.from(r.bytes)).toEqual(Array.from(tx.bytes));
    for (let i = 0; i < 256; i++) expect(r.timesUs[i]).toBeCloseTo(tx.timesUs[i]!, 6);
  });

  it('reads back every byte value at 100000 8E2 and at 420000 8N1 when the receiver uses the same setting', () => {
    for (const format of [{ ...SBUS_FORMAT, inverted: false }, CRSF_FORMAT]) {
      const r = receiveAs(everyByte(format), format);
      expect(r.errors).toEqual([]);
      expect(Array.from(r.bytes)).toEqual(Array.from({ length: 256 }, (_, i) => i));
    }
  });

  it('reads an inverted line back when the receiver inverts too', () => {
    const r = receiveAs(everyByte(SBUS_FORMAT), SBUS_FORMAT);
    expect(r.errors).toEqual([]);
    expect(r.bytes.length).toBe(256);
  });

  it('reports a parity error for every byte sent with even parity and read with odd', () => {
    const tx = everyByte({ baudRate: 115200, parity: 'even' });
    const r = receiveAs(tx, { baudRate: 115200, parity: 'odd' });
    expect(r.bytes.length).toBe(0);
    expect(count(r, 'ParityError')).toBe(256);
  });

  it('passes a simulated satellite stream through byte for byte', () => {
    const sim = simulate(preset('dsmx-11ms-2048-internal'), 500_000);
    const r = receiveAs(spektrumTransmission(sim));
    expect(r.errors).toEqual([]);
    expect(Array.from(r.bytes)).toEqual(Array.from(sim.bytes));
  });

  it('turns SBUS (100000 8E2, inverted) read at 115200 8N1 into framing errors and one break per packet', () => {
    const tx = sbusStream({ durationUs: 1_000_000 });
    const packets = tx.bytes.length / 25;
    const r = receiveAs(tx);
    expect(count(r, 'FramingError')).toBeGreaterThan(5 * packets);
    expect(count(r, 'BreakError')).toBeGreaterThanOrEqual(packets);
    expect(count(r, 'BreakError')).toBeLessThanOrEqual(packets * 1.1);
    expect(Array.from(r.bytes.subarray(0, 25))).not.toEqual(Array.from(tx.bytes.subarray(0, 25)));
  });

  it('turns an inverted satellite line into a break per frame and bytes that are not the frame', () => {
    const sim = simulate(preset('dsmx-11ms-2048-internal'), 1_000_000);
    const frames = sim.bytes.length / 16;
    const r = receiveAs(spektrumTransmission(sim, true));
    expect(count(r, 'BreakError')).toBe(frames);
    expect(count(r, 'FramingError')).toBeGreaterThan(frames);
    expect(r.bytes.length).toBeLessThan(sim.bytes.length);
  });

  it('turns CRSF at 420000 read at 115200 into framing errors but no breaks (the line idles high)', () => {
    const r = receiveAs(crsfStream({ durationUs: 500_000 }));
    expect(count(r, 'FramingError')).toBeGreaterThan(100);
    expect(count(r, 'BreakError')).toBe(0);
  });

  it('reads IBUS and SRXL2 at 115200 8N1 cleanly: same speed, another protocol', () => {
    for (const tx of [ibusStream({ durationUs: 100_000 }), srxl2Stream({ durationUs: 100_000 })]) {
      const r = receiveAs(tx);
      expect(r.errors).toEqual([]);
      expect(Array.from(r.bytes)).toEqual(Array.from(tx.bytes));
    }
  });

  it('places a break between the bytes it falls between', () => {
    const tx: Transmission = { format: UART_115200_8N1, bytes: Uint8Array.of(0x41, 0x42), timesUs: Float64Array.of(1000, 5000) };
    const line = lineSignal(tx);
    const edges = Array.from(line.edgesUs);
    edges.push(3000, 3500); // the line held low for 500 µs between the two bytes
    const r = uartReceive({ ...line, edgesUs: Float64Array.from(edges.sort((a, b) => a - b)) });
    expect(Array.from(r.bytes)).toEqual([0x41, 0x42]);
    expect(r.errors).toHaveLength(1);
    expect(r.errors[0]).toMatchObject({ kind: 'BreakError', offset: 1 });
    expect(r.errors[0]!.timeUs).toBeCloseTo(3000, 0);
  });

  it('reads noise as a mix of breaks, framing errors and random bytes', () => {
    const r = uartReceive(noiseSignal({ durationUs: 200_000, seed: 7 }));
    expect(count(r, 'BreakError')).toBeGreaterThan(10);
    expect(count(r, 'FramingError')).toBeGreaterThan(10);
  });

  it('rejects a line setting it cannot model', () => {
    expect(() => receiveAs(everyByte(), { baudRate: 0 })).toThrow(RangeError);
    expect(() => lineSignal({ ...everyByte(), format: { baudRate: 9600, stopBits: 3 as 1 } })).toThrow(RangeError);
  });
});
