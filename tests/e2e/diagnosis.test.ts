/**
 * The Diagnosis panel through Chromium's real WebSerial stack (a pseudo-terminal stands in for
 * /dev/ttyS0): a port that opens and sends nothing, FlySky IBUS bytes at 115200 (from the line
 * model), and a DSM2 22 ms 1024 satellite (the simulator): each shows its finding within 2 s,
 * the worst one also under the link state, and Copy settings gives the flight stack's lines.
 * Then the panel in replay at 390 and 1280 px, light and dark: it fits, and screenshots go to
 * test-results/screenshots/.
 */
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Browser, BrowserContext, Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { ibusStream } from '../../src/simulator/protocols.js';
import { preset } from '../../src/simulator/presets.js';
import { receiveAs } from '../../src/simulator/line.js';
import { simulate } from '../../src/simulator/simulator.js';
import { SHOTS, browserUnavailable, usbChunks, writeCapture, startSerialApp, type SerialAppSession } from './app-fixture.js';
import { axe } from './axe.js';
import type { StaticServer } from './harness/browser.js';
import { fakeSerialUnsupportedReason, type FakeSerialPort } from './harness/pty-serial.js';

const skip = browserUnavailable() ?? fakeSerialUnsupportedReason();
if (skip !== null) console.warn(`skipping the Diagnosis tests: ${skip}`);

/** The bar: the right finding on the panel within this long. */
const WITHIN_MS = 2000;

let rig: SerialAppSession | undefined;
let server: StaticServer;
let fake: FakeSerialPort;
let browser: Browser;
let dir = '';

/** IBUS at 115200 8N1 as the adapter's UART delivers it: bytes with per-byte times. */
function ibus(durationUs: number): { bytes: Uint8Array; timesUs: Float64Array } {
  const r = receiveAs(ibusStream({ durationUs }));
  expect(r.errors).toEqual([]);
  return r;
}

beforeAll(async () => {
  if (skip !== null) return;
  dir = mkdtempSync(join(tmpdir(), 'satscope-diagnosis-'));
  mkdirSync(SHOTS, { recursive: true });
  rig = await startSerialApp();
  ({ server, fake, browser } = rig);
});

afterAll(async () => {
  if (skip !== null) return;
  await rig?.close();
  rmSync(dir, { recursive: true, force: true });
});

async function open(
  options: { width?: number; scheme?: 'light' | 'dark'; clipboard?: boolean } = {},
): Promise<{ context: BrowserContext; page: Page; errors: string[] }> {
  const context = await browser.newContext({
    viewport: { width: options.width ?? 1280, height: 900 },
    colorScheme: options.scheme ?? 'dark',
  });
  if (options.clipboard === true) await context.grantPermissions(['clipboard-read', 'clipboard-write'], { origin: server.origin });
  const page = await context.newPage();
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(server.url('/'));
  return { context, page, errors };
}

/** Connects the granted port (offered at start) and waits until it is read at 115200. */
async function connect(page: Page): Promise<void> {
  await page.getByRole('button', { name: 'Serial port' }).click();
  await page.getByTestId('source-status').filter({ hasText: 'at 115200 baud' }).waitFor();
}

/** Waits for a finding on the panel; returns how long it took from `sinceMs`. */
async function finding(page: Page, code: string, sinceMs: number): Promise<number> {
  await page.locator(`.diagnosis .finding[data-code="${code}"]`).waitFor({ timeout: 10_000 });
  return Date.now() - sinceMs;
}

async function fits(page: Page): Promise<{ document: number; viewport: number }> {
  return page.evaluate(() => ({ document: document.documentElement.scrollWidth, viewport: document.documentElement.clientWidth }));
}

