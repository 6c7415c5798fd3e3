/**
 * Drive through Chromium's real WebSerial: the page writes a DSMX 11 ms satellite to the pty
 * standing in for the adapter, and the test reads it as a flight controller's UART would
 * (drive-timing.ts; with the tab hidden: drive-background.test.ts). The page keeps 8 ms of
 * silence before every frame by its clock; at the pty every group must be whole frames, in 11 ms
 * slots (frames read together are printed, not judged). What the test reads it writes back (the
 * loopback self-test): the page decodes it as a receiver. Escape stops the stream at once.
 * SATSCOPE_DRIVE_SECONDS sets how long it drives (default 30; docs/drive.md quotes a 600 s run);
 * the distribution is printed.
 */
import type { Browser } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../../src/decoder/decoder.js';
import { MIN_SILENCE_US } from '../../src/drive/schedule.js';
import { encodeMavlink, MAVLINK, MavlinkParser, SENSOR_RC_RECEIVER } from '../../src/drive/mavlink.js';
import { join } from 'node:path';
import { burstFigures, bursts } from './drive-timing.js';
import { browserUnavailable, SHOTS, shot, startSerialApp, type SerialAppSession } from './app-fixture.js';
import { axe } from './axe.js';
import { fakeSerialUnsupportedReason, type FakeSerialPort } from './harness/pty-serial.js';
import { eachLook, openDrive, sticksAtPty } from './drive-page.js';

const skip = browserUnavailable() ?? fakeSerialUnsupportedReason();
if (skip !== null) console.warn(`skipping the Drive tests: ${skip}`);
const SECONDS = Number(process.env.SATSCOPE_DRIVE_SECONDS ?? 30);

let rig: SerialAppSession | undefined;
let fake: FakeSerialPort;
let browser: Browser;

beforeAll(async () => {
  if (skip !== null) return;
  // The pump at a real-time priority: what it reads in one piece, the page wrote together.
  rig = await startSerialApp({}, { realtime: true });
  ({ fake, browser } = rig);
});

afterAll(async () => {
  await rig?.close();
});

