/**
 * A worker thread whose results this thread waits for in the middle of synchronous work (the
 * capture reader, the report), without an event loop: the worker posts each result on a port of
 * its own and counts it in shared memory; this thread sleeps on the count (`Atomics.wait`) and
 * takes the message off the port (`receiveMessageOnPort`). Results come in the order posted. A
 * worker that ends without posting a result (it failed to load, threw, was stopped) counts its
 * end as well, so that nobody waits for it for ever: the result is then undefined. This thread
 * can also send the worker a message on the same port, which the worker awaits (`next`).
 */
import { availableParallelism } from 'node:os';
import { MessageChannel, type MessagePort, receiveMessageOnPort, Worker, workerData } from 'node:worker_threads';

/** Whether a second thread can run beside this one (on one core they would only take turns). */
export function secondCore(): boolean {
  return availableParallelism() > 1;
}

/** What the worker gets besides its own data. */
interface Link {
  port: MessagePort;
  /** [0]: results posted so far, plus 1 once the worker ended; [1]: 1 once it ended. */
  signal: Int32Array;
}

export class WaitedWorker<Result> {
  readonly #worker: Worker;
  readonly #port: MessagePort;
  readonly #signal = new Int32Array(new SharedArrayBuffer(8));
  readonly #results: Result[] = [];

  /** Starts the worker module at `url` with `data` (structured-cloned; shared memory stays shared). */
  constructor(url: URL, data: object) {
    const channel = new MessageChannel();
    this.#port = channel.port1;
    const link: Link = { port: channel.port2, signal: this.#signal };
    this.#worker = new Worker(url, { workerData: { ...data, link }, transferList: [channel.port2] });
    // A worker that throws has ended without its result, which `result` reports as undefined and
    // the caller does the work itself; unheard, the error would end this process instead.
    this.#worker.on('error', () => {});
  }

  /** Result `i` (from 0, in the order the worker posts them), waiting for it; undefined if the worker ended without it. */
  result(i: number): Result | undefined {
    while (this.#results.length <= i) {
      const seen = Atomics.load(this.#signal, 0);
      const got = receiveMessageOnPort(this.#port);
      if (got !== undefined) this.#results.push(got.message as Result);
      else if (Atomics.load(this.#signal, 1) === 1) return undefined;
      else Atomics.wait(this.#signal, 0, seen);
    }
    return this.#results[i];
  }

  /** Sends the worker a message (its `next()`), without waiting. */
  send(message: unknown): void {
    this.#port.postMessage(message);
  }

  /** Stops the worker (whatever it was still doing). */
  close(): void {
    this.#port.close();
    void this.#worker.terminate();
  }
}

/** In the worker module: its data, how it posts a result, and the next message `send` sent it. */
export function workerSide<Data>(): { data: Data; post: (result: unknown) => void; next: () => Promise<unknown> } {
  const { link, ...data } = workerData as Data & { link: Link };
  process.on('exit', () => {
    Atomics.store(link.signal, 1, 1);
    Atomics.add(link.signal, 0, 1);
    Atomics.notify(link.signal, 0);
  });
  return {
    data: data as Data,
    post: (result) => {
      link.port.postMessage(result);
      Atomics.add(link.signal, 0, 1);
      Atomics.notify(link.signal, 0);
    },
    next: () => new Promise((resolve) => link.port.once('message', resolve)),
  };
}