describe.skipIf(skip !== null)('the Diagnosis panel on a real serial port', () => {
  it('says nothing arrives when the port opens and stays silent', async () => {
    await fake.reconnect();
    const { context, page, errors } = await open();
    await connect(page);
    const opened = Date.now();
    const ms = await finding(page, 'nothing-arrives', opened);
    console.log(`silence: "nothing arrives" ${ms} ms after the port showed as open`);
    expect(ms).toBeLessThan(WITHIN_MS);
    await expect(page.getByTestId('top-finding').textContent()).resolves.toMatch(/nothing arrives/);
    // What to check, most likely first, and the evidence with the port's speed.
    const item = page.locator('.finding[data-code="nothing-arrives"]');
    await expect(item.locator('.todo li').first().textContent()).resolves.toMatch(/Transmitter off/);
    await expect(item.locator('.evidence').textContent()).resolves.toMatch(/115200 baud/);
    await page.locator('.p-diagnosis').screenshot({ path: join(SHOTS, 'diagnosis-silence-1280-dark.png') });
    expect(errors).toEqual([]);
    await context.close();
  });

  it('names FlySky IBUS at 115200, with the provider to set, and clears it once the bytes stop', async () => {
    await fake.reconnect();
    const { context, page, errors } = await open();
    await connect(page);
    const stream = ibus(3_000_000);
    const started = Date.now();
    const writing = fake.writePaced(stream.bytes, stream.timesUs);
    const ms = await finding(page, 'ibus', started);
    console.log(`IBUS: "${await page.getByTestId('top-finding').textContent()}" ${ms} ms after the first byte`);
    expect(ms).toBeLessThan(WITHIN_MS);
    const item = page.locator('.finding[data-code="ibus"]');
    await expect(item.locator('.title').textContent()).resolves.toMatch(/FlySky IBUS, not a Spektrum satellite/);
    await expect(item.locator('pre').first().textContent()).resolves.toContain('set serialrx_provider = IBUS');
    await page.locator('.p-diagnosis').screenshot({ path: join(SHOTS, 'diagnosis-ibus-1280-dark.png') });
    await writing;
    // The line findings look at the last 3 s: with the bytes gone, the finding goes. What stays
    // true is that no satellite stream came, and what the bytes were: never "nothing wrong".
    const stopped = Date.now();
    await item.waitFor({ state: 'detached', timeout: 8000 });
    console.log(`IBUS: cleared ${Date.now() - stopped} ms after the last byte`);
    // Until the last packets leave the 3 s window they are too few to name; then the port's
    // whole history is told.
    const none = page.locator('.finding[data-code="no-satellite"]');
    await expect.poll(() => none.locator('.evidence').textContent(), { timeout: 5000 }).toMatch(/They were \d+ FlySky IBUS packets/);
    await expect(page.getByTestId('diagnosis-none').count()).resolves.toBe(0);
    expect(errors).toEqual([]);
    await context.close();
  });

  it('gives a 1024 satellite its settings and advises DSMX 11 ms; Copy settings puts the lines on the clipboard', async () => {
    await fake.reconnect();
    const { context, page, errors } = await open({ clipboard: true });
    await connect(page);
    const sim = simulate(preset('dsm2-22ms-1024-internal'), 4_000_000);
    const started = Date.now();
    const writing = fake.writePaced(sim.bytes, sim.timesUs);
    const ms = await finding(page, 'bind-mode', started);
    const msSettings = await finding(page, 'fc-settings', started);
    console.log(`1024: "bind-mode" ${ms} ms, "fc-settings" ${msSettings} ms after the first byte`);
    expect(ms).toBeLessThan(WITHIN_MS);
    expect(msSettings).toBeLessThan(WITHIN_MS);
    await expect(page.getByTestId('top-finding').textContent()).resolves.toMatch(
      // Until the fade count moves in byte 0 the header reads both ways (internal DSM2 or an
      // external remote's count): the title names only what the frames prove.
      /bound in (DSM2 22 ms 1024|1024, 22 ms); DSMX 11 ms is better/,
    );
    const settings = page.locator('.finding[data-code="fc-settings"]');
    await expect(settings.locator('.title').textContent()).resolves.toMatch(/1024|DSM2 22 ms/);

    // Keyboard: Tab reaches the stack choice and the button; Enter on a finding opens it.
    await page.locator('.diagnosis select').focus();
    await page.keyboard.press('Tab');
    await expect(page.evaluate(() => document.activeElement?.textContent)).resolves.toBe('Copy settings');
    await expect(page.evaluate(() => getComputedStyle(document.activeElement!).outlineStyle)).resolves.not.toBe('none');
    await page.keyboard.press('Enter');
    await page.locator('.diagnosis .copied', { hasText: 'Copied' }).waitFor();
    await expect(page.evaluate(() => navigator.clipboard.readText())).resolves.toBe('set serialrx_provider = SPEK1024\nsave\n');
    await page.locator('.diagnosis select').selectOption('iNav');
    await page.getByRole('button', { name: 'Copy settings' }).click();
    await page.locator('.diagnosis .copied', { hasText: 'iNav' }).waitFor();
    await expect(page.evaluate(() => navigator.clipboard.readText())).resolves.toBe(
      'set receiver_type = SERIAL\nset serialrx_provider = SPEK1024\nsave\n',
    );

    const summary = settings.locator('summary');
    await summary.focus();
    const before = await settings.locator('details').evaluate((d) => (d as HTMLDetailsElement).open);
    await page.keyboard.press('Enter');
    await expect.poll(() => settings.locator('details').evaluate((d) => (d as HTMLDetailsElement).open)).toBe(!before);
    if (before) await page.keyboard.press('Enter');
    await expect(settings.locator('pre').first().textContent()).resolves.toContain('set serialrx_provider = SPEK1024');
    await page.locator('.p-diagnosis').screenshot({ path: join(SHOTS, 'diagnosis-1024-1280-dark.png') });
    await writing;
    expect(errors).toEqual([]);
    await context.close();
  });
});

