/**
 * The worker: owns the serial port, the decoder, the recorder and replay. The page sends
 * commands (protocol.ts) and gets batches at display rate. One source at a time feeds the
 * engine: a serial port, the demo, or a capture being replayed.
 */
/// <reference lib="webworker" />
import { CaptureFormatError, decodeCapture, readCapture, type Capture, type FormatInfo } from '../decoder/index.js';
import { Engine } from './engine.js';
import type { FromWorker, Overview, PortIdentity, SourceKind, ToWorker } from './protocol.js';
import { Recorder } from './recorder.js';
import { DemoSource } from './sources/demo.js';
import { ReplaySource } from './sources/replay.js';
import { SerialSource, describePort, findPort, openProblem } from './sources/serial.js';

const scope = self as unknown as DedicatedWorkerGlobalScope;
/** Batches at most this often: about one per display frame. */
const MIN_BATCH_MS = 8;
/** While a live source is quiet, still tick this often so hold/failsafe and ages advance. */
const IDLE_TICK_MS = 50;
/** USB adapters deliver in batches up to their latency timer (FTDI: 16 ms). */
const USB_JITTER_US = 20_000;

function post(message: FromWorker, transfer: Transferable[] = []): void {
  scope.postMessage(message, transfer);
}

const nowUs = (): number => performance.now() * 1000;

let resolution: 'auto' | 1024 | 2048 = 'auto';
let engine = new Engine({ resolution, jitterUs: USB_JITTER_US });
let kind: SourceKind = 'none';
let state = 'idle';
let label = 'No receiver';
let lastFormat = '';
let lastBatchMs = 0;
let flushTimer: ReturnType<typeof setTimeout> | undefined;
let idleTimer: ReturnType<typeof setInterval> | undefined;
let demo: DemoSource | undefined;
let replay: ReplaySource | undefined;
let serialIdentity: PortIdentity | undefined;
const serial = new SerialSource(nowUs, {
  data: (bytes, timeUs) => onLiveData(bytes, timeUs),
  lineError: (name) => notice('warning', 'Line error survived', `${name}: some bytes may be lost; reading goes on.`),
  lost: () => {
    recorder.event('device lost', nowUs());
    setStatus('serial', 'lost', `${label.replace(/ at 115200 baud$/, '')}: device lost`);
    startReconnecting();
    notice('error', 'The receiver\'s adapter was unplugged', 'Reading stopped; everything recorded so far is kept. Plug it back in and it reconnects by itself.');
  },
  closed: () => undefined,
});
const recorder = new Recorder((recording) => post({ type: 'recording', recording }));

function notice(level: 'info' | 'warning' | 'error', title: string, detail: string): void {
  post({ type: 'notice', level, title, detail });
}

function sourceClock(): number {
  if (kind === 'replay' && replay !== undefined) return replay.positionUs;
  return nowUs();
}

function setStatus(k: SourceKind, s: string, l: string): void {
  kind = k;
  state = s;
  label = l;
  sendStatus(engine.decoder.format);
}

function sendStatus(format: FormatInfo): void {
  const clockRate = kind === 'replay' ? (replay?.playing === true ? replay.speed || 1 : 0) : kind === 'none' ? 0 : 1;
  lastFormat = JSON.stringify(format);
  post({ type: 'status', status: { kind, state, label, clockRate, format } });
}

/** Sends what changed, at most every MIN_BATCH_MS. */
function flush(): void {
  flushTimer = undefined;
  lastBatchMs = performance.now();
  const out = engine.batch(sourceClock());
  if (out !== null) post({ type: 'batch', batch: out.batch }, out.transfer);
  const format = engine.decoder.format;
  if (JSON.stringify(format) !== lastFormat) sendStatus(format);
}

function scheduleFlush(): void {
  if (flushTimer !== undefined) return;
  const wait = MIN_BATCH_MS - (performance.now() - lastBatchMs);
  if (wait <= 0) flush();
  else flushTimer = setTimeout(flush, wait);
}

function onLiveData(bytes: Uint8Array, timeUs: number): void {
  engine.push(bytes, timeUs, performance.timeOrigin + timeUs / 1000);
  recorder.data(bytes, timeUs);
  scheduleFlush();
}

function startIdleTicks(): void {
  stopIdleTicks();
  idleTimer = setInterval(scheduleFlush, IDLE_TICK_MS);
}

