/**
 * The flight controller's own view in the worker, in Node: the drive port's TX feeds a fake
 * Betaflight (tests/fake-fc.ts: a 5 ms gap ends a frame, 11 bits by its setting, RXLOSS 100 ms
 * after the last frame), and a second stand-in port answers MSP as its USB port would. What the
 * page is told must be what the flight controller answered: its stack, its receiver setting, its
 * channels in its own order, armed, and RXLOSS when the drive stops.
 */
import { describe, expect, it } from 'vitest';
import { MSP, MspParser, encodeMsp } from '../src/drive/msp.js';
import { driveReportHtml } from '../src/drive/report.js';
import type { FcStatus } from '../src/worker/fc.js';
import { FakeFc } from './fake-fc.js';
import { StandInPort, fakeHost, portRig } from './worker-fakes.js';

const le16 = (values: number[]) => new Uint8Array(values.flatMap((v) => [v & 0xff, v >> 8]));

/** Betaflight's MSP_STATUS_EX reply: armed in the flight-mode flags (offset 6), no extra mode bytes, then the arming-disable flags. */
function statusEx(armed: boolean, rxLoss: boolean): Uint8Array {
  const p = new Uint8Array(22);
  const v = new DataView(p.buffer);
  v.setUint32(6, armed ? 1 : 0, true);
  p[15] = 0;
  p[16] = 26;
  v.setUint32(17, rxLoss ? 1 << 2 : 0, true);
  return p;
}

function setup(resolution: 1024 | 2048, map = 'TAER1234') {
  const fake = fakeHost();
  const fcUart = new FakeFc({ resolution, map });
  const nowUs = () => fake.clock.now() * 1000;
  const adapter = new StandInPort(0x0403, (bytes) => fcUart.write(bytes, nowUs()));
  const requests = new MspParser();
  const usb = new StandInPort(0x0483, (bytes, port) => {
    requests.push(bytes);
    for (let m = requests.next(); m !== undefined; m = requests.next()) {
      const state = fcUart.state(nowUs());
      const payload =
        m.cmd === MSP.FC_VARIANT
          ? new TextEncoder().encode('BTFL')
          : m.cmd === MSP.RX_CONFIG
            ? new Uint8Array([resolution === 2048 ? 1 : 0])
            : m.cmd === MSP.RC
              ? le16(state.channels)
              : m.cmd === MSP.STATUS_EX
                ? statusEx(false, state.rxLoss)
                : null;
      if (payload !== null) port.reply(encodeMsp(m.cmd, payload, { direction: 'reply' }));
    }
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
