/**
 * The worker: owns the serial ports, the decoders, the recorder and replay. The page sends
 * commands (protocol.ts) and gets batches at display rate. Several sources can run side by side,
 * one per remote: serial ports (each opened on its own), the two-remote demo, or the ports of a
 * capture being replayed. A source's id is its port number in recordings.
 */
/// <reference lib="webworker" />
import { FRAME_PERIOD_11MS_US, FRAME_PERIOD_22MS_US, FRAME_SIZE, USB_CHUNK_JITTER_US, systemInfo } from '../decoder/index.js';
import { CaptureFormatError, capturePorts, readCapture, type Capture } from '../capture/index.js';
import { type LinkSeries, decodeCapture, resolutionKey, timingJitterUs } from '../analysis/index.js';
import { Engine } from './engine.js';
import { Diagnosis } from './diagnosis.js';
import { runBind } from './bind.js';
import {
  REMOTE_LABELS,
  type BindProgress,
  type FromWorker,
  type Overview,
  type PortIdentity,
  type SourceKind,
  type SourceStatus,
  type ToWorker,
} from './protocol.js';
import { Recorder } from './recorder.js';
import type { ReportReply, ReportRequest } from './report-worker.js';
import { DemoSource } from './sources/demo.js';
import { ReplaySource } from './sources/replay.js';
import { SerialSource, describePort, findPort, openProblem } from './sources/serial.js';

const scope = self as unknown as DedicatedWorkerGlobalScope;
/** Batches at most this often (a display frame is 16.7 ms at 60 Hz). */
const MIN_BATCH_MS = 8;
/** While live sources are quiet, still tick this often so hold/failsafe and ages advance. */
const IDLE_TICK_MS = 50;
/** After a device is lost, try its port again this often (Chromium does not always fire 'connect'). */
const RECONNECT_MS = 1000;

function post(message: FromWorker, transfer: Transferable[] = []): void {
  scope.postMessage(message, transfer);
}

function notice(level: 'info' | 'warning' | 'error', title: string, detail: string): void {
  post({ type: 'notice', level, title, detail });
}

const nowUs = (): number => performance.now() * 1000;

/** One remote being decoded. */
interface Source {
  id: number;
  kind: SourceKind;
  label: string;
  state: string;
  name: string;
  engine: Engine;
  serial?: SerialSource;
  identity?: PortIdentity;
  /** Signals to set whenever the port is (re)opened: the satellite's power after a bind. */
  signals?: SerialOutputSignals;
  /** The resolution the stream looked like when a forced one matched no frame, as last told. */
  toldMismatch?: 1024 | 2048 | null;
  /** The internal remote's resolution this (external) remote was given, and its counters then. */
  sharedKey?: 1024 | 2048;
  sharedAt?: { frames: number; discarded: number };
  /** A resolution that did not fit this remote's bytes: not given again. */
  refusedKey?: 1024 | 2048;
}

let resolution: 'auto' | 1024 | 2048 = 'auto';
const sources = new Map<number, Source>();
let lastSent = '';
let lastBatchMs = 0;
let flushTimer: ReturnType<typeof setTimeout> | undefined;
let idleTimer: ReturnType<typeof setInterval> | undefined;
let reconnectTimer: ReturnType<typeof setInterval> | undefined;
let demo: DemoSource | undefined;
let replay: ReplaySource | undefined;
let replayName = '';
/** The replayed file's bytes, for a report on it. */
let replayBytes: Uint8Array | null = null;
const recorder = new Recorder((recording) => post({ type: 'recording', recording }));
/** The doctor for the session: findings to the page (diagnosis.ts). */
const diagnosis = new Diagnosis(
  post,
  () => clockUs(),
  () => [...sources.values()].filter((s) => s.kind === 'serial' && s.state === 'reading').map((s) => s.id),
);

function freeId(): number {
  let id = 0;
  while (sources.has(id)) id++;
  return id;
}

function defaultLabel(id: number): string {
  return REMOTE_LABELS[id] ?? `R${id}`;
}

function addSource(kind: SourceKind, id: number, name: string, jitterUs: number): Source {
  const source: Source = { id, kind, label: defaultLabel(id), state: 'opening', name, engine: new Engine({ resolution, jitterUs }) };
  sources.set(id, source);
  diagnosis.attach(id, source.engine, source.label);
  post({ type: 'reset', source: id });
  return source;
}

