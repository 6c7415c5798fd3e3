/**
 * Honest states on the page (issues "one truth" and "the page as an instrument"): a Saleae
 * export replays on its own clock with a timeline, seeking and speeds, and ends frozen at its
 * last recorded time; forcing a resolution that no frame fits says so and counts nothing as
 * link loss; a capture with dropouts and line damage replayed in the page ends with the figures
 * `satscope info` gives for the same file; a paused replay's graphs hold the missed frames its
 * counters count. Needs the built page (`npm run build`) and Debian's
 * Chromium.
 */
import { spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { importSaleaeCsv } from '../../src/capture/saleae.js';
import { readCapture } from '../../src/capture/sniff.js';
import type { Capture } from '../../src/capture/model.js';
import { LinkMonitor } from '../../src/decoder/link.js';
import { SpektrumDecoder } from '../../src/decoder/decoder.js';
import { USB_CHUNK_JITTER_US } from '../../src/decoder/spec.js';
import { summarizeCapture } from '../../src/report/summary.js';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import { resolutionSource } from '../../src/app/components/SystemBadge/words.js';
import {
  ROOT,
  SHARED_CAPTURES,
  browserUnavailable,
  shot,
  startApp,
  usbChunks,
  writeCapture,
  writeLongCapture,
  type AppSession,
} from './app-fixture.js';
import { withoutIndex } from '../feeds.js';

const skip = browserUnavailable();
if (skip !== null) console.warn(`skipping the honest-state page tests: ${skip}`);

let app: AppSession;
let dir = '';

beforeAll(async () => {
  if (skip !== null) return;
  app = await startApp();
  dir = mkdtempSync(join(tmpdir(), 'satscope-truth-'));
});

afterAll(async () => {
  if (skip !== null) return;
  await app.close();
  rmSync(dir, { recursive: true, force: true });
});

async function open(query = ''): Promise<{ page: Page; errors: string[] }> {
  const context = await app.browser.newContext({ viewport: { width: 1400, height: 1000 } });
  const page = await context.newPage();
  const errors: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  await page.goto(app.server.url(`/${query}`));
  return { page, errors };
}

/** A Saleae async-serial export: the real PX4 DX9 capture when it is here, else one written from the simulator. */
function saleaeFile(): string {
  const real = join(SHARED_CAPTURES, 'dsm_x_dx9_px4_binding_data.txt');
  if (existsSync(real)) return real;
  const sim = simulate(preset('dsmx-11ms-2048-internal'), 5_000_000);
  const lines = ['Time [s],Value,Parity Error,Framing Error'];
  sim.bytes.forEach((b, i) => {
    lines.push(`${(sim.timesUs[i]! / 1e6).toFixed(9)},0x${b.toString(16).toUpperCase().padStart(2, '0')},,`);
  });
  const path = join(dir, 'sim-saleae.txt');
  writeFileSync(path, `${lines.join('\n')}\n`);
  return path;
}

/** "m:ss.s / m:ss.s" → [position, span] in seconds. */
async function replayTime(page: Page): Promise<[number, number]> {
  const text = (await page.getByTestId('replay-time').textContent()) ?? '';
  const m = /^(\d+):(\d+\.\d) \/ (\d+):(\d+\.\d)$/.exec(text.trim());
  if (m === null) throw new Error(`replay time reads "${text}"`);
  return [Number(m[1]) * 60 + Number(m[2]), Number(m[3]) * 60 + Number(m[4])];
}

/** The link panel's episode counts, as the page words them ("1 hold · 0 failsafes"). */
function episodesText(holds: number, failsafes: number): string {
  return `${holds} ${holds === 1 ? 'hold' : 'holds'} · ${failsafes} ${failsafes === 1 ? 'failsafe' : 'failsafes'}`;
}

describe.skipIf(skip !== null)('honest states', () => {
  it('replays a Saleae export on its own clock: a timeline, 1×, seeking, full speed, and an end frozen at the last recorded time', async () => {
    const path = saleaeFile();
    const summary = summarizeCapture(importSaleaeCsv(new Uint8Array(readFileSync(path))));
    const { page, errors } = await open('?demo=0');
    await page.setInputFiles('input[type=file]', path);
    await page.locator('section.replay').waitFor();
    // The span is the capture's (about 5 s), not "0:00.0 / 0:00.0".
    const [, span] = await replayTime(page);
    expect(span).toBeGreaterThan(4.5);
    expect(span).toBeLessThan(5.5);
    // The overview is drawn.
    await page.locator('.overview canvas').first().waitFor();
    // 1× moves the clock about as fast as the wall clock.
    const [a] = await replayTime(page);
    await page.waitForTimeout(1500);
    const [b] = await replayTime(page);
    expect(b - a).toBeGreaterThan(0.8);
    expect(b - a).toBeLessThan(2.5);
    // Seeking moves it to where it was asked.
    await page.getByRole('button', { name: 'Pause' }).click();
    const start = Number(await page.locator('input.seek').getAttribute('min'));
    await page.locator('input.seek').evaluate((el, v) => {
      const input = el as HTMLInputElement;
      input.value = String(v);
      input.dispatchEvent(new Event('change', { bubbles: true }));
    }, start + 3_000_000);
    await page.waitForFunction(() => /^0:03\.0 \//.test(document.querySelector('[data-testid="replay-time"]')?.textContent ?? ''));
    // Full speed to the end: the clock stops at the end, the state is frozen and says so.
    await page.getByRole('radio', { name: 'max' }).click();
    await page.getByRole('button', { name: 'Play' }).click();
    await page.getByTestId('link-hint').filter({ hasText: 'Replay ended' }).waitFor({ timeout: 20_000 });
    const [end, span2] = await replayTime(page);
    expect(end).toBe(span2);
    const state = await page.getByTestId('link-state').textContent();
    expect(state).toBe('Ended');
    await expect(page.getByTestId('link-hint').textContent()).resolves.toMatch(/: there the link was live\.$/);
    await expect(page.locator('.link dd').nth(1).textContent()).resolves.toBe(episodesText(summary.link.holds, summary.link.failsafes));
    await expect(page.getByTestId('count-missed').textContent()).resolves.toBe(String(summary.link.missedFrames));
    // The last frame is dated against the end, not "ago" (the clock stands still there).
    const since = await page.locator('.link dd').nth(0).textContent();
    expect(since).toMatch(/^\d+(\.\d)? m?s before the end$/);
    await shot(page, 'replay-ended');
    // The wall clock moving on changes nothing.
    await page.waitForTimeout(1500);
    await expect(page.getByTestId('link-state').textContent()).resolves.toBe(state);
    await expect(page.locator('.link dd').nth(0).textContent()).resolves.toBe(since);
    await expect(replayTime(page)).resolves.toEqual([end, span2]);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('says a forced resolution matches no frame, counts nothing as lost meanwhile, and leaves no episode after switching back', async () => {
    const { page, errors } = await open();
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    // The demo runs in real time from about here: remote B's first dropout is 12 s in.
    const liveAtMs = Date.now();
    // After the demo's first short dropout (a hold at 4 s), before its long one (at 27 s).
    await expect.poll(() => page.locator('.link dd').nth(1).textContent(), { timeout: 10_000 }).toBe('1 hold · 0 failsafes');
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 5000 });
    const episodes = await page.locator('.link dd').nth(1).textContent();
    const missed = Number(await page.getByTestId('count-missed').textContent());
    await page.getByRole('button', { name: 'Settings', exact: true }).click();
    await page.getByRole('combobox', { name: 'Resolution' }).selectOption('1024');
    await page.keyboard.press('Escape');
    await page
      .getByTestId('link-hint')
      .filter({ hasText: 'Forced 1024: no frame matches; the stream looks like 2048' })
      .waitFor({ timeout: 5000 });
    await shot(page, 'forced-1024');
    await page.waitForTimeout(2500);
    await expect(page.getByTestId('link-state').textContent()).resolves.toBe('Waiting');
    await expect(page.locator('.link dd').nth(1).textContent()).resolves.toBe(episodes);
    await page.getByRole('button', { name: 'Settings', exact: true }).click();
    await page.getByRole('combobox', { name: 'Resolution' }).selectOption('auto');
    await page.keyboard.press('Escape');
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 5000 });
    await page.waitForTimeout(1000);
    await expect(page.locator('.link dd').nth(1).textContent()).resolves.toBe(episodes);
    // Remote B has no dropout in its first 12 s: whatever the worker's timers did, no hold (on a
    // machine slow enough to be past its first dropout by now, that one is real).
    const row = await page.locator('.remotes tbody tr').nth(1).textContent();
    if (Date.now() - liveAtMs < 10_500) expect(row).toMatch(/0 \/ 0/);
    else expect(row).toMatch(/[01] \/ 0/);
    // At most what the receiver's own counter says it missed meanwhile (the demo fades a few an s), not the ~270 frames not decoded.
    expect(Number(await page.getByTestId('count-missed').textContent()) - missed).toBeLessThan(20);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  // Simulated links with dropouts (and line damage), recorded as a USB adapter delivers them, and
  // the real PX4 captures (Saleae exports, per-byte times) when ../shared is here.
  const simulated = (name: string) => () => {
    const sim = simulate(preset(name));
    const path = join(dir, `${name}.sscap`);
    writeCapture(path, usbChunks(sim.bytes, sim.timesUs));
    return path;
  };
  const real = ['dsm_x_data.txt', 'dsm_x_dx9_data.txt', 'dsm_x_dx9_px4_binding_data.txt']
    .map((name) => join(SHARED_CAPTURES, name))
    .filter((path) => existsSync(path));
  for (const [name, speed, file] of [
    ['dropouts-failsafe', '1×', simulated('dropouts-failsafe')],
    ['dropouts-failsafe', 'max', simulated('dropouts-failsafe')],
    ['dropouts-and-damage', 'max', simulated('dropouts-and-damage')],
    ...real.map((path) => [path.split('/').pop()!, 'max', () => path] as const),
  ] as const) {
    it(`replays ${name} at ${speed} in the page and ends with satscope info's frames, missed frames, episodes and resolution`, async () => {
      const path = file();
      const summary = summarizeCapture(readCapture(new Uint8Array(readFileSync(path)), path));
      if (name.startsWith('dropouts')) expect(summary.link.failsafes).toBe(1);

      const { page, errors } = await open('?demo=0');
      await page.setInputFiles('input[type=file]', path);
      await page.locator('section.replay').waitFor();
      if (speed === 'max') await page.getByRole('radio', { name: 'max' }).click();
      await page.getByTestId('link-hint').filter({ hasText: 'Replay ended' }).waitFor({ timeout: 20_000 });
      // The ended state shows with the last batch's figures, never beside older ones.
      const shown = {
        frames: await page.getByTestId('count-frames').textContent(),
        missed: await page.getByTestId('count-missed').textContent(),
        episodes: await page.locator('.link dd').nth(1).textContent(),
        resolution: await page.getByTestId('resolution').textContent(),
      };
      expect(shown).toEqual({
        frames: String(summary.decoder.frames),
        missed: String(summary.link.missedFrames),
        episodes: episodesText(summary.link.holds, summary.link.failsafes),
        resolution: `${summary.format.resolution ?? '?'}${resolutionSource(summary.format.resolutionReason)}`,
      });
      expect(errors).toEqual([]);
      await page.context().close();
    });
  }
});

describe.skipIf(skip !== null)('seeking in a long capture', () => {
  it('shows after a seek the counters and episodes of the whole capture up to there, as the library decodes them', async () => {
    // 12 minutes: longer than a decode started afresh ten minutes before the target would see.
    const sim = simulate(
      {
        ...preset('dsmx-11ms-2048-internal'),
        seed: 9,
        dropouts: [
          { atUs: 60e6, durationUs: 300_000 },
          { atUs: 150e6, durationUs: 1_500_000 },
        ],
      },
      12 * 60e6,
    );
    const path = join(dir, 'twelve-minutes.sscap');
    writeCapture(path, usbChunks(sim.bytes, sim.timesUs));
    const capture = readCapture(new Uint8Array(readFileSync(path)), path);
    const { page, errors } = await open('?demo=0');
    await page.setInputFiles('input[type=file]', path);
    await page.locator('section.replay .overview[data-complete="true"]').waitFor({ timeout: 30_000 });
    await page.getByRole('button', { name: 'Pause' }).click();
    const seek = page.locator('input.seek');
    const start = Number(await seek.getAttribute('min'));
    // The slider snaps the value to its step: the target is what it took.
    const target = await seek.evaluate(
      (el, v) => {
        const input = el as HTMLInputElement;
        input.value = String(v);
        input.dispatchEvent(new Event('change', { bubbles: true }));
        return Number(input.value);
      },
      start + 11.2 * 60e6,
    );
    const shownAt = `${Math.floor((target - start) / 60e6)}:${(((target - start) / 1e6) % 60).toFixed(1).padStart(4, '0')} /`;
    await page.getByTestId('replay-time').filter({ hasText: shownAt }).waitFor();
    const want = libraryUpTo(capture, target);
    expect(want.holds).toBe(2);
    await page
      .getByTestId('count-frames')
      .filter({ hasText: new RegExp(`^${want.frames}$`) })
      .waitFor({ timeout: 5000 });
    await expect(page.getByTestId('count-missed').textContent()).resolves.toBe(String(want.missed));
    await expect(page.getByTestId('count-bytes').textContent()).resolves.toBe(String(want.bytes));
    await expect(page.locator('.link dd').nth(1).textContent()).resolves.toBe(episodesText(want.holds, want.failsafes));
    expect(errors).toEqual([]);
    await page.context().close();
  });
});

describe.skipIf(skip !== null)('the graphs and the counters', () => {
  it('shows in the Lost graph of a paused replay every missed frame the counters count, the newest too', async () => {
    // An internal remote whose fade counter counts the frames a 40 ms dropout takes.
    const sim = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 4, dropouts: [{ atUs: 3e6, durationUs: 40_000 }] }, 20e6);
    const path = join(dir, 'one-dropout.sscap');
    writeCapture(path, usbChunks(sim.bytes, sim.timesUs));
    const { page, errors } = await open('?demo=0');
    await page.setInputFiles('input[type=file]', path);
    const missed = page.getByTestId('count-missed');
    await missed.filter({ hasText: /^[1-9]\d*$/ }).waitFor({ timeout: 15_000 });
    // Paused at once: the bucket the missed frames are in is still open (under half a second old).
    await page.getByRole('button', { name: 'Pause' }).click();
    await page.waitForTimeout(500);
    const counted = Number(await missed.textContent());
    // The newest 4 s of the Lost graph, read through its keyboard cursor's legend (a loaded
    // machine may take a second or more to pause after the count first moved).
    const chart = page.locator('[data-chart="lost"]');
    await chart.focus();
    await chart.press('End');
    let shown = 0;
    for (let k = 0; k < 40; k++) {
      const legend = (await chart.locator('.u-legend').textContent()) ?? '';
      shown += Number(/Lost\s*(\d+) \/100 ms/.exec(legend)?.[1] ?? Number.NaN);
      await chart.press('ArrowLeft');
    }
    expect(counted).toBeGreaterThan(0);
    expect(shown).toBe(counted);
    expect(errors).toEqual([]);
    await page.context().close();
  });
});

