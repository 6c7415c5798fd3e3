/**
 * Reads a File's slices for the replay's walk of it (file-walk.ts). In Chromium a worker that
 * reads a Blob receives its bytes on its own thread, so a read waits while the worker decodes,
 * and the decode waits while it reads: the day capture's walk spent a third of its time waiting
 * on reads. A reader worker of its own (slice-reader-worker.ts) reads the next slices while this
 * one decodes, and hands each over without a copy. bench/README.md has the figures.
 */

/** Bytes [start, end) of one file, read elsewhere or here. */
export interface SliceReader {
  read(start: number, end: number): Promise<Uint8Array>;
  /** Lets the reader go; reads asked for after this fail. */
  close(): void;
}

/** Makes a reader of `file`'s slices (one walk's). */
export type SliceReaderMaker = (file: Blob) => SliceReader;

/** Reads on this thread (tests, and where a worker cannot start another). */
export const READ_HERE: SliceReaderMaker = (file) => ({
  read: async (start, end) => new Uint8Array(await file.slice(start, end).arrayBuffer()),
  close: () => {},
});

/** A request to the reader worker, and its answer. */
export type SliceRequest = { file: Blob } | { id: number; start: number; end: number };
export type SliceReply = { id: number; bytes: ArrayBuffer } | { id: number; error: string };

/**
 * Reads in a worker of its own (the browser's). Where a worker cannot start another, or that
 * worker fails (it cannot load, or stops), the reads asked for and every one after are made here.
 */
export const READ_IN_WORKER: SliceReaderMaker = (file) => {
  if (typeof Worker === 'undefined') return READ_HERE(file);
  const worker = new Worker(new URL('./slice-reader-worker.ts', import.meta.url), { type: 'module', name: 'satscope-file-reader' });
  type Waiting = { start: number; end: number; resolve: (bytes: Uint8Array) => void; reject: (error: Error) => void };
  const waiting = new Map<number, Waiting>();
  let nextId = 0;
  let here: SliceReader | null = null;
  let closed = false;
  worker.addEventListener('message', (event: MessageEvent<SliceReply>) => {
    const reply = event.data;
    const w = waiting.get(reply.id);
    waiting.delete(reply.id);
    if ('bytes' in reply) w?.resolve(new Uint8Array(reply.bytes));
    else w?.reject(new Error(reply.error));
  });
  worker.addEventListener('error', () => {
    worker.terminate();
    const reader = READ_HERE(file);
    here = reader;
    for (const w of waiting.values()) reader.read(w.start, w.end).then(w.resolve, w.reject);
    waiting.clear();
  });
  worker.postMessage({ file } satisfies SliceRequest);
  return {
    read: (start, end) => {
      if (closed) return Promise.reject(new Error('the file reader was let go'));
      if (here !== null) return here.read(start, end);
      return new Promise((resolve, reject) => {
        const id = nextId++;
        waiting.set(id, { start, end, resolve, reject });
        worker.postMessage({ id, start, end } satisfies SliceRequest);
      });
    },
    close: () => {
      closed = true;
      worker.terminate();
      for (const w of waiting.values()) w.reject(new Error('the file reader was let go'));
      waiting.clear();
    },
  };
};
