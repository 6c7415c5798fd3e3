/**
 * What every browser test of the page needs: the built page (dist-app/, made by `npm run build`)
 * served on 127.0.0.1, Debian's Chromium, and a place for screenshots.
 */
import { closeSync, existsSync, mkdirSync, openSync, writeFileSync, writeSync } from 'node:fs';
import { join, resolve } from 'node:path';
import type { Browser, Page } from 'playwright-core';
import { expect } from 'vitest';
import { CaptureWriter } from '../../src/capture/writer.js';
import { Simulator } from '../../src/simulator/simulator.js';
import { preset } from '../../src/simulator/presets.js';
import { concatBytes } from '../bytes.js';
import { usbChunks, withSpikes } from '../feeds.js';
import { chromiumAvailable, launchChromium, startStaticServer, type LaunchChromiumOptions, type StaticServer } from './harness/browser.js';
import { installSerialPolicy } from './harness/policy.js';
import { openFakeSerialPort, type FakeSerialPort, type FakeSerialPortOptions } from './harness/pty-serial.js';

export const ROOT = resolve(import.meta.dirname, '../..');
export const APP_DIR = join(ROOT, 'dist-app');
export const SHOTS = join(ROOT, 'test-results/screenshots');
export const SHARED_CAPTURES = resolve(ROOT, '../shared/captures/px4');

/** Why the browser tests cannot run here, or null. */
export function browserUnavailable(): string | null {
  if (!chromiumAvailable()) return 'Debian chromium is not installed (/usr/lib/chromium/chromium): apt-get install chromium';
  if (!existsSync(join(APP_DIR, 'index.html'))) return 'the page is not built: run `npm run build` (npm test does)';
  return null;
}

export interface AppSession {
  browser: Browser;
  server: StaticServer;
  close(): Promise<void>;
}

export async function startApp(): Promise<AppSession> {
  mkdirSync(SHOTS, { recursive: true });
  const server = await startStaticServer(APP_DIR);
  const browser = await launchChromium();
  return {
    browser,
    server,
    async close() {
      await browser.close();
      await server.close();
    },
  };
}

/** The sizes the page is looked at: a phone, a laptop, a desktop. */
export const SIZES = [
  { name: '390', width: 390, height: 844 },
  { name: '1280', width: 1280, height: 800 },
  { name: '1920', width: 1920, height: 1080 },
] as const;

/** A page of the app at `/${query}` in a fresh context (1280 × 800, dark unless said), with its page and console errors. */
export async function openPage(
  app: AppSession,
  options: { width?: number; height?: number; scheme?: 'light' | 'dark'; query?: string } = {},
): Promise<{ page: Page; errors: string[] }> {
  const context = await app.browser.newContext({
    viewport: { width: options.width ?? 1280, height: options.height ?? 800 },
    colorScheme: options.scheme ?? 'dark',
    acceptDownloads: true,
  });
  const page = await context.newPage();
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(m.text());
  });
  await page.goto(app.server.url(`/${options.query ?? ''}`));
  return { page, errors };
}

/** Waits for the demo's two remotes to be live (on a phone their panel is folded away: attached is enough). */
export async function demoRunning(page: Page): Promise<void> {
  await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
  await page.locator('.remotes .state-chip', { hasText: 'live' }).nth(1).waitFor({ state: 'attached', timeout: 10_000 });
}

/** Waits until the selected remote's frame counter has counted `n` more frames than it shows now. */
export async function moreFrames(page: Page, n: number): Promise<void> {
  const now = Number(await page.getByTestId('count-frames').textContent());
  await page.waitForFunction((min) => Number(document.querySelector('[data-testid="count-frames"]')?.textContent) >= min, now + n, {
    timeout: 20_000,
  });
}

/** Opens the capture at `path` for replay and plays it at full speed to its end. */
export async function replayToEnd(page: Page, path: string): Promise<void> {
  await page.setInputFiles('input[type=file]', path);
  await page.locator('section.replay').waitFor();
  await page.getByRole('radio', { name: 'max' }).click();
  await page.locator('[data-testid="source-status"]', { hasText: '(end)' }).waitFor({ timeout: 20_000 });
}

