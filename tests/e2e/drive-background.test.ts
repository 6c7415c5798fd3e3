/**
 * Drive with the tab in the background, as a user leaves it while they look at the flight
 * controller's configurator: Chromium in a real window (Xvfb), a tab opened in front of the
 * page, the page hidden (its own record of document.visibilityState says so) and its main
 * thread's timers throttled, while the worker writes DSMX 11 ms to the pty on its own timers.
 * The test reads the pty as a flight controller's UART would (drive-timing.ts) and writes it back
 * (the loopback). It drives as long visible first, so the two distributions, printed, are of one
 * run on one machine's load. SATSCOPE_DRIVE_SECONDS sets how long hidden (default 15),
 * SATSCOPE_DRIVE_VISIBLE_SECONDS how long visible (default the same).
 */
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { MIN_SILENCE_US } from '../../src/drive/schedule.js';
import { APP_DIR } from './app-fixture.js';
import { burstFigures, bursts, type PtyChunk } from './drive-timing.js';
import { startStaticServer, type StaticServer } from './harness/browser.js';
import { installSerialPolicy, type SerialPolicy } from './harness/policy.js';
import { fakeSerialUnsupportedReason, monotonicUs, openFakeSerialPort, type FakeSerialPort } from './harness/pty-serial.js';
import { WindowedChromium, windowedUnavailable } from './harness/windowed.js';
import { existsSync } from 'node:fs';
import { join } from 'node:path';
import { openDrive } from './drive-page.js';

const skip =
  (existsSync(join(APP_DIR, 'index.html')) ? null : `${APP_DIR} is not built (npm run build)`) ??
  windowedUnavailable() ??
  fakeSerialUnsupportedReason();
if (skip !== null) console.warn(`skipping Drive in a background tab: ${skip}`);
const SECONDS = Number(process.env.SATSCOPE_DRIVE_SECONDS ?? 15);
const VISIBLE_SECONDS = Number(process.env.SATSCOPE_DRIVE_VISIBLE_SECONDS ?? SECONDS);

/** How long to wait for the serial devices, ms. */
const WAIT_MS = 300_000;

let server: StaticServer;
let policy: SerialPolicy;
let fake: FakeSerialPort;
let win: WindowedChromium;

beforeAll(async () => {
  if (skip !== null) return;
  server = await startStaticServer(APP_DIR);
  policy = await installSerialPolicy(server.origin);
  // The other browser tests hold /dev/ttyS0 a file at a time: wait for it as long as one may take.
  fake = await openFakeSerialPort({ realtime: true, lockTimeoutMs: WAIT_MS });
  win = await WindowedChromium.launch();
}, WAIT_MS + 60_000);

afterAll(async () => {
  await win?.close();
  await fake?.close();
  await policy?.remove();
  await server?.close();
});

