/**
 * The push decoder: bytes in (`push`), frames out (`next`). It finds frames without a sync
 * byte and without trusting timing, infers the stream's format, and never throws on bytes.
 *
 * Content alone decides where a frame starts, so the result is identical however the bytes are
 * chunked and whatever times come with them. A frame is emitted only on evidence:
 *
 * - Acquiring, it reads four frames from each of the next 48 start offsets under both
 *   resolutions and under one header model (an internal remote: one system byte in every frame
 *   and a fade byte that only rises, slowly; an external one: a UINT16 fade count that only
 *   rises, slowly). Every slot must hold a valid channel ID (or 0xFFFF, or VTX) with no repeats.
 *   Contiguous channel sets, layouts that recur every other frame and a system byte that agrees
 *   with the resolution score higher. The chain's first frame must carry channels: filler (runs
 *   of 0xFF are frames of seven empty slots) never locks. The winning chain is emitted as it stands.
 * - Locked, a frame is emitted when it continues the last one (same model, fade count risen by
 *   less than FADE_STEP) and the whole next frame is valid and continues it: one frame period
 *   of latency. A frame whose slot layout is new must also not overlap a frame that continues
 *   the stream (the front of one frame glued to the back of the next after lost bytes reads as
 *   a new layout).
 * - A frame that fails starts a search for the nearest offset where a known layout continues the
 *   stream; what lies between is discarded and counted. Where nothing continues (a rebind, a
 *   system byte that changed, a fade count that jumped, another satellite) it acquires afresh.
 *
 * Every pass of `next()` emits a frame, consumes at least one byte, waits for input, or turns
 * an unlock into an acquisition, which itself consumes or locks with frames it has confirmed
 * (emitted unconditionally): so `next()` always returns after bounded work.
 */
import { FRAME_SIZE, systemInfo, type Resolution } from './spec.js';
import {
  byteAt,
  channelEvidence,
  countZeroWords,
  createFrame,
  FrameSlots,
  INVALID,
  layoutChannels,
  readFrame,
  showSlots,
  slotLayout,
} from './frame.js';
import { copySlots, type DecoderCheckpoint } from './checkpoint.js';
import type {
  DecodedFrame,
  DecoderEvent,
  DecoderStats,
  FormatInfo,
  HeaderMode,
  HeaderReading,
  RemoteKind,
  ResolutionReason,
  Withheld,
} from './types.js';

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
  /**
   * Whether the locked decoder takes its one-pass path for frames that continue the stream
   * (default true). false decodes everything through the general path: the same frames, stats
   * and events, only slower (tests compare the two; benchmarks show the difference).
   */
  fastPath?: boolean;
}

/** A start acquisition may lock on: its score (-1: none), shift from the head and resolution; `filler`: see #best. */
interface Best {
  score: number;
  shift: number;
  resolution: Resolution;
  filler: boolean;
}

/** The options #score reads with no option forced. */
const FREE = { remote: 'auto', headerMode: 'auto' } as const;

/** Frames looked at before a lock. */
const ACQUIRE_FRAMES = 4;
/** Fewest of them that must chain for a lock: two frames that happen to parse are common. */
const MIN_CHAIN = 3;
/**
 * Start offsets compared before locking. A damaged frame can hide the real alignment's first
 * start while a shifted reading that happens to parse starts earlier; the real start lies at
 * most a frame after any such reading, so candidates over three frames of starts are compared,
 * but a lock is only taken in the first two: a best candidate in the third waits for the window
 * to slide on.
 */
const ACQUIRE_SHIFTS = 3 * FRAME_SIZE;
const ACQUIRE_COMMIT = 2 * FRAME_SIZE;
/**
 * Frames read, at most, to decide whether an internal remote's byte 0 is a fade count or
 * SPM4649T RSSI when every value so far could be either (a fade count of 156…226 reads as
 * -100…-30 dBm). RSSI wanders both ways; fades only rise. Without a fall or a value no RSSI
 * takes in this many frames the decoder says it does not know.
 */
const HEADER_EVIDENCE_FRAMES = 8;
/**
 * The largest rise of a fade counter between two consecutive frames that continues the chain
 * (≈ 90 ms of lost frames at 11 ms; an external count that lands on a §8.3 system byte, 0x12
 * say, is then more likely an internal remote taking over). A larger rise, or any fall that is not a wrap, breaks the
 * chain: the decoder acquires again and reports the jump (`fade-jump`).
 */
const FADE_STEP = 8;
/**
 * The rise a fade count may take between the frames of a chain that acquisition confirms (and
 * emits as it stands): counts rarely move from one frame to the next, while a frame glued from
 * two (a foreign byte read as its fade count) moves them anywhere.
 */
const ACQUIRE_FADE_STEP = 3;
/**
 * Bytes of channel words that are not filler (`channelEvidence`) the first frame of a chain
 * must carry for a lock: more than a header's two, which is all a shifted reading of frames of
 * filler slots finds. A transmitter sends four channels or more, and every frame it sends
 * carries four or more (a pair of 8 to 12 channels, 5 to 7 in each), one such byte each at
 * least (a centred channel's low byte is 0x00).
 */
const EVIDENCE_BYTES = 3;
/** How far a locked decoder searches for a frame that continues the stream before it acquires afresh. */
const MAX_RESYNC_BYTES = 8 * FRAME_SIZE;
/** Slot layouts remembered (a transmitter uses two to four). */
const LAYOUT_MEMORY = 16;
const INITIAL_CAPACITY = 4096;

const NEED_MORE = -2;
const NOT_FOUND = -1;

/** How byte 0 of an internal remote is read while the decoder runs (RSSI_FORCED: the caller said so). */
const B0_FADES = 0;
const B0_RSSI = 1;
const B0_UNKNOWN = 2;
const B0_RSSI_FORCED = 3;

/**
 * §8.3.1: SPM4649T RSSI is -42 (strong) … -92 dBm (weak), -128 on loss. A byte 0 ≥ 0x80 outside
 * -30 … -100 dBm (with a margin for receivers beyond the documented range) is a fade count.
 */
function plausibleRssi(byte: number): boolean {
  return byte === 0x80 || (byte >= 0x9c && byte <= 0xe2);
}

/** Whether byte 0 of an internal remote can go from `prev` to `next` between consecutive frames. */
function byte0Follows(prev: number, next: number, mode: number, step = FADE_STEP): boolean {
  if (mode === B0_RSSI_FORCED) return true;
  // Acquisition's tight step allows no wrap: 0xFF, an empty slot's byte, read as a fade count
  // would otherwise "wrap" to the next frame's 0.
  const rise = step === ACQUIRE_FADE_STEP ? next >= prev && next - prev < step : ((next - prev) & 0xff) < step;
  if (mode === B0_FADES) return rise;
  if (mode === B0_RSSI) return plausibleRssi(next);
  return rise || (plausibleRssi(prev) && plausibleRssi(next));
}

/** `t[i]` at an index the caller knows is inside `t`: a typed read (an index past the end, a bug, reads as NaN). */
function timeAt(t: Float64Array, i: number): number {
  return t[i] ?? NaN;
}

/** Whether an external remote's UINT16 fade count can go from `prev` to `next` between consecutive frames. */
function countFollows(prev: number, next: number, step = FADE_STEP): boolean {
  return step === ACQUIRE_FADE_STEP ? next >= prev && next - prev < step : ((next - prev) & 0xffff) < step;
}

export class SpektrumDecoder {
  #options: Required<Omit<DecoderOptions, 'onEvent' | 'resolutionFrom' | 'fastPath'>>;
  readonly #fastPath: boolean;
  readonly #onEvent: ((event: DecoderEvent) => void) | undefined;

  #buf = new Uint8Array(INITIAL_CAPACITY);
  /** #buf as 32-bit words: a frame that starts at a multiple of 4 is copied in four moves. */
  #buf32 = new Uint32Array(this.#buf.buffer);
  /** The buffer as a DataView, and the last `pushRange` source's (kept while it is fed from): short ranges are copied four bytes at a time. */
  #bufView = new DataView(this.#buf.buffer);
  #source: Uint8Array | null = null;
  #sourceView: DataView | null = null;
  /**
   * Times are kept per pushed chunk, not per byte (filling a time for every byte cost a third of
   * the decoder's throughput): each chunk's end offset in the stream and its time, or NaN. Only
   * chunks pushed with per-byte times store them, in #byteTimes parallel to #buf.
   */
  #chunkEnds = new Float64Array(64);
  #chunkTimes = new Float64Array(64);
  #chunkPerByte = new Uint8Array(64);
  #chunkHead = 0;
  #chunkTail = 0;
  #byteTimes: Float64Array | null = null;
  /** What #dateByte dates: a Float64Array slot, so the double is never boxed between calls. */
  readonly #when = new Float64Array(1);
  /** The time of the chunk pushRange() hands on, likewise. */
  readonly #pushedAt = new Float64Array(1);
  /** Index in #buf of the first byte not yet decided. */
  #head = 0;
  /** Index in #buf after the last byte pushed. */
  #tail = 0;
  /** Stream offset of #buf[0]. */
  #base = 0;
  #ended = false;

