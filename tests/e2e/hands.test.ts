/**
 * The page in a user's hands (issue 34, items 10, 12, 13): channel values over time with their
 * glitches marked, live and in replay; a phone that shows the link state and the channel bars
 * on its first screen, with the rest behind disclosures; a short capture read in proportion,
 * its timeline with a time axis and the graphs' window fitted to it. Screenshots at 390, 1280
 * and 1920 px in both themes. Needs the built page (`npm run build`) and Debian's Chromium.
 */
import { mkdirSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { healthReport } from '../../src/report/report.js';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import { perByteCapture } from '../feeds.js';
import {
  SHOTS,
  browserUnavailable,
  openPage,
  replayToEnd,
  startApp,
  usbChunks,
  withSpikes,
  writeCapture,
  type AppSession,
} from './app-fixture.js';

const skip = browserUnavailable();
if (skip !== null) console.warn(`skipping the page-in-hand tests: ${skip}`);

let app: AppSession;
let dir = '';
/** A capture with three one-frame glitches, a short dropout and a failsafe. */
let spiky = '';
let spikyGlitches = 0;
/** A 0.74 s capture with one 66 ms hold, and a clean one as short. */
let shortHold = '';
let shortClean = '';

beforeAll(async () => {
  if (skip !== null) return;
  app = await startApp();
  dir = mkdtempSync(join(tmpdir(), 'satscope-hands-'));
  const sim = withSpikes(simulate(preset('dropouts-failsafe'), 3_200_000, { truth: true }), [30, 90, 140]);
  spikyGlitches = healthReport(perByteCapture(sim)).remotes[0]?.glitches.count ?? -1;
  spiky = join(dir, 'spiky.sscap');
  writeCapture(spiky, usbChunks(sim.bytes, sim.timesUs));
  const hold = simulate({ ...preset('dsmx-11ms-2048-internal'), dropouts: [{ atUs: 300_000, durationUs: 66_000 }] }, 740_000);
  shortHold = join(dir, 'short-hold.sscap');
  writeCapture(shortHold, usbChunks(hold.bytes, hold.timesUs));
  const clean = simulate(preset('dsmx-11ms-2048-internal'), 740_000);
  shortClean = join(dir, 'short-clean.sscap');
  writeCapture(shortClean, usbChunks(clean.bytes, clean.timesUs));
});

afterAll(async () => {
  if (skip !== null) return;
  await app.close();
  rmSync(dir, { recursive: true, force: true });
});

const open = (options: Parameters<typeof openPage>[1] = {}) => openPage(app, options);

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
    await expect.poll(() => drawnPixels(page), { timeout: 10_000 }).toBeGreaterThan(2000);
    const lanes = await traceSeries(page);
    expect(lanes.map((l) => l.label).slice(0, 4)).toEqual(['Throttle', 'Aileron', 'Elevator', 'Rudder']);
    expect(lanes.length).toBeGreaterThanOrEqual(6);
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
    await replayToEnd(page, spiky);
    expect(spikyGlitches).toBe(3);
    // A 3.2 s capture: the 10 s window, the smallest that holds it.
    await expect(page.getByRole('radio', { name: '10 s' }).getAttribute('aria-checked')).resolves.toBe('true');
    // A radio group keyed as one: Tab reaches the chosen window only, the arrows move the choice.
    const windows = page.getByRole('radiogroup', { name: 'Window' });
    await expect(windows.locator('[tabindex="0"]').textContent()).resolves.toBe('10 s');
    await windows.getByRole('radio', { name: '10 s' }).focus();
    await page.keyboard.press('ArrowRight');
    await expect(page.getByRole('radio', { name: '1 min' }).getAttribute('aria-checked')).resolves.toBe('true');
    await expect(page.evaluate(() => document.activeElement?.textContent)).resolves.toBe('1 min');
    await page.keyboard.press('ArrowLeft');
    await page.keyboard.press('ArrowLeft');
    await expect(page.getByRole('radio', { name: '1 s' }).getAttribute('aria-checked')).resolves.toBe('true');
    await page.keyboard.press('End');
    await expect(page.getByRole('radio', { name: '10 min' }).getAttribute('aria-checked')).resolves.toBe('true');
    await page.keyboard.press('ArrowRight'); // wraps
    await expect(page.getByRole('radio', { name: '1 s' }).getAttribute('aria-checked')).resolves.toBe('true');
    await page.keyboard.press('ArrowRight');
    await expect(page.getByRole('radio', { name: '10 s' }).getAttribute('aria-checked')).resolves.toBe('true');
    await page.locator('.trace-picker').getByRole('button', { name: 'All sent' }).click();
    await expect.poll(() => page.getByTestId('glitch-count').textContent()).toBe(`${spikyGlitches} glitches in view`);
    mkdirSync(SHOTS, { recursive: true });
    await page.locator('.traces').screenshot({ path: join(SHOTS, 'hands-traces-glitches-1280-dark.png') });
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('says a capture without timing has no time axis for traces, and draws no empty lanes', async () => {
    const raw = join(dir, 'untimed.bin');
    writeFileSync(raw, simulate(preset('dsmx-11ms-2048-internal'), 2_000_000).bytes);
    const { page, errors } = await open({ query: '?demo=0' });
    await replayToEnd(page, raw);
    await page.locator('.traces').scrollIntoViewIfNeeded();
    await expect.poll(() => page.locator('.trace-note').textContent()).toMatch(/no times/);
    await expect(page.locator('.traces [data-chart="traces"]').isVisible()).resolves.toBe(false);
    // The channels it sent are still offered.
    await expect(page.locator('.trace-picker').getByRole('button', { name: /^0\b/ }).getAttribute('aria-pressed')).resolves.toBe('true');
    expect(errors).toEqual([]);
    await page.context().close();
  });
});