function clockUs(): number {
  return replay !== undefined ? replay.positionUs : nowUs();
}

function clockRate(): number {
  if (replay !== undefined) return replay.playing ? replay.speed || 1 : 0;
  return sources.size > 0 ? 1 : 0;
}

/** Sends the list of sources when anything in it changed. */
function sendSources(): void {
  const list: SourceStatus[] = [...sources.values()].map((s) => ({
    id: s.id,
    label: s.label,
    kind: s.kind,
    state: s.state,
    name: s.name,
    clockRate: clockRate(),
    format: s.engine.decoder.format,
  }));
  const key = JSON.stringify(list);
  if (key === lastSent) return;
  lastSent = key;
  post({ type: 'sources', sources: list });
}

function setState(source: Source, state: string, name = source.name): void {
  source.state = state;
  source.name = name;
  sendSources();
}

/**
 * External remotes take their resolution from the internal remote when one is connected
 * (spec §8: "the internal remote provides the key for … all remotes").
 */
function shareResolution(): void {
  const key = resolutionKey([...sources.values()].map((s) => s.engine.decoder.format));
  for (const s of sources.values()) {
    const d = s.engine.decoder;
    if (d.format.remote === 'internal' || resolution !== 'auto' || (key !== undefined && s.refusedKey === key)) continue;
    if (s.sharedKey !== key) {
      s.engine.setResolution(key ?? 'auto', clockUs(), 'internal-remote');
      s.sharedKey = key;
      s.sharedAt = { frames: d.stats.frames, discarded: d.stats.discardedBytes };
    } else if (
      s.sharedAt !== undefined &&
      d.stats.frames === s.sharedAt.frames &&
      d.stats.discardedBytes - s.sharedAt.discarded > REFUSE_AFTER_BYTES
    ) {
      // Its bytes do not read at that resolution (a remote of another system?): its own reading wins.
      s.engine.setResolution('auto', clockUs());
      s.refusedKey = key;
      s.sharedKey = undefined;
      notice(
        'warning',
        `Remote ${s.label} does not read at the internal remote's resolution`,
        `Its frames only make sense at the other resolution; it is decoded on its own (${key ?? ''} did not fit). Are both remotes bound to the same transmitter?`,
      );
    }
  }
}

/**
 * Tells the user once when the resolution they forced matches no frame: the link counts
 * nothing meanwhile (no hold, failsafe or missed frame), and the page shows it as waiting.
 */
function tellMismatch(s: Source): void {
  const m = s.engine.mismatch;
  if (m === (s.toldMismatch ?? null)) return;
  s.toldMismatch = m;
  if (m === null || resolution === 'auto') return;
  notice(
    'warning',
    `Remote ${s.label}: forced ${resolution}: no frame matches; the stream looks like ${m}`,
    `Nothing is counted as missed while no frame decodes. Choose Auto or ${m} to decode it again.`,
  );
}

/** Bytes an external remote may discard at the internal remote's resolution before it is given up. */
const REFUSE_AFTER_BYTES = 512;

/** Sends what changed, at most every MIN_BATCH_MS. */
function flush(): void {
  flushTimer = undefined;
  lastBatchMs = performance.now();
  for (const s of sources.values()) {
    // Replay judges each link on the capture's clock, never past a byte still to come.
    const out = s.engine.batch(replay !== undefined ? replay.linkNowUs(s.id) : nowUs());
    if (out !== null) post({ type: 'batch', source: s.id, batch: out.batch }, out.transfer);
    tellMismatch(s);
  }
  shareResolution();
  sendSources();
  diagnosis.tick();
}

function scheduleFlush(): void {
  if (flushTimer !== undefined) return;
  const wait = MIN_BATCH_MS - (performance.now() - lastBatchMs);
  if (wait <= 0) flush();
  else flushTimer = setTimeout(flush, wait);
}

function onLiveData(source: Source, bytes: Uint8Array, timeUs: number): void {
  source.engine.push(bytes, timeUs, performance.timeOrigin + timeUs / 1000);
  recorder.data(bytes, timeUs, source.id);
  scheduleFlush();
}

function startTicks(): void {
  if (idleTimer === undefined) idleTimer = setInterval(scheduleFlush, IDLE_TICK_MS);
}

