// Debian's Chromium in a real window (on Xvfb), for what only a windowed browser does: a tab that
// another tab covers is hidden (document.visibilityState 'hidden', its timers throttled), as a
// user's tab is when they look at another. Headless Chromium keeps every page visible, and so
// does a page Playwright is attached to (its focus emulation), so `background()` lets go of the
// browser and opens a tab in front; `foreground()` closes that tab and attaches again.
import { spawn, type ChildProcess } from 'node:child_process';
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { createServer } from 'node:net';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium, type Browser } from 'playwright-core';
import { CHROMIUM_ARGS, CHROMIUM_PATH } from './browser.js';

export const XVFB_PATH = '/usr/bin/Xvfb';

/** Why a windowed Chromium cannot run here, or null when it can. */
export function windowedUnavailable(): string | null {
  if (!existsSync(CHROMIUM_PATH)) return `${CHROMIUM_PATH} is absent`;
  if (!existsSync(XVFB_PATH)) return `${XVFB_PATH} is absent (Debian's xvfb; .ci/run installs it)`;
  return null;
}

/**
 * Runs `command` under a python3 watchdog that ends it when our stdin closes: when this process
 * dies, however it dies, the X server and the browser go with it.
 */
function guarded(command: string[], env: NodeJS.ProcessEnv = process.env): ChildProcess {
  const watchdog = 'import subprocess,sys\np=subprocess.Popen(sys.argv[1:])\nsys.stdin.read()\np.terminate()\np.wait()';
  return spawn('python3', ['-c', watchdog, ...command], { stdio: ['pipe', 'ignore', 'ignore'], env });
}

/** A free TCP port on loopback, for the browser's DevTools endpoint. */
function freePort(): Promise<number> {
  return new Promise((resolve, reject) => {
    const s = createServer();
    s.once('error', reject);
    s.listen(0, '127.0.0.1', () => {
      const { port } = s.address() as { port: number };
      s.close(() => resolve(port));
    });
  });
}

async function until<T>(what: string, probe: () => Promise<T | undefined>, timeoutMs = 20_000): Promise<T> {
  const end = Date.now() + timeoutMs;
  for (;;) {
    try {
      const v = await probe();
      if (v !== undefined) return v;
    } catch {
      // not yet
    }
    if (Date.now() > end) throw new Error(`windowed Chromium: timed out waiting for ${what}`);
    await new Promise((r) => setTimeout(r, 100));
  }
}

export class WindowedChromium {
  #coverId: string | null = null;
  #browser: Browser | null = null;

  private constructor(
    readonly endpoint: string,
    readonly xvfb: ChildProcess,
    readonly chrome: ChildProcess,
    readonly profile: string,
  ) {}

  /** Xvfb on a display of its own, and Chromium in a window on it with one blank tab. */
  static async launch(): Promise<WindowedChromium> {
    const display = `:${100 + (process.pid % 800)}`;
    const xvfb = guarded([XVFB_PATH, display, '-screen', '0', '1280x1024x24', '-nolisten', 'tcp']);
    const profile = mkdtempSync(join(tmpdir(), 'satscope-windowed-'));
    const port = await freePort();
    await until('Xvfb', async () => (existsSync(`/tmp/.X11-unix/X${display.slice(1)}`) ? true : undefined));
    const chrome = guarded(
      [
        CHROMIUM_PATH,
        ...CHROMIUM_ARGS,
        `--remote-debugging-port=${port}`,
        `--user-data-dir=${profile}`,
        '--window-size=1280,1000',
        'about:blank',
      ],
      { ...process.env, DISPLAY: display },
    );
    const endpoint = `http://127.0.0.1:${port}`;
    await until('the DevTools endpoint', async () => ((await fetch(`${endpoint}/json/version`)).ok ? true : undefined));
    return new WindowedChromium(endpoint, xvfb, chrome, profile);
  }

  /** Playwright attached to the browser (its one context holds the first tab). */
  async attach(): Promise<Browser> {
    this.#browser ??= await chromium.connectOverCDP(this.endpoint);
    return this.#browser;
  }

  /** Lets go of the browser and puts a new tab in front: the tab the test used is hidden now. */
  async background(): Promise<void> {
    await this.#browser?.close(); // over CDP: disconnects, the browser runs on
    this.#browser = null;
    const tab = (await (await fetch(`${this.endpoint}/json/new?about:blank`, { method: 'PUT' })).json()) as { id: string };
    this.#coverId = tab.id;
  }

  /** Closes the tab in front and attaches again. */
  async foreground(): Promise<Browser> {
    if (this.#coverId !== null) await fetch(`${this.endpoint}/json/close/${this.#coverId}`);
    this.#coverId = null;
    return this.attach();
  }

  async close(): Promise<void> {
    await this.#browser?.close().catch(() => undefined);
    for (const p of [this.chrome, this.xvfb]) {
      p.stdin?.end();
      await new Promise((r) => (p.exitCode !== null ? r(null) : p.once('exit', r)));
    }
    rmSync(this.profile, { recursive: true, force: true });
  }
}