describe.skipIf(skip !== null)('a capture being read', () => {
  // Two hours of two remotes: the page shows its span and overview while it walks the records,
  // and plays it from the file a window at a time (src/worker/replay/replay-session.ts).
  let path = '';
  /** The same capture without its index: its ports are known only once its records are walked. */
  let bare = '';
  beforeAll(() => {
    path = join(dir, 'two-hours.sscap');
    writeLongCapture(path, 2 * 3600e6);
    bare = join(dir, 'two-hours-no-index.sscap');
    writeFileSync(bare, withoutIndex(new Uint8Array(readFileSync(path))));
  });

  it("says a capture without an index is being read, never a receiver's wiring hint, until it plays", async () => {
    const { page, errors } = await open('?demo=0');
    await page.getByTestId('empty-state').waitFor();
    // Every state and hint the link panel shows, and whether Play could be pressed then.
    await page.evaluate(() => {
      const seen: string[] = [];
      (window as unknown as { seen: string[] }).seen = seen;
      const note = (): void => {
        const state = document.querySelector('[data-testid="link-state"]')?.textContent ?? null;
        if (state === null) return;
        const hint = document.querySelector('[data-testid="link-hint"]')?.textContent ?? '';
        const play = document.querySelector<HTMLButtonElement>('section.replay button.primary');
        const line = `${state} | ${hint} | ${play === null ? 'no bar' : play.disabled ? 'disabled' : 'enabled'}`;
        if (seen[seen.length - 1] !== line) seen.push(line);
      };
      new MutationObserver(note).observe(document.body, { subtree: true, childList: true, characterData: true, attributes: true });
    });
    await page.setInputFiles('input[type=file]', bare);
    await page
      .getByTestId('link-state')
      .filter({ hasText: /^Live$/ })
      .waitFor({ timeout: 60_000 });
    const seen = await page.evaluate(() => (window as unknown as { seen: string[] }).seen);
    const reading = seen.findIndex((l) => l.startsWith('Reading | Reading the capture'));
    expect(reading, seen.join('\n')).toBeGreaterThanOrEqual(0);
    // From the file's span on: no wiring hint, and Play only once the capture plays.
    const after = seen.slice(reading);
    expect(after.filter((l) => l.includes('grey DATA wire'))).toEqual([]);
    expect(after.filter((l) => l.startsWith('Reading') && !l.endsWith('disabled'))).toEqual([]);
    expect(errors).toEqual([]);
    await page.context().close();
  }, 90_000);

  it('reports on it exactly as satscope report does: the page reads the file the CLI reads', async () => {
    const { page, errors } = await open('?demo=0');
    await page.setInputFiles('input[type=file]', path);
    await page
      .getByTestId('link-state')
      .filter({ hasText: /^Live$/ })
      .waitFor({ timeout: 60_000 });
    const json = page.waitForEvent('download', { timeout: 60_000 });
    await page.getByRole('button', { name: 'Report', exact: true }).click();
    await page.getByRole('button', { name: 'Report as data (JSON)' }).click();
    const saved = join(dir, 'two-hours.page.json');
    await (await json).saveAs(saved);
    const cli = spawnSync(process.execPath, [join(ROOT, 'dist/cli/main.js'), 'report', '--json', path], {
      encoding: 'utf8',
      maxBuffer: 64 << 20,
    });
    expect(cli.status).toBe(0);
    expect(readFileSync(saved, 'utf8')).toBe(cli.stdout);
    expect(errors).toEqual([]);
    await page.context().close();
  }, 90_000);
});

/** What the library's decoder and link monitor say fed every chunk of port 0 that arrived by `untilUs`. */
function libraryUpTo(capture: Capture, untilUs: number) {
  const decoder = new SpektrumDecoder();
  const link = new LinkMonitor({ jitterUs: USB_CHUNK_JITTER_US });
  for (let i = 0; i < capture.chunkEnds.length; i++) {
    if (capture.chunkPorts[i] !== 0 || (capture.chunkTimesUs[i] ?? Infinity) > untilUs) continue;
    decoder.push(capture.bytes.subarray(i === 0 ? 0 : capture.chunkEnds[i - 1], capture.chunkEnds[i]), capture.chunkTimesUs[i]);
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) link.frame(f);
  }
  const l = link.stats;
  return { frames: decoder.stats.frames, bytes: decoder.stats.bytes, missed: l.missedFrames, holds: l.holds, failsafes: l.failsafes };
}