async function closeSource(id: number): Promise<void> {
  const s = sources.get(id);
  if (s === undefined) return;
  sources.delete(id);
  await s.serial?.close();
  diagnosis.remove(id);
  post({ type: 'reset', source: id });
  if (sources.size === 0) stopTimers();
  sendSources();
}

function stopTimers(): void {
  clearInterval(idleTimer);
  idleTimer = undefined;
  clearInterval(reconnectTimer);
  reconnectTimer = undefined;
  clearTimeout(flushTimer);
  flushTimer = undefined;
}

/** Stops every source: the demo, replay and all ports. */
async function closeAll(): Promise<void> {
  stopTimers();
  // A recording belongs to the sources it began with: it ends with them.
  await recorder.stop();
  demo?.stop();
  demo = undefined;
  replay?.stop();
  if (replay !== undefined) post({ type: 'replay', replay: null });
  replay = undefined;
  for (const s of sources.values()) await s.serial?.close();
  sources.clear();
  diagnosis.reset();
  post({ type: 'reset' });
  sendSources();
}

// ---- serial ---------------------------------------------------------------------------------

/** Whether two identities name the same adapter. */
function sameAdapter(a: PortIdentity | undefined, b: PortIdentity): boolean {
  if (a === undefined) return false;
  // USB IDs survive a replug (the place in getPorts() may not); without them, the place it is.
  if (a.usbVendorId !== undefined || b.usbVendorId !== undefined)
    return a.usbVendorId === b.usbVendorId && a.usbProductId === b.usbProductId;
  return a.index === b.index;
}

/**
 * Opens a granted port as a source (or again, for a source whose adapter was lost). `signals`
 * are set right after opening (after a bind: the line that powers the satellite), and kept for
 * later reconnects. Returns whether the port is being read.
 */
async function openSerial(identity: PortIdentity, signals?: SerialOutputSignals): Promise<boolean> {
  // Ports join each other, but not the demo or a replay.
  if (demo !== undefined || replay !== undefined) await closeAll();
  const port = await findPort(identity);
  if (port === undefined) {
    notice('error', 'The port is not available', 'It may have been unplugged. Plug it in and connect again.');
    return false;
  }
  for (const s of sources.values()) {
    if (s.serial?.port === port) {
      notice('info', 'Already connected', `${describePort(port)} is remote ${s.label}.`);
      return true;
    }
  }
  // A lost remote's adapter, connected by hand: that remote comes back (same label, same port
  // in the recording) instead of a second row.
  const lost = [...sources.values()].find((s) => s.state === 'lost' && sameAdapter(s.identity, identity));
  if (lost !== undefined) {
    if (signals !== undefined) lost.signals = signals;
    return reopen(lost, port);
  }
  const id = freeId();
  const source = addSource('serial', id, describePort(port), USB_CHUNK_JITTER_US);
  source.identity = identity;
  source.signals = signals;
  source.serial = new SerialSource(nowUs, {
    data: (bytes, timeUs) => onLiveData(source, bytes, timeUs),
    lineError: (name) => {
      // Recorded, so a recording keeps what the doctor judged the line by.
      recorder.event(`line error: ${name}`, nowUs(), id);
      diagnosis.lineError(id, name, nowUs());
      notice('warning', `Line error on ${source.label}`, `${name}: some bytes may be lost; reading goes on.`);
    },
    lost: () => {
      recorder.event('device lost', nowUs(), id);
      diagnosis.close(id);
      setState(source, 'lost');
      notice(
        'error',
        `Remote ${source.label}: the adapter was unplugged`,
        'Reading stopped; everything recorded so far is kept. Plug it back in and it reconnects by itself.',
      );
      if (reconnectTimer === undefined) reconnectTimer = setInterval(() => enqueue(reconnectLost), RECONNECT_MS);
    },
  });
  sendSources();
  try {
    await source.serial.open(port, signals);
  } catch (error) {
    sources.delete(id);
    post({ type: 'reset', source: id });
    sendSources();
    const problem = openProblem(error);
    notice('error', problem.title, problem.detail);
    return false;
  }
  recorder.event('port opened', nowUs(), id);
  diagnosis.open(id, nowUs());
  setState(source, 'reading', `${describePort(port)} at 115200 baud`);
  startTicks();
  return true;
}

