/**
 * Screenshots to open and look at (not compared): the live demo, a replay with glitches, the
 * inspector and the channel traces at 390, 1280 and 1920 px, light and dark, in
 * test-results/screenshots/hands/. They assert nothing the main tier's browser tests do not, so
 * they run in the slow tier (`npm run test:slow`, which `.ci/run` runs too). Needs the built
 * page (`npm run build`) and Debian's Chromium.
 */
import { mkdirSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { afterAll, beforeAll, describe, it } from 'vitest';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import {
  SHOTS,
  SIZES,
  browserUnavailable,
  openPage,
  replayToEnd,
  startApp,
  usbChunks,
  withSpikes,
  writeCapture,
  type AppSession,
} from '../e2e/app-fixture.js';

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
});
