/**
 * Page benchmark (npm run bench:page): the built page in Debian's Chromium. bench/README.md
 * says what each section measures and how to run parts of it. Results are printed and written
 * to bench-results/page.json; nothing is asserted (a benchmark measures, tests assert).
 *
 * Sections (BENCH_ONLY=serial,demo,four,record,hour,day,week,bundle picks some):
 * - serial: one receiver on the real WebSerial stack through a pty, at real pace, recording;
 * - demo: the built-in demo (two simulated remotes in the worker);
 * - four: four remotes at 11 ms for 10 minutes, a four-port capture replayed at 1×;
 * - record: an 8-hour recording fed through the pty faster than real time, heap sampled;
 * - hour: opening a 1-hour capture; day: opening the 24-hour capture and seeking in it; week:
 *   the 7-day capture (3 GB, bench/day.mjs --only 7d --make-only): memory and seeks;
 * - bundle: initial JS and CSS, gzipped.
 */
import { mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, statSync, writeFileSync, existsSync } from 'node:fs';
import { loadavg, tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { gzipSync } from 'node:zlib';
import type { Browser, CDPSession, Page } from 'playwright-core';
import { it } from 'vitest';
import { CaptureWriter } from '../src/capture/writer.js';
import { REMOTE_LABELS } from '../src/worker/protocol.js';
import { Simulator } from '../src/simulator/simulator.js';
import { demoScenario, preset } from '../src/simulator/presets.js';
import type { Scenario } from '../src/simulator/scenario.js';
import { APP_DIR, ROOT, browserUnavailable, usbChunks, writeCapture } from '../tests/e2e/app-fixture.js';
import { launchChromium, startStaticServer } from '../tests/e2e/harness/browser.js';
import { installSerialPolicy } from '../tests/e2e/harness/policy.js';
import { type FakeSerialPort, fakeSerialUnsupportedReason, openFakeSerialPort } from '../tests/e2e/harness/pty-serial.js';

const env = (name: string, fallback: number) => Number(process.env[name] ?? fallback);
/** Length of the serial and demo runs, s. */
const SECONDS = env('BENCH_SECONDS', 60);
/** Length of the four-remote run, s (the target is about 10 minutes). */
const FOUR_SECONDS = env('BENCH_FOUR_SECONDS', 600);
/** Hours of recording fed through the pty, and how many times faster than real time. */
const RECORD_HOURS = env('BENCH_RECORD_HOURS', 8);
const RECORD_SPEED = env('BENCH_RECORD_SPEED', 48);
const ONLY = (process.env.BENCH_ONLY ?? 'serial,demo,four,record,hour,day,week,bundle').split(',');
/** The 24-hour capture bench/day.mjs makes (two remotes at 11 ms, 446 MB). */
const DAY_FILE = join(tmpdir(), 'satscope-bench-day-v1-24h.sscap');
/** Times the day capture is opened, each on a new page after the same-run baseline (`twoCoreBaselineMs`). */
const DAY_RUNS = env('BENCH_DAY_RUNS', 5);

const pct = (xs: number[], p: number) => {
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor((p / 100) * s.length))] ?? Number.NaN;
};
const round = (x: number, digits = 1) => Number(x.toFixed(digits));
const load = () => loadavg().map((x) => round(x, 2));

async function observeLongTasks(page: Page): Promise<void> {
  await page.addInitScript(() => {
    const w = window as unknown as { __longTasks: number[] };
    w.__longTasks = [];
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) w.__longTasks.push(e.duration);
    }).observe({ type: 'longtask', buffered: true });
  });
}

async function collect(page: Page) {
  return page.evaluate(() => {
    const w = window as unknown as { __longTasks: number[]; __satscopeBench: { latencies: number[] } };
    const out = { longTasks: w.__longTasks.slice(), latencies: w.__satscopeBench.latencies.slice() };
    w.__longTasks.length = 0;
    w.__satscopeBench.latencies.length = 0;
    return out;
  });
}

interface HeapUsage {
  usedSize: number;
  backingStorageSize?: number;
}

/** The page's V8 heap after a full collection, MB (ArrayBuffer backing stores apart). */
async function heapMB(page: Page): Promise<number> {
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('HeapProfiler.collectGarbage');
  const { usedSize } = (await cdp.send('Runtime.getHeapUsage')) as HeapUsage;
  await cdp.detach();
  return usedSize / (1 << 20);
}

/**
 * The decoder worker through the browser's CDP session (playwright opens sessions on pages
 * only): attached without flattening, commands go through Target.sendMessageToTarget.
 */
class WorkerTarget {
  #next = 1;
  readonly #waiting = new Map<number, (result: unknown) => void>();
  private constructor(
    readonly cdp: CDPSession,
    readonly sessionId: string,
  ) {
    cdp.on('Target.receivedMessageFromTarget', (e: { sessionId: string; message: string }) => {
      if (e.sessionId !== this.sessionId) return;
      const m = JSON.parse(e.message) as { id?: number; result?: unknown; error?: unknown };
      if (m.id !== undefined) this.#waiting.get(m.id)?.(m.result ?? m.error);
    });
  }

  static async attach(browser: Browser): Promise<WorkerTarget | null> {
    const cdp = await browser.newBrowserCDPSession();
    const { targetInfos } = (await cdp.send('Target.getTargets')) as { targetInfos: { targetId: string; type: string; title: string }[] };
    const target = targetInfos.find((t) => t.type === 'worker' && t.title === 'satscope');
    if (target === undefined) return null;
    const { sessionId } = (await cdp.send('Target.attachToTarget', { targetId: target.targetId, flatten: false })) as { sessionId: string };
    return new WorkerTarget(cdp, sessionId);
  }