/** Opens a lost source's adapter again; its decode, graphs and recording port carry on. */
async function reopen(s: Source, port: SerialPort): Promise<boolean> {
  try {
    await (s.serial as SerialSource).open(port, s.signals);
  } catch {
    return false;
  }
  // Closed while the port was opening: let it go again.
  if (sources.get(s.id) !== s) {
    await s.serial?.close();
    return false;
  }
  recorder.event('device reconnected', nowUs(), s.id);
  diagnosis.open(s.id, nowUs());
  setState(s, 'reading', `${describePort(port)} at 115200 baud`);
  notice('info', `Remote ${s.label} reconnected`, 'The adapter is back; reading again.');
  return true;
}

/** Tries the ports of lost sources again: a replugged adapter comes back without a prompt. */
async function reconnectLost(): Promise<void> {
  for (const s of [...sources.values()]) {
    if (s.state !== 'lost' || s.identity === undefined) continue;
    const port = await findPort(s.identity);
    if (port !== undefined && sources.get(s.id) === s && s.state === 'lost') await reopen(s, port);
  }
  if (![...sources.values()].some((s) => s.state === 'lost')) {
    clearInterval(reconnectTimer);
    reconnectTimer = undefined;
  }
}

navigator.serial?.addEventListener('connect', () => enqueue(reconnectLost));

// ---- bind -----------------------------------------------------------------------------------

async function bind(message: Extract<ToWorker, { type: 'bind' }>): Promise<void> {
  if (demo !== undefined || replay !== undefined) await closeAll();
  const port = await findPort(message.port);
  if (port === undefined) {
    notice('error', 'The port is not available', 'Plug the adapter in and choose it again.');
    return;
  }
  // The bind needs the port to itself: close it if it is being read (or was, before it was lost).
  for (const s of [...sources.values()]) if (s.serial?.port === port || sameAdapter(s.identity, message.port)) await closeSource(s.id);
  const report = (progress: BindProgress) => post({ type: 'bind', progress });
  let keepOn: SerialOutputSignals;
  try {
    keepOn = await runBind(port, message, report);
  } catch (error) {
    const problem = openProblem(error);
    report({ step: 'failed', text: `${problem.title}: ${problem.detail}`, atMs: 0, sincePowerOnMs: null });
    notice('error', `Bind failed: ${problem.title}`, problem.detail);
    return;
  }
  if (await openSerial(message.port, keepOn)) {
    report({
      step: 'live',
      text: 'reading at 115200: the satellite blinks until the transmitter binds, then frames appear',
      atMs: 0,
      sincePowerOnMs: null,
    });
  } else {
    report({
      step: 'failed',
      text: 'the pulses were sent, but the port could not be opened again at 115200',
      atMs: 0,
      sincePowerOnMs: null,
    });
  }
}

// ---- demo -----------------------------------------------------------------------------------

async function startDemo(): Promise<void> {
  await closeAll();
  const d = new DemoSource(nowUs, (remote, bytes, timeUs) => {
    const s = sources.get(remote);
    if (s !== undefined) onLiveData(s, bytes, timeUs);
  });
  for (let i = 0; i < d.remotes; i++) {
    const s = addSource('demo', i, i === 0 ? 'Demo remote (internal, DSMX 11 ms)' : 'Demo remote (external)', USB_CHUNK_JITTER_US);
    s.state = 'reading';
  }
  demo = d;
  d.start();
  startTicks();
  sendSources();
}

// ---- replay ---------------------------------------------------------------------------------

/**
 * Whole-capture series for the replay timeline, every port on one time axis in 1 s bins: the
 * library's binned link series (the report's), fades and lost frames summed over the ports,
 * and the failsafe episodes. Also the frame period to pace a capture without timing at.
 */