describe.skipIf(skip !== null)('driving a flight controller with the tab in the background', () => {
  it(
    `writes DSMX 11 ms for ${VISIBLE_SECONDS} s visible, then ${SECONDS} s from a hidden tab, frame by frame, and reads it back through the loopback`,
    async () => {
      let browser = await win.attach();
      let page = browser.contexts()[0]!.pages()[0]!;
      const errors: string[] = [];
      page.on('pageerror', (e) => errors.push(e.message));
      await page.goto(server.url('/'));
      let panel = await openDrive(page);
      await panel.getByLabel('The propellers are off').check();

      const chunks: PtyChunk[] = [];
      const stop = fake.onData((bytes, tUs) => {
        chunks.push({ bytes: bytes.slice(), tUs });
        void fake.write(bytes); // the adapter's TX wired to its own RX
      });
      await panel.getByRole('button', { name: '▶ Start driving' }).click();
      await panel.getByTestId('drive-state').filter({ hasText: 'Sending “manual”' }).waitFor();
      // The page keeps its own record of being hidden and shown, and counts its main thread's 10 ms ticks.
      await page.evaluate(() => {
        const w = window as unknown as { visibility: [string, number, number][]; ticks: number };
        w.ticks = 0;
        w.visibility = [[document.visibilityState, performance.now(), 0]];
        document.addEventListener('visibilitychange', () => w.visibility.push([document.visibilityState, performance.now(), w.ticks]));
        setInterval(() => w.ticks++, 10);
      });
      const wait = (seconds = SECONDS) => new Promise((r) => setTimeout(r, seconds * 1000));
      const visibleFrom = monotonicUs();
      await wait(VISIBLE_SECONDS);
      const visibleTo = monotonicUs();
      await win.background();
      const hiddenFrom = monotonicUs();
      await wait();
      const hiddenTo = monotonicUs();
      browser = await win.foreground();
      page = browser
        .contexts()[0]!
        .pages()
        .find((p) => p.url().startsWith(server.origin))!;
      page.on('pageerror', (e) => errors.push(e.message));
      panel = page.getByRole('region', { name: 'Drive a flight controller' });
      const seen = await page.evaluate(() => {
        const w = window as unknown as { visibility: [string, number, number][] };
        return { visibility: w.visibility };
      });
      const loop = await panel.getByTestId('drive-loopback').textContent();
      const timing = await panel.getByTestId('drive-timing').textContent();
      await page.keyboard.press('Escape');
      await panel.getByTestId('drive-state').filter({ hasText: 'Stopped: stopped by the user' }).waitFor();
      await new Promise((r) => setTimeout(r, 300));
      stop();

      // Hidden for the drive: the page said so, and its main thread's timers slowed down.
      const hiddenAt = seen.visibility.find(([s]) => s === 'hidden');
      const shownAt = [...seen.visibility].reverse().find(([s]) => s === 'visible');
      const hiddenMs = (shownAt?.[1] ?? Number.NaN) - (hiddenAt?.[1] ?? Number.NaN);
      const hiddenTicks = (shownAt?.[2] ?? Number.NaN) - (hiddenAt?.[2] ?? Number.NaN);
      const b = bursts(chunks);
      const within = (from: number, to: number) => burstFigures(b.filter((x) => x.startUs >= from && x.startUs < to));
      const visible = within(visibleFrom, visibleTo);
      const hidden = within(hiddenFrom, hiddenTo);
      const figures = burstFigures(b);
      const skipped = Number(/; (\d+) skipped/.exec(timing ?? '')?.[1] ?? Number.NaN);
      const show = (f: ReturnType<typeof burstFigures>) => JSON.stringify({ ...f, spanUs: undefined });
      console.log(
        `drive, at the pty: visible ${show(visible)}; hidden ${show(hidden)} (hidden ${Math.round(hiddenMs)} ms, main thread ${hiddenTicks} ticks of 10 ms); page: ${timing} ${loop}`,
      );
      expect(seen.visibility[0]?.[0]).toBe('visible');
      expect(hiddenMs).toBeGreaterThanOrEqual(SECONDS * 1000 - 1000);
      // A visible page would count 100 ticks a second; a hidden one is throttled to about 1.
      expect(hiddenTicks).toBeLessThan((hiddenMs / 10) * 0.5);
      // The worker was not: frames kept coming, whole, in their 11 ms slots.
      expect(hidden.frames).toBeGreaterThan(((SECONDS * 1e6) / 11_000) * 0.9);
      expect(Object.keys(figures.lengths).every((n) => Number(n) % 16 === 0)).toBe(true);
      expect(Math.abs(figures.spanUs / (figures.frames + skipped - 1) - 11_000)).toBeLessThanOrEqual(330);
      expect(timing).toMatch(new RegExp(`shortest silence before a frame ${(MIN_SILENCE_US / 1000).toFixed(1)} ms`));
      // Skipped frames (the timer woke late) are the machine's load: see drive.test.ts.
      expect(skipped).toBeLessThanOrEqual(figures.frames * 0.2);
      expect(loop).toMatch(/read back \d+ frames.*; 0 broken, 0 resyncs/);
      expect(errors).toEqual([]);
    },
    (VISIBLE_SECONDS + SECONDS + 90) * 1000,
  );
});
