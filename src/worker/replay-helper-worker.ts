/**
 * A short-lived worker that decodes some ports of a long capture for the replay's overview and
 * checkpoints (replay-file-pass.ts) on a core of its own: first its job, then the file's pieces
 * as the worker reads them.
 */
/// <reference lib="webworker" />
import { ArrivingFile } from './arriving-file.js';
import { passOverFile } from './replay-file-pass.js';
import type { HelperMessage } from './replay-split.js';

const scope = self as unknown as DedicatedWorkerGlobalScope;
let file: ArrivingFile | null = null;

scope.addEventListener('message', (event: MessageEvent<HelperMessage>) => {
  const m = event.data;
  if ('job' in m) {
    file = new ArrivingFile(m.job.size);
    void passOverFile(
      m.job,
      file,
      (r, transfer) => scope.postMessage(r, transfer),
      () => performance.now(),
    );
  } else if ('piece' in m) file?.push(m.piece);
  else file?.fail(new Error(m.failed));
});
