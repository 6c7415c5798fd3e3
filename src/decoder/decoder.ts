/**
 * The push decoder: bytes in (`push`), frames out (`next`). It finds frames without a sync
 * byte and without trusting chunk timing, infers the stream's format, and never throws on bytes.
 *
 * Content decides where a frame starts, so the result is identical however the bytes are
 * chunked and whatever chunk times come with them; per-byte times add one rule (16 bytes with a
 * silence inside are no frame). A frame is emitted only on evidence. The decoder
 * is three parts over one state record (state.ts):
 *
 * - byte-window.ts: the bytes held and when they arrived;
 * - acquire.ts: where frames start and how to read them, before a lock;
 * - locked.ts: how each frame is accepted once locked, the one path every frame takes.
 */
import { ByteWindow, type WindowSnapshot } from './byte-window.js';
import type { DecoderCheckpoint } from './checkpoint.js';
import { formatOf, setReason } from './format.js';
import { createFrame, showSlots } from './frame.js';
import { nextFrame } from './locked.js';
import type { Resolution } from './spec.js';
import { type Core, copyState, createChain, type DecoderState, initialState, unlock } from './state.js';
import type { DecodedFrame, DecoderEvent, DecoderStats, FormatInfo, HeaderMode, RemoteKind } from './types.js';

/** How a `SpektrumDecoder` reads a stream; every field is optional and 'auto' decides on evidence. */
export interface DecoderOptions {
  /** Fix the servo resolution instead of inferring it (e.g. from the internal remote). Default 'auto'. */
  resolution?: 'auto' | Resolution;
  /** Who fixed `resolution`, for `format`: the user (default) or the internal remote of the system. */
  resolutionFrom?: 'user' | 'internal-remote';
  /** Fix the remote kind instead of inferring it from the header bytes. Default 'auto'. */
  remote?: 'auto' | RemoteKind;
  /** What byte 0 of an internal remote carries. 'auto' (default) decides on evidence (SPM4649T RSSI). */
  headerMode?: 'auto' | HeaderMode;
  /** Called synchronously for locks, discards, resyncs, format changes and fade jumps. */
  onEvent?: (event: DecoderEvent) => void;
}

/** What a checkpoint holds; callers see only `DecoderCheckpoint`, which says its version. */
interface CheckpointData {
  readonly version: typeof CHECKPOINT_VERSION;
  readonly window: WindowSnapshot;
  readonly state: DecoderState;
}

/** Bumped whenever what a checkpoint holds changes: a checkpoint of another version is refused. */
const CHECKPOINT_VERSION = 4;

function checkResolution(resolution: unknown): asserts resolution is 'auto' | Resolution {
  if (resolution !== 'auto' && resolution !== 1024 && resolution !== 2048) {
    throw new TypeError(`resolution must be 'auto', 1024 or 2048, not ${String(resolution)}`);
  }
}

/**
 * A push decoder for one satellite's byte stream: `push` bytes as they arrive, take frames with
 * `next` until it returns undefined. It never throws on bytes, and gives the same frames however
 * the bytes are chunked (see the file's comment for what it claims and when).
 */
export class SpektrumDecoder {
  readonly #d: Core;
  /** The counters `stats` hands out: one object for the decoder's life, whatever state is restored. */
  readonly #stats: DecoderStats;

  /**
   * @throws {TypeError} when an option has a value outside its documented set.
   */
  constructor(options: DecoderOptions = {}) {
    const resolution = options.resolution ?? 'auto';
    const remote = options.remote ?? 'auto';
    const headerMode = options.headerMode ?? 'auto';
    checkResolution(resolution);
    if (remote !== 'auto' && remote !== 'internal' && remote !== 'external') {
      throw new TypeError(`remote must be 'auto', 'internal' or 'external', not ${String(remote)}`);
    }
    if (headerMode !== 'auto' && headerMode !== 'fades' && headerMode !== 'rssi') {
      throw new TypeError(`headerMode must be 'auto', 'fades' or 'rssi', not ${String(headerMode)}`);
    }
    if (options.onEvent !== undefined && typeof options.onEvent !== 'function') {
      throw new TypeError('onEvent must be a function');
    }
    const s = initialState({ resolution, remote, headerMode }, options.resolutionFrom === 'internal-remote' ? 'internal-remote' : 'user');
    this.#stats = s.stats;
    this.#d = { w: new ByteWindow(), s, frame: createFrame(s.shown), chain: createChain(), onEvent: options.onEvent };
  }

  /**
   * Adds bytes as they arrived. `time` is one of:
   * - a number: the chunk's arrival time in µs (taken as the time of its last byte; earlier
   *   bytes are placed one byte time, 86.8 µs, apart before it);
   * - a Float64Array with one time in µs per byte (logic-analyser captures);
   * - omitted: no timing (frame times are then NaN).
   *
   * The bytes are copied; the caller may reuse its buffer.
   * @throws {TypeError} after `end()`, or when per-byte times do not match the bytes in length.
   */
  push(bytes: Uint8Array, time?: number | Float64Array): void {
    this.pushRange(bytes, 0, bytes.length, time);
  }