function stopIdleTicks(): void {
  clearInterval(idleTimer);
  idleTimer = undefined;
}

/** Stops whatever source runs and starts a fresh decode. */
async function stopSource(): Promise<void> {
  stopIdleTicks();
  stopReconnecting();
  demo?.stop();
  demo = undefined;
  replay?.stop();
  replay = undefined;
  post({ type: 'replay', replay: null });
  await serial.close();
  serialIdentity = undefined;
  resetEngine(USB_JITTER_US);
  setStatus('none', 'idle', 'No receiver');
}

function resetEngine(jitterUs: number): void {
  clearTimeout(flushTimer);
  flushTimer = undefined;
  engine = new Engine({ resolution, jitterUs });
  post({ type: 'reset' });
}

async function openSerial(identity: PortIdentity): Promise<void> {
  await stopSource();
  const port = await findPort(identity);
  if (port === undefined) {
    notice('error', 'The port is not available', 'It may have been unplugged. Plug it in and connect again.');
    return;
  }
  setStatus('serial', 'opening', describePort(port));
  try {
    await serial.open(port);
  } catch (error) {
    const problem = openProblem(error);
    notice('error', problem.title, problem.detail);
    setStatus('none', 'idle', 'No receiver');
    return;
  }
  serialIdentity = identity;
  recorder.event('port opened', nowUs());
  setStatus('serial', 'reading', `${describePort(port)} at 115200 baud`);
  startIdleTicks();
}

function overviewOf(capture: Capture): Overview {
  const BIN_US = 1_000_000;
  const t: number[] = [];
  const fades: number[] = [];
  const frames: number[] = [];
  let first = NaN;
  const { link } = decodeCapture(capture, { resolution }, (f) => {
    if (!Number.isFinite(f.timeUs)) return;
    if (Number.isNaN(first)) first = Math.floor(f.timeUs / BIN_US) * BIN_US;
    const bin = Math.floor((f.timeUs - first) / BIN_US);
    while (t.length <= bin) {
      t.push(first + t.length * BIN_US);
      fades.push(0);
      frames.push(0);
    }
    fades[bin] = (fades[bin] as number) + f.fadesDelta;
    frames[bin] = (frames[bin] as number) + 1;
  });
  const period = link.stats.nominalPeriodUs;
  return {
    t: Float64Array.from(t),
    fadeRate: Float32Array.from(fades),
    lost: Float32Array.from(frames, (n) => (Number.isFinite(period) ? Math.max(0, Math.round(BIN_US / period - n)) : 0)),
    failsafe: link.episodes.filter((e) => e.kind === 'failsafe').map((e) => ({ startUs: e.startUs, endUs: e.endUs ?? e.startUs })),
  };
}

function replayStatus(): void {
  if (replay === undefined) return;
  const c = replay.capture;
  post({
    type: 'replay',
    replay: {
      name: c.meta.note !== undefined ? String(c.meta.note) : currentReplayName, kind: c.kind, timing: c.timing,
      startUs: replay.startUs, endUs: replay.endUs, positionUs: replay.positionUs, playing: replay.playing, speed: replay.speed,
      frames: engine.decoder.stats.frames, issues: c.issues.map((i) => i.message),
    },
  });
}

let currentReplayName = '';

async function openReplay(name: string, data: ArrayBuffer): Promise<void> {
  let capture: Capture;
  try {
    capture = readCapture(new Uint8Array(data), name);
  } catch (error) {
    const why = error instanceof CaptureFormatError ? error.message : String(error);
    notice('error', `Cannot open ${name}`, why);
    return;
  }
  await stopSource();
  currentReplayName = name;
  resetEngine(capture.timing === 'per-chunk' ? USB_JITTER_US : 0);
  if (capture.issues.length > 0) {
    notice('warning', `${name}: ${capture.issues.length} damaged part(s) skipped`, `${capture.issues[0]?.message ?? ''} Every intact record is kept.`);
  }
  const overview = overviewOf(capture);
  post({ type: 'overview', overview }, [overview.t.buffer, overview.fadeRate.buffer, overview.lost.buffer]);
  replay = new ReplaySource(
    capture,
    (bytes, time, atUs) => engine.push(bytes, time, performance.timeOrigin + performance.now()),
    () => {
      flush();
      replayStatus();
    },
    () => {
      engine.end();
      flush();
      setStatus('replay', 'ended', `${name} (end)`);
      replayStatus();
    },
  );
  setStatus('replay', 'playing', name);
  replay.play();
  sendStatus(engine.decoder.format);
  replayStatus();
}

