/** The Drive panel as the browser tests reach it, and what the adapter's pty carries back. */
import type { Locator, Page } from 'playwright-core';
import { SpektrumDecoder } from '../../src/decoder/decoder.js';
import { servoToPercent } from '../../src/decoder/spec.js';
import type { FakeSerialPort } from './harness/pty-serial.js';

/** Opens "Drive a flight controller…" from the connect menu; the panel. */
export async function openDrive(page: Page): Promise<Locator> {
  await page.getByRole('button', { name: 'More ways to connect' }).click();
  await page.getByRole('button', { name: 'Drive a flight controller…' }).click();
  const panel = page.getByRole('region', { name: 'Drive a flight controller' });
  await panel.waitFor();
  return panel;
}

/**
 * Each channel's newest value (percent of travel, by channel ID) in the frames the page writes
 * to `fake`, decoded as they come; each read is written back (the loopback). `stop()` ends it.
 */
export function sticksAtPty(fake: FakeSerialPort): { last: Map<number, number>; stop(): void } {
  const decoder = new SpektrumDecoder();
  const last = new Map<number, number>();
  const stop = fake.onData((bytes, tUs) => {
    decoder.push(bytes, tUs);
    for (let f = decoder.next(); f !== undefined; f = decoder.next())
      for (let i = 0; i < f.count; i++) last.set(f.ids[i] as number, servoToPercent(f.positions[i] as number, f.resolution));
    void fake.write(bytes);
  });
  return { last, stop };
}

/** The four looks the Drive tests take: desktop and phone widths, light and dark; `look` is called at each, the page set to it. */
export async function eachLook(
  page: Page,
  look: (at: { width: number; scheme: 'light' | 'dark'; name: string }) => Promise<void>,
): Promise<void> {
  for (const [width, scheme] of [
    [1280, 'light'],
    [1280, 'dark'],
    [390, 'light'],
    [390, 'dark'],
  ] as const) {
    await page.setViewportSize({ width, height: 900 });
    await page.emulateMedia({ colorScheme: scheme });
    await look({ width, scheme, name: `${width < 600 ? 'phone' : 'desktop'}-${scheme}` });
  }
}
