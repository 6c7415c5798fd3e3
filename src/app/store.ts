/**
 * Low-rate page state as signals (source status, recording, replay, notices), and the bridge to
 * the worker: one place sends commands and routes every message the worker posts.
 */
import { signal } from '@preact/signals';
import type { FromWorker, Overview, RecordingStatus, ReplayStatus, SourceStatus, ToWorker } from '../worker/protocol.js';
import { live } from './live.js';

export interface Notice {
  id: number;
  level: 'info' | 'warning' | 'error';
  title: string;
  detail: string;
}

export const status = signal<SourceStatus>({
  kind: 'none', state: 'idle', label: 'No receiver', clockRate: 0,
  format: { locked: false, resolution: null, resolutionReason: 'unknown', explanation: 'Not locked on to frames yet.', remote: null, system: null, headerMode: 'fades' },
});
export const recording = signal<RecordingStatus | null>(null);
export const replay = signal<ReplayStatus | null>(null);
export const overview = signal<Overview | null>(null);
export const notices = signal<Notice[]>([]);
/** Set once X-Plus channels have been seen, so the panel appears and stays. */
export const xplusSeen = signal(false);
export const resolutionOverride = signal<'auto' | 1024 | 2048>('auto');
/** The frame period the link runs at (11 or 22 ms, in µs), NaN until known. */
export const nominalPeriodUs = signal(NaN);
/** The failsafe state machine's state, for views that change only when it does. */
export const linkState = signal<'waiting' | 'live' | 'hold' | 'failsafe'>('waiting');

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

function download(name: string, mime: string, data: ArrayBuffer): void {
  const url = URL.createObjectURL(new Blob([data], { type: mime }));
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(url), 10_000);
}

function receive(message: FromWorker): void {
  switch (message.type) {
    case 'status':
      status.value = message.status;
      live.clockRate = message.status.clockRate;
      break;
    case 'batch':
      live.apply(message.batch);
      if (!Object.is(message.batch.link.nominalPeriodUs, nominalPeriodUs.value)) nominalPeriodUs.value = message.batch.link.nominalPeriodUs;
      if (message.batch.link.state !== linkState.value) linkState.value = message.batch.link.state;
      if (!xplusSeen.value) for (let id = 12; id < 20; id++) if (Number.isFinite(live.seenUs[id])) xplusSeen.value = true;
      break;
    case 'reset':
      live.reset();
      xplusSeen.value = false;
      nominalPeriodUs.value = NaN;
      linkState.value = 'waiting';
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
      overview.value = message.overview;
      break;
    default: {
      const never: never = message;
      throw new Error(`unknown message ${JSON.stringify(never)}`);
    }
  }
}

export function startWorker(): Worker {
  worker = new Worker(new URL('../worker/worker.ts', import.meta.url), { type: 'module', name: 'satscope' });
  worker.addEventListener('message', (event: MessageEvent<FromWorker>) => receive(event.data));
  worker.addEventListener('error', (event) => notify('error', 'The decoder worker failed', event.message || 'Reload the page.'));
  return worker;
}
