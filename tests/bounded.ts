/**
 * Runs the built decoder (dist/, which `npm test` builds first) over inputs in a worker thread
 * with a watchdog: a decoder that loops forever blocks its thread, so only another thread can
 * notice. Each input must finish within `perInputMs`, or the run fails naming the input.
 */
import { Worker } from 'node:worker_threads';
import { fileURLToPath } from 'node:url';
import type { DecoderOptions } from '../src/decoder/decoder.js';

export interface BoundedInput {
  bytes: Uint8Array;
  options: Omit<DecoderOptions, 'onEvent'>;
  /** Bytes per push (default: the whole input at once). */
  chunk?: number;
  /** 'chunk': pass each chunk's index as its time; 'per-byte': one time per byte; default none. */
  times?: 'chunk' | 'per-byte';
}

export interface BoundedResult {
  frames: number;
  /** Every byte ended up framed or discarded. */
  accounted: boolean;
}

const DIST = fileURLToPath(new URL('../dist/decoder/index.js', import.meta.url));

const WORKER = `
const { parentPort, workerData } = require('node:worker_threads');
import(workerData.dist).then(({ SpektrumDecoder }) => {
  parentPort.on('message', (input) => {
    const d = new SpektrumDecoder(input.options);
    const b = input.bytes;
    const step = input.chunk || b.length || 1;
    let frames = 0;
    for (let i = 0; i < b.length; i += step) {
      const part = b.subarray(i, i + step);
      const time = input.times === 'chunk' ? i * 100 : input.times === 'per-byte' ? Float64Array.from(part, (_, k) => (i + k) * 87) : undefined;
      d.push(part, time);
      while (d.next()) frames++;
    }
    d.end();
    while (d.next()) frames++;
    const s = d.stats;
    parentPort.postMessage({ frames, accounted: s.pendingBytes === 0 && s.frameBytes + s.discardedBytes === s.bytes });
  });
  parentPort.postMessage('ready');
});
`;

/** Decodes every input in a worker; rejects when one takes longer than `perInputMs`. */
export async function runBounded(inputs: readonly BoundedInput[], perInputMs: number): Promise<BoundedResult[]> {
  const worker = new Worker(WORKER, { eval: true, workerData: { dist: DIST } });
  try {
    const next = (): Promise<unknown> =>
      new Promise((resolve, reject) => {
        const timer = setTimeout(() => reject(new Error('timeout')), perInputMs);
        worker.once('message', (m) => {
          clearTimeout(timer);
          resolve(m);
        });
        worker.once('error', (e) => {
          clearTimeout(timer);
          reject(e);
        });
      });
    await next();
    const results: BoundedResult[] = [];
    for (const [i, input] of inputs.entries()) {
      const reply = next();
      worker.postMessage(input);
      try {
        results.push((await reply) as BoundedResult);
      } catch (e) {
        const head = Array.from(input.bytes.subarray(0, 64), (b) => b.toString(16).padStart(2, '0')).join('');
        throw new Error(
          `input ${i} (${input.bytes.length} bytes, options ${JSON.stringify(input.options)}, starts ${head}) did not finish in ${perInputMs} ms: ${String(e)}`,
        );
      }
    }
    return results;
  } finally {
    await worker.terminate();
  }
}
