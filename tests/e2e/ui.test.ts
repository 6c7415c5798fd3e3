/**
 * The page on any screen and with any input, in Debian's Chromium: nothing wider than a phone's
 * viewport, a one-row toolbar on a laptop, the empty state that says what to do, keyboard-only
 * use with visible focus, light and dark themes, graphs that label their axes and show values
 * on hover, and axe-core with no serious or critical violation (the dark theme here; the light
 * one, and screenshots at three sizes in both themes, in tests/slow/screenshots.test.ts).
 */
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { readCapture } from '../../src/capture/sniff.js';
import { summarizeCapture } from '../../src/report/summary.js';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import { agoLabel, agoSplits, decimals, niceSplits, niceTop, timeStep } from '../../src/app/axes.js';
import {
  SHOTS,
  browserUnavailable,
  demoRunning,
  openPage,
  replayToEnd,
  startApp,
  usbChunks,
  writeCapture,
  type AppSession,
} from './app-fixture.js';
import { axeStates } from './axe.js';

const skip = browserUnavailable();
if (skip !== null) console.warn(`skipping the page tests: ${skip}`);

let app: AppSession;
let dir = '';
let capture = '';
let vtxCapture = '';

beforeAll(async () => {
  if (skip !== null) return;
  app = await startApp();
  dir = mkdtempSync(join(tmpdir(), 'satscope-ui-'));
  const sim = simulate(preset('dropouts-failsafe'), undefined);
  capture = join(dir, 'dropouts.sscap');
  writeCapture(capture, usbChunks(sim.bytes, sim.timesUs));
  const vtx = simulate(preset('vtx'), 1_000_000);
  vtxCapture = join(dir, 'vtx.sscap');
  writeCapture(vtxCapture, usbChunks(vtx.bytes, vtx.timesUs));
});

afterAll(async () => {
  if (skip !== null) return;
  await app.close();
  rmSync(dir, { recursive: true, force: true });
});

const open = (options: Parameters<typeof openPage>[1] = {}) => openPage(app, options);

/** The document's width against the viewport's (without its scrollbar). */
async function widths(page: Page): Promise<{ document: number; viewport: number; inner: number }> {
  return page.evaluate(() => ({
    document: document.documentElement.scrollWidth,
    viewport: document.documentElement.clientWidth,
    inner: window.innerWidth,
  }));
}

/** Elements whose right edge passes the viewport's, by a short description. */
async function overflowing(page: Page): Promise<string[]> {
  return page.evaluate(() => {
    const vw = document.documentElement.clientWidth;
    const out: string[] = [];
    for (const el of document.querySelectorAll<HTMLElement>('body *')) {
      const r = el.getBoundingClientRect();
      if (r.width === 0 || r.right <= vw + 0.5) continue;
      // Only the outermost: inside a scrolling box, overflow is that box's business.
      let p = el.parentElement;
      let clipped = false;
      while (p !== null && p !== document.body) {
        const o = getComputedStyle(p).overflowX;
        if (o === 'auto' || o === 'scroll' || o === 'hidden' || o === 'clip') {
          clipped = true;
          break;
        }
        p = p.parentElement;
      }
      if (!clipped) out.push(`${el.tagName.toLowerCase()}.${el.className} right=${Math.round(r.right)}`);
    }
    return out.slice(0, 10);
  });
}