  #locked = false;
  #everLocked = false;
  /** Stream offset up to which acquisition has confirmed frames: they are emitted as they stand. */
  #confirmedUntil = 0;
  /** The lock's resolution (the last one locked on; `format` shows null until #everLocked). */
  #resolution: Resolution = 2048;
  #reason: ResolutionReason = 'unknown';
  /** The lock's remote kind (as #resolution). */
  #remote: RemoteKind = 'external';
  /** The internal remote's system byte (valid or not), or null. */
  #system: number | null = null;
  /** B0_* : how byte 0 of an internal remote is read. */
  #b0Mode = B0_FADES;
  /** The resolution the bytes fit when a forced one fits nothing, else null. */
  #forcedMismatch: Resolution | null = null;
  /** Why bytes that read as frames give none, until a lock (`format.withheld`). */
  #withheld: Withheld | null = null;
  /** The internal reading may be an external count whose low byte is a §8.3 system byte (`format.remoteAmbiguous`). */
  #ambiguous = false;
  /** Header bytes of the last emitted frame (for deltas and continuity), valid when #haveLast. */
  #last0 = 0;
  #last1 = 0;
  #haveLast = false;
  /** Whether a fade jump at the first frame after a lock is the receiver's own count (same remote, known layouts). */
  #jumpTrusted = false;
  /** The layout of the frame at stream offset #nextAt, read while confirming the one before it. */
  #nextAt = -1;
  #nextLayout = INVALID;
  #layouts = new Int32Array(LAYOUT_MEMORY);

  #layoutCount = 0;
  #layoutNext = 0;