function overviewOf(capture: Capture, ports: readonly number[]): { overview: Overview; periodUs: number } {
  const BIN_US = 1_000_000;
  const all: LinkSeries[] = [];
  const failsafe: Overview['failsafe'] = [];
  let periodUs = NaN;
  // Without recorded timing, the fades and the receiver's missed frames go on the paced clock
  // replay plays at (a frame every period from the first byte): where in the file, not when.
  const untimed: { offset: number; fades: number; missed: number }[][] = [];
  for (const port of ports) {
    const marks: { offset: number; fades: number; missed: number }[] = [];
    let missed = 0;
    const { link, series, decoder } = decodeCapture(capture, { resolution, port, binUs: BIN_US }, (f, l) => {
      if (capture.timing === 'none') marks.push({ offset: f.offset, fades: l.lastFades, missed: l.stats.missedFrames - missed });
      missed = l.stats.missedFrames;
    });
    all.push(series);
    untimed.push(marks);
    for (const e of link.episodes) if (e.kind === 'failsafe') failsafe.push({ startUs: e.startUs, endUs: e.endUs ?? e.startUs });
    const info = decoder.format.system === null ? undefined : systemInfo(decoder.format.system);
    if (Number.isNaN(periodUs))
      periodUs = info
        ? info.periodMs === 11
          ? FRAME_PERIOD_11MS_US
          : FRAME_PERIOD_22MS_US
        : decoder.format.resolution === 1024
          ? FRAME_PERIOD_22MS_US
          : NaN;
  }
  if (Number.isNaN(periodUs)) periodUs = FRAME_PERIOD_11MS_US;
  if (capture.timing === 'none') {
    const usPerByte = periodUs / FRAME_SIZE;
    let bins = 0;
    for (const marks of untimed)
      for (const m of marks) bins = Math.max(bins, Math.floor(((m.offset + FRAME_SIZE) * usPerByte) / BIN_US) + 1);
    const t = Float64Array.from({ length: bins }, (_, b) => b * BIN_US);
    const fades = new Float32Array(bins);
    const lost = new Float32Array(bins);
    for (const marks of untimed) {
      for (const m of marks) {
        const b = Math.floor(((m.offset + FRAME_SIZE) * usPerByte) / BIN_US);
        fades[b] = (fades[b] as number) + m.fades;
        lost[b] = (lost[b] as number) + m.missed;
      }
    }
    return { overview: { t, fadeRate: fades, lost, failsafe: [] }, periodUs };
  }
  const bins = Math.max(0, ...all.map((x) => x.bins));
  const origin = all[0]?.originUs ?? NaN;
  const t = new Float64Array(Number.isNaN(origin) ? 0 : bins);
  const fades = new Float32Array(t.length);
  const lost = new Float32Array(t.length);
  for (let b = 0; b < t.length; b++) {
    t[b] = origin + b * BIN_US;
    for (const x of all) {
      fades[b] = (fades[b] as number) + x.fades(b);
      lost[b] = (lost[b] as number) + x.lost(b);
    }
  }
  return { overview: { t, fadeRate: fades, lost, failsafe }, periodUs };
}

const REPLAY_STATUS_MS = 200;
let lastReplayStatusMs = 0;

function replayStatus(): void {
  if (replay === undefined) return;
  lastReplayStatusMs = performance.now();
  const c = replay.capture;
  let frames = 0;
  for (const s of sources.values()) frames += s.engine.decoder.stats.frames;
  post({
    type: 'replay',
    replay: {
      name: replayName,
      kind: c.kind,
      timing: c.timing,
      startUs: replay.startUs,
      endUs: replay.endUs,
      positionUs: replay.positionUs,
      playing: replay.playing,
      speed: replay.speed,
      frames,
      issues: c.issues.map((i) => i.message),
      recordedTiming: replay.recordedTiming,
      ended: replay.ended,
    },
  });
}

/** Fresh decodes for every port of the replayed capture. */
function resetReplaySources(capture: Capture, ports: readonly number[]): void {
  sources.clear();
  diagnosis.replayReset(replay?.startUs ?? NaN);
  post({ type: 'reset' });
  for (const port of ports) {
    const s = addSource('replay', port, `${replayName}${ports.length > 1 ? ` port ${port}` : ''}`, timingJitterUs(capture.timing));
    // The label the remote had when it was recorded.
    const saved = capture.meta.ports?.[port]?.name;
    if (typeof saved === 'string' && saved !== '') s.label = saved;
    s.state = replay?.playing === false ? 'paused' : 'playing';
  }
}

