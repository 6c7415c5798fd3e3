/**
 * Drive in the worker, in Node: a stand-in port whose TX is kept (with the fake clock's time of
 * each write) and, for the loopback self-test, wired back to its own RX. What is written must
 * be frames of 16 bytes with at least 8 ms of silence before each, decode in SatScope's decoder
 * to the frames the scenario meant, stop at once when told, and never push the throttle past
 * the ceiling.
 */
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { BYTE_TIME_US, servoToPercent } from '../src/decoder/spec.js';
import { MIN_SILENCE_US } from '../src/drive/schedule.js';
import type { DriveStatus } from '../src/worker/drive.js';
import { StandInPort, fakeHost, portRig } from './worker-fakes.js';

/** The adapter: its writes kept with the fake clock's time; `loopback`: what it writes comes back on its RX. */
function txPort(now: () => number, loopback: boolean) {
  const writes: { atMs: number; bytes: Uint8Array }[] = [];
  const port = new StandInPort(0x0403, (bytes, p) => {
    writes.push({ atMs: now(), bytes });
    if (loopback) p.reply(bytes.slice());
  });
  return Object.assign(port, { writes });
}

const PORT = { index: 0, usbVendorId: 0x0403, usbProductId: 0x6001 };

function setup(loopback = false) {
  const fake = fakeHost();
  const port = txPort(() => fake.clock.now(), loopback);
  const { worker, send, run } = portRig(fake, async () => port as unknown as SerialPort);
  const status = (): DriveStatus | undefined => fake.of('drive').at(-1)?.drive;
  return { ...fake, port, worker, send, run, status };
}

/** A decoded frame kept: its header and channel positions by id. */
interface Read {
  system: number | null;
  resolution: 1024 | 2048;
  positions: Map<number, number>;
}

/** Decodes the writes as a flight controller's UART would see them: each byte at its time on the wire. */
function decodeWrites(writes: { atMs: number; bytes: Uint8Array }[]): Read[] {
  const frames: Read[] = [];
  const d = new SpektrumDecoder();
  for (let k = 0; k <= writes.length; k++) {
    const w = writes[k];
    if (w === undefined) d.end();
    else
      d.push(
        w.bytes,
        new Float64Array(w.bytes.length).map((_, i) => w.atMs * 1000 + (i + 1) * BYTE_TIME_US),
      );
    for (let f = d.next(); f !== undefined; f = d.next()) {
      const positions = new Map<number, number>();
      for (let i = 0; i < f.count; i++) positions.set(f.ids[i] as number, f.positions[i] as number);
      frames.push({ system: f.system, resolution: f.resolution, positions });
    }
  }
  return frames;
}

const DSMX_11 = { system: 0xb2, remote: 'internal' as const, channels: 8 };

