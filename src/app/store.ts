/**
 * Low-rate page state as signals (sources, recording, replay, notices), the high-rate data of
 * each remote (one Live each), and the bridge to the worker: one place sends commands and
 * routes every message the worker posts. The views show the selected remote; the Remotes panel
 * shows them all.
 */
import { batch, computed, signal } from '@preact/signals';
import type { InspectEntry } from '../worker/inspector.js';
import type { BindProgress, FromWorker, Overview, RecordingStatus, ReplayStatus, SourceStatus, ToWorker } from '../worker/protocol.js';
import type { WindowEnd } from './axes.js';
import { onFrame, wake } from './frame-loop.js';
import { Live } from './live.js';
import type { DiagnosisStatus } from '../worker/protocol.js';
import type { DriveStatus } from '../worker/drive.js';
import type { FcStatus } from '../worker/fc.js';

export interface Notice {
  id: number;
  level: 'info' | 'warning' | 'error';
  title: string;
  detail: string;
}

export const sources = signal<SourceStatus[]>([]);
/** The remote the channel bars, link panel, system badge and graphs show. */
export const selected = signal(0);
export const recording = signal<RecordingStatus | null>(null);
export const replay = signal<ReplayStatus | null>(null);
export const overview = signal<Overview | null>(null);
/** The replayed capture's name (null: no replay), and its length, µs: they change per capture, not with every status. */
export const replayName = computed(() => replay.value?.name ?? null);
export const replaySpanUs = computed(() => (replay.value === null ? 0 : replay.value.endUs - replay.value.startUs));
/** The end of the graphs' window: now, or in a replay 0 s before its position (the replay bar's clock). */
export const windowEnd: WindowEnd = () => (replay.peek() === null ? 'now' : '0 s');
/** A capture's file is still being read: nothing plays, and there is no link state or finding yet (not a receiver waiting). */
export const replayReading = computed(() => replay.value?.reading === true);
export const notices = signal<Notice[]>([]);
export const resolutionOverride = signal<'auto' | 1024 | 2048>('auto');
/** The frame inspector's last snapshot of the selected remote (null: none asked for yet). */
export const inspection = signal<InspectEntry[] | null>(null);
/** The steps of the bind in progress (or the last one). */
export const bindLog = signal<BindProgress[]>([]);
/** The doctor's findings for the session or the replay position (null: none yet). */
export const diagnosis = signal<DiagnosisStatus | null>(null);
/** The drive under way, or the last one (null: none this session). */
export const drive = signal<DriveStatus | null>(null);
/** What the flight controller being driven says it read (null: its port not opened). */
export const fc = signal<FcStatus | null>(null);

const IDLE: SourceStatus = {
  id: -1,
  label: '',
  kind: 'serial',
  state: 'idle',
  name: 'No receiver',
  clockRate: 0,
  format: {
    locked: false,
    resolution: null,
    resolutionReason: 'unknown',
    explanation: 'Not locked on to frames yet.',
    remote: null,
    system: null,
    systemValid: false,
    headerMode: 'fades',
    forcedMismatch: null,
    withheld: null,
    remoteAmbiguous: false,
    alignmentUnproven: false,
  },
};

/** The selected remote's status (a placeholder when there is none). */
export const status = computed(() => sources.value.find((s) => s.id === selected.value) ?? IDLE);

/** Each remote's high-rate data, by source id. */
const lives = new Map<number, Live>();
const none = new Live();

export function liveOf(id: number): Live {
  let live = lives.get(id);
  if (live === undefined) {
    live = new Live();
    lives.set(id, live);
  }
  return live;
}

/** The selected remote's data, for the renderers (read once per animation frame). */
export function current(): Live {
  return lives.get(selected.value) ?? none;
}

// Values of the selected remote that change rarely, as signals for the views that show them.
/** The frame period the link runs at (11 or 22 ms, in µs), NaN until known. */
export const nominalPeriodUs = signal(NaN);
/** The failsafe state machine's state. */
export const linkState = signal<'waiting' | 'live' | 'hold' | 'failsafe'>('waiting');
/** Set once X-Plus channels have been seen, so the panel appears and stays. */
export const xplusSeen = signal(false);
/** The selected source has ended (a replay at its end): `linkState` is its last state, frozen. */
export const linkEnded = signal(false);
/** While a forced resolution matches no frame: the resolution the stream looks like. */
export const linkMismatch = signal<1024 | 2048 | null>(null);

function refreshSelected(): void {
  const live = current();
  const l = live.link;
  let x = false;
  for (let id = 12; id < 20; id++) if (!Number.isNaN(live.seenUs[id] ?? Number.NaN)) x = true;
  const period = l?.nominalPeriodUs ?? Number.NaN;
  // One update for the views, however many of these changed (a signal skips a value equal by
  // ===, which NaN never is).
  batch(() => {
    if (!Object.is(period, nominalPeriodUs.value)) nominalPeriodUs.value = period;
    linkState.value = l?.state ?? 'waiting';
    linkEnded.value = live.ended || status.value.state === 'ended';
    linkMismatch.value = live.mismatch;
    xplusSeen.value = x;
  });
}

