/**
 * The small things a user trips on, in Chromium: the status pill whole at 1280 px, one unit for
 * the fade rate, the Bind panel (Escape closes it, its radios take the arrow keys, its wiring
 * follows the theme with text of at least 11 px, the wiring guide ships with the page), and the
 * replay's paused and ended states. Screenshots at 390 and 1280 px, light and dark.
 */
import type { Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import { browserUnavailable, shot, startApp, usbChunks, writeCapture, type AppSession } from './app-fixture.js';

const skip = browserUnavailable();
if (skip !== null) console.warn(`skipping the page-parts tests: ${skip}`);

let app: AppSession;
let dir = '';

beforeAll(async () => {
  if (skip !== null) return;
  app = await startApp();
  dir = mkdtempSync(join(tmpdir(), 'satscope-parts-'));
});

afterAll(async () => {
  if (skip !== null) return;
  await app.close();
  rmSync(dir, { recursive: true, force: true });
});

async function open(width: number, theme: 'light' | 'dark', query = ''): Promise<{ page: Page; errors: string[] }> {
  const context = await app.browser.newContext({ viewport: { width, height: 900 }, colorScheme: theme, acceptDownloads: true });
  const page = await context.newPage();
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(m.text());
  });
  await page.goto(app.server.url(`/${query}`));
  return { page, errors };
}

/** Whether an element's text is cut off (wider than its box). */
const clipped = (page: Page, testId: string) => page.getByTestId(testId).evaluate((e) => e.scrollWidth > e.clientWidth + 1);

