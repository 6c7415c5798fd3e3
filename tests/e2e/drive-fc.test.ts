/**
 * Drive and read back at once, through Chromium's real WebSerial on two ports: the page writes a
 * satellite to one pty (the adapter's TX) and asks the other over MSP (the flight controller's
 * USB port). On the test's side a fake Betaflight (tests/fake-fc.ts) reads the first pty's bytes
 * with their real timing by its documented rules and answers MSP on the second from what it read.
 * The page grades the scenario and shows and saves the report.
 */
import { existsSync, mkdirSync, readFileSync } from 'node:fs';
import { join } from 'node:path';
import type { Browser } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { BYTE_TIME_US } from '../../src/decoder/spec.js';
import type { DriveReport } from '../../src/drive/report.js';
import { FakeBetaflightUsb, FakeFc } from '../fake-fc.js';
import { APP_DIR, browserUnavailable, SHOTS } from './app-fixture.js';
import { launchChromium, startStaticServer, type StaticServer } from './harness/browser.js';
import { installSerialPolicy, type SerialPolicy } from './harness/policy.js';
import { fakeSerialUnsupportedReason, monotonicUs, openFakeSerialPort, type FakeSerialPort } from './harness/pty-serial.js';
import { eachLook, openDrive } from './drive-page.js';

const SECOND = '/dev/ttyS1';
const skip = browserUnavailable() ?? fakeSerialUnsupportedReason() ?? fakeSerialUnsupportedReason(SECOND);
if (skip !== null) console.warn(`skipping Drive with the flight controller read back: ${skip}`);

/** How long to wait for the serial devices, ms. */
const WAIT_MS = 300_000;

let server: StaticServer;
let policy: SerialPolicy;
let ports: FakeSerialPort[] = [];
let browser: Browser;

beforeAll(async () => {
  if (skip !== null) return;
  mkdirSync(SHOTS, { recursive: true });
  server = await startStaticServer(APP_DIR);
  policy = await installSerialPolicy(server.origin);
  // The other browser tests hold /dev/ttyS0 a file at a time: wait for it as long as one may take.
  ports = [await openFakeSerialPort({ lockTimeoutMs: WAIT_MS }), await openFakeSerialPort({ device: SECOND, lockTimeoutMs: WAIT_MS })];
  browser = await launchChromium();
}, WAIT_MS + 60_000);

afterAll(async () => {
  await browser?.close();
  for (const p of ports.reverse()) await p.close();
  await policy?.remove();
  await server?.close();
});

describe.skipIf(skip !== null)('driving a flight controller and reading it back, on two ports', () => {
  it('sweeps four channels into a fake Betaflight, reads it over MSP, and grades what it read', async () => {
    // The flight controller: its UART reads whichever pty carries satellite frames; its USB port
    // is whichever pty the page asks over MSP (the page lists both ports, in sysfs's order).
    const uart = new FakeFc({ resolution: 2048 });
    const usb = new FakeBetaflightUsb(uart, 2048);
    const role: ('unknown' | 'usb')[] = ports.map(() => 'unknown');
    let uartBytes = 0;
    const stops = ports.map((port, k) =>
      port.onData((bytes, tUs) => {
        const replies = usb.push(bytes, monotonicUs());
        if (replies.length > 0) role[k] = 'usb';
        for (const reply of replies) void port.write(reply);
        if (role[k] === 'usb') return;
        // A read's time is its last byte's.
        uart.write(bytes, tUs - (bytes.length - 1) * BYTE_TIME_US);
        uartBytes += bytes.length;
      }),
    );
    const context = await browser.newContext({ viewport: { width: 1280, height: 1000 }, acceptDownloads: true });
    const page = await context.newPage();
    const errors: string[] = [];
    page.on('pageerror', (e) => errors.push(e.message));
    try {
      await page.goto(server.url('/'));
      const panel = await openDrive(page);
      const view = panel.getByRole('region', { name: "The flight controller's view" });
      await view.getByLabel('Its USB port').selectOption({ index: 1 });
      await view.getByRole('button', { name: 'Read the flight controller' }).click();
      await view
        .getByTestId('fc-state')
        .filter({ hasText: /Betaflight on / })
        .waitFor({ timeout: 10_000 });
      // Before any frame: it says so (RXLOSS).
      await view.locator('.drive-fc-flags').filter({ hasText: 'Receiver lost (RXLOSS): yes' }).waitFor();
      await panel.getByLabel('Adapter').selectOption({ index: 0 });
      await panel.getByLabel('Channels', { exact: true }).fill('4');
      await panel.getByLabel('Scenario').selectOption('sweep');
      await panel.getByLabel('The propellers are off').check();
      await panel.getByRole('button', { name: '▶ Start driving' }).click();
      await panel.getByTestId('drive-state').filter({ hasText: 'Sending “sweep”' }).waitFor();
      await view.locator('.drive-fc-flags').filter({ hasText: 'Receiver lost (RXLOSS): no' }).waitFor({ timeout: 5000 });
      await panel
        .getByTestId('drive-state')
        .filter({ hasText: /Stopped: .*“sweep”/ })
        .waitFor({ timeout: 60_000 });
      const grade = panel.getByRole('region', { name: 'Conformance' });
      await grade.waitFor();
      const rows = await grade.locator('tbody tr').evaluateAll((trs) =>
        trs.map((tr) => ({
          id: tr.querySelector('th')?.textContent ?? '',
          verdict: tr.querySelector('.verdict')?.textContent ?? '',
          found: tr.querySelectorAll('td')[1]?.textContent ?? '',
        })),
      );
      console.log(`two ports, graded on the page: ${JSON.stringify({ role, uartBytes, rows })}`);
      expect(role.filter((r) => r === 'usb')).toHaveLength(1);
      const verdicts = Object.fromEntries(rows.map((r) => [r.id, r.verdict]));
      // Betaflight's rules: TAER1234 order, its own scale (off §9 at the ends), read within 2 frames.
      // The sweep sends no silence; a loaded machine's writer may (a late timer skips frames), and
      // the failsafe check then grades those silences: never a fail.
      const { failsafe, ...rest } = verdicts;
      expect(rest).toEqual({ 'channel-map': 'pass', values: 'fail', latency: 'pass', steady: 'pass' });
      expect(['unknown', 'pass']).toContain(failsafe);
      expect(rows.find((r) => r.id === 'values')?.found).toMatch(/serialrx_provider = SPEKTRUM2048/);
      // The report as saved: the same checks, and what the flight controller said of itself.
      const [download] = await Promise.all([
        page.waitForEvent('download'),
        grade.getByRole('button', { name: 'Save report (JSON)' }).click(),
      ]);
      const report = JSON.parse(readFileSync((await download.path()) as string, 'utf8')) as DriveReport;
      expect(report.fc).toMatchObject({ variant: 'BTFL', provider: 'SPEKTRUM2048' });
      expect(Object.fromEntries(report.checks.map((c) => [c.id, c.verdict]))).toEqual(verdicts);
      await eachLook(page, async ({ name }) => {
        await grade.screenshot({ path: join(SHOTS, `drive-grade-${name}.png`) });
      });
      expect(existsSync(join(SHOTS, 'drive-grade-phone-dark.png'))).toBe(true);
    } finally {
      for (const stop of stops) stop();
    }
    expect(errors).toEqual([]);
    await context.close();
  }, 120_000);
});