export interface SerialAppSession extends AppSession {
  /** The pty standing in for /dev/ttyS0, which the managed policy grants the page. */
  fake: FakeSerialPort;
}

/**
 * The built page served, a managed policy granting its origin the serial ports, a pty in place
 * of /dev/ttyS0, and Chromium: what every real-WebSerial test needs. `close()` undoes it all,
 * and so does a failure half-way.
 */
export async function startSerialApp(launch: LaunchChromiumOptions = {}, port: FakeSerialPortOptions = {}): Promise<SerialAppSession> {
  mkdirSync(SHOTS, { recursive: true });
  const undo: (() => Promise<void>)[] = [];
  const close = async () => {
    for (const step of undo.reverse()) await step();
  };
  try {
    const server = await startStaticServer(APP_DIR);
    undo.push(() => server.close());
    const policy = await installSerialPolicy(server.origin);
    undo.push(() => policy.remove());
    const fake = await openFakeSerialPort(port);
    undo.push(() => fake.close());
    const browser = await launchChromium(launch);
    undo.push(() => browser.close());
    return { browser, server, fake, close };
  } catch (error) {
    await close();
    throw error;
  }
}

export async function shot(page: Page, name: string): Promise<string> {
  const path = join(SHOTS, `${name}.png`);
  await page.screenshot({ path, fullPage: true });
  return path;
}

/** The µs value each channel bar on the page shows (0–11 and X-Plus), by channel name (NaN: no data). */
export async function barValues(page: Page): Promise<Record<string, number>> {
  return page.$$eval('.channels [role="meter"]', (bars) =>
    Object.fromEntries(bars.map((b) => [b.getAttribute('aria-label'), Number(b.getAttribute('aria-valuenow') ?? NaN)])),
  );
}

/**
 * Waits until the bars show each of `channels` at its `lastUs`: the bars are drawn on the
 * animation frame after the last batch, which the status pill ("(end)") may announce first.
 */
export async function barsShow(page: Page, channels: readonly { name: string; lastUs: number }[]): Promise<void> {
  const want = Object.fromEntries(channels.map((c) => [c.name, c.lastUs]));
  await expect.poll(() => barValues(page), { timeout: 5000 }).toMatchObject(want);
}

/** Writes chunks as a .sscap file (as the recorder would), for replay tests. */
export function writeCapture(path: string, chunks: { bytes: Uint8Array; timeUs: number }[]): void {
  const writer = new CaptureWriter({ baudRate: 115200, source: 'test' });
  writeFileSync(path, concatBytes([writer.header(), ...chunks.map((c) => writer.data(c.bytes, c.timeUs))]));
}

/**
 * Writes a capture of two remotes at 11 ms lasting `durationUs` to `path`, a minute of records
 * at a time (long enough for the page's long-capture path: over 32 MB is about two hours).
 */
export function writeLongCapture(path: string, durationUs: number): void {
  const writer = new CaptureWriter({ baudRate: 115200, source: 'test', ports: [{ name: 'internal' }, { name: 'external' }] });
  const sims = [
    new Simulator({ ...preset('dsmx-11ms-2048-internal'), seed: 21 }),
    new Simulator({ ...preset('dsmx-11ms-2048-external'), seed: 22 }),
  ];
  const fd = openSync(path, 'w');
  try {
    writeSync(fd, writer.header());
    const start = sims[0]?.scenario.timing.startUs ?? 0;
    for (let t = start; t < start + durationUs; t += 60e6) {
      const records = sims.flatMap((sim, port) => {
        const { bytes, timesUs } = sim.generate(Math.min(t + 60e6, start + durationUs));
        return usbChunks(bytes, timesUs).map((c) => ({ ...c, port }));
      });
      records.sort((a, b) => a.timeUs - b.timeUs || a.port - b.port);
      writeSync(fd, concatBytes(records.map((r) => writer.data(r.bytes, r.timeUs, r.port))));
    }
  } finally {
    closeSync(fd);
  }
}

export { usbChunks, withSpikes };
