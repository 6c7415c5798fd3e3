/**
 * A short-lived worker that decodes some ports of a long capture for the replay's overview and
 * checkpoints (replay-file-pass.ts), on a core of its own while the worker reads the file.
 */
/// <reference lib="webworker" />
import { type FilePassJob, passOverFile } from './replay-file-pass.js';

const scope = self as unknown as DedicatedWorkerGlobalScope;

scope.addEventListener('message', (event: MessageEvent<FilePassJob>) => {
  void passOverFile(
    event.data,
    (r, transfer) => scope.postMessage(r, transfer),
    () => performance.now(),
  );
});