  /**
   * `push(bytes.subarray(start, end), time)` without making that view (an allocation a chunk):
   * for a caller that holds a whole stream and feeds it chunk by chunk, such as a capture's
   * columns. Per-byte times are indexed like `bytes`: those of [start, end) are taken.
   * @throws {TypeError} as `push()`, and for a range that is not one of `bytes`.
   */
  pushRange(bytes: Uint8Array, start: number, end: number, time?: number | Float64Array): void {
    // Small, so that it is inlined into the caller's loop: a chunk's time then goes on in the
    // window's typed-array slot, not as a double handed to a call (boxed, an allocation a push).
    const w = this.#d.w;
    if (typeof time === 'number') {
      w.at[0] = time;
      w.pushTimed(bytes, start, end);
    } else w.pushOther(bytes, start, end, time);
    const stats = this.#stats;
    stats.bytes += end - start;
    stats.pendingBytes += end - start;
  }

  /**
   * Marks the end of the stream: bytes still held are decided with what is there (a last frame
   * that continues the stream with a known layout is emitted without a following frame to
   * confirm it; anything else left is discarded).
   */
  end(): void {
    this.#d.w.end();
  }

  /**
   * Changes the resolution setting while decoding (the user's override, or the internal
   * remote's resolution handed to an external one). When it contradicts the lock, the decoder
   * looks for frames again from the next undecided byte; counters and buffered bytes are kept.
   * `by` says where a fixed resolution comes from, for `format`: the user, or the internal
   * remote of the same system.
   * @throws {TypeError} for a value outside 'auto', 1024, 2048.
   */
  setResolution(resolution: 'auto' | Resolution, by: 'user' | 'internal-remote' = 'user'): void {
    checkResolution(resolution);
    const s = this.#d.s;
    const fixedBy = resolution === 'auto' ? 'user' : by;
    if (s.opts.resolution === resolution && s.fixedBy === fixedBy) return;
    s.opts.resolution = resolution;
    s.fixedBy = fixedBy;
    s.forcedMismatch = null;
    s.noStartBelow = 0;
    if (s.withheld === 'forced') s.withheld = null;
    if (!s.locked) return;
    if (resolution === 'auto' ? s.reason === 'override' || s.reason === 'internal-remote' : resolution !== s.resolution) {
      unlock(s);
      s.layoutCount = 0;
      s.reason = 'unknown';
    } else {
      setReason(s, s.resolution);
    }
  }

  /** Forgets everything: buffered bytes, lock, format and counters (the options stay). */
  reset(): void {
    this.#d.w.clear();
    this.#adopt(initialState(this.#d.s.opts, this.#d.s.fixedBy));
  }

  /** Live counters (the same object each time; read, don't write). */
  get stats(): Readonly<DecoderStats> {
    return this.#stats;
  }

  /** The resolution option in force: 'auto', or fixed by the constructor, `setResolution` or a restored checkpoint. */
  get resolutionSetting(): 'auto' | Resolution {
    return this.#d.s.opts.resolution;
  }

  /**
   * When the oldest byte the decoder still holds arrived (dated as a frame's first byte is): a
   * frame it will hand out once the next one confirms it. NaN when it holds none or has no times.
   */
  get pendingSinceUs(): number {
    const w = this.#d.w;
    if (w.head === w.tail) return Number.NaN;
    w.dateAny(w.base + w.head);
    return w.when[0] ?? Number.NaN;
  }

  /** What the decoder has decided about the format, and why (a new object each call). */
  get format(): FormatInfo {
    return formatOf(this.#d.s);
  }

  /**
   * The next decoded frame, or `undefined` when more bytes are needed. The frame is borrowed:
   * the same object is reused and is valid until the next call to `next()`, `push()`, `end()`
   * or `reset()`.
   */
  next(): DecodedFrame | undefined {
    return nextFrame(this.#d);
  }

  /**
   * The decoder's whole state now, as an opaque value no later call changes: the bytes it still
   * holds and their times, the lock, the format and the counters (a few kilobytes). It survives
   * `structuredClone` and `postMessage`. Between calls only (not while a borrowed frame is in use).
   */
  checkpoint(): DecoderCheckpoint {
    const data: CheckpointData = { version: CHECKPOINT_VERSION, window: this.#d.w.snapshot(), state: copyState(this.#d.s) };
    return data as unknown as DecoderCheckpoint;
  }

  /**
   * Puts the decoder back where `checkpoint()` was taken (from this decoder or another): fed
   * the same bytes from there, it gives the same frames, events, counters and format. Its own
   * `onEvent` stays; `cp` is left as it was and can be restored again.
   * @throws {TypeError} for a checkpoint of another version of this library, or not one at all.
   */
  restore(cp: DecoderCheckpoint): void {
    const data = cp as unknown as Partial<CheckpointData> | null;
    if (data?.version !== CHECKPOINT_VERSION || data.window === undefined || data.state === undefined) {
      throw new TypeError(`not a decoder checkpoint of this version (${CHECKPOINT_VERSION}): ${String(data?.version)}`);
    }
    this.#d.w.restore(data.window);
    this.#adopt(copyState(data.state));
  }

  /** Takes `s` as the state, keeping the counters' object and showing its frame. */
  #adopt(s: DecoderState): void {
    Object.assign(this.#stats, s.stats);
    s.stats = this.#stats;
    this.#d.s = s;
    showSlots(this.#d.frame, s.shown);
  }
}
