/**
 * The page looked at in every size and theme, in the slow tier (`npm run test:slow`, which
 * `.ci/run` runs too): screenshots to open (not compared) of the live demo, a replay with
 * glitches, the inspector, the channel traces, Bind and the empty state at 390, 1280 and 1920 px,
 * light and dark (test-results/screenshots/), with none wider than its viewport; and axe-core
 * on every state in the light theme. The main tier's browser tests check each behaviour at one
 * size and theme, and axe in the dark. Needs the built page (`npm run build`) and Chromium.
 */
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import {
  SHOTS,
  SIZES,
  browserUnavailable,
  demoRunning,
  openPage,
  replayToEnd,
  shot,
  startApp,
  usbChunks,
  withSpikes,
  writeCapture,
  type AppSession,
} from '../e2e/app-fixture.js';
import { axeStates } from '../e2e/axe.js';

const skip = browserUnavailable();
if (skip !== null) console.warn(`skipping the screenshots: ${skip}`);

let app: AppSession;
let dir = '';
/** A capture with three one-frame glitches, a short dropout and a failsafe. */
let spiky = '';

beforeAll(async () => {
  if (skip !== null) return;
  app = await startApp();
  dir = mkdtempSync(join(tmpdir(), 'satscope-shots-'));
  const sim = withSpikes(simulate(preset('dropouts-failsafe'), 3_200_000, { truth: true }), [30, 90, 140]);
  spiky = join(dir, 'spiky.sscap');
  writeCapture(spiky, usbChunks(sim.bytes, sim.timesUs));
});

afterAll(async () => {
  if (skip !== null) return;
  await app.close();
  rmSync(dir, { recursive: true, force: true });
});

const open = (options: Parameters<typeof openPage>[1] = {}) => openPage(app, options);

/** Where the screenshots go, beside the other browser tests' (opened and looked at, not compared). */
const OUT = join(SHOTS, 'hands');

describe.skipIf(skip !== null)('screenshots', () => {
  it('of the live demo, a replay, the inspector and the traces at 390, 1280 and 1920 px, light and dark', async () => {
    mkdirSync(OUT, { recursive: true });
    // One page a theme and state, resized to each width (the layout follows the width alone):
    // the demo's 3 s of history is waited for once a theme, not once a shot.
    for (const scheme of ['light', 'dark'] as const) {
      const demo = await open({ width: 1920, height: 1080, scheme });
      await demo.page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
      // 3 s of the demo's history (270 frames at 11 ms) in the graphs and traces.
      await demo.page.waitForFunction(() => Number(document.querySelector('[data-testid="count-frames"]')?.textContent) >= 270);
      for (const size of SIZES) {
        await demo.page.setViewportSize({ width: size.width, height: size.height });
        await demo.page.evaluate(() => window.scrollTo(0, 0));
        await demo.page.screenshot({ path: join(OUT, `demo-first-screen-${size.name}-${scheme}.png`) });
        await demo.page.screenshot({ path: join(OUT, `demo-${size.name}-${scheme}.png`), fullPage: true });
        if (size.width < 600) {
          for (const name of ['graphs', 'traces']) {
            const toggle = demo.page.locator(`.p-${name} .fold-toggle`);
            if ((await toggle.getAttribute('aria-expanded')) !== 'true') await toggle.click();
          }
          await demo.page.locator('.traces canvas').waitFor();
          await demo.page.screenshot({ path: join(OUT, `demo-unfolded-${size.name}-${scheme}.png`), fullPage: true });
        }
        // The traces draw while on screen: shot once drawn (their glitch count is then shown).
        await demo.page.locator('.traces').scrollIntoViewIfNeeded();
        await demo.page.getByTestId('glitch-count').waitFor();
        await demo.page.locator('.traces').screenshot({ path: join(OUT, `traces-${size.name}-${scheme}.png`) });
      }
      await demo.page.getByRole('button', { name: 'Inspect frames…' }).click();
      await demo.page.locator('.insp-body .row.frame').first().waitFor();
      for (const size of SIZES) {
        await demo.page.setViewportSize({ width: size.width, height: size.height });
        await demo.page.locator('.p-inspector').screenshot({ path: join(OUT, `inspector-${size.name}-${scheme}.png`) });
      }
      await demo.page.context().close();
      const rep = await open({ width: 390, height: 844, scheme, query: '?demo=0' });
      await replayToEnd(rep.page, spiky);
      await rep.page.locator('.p-traces .fold-toggle').click();
      for (const size of SIZES) {
        await rep.page.setViewportSize({ width: size.width, height: size.height });
        await rep.page.locator('.traces').scrollIntoViewIfNeeded();
        await rep.page.getByTestId('glitch-count').waitFor();
        await rep.page.evaluate(() => window.scrollTo(0, 0));
        await rep.page.screenshot({ path: join(OUT, `replay-${size.name}-${scheme}.png`), fullPage: true });
      }
      await rep.page.context().close();
    }
  }, 240_000);

  it('takes screenshots of the demo, Bind, a replay and the empty state at three sizes in both themes, none wider than its viewport', async () => {
    const report: string[] = [];
    // One page a theme and state, resized to each width (the layout follows the width alone).
    for (const scheme of ['light', 'dark'] as const) {
      const shootAll = async (page: Page, state: string) => {
        for (const size of SIZES) {
          await page.setViewportSize({ width: size.width, height: size.height });
          const w = await page.evaluate(() => ({
            document: document.documentElement.scrollWidth,
            viewport: document.documentElement.clientWidth,
          }));
          report.push(`${size.name} ${scheme} ${state}: document ${w.document} / viewport ${w.viewport}`);
          expect(w.document, `${state} ${size.name} ${scheme}`).toBe(w.viewport);
          if (size.width >= 1280) {
            const h = await page.locator('.toolbar').evaluate((e) => e.getBoundingClientRect().height);
            expect(h, `toolbar at ${size.name} (${state})`).toBeLessThan(56);
          }
          await shot(page, `ui-${state}-${size.name}-${scheme}`);
        }
      };
      const empty = await open({ width: 390, height: 844, scheme, query: '?demo=0' });
      await empty.page.getByTestId('empty-state').waitFor();
      await shootAll(empty.page, 'empty');
      await empty.page.context().close();

      const demo = await open({ width: 390, height: 844, scheme });
      await demoRunning(demo.page);
      // 4 s of the demo's history (360 frames at 11 ms) in the graphs.
      await demo.page.waitForFunction(() => Number(document.querySelector('[data-testid="count-frames"]')?.textContent) >= 360);
      await shootAll(demo.page, 'demo');
      await demo.page.getByRole('button', { name: 'Bind…' }).click();
      await demo.page.locator('.bind').waitFor();
      await shootAll(demo.page, 'bind');
      await demo.page.context().close();

      const rep = await open({ width: 390, height: 844, scheme, query: '?demo=0' });
      await replayToEnd(rep.page, spiky);
      await shootAll(rep.page, 'replay');
      await rep.page.context().close();
    }
    console.log(report.join('\n'));
  }, 240_000);

  it('has no serious or critical axe-core violation in any state of the page (light theme)', async () => {
    expect(await axeStates(app, 'light', spiky)).toEqual([]);
  }, 180_000);
});