  /**
   * Two sets of slot arrays: the one #frame shows, and one that holds the frame at stream
   * offset #stagedAt (-1: none), decoded by the fast path while it confirmed the frame before.
   * Emitting that frame then swaps the sets instead of decoding it again.
   */
  #shown = new FrameSlots();
  #staged = new FrameSlots();
  #stagedAt = -1;
  readonly #frame = createFrame(this.#shown);
  readonly #stats: DecoderStats = {
    bytes: 0,
    frames: 0,
    frameBytes: 0,
    discardedBytes: 0,
    pendingBytes: 0,
    resyncs: 0,
    badFrames: 0,
    emptySlots: 0,
    vtxFrames: 0,
    fadeJumps: 0,
  };

  /** Acquisition scratch: the best candidate's header reading. */
  #candInternal = false;
  #candSystem = 0;
  #candB0 = B0_FADES;
  #candFrames = 0;
  /** Index in the chain of a frame with a damaged header, skipped over (not confirmed), or -1. */
  #candSkipped = -1;
  /** The best score #score found for a chain that starts without channels (filler), since #best reset it; -1: none. */
  #fillerScore = -1;
  /** Who fixed the resolution, when it is fixed. */
  #fixedBy: 'user' | 'internal-remote' = 'user';

  /**
   * @throws {TypeError} when an option has a value outside its documented set.
   */
  constructor(options: DecoderOptions = {}) {
    const resolution = options.resolution ?? 'auto';
    const remote = options.remote ?? 'auto';
    const headerMode = options.headerMode ?? 'auto';
    if (resolution !== 'auto' && resolution !== 1024 && resolution !== 2048) {
      throw new TypeError(`resolution must be 'auto', 1024 or 2048, not ${String(resolution)}`);
    }
    if (remote !== 'auto' && remote !== 'internal' && remote !== 'external') {
      throw new TypeError(`remote must be 'auto', 'internal' or 'external', not ${String(remote)}`);
    }
    if (headerMode !== 'auto' && headerMode !== 'fades' && headerMode !== 'rssi') {
      throw new TypeError(`headerMode must be 'auto', 'fades' or 'rssi', not ${String(headerMode)}`);
    }
    if (options.onEvent !== undefined && typeof options.onEvent !== 'function') {
      throw new TypeError('onEvent must be a function');
    }
    if (options.fastPath !== undefined && typeof options.fastPath !== 'boolean') {
      throw new TypeError(`fastPath must be a boolean, not ${String(options.fastPath)}`);
    }
    this.#fastPath = options.fastPath ?? true;
    this.#options = { resolution, remote, headerMode };
    this.#fixedBy = options.resolutionFrom === 'internal-remote' ? 'internal-remote' : 'user';
    this.#onEvent = options.onEvent;
    // Written again, not only declared: a field written once the engine takes as constant, and
    // end() writing it then threw away the compiled decode (Chromium 156, the end of a long
    // capture's pass: #nextFast, #checkPush, the record walk's loop), which its first seek then
    // ran cold.
    this.#ended = false;
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
    // push() and this are kept this small so that they are inlined into the caller's loop whatever
    // else is (a compiler's budget for inlining runs out in a long loop, as a capture walk's), and
    // a chunk time goes on in a typed-array slot: a double handed to a call that is not inlined,
    // or to `instanceof`, is boxed (a 16-byte heap number every push).
    if (typeof time === 'number') {
      this.#pushedAt[0] = time;
      this.#pushTimed(bytes, start, end);
    } else this.#pushOther(bytes, start, end, time);
  }

  /** pushRange() of a chunk timed #pushedAt[0]. */
  #pushTimed(bytes: Uint8Array, start: number, end: number): void {
    this.#checkPush(bytes, start, end);
    const i = this.#append(bytes, null, start, end);
    if (i >= 0) this.#chunkTimes[i] = this.#pushedAt[0] ?? Number.NaN;
  }

  /** pushRange() of a chunk with per-byte times, or none. */
  #pushOther(bytes: Uint8Array, start: number, end: number, time: Float64Array | undefined): void {
    this.#checkPush(bytes, start, end);
    const perByte = time instanceof Float64Array;
    if (perByte && time.length !== bytes.length) {
      throw new TypeError(`per-byte times have length ${time.length}, bytes ${bytes.length}`);
    }
    const i = this.#append(bytes, perByte ? time : null, start, end);
    if (i >= 0) this.#chunkTimes[i] = Number.NaN;
  }

  /** @throws {TypeError} after `end()`, and for a range that is not one of `bytes` */
  #checkPush(bytes: Uint8Array, start: number, end: number): void {
    // `=== true` on the hot paths: optimised code tests a boolean field for every kind of falsy value otherwise.
    if (this.#ended === true) throw new TypeError('push() after end(): call reset() to decode a new stream');
    if (!(start >= 0 && start <= end && end <= bytes.length && (start | 0) === start && (end | 0) === end))
      throw new TypeError(`[${start}, ${end}) is not a range of ${bytes.length} bytes`);
  }

  /**
   * Takes a pushed chunk: copies its bytes (and per-byte times) into the buffer, compacting it
   * first and growing it (doubling) only when full, and records the chunk's end. Returns the
   * chunk's index, for the caller to store its time, or -1 for no bytes.
   *
   * One method for every kind of chunk, too big ever to be inlined (V8 inlines only below 460
   * bytes of bytecode): the push paths that call it stay small.
   */
  #append(bytes: Uint8Array, byteTimes: Float64Array | null, start: number, end: number): number {
    const n = end - start;
    if (n === 0) return -1;
    let times = this.#byteTimes;
    if (this.#head > 0 && (this.#tail + n > this.#buf.length || this.#head >= this.#buf.length >> 1)) {
      this.#buf.copyWithin(0, this.#head, this.#tail);
      times?.copyWithin(0, this.#head, this.#tail);
      this.#base += this.#head;
      this.#tail -= this.#head;
      this.#head = 0;
    }
    if (this.#tail + n > this.#buf.length) {
      // Doubled, or as much as this push needs (in whole 4 kB) when that is more: a stream pushed
      // whole takes its own size, not the next power of two (a quarter to a half more memory to
      // zero, fault in and collect).
      const capacity = Math.max(this.#buf.length * 2, Math.ceil((this.#tail + n) / 4096) * 4096);
      const buf = new Uint8Array(capacity);
      buf.set(this.#buf.subarray(0, this.#tail));
      this.#buf = buf;
      this.#buf32 = new Uint32Array(buf.buffer);
      this.#bufView = new DataView(buf.buffer);
      if (times !== null) {
        const grown = new Float64Array(capacity);
        grown.set(times.subarray(0, this.#tail));
        this.#byteTimes = times = grown;
      }
    }
    const at = this.#tail;
    const whole = start === 0 && end === bytes.length;
    if (whole) this.#buf.set(bytes, at);
    else if (n <= 64) {
      // A capture's chunk (the usual range): copied by hand four bytes at a time, cheaper than a
      // view for set(). The source's DataView is made once for all the ranges fed from it.
      if (bytes !== this.#source) {
        this.#source = bytes;
        this.#sourceView = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      }
      const from = this.#sourceView as DataView;
      const to = this.#bufView;
      let k = 0;
      for (; k + 4 <= n; k += 4) to.setInt32(at + k, from.getInt32(start + k));
      for (; k < n; k++) this.#buf[at + k] = bytes[start + k] as number;
    } else this.#buf.set(bytes.subarray(start, end), at);
    if (byteTimes !== null) {
      if (times === null) this.#byteTimes = times = new Float64Array(this.#buf.length);
      times.set(whole ? byteTimes : byteTimes.subarray(start, end), at);
    }
    // The chunk record: compacted when the arrays are full and mostly done with, else grown.
    if (this.#chunkTail === this.#chunkEnds.length) {
      const live = this.#chunkTail - this.#chunkHead;
      if (this.#chunkHead >= live) {
        this.#chunkEnds.copyWithin(0, this.#chunkHead, this.#chunkTail);
        this.#chunkTimes.copyWithin(0, this.#chunkHead, this.#chunkTail);
        this.#chunkPerByte.copyWithin(0, this.#chunkHead, this.#chunkTail);
      } else {
        const size = this.#chunkEnds.length * 2;
        const ends = new Float64Array(size);
        const chunkTimes = new Float64Array(size);
        const perBytes = new Uint8Array(size);
        ends.set(this.#chunkEnds.subarray(this.#chunkHead, this.#chunkTail));
        chunkTimes.set(this.#chunkTimes.subarray(this.#chunkHead, this.#chunkTail));
        perBytes.set(this.#chunkPerByte.subarray(this.#chunkHead, this.#chunkTail));
        this.#chunkEnds = ends;
        this.#chunkTimes = chunkTimes;
        this.#chunkPerByte = perBytes;
      }
      this.#chunkTail = live;
      this.#chunkHead = 0;
    }
    const i = this.#chunkTail++;
    this.#chunkEnds[i] = this.#base + at + n;
    this.#chunkPerByte[i] = byteTimes !== null ? 1 : 0;
    this.#tail = at + n;
    this.#stats.bytes += n;
    this.#stats.pendingBytes += n;
    return i;
  }

  /**
   * Marks the end of the stream: bytes still held are decided with what is there (a last frame
   * that continues the stream with a known layout is emitted without a following frame to
   * confirm it; anything else left is discarded).
   */
  end(): void {
    this.#ended = true;
    this.#source = this.#sourceView = null; // nothing more is copied from it
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
    if (resolution !== 'auto' && resolution !== 1024 && resolution !== 2048) {
      throw new TypeError(`resolution must be 'auto', 1024 or 2048, not ${String(resolution)}`);
    }
    const before = this.#options.resolution;
    const fixedBy = resolution === 'auto' ? 'user' : by;
    if (before === resolution && this.#fixedBy === fixedBy) return;
    this.#options.resolution = resolution;
    this.#fixedBy = fixedBy;
    this.#forcedMismatch = null;
    if (this.#withheld === 'forced') this.#withheld = null;
    if (!this.#locked) return;
    if (resolution === 'auto' ? this.#reason === 'override' || this.#reason === 'internal-remote' : resolution !== this.#resolution) {
      this.#unlock();
      this.#layoutCount = 0;
      this.#reason = 'unknown';
    } else {
      this.#setReason(this.#resolution);
    }
  }

  /** Forgets everything: buffered bytes, lock, format and counters. */
  reset(): void {
    this.#head = this.#tail = this.#base = 0;
    this.#source = this.#sourceView = null;
    this.#chunkHead = this.#chunkTail = 0;
    this.#ended = false;
    this.#locked = this.#everLocked = false;
    this.#confirmedUntil = 0;
    this.#nextAt = -1;
    this.#stagedAt = -1;
    this.#resolution = 2048;
    this.#reason = 'unknown';
    this.#remote = 'external';
    this.#system = null;
    this.#b0Mode = B0_FADES;
    this.#forcedMismatch = null;
    this.#withheld = null;
    this.#ambiguous = false;
    this.#haveLast = false;
    this.#jumpTrusted = false;
    this.#layoutCount = this.#layoutNext = 0;
    this.#frame.index = -1;
    const s = this.#stats;
    s.bytes = s.frames = s.frameBytes = s.discardedBytes = s.pendingBytes = 0;
    s.resyncs = s.badFrames = s.emptySlots = s.vtxFrames = s.fadeJumps = 0;
  }

  /** Live counters (the same object each time; read, don't write). */
  get stats(): Readonly<DecoderStats> {
    return this.#stats;
  }

  /** What the decoder has decided about the format, and why (a new object each call). */
  get format(): FormatInfo {
    return {
      locked: this.#locked,
      resolution: this.#everLocked ? this.#resolution : null,
      resolutionReason: this.#reason,
      explanation: this.#explain(),
      remote: this.#everLocked ? this.#remote : null,
      system: this.#system,
      systemValid: this.#system !== null && systemInfo(this.#system) !== undefined,
      headerMode: this.#headerReading(),
      forcedMismatch: this.#forcedMismatch,
      withheld: this.#withheld,
      remoteAmbiguous: this.#ambiguous,
    };
  }

  /**
   * The next decoded frame, or `undefined` when more bytes are needed. The frame is borrowed:
   * the same object is reused and is valid until the next call to `next()`, `push()`, `end()`
   * or `reset()`.
   */
  next(): DecodedFrame | undefined {
    // Kept small, so that it is inlined into the caller's loop beside push().
    if (this.#fastPath && this.#locked) {
      const frame = this.#nextFast();
      if (frame !== null) return frame;
    }
    return this.#nextGeneral();
  }

  /** next() on the general path: every rule, every case. */
  #nextGeneral(): DecodedFrame | undefined {
    for (;;) {
      if (!this.#locked) {
        if (!this.#acquire()) return undefined;
        continue;
      }
      const o = this.#head;
      const avail = this.#tail - o;
      if (avail < FRAME_SIZE) {
        if (this.#ended && avail > 0) this.#discard(o, avail, 'end-of-stream');
        return undefined;
      }
      const resolution = this.#resolution;
      const at = this.#base + o;
      const layout = at === this.#nextAt ? this.#nextLayout : slotLayout(this.#buf, o, resolution);
      // Frames acquisition confirmed go out as they stand.
      if (at < this.#confirmedUntil && layout !== INVALID) return this.#emit(o, layout);
      if (layout !== INVALID && this.#countMoved(o, layout)) this.#rereadExternal(o);
      const fits = layout !== INVALID && this.#fitsLast(o);
      if (fits) {
        // The whole next frame must be in: a header alone is too weak (`00 00` read one byte
        // late is `00 0c`, a count that rose by 12).
        if (avail < 2 * FRAME_SIZE) {
          if (!this.#ended) return undefined;
          // The stream's last frame: whole when the stream ends with it, or when what is left
          // after it starts with a header that continues it (a truncated last frame).
          if (
            this.#knownLayout(layout) &&
            (avail === FRAME_SIZE || (avail >= FRAME_SIZE + 2 && this.#standsAlone(o, layout, o + FRAME_SIZE)))
          ) {
            return this.#emit(o, layout);
          }
          this.#discard(o, avail, 'end-of-stream');
          return undefined;
        }
        const next = slotLayout(this.#buf, o + FRAME_SIZE, resolution);
        this.#nextAt = at + FRAME_SIZE;
        this.#nextLayout = next;
        if (next !== INVALID && this.#follows(o, o + FRAME_SIZE)) {
          if (this.#knownLayout(layout)) return this.#emit(o, layout);
          // A new layout: make sure no frame that continues the stream starts inside this one.
          const q = this.#search(o + 1, o + FRAME_SIZE - 1);
          if (q === NEED_MORE) return undefined;
          if (q === NOT_FOUND) return this.#emit(o, layout);
          this.#resync(o, q);
          continue;
        }
      }
      if (!fits && layout !== INVALID && this.#countJumped(o, layout)) {
        // The same remote goes on after lost frames (its fade count jumped): no frame that
        // continues the old count starts inside this one.
        const q = this.#search(o + 1, o + FRAME_SIZE - 1);
        if (q === NEED_MORE) return undefined;
        if (q === NOT_FOUND) {
          this.#jumpTrusted = true;
          return this.#emit(o, layout);
        }
      }
      // The frame at o does not continue the stream (or the next one does not continue it).
      const broken = this.#broken(o, layout, fits);
      if (broken === undefined) return undefined;
      if (broken !== null) return broken;
    }
  }

  // ---- locked path -------------------------------------------------------------------------

  /**
   * The frame at `o` does not continue the stream, or the frame after it does not continue it:
   * find where frames go on. Returns the frame at `o` when it is whole after all, null when the
   * caller should go round again (bytes were discarded, or the lock was let go), undefined when
   * more bytes are needed. Kept out of next() so that the common path stays small.
   */
  #broken(o: number, layout: number, fits: boolean): DecodedFrame | null | undefined {
    const q = this.#search(o + 1, o + MAX_RESYNC_BYTES);
    if (q === NEED_MORE) return undefined;
    // This remote's own chain that starts right after this frame (or at it) is the remote going
    // on after its count fell (a restart), not noise to skip on the way to a frame that
    // happens to fit the old count further on.
    const internal = this.#remote === 'internal';
    const restartAfter = internal && q !== NOT_FOUND && q > o + FRAME_SIZE && this.#ownChainAt(o + FRAME_SIZE);
    if (
      fits &&
      (q === NOT_FOUND ? this.#lastOfItsKind(o, layout) : (restartAfter && this.#knownLayout(layout)) || this.#standsAlone(o, layout, q))
    ) {
      // This frame is whole: what follows it up to q is noise, or something new starts after it.
      return this.#emit(o, layout);
    }
    if (!fits && internal && q !== NOT_FOUND && q >= o + FRAME_SIZE && this.#ownChainAt(o)) {
      this.#unlock();
      return null;
    }
    if (q !== NOT_FOUND) {
      this.#resync(o, q);
      return null;
    }
    // Nothing continues within reach: the format may have changed. Acquire afresh from here.
    this.#unlock();
    return null;
  }

  /**
   * The common locked case in one pass: the frame at the head has the layout read while
   * confirming the one before it (#nextAt), a known one; acquisition's confirmed frames are
   * behind; its header continues the last frame's with a fade step the general path would count
   * without an event; and the whole next frame is in, valid, and continues it. Then it is
   * emitted exactly as the general path would emit it. Anything else returns null and the
   * general path decides (it finds the same state: nothing it reads is changed before emitting).
   *
   * Each byte is read once: validating the next frame decodes it into the spare slot arrays
   * (#staged), which the frame shows when that one is emitted in turn.
   */
  #nextFast(): DecodedFrame | null | undefined {
    // Numbers are written out, each beside the constant it is (FRAME_SIZE, FADE_STEP, B0_*,
    // INVALID): optimised code reads a module's constants and imports from its context with a
    // hole check each time (see readFrame).
    const o = this.#head;
    const n = o + 16; // FRAME_SIZE
    const at = this.#base + o;
    // The whole next frame is not in: the general path would wait too, unless the stream has
    // ended or the frame is one acquisition confirmed (emitted as it stands).
    if (n + 16 > this.#tail) return this.#ended === true || at < this.#confirmedUntil ? null : undefined;
    if (at !== this.#nextAt || at < this.#confirmedUntil || this.#haveLast !== true) return null; // `=== true`: see push()
    const layout = this.#nextLayout;
    if (layout === -1 || !this.#knownLayout(layout)) return null; // INVALID
    const buf = this.#buf;
    const b0 = buf[o]!;
    const b1 = buf[o + 1]!;
    const internal = this.#remote === 'internal';
    let delta = 0;
    if (internal) {
      const mode = this.#b0Mode;
      if (b1 !== this.#system || buf[n + 1] !== b1) return null;
      // Byte 0 moving decides an ambiguous remote: the general path's job.
      if (this.#ambiguous === true && b0 !== this.#last0) return null;
      if (mode === 0) {
        // B0_FADES: #fitsLast and #follows with FADE_STEP, and #fadeDelta's rise without an event.
        delta = (b0 - this.#last0) & 0xff;
        if (delta >= 8 || ((buf[n]! - b0) & 0xff) >= 8) return null;
      } else if (mode === 1) {
        // B0_RSSI
        if (!plausibleRssi(b0) || !plausibleRssi(buf[n]!)) return null;
      } else if (mode !== 3) {
        return null; // B0_UNKNOWN (not B0_RSSI_FORCED): emitting may decide byte 0 (an event), the general path's job.
      }
    } else {
      const count = (b0 << 8) | b1;
      delta = (count - ((this.#last0 << 8) | this.#last1)) & 0xffff;
      if (delta >= 8 || ((((buf[n]! << 8) | buf[n + 1]!) - count) & 0xffff) >= 8) return null;
    }
    // This frame's slots: staged while the one before was confirmed, else decoded now.
    const resolution = this.#resolution;
    const slots = this.#staged;
    if (this.#stagedAt !== at) readFrame(buf, this.#buf32, o, resolution, slots);
    const spare = this.#shown;
    const next = readFrame(buf, this.#buf32, n, resolution, spare);
    if (next === -1) {
      // INVALID
      this.#stagedAt = at;
      return null;
    }
    this.#shown = slots;
    this.#staged = spare;
    this.#stagedAt = at + 16;
    this.#nextAt = at + 16;
    this.#nextLayout = next;
    const frame = this.#frame;
    frame.index++;
    frame.offset = at;
    this.#stampTime(frame, o);
    frame.resolution = resolution;
    if (internal) {
      frame.remote = 'internal';
      frame.system = b1;
      if (this.#b0Mode === 0) {
        frame.rssi = null;
        frame.fades = b0;
      } else {
        frame.rssi = b0 >= 0x80 ? b0 - 0x100 : b0;
        frame.fades = null;
      }
    } else {
      frame.remote = 'external';
      frame.system = null;
      frame.rssi = null;
      frame.fades = (b0 << 8) | b1;
    }
    frame.fadesDelta = delta;
    this.#last0 = b0;
    this.#last1 = b1;
    this.#jumpTrusted = false;
    showSlots(frame, slots);
    return this.#counted(frame, o, slots);
  }

  /** Whether the header at `o` continues the last emitted frame under the lock's model. */
  #fitsLast(o: number): boolean {
    const b = this.#buf;
    const b0 = byteAt(b, o);
    const b1 = byteAt(b, o + 1);
    if (this.#remote === 'internal') {
      if (b1 !== this.#system) return false;
      return this.#haveLast ? byte0Follows(this.#last0, b0, this.#b0Mode) : this.#b0Mode !== B0_RSSI || b0 >= 0x80;
    }
    const word = (b0 << 8) | b1;
    return !this.#haveLast || countFollows((this.#last0 << 8) | this.#last1, word);
  }

  /** Whether the frame at `b` can be the frame right after the one at `a` under the lock's model. */
  #follows(a: number, b: number): boolean {
    const buf = this.#buf;
    if (this.#remote === 'internal') {
      return buf[b + 1] === this.#system && byte0Follows(byteAt(buf, a), byteAt(buf, b), this.#b0Mode);
    }
    return countFollows((byteAt(buf, a) << 8) | byteAt(buf, a + 1), (byteAt(buf, b) << 8) | byteAt(buf, b + 1));
  }

  /**
   * Whether the frame at `o` is the same internal remote going on with a fade count that jumped:
   * a known layout, its own system byte, and a whole next frame that continues it.
   */
  #countJumped(o: number, layout: number): boolean {
    const buf = this.#buf;
    // An external count has no system byte to vouch for it: a jump there may be an internal
    // remote taking over (`00 00` then `00 B2`), which acquisition decides.
    if (this.#remote !== 'internal' || !this.#knownLayout(layout) || o + 2 * FRAME_SIZE > this.#tail) return false;
    if (buf[o + 1] !== this.#system || (this.#b0Mode === B0_RSSI && !plausibleRssi(byteAt(buf, o)))) return false;
    // Fades rise: a fall is something else (a restarted receiver, RSSI), for acquisition to read.
    if (this.#b0Mode !== B0_RSSI && this.#haveLast && ((byteAt(buf, o) - this.#last0) & 0xff) >= 0x80) return false;
    return slotLayout(buf, o + FRAME_SIZE, this.#resolution) !== INVALID && this.#follows(o, o + FRAME_SIZE);
  }

  /**
   * The nearest offset in [from, to] where frames continue: a frame with a known layout that
   * continues the stream, confirmed by the frame after it; or, before that one, a frame that
   * stands alone (see #standsAlone). NOT_FOUND, or NEED_MORE when the answer depends on bytes
   * that have not arrived.
   */
  #search(from: number, to: number): number {
    const resolution = this.#resolution;
    const buf = this.#buf;
    let alone = NOT_FOUND;
    let aloneLayout = INVALID;
    for (let q = from; q <= to; q++) {
      if (q + 2 * FRAME_SIZE > this.#tail) return this.#ended ? NOT_FOUND : NEED_MORE;
      const layout = slotLayout(buf, q, resolution);
      if (layout === INVALID || !this.#fitsLast(q) || !this.#knownLayout(layout)) continue;
      if (slotLayout(buf, q + FRAME_SIZE, resolution) !== INVALID && this.#follows(q, q + FRAME_SIZE)) {
        return alone !== NOT_FOUND && this.#standsAlone(alone, aloneLayout, q) ? alone : q;
      }
      if (alone === NOT_FOUND) {
        alone = q;
        aloneLayout = layout;
      }
    }
    return NOT_FOUND;
  }

  /**
   * Whether the frame at `o`, which continues the last frame but is not continued by a valid next
   * frame, is whole, with frames going on at `q`. Bytes lost or added inside `o` can leave a
   * frame that reads as whole (its front glued to another's back, a stray byte in its last
   * slot), and no rule on content tells that from noise after a whole frame; so it stands alone
   * only when the next frame's header sits where `o` ends and continues it (that frame is the
   * truncated one), and only an internal remote's system byte and fade byte are strong enough
   * to say so. Otherwise it is dropped with the damage (the frame beside damage may go).
   */
  #standsAlone(o: number, layout: number, q: number): boolean {
    if (q < o + FRAME_SIZE || !this.#knownLayout(layout)) return false;
    const buf = this.#buf;
    const n = o + FRAME_SIZE;
    // An external count (often `00 00`) is too weak a header to stand on: zero bytes abound in slots.
    return this.#remote === 'internal' && buf[n + 1] === this.#system && byte0Follows(byteAt(buf, o), byteAt(buf, n), this.#b0Mode);
  }

  /**
   * Whether the frame at `o` may be the last of the stream's current kind (nothing within reach
   * continues it): its layout is known and a new kind of stream starts right where it ends
   * (two valid frames at any resolution whose headers continue each other), so that nothing
   * was lost inside it.
   */
  #lastOfItsKind(o: number, layout: number): boolean {
    if (!this.#knownLayout(layout)) return false;
    const a = o + FRAME_SIZE;
    if (this.#haveLast && a + FRAME_SIZE <= this.#tail && slotLayout(this.#buf, a, this.#resolution) !== INVALID && this.#fitsLast(a))
      return false;
    return this.#chainStartsAt(a) === 1;
  }

  /**
   * Whether two valid frames of this internal remote start at `a`: its system byte in both and
   * a byte 0 that goes on from one to the other. Needs only bytes the search has already seen.
   */
  #ownChainAt(a: number): boolean {
    const buf = this.#buf;
    const b = a + FRAME_SIZE;
    if (b + FRAME_SIZE > this.#tail) return false;
    const resolution = this.#resolution;
    return (
      buf[a + 1] === this.#system &&
      buf[b + 1] === this.#system &&
      slotLayout(buf, a, resolution) !== INVALID &&
      slotLayout(buf, b, resolution) !== INVALID &&
      byte0Follows(byteAt(buf, a), byteAt(buf, b), this.#b0Mode)
    );
  }

  /**
   * Whether a stream starts at `a` as acquisition would lock on it: a chain of frames of one
   * remote at either resolution (two frames that parse are common in slot bytes read as
   * headers, so it takes the same evidence as a lock).
   */
  #chainStartsAt(a: number): 0 | 1 | typeof NEED_MORE {
    // The answer must not depend on how the bytes were chunked: wait for a whole window.
    if (this.#tail - a < ACQUIRE_FRAMES * FRAME_SIZE && !this.#ended) return NEED_MORE;
    const frames = Math.min(ACQUIRE_FRAMES, Math.floor((this.#tail - a) / FRAME_SIZE));
    if (frames < MIN_CHAIN) return 0;
    const forced = this.#options.resolution;
    return (forced !== 1024 && this.#score(a, 2048, frames) >= 0) || (forced !== 2048 && this.#score(a, 1024, frames) >= 0) ? 1 : 0;
  }

  /** Discards the bytes from `o` up to `q`, where frames continue. */
  #resync(o: number, q: number): void {
    this.#stats.resyncs++;
    this.#stats.badFrames++;
    this.#event({ type: 'resync', offset: this.#base + q });
    this.#discard(o, q - o, q - o < FRAME_SIZE ? 'truncated-frame' : 'noise');
  }

  #unlock(): void {
    this.#locked = false;
    this.#confirmedUntil = 0;
    this.#nextAt = -1;
    this.#stagedAt = -1;
  }

  #knownLayout(layout: number): boolean {
    const layouts = this.#layouts;
    for (let i = 0; i < this.#layoutCount; i++) if (layouts[i] === layout) return true;
    return false;
  }

  #learnLayout(layout: number): void {
    if (this.#knownLayout(layout)) return;
    this.#layouts[this.#layoutNext] = layout;
    this.#layoutNext = (this.#layoutNext + 1) % LAYOUT_MEMORY;
    if (this.#layoutCount < LAYOUT_MEMORY) this.#layoutCount++;
  }

  #emit(o: number, layout: number): DecodedFrame {
    this.#learnLayout(layout);
    const buf = this.#buf;
    const frame = this.#frame;
    const resolution = this.#resolution;
    frame.index++;
    frame.offset = this.#base + o;
    this.#stampTime(frame, o);
    frame.resolution = resolution;
    const remote = this.#remote;
    frame.remote = remote;
    const b0 = byteAt(buf, o);
    const b1 = byteAt(buf, o + 1);
    let delta = 0;
    if (remote === 'internal') {
      frame.system = b1;
      // Byte 0 moved under a still byte 1: an internal remote (an external count moves its low
      // byte first). The reading stands, only surer: no event.
      if (this.#ambiguous && this.#haveLast && b0 !== this.#last0) this.#ambiguous = false;
      if (this.#b0Mode === B0_UNKNOWN && this.#haveLast) this.#decideByte0(o, b0);
      if (this.#b0Mode === B0_RSSI || this.#b0Mode === B0_RSSI_FORCED) {
        frame.rssi = b0 >= 0x80 ? b0 - 0x100 : b0;
        frame.fades = null;
      } else if (this.#b0Mode === B0_UNKNOWN) {
        frame.rssi = null;
        frame.fades = null;
      } else {
        frame.rssi = null;
        frame.fades = b0;
        if (this.#haveLast) delta = this.#fadeDelta(o, this.#last0, b0, 0xff);
      }
    } else {
      const count = (b0 << 8) | b1;
      frame.system = null;
      frame.rssi = null;
      frame.fades = count;
      if (this.#haveLast) delta = this.#fadeDelta(o, (this.#last0 << 8) | this.#last1, count, 0xffff);
    }
    frame.fadesDelta = delta;
    this.#last0 = b0;
    this.#last1 = b1;
    this.#haveLast = true;
    this.#jumpTrusted = false;
    const slots = this.#shown;
    readFrame(buf, this.#buf32, o, resolution, slots);
    showSlots(frame, slots);
    return this.#counted(frame, o, slots);
  }

  /** Counts the frame just filled at `o` from `slots` and moves past it: both emit paths end here. */
  #counted(frame: DecodedFrame, o: number, slots: FrameSlots): DecodedFrame {
    const s = this.#stats;
    s.frames++;
    s.frameBytes += 16; // FRAME_SIZE, written out as in #nextFast
    s.pendingBytes -= 16;
    s.emptySlots += slots.empty;
    if (slots.hasVtx === true) s.vtxFrames++; // `=== true`: see push()
    this.#head = o + 16;
    return frame;
  }

  /**
   * Fades since the last frame. Within a chain the rise is below FADE_STEP. A larger one only
   * comes after a new lock: it is the receiver's own count (and counted) when the same remote
   * continues with layouts it used before and the counter rose by less than half its range;
   * anything else is reported as a `fade-jump` and counts nothing.
   */
  #fadeDelta(o: number, from: number, to: number, mask: number): number {
    const delta = (to - from) & mask;
    if (delta < FADE_STEP) return delta;
    const counted = this.#jumpTrusted && delta <= mask >> 1;
    if (!counted) this.#stats.fadeJumps++;
    this.#event({ type: 'fade-jump', offset: this.#base + o, from, to, counted });
    return counted ? delta : 0;
  }

  /** An internal remote whose byte 0 was undecided: a value no RSSI takes says fades, a fall says RSSI. */
  #decideByte0(o: number, b0: number): void {
    if (!plausibleRssi(b0)) this.#b0Mode = B0_FADES;
    else if (b0 < this.#last0) this.#b0Mode = B0_RSSI;
    else return;
    this.#event({ type: 'format-changed', offset: this.#base + o, format: this.format });
  }

  #discard(o: number, length: number, reason: 'before-lock' | 'noise' | 'truncated-frame' | 'end-of-stream'): void {
    this.#stats.discardedBytes += length;
    this.#stats.pendingBytes -= length;
    // Before the chunk records go: the event is timed by them.
    this.#event({ type: 'discarded', offset: this.#base + o, length, reason });
    this.#head = o + length;
    // A stream that never locks emits nothing: its chunk records must go with its bytes.
    this.#dropChunksBefore(this.#base + this.#head);
  }

  // ---- acquisition -------------------------------------------------------------------------

  /** Tries to lock at the head. Returns false when it needs more bytes (or the stream is done). */
  #acquire(): boolean {
    const p = this.#head;
    const avail = this.#tail - p;
    const window = ACQUIRE_FRAMES * FRAME_SIZE + ACQUIRE_SHIFTS - 1;
    if (avail < window && !this.#ended) return false;
    const lost = this.#everLocked ? 'noise' : 'before-lock';
    if (avail < FRAME_SIZE) {
      if (avail > 0) this.#discard(p, avail, this.#everLocked ? 'end-of-stream' : 'before-lock');
      return false;
    }
    const forced = this.#options.resolution;
    let best = this.#best(p, avail, forced === 'auto' ? 0 : forced, false);
    if (best.filler) this.#withhold('filler', p);
    else if (forced !== 'auto' || this.#options.remote !== 'auto' || this.#options.headerMode !== 'auto')
      best = this.#matchForced(p, avail, best);
    if (best.score < 0 || (best.shift >= ACQUIRE_COMMIT && avail >= window)) {
      // No alignment starting in these 16 bytes works (or the best starts too late to commit).
      this.#discard(p, Math.min(FRAME_SIZE, avail), lost);
      return true;
    }
    let o = p + best.shift;
    const resolution = best.resolution;
    // Score again to leave the winner's header reading in the scratch fields.
    this.#score(o, resolution, Math.min(ACQUIRE_FRAMES, Math.floor((avail - best.shift) / FRAME_SIZE)));
    let frames = this.#candFrames;
    let skipped = this.#candSkipped;
    const internal = this.#candInternal;
    const system = this.#candSystem;
    // A start that scored best can be a frame late (its chain's layouts recur better): take in
    // the frames before it that the chain continues from.
    while (o - FRAME_SIZE >= p && this.#chainsInto(o - FRAME_SIZE, o, resolution, internal, system)) {
      o -= FRAME_SIZE;
      frames++;
      if (skipped >= 0) skipped++;
    }
    const sameRemote =
      this.#haveLast &&
      this.#remote === (internal ? 'internal' : 'external') &&
      (internal ? this.#system === system : true) &&
      this.#resolution === resolution;
    let b0Mode = this.#candB0;
    // The same remote going on keeps what its byte 0 was shown to be: where byte 0 goes on, and
    // where it jumped across a break with the layouts it used before (a 1.5 s dropout takes a
    // fade count from 40 to 176, which reads as RSSI as well until it moves).
    if (
      internal &&
      b0Mode === B0_UNKNOWN &&
      sameRemote &&
      (byte0Follows(this.#last0, byteAt(this.#buf, o), this.#b0Mode) || this.#chainKnown(o, resolution, frames))
    )
      b0Mode = this.#b0Mode;
    if (internal && b0Mode === B0_UNKNOWN) {
      // Byte 0 has only been a plausible RSSI and never fallen: read further along the chain before deciding.
      const evidence = this.#byte0Evidence(o, resolution, system);
      if (evidence === NEED_MORE) return false;
      b0Mode = evidence;
    }
    // Byte 0 still under a §8.3 system byte reads as an external count whose low byte is that
    // byte as well (18, 162, 178, 434 ...): the bytes tell only when byte 0 moves (internal) or
    // byte 1 does (external; see #countMoved). A remote shown internal that goes on stays so.
    const ambiguous =
      internal &&
      this.#options.remote === 'auto' &&
      b0Mode !== B0_RSSI_FORCED &&
      systemInfo(system) !== undefined &&
      this.#byte0Still(o, frames) &&
      !(sameRemote && !this.#ambiguous);
    if (o > p) this.#discard(p, o - p, lost);
    if (this.#resolution !== resolution) this.#layoutCount = 0;
    // A count that jumped across the break is the receiver's own when the same remote goes on
    // with layouts it used before (a shifted reading of the stream makes layouts of its own).
    this.#jumpTrusted = sameRemote && this.#chainKnown(o, resolution, frames);
    if (!sameRemote) this.#haveLast = false;
    const changed =
      this.#everLocked &&
      (this.#remote !== (internal ? 'internal' : 'external') ||
        this.#system !== (internal ? system : null) ||
        this.#resolution !== resolution);
    this.#locked = true;
    this.#nextAt = -1;
    this.#everLocked = true;
    this.#forcedMismatch = null;
    this.#withheld = null;
    // Each frame of the chain is confirmed by the one after it; the last waits for its own next
    // (or the stream's end) like any other, and so does a frame with a damaged header.
    const confirmed = skipped >= 0 ? skipped : frames - (this.#ended && o + frames * FRAME_SIZE >= this.#tail - FRAME_SIZE ? 0 : 1);
    this.#confirmedUntil = this.#base + o + confirmed * FRAME_SIZE;
    this.#resolution = resolution;
    this.#remote = internal ? 'internal' : 'external';
    this.#system = internal ? system : null;
    this.#b0Mode = internal ? b0Mode : B0_FADES;
    this.#ambiguous = ambiguous;
    this.#setReason(resolution);
    this.#event({ type: 'locked', offset: this.#base + o, format: this.format });
    if (changed) this.#event({ type: 'format-changed', offset: this.#base + o, format: this.format });
    return true;
  }

  /**
   * Says why bytes that read as frames give none (`format.withheld`), with a format-changed
   * event when the reason is new: it stands until a lock.
   */
  #withhold(why: Withheld, o: number): void {
    if (this.#withheld === why) return;
    this.#withheld = why;
    this.#event({ type: 'format-changed', offset: this.#base + o, format: this.format });
  }

  /** Whether `layout` is the layout of one of the `frames` frames from `o`. */
  #layoutInChain(layout: number, o: number, frames: number, resolution: Resolution): boolean {
    for (let k = 0; k < frames; k++) if (slotLayout(this.#buf, o + k * FRAME_SIZE, resolution) === layout) return true;
    return false;
  }

  /**
   * Whether the frame at `a` is valid, has a layout of the chain that starts at `b`, and its
   * header continues into frame `b`'s as acquisition chains them.
   */
  #chainsInto(a: number, b: number, resolution: Resolution, internal: boolean, system: number): boolean {
    const buf = this.#buf;
    const layout = slotLayout(buf, a, resolution);
    if (
      layout === INVALID ||
      !this.#layoutInChain(layout, b, Math.min(ACQUIRE_FRAMES, Math.floor((this.#tail - b) / FRAME_SIZE)), resolution)
    )
      return false;
    if (internal) {
      const mode = this.#options.headerMode === 'rssi' ? B0_RSSI_FORCED : this.#options.headerMode === 'fades' ? B0_FADES : B0_UNKNOWN;
      return buf[a + 1] === system && buf[b + 1] === system && byte0Follows(byteAt(buf, a), byteAt(buf, b), mode, ACQUIRE_FADE_STEP);
    }
    return countFollows((byteAt(buf, a) << 8) | byteAt(buf, a + 1), (byteAt(buf, b) << 8) | byteAt(buf, b + 1), ACQUIRE_FADE_STEP);
  }

  /**
   * The best-scoring start among the next ACQUIRE_SHIFTS offsets, at one resolution or (0) both.
   * None (score -1, `filler`) when a chain that starts without channels (see
   * EVIDENCE_BYTES) reads better than any that starts with them: those are then shifted
   * readings of the filler and its headers (`00 B2` then seven 0xFFFF slots, read a byte
   * early, has a channel 6 at 0x2FF), not frames.
   */
  #best(p: number, avail: number, only: 0 | Resolution, free: boolean): Best {
    this.#fillerScore = -1;
    let score = -1;
    let shift = 0;
    let resolution: Resolution = 2048;
    // Where no start can carry a channel, no chain leads: all that is left to learn is whether
    // the bytes parse as filler, which the first reading that parses tells (runs of 0xFF or
    // 0x00 would otherwise be scored at every shift, both ways, again every 16 bytes).
    const leadable = this.#leadable(p, avail);
    for (let s = 0; s < ACQUIRE_SHIFTS; s++) {
      if (!leadable && this.#fillerScore > -1) break;
      const frames = Math.min(ACQUIRE_FRAMES, Math.floor((avail - s) / FRAME_SIZE));
      if (frames < 1) break;
      if (only !== 1024) {
        const v = this.#score(p + s, 2048, frames, free);
        if (v > score) {
          score = v;
          shift = s;
          resolution = 2048;
        }
      }
      if (only !== 2048) {
        const v = this.#score(p + s, 1024, frames, free);
        if (v > score) {
          score = v;
          shift = s;
          resolution = 1024;
        }
      }
    }
    const filler = this.#fillerScore > score;
    return { score: filler ? -1 : score, shift, resolution, filler };
  }

  /**
   * Whether a frame starting at one of the next ACQUIRE_SHIFTS offsets has EVIDENCE_BYTES bytes
   * other than 0x00 and 0xFF after its header: what `channelEvidence` needs at the least, so
   * where none has, no chain can lead.
   */
  #leadable(p: number, avail: number): boolean {
    const buf = this.#buf;
    const filler = (i: number): number => {
      const b = byteAt(buf, i);
      return b === 0 || b === 0xff ? 0 : 1;
    };
    const words = FRAME_SIZE - 2;
    let n = 0;
    for (let i = p + 2; i < p + 2 + words && i < p + avail; i++) n += filler(i);
    for (let s = 0; s < ACQUIRE_SHIFTS && s + FRAME_SIZE <= avail; s++) {
      if (n >= EVIDENCE_BYTES) return true;
      n += (s + FRAME_SIZE < avail ? filler(p + s + FRAME_SIZE) : 0) - filler(p + s + 2);
    }
    return false;
  }

  /**
   * Forced options choose how frames are read, never where they lie: the best reading under
   * them (`best`) stands only at the alignment the bytes show with no option forced. A shifted
   * reading can fit a forced option that the frames do not (1024 forced on DSMX 22 ms 2048
   * frames reads slots as headers; a channel held still reads as an internal remote's system
   * byte), and its frames would match nothing that was sent. Where nothing reads as frames
   * with no option forced there is no lock yet (none, score -1). At the free reading's
   * alignment the forced reading is scored again; where it fits no frame there, the result is
   * none, `format.withheld` is 'forced' and `forcedMismatch` names the resolution the frames
   * have when it is not the forced one (both stand until a lock or a new setting: no need to
   * score again meanwhile).
   */
  #matchForced(p: number, avail: number, best: Best): Best {
    if (best.score < 0 && this.#withheld === 'forced') return best;
    const free = this.#best(p, avail, 0, true);
    if (free.score < 0) return free;
    if (best.score >= 0 && (best.shift - free.shift) % FRAME_SIZE === 0) return best;
    const frames = Math.min(ACQUIRE_FRAMES, Math.floor((avail - free.shift) / FRAME_SIZE));
    const forced = this.#options.resolution;
    let score = -1;
    let resolution: Resolution = free.resolution;
    for (const r of forced === 'auto' ? ([2048, 1024] as const) : [forced]) {
      const v = this.#score(p + free.shift, r, frames);
      if (v > score) {
        score = v;
        resolution = r;
      }
    }
    if (score >= 0) return { score, shift: free.shift, resolution, filler: false };
    this.#forcedMismatch = forced !== 'auto' && free.resolution !== forced ? free.resolution : null;
    this.#withhold('forced', p);
    return { score: -1, shift: 0, resolution, filler: false };
  }

  /** Whether byte 0 is the same in each of the `frames` frames from `o`. */
  #byte0Still(o: number, frames: number): boolean {
    const b0 = byteAt(this.#buf, o);
    for (let k = 1; k < frames; k++) if (byteAt(this.#buf, o + k * FRAME_SIZE) !== b0) return false;
    return true;
  }

  /**
   * Whether the frame at `o` (valid, its layout `layout`) shows that the internal remote the
   * lock may have misread (#ambiguous) is an external one whose count moved in its low byte:
   * byte 1, a true system byte that never changes, rose as a count does from the last frame,
   * with a layout the lock knows, and the whole next frame goes on as that count (a flipped
   * bit in byte 1 goes back).
   */
  #countMoved(o: number, layout: number): boolean {
    if (!this.#ambiguous || !this.#haveLast || !this.#knownLayout(layout) || o + 2 * FRAME_SIZE > this.#tail) return false;
    const buf = this.#buf;
    const last = (this.#last0 << 8) | this.#last1;
    const count = (byteAt(buf, o) << 8) | byteAt(buf, o + 1);
    if (count === last || !countFollows(last, count)) return false;
    const next = (byteAt(buf, o + FRAME_SIZE) << 8) | byteAt(buf, o + FRAME_SIZE + 1);
    return slotLayout(buf, o + FRAME_SIZE, this.#resolution) !== INVALID && countFollows(count, next);
  }

  /** The lock read an external remote as internal (#ambiguous): it reads it as the external one it is from here. */
  #rereadExternal(o: number): void {
    this.#remote = 'external';
    this.#system = null;
    this.#b0Mode = B0_FADES;
    this.#ambiguous = false;
    this.#nextAt = -1;
    this.#stagedAt = -1;
    this.#setReason(this.#resolution);
    this.#event({ type: 'format-changed', offset: this.#base + o, format: this.format });
  }

  /** Whether every frame of the chain at `o` has a layout the lock knows. */
  #chainKnown(o: number, resolution: Resolution, frames: number): boolean {
    for (let k = 0; k < frames; k++) if (!this.#knownLayout(slotLayout(this.#buf, o + k * FRAME_SIZE, resolution))) return false;
    return true;
  }

  /**
   * Reads byte 0 along the chain at `o` (an internal remote whose byte 0 has only been a plausible
   * RSSI): B0_FADES on a value no RSSI takes, B0_RSSI on a fall, B0_UNKNOWN after HEADER_EVIDENCE_FRAMES
   * without either (or where the chain ends), NEED_MORE when more bytes could decide it.
   */
  #byte0Evidence(o: number, resolution: Resolution, system: number): number {
    const buf = this.#buf;
    let prev = byteAt(buf, o);
    for (let k = 1; k < HEADER_EVIDENCE_FRAMES; k++) {
      const f = o + k * FRAME_SIZE;
      if (f + FRAME_SIZE > this.#tail) return this.#ended ? B0_UNKNOWN : NEED_MORE;
      const b0 = byteAt(buf, f);
      if (buf[f + 1] !== system || slotLayout(buf, f, resolution) === INVALID || !byte0Follows(prev, b0, B0_UNKNOWN, ACQUIRE_FADE_STEP))
        return B0_UNKNOWN;
      if (!plausibleRssi(b0)) return B0_FADES;
      if (b0 < prev) return B0_RSSI;
      prev = b0;
    }
    return B0_UNKNOWN;
  }

  /**
   * How well the frames at `o` (up to `frames`) read as consecutive frames of one remote at
   * `resolution`; -1 when fewer than MIN_CHAIN do. The chain ends at the first invalid frame or header
   * that does not continue it (a damaged frame ahead shortens it, and a shorter chain scores
   * less). Leaves the reading in #candInternal / #candSystem / #candB0 and its length in
   * #candFrames.
   */
  #score(o: number, resolution: Resolution, frames: number, free = false): number {
    const buf = this.#buf;
    const { remote, headerMode } = free ? FREE : this.#options;
    const s = byteAt(buf, o + 1);
    const forcedB0 = headerMode === 'rssi' ? B0_RSSI_FORCED : headerMode === 'fades' ? B0_FADES : B0_UNKNOWN;
    // How far each header reading carries the chain.
    let chainI = remote === 'external' ? 0 : frames;
    let chainE = remote === 'internal' ? 0 : frames;
    let zeroByte0 = false;
    const info = systemInfo(s);
    // Under a §8.3 system byte, one frame inside the chain may have a damaged header (a flipped
    // bit): it is skipped over, not confirmed, and costs score.
    let damaged = -1;
    let good = o;
    for (let k = 0; k < frames; k++) {
      const f = o + k * FRAME_SIZE;
      if (buf[f] === 0) zeroByte0 = true;
      if (slotLayout(buf, f, resolution) === INVALID) {
        chainI = Math.min(chainI, k);
        chainE = Math.min(chainE, k);
        break;
      }
      if (k === 0) continue;
      const p = f - FRAME_SIZE;
      if (chainI > k) {
        if (buf[f + 1] === s && byte0Follows(byteAt(buf, good), byteAt(buf, f), forcedB0, ACQUIRE_FADE_STEP)) good = f;
        else if (damaged < 0 && info !== undefined && k < frames - 1) damaged = k;
        else chainI = k;
      }
      if (
        chainE > k &&
        !countFollows((byteAt(buf, p) << 8) | byteAt(buf, p + 1), (byteAt(buf, f) << 8) | byteAt(buf, f + 1), ACQUIRE_FADE_STEP)
      )
        chainE = k;
      if (chainI <= k && chainE <= k) break;
    }
    // A skipped frame counts only when good frames follow it.
    if (damaged >= 0 && chainI <= damaged + 1) chainI = Math.min(chainI, damaged);
    // Both readings hold as far: §8.3 names four system bytes. Any other byte 1 is an external
    // fade count (one above 255 keeps byte 1 still between fades), unless this stream's remote
    // was internal and byte 0 is never zero (`03 55`): then it is a system byte to ignore
    // (§8.3). `00 xx` is a count below 256, the header of an external remote (or a clone).
    // A header that continues the last one as a rising count is that count moving, though.
    const countGoesOn =
      this.#haveLast &&
      countFollows((this.#last0 << 8) | this.#last1, (byteAt(buf, o) << 8) | s) &&
      ((byteAt(buf, o) << 8) | s) !== ((this.#last0 << 8) | this.#last1);
    const preferInternal =
      remote === 'internal' || info !== undefined || (s !== 0 && !zeroByte0 && !countGoesOn && this.#remote === 'internal');
    const internal = chainI > chainE || (chainI === chainE && preferInternal);
    const length = internal ? chainI : chainE;
    const skipped = internal && damaged >= 0 && damaged < length ? damaged : -1;
    // Where the stream ends too: fewer frames are no evidence (its last frames may go). An
    // unlisted system byte (read as one only after an internal remote) needs a full window.
    if (length < (internal && info === undefined ? ACQUIRE_FRAMES : MIN_CHAIN)) return -1;
    if (internal && info !== undefined && info.resolution !== resolution && (free || this.#options.resolution === 'auto')) {
      // Contradict a §8.3 system byte only where its resolution cannot read the frames.
      let readable = 0;
      for (let k = 0; k < length; k++) if (slotLayout(buf, o + k * FRAME_SIZE, info.resolution) !== INVALID) readable++;
      if (readable === length) return -1;
    }
    let positive = false;
    let fell = false;
    let channels = 0;
    let zeroWords = 0;
    let recurring = 0;
    let layout1 = INVALID;
    let layout2 = INVALID;
    let leads = false;
    for (let k = 0; k < length; k++) {
      const f = o + k * FRAME_SIZE;
      const layout = slotLayout(buf, f, resolution);
      if (k === 0) leads = channelEvidence(buf, f, layout) >= EVIDENCE_BYTES;
      const b0 = byteAt(buf, f);
      if (!plausibleRssi(b0)) positive = true;
      else if (k > 0 && b0 < byteAt(buf, f - FRAME_SIZE)) fell = true;
      if (layout === layout2) recurring++;
      layout2 = layout1;
      layout1 = layout;
      channels |= layoutChannels(layout);
      zeroWords += countZeroWords(buf, f);
    }
    if (!internal && this.#readsInternalLate(o, resolution, length)) return -1;
    // Transmitters repeat their layouts (a pair of frames, mostly): a first frame whose layout
    // comes nowhere else in the chain may be damage (a stray byte that made a slot), not a frame.
    if (length >= MIN_CHAIN && !this.#layoutInChain(slotLayout(buf, o, resolution), o + FRAME_SIZE, length - 1, resolution)) return -1;
    let score = 10 * length + recurring - zeroWords - (skipped >= 0 ? 5 : 0);
    if (internal) {
      // A §8.3 system byte in every frame is strong evidence of an internal remote.
      if (info !== undefined) score += 8;
      if (info?.resolution === resolution) score += 2;
    } else if (((byteAt(buf, o) << 8) | s) < 256) {
      score += 1;
    }
    // A header of 0xFFFF is an empty slot's filler more often than a fade count at its limit.
    if (((byteAt(buf, o) << 8) | s) === 0xffff) score -= 3;
    // Transmitters send channels 0…N-1: a contiguous set is the signature of the right reading.
    if ((channels & (channels + 1)) === 0) score += 2;
    // A chain whose first frame carries no channel is filler that happens to parse (or
    // filler whose chain runs into the frames after it): never a lock, but #best weighs it
    // against the other readings.
    if (!leads) {
      if (score > this.#fillerScore) this.#fillerScore = score;
      return -1;
    }
    this.#candInternal = internal;
    this.#candSystem = s;
    this.#candFrames = length;
    this.#candSkipped = skipped;
    this.#candB0 = forcedB0 !== B0_UNKNOWN ? forcedB0 : positive ? B0_FADES : fell ? B0_RSSI : B0_UNKNOWN;
    return score;
  }

  /**
   * Whether the external reading at `o` is an internal remote's stream read at the wrong offset:
   * a slot whose low byte is a §8.3 system byte, where frames starting at that slot (as their
   * header) are valid internal frames with that system byte, for as many frames as the reading
   * has. A 1024-mode internal remote read two bytes late otherwise looks like an external one
   * whose fade count is channel 0's position.
   */
  #readsInternalLate(o: number, resolution: Resolution, length: number): boolean {
    const buf = this.#buf;
    for (let i = 0; i < 7; i++) {
      const system = byteAt(buf, o + 3 + 2 * i);
      if (systemInfo(system) === undefined) continue;
      let agree = 0;
      for (let h = o + 2 + 2 * i - FRAME_SIZE; h + FRAME_SIZE <= this.#tail && h < o + length * FRAME_SIZE; h += FRAME_SIZE) {
        if (h >= this.#head && buf[h + 1] === system && slotLayout(buf, h, resolution) !== INVALID) agree++;
      }
      if (agree >= Math.max(2, length - 1)) return true;
    }
    return false;
  }

  #headerReading(): HeaderReading {
    if (this.#remote !== 'internal') return 'fades';
    if (this.#b0Mode === B0_UNKNOWN) return 'unknown';
    return this.#b0Mode === B0_FADES ? 'fades' : 'rssi';
  }

  #setReason(resolution: Resolution): void {
    if (this.#options.resolution !== 'auto') {
      this.#reason = this.#fixedBy === 'internal-remote' ? 'internal-remote' : 'override';
      return;
    }
    const info = this.#system === null ? undefined : systemInfo(this.#system);
    if (info === undefined) this.#reason = 'channel-ids';
    else this.#reason = info.resolution === resolution ? 'system-byte' : 'system-byte-contradicted';
  }

  #explain(): string {
    const other = this.#forcedMismatch;
    if (other !== null) {
      return `Forced ${this.#options.resolution}: no frame matches; the stream looks like ${other}.`;
    }
    if (!this.#locked && this.#withheld === 'forced') {
      const { resolution, remote, headerMode } = this.#options;
      const set = [
        resolution === 'auto' ? '' : `resolution ${resolution}`,
        remote === 'auto' ? '' : `remote ${remote}`,
        headerMode === 'auto' ? '' : `header mode ${headerMode}`,
      ].filter((x) => x !== '');
      return `No frame matches the forced ${set.join(', ')}: the bytes are frames, read another way; nothing is decoded.`;
    }
    if (!this.#locked && this.#withheld === 'filler') {
      return `${this.#everLocked ? 'Looking for frames again' : 'No frames'}: the bytes read as frames only of empty slots (0xFFFF) or 0x00/0xFF filler, which carry no channel.`;
    }
    if (!this.#everLocked) return 'Not locked on to frames yet.';
    if (!this.#locked) return 'Looking for frames again: the format changed or the frames stopped making sense.';
    const res = this.#resolution;
    const sys = this.#system === null ? undefined : systemInfo(this.#system);
    const hex = (v: number) => `0x${v.toString(16).padStart(2, '0').toUpperCase()}`;
    let remote = 'external remote (or a receiver that sends no system byte): bytes 0–1 are a UINT16 fade count';
    if (this.#remote === 'internal') {
      const b0 =
        this.#b0Mode === B0_UNKNOWN
          ? '; byte 0 has stayed at values that are fades above 155 or SPM4649T RSSI, without falling: not yet known which'
          : this.#b0Mode === B0_FADES
            ? ''
            : '; byte 0 is SPM4649T RSSI';
      const or = this.#ambiguous
        ? `; or an external remote whose fade count's low byte is ${hex(this.#system ?? 0)}: not yet known which (byte 0 moving says internal, byte 1 moving external)`
        : '';
      remote = sys
        ? `internal remote (system byte ${hex(this.#system ?? 0)}, ${sys.name})${b0}${or}`
        : `internal remote (system byte ${hex(this.#system ?? 0)} is none of the four in §8.3: ignored)${b0}`;
    }
    switch (this.#reason) {
      case 'override':
        return `${res} resolution set by the user; ${remote}.`;
      case 'internal-remote':
        return `${res} resolution from the internal remote's system byte (on another port: it holds the key for every remote); ${remote}.`;
      case 'system-byte':
        return `${res} resolution from the system byte, confirmed by the channel IDs; ${remote}.`;
      case 'system-byte-contradicted':
        return `${res} resolution inferred from the channel IDs: the system byte says ${sys?.resolution ?? '?'} but its channel IDs only make sense at ${res}; ${remote}.`;
      default:
        return `${res} resolution inferred from the channel IDs (no valid system byte); ${remote}.`;
    }
  }

  /**
   * Hands `event` to `onEvent` with its time (that of the byte at its offset, dated as
   * `#stampTime` dates a frame's first byte) and, for a discard, a view of its bytes (borrowed:
   * valid during the call). Events are rare: the chunk records are searched here, off the
   * frame path. The byte at the offset is still held (events come before their bytes are
   * dropped), or has not arrived yet (NaN).
   */
  #event(event: DecoderEvent extends infer E ? (E extends DecoderEvent ? Omit<E, 'timeUs' | 'bytes'> : never) : never): void {
    const onEvent = this.#onEvent;
    if (onEvent === undefined) return;
    const x = event.offset;
    const o = x - this.#base;
    let timeUs = Number.NaN;
    if (o >= 0 && o < this.#tail) {
      for (let i = this.#chunkHead; i < this.#chunkTail; i++) {
        const end = this.#chunkEnds[i] ?? 0;
        if (end <= x) continue;
        this.#dateByte(x, i);
        timeUs = timeAt(this.#when, 0);
        break;
      }
    }
    if (event.type === 'discarded') onEvent({ ...event, timeUs, bytes: this.#buf.subarray(o, o + event.length) });
    else onEvent({ ...event, timeUs });
  }

  /**
   * Sets `frame.timeUs` to the time of the byte at buffer index `o`: its own time, or its
   * chunk's time less one byte time for each byte after it in the chunk. Frames are emitted in
   * stream order, so chunks before `o` are done with and dropped here. (It assigns rather than
   * returns: a double returned from a call that is not inlined is boxed, one allocation a frame.)
   */
  #stampTime(frame: DecodedFrame, o: number): void {
    const x = this.#base + o;
    this.#dateByte(x, this.#dropChunksBefore(x));
    frame.timeUs = this.#when[0]!;
  }

  /**
   * Dates the byte at stream offset `x`, held in chunk `i`, into #when[0]: its own time, or its
   * chunk's time less one byte time for each byte after it in the chunk (NaN without times).
   * The one rule for frames and events.
   */
  #dateByte(x: number, i: number): void {
    const byteTimes = this.#byteTimes;
    // 86.80555555555556: BYTE_TIME_US written out, as in #nextFast.
    this.#when[0] =
      this.#chunkPerByte[i] === 1 && byteTimes !== null
        ? byteTimes[x - this.#base]!
        : this.#chunkTimes[i]! - (this.#chunkEnds[i]! - 1 - x) * 86.80555555555556;
  }

  /** Forgets the records of chunks that end at or before stream offset `x` (keeps the last one); returns the first kept. */
  #dropChunksBefore(x: number): number {
    const ends = this.#chunkEnds;
    const last = this.#chunkTail - 1;
    let i = this.#chunkHead;
    while (i < last && ends[i]! <= x) i++;
    this.#chunkHead = i;
    return i;
  }

  // ---- checkpoints -------------------------------------------------------------------------

  /**
   * The decoder's whole state now, as data no later call changes (checkpoint.ts): the bytes it
   * still holds and their chunk records, the lock, the format, the layouts, the staged frame
   * and the counters. Between calls only (not while a borrowed frame is in use).
   */
  checkpoint(): DecoderCheckpoint {
    const h = this.#chunkHead;
    const t = this.#chunkTail;
    return {
      resolutionOption: this.#options.resolution,
      remoteOption: this.#options.remote,
      headerModeOption: this.#options.headerMode,
      fixedBy: this.#fixedBy,
      bytes: this.#buf.slice(this.#head, this.#tail),
      byteTimes: this.#byteTimes === null ? null : this.#byteTimes.slice(this.#head, this.#tail),
      base: this.#base + this.#head,
      chunkEnds: this.#chunkEnds.slice(h, t),
      chunkTimes: this.#chunkTimes.slice(h, t),
      chunkPerByte: this.#chunkPerByte.slice(h, t),
      ended: this.#ended,
      locked: this.#locked,
      everLocked: this.#everLocked,
      confirmedUntil: this.#confirmedUntil,
      resolution: this.#resolution,
      reason: this.#reason,
      remote: this.#remote,
      system: this.#system,
      b0Mode: this.#b0Mode,
      forcedMismatch: this.#forcedMismatch,
      withheld: this.#withheld,
      ambiguous: this.#ambiguous,
      last0: this.#last0,
      last1: this.#last1,
      haveLast: this.#haveLast,
      jumpTrusted: this.#jumpTrusted,
      nextAt: this.#nextAt,
      nextLayout: this.#nextLayout,
      layouts: this.#layouts.slice(),
      layoutCount: this.#layoutCount,
      layoutNext: this.#layoutNext,
      shown: copySlots(this.#shown),
      staged: copySlots(this.#staged),
      stagedAt: this.#stagedAt,
      frameIndex: this.#frame.index,
      stats: { ...this.#stats },
      candInternal: this.#candInternal,
      candSystem: this.#candSystem,
      candB0: this.#candB0,
      candFrames: this.#candFrames,
      candSkipped: this.#candSkipped,
    };
  }

  /**
   * Puts the decoder back where `checkpoint()` was taken (from this decoder or another): fed
   * the same bytes from there, it gives the same frames, events, counters and format. Its own
   * `onEvent` and `fastPath` stay; `cp` is left as it was and can be restored again.
   */
  restore(cp: DecoderCheckpoint): void {
    const n = cp.bytes.length;
    let capacity = INITIAL_CAPACITY;
    while (capacity < n) capacity *= 2;
    this.#buf = new Uint8Array(capacity);
    this.#buf.set(cp.bytes);
    this.#buf32 = new Uint32Array(this.#buf.buffer);
    this.#bufView = new DataView(this.#buf.buffer);
    this.#byteTimes = null;
    if (cp.byteTimes !== null) {
      this.#byteTimes = new Float64Array(capacity);
      this.#byteTimes.set(cp.byteTimes);
    }
    this.#head = 0;
    this.#tail = n;
    this.#base = cp.base;
    const chunks = cp.chunkEnds.length;
    let records = 64;
    while (records < chunks) records *= 2;
    this.#chunkEnds = new Float64Array(records);
    this.#chunkEnds.set(cp.chunkEnds);
    this.#chunkTimes = new Float64Array(records);
    this.#chunkTimes.set(cp.chunkTimes);
    this.#chunkPerByte = new Uint8Array(records);
    this.#chunkPerByte.set(cp.chunkPerByte);
    this.#chunkHead = 0;
    this.#chunkTail = chunks;
    this.#options = { resolution: cp.resolutionOption, remote: cp.remoteOption, headerMode: cp.headerModeOption };
    this.#fixedBy = cp.fixedBy;
    this.#ended = cp.ended;
    this.#locked = cp.locked;
    this.#everLocked = cp.everLocked;
    this.#confirmedUntil = cp.confirmedUntil;
    this.#resolution = cp.resolution;
    this.#reason = cp.reason;
    this.#remote = cp.remote;
    this.#system = cp.system;
    this.#b0Mode = cp.b0Mode;
    this.#forcedMismatch = cp.forcedMismatch;
    this.#withheld = cp.withheld;
    this.#ambiguous = cp.ambiguous;
    this.#last0 = cp.last0;
    this.#last1 = cp.last1;
    this.#haveLast = cp.haveLast;
    this.#jumpTrusted = cp.jumpTrusted;
    this.#nextAt = cp.nextAt;
    this.#nextLayout = cp.nextLayout;
    this.#layouts.set(cp.layouts);
    this.#layoutCount = cp.layoutCount;
    this.#layoutNext = cp.layoutNext;
    copySlots(cp.shown, this.#shown);
    copySlots(cp.staged, this.#staged);
    this.#stagedAt = cp.stagedAt;
    this.#frame.index = cp.frameIndex;
    showSlots(this.#frame, this.#shown);
    Object.assign(this.#stats, cp.stats);
    this.#candInternal = cp.candInternal;
    this.#candSystem = cp.candSystem;
    this.#candB0 = cp.candB0;
    this.#candFrames = cp.candFrames;
    this.#candSkipped = cp.candSkipped;
  }
}