describe('driving a flight controller from the worker', () => {
  it('writes each frame whole, 11 ms apart with the silence flight stacks need, and the decoder reads them', async () => {
    const { send, run, port, status } = setup();
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'sweep', throttleCeilingPercent: 100 });
    await run(3000);
    const frames = port.writes.filter((w) => w.bytes.length === 16);
    expect(frames.length).toBe(port.writes.length);
    expect(frames.length).toBeGreaterThan(260);
    for (let i = 1; i < frames.length; i++) {
      const gap = (frames[i]?.atMs ?? 0) - (frames[i - 1]?.atMs ?? 0);
      expect(gap).toBeCloseTo(11, 1);
      expect(gap - (16 * BYTE_TIME_US) / 1000).toBeGreaterThanOrEqual(MIN_SILENCE_US / 1000);
    }
    const decoded = decodeWrites(port.writes);
    expect(decoded.length).toBe(frames.length);
    expect(decoded.every((f) => f.system === 0xb2 && f.resolution === 2048)).toBe(true);
    const s = status();
    expect(s).toMatchObject({ state: 'driving', name: 'sweep' });
    // The status the page last got (every 250 ms): the schedule's own account of the same writes.
    expect(s?.timing.frames).toBeGreaterThan(frames.length - 25);
    expect(s?.timing.skipped).toBe(0);
    expect(s?.timing.minSilenceUs).toBeGreaterThanOrEqual(MIN_SILENCE_US);
    expect(Math.abs((s?.timing.interval?.p50 ?? 0) - 11_000)).toBeLessThanOrEqual(100);
    expect(s?.sent?.system).toBe(0xb2);
    // Every channel's newest value, though a frame of a pair carries half of them.
    expect(s?.sent?.us.filter(Number.isFinite).length).toBe(8);
  });

  it('stops at once when told, not behind a command under way, and says why', async () => {
    const { send, run, port, worker, status } = setup();
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'manual', throttleCeilingPercent: 100 });
    await run(500);
    const before = port.writes.length;
    worker.receive({ type: 'drive-stop' });
    await run(500);
    expect(port.writes.length).toBe(before);
    expect(status()).toMatchObject({ state: 'stopped', reason: 'stopped by the user' });
  });

  it('holds the sticks the page sets, and never sends throttle past the ceiling', async () => {
    const { send, run, port, worker } = setup();
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'manual', throttleCeilingPercent: -50 });
    worker.receive({ type: 'drive-channel', id: 0, percent: 100 });
    worker.receive({ type: 'drive-channel', id: 1, percent: 40 });
    await run(400);
    const last = decodeWrites(port.writes).slice(-4);
    const percent = (f: Read, id: number) => {
      const pos = f.positions.get(id);
      return pos === undefined ? Number.NaN : servoToPercent(pos, f.resolution);
    };
    for (const f of last) {
      const throttle = percent(f, 0);
      if (!Number.isNaN(throttle)) expect(throttle).toBeLessThanOrEqual(-49.5);
      const aileron = percent(f, 1);
      if (!Number.isNaN(aileron)) expect(aileron).toBeCloseTo(40, 0);
    }
  });

  it('ends with the scenario, and a user scenario in JSON is checked first', async () => {
    const { send, run, port, status, of } = setup();
    const mine = {
      name: 'short',
      title: 'Half a second of DSM2 22 ms, then silence.',
      steps: [
        { note: 'DSM2 22 ms', durationUs: 500_000, receiver: { system: 0x01, remote: 'internal', channels: 6 } },
        { note: 'Silent', durationUs: 300_000 },
      ],
    };
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: JSON.stringify(mine), throttleCeilingPercent: 100 });
    await run(1000);
    expect(status()).toMatchObject({ state: 'ended', name: 'short' });
    expect(port.writes.length).toBeGreaterThan(20);
    expect(port.writes.length).toBeLessThan(25);
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: '{"name":"x"}', throttleCeilingPercent: 100 });
    expect(of('notice').at(-1)).toMatchObject({ title: 'The scenario cannot be driven' });
  });

  it('decodes its own output through the loopback: the frames the adapter read are the frames it wrote', async () => {
    const { send, run, port, worker, status } = setup(true);
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'manual', throttleCeilingPercent: 100 });
    await run(2000);
    const source = worker.registry.get(status()?.source ?? -1);
    expect(source).toBeDefined();
    const link = source?.engine.link.stats;
    expect(link?.frames).toBeGreaterThanOrEqual(port.writes.length - 1);
    expect(link?.missedFrames).toBe(0);
    expect(link?.nominalPeriodUs).toBe(11_000);
  });

  it("keeps going through a scenario's silences: a rebind runs to its end, frames after the silent step", async () => {
    const { send, run, port, status } = setup();
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'rebind', throttleCeilingPercent: 100 });
    await run(6000);
    expect(status()?.state).toBe('driving');
    await run(6000);
    expect(status()).toMatchObject({ state: 'ended', reason: 'the scenario ended' });
    // 5 s as bound, 1.5 s silent, 5 s in the other format.
    const after = port.writes.filter((w) => w.atMs > 1000 + 6_600);
    expect(after.length).toBeGreaterThan(200);
    expect(port.writes.filter((w) => w.atMs > 1000 + 5_100 && w.atMs < 1000 + 6_400)).toEqual([]);
  });

  it('a stop sent while the start is still opening the port wins', async () => {
    const { worker, run, port, status } = setup();
    worker.receive({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'manual', throttleCeilingPercent: 100 });
    worker.receive({ type: 'drive-stop' });
    await worker.queue.idle();
    await run(300);
    expect(port.writes).toEqual([]);
    expect(status()?.state).not.toBe('driving');
  });

  it('sends the sticks the page holds from the first frame of a new drive', async () => {
    const { send, run, port } = setup();
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'manual', throttleCeilingPercent: 100, held: { 1: 100 } });
    await run(60);
    const first = decodeWrites(port.writes).find((f) => f.positions.has(1));
    expect(servoToPercent(first?.positions.get(1) ?? 0, 2048)).toBeCloseTo(100, 0);
  });

  it('stops when its port is closed from the page', async () => {
    const { send, run, port, status } = setup();
    await send({ type: 'drive-start', port: PORT, receiver: DSMX_11, scenario: 'manual', throttleCeilingPercent: 100 });
    await run(200);
    await send({ type: 'serial-close', source: status()?.source ?? -1 });
    const before = port.writes.length;
    await run(300);
    expect(port.writes.length).toBe(before);
    expect(status()).toMatchObject({ state: 'stopped', reason: 'its port was closed' });
  });
});
