/**
 * The sources: one per remote being decoded, each with its id (its port number in recordings),
 * label, state and decode (an Engine), fed by one driver at a time: the serial ports, the demo
 * or a replay (sources/). Ids and labels, adding and removing sources, closing everything when
 * the session changes kind, the session's clock and the list the page shows all live here.
 */
import { Engine } from './engine.js';
import type { Diagnosis } from './diagnosis.js';
import { type Host, nowUs } from './host.js';
import { REMOTE_LABELS, type PortIdentity, type SourceKind, type SourceStatus } from './protocol.js';
import type { SerialSource } from './sources/serial.js';

/** One remote being decoded. */
export interface Source {
  readonly id: number;
  readonly kind: SourceKind;
  label: string;
  state: string;
  name: string;
  readonly engine: Engine;
  serial?: SerialSource;
  identity?: PortIdentity;
  /** Signals to set whenever the port is (re)opened: the satellite's power after a bind. */
  signals?: SerialOutputSignals;
  /** The resolution the stream looked like when a forced one matched no frame, as last told. */
  toldMismatch?: 1024 | 2048 | null;
  /** The internal remote's resolution this (external) remote was given, and its counters then. */
  sharedKey?: 1024 | 2048;
  sharedAt?: { frames: number; discarded: number };
  /** A resolution that did not fit this remote's bytes: not given again. */
  refusedKey?: 1024 | 2048;
}

/** What feeds sources (sources/): the serial ports, the demo or a replay. One kind at a time. */
export interface Driver {
  readonly kind: SourceKind;
  /** The session's clock, µs: the worker's clock live, the position in replay. */
  clockUs(): number;
  /** How that clock advances against wall time: 1 live, the speed in replay, 0 paused. */
  clockRate(): number;
  /** The time source `id`'s link is judged at (in replay, never past a byte still to come). */
  linkNowUs(id: number): number;
  /** Stops feeding every source (`sources`, just forgotten by the registry): ports closed, timers stopped. */
  stop(sources: readonly Source[]): Promise<void>;
  /** Stops feeding one source (a port the user closed). */
  release(source: Source): Promise<void>;
}

export interface RegistryHooks {
  /** Before every source closes (a recording belongs to the sources it began with). */
  closing(): Promise<void>;
  /** The last source went: timers can stop. */
  empty(): void;
}

export class SourceRegistry {
  /** The resolution the user chose, for every new decode. */
  resolution: 'auto' | 1024 | 2048 = 'auto';
  readonly #sources = new Map<number, Source>();
  #driver: Driver | undefined;
  #lastSent = '';

  constructor(
    readonly host: Host,
    readonly diagnosis: Diagnosis,
    readonly hooks: RegistryHooks,
  ) {}

  get driver(): Driver | undefined {
    return this.#driver;
  }

  /**
   * Makes `driver` feed the session. A driver of another kind (or another instance) closes the
   * sources first: ports join each other, but not the demo or a replay.
   */
  async use(driver: Driver): Promise<void> {
    if (this.#driver === driver) return;
    if (this.#driver !== undefined || this.#sources.size > 0) await this.closeAll();
    this.#driver = driver;
  }

  get size(): number {
    return this.#sources.size;
  }

  get(id: number): Source | undefined {
    return this.#sources.get(id);
  }

  /** The sources, as a list (safe to change the registry while walking it). */
  list(): Source[] {
    return [...this.#sources.values()];
  }

  /** The lowest id not in use. */
  freeId(): number {
    let id = 0;
    while (this.#sources.has(id)) id++;
    return id;
  }

  /** A new source with a fresh decode; the page is told its decode starts. */
  add(kind: SourceKind, id: number, name: string, jitterUs: number): Source {
    const source: Source = {
      id,
      kind,
      label: REMOTE_LABELS[id] ?? `R${id}`,
      state: 'opening',
      name,
      engine: new Engine({ resolution: this.resolution, jitterUs }),
    };
    this.#sources.set(id, source);
    this.diagnosis.attach(id, source.engine, source.label);
    this.host.post({ type: 'reset', source: id });
    return source;
  }

  /** Forgets a source that never opened (no driver to release it). */
  discard(id: number): void {
    this.#sources.delete(id);
    this.host.post({ type: 'reset', source: id });
    this.send();
  }

  /** Closes one source: its driver stops feeding it, its port number is free again. */
  async remove(id: number): Promise<void> {
    const s = this.#sources.get(id);
    if (s === undefined) return;
    this.#sources.delete(id);
    await this.#driver?.release(s);
    this.diagnosis.remove(id);
    this.host.post({ type: 'reset', source: id });
    if (this.#sources.size === 0) this.hooks.empty();
    this.send();
  }

  /** Every source goes, and the driver stops: a new live session starts. */
  async closeAll(): Promise<void> {
    this.hooks.empty();
    await this.hooks.closing();
    const driver = this.#driver;
    const sources = this.list();
    this.#driver = undefined;
    this.#sources.clear();
    await driver?.stop(sources);
    this.diagnosis.reset();
    this.host.post({ type: 'reset' });
    this.send();
  }

  /** Forgets every source but keeps the driver (a replay starting over): the page starts over too. */
  clear(): void {
    this.#sources.clear();
    this.host.post({ type: 'reset' });
  }

  setLabel(id: number, label: string): void {
    const s = this.#sources.get(id);
    if (s === undefined) return;
    s.label = label.slice(0, 8);
    this.diagnosis.relabel(s.id, s.engine, s.label);
    this.send();
  }

  setState(source: Source, state: string, name = source.name): void {
    source.state = state;
    source.name = name;
    this.send();
  }

  setAllStates(state: string): void {
    for (const s of this.#sources.values()) s.state = state;
    this.send();
  }

  /** The session's clock, µs. */
  clockUs(): number {
    return this.#driver?.clockUs() ?? nowUs(this.host);
  }

  /** The time source `id`'s link is judged at. */
  linkNowUs(id: number): number {
    return this.#driver?.linkNowUs(id) ?? nowUs(this.host);
  }

  /** Sends the list of sources when anything in it changed. */
  send(): void {
    const rate = this.#sources.size > 0 ? (this.#driver?.clockRate() ?? 0) : 0;
    const list: SourceStatus[] = [...this.#sources.values()].map((s) => ({
      id: s.id,
      label: s.label,
      kind: s.kind,
      state: s.state,
      name: s.name,
      clockRate: rate,
      format: s.engine.decoder.format,
    }));
    const key = JSON.stringify(list);
    if (key === this.#lastSent) return;
    this.#lastSent = key;
    this.host.post({ type: 'sources', sources: list });
  }
}
