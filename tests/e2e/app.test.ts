/**
 * The built page in Debian's Chromium: the demo source, replay of captures (ours and the real
 * PX4 ones) checked against the library, the failsafe states, recording and recovery, bad
 * files, CSP, no third-party requests, and offline use. Screenshots of each state go to
 * test-results/screenshots/.
 */
import { spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import type { Download, Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, it } from 'vitest';
import { channelName } from '../../src/decoder/spec.js';
import { CaptureWriter } from '../../src/capture/writer.js';
import { captureChunks } from '../../src/capture/model.js';
import { capturePorts } from '../../src/capture/facts.js';
import { parseCapture } from '../../src/capture/reader.js';
import { readCapture } from '../../src/capture/sniff.js';
import { captureSpan } from '../../src/report/capture-span.js';
import { decodeCapture } from '../../src/report/capture-pass.js';
import { summarizeCapture } from '../../src/report/summary.js';
import { preset } from '../../src/simulator/presets.js';
import { simulate } from '../../src/simulator/simulator.js';
import {
  SHARED_CAPTURES,
  SHOTS as SHOTS_DIR,
  barValues,
  barsShow,
  browserUnavailable,
  moreFrames,
  shot,
  startApp,
  usbChunks,
  writeCapture,
  type AppSession,
} from './app-fixture.js';
import { CLI } from '../built-cli.js';

const skip = browserUnavailable();
if (skip !== null) console.warn(`skipping the page tests: ${skip}`);

let app: AppSession;
let dir = '';

beforeAll(async () => {
  if (skip !== null) return;
  app = await startApp();
  dir = mkdtempSync(join(tmpdir(), 'satscope-e2e-'));
});

afterAll(async () => {
  if (skip !== null) return;
  await app.close();
  rmSync(dir, { recursive: true, force: true });
});

async function open(query = ''): Promise<{ page: Page; errors: string[]; requests: string[] }> {
  const context = await app.browser.newContext({ viewport: { width: 1400, height: 1000 }, acceptDownloads: true });
  const page = await context.newPage();
  const errors: string[] = [];
  const requests: string[] = [];
  page.on('pageerror', (e) => errors.push(e.message));
  page.on('console', (m) => {
    if (m.type() === 'error') errors.push(m.text());
  });
  page.on('request', (r) => requests.push(r.url()));
  await page.goto(app.server.url(`/${query}`));
  return { page, errors, requests };
}

async function replayFile(page: Page, path: string): Promise<void> {
  await page.setInputFiles('input[type=file]', path);
  await page.locator('section.replay').waitFor();
}

async function playToEnd(page: Page): Promise<void> {
  await page.getByRole('radio', { name: 'max' }).click();
  await page.locator('[data-testid="source-status"]', { hasText: '(end)' }).waitFor({ timeout: 20_000 });
}

describe.skipIf(skip !== null)('the page', () => {
  it('starts the demo receiver when no port is granted and shows live bars, system and link state', async () => {
    const { page, errors, requests } = await open();
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await page.waitForFunction(() => document.querySelectorAll('.channels [role="meter"][aria-valuenow]').length >= 12);
    const bars = await barValues(page);
    expect(Object.keys(bars).slice(0, 12)).toEqual(Array.from({ length: 12 }, (_, i) => channelName(i)));
    for (const us of Object.values(bars).slice(0, 12)) {
      expect(us).toBeGreaterThanOrEqual(903);
      expect(us).toBeLessThanOrEqual(2097);
    }
    await expect(page.getByTestId('protocol').textContent()).resolves.toBe('DSMX 11 ms');
    await expect(page.getByTestId('source-status').textContent()).resolves.toMatch(/Demo receiver/);
    // 1.5 s of history in the graphs (11 ms frames).
    await moreFrames(page, 136);
    await shot(page, 'live-demo');
    // Strict CSP, everything from this origin, no violation.
    await expect(page.locator('meta[http-equiv="Content-Security-Policy"]').getAttribute('content')).resolves.toMatch(
      /default-src 'self'; script-src 'self'/,
    );
    const origin = app.server.origin;
    expect(requests.filter((u) => !u.startsWith(origin) && !u.startsWith('blob:') && !u.startsWith('data:'))).toEqual([]);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('replays a real PX4 capture and its bars end on the values the library decodes', async () => {
    const file = join(SHARED_CAPTURES, 'dsm_x_dx9_px4_binding_data.txt');
    if (!existsSync(file)) {
      console.warn(`skipping PX4 replay: ${file} is not here`);
      return;
    }
    const expected = summarizeCapture(readCapture(new Uint8Array(readFileSync(file)), 'x.txt'));
    const { page, errors } = await open('?demo=0');
    await replayFile(page, file);
    await playToEnd(page);
    await page.locator('.channels').nth(1).waitFor();
    await barsShow(page, expected.channels);
    await expect(page.getByTestId('protocol').textContent()).resolves.toBe('DSMX 11 ms');
    await expect(page.getByTestId('count-frames').textContent()).resolves.toBe(String(expected.decoder.frames));
    await shot(page, 'replay-px4-xplus');
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('shows Hold inside a short gap and Failsafe a second into a long one, with the episodes', async () => {
    const sim = simulate(preset('dropouts-failsafe'), undefined, { truth: true });
    const path = join(dir, 'dropouts.sscap');
    writeCapture(path, usbChunks(sim.bytes, sim.timesUs));
    const failsafeGap = sim.truth!.gaps.find((g) => g.failsafe)!;
    const { page } = await open('?demo=0');
    await replayFile(page, path);
    await page.getByRole('button', { name: 'Pause' }).click();
    const seek = async (us: number) => {
      await page.locator('input.seek').evaluate((el, v) => {
        const input = el as HTMLInputElement;
        input.value = String(v);
        input.dispatchEvent(new Event('change', { bubbles: true }));
      }, us);
    };
    // Paused, the panel says so, and what the link was doing at that point of the capture.
    await seek(failsafeGap.lastFrameUs! + 200_000);
    await page.getByTestId('link-hint').filter({ hasText: 'there the link was in hold' }).waitFor();
    await expect(page.getByTestId('link-state').textContent()).resolves.toBe('Paused');
    await shot(page, 'hold');
    await seek(failsafeGap.lastFrameUs! + 1_200_000);
    await page.getByTestId('link-hint').filter({ hasText: 'there the link was in failsafe' }).waitFor();
    await expect(page.getByTestId('link-state').textContent()).resolves.toBe('Paused');
    await shot(page, 'failsafe');
    // Playing, the state at the replay position, named as the capture's.
    await page.getByRole('button', { name: 'Play' }).click();
    await page
      .getByTestId('link-hint')
      .filter({ hasText: /^Replay at \d:\d\d\.\d: / })
      .waitFor();
    await playToEnd(page);
    await page.getByTestId('link-state').filter({ hasText: 'Ended' }).waitFor();
    await page
      .getByTestId('link-hint')
      .filter({ hasText: /^Replay ended at 0:03\.\d: there the link was live\.$/ })
      .waitFor();
    await expect(page.locator('.link dd').nth(1).textContent()).resolves.toBe('2 holds · 1 failsafe');
    // The health report of the capture, as a page and as JSON.
    const html = page.waitForEvent('download');
    await page.getByRole('button', { name: 'Report', exact: true }).click();
    await page.getByRole('button', { name: 'Report as a page (HTML)' }).click();
    const htmlFile = join(dir, 'report.html');
    await (await html).saveAs(htmlFile);
    const text = readFileSync(htmlFile, 'utf8');
    expect(text).toMatch(/<svg/);
    expect(text).not.toMatch(/<script/i);
    const json = page.waitForEvent('download');
    await page.getByRole('button', { name: 'Report', exact: true }).click();
    await page.getByRole('button', { name: 'Report as data (JSON)' }).click();
    const jsonFile = join(dir, 'report.json');
    await (await json).saveAs(jsonFile);
    const report = JSON.parse(readFileSync(jsonFile, 'utf8')) as { remotes: { failsafes: unknown[] }[] };
    expect(report.remotes[0]?.failsafes).toHaveLength(1);
    await page.context().close();
  });

  it('records the demo to storage, exports it, and offers an unfinished recording back after a reload', async () => {
    const { page, errors } = await open();
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await page.getByRole('button', { name: '● Record' }).click();
    // 2 s of the demo recorded.
    await moreFrames(page, 180);
    await page.getByRole('button', { name: 'Stop recording' }).click();
    const download = page.waitForEvent('download');
    await page.getByRole('button', { name: 'Export .sscap' }).first().click();
    const file = join(dir, 'recorded.sscap');
    await (await download).saveAs(file);
    const capture = parseCapture(new Uint8Array(readFileSync(file)));
    expect(capture.issues).toEqual([]);
    expect(capture.chunkEnds.length).toBeGreaterThan(50);
    const summary = summarizeCapture(capture);
    expect(summary.decoder.frames).toBeGreaterThan(120);
    expect(summary.format.system).toBe(0xb2);
    // Both demo remotes, each its own port on the one clock, labelled.
    expect(capturePorts(capture)).toEqual([0, 1]);
    expect(summarizeCapture(capture, { port: 1 }).format.remote).toBe('external');
    expect(capture.meta.ports?.map((p) => p.name)).toEqual(['A', 'B']);
    // Raw .bin: one file per port, each exactly that remote's bytes, decoding with nothing discarded.
    const raws: Download[] = [];
    page.on('download', (d) => raws.push(d));
    await page.getByRole('button', { name: 'Other export formats' }).click();
    await page.getByRole('button', { name: 'raw .bin' }).click();
    await expect.poll(() => raws.length, { timeout: 5000 }).toBe(2);
    await page.waitForTimeout(300);
    expect(raws.length).toBe(2);
    expect(raws.map((d) => d.suggestedFilename())).toEqual([expect.stringMatching(/-port0\.bin$/), expect.stringMatching(/-port1\.bin$/)]);
    for (const [port, d] of raws.entries()) {
      const path = join(dir, `recorded-${port}.bin`);
      await d.saveAs(path);
      const raw = readCapture(new Uint8Array(readFileSync(path)), path);
      const want = [...captureChunks(capture, port)].flatMap((c) => [...c.bytes]);
      expect(Buffer.from(raw.bytes).equals(Buffer.from(want))).toBe(true);
      const alone = summarizeCapture(raw);
      expect(alone.decoder.discardedBytes).toBe(0);
      expect(alone.decoder.frames).toBe(summarizeCapture(capture, { port }).decoder.frames);
      expect(alone.format.remote).toBe(port === 0 ? 'internal' : 'external');
    }
    page.removeAllListeners('download');
    // A report on the live session's recording, made off the reading worker.
    const reportDownload = page.waitForEvent('download');
    await page.getByRole('button', { name: 'Report', exact: true }).click();
    await page.getByRole('button', { name: 'Report as data (JSON)' }).click();
    const reportFile = join(dir, 'live.report.json');
    await (await reportDownload).saveAs(reportFile);
    const liveReport = JSON.parse(readFileSync(reportFile, 'utf8')) as { remotes: { frames: number }[] };
    expect(liveReport.remotes).toHaveLength(2);
    expect(liveReport.remotes[0]!.frames).toBe(summary.decoder.frames);

    // Start again and reload without stopping: the recording is kept and offered back.
    await page.getByRole('button', { name: '● Record' }).click();
    await moreFrames(page, 136);
    await page.reload();
    const banner = page.locator('.recovered');
    await banner.waitFor();
    await expect(banner.textContent()).resolves.toMatch(/unfinished recording/);
    const again = page.waitForEvent('download');
    await banner.getByRole('button', { name: 'Export .sscap' }).click();
    const kept = join(dir, 'kept.sscap');
    await (await again).saveAs(kept);
    const recovered = summarizeCapture(parseCapture(new Uint8Array(readFileSync(kept))));
    expect(recovered.decoder.frames).toBeGreaterThan(80);
    await banner.getByRole('button', { name: 'Discard' }).click();
    await banner.waitFor({ state: 'detached' });
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('shows the two demo remotes side by side and switches the views to the one clicked', async () => {
    const { page, errors } = await open();
    const rows = page.locator('.remotes .remote-table tbody tr');
    await rows.nth(1).waitFor({ timeout: 10_000 });
    await expect(rows.count()).resolves.toBe(2);
    await page.locator('.remotes .state-chip', { hasText: 'live' }).nth(1).waitFor({ timeout: 10_000 });
    await expect(page.getByTestId('remote').count()).resolves.toBe(1);
    await expect(page.getByTestId('remote').textContent()).resolves.toBe('Internal remote');
    await page.getByTestId('remote-B').click();
    await page.locator('.panel h2', { hasText: 'remote B' }).waitFor();
    await expect(page.getByTestId('remote').textContent()).resolves.toBe('External remote');
    await moreFrames(page, 90);
    await shot(page, 'remotes-demo');
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('replays a two-port capture on one clock, each remote with its own values', async () => {
    const a = simulate({ ...preset('dropouts-failsafe'), seed: 11 }, 3_000_000);
    const b = simulate({ ...preset('dsmx-11ms-2048-external'), seed: 12, dropouts: [{ atUs: 2_000_000, durationUs: 300_000 }] }, 3_000_000);
    const writer = new CaptureWriter({ source: 'test', ports: [{ name: 'A' }, { name: 'R' }] });
    const parts = [writer.header()];
    const chunksA = usbChunks(a.bytes, a.timesUs).map((c) => ({ ...c, port: 0 }));
    const chunksB = usbChunks(b.bytes, b.timesUs).map((c) => ({ ...c, port: 1 }));
    for (const c of [...chunksA, ...chunksB].sort((x, y) => x.timeUs - y.timeUs)) parts.push(writer.data(c.bytes, c.timeUs, c.port));
    const path = join(dir, 'two.sscap');
    writeFileSync(path, Buffer.concat(parts));
    const capture = parseCapture(new Uint8Array(readFileSync(path)));
    const expectA = summarizeCapture(capture, { port: 0 });
    const expectB = summarizeCapture(capture, { port: 1 });
    const { page, errors } = await open('?demo=0');
    await replayFile(page, path);
    await playToEnd(page);
    await page.getByTestId('remote-R').waitFor();
    // At full speed the end can show before a channel sent only now and then was ever drawn.
    const check = (expected: typeof expectA) =>
      barsShow(
        page,
        expected.channels.filter((ch) => ch.id < 12),
      );
    await check(expectA);
    await page.getByTestId('remote-R').click();
    await page.locator('.panel h2', { hasText: 'remote R' }).waitFor();
    await check(expectB);
    await expect(page.getByTestId('count-frames').textContent()).resolves.toBe(String(expectB.decoder.frames));
    // The external remote takes its resolution from the internal one on the other port.
    await expect(page.getByTestId('resolution').textContent()).resolves.toMatch(/2048 from the internal remote/);
    await page.waitForTimeout(500);
    await shot(page, 'remotes-replay');
    // Min / max / last per channel: what satscope info prints for that port.
    await page.getByText('Min / max / last per channel').first().click();
    const table = page.getByTestId('channel-ranges').first();
    const ranges = expectB.channels
      .filter((c) => c.id < 12)
      .map((c) => [c.name, String(c.frames), `${c.minUs} µs`, `${c.maxUs} µs`, `${c.lastUs} µs`]);
    await expect
      .poll(() => table.locator('tbody tr').evaluateAll((rows) => rows.map((r) => [...r.children].map((c) => c.textContent ?? ''))), {
        timeout: 3000,
      })
      .toEqual(ranges);
    await page.getByText('Every frame so far.').first().waitFor();

    // Remote R's decoded frames, the whole capture and then 1-2 s of it, are the lines
    // `satscope decode` prints for that port.
    const cli = (format: string) =>
      spawnSync(process.execPath, [CLI, 'decode', path, '--format', format, '--port', '1'], { encoding: 'utf8' }).stdout;
    const exportFrames = async (button: string, from = '', to = ''): Promise<string> => {
      await page.getByRole('button', { name: 'Report', exact: true }).click();
      await page.getByRole('group', { name: 'Decoded frames of remote R' }).waitFor();
      await page.getByRole('textbox', { name: 'from' }).fill(from);
      await page.getByRole('textbox', { name: 'to' }).fill(to);
      if (from !== '') await shot(page, 'frames-export');
      const download = page.waitForEvent('download');
      await page.getByRole('button', { name: button }).click();
      const d = await download;
      expect(d.suggestedFilename()).toMatch(/^two-R\.frames\.(csv|jsonl)$/);
      const saved = join(dir, d.suggestedFilename());
      await d.saveAs(saved);
      return readFileSync(saved, 'utf8');
    };
    const csv = cli('csv');
    expect(csv.split('\n').length).toBeGreaterThan(200);
    await expect(exportFrames('Frames as CSV')).resolves.toBe(csv);
    const start = captureSpan(capture).startUs;
    const inSpan = (line: string) => {
      const t = (JSON.parse(line) as { t: number }).t * 1e6 - start;
      return t >= 1e6 && t <= 2e6;
    };
    const want = cli('jsonl').trimEnd().split('\n').filter(inSpan);
    expect(want.length).toBeGreaterThan(80);
    await expect(exportFrames('Frames as JSONL', '1', '2')).resolves.toBe(`${want.join('\n')}\n`);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('inspects frames in hex with discarded bytes and resyncs where the decoder met them', async () => {
    // A damaged line: truncated frames, noise and flipped bits between good frames.
    const sim = simulate({ ...preset('damaged-line'), seed: 21 }, 1_000_000);
    const path = join(dir, 'damaged.sscap');
    writeCapture(path, usbChunks(sim.bytes, sim.timesUs));
    const expected = { discarded: [] as { offset: number; length: number }[], frames: [] as number[] };
    const { decoder } = decodeCapture(
      readCapture(new Uint8Array(readFileSync(path)), 'd.sscap'),
      {
        onEvent: (e) => {
          if (e.type === 'discarded') expected.discarded.push({ offset: e.offset, length: e.length });
        },
      },
      (f) => expected.frames.push(f.offset),
    );
    expect(expected.discarded.length).toBeGreaterThan(2);
    const { page, errors } = await open('?demo=0');
    await replayFile(page, path);
    await playToEnd(page);
    await page.getByRole('button', { name: 'Inspect frames…' }).click();
    const rows = page.locator('.insp-body [role="row"]');
    await rows.first().waitFor();
    await page.waitForTimeout(600);
    const shown = await rows.evaluateAll((els) =>
      els.map((el) => ({ cls: el.className, offset: Number(el.children[1]?.textContent), text: el.textContent ?? '' })),
    );
    const frames = shown.filter((r) => r.cls.includes('frame')).map((r) => r.offset);
    expect(frames).toEqual(expected.frames);
    // Every discard the library reports is shown at its offset (runs of one reason merged).
    for (const d of expected.discarded)
      expect(
        shown.some((r) => r.cls.includes('discard') && r.offset <= d.offset && r.text.includes('discarded')),
        `discard at ${d.offset}`,
      ).toBe(true);
    expect(shown.some((r) => r.text.includes('resync'))).toBe(true);
    expect(decoder.stats.frames).toBe(frames.length);
    const panel = page.locator('.panel', { has: page.getByText('Frame inspector') }).last();
    await panel.scrollIntoViewIfNeeded();
    await panel.screenshot({ path: join(SHOTS_DIR, 'inspector.png') });
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it("gives up the internal remote's resolution for a remote whose bytes do not read at it", async () => {
    const a = simulate({ ...preset('dsmx-11ms-2048-internal'), seed: 31 }, 2_000_000);
    const b = simulate({ ...preset('dsm2-22ms-1024-external'), seed: 32 }, 2_000_000);
    const writer = new CaptureWriter({ source: 'test', ports: [{ name: 'A' }, { name: 'B' }] });
    const chunks = [
      ...usbChunks(a.bytes, a.timesUs).map((c) => ({ ...c, port: 0 })),
      ...usbChunks(b.bytes, b.timesUs).map((c) => ({ ...c, port: 1 })),
    ];
    const path = join(dir, 'mixed.sscap');
    writeFileSync(
      path,
      Buffer.concat([writer.header(), ...chunks.sort((x, y) => x.timeUs - y.timeUs).map((c) => writer.data(c.bytes, c.timeUs, c.port))]),
    );
    const expectB = summarizeCapture(parseCapture(new Uint8Array(readFileSync(path))), { port: 1 });
    const { page } = await open('?demo=0');
    await replayFile(page, path);
    await page.getByRole('radio', { name: '4×' }).click();
    await page
      .getByRole('alert')
      .or(page.getByRole('status'))
      .filter({ hasText: 'does not read at the internal remote' })
      .first()
      .waitFor({ timeout: 10_000 });
    await page.getByRole('radio', { name: 'max' }).click();
    await page.locator('[data-testid="source-status"]', { hasText: '(end)' }).waitFor({ timeout: 20_000 });
    await page.getByTestId('remote-B').click();
    await page.locator('.panel h2', { hasText: 'remote B' }).waitFor();
    await expect(page.getByTestId('resolution').textContent()).resolves.toMatch(/^1024/);
    await barsShow(page, expectB.channels);
    await page.context().close();
  });

  it('replays a raw .bin (no timing) and shows its channels', async () => {
    const sim = simulate({ ...preset('xplus-dx9'), seed: 5 }, 1_000_000);
    const path = join(dir, 'dump.bin');
    writeFileSync(path, sim.bytes);
    const expected = summarizeCapture(readCapture(sim.bytes, 'dump.bin'));
    const { page, errors } = await open('?demo=0');
    await replayFile(page, path);
    await page.locator('[data-testid="source-status"]', { hasText: '(end)' }).waitFor({ timeout: 10_000 });
    await page.locator('.channels').nth(1).waitFor();
    await barsShow(page, expected.channels);
    expect(errors).toEqual([]);
    await page.context().close();
  });

  it('tells a browser without Web Serial what to do, and still runs the demo', async () => {
    const context = await app.browser.newContext({ viewport: { width: 1400, height: 1000 } });
    // What Firefox and Safari look like to the page.
    await context.addInitScript(() => {
      delete (Navigator.prototype as unknown as { serial?: unknown }).serial;
    });
    const page = await context.newPage();
    await page.goto(app.server.url('/?demo=0'));
    // The empty state says so before anything is pressed, and the button says it again.
    await expect(page.getByTestId('empty-state').textContent()).resolves.toMatch(/This browser has no Web Serial/);
    await page.getByRole('banner').getByRole('button', { name: 'Connect receiver' }).click();
    const alert = page.getByRole('alert').filter({ hasText: 'This browser has no Web Serial' });
    await alert.waitFor();
    await expect(alert.textContent()).resolves.toMatch(/Use Chrome, Edge or Opera/);
    await page.getByRole('button', { name: 'Demo', exact: true }).click();
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await context.close();
  });

  it('tells the user a file is not a capture and keeps the page usable', async () => {
    const path = join(dir, 'notes.txt');
    writeFileSync(path, 'shopping list\neggs\n');
    const { page } = await open('?demo=0');
    await page.setInputFiles('input[type=file]', path);
    const alert = page.getByRole('alert').filter({ hasText: 'Cannot open notes.txt' });
    await alert.waitFor();
    await expect(alert.textContent()).resolves.toMatch(/not a Saleae|text/i);
    await shot(page, 'bad-file');
    await page.context().close();
  });

  it('works offline once loaded: the service worker serves the page', async () => {
    const { page } = await open();
    await page.waitForFunction(
      () => navigator.serviceWorker.controller !== null || navigator.serviceWorker.ready.then(() => true),
      undefined,
      { timeout: 10_000 },
    );
    await page.evaluate(() => navigator.serviceWorker.ready);
    await page.reload();
    await page.context().setOffline(true);
    await page.reload();
    await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
    await page.context().close();
  });
});