describe.skipIf(skip !== null)('driving a flight controller through the adapter', () => {
  it(
    `writes ${SECONDS} s of DSMX 11 ms frame by frame and reads it back through the loopback`,
    async () => {
      const context = await browser.newContext({ viewport: { width: 1280, height: 1000 } });
      const page = await context.newPage();
      const errors: string[] = [];
      page.on('pageerror', (e) => errors.push(e.message));
      await page.goto(rig!.server.url('/'));
      const panel = await openDrive(page);
      // Nothing is sent before the user says the propellers are off.
      const startButton = panel.getByRole('button', { name: '▶ Start driving' });
      expect(await startButton.isDisabled()).toBe(true);
      await panel.getByLabel('The propellers are off').check();

      const chunks: { bytes: Uint8Array; tUs: number }[] = [];
      const decoder = new SpektrumDecoder();
      let decoded = 0;
      const stop = fake.onData((bytes, tUs) => {
        chunks.push({ bytes: bytes.slice(), tUs });
        decoder.push(bytes, tUs);
        for (let f = decoder.next(); f !== undefined; f = decoder.next()) decoded++;
        // The loopback: the adapter's TX wired to its own RX.
        if (process.env.SATSCOPE_DRIVE_ECHO !== '0') void fake.write(bytes);
      });
      await startButton.click();
      await panel.getByTestId('drive-state').filter({ hasText: 'Sending “manual”' }).waitFor();
      await new Promise((r) => setTimeout(r, SECONDS * 1000));
      // The panel at both widths and in both themes, to look at.
      await eachLook(page, async ({ name }) => {
        await shot(page, `drive-${name}`);
      });
      const echo = process.env.SATSCOPE_DRIVE_ECHO !== '0';
      const loop = echo ? await panel.getByTestId('drive-loopback').textContent() : null;
      const timing = await panel.getByTestId('drive-timing').textContent();
      await page.keyboard.press('Escape');
      await panel.getByTestId('drive-state').filter({ hasText: 'Stopped: stopped by the user' }).waitFor();
      const atStop = chunks.length;
      await new Promise((r) => setTimeout(r, 300));
      stop();
      // The decoder keeps a frame back until the bytes after it are seen: the stream has ended.
      decoder.end();
      for (let f = decoder.next(); f !== undefined; f = decoder.next()) decoded++;
      // Escape stopped it: at most the two writes the worker lets be on their way (drive.ts) after it.
      expect(chunks.length - atStop).toBeLessThanOrEqual(2);

      const { spanUs: span, ...figures } = burstFigures(bursts(chunks));
      console.log(`drive through the pty: ${JSON.stringify({ ...figures, decoded, loop, timing })}`);
      const { frames } = figures;
      // Frames the worker skipped (its timer late) are no frames: at most a tenth (below).
      expect(frames).toBeGreaterThan(((SECONDS * 1e6) / 11_000) * 0.9);
      // Whole frames only: nothing split or cut short.
      expect(Object.keys(figures.lengths).every((n) => Number(n) % 16 === 0)).toBe(true);
      // Frames read in one piece with the next are reported, not judged: the pty's reader cannot
      // tell its own lateness (hundreds of ms under load) from the page's.
      // The slots kept: over the drive, frames written plus frames skipped come 11 ms apart.
      const skippedNow = Number(/; (\d+) skipped/.exec(timing ?? '')?.[1] ?? Number.NaN);
      expect(Math.abs(span / (frames + skippedNow - 1) - 11_000)).toBeLessThanOrEqual(330);
      // The page's own account: the silence it kept by its clock, and few frames skipped.
      expect(timing).toMatch(new RegExp(`shortest silence before a frame ${(MIN_SILENCE_US / 1000).toFixed(1)} ms`));
      const skipped = Number(/; (\d+) skipped/.exec(timing ?? '')?.[1] ?? Number.NaN);
      // A frame due while the timer slept is skipped, not sent late in a burst: how many is the
      // machine's load (under 1 % alone, 11 % with four other test sessions on two cores).
      expect(skipped).toBeLessThanOrEqual(frames * 0.2);
      expect(decoded).toBeGreaterThanOrEqual(frames - 1);
      // The page read its own frames back: none broken (bytes before the decoder locked on may be set aside).
      if (echo) expect(loop).toMatch(/read back \d+ frames.*; 0 broken, 0 resyncs/);
      expect(errors).toEqual([]);
      await context.close();
    },
    (SECONDS + 60) * 1000,
  );

  it('takes the sticks from a gamepad, bounds its throttle by the ceiling, and the frames carry them', async () => {
    const context = await browser.newContext({ viewport: { width: 1280, height: 1000 } });
    // A gamepad the browser lists: the test moves its axes (the standard layout; mode 2).
    await context.addInitScript(() => {
      const pad = {
        id: 'Test pad (STANDARD GAMEPAD)',
        index: 0,
        connected: true,
        mapping: 'standard',
        timestamp: 0,
        axes: [0, 0, 0, 0],
        buttons: Array.from({ length: 17 }, () => ({ pressed: false, touched: false, value: 0 })),
      };
      (window as unknown as { testPad: typeof pad }).testPad = pad;
      Object.defineProperty(navigator, 'getGamepads', { value: () => [pad, null, null, null], configurable: true });
    });
    const page = await context.newPage();
    const errors: string[] = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(rig!.server.url('/'));
    await page.evaluate(() => localStorage.removeItem('satscope.drive.gamepad'));
    const panel = await openDrive(page);
    await panel.getByLabel('Gamepad or transmitter (joystick mode)').check();
    await panel.getByTestId('drive-pad-state').filter({ hasText: 'Test pad (STANDARD GAMEPAD): 4 axes, 17 buttons' }).waitFor();
    // Gear from button 0, kept by the page across a reload.
    await panel.getByLabel('Gear from').selectOption('button:0');
    await page.reload();
    await openDrive(page);
    await panel.getByLabel('Gamepad or transmitter (joystick mode)').check();
    expect(await panel.getByLabel('Gear from').inputValue()).toBe('button:0');

    const { last, stop } = sticksAtPty(fake);
    await panel.getByLabel('The propellers are off').check();
    await panel.getByRole('button', { name: '▶ Start driving' }).click();
    await panel.getByTestId('drive-state').filter({ hasText: 'Sending “manual”' }).waitFor();
    // Left stick full up (throttle: past the −60 % ceiling), right stick half right (aileron +50 %), button 0 held.
    await page.evaluate(() => {
      const pad = (window as unknown as { testPad: { axes: number[]; buttons: { pressed: boolean; value: number }[] } }).testPad;
      pad.axes = [0, -1, 0.5, 0];
      pad.buttons[0] = { pressed: true, value: 1 };
    });
    const near = (id: number, want: number) => Math.abs((last.get(id) ?? Number.NaN) - want) <= 0.5;
    for (let i = 0; i < 50 && !(near(0, -60) && near(1, 50) && near(4, 100)); i++) await new Promise((r) => setTimeout(r, 100));
    const seen = Object.fromEntries([0, 1, 2, 3, 4].map((id) => [id, +(last.get(id) ?? Number.NaN).toFixed(1)]));
    console.log(`gamepad sticks in the frames (%): ${JSON.stringify(seen)}`);
    // The deadband (5 %) scales the aileron's half travel to 47 %.
    expect(seen[1]).toBeCloseTo(47.4, 0);
    expect(seen[0]).toBeCloseTo(-60, 0);
    expect(seen[4]).toBeCloseTo(100, 0);
    expect(seen[2]).toBeCloseTo(0, 0);
    // Unplugged: its channels go back to the scenario (the manual one rests the throttle low, the sticks centred).
    await page.evaluate(() => {
      Object.defineProperty(navigator, 'getGamepads', { value: () => [null, null, null, null], configurable: true });
    });
    for (let i = 0; i < 50 && !(near(0, -100) && near(1, 0) && near(4, 0)); i++) await new Promise((r) => setTimeout(r, 100));
    const gone = Object.fromEntries([0, 1, 4].map((id) => [id, +(last.get(id) ?? Number.NaN).toFixed(1)]));
    console.log(`gamepad unplugged, the frames (%): ${JSON.stringify(gone)}`);
    expect(gone).toEqual({ 0: -100, 1: 0, 4: 0 });
    await page.evaluate(() => {
      const pad = (window as unknown as { testPad: unknown }).testPad;
      Object.defineProperty(navigator, 'getGamepads', { value: () => [pad, null, null, null], configurable: true });
    });
    await panel.getByTestId('drive-pad-state').filter({ hasText: 'Test pad' }).waitFor();
    // The panel with the gamepad's mapping, to look at.
    await eachLook(page, async ({ width, scheme, name }) => {
      await panel.screenshot({ path: join(SHOTS, `drive-pad-${name}.png`) });
      expect(await axe(page, `drive sticks ${width} ${scheme}`, ['.drive'])).toEqual([]);
    });
    // Escape still stops.
    await page.keyboard.press('Escape');
    await panel.getByTestId('drive-state').filter({ hasText: 'Stopped: stopped by the user' }).waitFor();
    stop();
    expect(errors).toEqual([]);
    await context.close();
  }, 60_000);

  it('takes the sticks from the keyboard, shows its map, and Space still stops', async () => {
    const context = await browser.newContext({ viewport: { width: 1280, height: 1000 } });
    const page = await context.newPage();
    const errors: string[] = [];
    page.on('pageerror', (e) => errors.push(e.message));
    await page.goto(rig!.server.url('/'));
    const panel = await openDrive(page);
    expect(await panel.getByRole('table', { name: 'Keyboard sticks' }).textContent()).toMatch(/W \/ SThrottle.*↑ \/ ↓Elevator/);
    await panel.getByRole('checkbox', { name: 'Keyboard sticks' }).check();
    const { last, stop } = sticksAtPty(fake);
    await panel.getByLabel('The propellers are off').check();
    await panel.getByRole('button', { name: '▶ Start driving' }).click();
    await panel.getByTestId('drive-state').filter({ hasText: 'Sending “manual”' }).waitFor();
    await page.locator('body').click({ position: { x: 5, y: 5 } });
    // W held: the throttle climbs to the ceiling (−60 %) and no further; ↑ held: the elevator climbs.
    await page.keyboard.down('w');
    await page.keyboard.down('ArrowUp');
    await new Promise((r) => setTimeout(r, 1500));
    const held = { throttle: last.get(0), elevator: last.get(2) };
    await page.keyboard.up('w');
    await page.keyboard.up('ArrowUp');
    // Let go: the elevator springs back to centre, the throttle stays.
    await new Promise((r) => setTimeout(r, 1500));
    const after = { throttle: last.get(0), elevator: last.get(2) };
    console.log(`keyboard sticks in the frames (%): held ${JSON.stringify(held)}, let go ${JSON.stringify(after)}`);
    expect(held.throttle).toBeCloseTo(-60, 0);
    expect(held.elevator).toBeGreaterThan(90);
    expect(after.throttle).toBeCloseTo(-60, 0);
    expect(after.elevator).toBeCloseTo(0, 0);
    await page.keyboard.press(' ');
    await panel.getByTestId('drive-state').filter({ hasText: 'Stopped: stopped by the user' }).waitFor();
    // The loopback goes silent: the doctor's failsafe there is the drive's stop, and the page says so.
    await page
      .locator('[data-code="weak-link"] .title', { hasText: 'the drive stopped sending, not a weak link' })
      .waitFor({ state: 'attached', timeout: 10_000 });
    const findings = await page.locator('[data-code="weak-link"] .title').allTextContents();
    console.log(`findings on the loopback after the stop: ${JSON.stringify(findings)}`);
    expect(findings.join(' ')).not.toMatch(/the link is weak/);
    stop();
    expect(errors).toEqual([]);
    await context.close();
  }, 60_000);

  it("reads an ArduPilot over MAVLink on the flight controller's port and shows what it said", async () => {
    // The pty is the flight controller's USB port here: an ArduPilot that sends its HEARTBEAT
    // unasked and RC_CHANNELS and SYS_STATUS once asked (SET_MESSAGE_INTERVAL or REQUEST_DATA_STREAM).
    const context = await browser.newContext({ viewport: { width: 1280, height: 1000 } });
    const page = await context.newPage();
    const errors: string[] = [];
    page.on('pageerror', (e) => errors.push(e.message));
    let seq = 0;
    const out = (id: number, payload: Uint8Array) =>
      void fake.write(encodeMavlink(id, payload, { seq: seq++ & 0xff, sysid: 1, compid: 1 }));
    const asked = new Set<number>();
    const parser = new MavlinkParser();
    const stopData = fake.onData((bytes) => {
      parser.push(bytes);
      for (let m = parser.next(); m !== undefined; m = parser.next()) asked.add(m.msgid);
    });
    const heartbeat = setInterval(() => out(MAVLINK.HEARTBEAT.id, Uint8Array.of(0, 0, 0, 0, 2, 3, 0x81, 4, 3)), 1000);
    // Its channels as its DSM decoder gives them (RC1 roll, RC2 pitch, RC3 throttle, RC4 yaw…).
    const us = [1701, 1500, 1099, 1500, 1900, 1500, 1500, 1500];
    const streams = setInterval(() => {
      if (!asked.has(MAVLINK.COMMAND_LONG.id) && !asked.has(MAVLINK.REQUEST_DATA_STREAM.id)) return;
      const rc = new Uint8Array(MAVLINK.RC_CHANNELS.length);
      const v = new DataView(rc.buffer);
      for (const [i, x] of us.entries()) v.setUint16(4 + 2 * i, x, true);
      v.setUint8(40, us.length);
      v.setUint8(41, 200);
      out(MAVLINK.RC_CHANNELS.id, rc);
      const sys = new Uint8Array(MAVLINK.SYS_STATUS.length);
      const w = new DataView(sys.buffer);
      for (const at of [0, 4, 8]) w.setUint32(at, SENSOR_RC_RECEIVER, true);
      out(MAVLINK.SYS_STATUS.id, sys);
    }, 50);
    try {
      await page.goto(rig!.server.url('/'));
      const panel = await openDrive(page);
      const view = panel.getByRole('region', { name: "The flight controller's view" });
      // The port the page was granted, as the user picks it in the list.
      await view.getByLabel('Its USB port').selectOption({ index: 0 });
      await view.getByRole('button', { name: 'Read the flight controller' }).click();
      await view
        .getByTestId('fc-state')
        .filter({ hasText: /ArduPilot on .* \(MAVLink\)/ })
        .waitFor({ timeout: 10_000 });
      await view.getByRole('cell', { name: '1099 µs' }).waitFor({ timeout: 5000 });
      const table = await view.getByRole('region', { name: 'Channels the flight controller decoded' }).textContent();
      const flags = await view.locator('.drive-fc-flags').textContent();
      console.log(`ArduPilot on the page: ${JSON.stringify({ table, flags })}`);
      expect(table).toContain('RC1 roll1701 µs');
      expect(table).toContain('RC3 throttle1099 µs');
      expect(flags).toMatch(
        /Armed: yes · Receiver lost \(SYS_STATUS RC receiver, or no channels\): no · In failsafe \(MAV_STATE_CRITICAL\): no · RSSI: 200/,
      );
      expect(await view.getByRole('alert').textContent()).toMatch(/ARMED/);
      expect(asked.has(MAVLINK.HEARTBEAT.id)).toBe(false);
      await eachLook(page, async ({ width, scheme, name }) => {
        await view.screenshot({ path: join(SHOTS, `drive-fc-mavlink-${name}.png`) });
        expect(await axe(page, `drive MAVLink view ${width} ${scheme}`, ['.drive-fc'])).toEqual([]);
      });
      await view.getByRole('button', { name: 'Stop reading' }).click();
      await view.getByTestId('fc-state').filter({ hasText: 'Not reading' }).waitFor();
    } finally {
      clearInterval(heartbeat);
      clearInterval(streams);
      stopData();
    }
    expect(errors).toEqual([]);
    await context.close();
  }, 60_000);
});