/**
 * The worker's news reaches the link state at the next animation frame, with the counters,
 * bars and graphs that draw from the same batch there: the page never says "Replay ended" (or
 * Hold, or Live) beside figures one batch old.
 */
let refreshDue = false;
function refreshOnFrame(): void {
  refreshDue = true;
}
onFrame(() => {
  if (!refreshDue) return;
  refreshDue = false;
  refreshSelected();
});

export function select(id: number): void {
  batch(() => {
    if (id !== selected.value) inspection.value = null;
    selected.value = id;
    refreshSelected();
  });
}

let nextNotice = 1;
export function notify(level: Notice['level'], title: string, detail: string): void {
  // The same message again replaces the old one instead of stacking up.
  const rest = notices.value.filter((n) => n.title !== title);
  notices.value = [...rest.slice(-4), { id: nextNotice++, level, title, detail }];
}

export function dismiss(id: number): void {
  notices.value = notices.value.filter((n) => n.id !== id);
}

let worker: Worker | undefined;

export function send(message: ToWorker, transfer: Transferable[] = []): void {
  worker?.postMessage(message, transfer);
}

/** Saves `data` as a file the browser downloads. */
export function download(name: string, mime: string, data: ArrayBuffer): void {
  const url = URL.createObjectURL(new Blob([data], { type: mime }));
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

function receive(message: FromWorker): void {
  switch (message.type) {
    case 'sources': {
      sources.value = message.sources;
      refreshOnFrame();
      for (const s of message.sources) liveOf(s.id).clockRate = s.clockRate;
      for (const id of lives.keys()) if (!message.sources.some((s) => s.id === id)) lives.delete(id);
      // Keep the selection on a remote that exists, preferring the internal one.
      if (!message.sources.some((s) => s.id === selected.value) && message.sources.length > 0) {
        const internal = message.sources.find((s) => s.format.remote === 'internal');
        const pick = internal ?? message.sources[0];
        if (pick !== undefined) select(pick.id);
      }
      break;
    }
    case 'batches':
      for (const { source, batch } of message.batches) {
        liveOf(source).apply(batch);
        if (source === selected.value) refreshOnFrame();
      }
      break;
    case 'reset':
      if (message.source === undefined) lives.clear();
      else lives.get(message.source)?.reset();
      // Source ids are reused: what the inspector shows belonged to the old source.
      if (message.source === undefined || message.source === selected.value) inspection.value = null;
      refreshSelected();
      break;
    case 'notice':
      notify(message.level, message.title, message.detail);
      break;
    case 'recording':
      recording.value = message.recording;
      break;
    case 'export-ready':
      download(message.name, message.mime, message.data);
      break;
    case 'replay':
      replay.value = message.replay;
      if (message.replay === null) overview.value = null;
      break;
    case 'overview':
      // The first (maybe partial) overview, and the complete one.
      if (overview.peek() === null) performance.mark('satscope:overview-received');
      if (message.overview.complete) performance.mark('satscope:overview-complete');
      overview.value = message.overview;
      break;
    case 'inspection':
      if (message.source === selected.value) inspection.value = message.entries;
      break;
    case 'bind':
      bindLog.value = message.progress.step === 'open' ? [message.progress] : [...bindLog.value, message.progress];
      break;
    case 'diagnosis':
      diagnosis.value = message.diagnosis;
      break;
    case 'drive':
      drive.value = message.drive;
      break;
    case 'fc':
      fc.value = message.fc;
      break;
    default: {
      const never: never = message;
      throw new Error(`unknown message ${JSON.stringify(never)}`);
    }
  }
}

/** Every remote's data, for the views that show them side by side. */
export function allLives(): ReadonlyMap<number, Live> {
  return lives;
}

/** The worker's messages that change what the frame loop's views draw (their remotes' data). */
const FRAME_NEWS: ReadonlySet<FromWorker['type']> = new Set(['sources', 'batches', 'reset']);

export function startWorker(): Worker {
  worker = new Worker(new URL('../worker/worker.ts', import.meta.url), { type: 'module', name: 'satscope' });
  // A message's updates (sources and the selection, a replay and its overview…) reach the views as one.
  worker.addEventListener('message', (event: MessageEvent<FromWorker>) => {
    // What the frame loop draws changed: it draws every frame again (replay's status and
    // overview, notices and findings are drawn by their components, not by the loop).
    if (FRAME_NEWS.has(event.data.type)) wake();
    batch(() => receive(event.data));
  });
  worker.addEventListener('error', (event) => notify('error', 'The decoder worker failed', event.message || 'Reload the page.'));
  return worker;
}