describe("the graphs' axes", () => {
  it('count time back from now in round steps, so the labels stay put as the window slides', () => {
    expect(timeStep(60, 600)).toBe(10);
    expect(timeStep(10, 600)).toBe(2);
    expect(timeStep(600, 600)).toBe(120);
    expect(timeStep(600, 1000)).toBe(60);
    expect(timeStep(60, 300)).toBe(15);
    // Whatever the clock reads, the labels are the same round ones.
    for (const end of [12.345, 59.001, 1234.5]) {
      const ticks = agoSplits(end - 60, end, 10);
      expect(ticks.map((t) => agoLabel(t - end))).toEqual(['−60 s', '−50 s', '−40 s', '−30 s', '−20 s', '−10 s', 'now']);
    }
    expect(agoSplits(0, 600, 120).map((t) => agoLabel(t - 600, 120))).toEqual(['−10 min', '−8 min', '−6 min', '−4 min', '−2 min', 'now']);
  });

  it('give every y axis a round range and several labels, also when every value is zero or missing', () => {
    expect(niceTop(0)).toBe(1);
    expect(niceTop(null)).toBe(1);
    expect(niceTop(Number.NaN, 2)).toBe(2);
    expect(niceTop(0.7)).toBe(1);
    expect(niceTop(3.2)).toBe(5);
    expect(niceTop(17)).toBe(20);
    expect(niceSplits(1)).toEqual([0, 0.2, 0.4, 0.6, 0.8, 1]);
    expect(niceSplits(20)).toEqual([0, 5, 10, 15, 20]);
    expect(niceSplits(2, true)).toEqual([0, 1, 2]);
    expect(niceSplits(50)).toEqual([0, 10, 20, 30, 40, 50]);
    // A short chart gets fewer labels, still round.
    expect(niceSplits(500, false, 2)).toEqual([0, 250, 500]);
    expect(niceSplits(20, true, 2)).toEqual([0, 10, 20]);
    expect(niceSplits(1, false, 3)).toEqual([0, 0.5, 1]);
    // Labels are exact: 0.25 is "0.25", never "0.3".
    expect(niceSplits(1, false, 4)).toEqual([0, 0.25, 0.5, 0.75, 1]);
    expect(decimals(0.25)).toBe(2);
    expect(decimals(0.2)).toBe(1);
    expect(decimals(2.5)).toBe(1);
    expect(decimals(250)).toBe(0);
  });
});