  send(method: string, params: object = {}): Promise<unknown> {
    const id = this.#next++;
    const reply = new Promise<unknown>((resolve) => this.#waiting.set(id, resolve));
    void this.cdp.send('Target.sendMessageToTarget', { sessionId: this.sessionId, message: JSON.stringify({ id, method, params }) });
    return reply;
  }

  /** Heap after a full collection, MB: V8's objects and, apart, ArrayBuffer backing stores. */
  async heapMB(): Promise<{ used: number; buffers: number }> {
    await this.send('HeapProfiler.collectGarbage');
    const h = (await this.send('Runtime.getHeapUsage')) as HeapUsage;
    return { used: round(h.usedSize / (1 << 20), 2), buffers: round((h.backingStorageSize ?? Number.NaN) / (1 << 20), 2) };
  }

  async detach(): Promise<void> {
    await this.cdp.detach();
  }
}

/**
 * Heap the worker allocates while `open` runs, MB, objects already collected included (Chromium's
 * sampling heap profiler): garbage Node's benchmarks cannot see, such as a double boxed a record
 * where the browser's compiler did not inline a call (250 MB over the day capture, once). The
 * worker's half only: the helper worker ends with the open, and its profile with it.
 */
async function workerAllocatedMB(browser: Browser, open: () => Promise<unknown>): Promise<number> {
  // The page starts its worker as it loads.
  let worker: WorkerTarget | null = null;
  for (let tries = 0; worker === null && tries < 50; tries++) {
    worker = await WorkerTarget.attach(browser);
    if (worker === null) await new Promise((resolve) => setTimeout(resolve, 100));
  }
  if (worker === null) return Number.NaN;
  await worker.send('HeapProfiler.enable');
  await worker.send('HeapProfiler.startSampling', {
    samplingInterval: 1 << 16,
    includeObjectsCollectedByMajorGC: true,
    includeObjectsCollectedByMinorGC: true,
  });
  await open();
  const { profile } = (await worker.send('HeapProfiler.stopSampling')) as { profile: { head: SamplingNode } };
  await worker.detach();
  let bytes = 0;
  const add = (n: SamplingNode): void => {
    bytes += n.selfSize;
    for (const c of n.children) add(c);
  };
  add(profile.head);
  return round(bytes / (1 << 20), 1);
}

interface SamplingNode {
  selfSize: number;
  children: SamplingNode[];
}

/** Page heap used plus ArrayBuffer backing stores (the page's share of a file it holds), MB. */
async function pageHeap(page: Page): Promise<{ used: number; buffers: number }> {
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('HeapProfiler.collectGarbage');
  const h = (await cdp.send('Runtime.getHeapUsage')) as HeapUsage;
  await cdp.detach();
  return { used: round(h.usedSize / (1 << 20), 2), buffers: round((h.backingStorageSize ?? Number.NaN) / (1 << 20), 2) };
}

/**
 * CPU time of the page's threads, read from /proc: the renderer's main thread and its
 * DedicatedWorker thread (the decoder worker), in clock ticks. Chromium runs a page and its
 * workers in one renderer process, each on a thread of its own, so the kernel's per-thread
 * counters measure the worker's whole cost (decoding, messages, its own GC) without touching its
 * code and without a profiler's overhead. Renderers are found among this process's descendants.
 */
interface ThreadTimes {
  main: number;
  worker: number;
  rssMB: number;
}

function descendants(): number[] {
  const children = new Map<number, number[]>();
  for (const d of readdirSync('/proc')) {
    if (!/^\d+$/.test(d)) continue;
    try {
      const stat = readFileSync(`/proc/${d}/stat`, 'utf8');
      const ppid = Number(stat.slice(stat.lastIndexOf(')') + 2).split(' ')[1]);
      const list = children.get(ppid) ?? [];
      list.push(Number(d));
      children.set(ppid, list);
    } catch {
      // gone meanwhile
    }
  }
  const out: number[] = [];
  const queue = [process.pid];
  for (let p = queue.pop(); p !== undefined; p = queue.pop()) {
    for (const c of children.get(p) ?? []) {
      out.push(c);
      queue.push(c);
    }
  }
  return out;
}

/** utime + stime of a task, clock ticks. */
function ticks(path: string): number {
  const stat = readFileSync(path, 'utf8');
  const fields = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
  return Number(fields[11]) + Number(fields[12]);
}

/** CPU time (user + system) of every Chromium process this run started, s: their exited threads too (the replay's helper worker). */
function chromiumCpuSeconds(): number {
  let sum = 0;
  for (const pid of descendants()) {
    try {
      if (readFileSync(`/proc/${pid}/cmdline`, 'utf8').includes('chrom')) sum += ticks(`/proc/${pid}/stat`);
    } catch {
      // gone meanwhile
    }
  }
  return sum / 100;
}

/**
 * The day capture's yardstick, measured just before each open: two workers at once,
 * each a plain CRC-32 loop (a table, a byte at a time) over 128 MB (a 16 MB buffer eight
 * times), ms until both are done. The open is bound by what two cores can do, and on a shared
 * machine that changes from one minute to the next (the same build's open took 3.4 to 6.1 s
 * within twenty minutes): an open's time over this one's, in the same minute, is the figure to
 * compare between runs.
 */
async function twoCoreBaselineMs(browser: Browser): Promise<number> {
  // A blank page of its own: the app's Content-Security-Policy admits no worker from a blob.
  const page = await browser.newPage();
  await page.goto('about:blank');
  const ms = await page.evaluate(async () => {
    const source = `
      const table = new Int32Array(256);
      for (let n = 0; n < 256; n++) {
        let c = n;
        for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
        table[n] = c;
      }
      const bytes = new Uint8Array(16 << 20);
      let x = 2463534242;
      for (let i = 0; i < bytes.length; i++) {
        x ^= x << 13; x ^= x >>> 17; x ^= x << 5;
        bytes[i] = x;
      }
      onmessage = () => {
        let c = -1;
        for (let r = 0; r < 8; r++) for (let i = 0; i < bytes.length; i++) c = table[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
        postMessage(c);
      };
      postMessage('ready');`;
    const url = URL.createObjectURL(new Blob([source], { type: 'text/javascript' }));
    const workers = [new Worker(url), new Worker(url)];
    const next = (w: Worker) => new Promise<unknown>((resolve) => w.addEventListener('message', (e) => resolve(e.data), { once: true }));
    const failed = new Promise<never>((_, reject) => {
      for (const w of workers) w.addEventListener('error', (e) => reject(new Error(`baseline worker: ${e.message}`)));
    });
    await Promise.race([Promise.all(workers.map(next)), failed]);
    const start = performance.now();
    const done = Promise.all(workers.map(next));
    for (const w of workers) w.postMessage('go');
    await Promise.race([done, failed]);
    const ms = performance.now() - start;
    for (const w of workers) w.terminate();
    URL.revokeObjectURL(url);
    return Math.round(ms);
  });
  await page.close();
  return ms;
}

function threadTimes(): ThreadTimes | null {
  for (const pid of descendants()) {
    try {
      if (!readFileSync(`/proc/${pid}/cmdline`, 'utf8').includes('--type=renderer')) continue;
      const tasks = readdirSync(`/proc/${pid}/task`);
      const worker = tasks.find((t) => readFileSync(`/proc/${pid}/task/${t}/comm`, 'utf8').startsWith('DedicatedWorker'));
      if (worker === undefined) continue;
      const rss = /VmRSS:\s+(\d+)/.exec(readFileSync(`/proc/${pid}/status`, 'utf8'));
      return {
        main: ticks(`/proc/${pid}/task/${pid}/stat`),
        worker: ticks(`/proc/${pid}/task/${worker}/stat`),
        rssMB: Number(rss?.[1] ?? Number.NaN) / 1024,
      };
    } catch {
      // the process went away meanwhile
    }
  }
  return null;
}

/** Per cent of one core each thread used between two readings `seconds` apart (USER_HZ = 100). */
function cpuShare(a: ThreadTimes | null, b: ThreadTimes | null, seconds: number) {
  if (a === null || b === null) return { mainCpuPct: Number.NaN, workerCpuPct: Number.NaN };
  return { mainCpuPct: round((b.main - a.main) / seconds), workerCpuPct: round((b.worker - a.worker) / seconds) };
}

function summarize(name: string, seconds: number, m: { longTasks: number[]; latencies: number[] }) {
  const lat = m.latencies.filter((x) => x >= 0 && x < 5000);
  return {
    source: name,
    seconds,
    longTasks: m.longTasks.length,
    longTaskMsTotal: Math.round(m.longTasks.reduce((a, b) => a + b, 0)),
    longTaskMsMax: Math.round(Math.max(0, ...m.longTasks)),
    batchesPainted: lat.length,
    latencyMsMedian: round(pct(lat, 50)),
    latencyMsP95: round(pct(lat, 95)),
    latencyMsMax: round(Math.max(0, ...lat)),
  };
}

/** Four remotes as a real installation has them (spec §7.3): A internal, B, R, L external, each with its own fades and dropouts. */
function fourRemotes(): Scenario[] {
  const a = demoScenario();
  const external = (seed: number, lossRate: number, dropAtS: number): Scenario => ({
    ...a,
    name: `external-${seed}`,
    seed,
    remote: 'external',
    vtx: undefined,
    fades: { start: 40, lossRate, randomRate: 0.002 },
    dropouts: [{ atUs: dropAtS * 1e6, durationUs: 0.3e6 }],
  });
  return [a, external(21, 0.004, 20), external(22, 0.008, 45), external(23, 0.012, 70)];
}

/** A capture of `scenarios` (one port each) for `seconds`, as the recorder writes them: 16 ms USB windows, one clock. */
function multiPortCapture(path: string, scenarios: Scenario[], seconds: number): number {
  const writer = new CaptureWriter({
    source: 'bench',
    baudRate: 115200,
    ports: scenarios.map((_, i) => ({ name: REMOTE_LABELS[i] ?? `R${i}` })),
  });
  const sims = scenarios.map((s) => new Simulator(s));
  const parts: Uint8Array[] = [writer.header()];
  const start = (sims[0] as Simulator).scenario.timing.startUs;
  for (let t = start; t < start + seconds * 1e6; t += 1e6) {
    const records: { port: number; bytes: Uint8Array; timeUs: number }[] = [];
    sims.forEach((sim, port) => {
      const { bytes, timesUs } = sim.generate(Math.min(t + 1e6, start + seconds * 1e6));
      for (const c of usbChunks(bytes, timesUs)) records.push({ port, ...c });
    });
    records.sort((x, y) => x.timeUs - y.timeUs || x.port - y.port);
    for (const r of records) parts.push(writer.data(r.bytes, r.timeUs, r.port));
  }
  const size = parts.reduce((n, p) => n + p.length, 0);
  const out = new Uint8Array(size);
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  writeFileSync(path, out);
  return size;
}

/**
 * Arms a timer in the page from the file input's change (the test's own upload of the file
 * through CDP is not counted) to the first overview drawn (of a long capture, the part read so
 * far), to the first frames counted, and to the overview drawn complete.
 */
async function armOpenTimer(page: Page): Promise<void> {
  await page.evaluate(() => {
    const w = window as unknown as { __open: { start: number; plotted: number; withData: number; counted: number; complete: number } };
    w.__open = { start: 0, plotted: 0, withData: 0, counted: 0, complete: 0 };
    document.querySelector('input[type=file]')?.addEventListener(
      'change',
      () => {
        w.__open.start = performance.now();
      },
      { capture: true },
    );
    new MutationObserver((_, obs) => {
      const counted = document.querySelector('[data-testid="count-frames"]')?.textContent !== '—';
      if (w.__open.counted === 0 && counted) w.__open.counted = performance.now();
      if (w.__open.plotted === 0 && document.querySelector('section.replay .overview canvas') !== null)
        w.__open.plotted = performance.now();
      // A page without a growing overview (BENCH_APP_DIR of an older build) is complete at once.
      const o = document.querySelector('section.replay .overview');
      const drawnComplete = o?.querySelector('canvas') && o.getAttribute('data-complete') !== 'false';
      // The first overview drawn is the span alone, hatched: the first with anything read says more than 0 %.
      const reading = document.querySelector('[data-testid="replay-reading"]')?.textContent ?? '';
      if (w.__open.withData === 0 && (drawnComplete || (/^Reading the capture: /.test(reading) && !reading.endsWith(': 0 %'))))
        w.__open.withData = performance.now();
      if (w.__open.counted > 0 && drawnComplete) {
        w.__open.complete = performance.now();
        obs.disconnect();
      }
    }).observe(document.body, {
      subtree: true,
      childList: true,
      characterData: true,
      attributes: true,
      attributeFilter: ['data-complete'],
    });
  });
}

/**
 * Opens `file` and times it: in all, and its parts from the page's marks (open-file.ts,
 * store.ts): the page reading the file, the worker from the bytes posted to its overview
 * received (reading the capture and decoding it for the overview), and the page drawing it.
 */
async function openTimes(
  page: Page,
  file: string,
  timeoutMs: number,
): Promise<{
  ms: number;
  withDataMs: number;
  countedMs: number;
  completeMs: number;
  pageReadMs: number;
  workerMs: number;
  drawMs: number;
}> {
  await armOpenTimer(page);
  await page.setInputFiles('input[type=file]', file);
  await page.waitForFunction(() => (window as unknown as { __open: { complete: number } }).__open.complete > 0, undefined, {
    timeout: timeoutMs,
  });
  return page.evaluate(() => {
    const o = (window as unknown as { __open: { start: number; plotted: number; withData: number; counted: number; complete: number } })
      .__open;
    const mark = (name: string) => performance.getEntriesByName(name).at(-1)?.startTime ?? Number.NaN;
    const read = mark('satscope:capture-read');
    const received = mark('satscope:overview-received');
    return {
      ms: Math.round(o.plotted - o.start),
      withDataMs: Math.round(o.withData - o.start),
      countedMs: Math.round(o.counted - o.start),
      completeMs: Math.round(o.complete - o.start),
      pageReadMs: Math.round(read - o.start),
      workerMs: Math.round(received - read),
      drawMs: Math.round(o.plotted - received),
    };
  });
}

/**
 * Seeks to `fraction` of the capture through the seek slider (as a user lets go of it): ms from
 * the slider's change to the animation frame that drew the remote at its new position (its clock
 * within 2 s after the target: a seek replays a little history first), split at the first batch
 * after the worker's reset into the worker's part and the page's.
 */
async function seekTime(page: Page, fraction: number): Promise<{ ms: number; workerMs: number; pageMs: number }> {
  return page.evaluate(async (f) => {
    const none = { ms: Number.NaN, workerMs: Number.NaN, pageMs: Number.NaN };
    const input = document.querySelector<HTMLInputElement>('section.replay input.seek');
    const bench = window.__satscopeBench;
    // A build without these hooks (BENCH_APP_DIR of an older page) cannot time seeks.
    if (input === null || bench === undefined || !('painted' in bench) || !('firstBatchAtMs' in bench)) return none;
    const min = Number(input.min);
    const max = Number(input.max);
    const target = Math.round(min + f * (max - min));
    input.value = String(target);
    const start = performance.now();
    input.dispatchEvent(new Event('change', { bubbles: true }));
    return new Promise<typeof none>((resolve) => {
      const deadline = start + 30_000;
      const check = () => {
        const p = bench.painted;
        if (p.atMs > start && p.clockUs >= target - 1e6 && p.clockUs <= target + 2e6) {
          const batch = bench.firstBatchAtMs > start ? bench.firstBatchAtMs : Number.NaN;
          resolve({ ms: Math.round(p.atMs - start), workerMs: Math.round(batch - start), pageMs: Math.round(p.atMs - batch) });
        } else if (performance.now() > deadline) resolve(none);
        else requestAnimationFrame(check);
      };
      requestAnimationFrame(check);
    });
  }, fraction);
}

interface ProfileNode {
  id: number;
  callFrame: { functionName: string; url: string; lineNumber: number };
  children?: number[];
}

/** Self time by function from a CPU profile, the largest first: where a thread's time goes. */
function topSelf(profile: { nodes: ProfileNode[]; samples: number[]; timeDeltas: number[] }, count = 12): string[] {
  const byId = new Map(profile.nodes.map((n) => [n.id, n]));
  const self = new Map<string, number>();
  let total = 0;
  profile.samples.forEach((id, i) => {
    const n = byId.get(id);
    const dt = profile.timeDeltas[i] ?? 0;
    total += dt;
    if (n === undefined) return;
    const file = n.callFrame.url.split('/').pop() ?? '';
    const key = `${n.callFrame.functionName || '(anonymous)'} ${file}:${n.callFrame.lineNumber + 1}`;
    self.set(key, (self.get(key) ?? 0) + dt);
  });
  return [...self.entries()]
    .sort((a, b) => b[1] - a[1])
    .slice(0, count)
    .map(([k, us]) => `${((100 * us) / total).toFixed(1)} % ${k}`);
}

/**
 * Traces the page for `ms` (BENCH_PROFILE=1): the main thread's time by kind of work (script,
 * style, layout, paint…), in ms per second, and what the tasks over 50 ms were made of (their
 * own work by kind, summed over them, ms). Events nest (a task holds its script and layout),
 * so the rows overlap: read each against RunTask, the whole of the thread's tasks.
 */
async function traceMainThread(
  page: Page,
  ms: number,
): Promise<{ msPerSecond: Record<string, number>; longTasks: number; inLongTasksMs: Record<string, number> }> {
  const cdp = await page.context().newCDPSession(page);
  type TraceEvent = { name: string; ph: string; ts: number; dur?: number; tid: number; args?: { name?: string } };
  const events: TraceEvent[] = [];
  // Playwright types trace events as string maps; they are JSON objects with numbers.
  cdp.on('Tracing.dataCollected', (e) => {
    events.push(...(e.value as unknown as TraceEvent[]));
  });
  const done = new Promise<void>((resolve) => cdp.once('Tracing.tracingComplete', () => resolve()));
  await cdp.send('Tracing.start', { categories: 'devtools.timeline,disabled-by-default-devtools.timeline', transferMode: 'ReportEvents' });
  await page.waitForTimeout(ms);
  await cdp.send('Tracing.end');
  await done;
  await cdp.detach();
  const main = events.find((e) => e.ph === 'M' && e.name === 'thread_name' && e.args?.name === 'CrRendererMain')?.tid;
  const complete = events.filter((e) => e.tid === main && e.ph === 'X' && e.dur !== undefined).sort((x, y) => x.ts - y.ts);
  const byName = new Map<string, number>();
  for (const e of complete) byName.set(e.name, (byName.get(e.name) ?? 0) + (e.dur ?? 0));
  const long = complete.filter((e) => e.name === 'RunTask' && (e.dur ?? 0) > 50_000);
  const inLong = new Map<string, number>();
  for (const task of long) {
    const end = task.ts + (task.dur ?? 0);
    for (const e of complete) {
      if (e.ts < task.ts || e === task) continue;
      if (e.ts >= end) break;
      inLong.set(e.name, (inLong.get(e.name) ?? 0) + (e.dur ?? 0));
    }
  }
  const top = (m: Map<string, number>, scale: number) =>
    Object.fromEntries(
      [...m.entries()]
        .sort((x, y) => y[1] - x[1])
        .slice(0, 14)
        .map(([name, us]) => [name, round(us / scale, 1)]),
    );
  return { msPerSecond: top(byName, ms), longTasks: long.length, inLongTasksMs: top(inLong, 1000) };
}

/** A main-thread task with over 30 ms of the thread's CPU: when, how long, and what it was made of. */
interface LongTask {
  /** Seconds since the trace started. */
  atS: number;
  wallMs: number;
  cpuMs: number;
  /** Its nested work by kind (trace event names: FunctionCall, MajorGC, Layout…), ms of wall time, the largest first. */
  kinds: Record<string, number>;
  /** The script functions it called (the trace's FunctionCall and timer/animation-frame/message events), ms. */
  calls: Record<string, number>;
  /** Stack samples in it by their top frame (self), ms: the functions (or "(garbage collector)", "(program)") it ran. */
  topFrames: Record<string, number>;
  /** The same samples by their top four frames (callee < caller < …), ms. */
  topStacks: Record<string, number>;
  /** Seconds since the bench last asked for a heap sample (a full collection forced through CDP), if it did. */
  sinceHeapSampleS?: number;
  /** The task is that forced collection: the bench's work, not the page's. */
  benchHeapSample?: true;
}

type TraceEvent = {
  name: string;
  ph: string;
  ts: number;
  dur?: number;
  tdur?: number;
  pid: number;
  tid: number;
  args?: {
    name?: string;
    data?: {
      functionName?: string;
      url?: string;
      lineNumber?: number;
      type?: string;
      message?: string;
    };
  };
};

/** Where a script frame is: function, file and line. */
const frameName = (f: { functionName?: string; url?: string; lineNumber?: number }) =>
  `${f.functionName || '(anonymous)'} ${(f.url ?? '').split('/').pop() ?? ''}:${(f.lineNumber ?? -1) + 1}`;

/** The pid of the renderer that runs the page and its decoder worker (Linux: its main thread's tid is the pid). */
function rendererPid(): number | null {
  for (const pid of descendants()) {
    try {
      if (!readFileSync(`/proc/${pid}/cmdline`, 'utf8').includes('--type=renderer')) continue;
      const tasks = readdirSync(`/proc/${pid}/task`);
      if (tasks.some((t) => readFileSync(`/proc/${pid}/task/${t}/comm`, 'utf8').startsWith('DedicatedWorker'))) return pid;
    } catch {
      // the process went away meanwhile
    }
  }
  return null;
}

/**
 * Records the main thread's tasks until the returned function is called, from a trace: each
 * task's wall time, as the `longtask` observer sees it, and the thread's own CPU time in it. A
 * task over 50 ms of wall time but under 50 ms of CPU is the thread waiting for a core
 * (descheduled on a loaded machine), not the page's work. A task that runs the full collection
 * the bench itself asks for through CDP to sample the heap (`bench:heap-sample` in the trace) is
 * counted apart: the page never does that, and the `longtask` observer does not see it.
 *
 * Each task with over 30 ms of the thread's CPU is described (`LongTask`): its nested trace
 * events by kind and the script functions it called, and, from a CPU profile of the main thread
 * over the whole run (sampled every ms) cut to the task's window, its samples by top frame and
 * by their top four frames. Only a few seconds of the trace's events are kept at a time.
 */
async function traceTasks(page: Page): Promise<
  () => Promise<{
    overWallMs50: number;
    overCpuMs50: number;
    maxCpuMs: number;
    maxWallMs: number;
    heapSampleTasksOverCpuMs50: number;
    over30CpuMs: LongTask[];
    dataLost?: boolean;
  }>
> {
  const cdp = await page.context().newCDPSession(page);
  const pid = rendererPid();
  /** Tasks with more of the thread's own CPU than this are described (the candidates for the page's own long tasks). */
  const DESCRIBE_CPU_US = 30_000;
  /** The main thread's events of the last few seconds (they come in chunks, roughly in time order). */
  let recent: TraceEvent[] = [];
  let latestUs = 0;
  let originUs = Number.NaN;
  const tasks: { ts: number; wallMs: number; cpuMs: number }[] = [];
  /** The main thread's major collections (start, end), µs. */
  const majorGCs: [number, number][] = [];
  const pending: TraceEvent[] = [];
  const described: (LongTask & { fromUs: number; toUs: number })[] = [];
  const heapSamplesUs: number[] = [];
  /** A heap sample's forced collection starts within this of its mark. */
  const HEAP_SAMPLE_US = 0.5e6;
  const afterHeapSample = (ts: number) => {
    const before = heapSamplesUs.filter((t) => t <= ts).at(-1);
    return before === undefined ? undefined : ts - before;
  };
  const ms = (m: Map<string, number>) =>
    Object.fromEntries(
      [...m.entries()]
        .sort((x, y) => y[1] - x[1])
        .slice(0, 10)
        .map(([k, us]) => [k, round(us / 1000, 1)]),
    );
  const describe = (task: TraceEvent) => {
    const end = task.ts + (task.dur ?? 0);
    const kinds = new Map<string, number>();
    const calls = new Map<string, number>();
    for (const e of recent) {
      if (e === task || e.ts < task.ts || e.ts >= end) continue;
      kinds.set(e.name, (kinds.get(e.name) ?? 0) + (e.dur ?? 0));
      const d = e.args?.data;
      if (e.name === 'FunctionCall' && d !== undefined) calls.set(frameName(d), (calls.get(frameName(d)) ?? 0) + (e.dur ?? 0));
      else if ((e.name === 'EventDispatch' || e.name === 'TimerFire' || e.name === 'FireAnimationFrame') && d?.type !== undefined)
        calls.set(`${e.name} ${d.type}`, (calls.get(`${e.name} ${d.type}`) ?? 0) + (e.dur ?? 0));
    }
    const since = afterHeapSample(task.ts);
    described.push({
      atS: round((task.ts - originUs) / 1e6, 1),
      wallMs: round((task.dur ?? 0) / 1000),
      cpuMs: round((task.tdur ?? 0) / 1000),
      kinds: ms(kinds),
      calls: ms(calls),
      topFrames: {},
      topStacks: {},
      ...(since === undefined ? {} : { sinceHeapSampleS: round(since / 1e6, 2) }),
      fromUs: task.ts,
      toUs: end,
    });
  };
  const settle = (all: boolean) => {
    for (let i = pending.length - 1; i >= 0; i--) {
      const t = pending[i] as TraceEvent;
      if (all || latestUs > t.ts + (t.dur ?? 0) + 2e6) {
        describe(t);
        pending.splice(i, 1);
      }
    }
    // Keep 10 s of events (a task is described once the trace is 2 s past its end).
    const keepFrom = latestUs - 10e6;
    if (recent.length > 0 && (recent[0] as TraceEvent).ts < keepFrom - 10e6) recent = recent.filter((e) => e.ts >= keepFrom);
  };
  // Playwright types trace events as string maps; they are JSON objects with numbers.
  cdp.on('Tracing.dataCollected', (e) => {
    for (const x of e.value as unknown as TraceEvent[]) {
      if (x.pid !== pid || x.tid !== pid) continue;
      if (Number.isNaN(originUs) && x.ts > 0) originUs = x.ts;
      if (x.name === 'TimeStamp' && x.args?.data?.message === 'bench:heap-sample') heapSamplesUs.push(x.ts);
      if (x.ph !== 'X') continue;
      recent.push(x);
      latestUs = Math.max(latestUs, x.ts);
      if (x.name === 'MajorGC') majorGCs.push([x.ts, x.ts + (x.dur ?? 0)]);
      if (x.name === 'RunTask' && (x.dur ?? 0) > 20_000) {
        tasks.push({ ts: x.ts, wallMs: (x.dur ?? 0) / 1000, cpuMs: (x.tdur ?? 0) / 1000 });
        if ((x.tdur ?? 0) > DESCRIBE_CPU_US) pending.push(x);
      }
    }
    settle(false);
  });
  let dataLost = false;
  const done = new Promise<void>((resolve) =>
    cdp.once('Tracing.tracingComplete', (e: { dataLossOccurred?: boolean }) => {
      dataLost = e.dataLossOccurred === true;
      resolve();
    }),
  );
  await cdp.send('Profiler.enable');
  await cdp.send('Profiler.setSamplingInterval', { interval: 1000 });
  // Starting the profiler is a task of its own on the main thread (V8 lists every compiled
  // function: 30–50 ms of CPU, no script): over before the trace starts, so it is not counted.
  await cdp.send('Profiler.start');
  await page.waitForTimeout(1000);
  // Read as it comes: a ring buffer that this reads faster than the page fills it (the default,
  // record until full, stopped after about 5 minutes of these categories with dataLossOccurred).
  await cdp.send('Tracing.start', {
    transferMode: 'ReportEvents',
    traceConfig: {
      recordMode: 'recordContinuously',
      traceBufferSizeInKb: 400_000,
      includedCategories: ['devtools.timeline', 'disabled-by-default-devtools.timeline'],
    },
  });
  return async () => {
    // The trace ends first: handing over the profile is a task of 100 ms or more of its own.
    await cdp.send('Tracing.end');
    await done;
    const { profile } = (await cdp.send('Profiler.stop')) as {
      profile: { nodes: ProfileNode[]; samples: number[]; timeDeltas: number[]; startTime: number };
    };
    await cdp.detach();
    settle(true);
    // The profile's clock is the trace's (both are the browser's monotonic µs).
    const nodes = new Map(profile.nodes.map((n) => [n.id, n]));
    const parents = new Map<number, number>();
    for (const n of profile.nodes) for (const c of n.children ?? []) parents.set(c, n.id);
    let t = profile.startTime;
    const times = profile.timeDeltas.map((d) => {
      t += d;
      return t;
    });
    for (const task of described) {
      const top = new Map<string, number>();
      const stacks = new Map<string, number>();
      let last = task.fromUs;
      profile.samples.forEach((id, i) => {
        const at = times[i] ?? 0;
        if (at < task.fromUs || at >= task.toUs) return;
        const n = nodes.get(id);
        const key = n === undefined ? '(unknown)' : frameName(n.callFrame);
        const chain: string[] = [];
        for (
          let f = n;
          f !== undefined && chain.length < 4 && f.callFrame.functionName !== '(root)';
          f = nodes.get(parents.get(f.id) ?? -1)
        )
          chain.push(frameName(f.callFrame));
        top.set(key, (top.get(key) ?? 0) + (at - last));
        const stack = chain.join(' < ') || key;
        stacks.set(stack, (stacks.get(stack) ?? 0) + (at - last));
        last = at;
      });
      task.topFrames = ms(top);
      task.topStacks = ms(stacks);
    }
    // The bench's own: a task just after a heap-sample mark that is mostly a major collection.
    const heapSample = (x: { ts: number; wallMs: number }) => {
      const since = afterHeapSample(x.ts);
      const gc = majorGCs.filter(([a, b]) => a >= x.ts && b <= x.ts + x.wallMs * 1000).reduce((n, [a, b]) => n + b - a, 0);
      return since !== undefined && since < HEAP_SAMPLE_US && gc > (x.wallMs * 1000) / 2;
    };
    for (const d of described) if (heapSample({ ts: d.fromUs, wallMs: d.wallMs })) d.benchHeapSample = true;
    const page = tasks.filter((x) => !heapSample(x));
    return {
      overWallMs50: page.filter((x) => x.wallMs > 50).length,
      overCpuMs50: page.filter((x) => x.cpuMs > 50).length,
      maxCpuMs: round(Math.max(0, ...page.map((x) => x.cpuMs))),
      maxWallMs: round(Math.max(0, ...page.map((x) => x.wallMs))),
      heapSampleTasksOverCpuMs50: tasks.filter((x) => heapSample(x) && x.cpuMs > 50).length,
      over30CpuMs: described.sort((a, b) => a.atS - b.atS).map(({ fromUs, toUs, ...d }) => d),
      ...(dataLost ? { dataLost } : {}),
    };
  };
}

/** Samples the page's main thread for `ms` (BENCH_PROFILE=1): the functions that took the most time. */
async function profilePage(page: Page, ms: number): Promise<string[]> {
  const cdp = await page.context().newCDPSession(page);
  await cdp.send('Profiler.enable');
  await cdp.send('Profiler.setSamplingInterval', { interval: 1000 });
  await cdp.send('Profiler.start');
  await page.waitForTimeout(ms);
  const { profile } = (await cdp.send('Profiler.stop')) as { profile: { nodes: ProfileNode[]; samples: number[]; timeDeltas: number[] } };
  await cdp.detach();
  return topSelf(profile);
}

it(
  'measures the page',
  async () => {
    const skip = browserUnavailable();
    if (skip !== null) {
      console.warn(`page benchmark skipped: ${skip}`);
      return;
    }
    const results: Record<string, unknown> = { loadBefore: load() };
    // BENCH_APP_DIR: another build of the page (e.g. main's), to compare in the same conditions.
    const appDir = process.env.BENCH_APP_DIR ?? APP_DIR;
    results.appDir = appDir;
    const server = await startStaticServer(appDir);
    const tmp = mkdtempSync(join(tmpdir(), 'satscope-bench-'));
    const serialSkip = fakeSerialUnsupportedReason();
    const wantsSerial = ONLY.includes('serial') || ONLY.includes('record');
    // The policy goes in before the browser starts; the pty (one device, shared with other
    // runs' browser tests under a lock) is held only while a section feeds it.
    const policy = serialSkip === null && wantsSerial ? await installSerialPolicy(server.origin) : null;
    let fake: FakeSerialPort | null = null;
    const withPty = async (run: (port: FakeSerialPort) => Promise<void>) => {
      fake = await openFakeSerialPort();
      try {
        await run(fake);
      } finally {
        await fake.close();
        fake = null;
      }
    };
    const browser = await launchChromium({ args: ['--enable-precise-memory-info'] });
    const newPage = async () => {
      const page = await browser.newPage({ viewport: { width: 1400, height: 1000 } });
      await observeLongTasks(page);
      return page;
    };
    try {
      // A receiver on the serial stack at real pace, recording the whole time.
      if (ONLY.includes('serial')) {
        if (serialSkip === null) {
          await withPty(async (fake) => {
            const page = await newPage();
            await page.goto(server.url('/?bench'));
            await page.getByRole('button', { name: 'Serial port' }).click();
            await page.getByTestId('source-status').filter({ hasText: 'at 115200 baud' }).waitFor();
            const sim = new Simulator({ ...preset('dsmx-11ms-2048-internal'), seed: 5 });
            const stream = sim.generate(sim.scenario.timing.startUs + SECONDS * 1e6 + 2e6);
            await page.getByRole('button', { name: '● Record' }).click();
            const heapBefore = await heapMB(page);
            await collect(page);
            const cpu0 = threadTimes();
            const t0 = performance.now();
            await fake.writePaced(stream.bytes, stream.timesUs);
            const cpu = cpuShare(cpu0, threadTimes(), (performance.now() - t0) / 1000);
            const serial = summarize('serial (pty, real WebSerial), recording', SECONDS, await collect(page));
            const heapAfter = await heapMB(page);
            await page.getByRole('button', { name: 'Stop recording' }).click();
            results.serial = {
              ...serial,
              ...cpu,
              heapMBBefore: round(heapBefore, 2),
              heapMBAfter: round(heapAfter, 2),
              heapGrowthMB: round(heapAfter - heapBefore, 2),
              load: load(),
            };
            await page.close();
          });
        } else {
          results.serial = `skipped: ${serialSkip}`;
        }
      }

      // The demo source.
      if (ONLY.includes('demo')) {
        const page = await newPage();
        await page.goto(server.url('/?bench'));
        // With a port granted (the serial policy), the page waits to be told to start the demo.
        if (policy !== null) await page.getByRole('button', { name: 'Demo', exact: true }).click();
        await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
        await collect(page);
        const cpu0 = threadTimes();
        await page.waitForTimeout(SECONDS * 1000);
        results.demo = {
          ...summarize('demo (simulator in the worker)', SECONDS, await collect(page)),
          ...cpuShare(cpu0, threadTimes(), SECONDS),
          load: load(),
        };
        await page.close();
      }

      // Four remotes at 11 ms: a four-port capture replayed at 1×, which reaches the page
      // exactly as four live ports do (the worker decodes each port and sends the same batches).
      if (ONLY.includes('four')) {
        const file = join(tmp, 'four.sscap');
        const size = multiPortCapture(file, fourRemotes(), FOUR_SECONDS + 10);
        const page = await newPage();
        await page.goto(server.url('/?bench&demo=0'));
        await page.setInputFiles('input[type=file]', file);
        await page.getByTestId('remote-L').waitFor({ timeout: 30_000 });
        await page.getByTestId('link-state').filter({ hasText: 'Live' }).waitFor({ timeout: 10_000 });
        const worker = await WorkerTarget.attach(browser);
        const heapBefore = await pageHeap(page);
        const workerBefore = await worker?.heapMB();
        // The trace first: starting its profiler is a long task the page did not make.
        const stopTasks = await traceTasks(page);
        await collect(page);
        const cpu0 = threadTimes();
        const samples: { s: number; pageMB: number }[] = [];
        const t0 = performance.now();
        for (let s = 60; s < FOUR_SECONDS; s += 60) {
          await page.waitForTimeout(Math.max(0, t0 + s * 1000 - performance.now()));
          // Marked in the trace: the sample forces a full GC on the page's main thread.
          await page.evaluate(() => console.timeStamp('bench:heap-sample'));
          samples.push({ s, pageMB: (await pageHeap(page)).used });
        }
        await page.waitForTimeout(Math.max(0, t0 + FOUR_SECONDS * 1000 - performance.now()));
        const seconds = (performance.now() - t0) / 1000;
        const cpu = cpuShare(cpu0, threadTimes(), seconds);
        const m = summarize('four remotes at 11 ms (four-port capture at 1×)', round(seconds, 0), await collect(page));
        const tasks = await stopTasks();
        const heapAfter = await pageHeap(page);
        // After the measured window: sampling slows the page.
        const profile = process.env.BENCH_PROFILE ? await profilePage(page, 20_000) : undefined;
        const trace = process.env.BENCH_PROFILE ? await traceMainThread(page, 10_000) : undefined;
        results.fourRemotes = {
          ...m,
          longTasksByTrace: tasks,
          ...cpu,
          fileMB: round(size / (1 << 20), 2),
          pageHeapMBBefore: heapBefore.used,
          pageHeapMBAfter: heapAfter.used,
          pageHeapGrowthMB: round(heapAfter.used - heapBefore.used, 2),
          pageHeapMBEveryMinute: samples.map((x) => x.pageMB),
          workerHeapMBBefore: workerBefore?.used,
          workerHeapMBAfter: (await worker?.heapMB())?.used,
          load: load(),
          ...(profile === undefined ? {} : { mainThreadSelfTime: profile, mainThreadMsPerSecond: trace }),
        };
        await worker?.detach();
        await page.close();
      }

      // An 8-hour recording fed through the pty faster than real time: the page heap must not
      // grow with the recording's length. Sampled every recorded hour.
      if (ONLY.includes('record')) {
        if (serialSkip === null) {
          await withPty(async (fake) => {
            const page = await newPage();
            await page.goto(server.url('/?bench'));
            await page.getByRole('button', { name: 'Serial port' }).click();
            await page.getByTestId('source-status').filter({ hasText: 'at 115200 baud' }).waitFor();
            await page.getByRole('button', { name: '● Record' }).click();
            const worker = await WorkerTarget.attach(browser);
            const sim = new Simulator({ ...preset('dsmx-11ms-2048-internal'), seed: 7, fades: { lossRate: 0.002 } });
            const origin = sim.scenario.timing.startUs;
            const hours: { hour: number; pageMB: number; workerMB: number | undefined; wallS: number; buckets: number }[] = [];
            // The graph buckets the page holds: they grow with wall time (the arrival clock), up to 12.5 minutes' worth.
            const buckets = () =>
              page.evaluate(() => [...(window.__satscopeBench?.lives().values() ?? [])].reduce((n, l) => n + l.series.length, 0));
            const first = await pageHeap(page);
            hours.push({ hour: 0, pageMB: first.used, workerMB: (await worker?.heapMB())?.used, wallS: 0, buckets: await buckets() });
            const cpu0 = threadTimes();
            const t0 = performance.now();
            const BLOCK_US = 600e6;
            let lateMaxUs = 0;
            let sent = 0;
            for (let until = origin + BLOCK_US; until <= origin + RECORD_HOURS * 3600e6 + 1; until += BLOCK_US) {
              const { bytes, timesUs } = sim.generate(until);
              const fast = new Float64Array(timesUs.length);
              for (let i = 0; i < fast.length; i++) fast[i] = (timesUs[i] as number) / RECORD_SPEED;
              const r = await fake.writePaced(bytes, fast);
              lateMaxUs = Math.max(lateMaxUs, r.lateMaxUs);
              sent += bytes.length;
              const recorded = (until - origin) / 3600e6;
              if (Math.abs(recorded - Math.round(recorded)) < 1e-9) {
                const h = await pageHeap(page);
                hours.push({
                  hour: Math.round(recorded),
                  pageMB: h.used,
                  workerMB: (await worker?.heapMB())?.used,
                  wallS: round((performance.now() - t0) / 1000, 0),
                  buckets: await buckets(),
                });
              }
            }
            const seconds = (performance.now() - t0) / 1000;
            const cpu = cpuShare(cpu0, threadTimes(), seconds);
            const recordedText = await page.locator('.recorder').innerText();
            const m = summarize(`${RECORD_HOURS} h recording at ${RECORD_SPEED}× real time (pty)`, round(seconds, 0), await collect(page));
            await page.getByRole('button', { name: 'Stop recording' }).click();
            const pages = hours.map((h) => h.pageMB);
            results.recording = {
              source: m.source,
              wallSeconds: m.seconds,
              bytesSent: sent,
              recorderShows: recordedText.replace(/\s+/g, ' ').trim(),
              paceLateMaxMs: round(lateMaxUs / 1000),
              longTasks: m.longTasks,
              longTaskMsMax: m.longTaskMsMax,
              ...cpu,
              pageHeapMBByHour: pages,
              pageHeapSpreadMB: round(Math.max(...pages) - Math.min(...pages), 2),
              workerHeapMBByHour: hours.map((h) => h.workerMB),
              wallSecondsByHour: hours.map((h) => h.wallS),
              graphBucketsByHour: hours.map((h) => h.buckets),
              load: load(),
            };
            await worker?.detach();
            await page.close();
          });
        } else {
          results.recording = `skipped: ${serialSkip}`;
        }
      }

      // Open and plot a 1-hour capture (USB-batched, as the recorder writes them).
      if (ONLY.includes('hour')) {
        const sim = new Simulator({ ...preset('dsmx-11ms-2048-internal'), seed: 6 });
        const hour = sim.generate(sim.scenario.timing.startUs + 3600e6);
        const file = join(tmp, 'hour.sscap');
        writeCapture(file, usbChunks(hour.bytes, hour.timesUs));
        const size = readFileSync(file).length;
        const times: number[] = [];
        const complete: number[] = [];
        const parts: { pageReadMs: number; workerMs: number; drawMs: number }[] = [];
        for (let run = 0; run < 3; run++) {
          const page = await newPage();
          await page.goto(server.url('/?demo=0'));
          const t = await openTimes(page, file, 30_000);
          times.push(t.ms);
          complete.push(t.completeMs);
          parts.push(t);
          await page.close();
        }
        results.openHourCapture = {
          fileMB: round(size / (1 << 20)),
          frames: sim.framesGenerated,
          msRuns: times,
          msMedian: pct(times, 50),
          completeMsRuns: complete,
          completeMsMedian: pct(complete, 50),
          load: load(),
        };
      }

      // The 24-hour capture: overview drawn, seeks, and what the page and the worker hold.
      if (ONLY.includes('day')) {
        if (existsSync(DAY_FILE)) {
          const size = statSync(DAY_FILE).size;
          // Opened DAY_RUNS times, each on a new page right after the baseline; the first seek
          // (to the middle) follows each open at once. The last page is left open (the day's
          // then seeks on, and its heap is read).
          type Open = Awaited<ReturnType<typeof openTimes>> & {
            baselineMs: number;
            cpuS: number;
            firstSeek: Awaited<ReturnType<typeof seekTime>>;
          };
          /** The page of the last open, and the renderer's threads before it. */
          const last: { page: Page | null; idle: ThreadTimes | null } = { page: null, idle: null };
          const openRuns = async (file: string): Promise<Open[]> => {
            const out: Open[] = [];
            for (let run = 0; run < DAY_RUNS; run++) {
              await last.page?.close();
              const page = await newPage();
              last.page = page;
              await page.goto(server.url('/?bench&demo=0'));
              const baselineMs = await twoCoreBaselineMs(browser);
              last.idle = threadTimes();
              const cpu0 = chromiumCpuSeconds();
              const open = await openTimes(page, file, 300_000);
              const cpuS = chromiumCpuSeconds() - cpu0;
              out.push({ ...open, baselineMs, cpuS, firstSeek: await seekTime(page, 0.5) });
              await page.waitForTimeout(500);
            }
            return out;
          };
          const spread = (xs: number[], digits = 0) => ({
            median: round(pct(xs, 50), digits),
            min: round(Math.min(...xs), digits),
            max: round(Math.max(...xs), digits),
          });
          // The cost with the capture's length: bench/day.mjs's 1-minute and 1-hour captures of
          // the same two remotes (read whole: under the 32 MB a split pass takes), then the day's.
          const growth: Record<string, unknown>[] = [];
          const perLength = (name: string, file: string, opens: Open[]) => {
            const mb = statSync(file).size / (1 << 20);
            const complete = opens.map((o) => o.completeMs);
            growth.push({
              capture: name,
              fileMB: round(mb, 2),
              openToCompleteOverviewMs: spread(complete),
              completeOverBaseline: spread(
                opens.map((o) => o.completeMs / o.baselineMs),
                2,
              ),
              msPerFileMB: round(pct(complete, 50) / mb, 1),
              chromiumCpuSecondsPerFileMB: round(
                pct(
                  opens.map((o) => o.cpuS),
                  50,
                ) / mb,
                3,
              ),
            });
          };
          for (const name of ['1m', '1h']) {
            const file = DAY_FILE.replace('-24h.', `-${name}.`);
            if (existsSync(file)) perLength(name, file, await openRuns(file));
          }
          const opens = await openRuns(DAY_FILE);
          perLength('24h', DAY_FILE, opens);
          const { page, idle } = last;
          if (page === null) throw new Error('BENCH_DAY_RUNS must be 1 or more');
          const open = opens.at(-1) as Open;
          const fractions = [0.5, 0.1, 0.9, 0.99, 0.01, 0.5];
          const seekParts: { ms: number; workerMs: number; pageMs: number }[] = [open.firstSeek];
          for (const f of fractions.slice(1)) {
            seekParts.push(await seekTime(page, f));
            await page.waitForTimeout(500);
          }
          const seeks = seekParts.map((x) => x.ms);
          const complete = opens.map((o) => o.completeMs);
          const firstSeeks = opens.map((o) => o.firstSeek.ms);
          const worker = await WorkerTarget.attach(browser);
          const pageH = await pageHeap(page);
          const workerH = await worker?.heapMB();
          const rss = threadTimes()?.rssMB ?? Number.NaN;
          const fileMB = size / (1 << 20);
          const held = pageH.used + pageH.buffers + (workerH?.used ?? Number.NaN) + (workerH?.buffers ?? Number.NaN);
          results.openDayCapture = {
            fileMB: round(fileMB),
            runs: DAY_RUNS,
            baselineMs: opens.map((o) => o.baselineMs),
            openToCompleteOverviewMs: complete,
            openToCompleteOverview: spread(complete),
            completeOverBaseline: spread(
              opens.map((o) => o.completeMs / o.baselineMs),
              2,
            ),
            chromiumCpuSecondsWhileOpening: spread(
              opens.map((o) => o.cpuS),
              2,
            ),
            openToOverviewMs: opens.map((o) => o.ms),
            openToOverviewWithDataMs: opens.map((o) => o.withDataMs),
            openToFramesCountedMs: opens.map((o) => o.countedMs),
            openPartsMs: opens.map((o) => ({ pageRead: o.pageReadMs, worker: o.workerMs, draw: o.drawMs })),
            firstSeekMs: firstSeeks,
            firstSeek: spread(firstSeeks),
            growth,
            seekFractions: fractions,
            seekMs: seeks,
            seekWorkerMs: seekParts.map((x) => x.workerMs),
            seekPageMs: seekParts.map((x) => x.pageMs),
            seekMsMedian: pct(seeks, 50),
            seekMsMax: Math.max(...seeks),
            pageHeapMB: pageH,
            workerHeapMB: workerH,
            heapOverFile: round(held / fileMB, 2),
            rendererRssMBBefore: round(idle?.rssMB ?? Number.NaN, 0),
            rendererRssMB: round(rss, 0),
            load: load(),
          };
          await worker?.detach();
          await page.close();
          // Opened once more, the worker's heap sampled this time (the figures above are not).
          const sampled = await newPage();
          await sampled.goto(server.url('/?bench&demo=0'));
          const allocated = await workerAllocatedMB(browser, () => openTimes(sampled, DAY_FILE, 300_000));
          await sampled.close();
          (results.openDayCapture as Record<string, unknown>).workerAllocatedMBWhileOpening = allocated;
        } else {
          results.openDayCapture = `skipped: ${DAY_FILE} is missing (node bench/day.mjs makes it)`;
        }
      }

      // The week (bench/day.mjs --only 7d --make-only, 3 GB): memory stays bounded, seeks stay quick.
      if (ONLY.includes('week')) {
        const file = DAY_FILE.replace('-24h.', '-7d.');
        if (existsSync(file)) {
          const page = await newPage();
          await page.goto(server.url('/?bench&demo=0'));
          const idle = threadTimes();
          // The renderer's resident memory sampled while the week opens: its peak is the figure.
          let peakRssMB = idle?.rssMB ?? Number.NaN;
          const sampler = setInterval(() => {
            const rss = threadTimes()?.rssMB ?? Number.NaN;
            if (rss > peakRssMB || Number.isNaN(peakRssMB)) peakRssMB = rss;
          }, 250);
          let open: Awaited<ReturnType<typeof openTimes>>;
          try {
            open = await openTimes(page, file, 900_000);
          } finally {
            clearInterval(sampler);
          }
          const fractions = [0.5, 0.1, 0.9, 0.99, 0.01, 0.5, 0.3, 0.7];
          const seeks: number[] = [];
          for (const f of fractions) {
            seeks.push((await seekTime(page, f)).ms);
            await page.waitForTimeout(500);
          }
          const worker = await WorkerTarget.attach(browser);
          const pageH = await pageHeap(page);
          const workerH = await worker?.heapMB();
          results.openWeekCapture = {
            fileMB: round(statSync(file).size / (1 << 20)),
            openToCompleteOverviewMs: round(open.completeMs, 0),
            openToOverviewMs: round(open.ms, 0),
            openToFramesCountedMs: round(open.countedMs, 0),
            seekFractions: fractions,
            seekMs: seeks.map((x) => round(x, 0)),
            seekMsMedian: round(pct(seeks, 50), 0),
            pageHeapMB: pageH,
            workerHeapMB: workerH,
            rendererRssMBBefore: round(idle?.rssMB ?? Number.NaN, 0),
            rendererRssMBPeakWhileOpening: round(peakRssMB, 0),
            rendererRssMBAfterSeeks: round(threadTimes()?.rssMB ?? Number.NaN, 0),
            load: load(),
          };
          await worker?.detach();
          await page.close();
        } else {
          results.openWeekCapture = `skipped: ${file} is missing (node bench/day.mjs --only 7d --make-only makes it)`;
        }
      }

      // What the browser downloads first.
      if (ONLY.includes('bundle')) {
        const assets = join(appDir, 'assets');
        const files = readdirSync(assets);
        const gz = (f: string) => gzipSync(readFileSync(join(assets, f)), { level: 9 }).length;
        const entry = files.filter((f) => f.startsWith('index-') && f.endsWith('.js'));
        const worker = files.filter((f) => f.startsWith('worker-'));
        results.bundle = {
          initialJsGzipKB: round(entry.reduce((n, f) => n + gz(f), 0) / 1024),
          workerJsGzipKB: round(worker.reduce((n, f) => n + gz(f), 0) / 1024),
          cssGzipKB: round(files.filter((f) => f.endsWith('.css')).reduce((n, f) => n + gz(f), 0) / 1024),
        };
      }
    } finally {
      await browser.close();
      await (fake as FakeSerialPort | null)?.close();
      await policy?.remove();
      await server.close();
      rmSync(tmp, { recursive: true, force: true });
    }
    results.loadAfter = load();
    // Printed first: a file that cannot be written loses no figure. BENCH_OUT may be a path of its own.
    console.log(JSON.stringify(results, null, 2));
    const out = resolve(ROOT, 'bench-results', process.env.BENCH_OUT ?? 'page.json');
    mkdirSync(dirname(out), { recursive: true });
    writeFileSync(out, `${JSON.stringify(results, null, 2)}\n`);
  },
  120 * 60_000,
);
