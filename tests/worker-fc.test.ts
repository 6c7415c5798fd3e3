/**
 * The flight controller's own view in the worker, in Node: the drive port's TX feeds a fake
 * Betaflight (tests/fake-fc.ts: a 5 ms gap ends a frame, 11 bits by its setting, RXLOSS 100 ms
 * after the last frame), and a second stand-in port answers MSP as its USB port would. What the
 * page is told must be what the flight controller answered: its stack, its receiver setting, its
 * channels in its own order, armed, and RXLOSS when the drive stops.
 */
import { describe, expect, it } from 'vitest';
import { driveReportHtml } from '../src/drive/report.js';
import type { FcStatus } from '../src/worker/fc.js';
import { FakeBetaflightUsb, FakeFc } from './fake-fc.js';
import { StandInPort, fakeHost, portRig } from './worker-fakes.js';

function setup(resolution: 1024 | 2048, map = 'TAER1234') {
  const fake = fakeHost();
  const fcUart = new FakeFc({ resolution, map });
  const nowUs = () => fake.clock.now() * 1000;
  const adapter = new StandInPort(0x0403, (bytes) => fcUart.write(bytes, nowUs()));
  const betaflight = new FakeBetaflightUsb(fcUart, resolution);
  const usb = new StandInPort(0x0483, (bytes, port) => {
    for (const reply of betaflight.push(bytes, nowUs())) port.reply(reply);
  });
  const ports = [adapter, usb];
  const { worker, send, run } = portRig(fake, async (id) => ports.find((p) => p.vid === id.usbVendorId) as unknown as SerialPort);
  const fcNow = (): FcStatus | undefined => fake.of('fc').at(-1)?.fc;
  return { ...fake, worker, send, run, fcNow };
}

const ADAPTER = { index: 0, usbVendorId: 0x0403, usbProductId: 1 };
const FC_USB = { index: 1, usbVendorId: 0x0483, usbProductId: 1 };

