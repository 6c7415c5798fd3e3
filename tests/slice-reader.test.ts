/**
 * The replay walk's file reader (slice-reader.ts): where its worker cannot run (it fails to
 * start, or stops), the reads asked for and those after are made on this thread instead.
 */
import { afterEach, describe, expect, it, vi } from 'vitest';
import { READ_IN_WORKER } from '../src/worker/replay/slice-reader.js';

/** A worker that fails as it starts, as a blocked or missing script does. */
class FailingWorker extends EventTarget {
  posted = 0;
  terminated = false;
  constructor() {
    super();
    setTimeout(() => this.dispatchEvent(new Event('error')), 5);
  }
  postMessage(): void {
    this.posted++;
  }
  terminate(): void {
    this.terminated = true;
  }
}

describe('the file reader of a replay walk', () => {
  afterEach(() => vi.unstubAllGlobals());

  it('reads here what it asked its worker for, and all after, when the worker fails', async () => {
    const workers: FailingWorker[] = [];
    vi.stubGlobal(
      'Worker',
      class extends FailingWorker {
        constructor() {
          super();
          workers.push(this);
        }
      },
    );
    const bytes = Uint8Array.from({ length: 5000 }, (_, i) => (i * 7) & 0xff);
    const reader = READ_IN_WORKER(new Blob([bytes]));
    const asked = [reader.read(0, 1000), reader.read(1000, 3000)];
    expect(await Promise.all(asked)).toEqual([bytes.slice(0, 1000), bytes.slice(1000, 3000)]);
    expect(await reader.read(3000, 5000)).toEqual(bytes.slice(3000, 5000));
    expect(workers.map((w) => w.terminated)).toEqual([true]);
    reader.close();
    await expect(reader.read(0, 10)).rejects.toThrow('let go');
  });
});
