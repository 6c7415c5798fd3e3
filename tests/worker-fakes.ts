/** A fake clock and host for driving the worker's parts in Node: time moves only when a test says. */
import type { Clock, Host } from '../src/worker/host.js';
import { Dispatcher } from '../src/worker/dispatcher.js';
import type { Batch, FromWorker, PortIdentity, ToWorker } from '../src/worker/protocol.js';
import type { ReplayClock } from '../src/worker/sources/replay.js';

interface Timer {
  at: number;
  every: number;
  fn: () => void;
}

export class FakeClock implements Clock {
  #now = 1000;
  #next = 1;
  readonly #timers = new Map<number, Timer>();

  now(): number {
    return this.#now;
  }

  after(ms: number, fn: () => void): number {
    const id = this.#next++;
    this.#timers.set(id, { at: this.#now + Math.max(0, ms), every: 0, fn });
    return id;
  }

  every(ms: number, fn: () => void): number {
    const id = this.#next++;
    this.#timers.set(id, { at: this.#now + ms, every: ms, fn });
    return id;
  }

  cancel(handle: unknown): void {
    if (typeof handle === 'number') this.#timers.delete(handle);
  }

  /** Timers waiting. */
  get pending(): number {
    return this.#timers.size;
  }

  /** Moves time on by `ms`, running every timer due on the way at its time, in time order. */
  advance(ms: number): void {
    const end = this.#now + ms;
    for (;;) {
      let due: [number, Timer] | undefined;
      for (const entry of this.#timers) if (entry[1].at <= end && (due === undefined || entry[1].at < due[1].at)) due = entry;
      if (due === undefined) break;
      const [id, t] = due;
      this.#now = t.at;
      if (t.every > 0) t.at += t.every;
      else this.#timers.delete(id);
      t.fn();
    }
    this.#now = end;
  }

  /**
   * Moves time on by `ms` with the thread starved: no timer runs on the way, and each one due
   * runs once at the end, late, as a browser's timers do after a long task.
   */
  stall(ms: number): void {
    const end = this.#now + ms;
    for (const t of this.#timers.values()) if (t.at < end) t.at = end;
    this.#now = end;
    this.advance(0);
  }
}

/** A clock that moves 10 ms each time it is read, so the capture's decode goes in slices. */
export class ReadingClock extends FakeClock {
  #extra = 0;
  /** @param stepMs how far each reading moves the clock */
  constructor(readonly stepMs = 10) {
    super();
  }
  override now(): number {
    this.#extra += this.stepMs;
    return super.now() + this.#extra;
  }
}

/** A host whose posts are kept, in order, with what they transferred. */
export function fakeHost(clock = new FakeClock()) {
  const posts: FromWorker[] = [];
  const host: Host = {
    post: (message) => {
      posts.push(message);
    },
    clock,
    timeOriginMs: 1_700_000_000_000,
  };
  const of = <T extends FromWorker['type']>(type: T): Extract<FromWorker, { type: T }>[] =>
    posts.filter((p): p is Extract<FromWorker, { type: T }> => p.type === type);
  /** Every source's batch posted so far, in order (the batcher posts all sources' batches of a flush in one message). */
  const batches = (from = 0): { source: number; batch: Batch }[] =>
    posts.slice(from).flatMap((p) => (p.type === 'batches' ? p.batches : []));
  return { host, clock, posts, of, batches };
}

/** Wall time for replay: each tick moves it 10 ms; every reading moves it a µs, so slices end. */
export class SimulatedClock implements ReplayClock {
  ms = 0;
  readonly #timers = new Map<number, () => void>();
  #next = 1;
  now(): number {
    this.ms += 0.001;
    return this.ms;
  }
  every(_ms: number, fn: () => void): unknown {
    const id = this.#next++;
    this.#timers.set(id, fn);
    return id;
  }
  cancel(handle: unknown): void {
    if (typeof handle === 'number') this.#timers.delete(handle);
  }
  /** Runs the timers `n` times, 10 ms apart (fewer if none is left). */
  tick(n = 1): void {
    for (let i = 0; i < n && this.#timers.size > 0; i++) {
      this.ms += 10;
      for (const fn of [...this.#timers.values()]) fn();
    }
  }
  /** Runs the timers, 10 ms apart, until `done()` or none is left. */
  run(done: () => boolean): void {
    for (let guard = 0; !done() && this.#timers.size > 0 && guard < 1e6; guard++) this.tick();
  }
}

/**
 * A dispatcher on a fake host for replay tests: `send` waits for each command to be handled,
 * `walked` for a file's records to be walked to the end (its overview sent complete), which goes
 * on between the commands as it does in the worker.
 */
export function openReplay(clock: FakeClock = new FakeClock()) {
  const fake = fakeHost(clock);
  const worker = new Dispatcher(fake.host);
  const send = async (...messages: ToWorker[]): Promise<void> => {
    for (const m of messages) worker.receive(m);
    await worker.queue.idle();
  };
  const walked = async (): Promise<void> => {
    for (let guard = 0; guard < 100_000; guard++) {
      if (fake.of('overview').at(-1)?.overview.complete === true) return;
      // The walk yields to the clock now and then (the fake one moves only when advanced).
      clock.advance(1);
      await new Promise((resolve) => setTimeout(resolve, 0));
    }
    throw new Error('the walk did not end');
  };
  return { ...fake, worker, send, walked };
}

/**
 * The whole worker over stand-in ports (`findPort` finds them): commands sent and waited for,
 * and the fake clock moved on in 1 ms steps with the promises between them settled (reads, writes).
 */
export function portRig(fake: ReturnType<typeof fakeHost>, findPort: (identity: PortIdentity) => Promise<SerialPort | undefined>) {
  const worker = new Dispatcher(fake.host, { findPort });
  const send = async (...messages: ToWorker[]): Promise<void> => {
    for (const m of messages) worker.receive(m);
    await worker.queue.idle();
  };
  const run = async (ms: number): Promise<void> => {
    for (let i = 0; i < ms; i++) {
      fake.clock.advance(1);
      await new Promise((r) => setImmediate(r));
    }
  };
  return { worker, send, run };
}

/** A stand-in SerialPort: `onWrite` sees what the page writes; `reply` puts bytes on its RX. */
export class StandInPort {
  #rx: ReadableStreamDefaultController<Uint8Array> | undefined;
  #readable: ReadableStream<Uint8Array> | null = null;
  #writable: WritableStream<Uint8Array> | null = null;
  constructor(
    readonly vid: number,
    readonly onWrite: (bytes: Uint8Array, port: StandInPort) => void,
  ) {}
  async open(): Promise<void> {
    this.#readable = new ReadableStream<Uint8Array>({
      start: (c) => {
        this.#rx = c;
      },
    });
    this.#writable = new WritableStream<Uint8Array>({ write: (bytes) => this.onWrite(bytes.slice(), this) });
  }
  reply(bytes: Uint8Array): void {
    this.#rx?.enqueue(bytes);
  }
  get readable(): ReadableStream<Uint8Array> | null {
    return this.#readable;
  }
  get writable(): WritableStream<Uint8Array> | null {
    return this.#writable;
  }
  async close(): Promise<void> {
    this.#readable = null;
    this.#writable = null;
  }
  async setSignals(): Promise<void> {}
  getInfo(): SerialPortInfo {
    return { usbVendorId: this.vid, usbProductId: 1 };
  }
}
