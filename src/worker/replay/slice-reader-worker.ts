/**
 * The reader worker of slice-reader.ts: told the file once, then reads the slices asked for and
 * hands each back without a copy (the error's text where a read fails, the file gone or changed).
 */
/// <reference lib="webworker" />
import type { SliceReply, SliceRequest } from './slice-reader.js';

const scope = self as unknown as DedicatedWorkerGlobalScope;
let file: Blob | null = null;

scope.addEventListener('message', async (event: MessageEvent<SliceRequest>) => {
  const request = event.data;
  if ('file' in request) {
    file = request.file;
    return;
  }
  const { id, start, end } = request;
  try {
    if (file === null) throw new Error('no file to read');
    const bytes = await file.slice(start, end).arrayBuffer();
    scope.postMessage({ id, bytes } satisfies SliceReply, [bytes]);
  } catch (error) {
    scope.postMessage({ id, error: error instanceof Error ? error.message : String(error) } satisfies SliceReply);
  }
});