async function openReplay(name: string, data: ArrayBuffer): Promise<void> {
  let capture: Capture;
  try {
    capture = readCapture(new Uint8Array(data), name);
  } catch (error) {
    const why = error instanceof CaptureFormatError ? error.message : String(error);
    notice('error', `Cannot open ${name}`, why);
    return;
  }
  await closeAll();
  replayName = name;
  replayBytes = new Uint8Array(data);
  if (capture.issues.length > 0) {
    notice(
      'warning',
      `${name}: ${capture.issues.length} damaged part(s) skipped`,
      `${capture.issues[0]?.message ?? ''} Every intact record is kept.`,
    );
  }
  const { overview, periodUs } = overviewOf(capture, capturePorts(capture));
  const r = new ReplaySource(
    capture,
    (port, bytes, time) => sources.get(port)?.engine.push(bytes, time, performance.timeOrigin + performance.now()),
    () => {
      flush();
      // The position moves every tick; the page needs it a few times a second.
      if (performance.now() - lastReplayStatusMs >= REPLAY_STATUS_MS) replayStatus();
    },
    () => {
      // The end: every link is judged at the capture's last recorded time, and stays so.
      for (const s of sources.values()) {
        s.engine.end(r.recordedTiming ? r.endUs : Number.NaN);
        s.state = 'ended';
      }
      flush();
      replayStatus();
    },
    { untimedPeriodUs: periodUs },
  );
  replay = r;
  diagnosis.replay(capture, r.startUs);
  post({ type: 'overview', overview }, [overview.t.buffer, overview.fadeRate.buffer, overview.lost.buffer]);
  if (!r.recordedTiming) {
    notice(
      'info',
      `${name}: no recorded timing`,
      `Replayed at the receiver's pace (a frame every ${periodUs / 1000} ms). Holds, failsafes, lost frames and the frame period cannot be measured without the recorded times.`,
    );
  }
  resetReplaySources(capture, r.ports);
  r.play();
  setReplayState('playing');
  replayStatus();
}

function setReplayState(state: string): void {
  for (const s of sources.values()) s.state = state;
  sendSources();
}

// ---- reports ------------------------------------------------------------------------------

/**
 * Builds a health report in a worker of its own: decoding a long capture takes a good part of a
 * second, and this worker must keep reading ports meanwhile (a stall shows as a gap in the
 * data and in the recording).
 */
function makeReport(bytes: Uint8Array, name: string, format: 'html' | 'json'): void {
  const helper = new Worker(new URL('./report-worker.ts', import.meta.url), { type: 'module', name: 'satscope-report' });
  const copy = bytes.slice();
  helper.addEventListener('message', (event: MessageEvent<ReportReply>) => {
    helper.terminate();
    const reply = event.data;
    if (reply.error !== undefined) {
      notice('error', 'The report could not be made', reply.error);
      return;
    }
    const base = (name.replace(/\.[^.]+$/, '') || 'satscope').replace(/[^\w.-]+/g, '-');
    post(
      {
        type: 'export-ready',
        name: `${base}.report.${format}`,
        mime: format === 'html' ? 'text/html' : 'application/json',
        data: reply.data,
      },
      [reply.data],
    );
  });
  const request: ReportRequest = { bytes: copy, name, format, resolution };
  helper.postMessage(request, [copy.buffer]);
}

// ---- commands -------------------------------------------------------------------------------

