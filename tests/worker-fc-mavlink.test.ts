/**
 * The flight controller's own view over MAVLink, in Node: the drive port's TX feeds a fake
 * ArduPilot or PX4 (tests/fake-mavlink-fc.ts: their shared DSM decoder, throttle on RC3), whose
 * USB port, a second stand-in, speaks MAVLink v2. The worker must find the stack by its
 * HEARTBEAT (PX4 only after it hears MAVLink), ask for RC_CHANNELS and SYS_STATUS, and tell the
 * page what it said: armed, its channels in its own order, the receiver lost when the drive
 * stops; and grade a scenario against ArduPilot's order.
 */
import { describe, expect, it } from 'vitest';
import { MAVLINK } from '../src/drive/mavlink.js';
import { driveReportHtml, fixFor } from '../src/drive/report.js';
import type { FcStatus } from '../src/worker/fc.js';
import { FakeMavlinkFc } from './fake-mavlink-fc.js';
import { fakeHost, portRig, StandInPort } from './worker-fakes.js';

const ADAPTER = { index: 0, usbVendorId: 0x0403, usbProductId: 1 };
const FC_USB = { index: 1, usbVendorId: 0x1209, usbProductId: 1 };

function setup(stack: 'ArduPilot' | 'PX4', options: { armed?: boolean; acceptsInterval?: boolean; reportsRc?: boolean } = {}) {
  const fake = fakeHost();
  const fc = new FakeMavlinkFc({ stack, clock: fake.clock, ...options });
  const adapter = new StandInPort(0x0403, (bytes) => fc.rx(bytes));
  const ports = [adapter, fc.usb];
  const { worker, send, run } = portRig(fake, async (id) => ports.find((p) => p.vid === id.usbVendorId) as unknown as SerialPort);
  const fcNow = (): FcStatus | undefined => fake.of('fc').at(-1)?.fc;
  const drive = (scenario: string, channels = 8) =>
    send({
      type: 'drive-start',
      port: ADAPTER,
      receiver: { system: 0xb2, remote: 'internal', channels },
      scenario,
      throttleCeilingPercent: 100,
    });
  return { ...fake, fc, worker, send, run, fcNow, drive };
}