describe("the flight controller's own view while driving it", () => {
  it('says what Betaflight answered: its stack, setting, channels in its order, and RXLOSS when the frames stop', async () => {
    const { send, run, fcNow, worker } = setup(2048);
    await send({ type: 'fc-open', port: FC_USB });
    await run(600);
    // Nothing driven yet: the flight controller says so.
    expect(fcNow()).toMatchObject({ state: 'reading', variant: 'BTFL', provider: 'SPEKTRUM2048', armed: false, rxLoss: true });
    await send({
      type: 'drive-start',
      port: ADAPTER,
      receiver: { system: 0xb2, remote: 'internal', channels: 8 },
      scenario: 'manual',
      throttleCeilingPercent: 100,
    });
    worker.receive({ type: 'drive-channel', id: 1, percent: 50 });
    await run(1500);
    const live = fcNow();
    expect(live?.rxLoss).toBe(false);
    // Betaflight's order is roll, pitch, yaw, throttle: aileron at +50 % is 1024 + 342 sent, 988 + v/2 = 1671 µs by its rule.
    expect(live?.channels?.[0]).toBeGreaterThanOrEqual(1670);
    expect(live?.channels?.[0]).toBeLessThanOrEqual(1672);
    // Throttle at rest, −100 %: 1024 − 684 sent, 988 + 340/2 = 1158 µs.
    expect(live?.channels?.[3]).toBe(1158);
    worker.receive({ type: 'drive-stop' });
    await run(600);
    expect(fcNow()?.rxLoss).toBe(true);
    await send({ type: 'fc-close' });
    expect(fcNow()?.state).toBe('closed');
  });

  it('says the flight controller is silent when nothing answers, and shows no value it did not send', async () => {
    const fake = fakeHost();
    const mute = new StandInPort(0x0483, () => undefined);
    const { send, run } = portRig(fake, async () => mute as unknown as SerialPort);
    await send({ type: 'fc-open', port: FC_USB });
    await run(1500);
    expect(fake.of('fc').at(-1)?.fc).toMatchObject({
      state: 'silent',
      variant: null,
      channels: null,
      armed: null,
      rxLoss: null,
      replies: 0,
    });
  });

  it('grades a built-in scenario against what the flight controller read, and the report says it', async () => {
    // Betaflight set to AETR1234 while Spektrum sends throttle first: its roll follows the throttle.
    const { send, run, of } = setup(2048, 'AETR1234');
    await send({ type: 'fc-open', port: FC_USB });
    await run(300);
    await send({
      type: 'drive-start',
      port: ADAPTER,
      receiver: { system: 0xb2, remote: 'internal', channels: 4 },
      scenario: 'sweep',
      throttleCeilingPercent: 100,
    });
    await run(19_000);
    const done = of('drive').at(-1)?.drive;
    expect(done?.state).toBe('ended');
    const checks = Object.fromEntries((done?.checks ?? []).map((c) => [c.id, c]));
    expect(checks['channel-map']?.verdict).toBe('fail');
    expect(checks['channel-map']?.found).toMatch(/its channel 1 follows Throttle/);
    expect(done?.gradeNote).toMatch(/Graded on \d+ readings/);
    const html = driveReportHtml({
      date: '2026-11-29T00:00:00Z',
      scenario: { name: done?.name ?? '', title: done?.title ?? '' },
      receiver: done!.receiver,
      timing: done!.timing,
      fc: { variant: 'BTFL', provider: 'SPEKTRUM2048' },
      checks: done?.checks ?? [],
      notes: [],
    });
    expect(html).toContain('map TAER1234');
    expect(html).not.toMatch(/<script|https?:\/\//);
  });

  it('grades a drive by hand (the sticks alone run an hour) over its last 2 minutes, on the sticks that moved', async () => {
    const { send, run, of, worker } = setup(2048);
    await send({ type: 'fc-open', port: FC_USB });
    await run(300);
    await send({
      type: 'drive-start',
      port: ADAPTER,
      receiver: { system: 0xb2, remote: 'internal', channels: 6 },
      scenario: 'manual',
      throttleCeilingPercent: 100,
    });
    // Three minutes of the aileron stepped by hand every 2 s, the other sticks left alone.
    for (let s = 0; s < 90; s++) {
      worker.receive({ type: 'drive-channel', id: 1, percent: s % 2 === 0 ? 60 : -40 });
      await run(2000);
    }
    await send({ type: 'drive-stop' });
    const done = of('drive').at(-1)?.drive;
    expect(done?.gradeNote).toMatch(
      /^Graded on \d+ readings of the flight controller's channels, over the drive's last 2 minutes \(from 6\d s\)\.$/,
    );
    const checks = Object.fromEntries((done?.checks ?? []).map((c) => [c.id, c]));
    expect(checks['channel-map']).toMatchObject({
      verdict: 'pass',
      found: 'As expected (Elevator, Rudder, Throttle: no channel followed them).',
    });
    expect(checks.latency?.verdict).toBe('pass');
    expect(checks.latency?.found).toMatch(/^60 steps/);
    expect(checks.steady?.verdict).toBe('pass');
  }, 60_000);

  it('does not grade a drive the flight controller was not read during, and says so', async () => {
    const { send, run, of } = setup(2048);
    await send({
      type: 'drive-start',
      port: ADAPTER,
      receiver: { system: 0xb2, remote: 'internal', channels: 4 },
      scenario: 'dropouts',
      throttleCeilingPercent: 100,
    });
    await run(500);
    await send({ type: 'drive-stop' });
    const done = of('drive').at(-1)?.drive;
    expect(done?.checks).toBeNull();
    expect(done?.gradeNote).toMatch(/not read during the drive/);
  });
});

describe('every built-in scenario, graded against the fake Betaflight', () => {
  it('grades each end to end and says what it measured; the fake reads by its stack rules, so the verdicts are its', async () => {
    const { builtinScenarios } = await import('../src/drive/builtins.js');
    const { scenarioDurationUs } = await import('../src/drive/scenario.js');
    const receiver = { system: 0xb2, remote: 'internal', channels: 6 } as const;
    const rows: string[] = [];
    const verdicts: Record<string, Record<string, string>> = {};
    for (const scenario of builtinScenarios(receiver)) {
      const { send, run, of } = setup(2048);
      await send({ type: 'fc-open', port: FC_USB });
      await run(300);
      await send({ type: 'drive-start', port: ADAPTER, receiver, scenario: scenario.name, throttleCeilingPercent: 100 });
      await run(scenarioDurationUs(scenario) / 1000 + 1500);
      const done = of('drive').at(-1)?.drive;
      expect(done?.state, scenario.name).toBe('ended');
      expect(done?.checks, `${scenario.name}: ${done?.gradeNote}`).not.toBeNull();
      const checks = done?.checks ?? [];
      rows.push(`${scenario.name}: ${checks.map((c) => `${c.id} ${c.verdict} (${c.found})`).join('; ')}`);
      verdicts[scenario.name] = Object.fromEntries(checks.map((c) => [c.id, c.verdict]));
    }
    console.log(`every built-in against the fake Betaflight:\n${rows.join('\n')}`);
    // Betaflight's rules (fake-fc.ts): its own scale (988 + v/2, some 57 µs off §9 at the ends),
    // the resolution from its setting (not the system byte: 1024 data under 0xB2, and a rebind
    // to 1024, read wrong), frames cut by silence alone (a truncated frame glued to noise is
    // read), IDs 12 and over and 0xFFFF dropped, RXLOSS 100 ms after the last frame.
    const still = { 'channel-map': 'unknown', values: 'unknown', latency: 'unknown', failsafe: 'unknown', steady: 'pass' };
    expect(verdicts).toEqual({
      sweep: { 'channel-map': 'pass', values: 'fail', latency: 'pass', failsafe: 'unknown', steady: 'pass' },
      steps: { 'channel-map': 'pass', values: 'fail', latency: 'pass', failsafe: 'unknown', steady: 'pass' },
      dropouts: { ...still, failsafe: 'pass' },
      fades: still,
      'lying-system-byte': { ...still, steady: 'fail' },
      'empty-slots': still,
      xplus: still,
      vtx: still,
      damage: { ...still, steady: 'fail' },
      'period-switch': still,
      rebind: { ...still, failsafe: 'pass', steady: 'fail' },
    });
  }, 120_000);
});
