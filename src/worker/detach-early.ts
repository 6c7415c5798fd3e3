/**
 * A worker's first act: one small ArrayBuffer with two views detached, so that the JavaScript
 * engine drops, before it has optimized anything, an assumption this worker breaks anyway.
 *
 * The engine compiles typed-array code without detach checks for as long as no buffer with more
 * than one view has been detached in the worker, and throws every such function away the first
 * time one is. A replay does detach such buffers (pieces of the file handed back to be read
 * into again), so it is done first, before anything is compiled, instead of in the middle of a
 * long open (figures: bench/README.md, "Why the hot paths are written as they are").
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