describe.skipIf(skip !== null)("the probe's line settings on Chromium's serial stack", () => {
  it('opens the port at 420000 8N1 and 100000 8E2 and again at 115200, as "listen at the other speed" does', async () => {
    await fake.reconnect();
    const { context, page } = await open();
    const opened = await page.evaluate(async () => {
      const [port] = await navigator.serial.getPorts();
      const out: string[] = [];
      for (const o of [
        { baudRate: 420_000 },
        { baudRate: 100_000, parity: 'even' as const, stopBits: 2 as const },
        { baudRate: 115_200 },
      ]) {
        try {
          await port!.open(o);
          out.push(`${o.baudRate} ok`);
          await port!.close();
        } catch (e) {
          out.push(`${o.baudRate} ${(e as Error).name}`);
        }
      }
      return out;
    });
    console.log(`probe settings on the pty: ${opened.join(', ')}`);
    expect(opened).toEqual(['420000 ok', '100000 ok', '115200 ok']);
    await context.close();
  });
});

describe.skipIf(skip !== null)('the Diagnosis panel in replay, on a phone and a laptop, light and dark', () => {
  it('shows the findings of a replayed capture, fits 390 px, and looks right in both themes', async () => {
    const sim = simulate(preset('dsm2-22ms-1024-internal'), 3_000_000);
    const sat = join(dir, 'dsm2-1024.sscap');
    writeCapture(sat, usbChunks(sim.bytes, sim.timesUs));
    const i = ibus(2_000_000);
    const foreign = join(dir, 'ibus.sscap');
    writeCapture(foreign, usbChunks(i.bytes, i.timesUs));
    // Each capture at one width and theme, the two between them covering both (the panel at every
    // size and theme is in the slow tier's screenshots).
    for (const [name, file, code, width, scheme] of [
      ['1024', sat, 'bind-mode', 390, 'light'],
      ['ibus', foreign, 'ibus', 1280, 'dark'],
    ] as const) {
      const { context, page, errors } = await open({ width, scheme });
      await page.setInputFiles('input[type=file]', file);
      await page.locator('section.replay').waitFor();
      await page.getByRole('radio', { name: 'max' }).click();
      await page.locator('[data-testid="source-status"]', { hasText: '(end)' }).waitFor({ timeout: 20_000 });
      // On a phone the panel is folded under the channel bars until tapped.
      if (width < 600) await page.locator('.p-diagnosis .fold-toggle').click();
      await page.locator(`.diagnosis .finding[data-code="${code}"]`).waitFor({ timeout: 5000 });
      // The panel hears at most 4× a second: let the last word of the replay arrive.
      await page.waitForTimeout(600);
      // Open the finding with settings, so the screenshot shows what a user copies.
      const withSettings = page.locator('.diagnosis .finding', { has: page.locator('pre') }).first();
      if (!(await withSettings.locator('details').evaluate((d) => (d as HTMLDetailsElement).open)))
        await withSettings.locator('summary').click();
      await expect(page.getByTestId('top-finding').isVisible()).resolves.toBe(true);
      const w = await fits(page);
      expect(w.document, `${name} ${width} ${scheme}`).toBeLessThanOrEqual(w.viewport);
      await page.locator('.p-diagnosis').screenshot({ path: join(SHOTS, `diagnosis-${name}-panel-${width}-${scheme}.png`) });
      expect(await axe(page, `diagnosis ${name} ${width} ${scheme}`, ['.p-diagnosis', '.top-finding'])).toEqual([]);
      await page.screenshot({ path: join(SHOTS, `diagnosis-${name}-page-${width}-${scheme}.png`), fullPage: width === 390 });
      expect(errors).toEqual([]);
      await context.close();
    }
  });
});
