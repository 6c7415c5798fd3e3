/**
 * A short-lived worker that decodes some ports of a long capture for the replay's overview and
 * checkpoints (replay-file-pass.ts) on a core of its own: first its job, then the file's pieces
 * as the worker reads them.
 */
/// <reference lib="webworker" />
import { detachEarly } from '../detach-early.js';
import { type HelperMessage, helperReceiver } from './replay-file-pass.js';

detachEarly();
const scope = self as unknown as DedicatedWorkerGlobalScope;
const receive = helperReceiver(
  (r, transfer) => scope.postMessage(r, transfer),
  () => performance.now(),
);

scope.addEventListener('message', (event: MessageEvent<HelperMessage>) => receive(event.data));