describe("the flight controller's own view over MAVLink", () => {
  it('finds ArduPilot by its HEARTBEAT, asks for its channels, and says what it read: RC3 throttle, armed, RC failsafe', async () => {
    const { send, run, fcNow, worker, fc, drive } = setup('ArduPilot', { armed: true });
    await send({ type: 'fc-open', port: FC_USB });
    await run(1500);
    // Found by its heartbeat, and asked for RC_CHANNELS and SYS_STATUS (SET_MESSAGE_INTERVAL and REQUEST_DATA_STREAM).
    expect(fcNow()).toMatchObject({ state: 'reading', protocol: 'mavlink', variant: 'ArduPilot', armed: true });
    expect(fc.asked.get(MAVLINK.COMMAND_LONG.id)).toBeGreaterThanOrEqual(2);
    expect(fc.asked.get(MAVLINK.REQUEST_DATA_STREAM.id)).toBeGreaterThanOrEqual(2);
    // No frame yet: ArduPilot reports its RC receiver unhealthy (radio failsafe).
    expect(fcNow()?.rxLoss).toBe(true);
    await drive('manual');
    worker.receive({ type: 'drive-channel', id: 1, percent: 50 });
    await run(1500);
    const live = fcNow();
    expect(live?.rxLoss).toBe(false);
    // RC1 is the aileron at +50 %: 1024 + 342 sent, 1500 + (1366 − 1024) × 1000 / 1700 = 1701 µs by its rule.
    expect(live?.channels?.[0]).toBeGreaterThanOrEqual(1700);
    expect(live?.channels?.[0]).toBeLessThanOrEqual(1702);
    // RC3 is the throttle at −100 %: 341 sent, 1500 + (341 − 1024) × 1000 / 1700 = 1099 µs (truncated towards 0, as in C).
    expect(live?.channels?.[2]).toBe(1099);
    expect(live?.channels).toHaveLength(8);
    worker.receive({ type: 'drive-stop' });
    // Its failsafe after RC_FS_TIMEOUT (1 s): SYS_STATUS says the receiver unhealthy, HEARTBEAT critical.
    await run(2500);
    expect(fcNow()).toMatchObject({ rxLoss: true, failsafe: true });
    // Over 6.5 s it was never sent a ground station's heartbeat (whose stop is its GCS failsafe).
    expect(fc.asked.get(MAVLINK.HEARTBEAT.id) ?? 0).toBe(0);
    await send({ type: 'fc-close' });
    expect(fcNow()?.state).toBe('closed');
  });

  it('wakes a PX4 that waits to hear MAVLink, and reads the receiver lost when its RC drops out of SYS_STATUS', async () => {
    const { send, run, fcNow, fc, drive, worker } = setup('PX4');
    await send({ type: 'fc-open', port: FC_USB });
    await run(800);
    // MSP first: a Betaflight would have answered. PX4 ignores it and says nothing yet.
    expect(fcNow()?.protocol).toBeNull();
    expect(fc.ignored).toBeGreaterThan(0);
    expect(fc.asked.size).toBe(0);
    await run(3500);
    // Then a GCS heartbeat (after 2.5 s without MSP or a HEARTBEAT): PX4 starts MAVLink, is found, and asked for its streams.
    expect(fc.asked.get(MAVLINK.HEARTBEAT.id)).toBeGreaterThanOrEqual(1);
    expect(fcNow()).toMatchObject({ protocol: 'mavlink', variant: 'PX4', armed: false });
    // It has never said it has a receiver: not said, never guessed.
    expect(fcNow()?.rxLoss).toBeNull();
    await drive('manual');
    await run(1000);
    expect(fcNow()?.channels?.[2]).toBe(1099);
    expect(fcNow()?.rxLoss).toBe(false);
    worker.receive({ type: 'drive-stop' });
    await run(1000);
    expect(fcNow()?.rxLoss).toBe(true);
  });

  it('says nothing of the receiver state of a PX4 that does not report it', async () => {
    const { send, run, fcNow, drive } = setup('PX4', { reportsRc: false });
    await send({ type: 'fc-open', port: FC_USB });
    await run(4500);
    await drive('manual');
    await run(1000);
    expect(fcNow()?.channels?.[2]).toBe(1099);
    expect(fcNow()?.rxLoss).toBeNull();
  });

  it('asks an older ArduPilot by REQUEST_DATA_STREAM when SET_MESSAGE_INTERVAL is not taken', async () => {
    const { send, run, fcNow } = setup('ArduPilot', { acceptsInterval: false });
    await send({ type: 'fc-open', port: FC_USB });
    await run(1500);
    expect(fcNow()?.rxLoss).toBe(true);
    expect(fcNow()?.replies).toBeGreaterThan(10);
  });

  it("grades scenarios against ArduPilot's channel order and failsafe, and says what to change in its parameters", async () => {
    const { send, run, of, drive } = setup('ArduPilot');
    await send({ type: 'fc-open', port: FC_USB });
    await run(1200);
    const play = async (scenario: string) => {
      await drive(scenario, 4);
      await run(Math.ceil((of('drive').at(-1)?.drive.durationUs ?? 0) / 1000) + 500);
      const done = of('drive').at(-1)?.drive;
      expect(done?.state).toBe('ended');
      expect(done?.gradeNote).toMatch(/Graded on \d+ readings/);
      const checks = Object.fromEntries((done?.checks ?? []).map((c) => [c.id, c]));
      console.log(`ArduPilot graded on ${scenario}: ${JSON.stringify(Object.values(checks).map((c) => [c.id, c.verdict, c.found]))}`);
      return { done: done!, checks };
    };
    const sweep = await play('sweep');
    // Throttle on RC3 is ArduPilot's order: a pass, where Betaflight's order would fail.
    expect(sweep.checks['channel-map']?.verdict).toBe('pass');
    // Its own scale is not §9's: the fix is in ArduPilot's words.
    const values = sweep.checks.values;
    expect(values?.verdict).toBe('fail');
    const fcSaid = { variant: 'ArduPilot', provider: null };
    expect(fixFor(values!, { receiver: sweep.done.receiver, fc: fcSaid })).toMatch(/RC_PROTOCOLS/);
    const html = driveReportHtml({
      date: '2026-11-30T00:00:00Z',
      scenario: { name: sweep.done.name, title: sweep.done.title },
      receiver: sweep.done.receiver,
      timing: sweep.done.timing,
      fc: fcSaid,
      checks: sweep.done.checks ?? [],
      notes: [],
    });
    expect(html).toContain('Flight controller: ArduPilot');
    expect(html).not.toContain('serialrx_provider');
    // The 1.2 s and 5 s silences reach its 1 s RC failsafe and it reports them; back when frames return.
    const dropouts = await play('dropouts');
    expect(dropouts.checks.failsafe?.verdict).toBe('pass');
    expect(dropouts.checks.failsafe?.found).toMatch(/500\d ms silence: lost after 1\d\d\d ms, back after \d+ ms/);
  }, 120_000);
});