async function handle(message: ToWorker): Promise<void> {
  switch (message.type) {
    case 'serial-open':
      await openSerial(message.port);
      break;
    case 'serial-close':
      await closeSource(message.source);
      break;
    case 'close-all':
      await closeAll();
      break;
    case 'demo-start':
      await startDemo();
      break;
    case 'demo-stop':
      await closeAll();
      break;
    case 'bind':
      await bind(message);
      break;
    case 'set-label': {
      const s = sources.get(message.source);
      if (s !== undefined) {
        s.label = message.label.slice(0, 8);
        diagnosis.relabel(s.id, s.engine, s.label);
        sendSources();
      }
      break;
    }
    case 'record-start': {
      const live = [...sources.values()].filter((s) => s.kind === 'serial' || s.kind === 'demo');
      if (live.length === 0) {
        notice('warning', 'Nothing to record', 'Connect a receiver (or start the demo) first.');
        break;
      }
      const first = live[0]?.identity;
      // One entry per port number (= source id): the remote's label and its adapter.
      const ports = Array.from({ length: Math.max(...live.map((s) => s.id)) + 1 }, (_, id) => {
        const s = sources.get(id);
        return s === undefined
          ? {}
          : { name: s.label, baudRate: 115200, usbVendorId: s.identity?.usbVendorId, usbProductId: s.identity?.usbProductId };
      });
      await recorder.start(
        {
          baudRate: 115200,
          source: live[0]?.kind === 'demo' ? 'demo' : 'webserial',
          usbVendorId: first?.usbVendorId,
          usbProductId: first?.usbProductId,
          ports,
        },
        new Date().toISOString(),
      );
      break;
    }
    case 'record-stop':
      await recorder.stop();
      break;
    case 'export': {
      const result = await recorder.export(message.recording, message.what);
      if (typeof result === 'string') notice('warning', 'Nothing to export', result);
      else post({ type: 'export-ready', name: result.name, mime: 'application/octet-stream', data: result.data }, [result.data]);
      break;
    }
    case 'inspect': {
      const entries = sources.get(message.source)?.engine.inspector.snapshot(message.limit) ?? [];
      // All entries of a snapshot share one buffer: transfer it once.
      const buffer = entries.find((e) => e.bytes !== null)?.bytes?.buffer;
      post({ type: 'inspection', source: message.source, entries }, buffer instanceof ArrayBuffer ? [buffer] : []);
      break;
    }
    case 'report': {
      let bytes: Uint8Array | null = null;
      let name = replayName;
      if (replay !== undefined) {
        bytes = replayBytes;
      } else {
        bytes = await recorder.current();
        name = 'live session';
      }
      if (bytes === null) {
        notice(
          'warning',
          'Nothing to report on yet',
          'Record the live session (● Record) or open a capture; the report covers what was recorded.',
        );
        break;
      }
      makeReport(bytes, name, message.format);
      break;
    }
    case 'diagnosis-confirm': {
      const s = sources.get(message.source);
      if (s?.serial === undefined || s.state !== 'reading') {
        notice('warning', 'Cannot listen at another speed', 'Only a connected serial port can (not the demo or a replay).');
        break;
      }
      const problem = await diagnosis.confirm(s.id, s.serial, s.signals, message.probe, {
        nowUs,
        event: (text, t) => recorder.event(text, t, s.id),
        data: (bytes, t) => recorder.data(bytes, t, s.id),
        state: (state, name) =>
          setState(s, state, name === undefined ? s.name.replace(/ at .*$/, ' at 115200 baud') : s.name.replace(/ at .*$/, ` ${name}`)),
      });
      if (problem !== null) notice('warning', `Remote ${s.label}: could not listen at ${message.probe.baudRate} baud`, problem);
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
        // At the end, play starts over.
        if (replay.ended) {
          resetReplaySources(replay.capture, replay.ports);
          replay.seek(replay.startUs);
        }
        replay.play();
        setReplayState('playing');
        replayStatus();
      }
      break;
    case 'replay-pause':
      if (replay !== undefined) {
        replay.pause();
        setReplayState('paused');
        replayStatus();
      }
      break;
    case 'replay-speed':
      replay?.setSpeed(message.speed);
      sendSources();
      replayStatus();
      break;
    case 'replay-seek':
      if (replay !== undefined) {
        const state = replay.playing ? 'playing' : 'paused';
        resetReplaySources(replay.capture, replay.ports);
        replay.seek(message.timeUs);
        setReplayState(state);
        replayStatus();
      }
      break;
    case 'set-resolution':
      resolution = message.resolution;
      // The frames may stop while the decoder finds them at the new resolution: not link loss.
      for (const s of sources.values()) {
        s.engine.setResolution(resolution, replay !== undefined ? replay.linkNowUs(s.id) : clockUs());
        s.sharedKey = undefined;
      }
      scheduleFlush();
      break;
    default: {
      const never: never = message;
      throw new Error(`unknown message ${JSON.stringify(never)}`);
    }
  }
}

let queue: Promise<void> = Promise.resolve();

/**
 * Runs `task` after everything queued before it: commands and reconnects one after another,
 * since opening a port while another command closes it would race.
 */
function enqueue(task: () => Promise<void>): void {
  queue = queue.then(task).catch((error: unknown) => {
    notice('error', 'Something went wrong in the worker', String(error));
  });
}

scope.addEventListener('message', (event: MessageEvent<ToWorker>) => enqueue(() => handle(event.data)));

void recorder.init();
sendSources();
