/**
 * Binding from the page through the real WebSerial stack: a pty stands in for the adapter, a
 * preloaded shim gives it the modem lines, and the test watches what the page does on the wire
 * — power off, power on, the pulse bytes ~60 ms later, power on again after the reopen at
 * 115200 — then plays the newly bound internal remote and sees it live.
 */
import type { Browser } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { planPulses } from '../../src/bind/index.js';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import { browserUnavailable, shot, startSerialApp, type SerialAppSession } from './app-fixture.js';
import type { StaticServer } from './harness/browser.js';
import { buildSignalShim, fakeSerialUnsupportedReason, type FakeSerialPort } from './harness/pty-serial.js';

const skip = browserUnavailable() ?? fakeSerialUnsupportedReason();
if (skip !== null) console.warn(`skipping the bind tests: ${skip}`);

let rig: SerialAppSession | undefined;
let server: StaticServer;
let fake: FakeSerialPort;
let browser: Browser;
let shim: string | null = null;

beforeAll(async () => {
  if (skip !== null) return;
  shim = await buildSignalShim();
  if (shim === null) return;
  rig = await startSerialApp({ preload: [shim] });
  ({ server, fake, browser } = rig);
});

afterAll(async () => {
  if (skip !== null || shim === null) return;
  await rig?.close();
});

describe.skipIf(skip !== null)('binding a satellite', () => {
  it('power-cycles through RTS, sends 9 pulses in the window, reopens at 115200 and shows the bind take', async (ctx) => {
    if (shim === null) ctx.skip(); // no C compiler for the modem-line shim: a bare pty rejects setSignals
    const written: { bytes: Uint8Array; tUs: number }[] = [];
    fake.onData((bytes, tUs) => written.push({ bytes, tUs }));
    const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
    const errors: string[] = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(server.url('/'));
    await page.getByRole('button', { name: 'Bind…' }).click();
    await expect(page.getByRole('radio', { name: '9 pulses' }).isChecked()).resolves.toBe(true);
    // A pty has no USB IDs: the panel says it shows the common adapters' plan, the one the worker runs.
    await expect(page.getByTestId('bind-adapter').textContent()).resolves.toMatch(/does not know this adapter's chip/);
    const preview = (await page.getByTestId('bind-plan').textContent())?.replace(/\s+/g, ' ') ?? '';
    await shot(page, 'bind-panel');
    const since = fake.signalChanges.length;
    await page.getByRole('button', { name: 'Bind on Serial port' }).click();
    const result = page.locator('.bind .progress li.live, .bind .progress li.failed');
    await result.first().waitFor({ timeout: 5000 });
    await expect(
      page.locator('.bind .progress li.failed').count(),
      (await page.locator('.bind .progress').textContent()) ?? '',
    ).resolves.toBe(0);

    // What reached the wire, in order, with the shim's and the pty's monotonic times.
    const changes = fake.signalChanges.slice(since).filter((c) => c.op === 'set');
    const offAt = changes.findIndex((c) => !c.requestToSend);
    const onAt = changes.findIndex((c, i) => i > offAt && c.requestToSend);
    expect(offAt).toBeGreaterThanOrEqual(0);
    expect(onAt).toBeGreaterThan(offAt);
    const off = changes[offAt]!;
    const on = changes[onAt]!;
    expect((on.tUs - off.tUs) / 1000).toBeGreaterThanOrEqual(490); // off long enough to reset
    const pulses = written.filter((w) => w.tUs > on.tUs);
    const bytes = Uint8Array.from(pulses.flatMap((w) => Array.from(w.bytes)));
    expect(Array.from(bytes)).toEqual(Array.from(planPulses(9).bytes)); // 9 × 0xF0: nothing else
    // What the panel showed before the bind is what went on the wire.
    const hex = (v: number) => `0x${v.toString(16).toUpperCase().padStart(2, '0')}`;
    expect(preview).toContain(`Pulses: ${Array.from(bytes, hex).join(' ')} at ${planPulses(9).baudRate} baud`);
    const writeMs = (pulses[0]!.tUs - on.tUs) / 1000;
    // Sent 60 ms after power-on as firmware does; Chromium's serial pipeline adds 0–40 ms here.
    expect(writeMs).toBeGreaterThan(55); // the satellite has settled…
    expect(writeMs).toBeLessThan(140); // …and the pulses land in the bind window (20–140 ms)
    // After the reopen at 115200 the power line is asserted again, after the pulses.
    const again = changes.slice(onAt + 1).find((c) => c.requestToSend && c.tUs > pulses[0]!.tUs);
    expect(again).toBeDefined();
    console.log(
      `[bind] off ${((on.tUs - off.tUs) / 1000).toFixed(1)} ms, pulses at t0 + ${writeMs.toFixed(1)} ms, power re-asserted at t0 + ${((again!.tUs - on.tUs) / 1000).toFixed(1)} ms`,
    );

    // The satellite, now bound as internal DSMX 11 ms, starts sending frames.
    const sim = simulate(preset('dsmx-11ms-2048-internal'), 1_500_000);
    await fake.writePaced(sim.bytes, sim.timesUs);
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor();
    await expect(page.getByTestId('protocol').textContent()).resolves.toBe('DSMX 11 ms');
    await shot(page, 'bind-took');
    expect(errors).toEqual([]);
    await page.close();
  });
});
