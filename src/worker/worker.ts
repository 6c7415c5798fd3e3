/**
 * The worker's entry: owns the serial ports, the decoders, the recorder and replay for the page
 * (protocol.ts: every message). It only receives: each message is queued and dispatched in
 * order (dispatcher.ts), with the browser's post and clock as the host.
 */
/// <reference lib="webworker" />
import { Dispatcher } from './dispatcher.js';
import { BROWSER_CLOCK } from './host.js';
import type { ToWorker } from './protocol.js';
import { READ_IN_WORKER } from './replay/slice-reader.js';

const scope = self as unknown as DedicatedWorkerGlobalScope;
const worker = new Dispatcher(
  {
    post: (message, transfer = []) => scope.postMessage(message, transfer),
    clock: BROWSER_CLOCK,
    timeOriginMs: performance.timeOrigin,
  },
  { readSlices: READ_IN_WORKER },
);

scope.addEventListener('message', (event: MessageEvent<ToWorker>) => worker.receive(event.data));
navigator.serial?.addEventListener('connect', () => worker.serial.connected());
void worker.recorder.init();
worker.registry.send();