describe.skipIf(skip !== null)('the page parts', () => {
  it('shows the status pill whole at 1280 px, live, recording and in replay', async () => {
    const { page, errors } = await open(1280, 'light');
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await expect(clipped(page, 'source-status')).resolves.toBe(false);
    await page.getByRole('button', { name: '● Record' }).click();
    // The pill and the button as wide as a recording makes them: a second or more recorded, its size shown.
    await page
      .locator('.rec-info')
      .filter({ hasText: /^0:0[1-9]|^[1-9]|^0:[1-5]/ })
      .waitFor({ timeout: 5000 });
    await expect(clipped(page, 'source-status')).resolves.toBe(false);
    await page.getByRole('button', { name: 'Stop recording' }).click();
    await page.getByRole('button', { name: 'Export .sscap' }).waitFor();
    await expect(clipped(page, 'source-status')).resolves.toBe(false);
    await expect(page.locator('.toolbar').evaluate((e) => e.getBoundingClientRect().height)).resolves.toBeLessThan(56);
    // One unit for the fade rate, the Remotes table's: per minute.
    await expect(page.getByTestId('count-fades').textContent()).resolves.toMatch(/^\d+ \(\d+\/min\)$/);
    await shot(page, 'parts-1280-light-toolbar');
    // A replay: paused and ended are said in the visible words, the full line is its tooltip.
    const sim = simulate(preset('dsmx-11ms-2048-internal'), 2_000_000);
    const path = join(dir, 'pill.sscap');
    writeCapture(path, usbChunks(sim.bytes, sim.timesUs));
    await page.setInputFiles('input[type=file]', path);
    await page.locator('section.replay').waitFor();
    await page.getByRole('button', { name: 'Pause' }).click();
    await page.getByTestId('source-status').filter({ hasText: 'Replay paused' }).waitFor();
    await expect(clipped(page, 'source-status')).resolves.toBe(false);
    await expect(page.getByTestId('source-status').getAttribute('title')).resolves.toBe('pill.sscap (paused)');
    expect(errors).toEqual([]);
    await page.context().close();
  });

  // Each width once and each theme once (every size in both themes: the slow tier's screenshots).
  for (const [width, theme] of [
    [390, 'light'],
    [1280, 'dark'],
  ] as const)
    it(`shows the Bind panel at ${width} px (${theme}): themed wiring, 11 px text, arrow keys, the guide, Escape`, async () => {
      const { page, errors } = await open(width, theme);
      await page.getByRole('button', { name: 'Bind…' }).first().click();
      const panel = page.getByRole('region', { name: 'Bind a satellite' });
      await panel.waitFor();
      const svg = panel.locator('.wiring-scroll svg');
      await svg.waitFor();
      // The diagram's background is the panel's, in either theme.
      const colours = await panel.evaluate((p) => {
        const bg = p.querySelector('.wiring-scroll .bg');
        return { bg: bg === null ? '' : getComputedStyle(bg).fill, panel: getComputedStyle(p).backgroundColor };
      });
      expect(colours.bg).toBe(colours.panel);
      // Its smallest text as drawn: at least 11 px.
      const smallest = await svg.evaluate((s) => {
        const scale = s.getBoundingClientRect().width / 900;
        return Math.min(...[...s.querySelectorAll('text')].map((t) => Number.parseFloat(getComputedStyle(t).fontSize) * scale));
      });
      expect(smallest).toBeGreaterThanOrEqual(11);
      // The bind modes are radios: the arrow keys move the choice.
      await page.getByRole('radio', { name: '9 pulses' }).focus();
      await page.keyboard.press('ArrowDown');
      await expect(page.getByRole('radio', { name: '10 pulses' }).isChecked()).resolves.toBe(true);
      await page.keyboard.press('ArrowUp');
      await expect(page.getByRole('radio', { name: '9 pulses' }).isChecked()).resolves.toBe(true);
      // The wiring guide ships with the page.
      await page.getByText('Guide: binding wiring and timeline').click();
      await expect(page.getByTestId('bind-guide').textContent()).resolves.toMatch(/^# Binding a satellite from the page/);
      await page.getByText('Guide: binding wiring and timeline').click();
      await shot(page, `parts-${width}-${theme}-bind`);
      // Escape closes the panel.
      await page.keyboard.press('Escape');
      await panel.waitFor({ state: 'detached', timeout: 2000 });
      expect(errors).toEqual([]);
      await page.context().close();
    });

  for (const [width, theme] of [
    [390, 'dark'],
    [1280, 'light'],
  ] as const)
    it(`says Paused and Ended in a replay at ${width} px (${theme}), never Live`, async () => {
      const sim = simulate(preset('dropouts-failsafe'), undefined, { truth: true });
      const path = join(dir, `dropouts-${width}-${theme}.sscap`);
      writeCapture(path, usbChunks(sim.bytes, sim.timesUs));
      const { page, errors } = await open(width, theme, '?demo=0');
      await page.setInputFiles('input[type=file]', path);
      await page.locator('section.replay').waitFor();
      await page.getByRole('button', { name: 'Pause' }).click();
      // The worker says it paused: wait for its word, then read the hint it came with.
      await page
        .getByTestId('link-state')
        .filter({ hasText: /^Paused$/ })
        .waitFor({ timeout: 5000 });
      await expect.poll(() => page.getByTestId('link-hint').textContent()).toMatch(/^Paused at \d:\d\d\.\d of the capture: there /);
      await shot(page, `parts-${width}-${theme}-paused`);
      await page.getByRole('radio', { name: 'max' }).click();
      await page.getByRole('button', { name: 'Play' }).click();
      await page.getByTestId('link-state').filter({ hasText: 'Ended' }).waitFor({ timeout: 20_000 });
      await expect(page.getByTestId('link-hint').textContent()).resolves.toMatch(/^Replay ended at 0:03\.\d: there the link was live\.$/);
      // Min / max / last open, and the frames export in the Report menu, fit the width.
      await page.getByText('Min / max / last per channel').first().click();
      await page.getByTestId('channel-ranges').first().locator('tbody tr').first().filter({ hasText: 'µs' }).waitFor();
      await page.getByRole('button', { name: 'Report', exact: true }).click();
      await page.getByRole('group', { name: 'Decoded frames of remote A' }).waitFor();
      await expect(page.evaluate(() => document.documentElement.scrollWidth)).resolves.toBeLessThanOrEqual(width);
      const pop = await page.locator('.menu-pop:not([hidden])').boundingBox();
      expect(pop?.x).toBeGreaterThanOrEqual(0);
      expect((pop?.x ?? 0) + (pop?.width ?? 0)).toBeLessThanOrEqual(width);
      const table = await page
        .getByTestId('channel-ranges')
        .first()
        .evaluate((t) => t.getBoundingClientRect().right);
      const box = await page
        .locator('section.channels')
        .first()
        .evaluate((c) => c.getBoundingClientRect().right);
      expect(table).toBeLessThanOrEqual(box + 1);
      await shot(page, `parts-${width}-${theme}-ended`);
      expect(errors).toEqual([]);
      await page.context().close();
    });
});
