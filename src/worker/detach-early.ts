/**
 * A worker's first act: one small ArrayBuffer with two views detached, so that the JavaScript
 * engine drops, before it has optimized anything, an assumption this worker breaks anyway.
 *
 * V8 (Chromium 156) compiles typed-array code without detach checks for as long as no buffer
 * with more than one view has been detached in the worker. A replay breaks that within its first
 * second: a piece of the file handed back to be read into again, a byte-stream read into a
 * recycled piece. The engine then throws away every optimized function that reads typed arrays
 * and compiles them again. On the day capture's open (--trace-deopt): 45–48 functions of the
 * helper's walk and decode dropped about 0.5 s in, 24 more with its first report, and 8 of the
 * worker's preview; with this, none. With prime-runs.ts (a compiled loop nothing throws away
 * must be compiled right), 600–820 ms of optimizing compile an open against 920–1010, in three
 * opens each.
 *
 * Returns whether the buffer was detached (false where structuredClone is missing).
 */
export function detachEarly(): boolean {
  if (typeof structuredClone !== 'function') return false;
  const buffer = new ArrayBuffer(8);
  // Two views: a buffer with one is detached without the engine giving anything up.
  const bytes = new Uint8Array(buffer);
  const view = new DataView(buffer);
  structuredClone(buffer, { transfer: [buffer] });
  return bytes.length === 0 && view.buffer.byteLength === 0;
}
