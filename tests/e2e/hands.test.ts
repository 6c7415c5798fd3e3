/**
 * The page in a user's hands (issue 34, items 10, 12, 13): channel values over time with their
 * glitches marked, live and in replay; a phone that shows the link state and the channel bars
 * on its first screen, with the rest behind disclosures; a short capture read in proportion,
 * its timeline with a time axis and the graphs' window fitted to it. Screenshots at 390, 1280
 * and 1920 px in both themes. Needs the built page (`npm run build`) and Debian's Chromium.
 */
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { healthReport } from '../../src/analysis/index.js';
import { preset, simulate, type SimChunk } from '../../src/simulator/index.js';
import { perByteCapture } from '../feeds.js';
import { SHOTS, browserUnavailable, startApp, usbChunks, writeCapture, type AppSession } from './app-fixture.js';

const skip = browserUnavailable();
if (skip !== null) console.warn(`skipping the page-in-hand tests: ${skip}`);

let app: AppSession;
let dir = '';
/** A capture with three one-frame glitches, a short dropout and a failsafe. */
let spiky = '';
let spikyGlitches = 0;

/** `sim` with channel slot 0 of each frame in `frames` pushed 600 steps away, for that frame only. */
function withSpikes(sim: SimChunk, frames: number[]): SimChunk {
  const bytes = sim.bytes.slice();
  for (const k of frames) {
    const f = sim.truth?.frames[k];
    if (f === undefined) throw new Error(`no frame ${k}`);
    const at = f.offset + 2;
    const w = ((bytes[at] ?? 0) << 8) | (bytes[at + 1] ?? 0);
    const pos = w & 0x7ff;
    const spiked = (w & ~0x7ff) | (pos > 1024 ? pos - 600 : pos + 600);
    bytes[at] = spiked >> 8;
    bytes[at + 1] = spiked & 0xff;
  }
  return { ...sim, bytes };
}

beforeAll(async () => {
  if (skip !== null) return;
  app = await startApp();
  dir = mkdtempSync(join(tmpdir(), 'satscope-hands-'));
  const sim = withSpikes(simulate(preset('dropouts-failsafe'), 3_200_000, { truth: true }), [30, 90, 140]);
  spikyGlitches = healthReport(perByteCapture(sim)).remotes[0]?.glitches.count ?? -1;
  spiky = join(dir, 'spiky.sscap');
  writeCapture(spiky, usbChunks(sim.bytes, sim.timesUs));
});

afterAll(async () => {
  if (skip !== null) return;
  await app.close();
  rmSync(dir, { recursive: true, force: true });
});

async function open(
  options: { width?: number; height?: number; scheme?: 'light' | 'dark'; query?: string } = {},
): Promise<{ page: Page; errors: string[] }> {
  const context = await app.browser.newContext({
    viewport: { width: options.width ?? 1280, height: options.height ?? 800 },
    colorScheme: options.scheme ?? 'dark',
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

async function replayed(page: Page, path: string): Promise<void> {
  await page.setInputFiles('input[type=file]', path);
  await page.locator('section.replay').waitFor();
  await page.getByRole('radio', { name: 'max' }).click();
  await page.locator('[data-testid="source-status"]', { hasText: '(end)' }).waitFor({ timeout: 20_000 });
}

/** The traces chart's series as uPlot holds them: labels and how many points have a value. */
async function traceSeries(page: Page): Promise<{ label: string; values: number }[]> {
  return page.$$eval('.traces .u-legend .u-series', (rows) =>
    rows.slice(1).map((r) => ({ label: r.querySelector('.u-label')?.textContent ?? '', values: 0 })),
  );
}

/** The pixels of the traces' canvas that are not background, for "something is drawn". */
async function drawnPixels(page: Page): Promise<number> {
  return page.$eval('.traces canvas', (c) => {
    const canvas = c as HTMLCanvasElement;
    const ctx = canvas.getContext('2d');
    if (ctx === null) return 0;
    const d = ctx.getImageData(0, 0, canvas.width, canvas.height).data;
    const seen = new Map<number, number>();
    for (let i = 0; i < d.length; i += 4) {
      const k = ((d[i] ?? 0) << 16) | ((d[i + 1] ?? 0) << 8) | (d[i + 2] ?? 0);
      seen.set(k, (seen.get(k) ?? 0) + 1);
    }
    // The most common colour is the background; everything else was drawn.
    const most = Math.max(...seen.values());
    return d.length / 4 - most;
  });
}

describe.skipIf(skip !== null)('channel traces', () => {
  it('shows every channel the demo sends in a lane of its own, live, and the picker chooses them', async () => {
    const { page, errors } = await open();
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await page.locator('.traces canvas').waitFor();
    await page.waitForTimeout(1500);
    const lanes = await traceSeries(page);
    expect(lanes.map((l) => l.label).slice(0, 4)).toEqual(['Throttle', 'Aileron', 'Elevator', 'Rudder']);
    expect(lanes.length).toBeGreaterThanOrEqual(6);
    expect(await drawnPixels(page)).toBeGreaterThan(2000);
    // Sticks only, then one more.
    await page.locator('.trace-picker').getByRole('button', { name: 'Sticks' }).click();
    await expect.poll(async () => (await traceSeries(page)).length).toBe(4);
    await page.locator('.trace-picker').getByRole('button', { name: /^5\b/ }).click();
    await expect
      .poll(async () => (await traceSeries(page)).map((l) => l.label))
      .toEqual(['Throttle', 'Aileron', 'Elevator', 'Rudder', 'Aux 1']);
    await expect(page.locator('.trace-picker').getByRole('button', { name: /^5\b/ }).getAttribute('aria-pressed')).resolves.toBe('true');
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('marks in replay exactly the glitches the health report counts, on the window fitted to the capture', async () => {
    const { page, errors } = await open({ query: '?demo=0' });
    await replayed(page, spiky);
    expect(spikyGlitches).toBe(3);
    // A 3.2 s capture: the 10 s window, the smallest that holds it.
    await expect(page.getByRole('radio', { name: '10 s' }).getAttribute('aria-checked')).resolves.toBe('true');
    await page.locator('.trace-picker').getByRole('button', { name: 'All sent' }).click();
    await expect.poll(() => page.getByTestId('glitch-count').textContent()).toBe(`${spikyGlitches} glitches in view`);
    mkdirSync(SHOTS, { recursive: true });
    await page.locator('.traces').screenshot({ path: join(SHOTS, 'hands-traces-glitches-1280-dark.png') });
    expect(errors).toEqual([]);
    await page.context().close();
  });
});