async function handle(message: ToWorker): Promise<void> {
  switch (message.type) {
    case 'serial-open':
      await openSerial(message.port);
      break;
    case 'serial-close':
      await stopSource();
      break;
    case 'demo-start':
      await stopSource();
      demo = new DemoSource(nowUs, onLiveData);
      demo.start();
      setStatus('demo', 'reading', 'Demo receiver (simulated DSMX 11 ms)');
      startIdleTicks();
      break;
    case 'demo-stop':
      await stopSource();
      break;
    case 'record-start':
      if (kind !== 'serial' && kind !== 'demo') {
        notice('warning', 'Nothing to record', 'Connect a receiver (or start the demo) first.');
        break;
      }
      await recorder.start({ baudRate: 115200, source: kind, note: label, usbVendorId: serialIdentity?.usbVendorId, usbProductId: serialIdentity?.usbProductId }, new Date().toISOString());
      break;
    case 'record-stop':
      await recorder.stop();
      break;
    case 'export': {
      const result = await recorder.export(message.recording, message.what);
      if (typeof result === 'string') notice('warning', 'Nothing to export', result);
      else post({ type: 'export-ready', name: result.name, mime: 'application/octet-stream', data: result.data }, [result.data]);
      break;
    }
    case 'discard-recovered':
      await recorder.discardRecovered();
      break;
    case 'replay-open':
      await openReplay(message.name, message.data);
      break;
    case 'replay-play':
      if (replay !== undefined) {
        replay.play();
        setStatus('replay', 'playing', currentReplayName);
        replayStatus();
      }
      break;
    case 'replay-pause':
      if (replay !== undefined) {
        replay.pause();
        setStatus('replay', 'paused', currentReplayName);
        replayStatus();
      }
      break;
    case 'replay-speed':
      replay?.setSpeed(message.speed);
      sendStatus(engine.decoder.format);
      replayStatus();
      break;
    case 'replay-seek':
      if (replay !== undefined) {
        resetEngine(replay.capture.timing === 'per-chunk' ? USB_JITTER_US : 0);
        replay.seek(message.timeUs);
        replayStatus();
      }
      break;
    case 'set-resolution':
      resolution = message.resolution;
      resetEngine(kind === 'replay' ? 0 : USB_JITTER_US);
      if (replay !== undefined) replay.seek(replay.positionUs);
      break;
    default: {
      const never: never = message;
      throw new Error(`unknown message ${JSON.stringify(never)}`);
    }
  }
}

// A replugged adapter is picked up again without a new prompt: after a loss the worker tries
// the same port again every second (Chromium does not always fire 'connect', e.g. without udev,
// and a replugged adapter keeps its grant), and at once when 'connect' does fire.
const RECONNECT_MS = 1000;
let reconnectTimer: ReturnType<typeof setInterval> | undefined;
let reconnecting = false;

function startReconnecting(): void {
  stopReconnecting();
  reconnectTimer = setInterval(() => void reconnect(), RECONNECT_MS);
}

function stopReconnecting(): void {
  clearInterval(reconnectTimer);
  reconnectTimer = undefined;
}

async function reconnect(): Promise<void> {
  const identity = serialIdentity;
  if (reconnecting || identity === undefined || kind !== 'serial' || state !== 'lost') return;
  reconnecting = true;
  try {
    const port = await findPort(identity);
    if (port === undefined) return;
    await serial.open(port);
    stopReconnecting();
    recorder.event('device reconnected', nowUs());
    setStatus('serial', 'reading', `${describePort(port)} at 115200 baud`);
    notice('info', 'Reconnected', 'The adapter is back; reading again.');
  } catch {
    // Still gone: try again on the next tick.
  } finally {
    reconnecting = false;
  }
}

navigator.serial?.addEventListener('connect', () => void reconnect());

let queue: Promise<void> = Promise.resolve();
scope.addEventListener('message', (event: MessageEvent<ToWorker>) => {
  // Commands run one after another: opening a port while the last one closes would race.
  queue = queue.then(() => handle(event.data)).catch((error: unknown) => {
    notice('error', 'Something went wrong in the worker', String(error));
  });
});

void recorder.init();
setStatus('none', 'idle', 'No receiver');