describe.skipIf(skip !== null)('the page on any screen', () => {
  it('shows what to do with no source: the wiring and the three ways to start, and no empty bars', async () => {
    const { page, errors } = await open({ query: '?demo=0' });
    const empty = page.getByTestId('empty-state');
    await empty.waitFor();
    const text = (await empty.textContent()) ?? '';
    expect(text).toMatch(/grey.*DATA/s);
    expect(text).toMatch(/RX/);
    expect(text).toMatch(/black.*ground/s);
    expect(text).toMatch(/orange.*3\.3 V/s);
    expect(text).toMatch(/Never 5 V/);
    for (const name of ['Connect receiver', 'Open capture…', 'Start demo'])
      await empty.getByRole('button', { name, exact: true }).waitFor();
    // None of the views that have nothing to say.
    await expect(page.locator('.bar:not(.scale)').count()).resolves.toBe(0);
    await expect(page.getByText('no data').count()).resolves.toBe(0);
    await expect(page.getByText('Last frame').count()).resolves.toBe(0);
    await expect(page.getByTestId('source-status').textContent()).resolves.toBe('No receiver');
    // Open capture asks for a file, and the file replays.
    const chooser = page.waitForEvent('filechooser');
    await empty.getByRole('button', { name: 'Open capture…' }).click();
    await (await chooser).setFiles(capture);
    await page.locator('section.replay').waitFor();
    await empty.waitFor({ state: 'detached' });
    await page.reload();
    await page.getByTestId('empty-state').waitFor();
    await empty.getByRole('button', { name: 'Start demo' }).click();
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await empty.waitFor({ state: 'detached' });
    // Stopping the demo brings the help back.
    await page.getByRole('button', { name: 'Stop demo' }).click();
    await page.getByTestId('empty-state').waitFor();
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('fits a 390 px phone: the document is as wide as the viewport, bars keep their track, chips are whole', async () => {
    const { page, errors } = await open({ width: 390, height: 844 });
    await demoRunning(page);
    await page.waitForTimeout(1500);
    const w = await widths(page);
    console.log(`390 demo: document ${w.document} px, viewport ${w.viewport} px (window ${w.inner})`);
    expect(await overflowing(page)).toEqual([]);
    expect(w.document).toBe(w.viewport);
    const tracks = await page.$$eval('.channel-list .bar .track', (els) => els.map((e) => e.getBoundingClientRect().width));
    expect(tracks.length).toBeGreaterThanOrEqual(12);
    for (const t of tracks) expect(t).toBeGreaterThan(100);
    // The raw and % columns went first.
    await expect(page.locator('.channel-list .bar .raw').first().isVisible()).resolves.toBe(false);
    await expect(page.locator('.channel-list .bar .pct').first().isVisible()).resolves.toBe(false);
    // State chips are not clipped ("HOL"): their text fits (the remotes' panel unfolded).
    await page.locator('.p-remotes .fold-toggle').click();
    const chips = await page.$$eval('.state-chip', (els) => els.map((e) => e.scrollWidth - e.clientWidth));
    for (const c of chips) expect(c).toBeLessThanOrEqual(0);
    // The inspector's table scrolls inside its panel.
    await page.getByRole('button', { name: 'Inspect frames…' }).click();
    await page.locator('.insp-table').waitFor();
    const after = await widths(page);
    expect(after.document).toBe(after.viewport);
    // So does the bind panel.
    await page.getByRole('button', { name: 'Bind…' }).click();
    await page.locator('.bind').waitFor();
    const bind = await widths(page);
    console.log(`390 demo + inspector + bind: document ${bind.document} px, viewport ${bind.viewport} px`);
    expect(await overflowing(page)).toEqual([]);
    expect(bind.document).toBe(bind.viewport);
    // A message with a long text wraps inside the page.
    const notes = join(dir, 'a-file-with-a-rather-long-name-that-is-not-a-capture-at-all.txt');
    writeFileSync(notes, 'shopping list\neggs\n');
    await page.setInputFiles('input[type=file]', notes);
    await page.getByRole('alert').first().waitFor();
    const notice = await widths(page);
    expect(await overflowing(page)).toEqual([]);
    expect(notice.document).toBe(notice.viewport);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('keeps the toolbar on one row at 1280 px, with the rarer actions behind menus', async () => {
    const { page } = await open({ width: 1280, height: 800 });
    await demoRunning(page);
    const rows = await page.$$eval(
      '.toolbar > :not(.recovered)',
      (els) => new Set(els.map((e) => Math.round(e.getBoundingClientRect().top + e.getBoundingClientRect().height / 2))).size,
    );
    const height = await page.locator('.toolbar').evaluate((e) => e.getBoundingClientRect().height);
    console.log(`1280 toolbar: ${rows} distinct row centres, ${Math.round(height)} px high`);
    expect(height).toBeLessThan(56);
    // Still one row while recording and with an export to offer.
    await page.getByRole('button', { name: '● Record' }).click();
    await page
      .locator('.rec-info')
      .filter({ hasText: /^0:0[1-9]|^[1-9]|^0:[1-5]/ })
      .waitFor({ timeout: 5000 });
    await expect(page.locator('.toolbar').evaluate((e) => e.getBoundingClientRect().height)).resolves.toBeLessThan(56);
    await page.getByRole('button', { name: 'Stop recording' }).click();
    await page.getByRole('button', { name: 'Export .sscap' }).waitFor();
    await expect(page.locator('.toolbar').evaluate((e) => e.getBoundingClientRect().height)).resolves.toBeLessThan(56);
    // No text links among the buttons.
    await expect(page.locator('.toolbar > .tb-group > button.link').count()).resolves.toBe(0);
    // Resolution lives in Settings.
    await page.getByRole('button', { name: 'Settings', exact: true }).click();
    await page.getByRole('combobox', { name: 'Resolution' }).waitFor();
    await page.keyboard.press('Escape');
    await expect(page.getByRole('combobox', { name: 'Resolution' }).count()).resolves.toBe(0);
    await expect(page.getByRole('button', { name: 'Settings', exact: true }).evaluate((e) => e === document.activeElement)).resolves.toBe(
      true,
    );
    await page.context().close();
  });

  it('closes a menu with Escape from the moment its panel shows, before the next frame', async () => {
    const { page, errors } = await open({ width: 1280, height: 800 });
    await demoRunning(page);
    // All in one task: open, wait only for Preact's render (microtasks), press Escape. A key
    // listener added after the next animation frame would miss the key, as a busy page did.
    const result = await page.evaluate(async () => {
      const button = [...document.querySelectorAll<HTMLButtonElement>('.menu-button')].find((b) => b.textContent?.trim() === 'Settings');
      if (button === undefined) return 'no Settings button';
      button.click();
      const panel = document.getElementById(button.getAttribute('aria-controls') ?? '');
      for (let i = 0; i < 20 && panel?.hidden !== false; i++) await Promise.resolve();
      if (panel?.hidden !== false) return 'the panel did not show';
      document.dispatchEvent(new KeyboardEvent('keydown', { key: 'Escape', bubbles: true }));
      for (let i = 0; i < 20 && !panel.hidden; i++) await Promise.resolve();
      return panel.hidden && document.activeElement === button ? 'closed' : 'still open';
    });
    expect(result).toBe('closed');
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('selects a remote with the keyboard alone, with visible focus on the way', async () => {
    const { page, errors } = await open({ width: 1280, height: 800 });
    await demoRunning(page);
    await page.locator('body').click({ position: { x: 1, y: 700 } });
    let reached = false;
    const outlines: string[] = [];
    for (let i = 0; i < 60 && !reached; i++) {
      await page.keyboard.press('Tab');
      const focus = await page.evaluate(() => {
        const el = document.activeElement as HTMLElement | null;
        if (el === null || el === document.body) return null;
        const s = getComputedStyle(el);
        return {
          inB: el.closest('[data-testid="remote-B"]') !== null && el.tagName === 'BUTTON',
          outline: `${s.outlineStyle} ${s.outlineWidth}`,
          text: el.textContent ?? '',
        };
      });
      if (focus === null) continue;
      outlines.push(focus.outline);
      reached = focus.inB;
    }
    expect(reached).toBe(true);
    await page.locator('.remotes').screenshot({ path: join(SHOTS, 'ui-keyboard-focus-1280-dark.png') });
    // Every stop on the way had a visible focus ring.
    for (const o of outlines) expect(o).toMatch(/^(solid|auto) [1-9]/);
    await page.keyboard.press('Enter');
    await page.locator('.panel h2', { hasText: 'remote B' }).waitFor();
    await expect(page.getByTestId('remote').textContent()).resolves.toBe('External remote');
    await expect(page.locator('[data-testid="remote-B"] button[aria-pressed="true"]').count()).resolves.toBe(1);
    // And back with Space.
    await page.keyboard.press('Shift+Tab');
    await page.keyboard.press('Shift+Tab');
    await page.locator('[data-testid="remote-A"] button.show').focus();
    await page.keyboard.press('Space');
    await expect(page.getByTestId('remote').textContent()).resolves.toBe('Internal remote');
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('follows the system theme, and the toggle switches it and is remembered', async () => {
    const { page } = await open({ scheme: 'light', query: '?demo=0' });
    const bg = () => page.evaluate(() => getComputedStyle(document.body).backgroundColor);
    await expect(page.evaluate(() => document.documentElement.dataset.theme)).resolves.toBe('light');
    const light = await bg();
    const toggle = page.getByRole('button', { name: 'Dark theme' });
    await expect(toggle.getAttribute('aria-pressed')).resolves.toBe('false');
    await toggle.click();
    await expect(page.evaluate(() => document.documentElement.dataset.theme)).resolves.toBe('dark');
    await expect(toggle.getAttribute('aria-pressed')).resolves.toBe('true');
    expect(await bg()).not.toBe(light);
    await page.reload();
    await page.getByTestId('empty-state').waitFor();
    await expect(page.evaluate(() => document.documentElement.dataset.theme)).resolves.toBe('dark');
    // Back to following the system, from Settings.
    await page.getByRole('button', { name: 'Settings', exact: true }).click();
    await page.getByRole('combobox', { name: 'Theme' }).selectOption('system');
    await expect(page.evaluate(() => document.documentElement.dataset.theme)).resolves.toBe('light');
    await page.context().close();
    const dark = await open({ scheme: 'dark', query: '?demo=0' });
    await expect(dark.page.evaluate(() => document.documentElement.dataset.theme)).resolves.toBe('dark');
    await dark.page.context().close();
  });

  it('shows the values under the cursor when a graph is hovered, or stepped through from the keyboard', async () => {
    const { page } = await open({ width: 1280, height: 800 });
    await demoRunning(page);
    // 3 s of the demo's history (270 frames at 11 ms) in the graphs.
    await page.waitForFunction(() => Number(document.querySelector('[data-testid="count-frames"]')?.textContent) >= 270);
    const chart = page.locator('.chart[data-chart="periodMs"] .u-over');
    await chart.scrollIntoViewIfNeeded();
    const box = (await chart.boundingBox())!;
    await page.mouse.move(box.x + box.width - 20, box.y + box.height / 2);
    const legend = page.locator('.chart[data-chart="periodMs"] .u-legend .u-value');
    await expect.poll(async () => legend.nth(1).textContent()).toMatch(/^\d+\.\d\d ms$/);
    await expect(legend.nth(0).textContent()).resolves.toMatch(/^(now|−\d+\.\d s)$/);
    // The other graphs follow the same cursor.
    await expect.poll(async () => page.locator('.chart[data-chart="fadeRate"] .u-legend .u-value').nth(1).textContent()).toMatch(/\/s$/);
    // The keyboard gets there too: focus a graph, step back a second with the arrow keys.
    await page.mouse.move(0, 0);
    const lost = page.locator('.chart[data-chart="lost"]');
    await lost.focus();
    await page.keyboard.press('End');
    for (let i = 0; i < 10; i++) await page.keyboard.press('ArrowLeft');
    const time = async () =>
      Number(((await lost.locator('.u-legend .u-value').nth(0).textContent()) ?? '').replace('−', '-').replace(' s', ''));
    await expect.poll(time).toBeLessThan(-0.8);
    // The other graphs show the same time, read in one turn of the page's loop (the demo is live
    // and the cursor's time moves as the data slides).
    const both = () =>
      page.evaluate(() =>
        ['lost', 'periodMs'].map((name) => document.querySelector(`.chart[data-chart="${name}"] .u-legend .u-value`)?.textContent),
      );
    await expect
      .poll(async () => {
        const [a, b] = await both();
        return a === b ? a : `${a} ≠ ${b}`;
      })
      .toMatch(/^−\d+\.\d s$/);
    await page.context().close();
  });

  it("draws the graphs' axis labels when the axes change, not on every redraw as the data slides", async () => {
    const { page } = await open({ width: 1280, height: 800 });
    await demoRunning(page);
    await page.waitForTimeout(1000);
    // Every canvas's redraws (uPlot clears the canvas for each) and text drawn, over three seconds.
    const counts = await page.evaluate(async () => {
      const c = { clears: 0, texts: 0 };
      const proto = CanvasRenderingContext2D.prototype;
      const { clearRect, fillText } = proto;
      proto.clearRect = function (...args: Parameters<typeof clearRect>) {
        c.clears++;
        clearRect.apply(this, args);
      };
      proto.fillText = function (...args: Parameters<typeof fillText>) {
        c.texts++;
        fillText.apply(this, args);
      };
      await new Promise((resolve) => setTimeout(resolve, 3000));
      proto.clearRect = clearRect;
      proto.fillText = fillText;
      return c;
    });
    // Three graphs ten times a second and the remotes' chart five: about 100 redraws. Each drew
    // its 10–15 labels again when the axes were part of it; now only a change of range does.
    expect(counts.clears).toBeGreaterThan(50);
    expect(counts.texts).toBeLessThan(counts.clears);
    await page.context().close();
  });

  it('counts empty slots and VTX frames in the inspector, as the decoder does', async () => {
    const bytes = new Uint8Array(readFileSync(vtxCapture));
    const expected = summarizeCapture(readCapture(bytes, 'vtx.sscap')).decoder;
    expect(expected.vtxFrames).toBeGreaterThan(0);
    const { page, errors } = await open({ query: '?demo=0' });
    await replayToEnd(page, vtxCapture);
    await page.getByRole('button', { name: 'Inspect frames…' }).click();
    const counts = page.getByTestId('inspector-counts');
    await counts.waitFor();
    const text = (await counts.textContent()) ?? '';
    expect(text).toContain(`${expected.frames} frames shown`);
    expect(text).toContain(`${expected.vtxFrames} VTX frame`);
    if (expected.emptySlots > 0) expect(text).toContain(`${expected.emptySlots} empty slot`);
    // A decoded value never breaks across lines.
    const broken = await page.$$eval(
      '.inspector .summary .v',
      (els) => els.filter((e) => e.getClientRects().length > 1 || e.getBoundingClientRect().height > 24).length,
    );
    expect(broken).toBe(0);
    await page.locator('.inspector').screenshot({ path: join(SHOTS, 'ui-inspector-vtx-1280-dark.png') });
    expect(errors).toEqual([]);
    await page.context().close();
  });

  // The light theme's walk is in the slow tier (tests/slow/screenshots.test.ts).
  it('has no serious or critical axe-core violation in any state of the page (dark theme)', async () => {
    expect(await axeStates(app, 'dark', capture)).toEqual([]);
  }, 120_000);
});