describe.skipIf(skip !== null)('a phone at 390 px', () => {
  it('shows the link state and every channel bar on the first screen, the rest folded until tapped', async () => {
    const { page, errors } = await open({ width: 390, height: 844 });
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await page.waitForTimeout(1000);
    const box = async (selector: string) => {
      const b = await page.locator(selector).first().boundingBox();
      if (b === null) throw new Error(`${selector} is not shown`);
      return b;
    };
    const link = await box('[data-testid="link-state"]');
    const bars = await box('.p-channels');
    console.log(
      `390 × 844: link state at ${Math.round(link.y)} px, channel bars ${Math.round(bars.y)}–${Math.round(bars.y + bars.height)} px`,
    );
    expect(link.y + link.height).toBeLessThan(844);
    expect(bars.y).toBeLessThan(844);
    // All twelve, not only the first.
    expect(bars.y + bars.height).toBeLessThanOrEqual(844);
    // The rest is folded: its disclosure shows, its content does not.
    for (const name of ['diagnosis', 'remotes', 'graphs', 'traces', 'system', 'counters']) {
      await expect(page.locator(`.p-${name} .fold-toggle`).getAttribute('aria-expanded')).resolves.toBe('false');
      await expect(page.locator(`.p-${name} .fold-body`).isVisible()).resolves.toBe(false);
    }
    await page.locator('.p-graphs .fold-toggle').click();
    await expect(page.locator('.p-graphs .fold-toggle').getAttribute('aria-expanded')).resolves.toBe('true');
    await page.locator('.graphs canvas').first().waitFor();
    // The charts take the panel's width once shown (they were made while it was folded).
    await expect
      .poll(() =>
        page
          .locator('.graphs .chart')
          .first()
          .evaluate((e) => e.getBoundingClientRect().width),
      )
      .toBeGreaterThan(300);
    // The worst finding under the link state opens the folded diagnosis and goes there.
    await page.getByTestId('top-finding').click();
    await expect(page.locator('.p-diagnosis .fold-toggle').getAttribute('aria-expanded')).resolves.toBe('true');
    await expect(page.locator('.p-diagnosis .fold-body').isVisible()).resolves.toBe(true);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('gives every control a touch target of 40 px or more, replay speed and window included', async () => {
    const { page, errors } = await open({ width: 390, height: 844, query: '?demo=0' });
    await replayToEnd(page, spiky);
    for (const name of ['graphs', 'traces', 'diagnosis', 'counters', 'system']) await page.locator(`.p-${name} .fold-toggle`).click();
    await page.getByRole('button', { name: 'Inspect frames…' }).click();
    await page.locator('.insp-table').waitFor();
    const small = await page.$$eval('button, select, [role="radio"], input[type="range"]', (els) =>
      els
        .filter((e) => (e as HTMLElement).offsetParent !== null)
        .map((e) => ({ what: `${e.tagName.toLowerCase()} ${e.textContent?.trim() ?? ''}`, h: e.getBoundingClientRect().height }))
        .filter((x) => x.h < 40),
    );
    expect(small).toEqual([]);
    expect(await page.getByRole('radio', { name: '4×' }).count()).toBe(1);
    expect(await page.getByRole('radio', { name: '1 s' }).count()).toBe(1);
    // The bind modes: each row is its radio's target (a tap anywhere on it chooses).
    await page.getByRole('button', { name: 'Bind…' }).first().click();
    await page.getByRole('region', { name: 'Bind a satellite' }).locator('.modes tbody tr').first().waitFor();
    const smallInBind = await page.$$eval('.bind button, .bind select, .bind summary', (els) =>
      els
        .filter((e) => (e as HTMLElement).offsetParent !== null)
        .map((e) => ({
          what: `${e.tagName.toLowerCase()} ${e.textContent?.trim().slice(0, 30) ?? ''}`,
          h: e.getBoundingClientRect().height,
        }))
        .filter((x) => x.h < 40),
    );
    expect(smallInBind).toEqual([]);
    const rows = await page.$$eval('.bind .modes tbody tr', (els) => els.map((e) => e.getBoundingClientRect().height));
    expect(rows.length).toBeGreaterThan(5);
    expect(Math.min(...rows)).toBeGreaterThanOrEqual(40);
    await page
      .locator('.bind .modes tbody tr')
      .nth(2)
      .click({ position: { x: 200, y: 10 } });
    await expect(page.locator('.bind .modes tbody tr').nth(2).locator('input').isChecked()).resolves.toBe(true);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('shows the inspector readable: each row its bytes wrapped whole in their groups, then its values', async () => {
    const { page, errors } = await open({ width: 390, height: 844 });
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await page.getByRole('button', { name: 'Inspect frames…' }).click();
    await page.locator('.insp-body .row.frame').first().waitFor();
    await page.waitForTimeout(600);
    const rows = await page.$$eval('.insp-body .row.frame', (els) =>
      els.slice(-20).map((row) => {
        const scroll = row.closest('.insp-scroll')?.getBoundingClientRect();
        const groups = [...row.querySelectorAll('.g')].map((g) => g.getBoundingClientRect());
        return {
          height: row.getBoundingClientRect().height,
          groups: groups.length,
          // Every byte group inside the visible box, none cut off at its right edge.
          inside: groups.every((g) => scroll !== undefined && g.right <= scroll.right && g.left >= scroll.left),
        };
      }),
    );
    expect(rows.length).toBeGreaterThan(5);
    for (const r of rows) {
      expect(r.groups).toBeGreaterThanOrEqual(8);
      expect(r.inside).toBe(true);
      expect(r.height).toBeLessThan(200);
    }
    const widths = await page.evaluate(() => [document.documentElement.scrollWidth, document.documentElement.clientWidth]);
    expect(widths[0]).toBe(widths[1]);
    expect(errors).toEqual([]);
    await page.context().close();
  });
});

/** The replay timeline's canvas read back: the plot's columns with a lost-frame bar, and whether its time axis is drawn. */
async function timeline(page: Page): Promise<{ width: number; lostColumns: number; axisPixels: number }> {
  return page.$eval('.replay .overview canvas', (c) => {
    const canvas = c as HTMLCanvasElement;
    const ctx = canvas.getContext('2d');
    if (ctx === null) return { width: 0, lostColumns: 0, axisPixels: 0 };
    const { width, height } = canvas;
    const d = ctx.getImageData(0, 0, width, height).data;
    const px = (x: number, y: number) => d.slice((y * width + x) * 4, (y * width + x) * 4 + 4);
    // Red bars: red well above green and blue, and opaque.
    const red = (x: number, y: number) => {
      const [r = 0, g = 0, b = 0, a = 0] = px(x, y);
      return a > 100 && r > 150 && r > g + 60 && r > b + 60;
    };
    const axisTop = Math.round(height * (56 / 78));
    let lostColumns = 0;
    for (let x = 0; x < width; x++) {
      let hit = false;
      for (let y = 0; y < axisTop && !hit; y++) hit = red(x, y);
      if (hit) lostColumns++;
    }
    let axisPixels = 0;
    for (let y = axisTop; y < height; y++) for (let x = 0; x < width; x++) if ((px(x, y)[3] ?? 0) > 100) axisPixels++;
    return { width, lostColumns, axisPixels };
  });
}

describe.skipIf(skip !== null)('a short capture', () => {
  it('draws a 66 ms hold of a 0.74 s capture as long as it was, on a time axis, in the 1 s window', async () => {
    const { page, errors } = await open({ query: '?demo=0' });
    await replayToEnd(page, shortHold);
    await page.locator('.replay .overview canvas').waitFor();
    await page.waitForTimeout(300);
    const t = await timeline(page);
    console.log(`0.74 s capture, 66 ms hold: lost-frame bars over ${t.lostColumns} of ${t.width} px; axis ${t.axisPixels} px`);
    // 66 ms of 740 is 9 % of the width: drawn in 20 ms bins, between 5 % and 15 %, never half of it.
    expect(t.lostColumns).toBeGreaterThan(0.05 * t.width);
    expect(t.lostColumns).toBeLessThan(0.15 * t.width);
    expect(t.axisPixels).toBeGreaterThan(100);
    await expect(page.getByRole('radio', { name: '1 s' }).getAttribute('aria-checked')).resolves.toBe('true');
    await page.locator('section.replay').screenshot({ path: join(SHOTS, 'hands-short-hold-timeline-1280-dark.png') });
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('gives a clean short capture a time axis and no lost-frame bar', async () => {
    const { page, errors } = await open({ query: '?demo=0' });
    await replayToEnd(page, shortClean);
    await page.locator('.replay .overview canvas').waitFor();
    await page.waitForTimeout(300);
    const t = await timeline(page);
    expect(t.lostColumns).toBe(0);
    expect(t.axisPixels).toBeGreaterThan(100);
    await expect(page.getByRole('radio', { name: '1 s' }).getAttribute('aria-checked')).resolves.toBe('true');
    await page.locator('section.replay').screenshot({ path: join(SHOTS, 'hands-short-clean-timeline-1280-dark.png') });
    expect(errors).toEqual([]);
    await page.context().close();
  });
});
