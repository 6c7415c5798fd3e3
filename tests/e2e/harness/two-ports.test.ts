// Proof that the harness can stand in for two serial ports at once (an adapter and a flight
// controller's USB port): /dev/ttyS0 and /dev/ttyS1, which sysfs does not list on a machine with
// one UART until pty-pump.py lists it for the time the test runs.
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Browser } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { chromiumAvailable, CHROMIUM_PATH, launchChromium, startStaticServer, type StaticServer } from './browser.js';
import { installSerialPolicy, type SerialPolicy } from './policy.js';
import { fakeSerialUnsupportedReason, openFakeSerialPort, type FakeSerialPort } from './pty-serial.js';

const SECOND = '/dev/ttyS1';
const skipReason = !chromiumAvailable()
  ? `${CHROMIUM_PATH} is absent`
  : (fakeSerialUnsupportedReason() ?? fakeSerialUnsupportedReason(SECOND));
if (skipReason) console.warn(`[e2e harness, two ports] skipped: ${skipReason}`);

/** Opens every port the page may use, writes its index to each, and returns what each read back. */
const PAGE = `<!doctype html><meta charset="utf-8"><title>two ports</title><script>
window.run = async () => {
  const ports = await navigator.serial.getPorts();
  const out = [];
  for (const [i, port] of ports.entries()) {
    await port.open({ baudRate: 115200 });
    const w = port.writable.getWriter();
    await w.write(new Uint8Array([0xa0 + i]));
    w.releaseLock();
    const r = port.readable.getReader();
    const { value } = await r.read();
    r.releaseLock();
    await port.close();
    out.push({ wrote: 0xa0 + i, read: Array.from(value) });
  }
  return out;
};
</script>`;

describe.skipIf(!!skipReason)('e2e harness: two fake serial ports at once', () => {
  let dir: string;
  let server: StaticServer;
  let policy: SerialPolicy;
  let first: FakeSerialPort;
  let second: FakeSerialPort;
  let browser: Browser;

  beforeAll(async () => {
    dir = mkdtempSync(join(tmpdir(), 'satscope-two-ports-'));
    writeFileSync(join(dir, 'index.html'), PAGE);
    server = await startStaticServer(dir);
    policy = await installSerialPolicy(server.origin);
    first = await openFakeSerialPort();
    second = await openFakeSerialPort({ device: SECOND });
    browser = await launchChromium();
  }, 60_000);

  afterAll(async () => {
    await browser?.close();
    await second?.close();
    await first?.close();
    await policy?.remove();
    await server?.close();
    rmSync(dir, { recursive: true, force: true });
  });

  it('the page lists both, and each port reaches its own pty both ways; closing unlists the second', async () => {
    const page = await browser.newPage();
    await page.goto(server.url('/'));
    // Each pty answers what the page wrote to it with its own mark.
    first.onData((b) => void first.write(Uint8Array.of(0x10, ...b)));
    second.onData((b) => void second.write(Uint8Array.of(0x20, ...b)));
    const got = await page.evaluate(() => (window as unknown as { run(): Promise<{ wrote: number; read: number[] }[]> }).run());
    expect(got).toHaveLength(2);
    // getPorts' order is sysfs's: ttyS0 first or not; each port's answer says which pty it reached.
    const marks = got.map((g) => g.read[0]).sort();
    expect(marks).toEqual([0x10, 0x20]);
    for (const g of got) expect(g.read.slice(1)).toEqual([g.wrote]);
    await page.close();
    await second.close();
    expect(existsSync(SECOND)).toBe(false);
    const listed = readFileSync('/proc/self/mountinfo', 'utf8').includes('/sys/devices/virtual/tty/');
    expect(listed).toBe(false);
  }, 60_000);
});
