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
 *   with the resolution score higher. The winning chain is emitted as it stands.
 * - Locked, a frame is emitted when it continues the last one (same model, fade count risen by
 *   less than FADE_STEP), its slot layout is one the transmitter has used, and the next frame's
 *   header continues it: at most one frame period of latency. A frame whose slot layout is new
 *   needs the whole next frame, and must not overlap a frame that continues the stream (the
 *   front of one frame glued to the back of the next after lost bytes reads as a new layout).
 * - A frame that fails starts a search for the nearest offset where a known layout continues the
 *   stream; what lies between is discarded and counted. Where nothing continues (a rebind, a
 *   system byte that changed, a fade count that jumped, another satellite) it acquires afresh.
 *
 * Every pass of `next()` emits a frame, consumes at least one byte, waits for input, or turns
 * an unlock into an acquisition, which itself consumes or locks with frames it has confirmed
 * (emitted unconditionally): so `next()` always returns after bounded work.
 */
import { BYTE_TIME_US, FRAME_SIZE, systemInfo, type Resolution } from './spec.js';
import { createFrame, createVtx, countZeroWords, INVALID, isVtxFrame, layoutChannels, readSlots, slotLayout } from './frame.js';
import type {
  DecodedFrame, DecoderEvent, DecoderStats, FormatInfo, HeaderMode, HeaderReading, RemoteKind, ResolutionReason,
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
}

/** §8.3, §8.4: the two header bytes (system and fades, or a UINT16 fade count). */
const HEADER_SIZE = 2;
/** Frames looked at before a lock. */
const ACQUIRE_FRAMES = 4;
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
 * (≈ 0.35 s of lost frames at 11 ms). A larger rise, or any fall that is not a wrap, breaks the
 * chain: the decoder acquires again and reports the jump (`fade-jump`).
 */
const FADE_STEP = 32;
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
function byte0Follows(prev: number, next: number, mode: number): boolean {
  if (mode === B0_RSSI_FORCED) return true;
  const rise = ((next - prev) & 0xff) < FADE_STEP;
  if (mode === B0_FADES) return rise;
  if (mode === B0_RSSI) return plausibleRssi(next);
  return rise || (plausibleRssi(prev) && plausibleRssi(next));
}

/** Whether an external remote's UINT16 fade count can go from `prev` to `next` between consecutive frames. */
function countFollows(prev: number, next: number): boolean {
  return ((next - prev) & 0xffff) < FADE_STEP;
}

export class SpektrumDecoder {
  #options: Required<Omit<DecoderOptions, 'onEvent' | 'resolutionFrom'>>;
  readonly #onEvent: ((event: DecoderEvent) => void) | undefined;

  #buf = new Uint8Array(INITIAL_CAPACITY);
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
  #resolution: Resolution | null = null;
  #reason: ResolutionReason = 'unknown';
  #remote: RemoteKind | null = null;
  /** The internal remote's system byte (valid or not), or null. */
  #system: number | null = null;
  /** B0_* : how byte 0 of an internal remote is read. */
  #b0Mode = B0_FADES;
  /** The resolution the bytes fit when a forced one fits nothing, else null. */
  #forcedMismatch: Resolution | null = null;
  /** Header bytes of the last emitted frame (for deltas and continuity), valid when #haveLast. */
  #last0 = 0;
  #last1 = 0;
  #haveLast = false;
  /** Whether a fade jump at the first frame after a lock is the receiver's own count (same remote, known layouts). */
  #jumpTrusted = false;
  #layouts = new Int32Array(LAYOUT_MEMORY);
  #layoutCount = 0;
  #layoutNext = 0;

  readonly #frame = createFrame();
  readonly #vtx = createVtx();
  readonly #stats: DecoderStats = {
    bytes: 0, frames: 0, frameBytes: 0, discardedBytes: 0, pendingBytes: 0,
    resyncs: 0, badFrames: 0, emptySlots: 0, vtxFrames: 0, fadeJumps: 0,
  };

  /** Acquisition scratch: the best candidate's header reading. */
  #candInternal = false;
  #candSystem = 0;
  #candB0 = B0_FADES;
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
    this.#options = { resolution, remote, headerMode };
    this.#fixedBy = options.resolutionFrom === 'internal-remote' ? 'internal-remote' : 'user';
    this.#onEvent = options.onEvent;
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
    if (this.#ended) throw new TypeError('push() after end(): call reset() to decode a new stream');
    const n = bytes.length;
    if (time instanceof Float64Array && time.length !== n) {
      throw new TypeError(`per-byte times have length ${time.length}, bytes ${n}`);
    }
    if (n === 0) return;
    this.#reserve(n);
    const at = this.#tail;
    this.#buf.set(bytes, at);
    const perByte = time instanceof Float64Array;
    if (perByte) {
      if (this.#byteTimes === null) this.#byteTimes = new Float64Array(this.#buf.length);
      this.#byteTimes.set(time, at);
    }
    this.#addChunk(this.#base + at + n, perByte ? NaN : (time ?? NaN), perByte);
    this.#tail = at + n;
    this.#stats.bytes += n;
    this.#stats.pendingBytes += n;
  }

  /**
   * Marks the end of the stream: bytes still held are decided with what is there (a last frame
   * that continues the stream with a known layout is emitted without a following frame to
   * confirm it; anything else left is discarded).
   */
  end(): void {
    this.#ended = true;
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
    if (!this.#locked) return;
    if (resolution === 'auto' ? this.#reason === 'override' || this.#reason === 'internal-remote' : resolution !== this.#resolution) {
      this.#unlock();
      this.#layoutCount = 0;
      this.#reason = 'unknown';
    } else {
      this.#setReason(this.#resolution as Resolution);
    }
  }

  /** Forgets everything: buffered bytes, lock, format and counters. */
  reset(): void {
    this.#head = this.#tail = this.#base = 0;
    this.#chunkHead = this.#chunkTail = 0;
    this.#ended = false;
    this.#locked = this.#everLocked = false;
    this.#confirmedUntil = 0;
    this.#resolution = null;
    this.#reason = 'unknown';
    this.#remote = this.#system = null;
    this.#b0Mode = B0_FADES;
    this.#forcedMismatch = null;
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
      resolution: this.#resolution,
      resolutionReason: this.#reason,
      explanation: this.#explain(),
      remote: this.#remote,
      system: this.#system,
      systemValid: this.#system !== null && systemInfo(this.#system) !== undefined,
      headerMode: this.#headerReading(),
      forcedMismatch: this.#forcedMismatch,
    };
  }

  /**
   * The next decoded frame, or `undefined` when more bytes are needed. The frame is borrowed:
   * the same object is reused and is valid until the next call to `next()`, `push()`, `end()`
   * or `reset()`.
   */
  next(): DecodedFrame | undefined {
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
      const resolution = this.#resolution as Resolution;
      const layout = slotLayout(this.#buf, o, resolution);
      // Frames acquisition confirmed go out as they stand.
      if (this.#base + o < this.#confirmedUntil && layout !== INVALID) return this.#emit(o, layout);
      const fits = layout !== INVALID && this.#fitsLast(o);
      if (fits) {
        const known = this.#knownLayout(layout);
        // A known layout needs the next frame's header to continue it; a new one the whole next frame.
        if (avail < (known ? FRAME_SIZE + HEADER_SIZE : 2 * FRAME_SIZE)) {
          if (!this.#ended) return undefined;
          if (known) return this.#emit(o, layout);
          this.#discard(o, avail, 'end-of-stream');
          return undefined;
        }
        if (this.#follows(o, o + FRAME_SIZE)) {
          if (known) return this.#emit(o, layout);
          if (slotLayout(this.#buf, o + FRAME_SIZE, resolution) !== INVALID) {
            // A new layout: make sure no frame that continues the stream starts inside this one.
            const q = this.#search(o + 1, o + FRAME_SIZE - 1);
            if (q === NEED_MORE) return undefined;
            if (q === NOT_FOUND) return this.#emit(o, layout);
            this.#resync(o, q);
            continue;
          }
        }
      }
      // The frame at o does not continue the stream (or the next one does not continue it).
      const q = this.#search(o + 1, o + MAX_RESYNC_BYTES);
      if (q === NEED_MORE) return undefined;
      if (fits && this.#knownLayout(layout) && (q === NOT_FOUND || q >= o + FRAME_SIZE) && this.#aloneOk(o)) {
        // This frame is whole; the damage is in what follows it.
        return this.#emit(o, layout);
      }
      if (q !== NOT_FOUND) {
        this.#resync(o, q);
        continue;
      }
      // Nothing continues within reach: the format may have changed. Acquire afresh from here.
      this.#unlock();
    }
  }

  // ---- locked path -------------------------------------------------------------------------

  /** Whether the header at `o` continues the last emitted frame under the lock's model. */
  #fitsLast(o: number): boolean {
    const b = this.#buf;
    const b0 = b[o] as number;
    const b1 = b[o + 1] as number;
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
      return buf[b + 1] === this.#system && byte0Follows(buf[a] as number, buf[b] as number, this.#b0Mode);
    }
    return countFollows(((buf[a] as number) << 8) | (buf[a + 1] as number), ((buf[b] as number) << 8) | (buf[b + 1] as number));
  }

  /**
   * The nearest offset in [from, to] where frames continue: a frame with a known layout that
   * continues the stream, confirmed by the frame after it, or, when that next frame is damaged,
   * one that no confirmed frame overlaps. NOT_FOUND, or NEED_MORE when the answer depends on
   * bytes that have not arrived.
   */
  #search(from: number, to: number): number {
    const resolution = this.#resolution as Resolution;
    const buf = this.#buf;
    let pending = NOT_FOUND;
    for (let q = from; q <= to || pending !== NOT_FOUND; q++) {
      if (pending !== NOT_FOUND && q >= pending + FRAME_SIZE) return pending;
      if (q + FRAME_SIZE > this.#tail) return this.#ended ? pending : NEED_MORE;
      const layout = slotLayout(buf, q, resolution);
      if (layout === INVALID || !this.#fitsLast(q) || !this.#knownLayout(layout)) continue;
      if (q + 2 * FRAME_SIZE > this.#tail) {
        if (!this.#ended) return NEED_MORE;
        return pending === NOT_FOUND ? q : pending;
      }
      if (slotLayout(buf, q + FRAME_SIZE, resolution) !== INVALID && this.#follows(q, q + FRAME_SIZE)) return q;
      if (pending === NOT_FOUND && this.#aloneOk(q)) pending = q;
    }
    return NOT_FOUND;
  }

  /**
   * Whether the frame at `o`, which continues the last frame but is not continued by the next,
   * may stand alone: the next frame must be damaged (invalid) or start something new. A valid
   * next frame that continues the last frame says the header at `o` is the foreign one (bytes
   * lost across a frame boundary: one frame's last byte read as the next one's fade count).
   */
  #aloneOk(o: number): boolean {
    const next = o + FRAME_SIZE;
    if (next + FRAME_SIZE > this.#tail || !this.#haveLast) return true;
    return slotLayout(this.#buf, next, this.#resolution as Resolution) === INVALID || !this.#fitsLast(next);
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
    const resolution = this.#resolution as Resolution;
    frame.index++;
    frame.offset = this.#base + o;
    this.#stampTime(frame, o);
    frame.resolution = resolution;
    const remote = this.#remote as RemoteKind;
    frame.remote = remote;
    const b0 = buf[o] as number;
    const b1 = buf[o + 1] as number;
    let delta = 0;
    if (remote === 'internal') {
      frame.system = b1;
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
    const empty = readSlots(frame, buf, o, resolution, isVtxFrame(buf, o), this.#vtx);
    const s = this.#stats;
    s.frames++;
    s.frameBytes += FRAME_SIZE;
    s.pendingBytes -= FRAME_SIZE;
    s.emptySlots += empty;
    if (frame.vtx !== null) s.vtxFrames++;
    this.#head = o + FRAME_SIZE;
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
    this.#head = o + length;
    // A stream that never locks emits nothing: its chunk records must go with its bytes.
    this.#dropChunksBefore(this.#base + this.#head);
    this.#event({ type: 'discarded', offset: this.#base + o, length, reason });
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
    const best = this.#best(p, avail, forced === 'auto' ? 0 : forced);
    if (best.score < 0 || (best.shift >= ACQUIRE_COMMIT && avail >= window)) {
      if (best.score < 0 && forced !== 'auto') {
        // Say so when the bytes are frames, only not at the resolution the caller forced.
        const other: Resolution = forced === 2048 ? 1024 : 2048;
        if (this.#best(p, avail, other).score >= 0) this.#forcedMismatch = other;
      }
      // No alignment starting in these 16 bytes works (or the best starts too late to commit).
      this.#discard(p, Math.min(FRAME_SIZE, avail), lost);
      return true;
    }
    const o = p + best.shift;
    const resolution = best.resolution;
    // Score again to leave the winner's header reading in the scratch fields.
    const frames = Math.min(ACQUIRE_FRAMES, Math.floor((avail - best.shift) / FRAME_SIZE));
    this.#score(o, resolution, frames);
    const internal = this.#candInternal;
    const system = this.#candSystem;
    let b0Mode = this.#candB0;
    if (internal && b0Mode === B0_UNKNOWN) {
      // Byte 0 has only been a plausible RSSI and never fallen: read further along the chain before deciding.
      const evidence = this.#byte0Evidence(o, resolution, system);
      if (evidence === NEED_MORE) return false;
      b0Mode = evidence;
    }
    if (best.shift > 0) this.#discard(p, best.shift, lost);
    const sameRemote = this.#haveLast && this.#remote === (internal ? 'internal' : 'external') &&
      (internal ? this.#system === system : true) && this.#resolution === resolution;
    if (this.#resolution !== resolution) this.#layoutCount = 0;
    // A count that jumped across the break is the receiver's own when the same remote goes on
    // with layouts it used before (a shifted reading of the stream makes layouts of its own).
    this.#jumpTrusted = sameRemote && this.#chainKnown(o, resolution, frames);
    if (!sameRemote) this.#haveLast = false;
    const changed = this.#everLocked && (this.#remote !== (internal ? 'internal' : 'external') || this.#system !== (internal ? system : null) ||
      this.#resolution !== resolution);
    this.#locked = true;
    this.#everLocked = true;
    this.#forcedMismatch = null;
    this.#confirmedUntil = this.#base + o + frames * FRAME_SIZE;
    this.#resolution = resolution;
    this.#remote = internal ? 'internal' : 'external';
    this.#system = internal ? system : null;
    this.#b0Mode = internal ? b0Mode : B0_FADES;
    this.#setReason(resolution);
    this.#event({ type: 'locked', offset: this.#base + o, format: this.format });
    if (changed) this.#event({ type: 'format-changed', offset: this.#base + o, format: this.format });
    return true;
  }

  /** The best-scoring start among the next ACQUIRE_SHIFTS offsets, at one resolution or (0) both. */
  #best(p: number, avail: number, only: 0 | Resolution): { score: number; shift: number; resolution: Resolution } {
    let score = -1;
    let shift = 0;
    let resolution: Resolution = 2048;
    for (let s = 0; s < ACQUIRE_SHIFTS; s++) {
      const frames = Math.min(ACQUIRE_FRAMES, Math.floor((avail - s) / FRAME_SIZE));
      if (frames < 1) break;
      if (only !== 1024) {
        const v = this.#score(p + s, 2048, frames);
        if (v > score) { score = v; shift = s; resolution = 2048; }
      }
      if (only !== 2048) {
        const v = this.#score(p + s, 1024, frames);
        if (v > score) { score = v; shift = s; resolution = 1024; }
      }
    }
    return { score, shift, resolution };
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
    let prev = buf[o] as number;
    for (let k = 1; k < HEADER_EVIDENCE_FRAMES; k++) {
      const f = o + k * FRAME_SIZE;
      if (f + FRAME_SIZE > this.#tail) return this.#ended ? B0_UNKNOWN : NEED_MORE;
      const b0 = buf[f] as number;
      if (buf[f + 1] !== system || slotLayout(buf, f, resolution) === INVALID || !byte0Follows(prev, b0, B0_UNKNOWN)) return B0_UNKNOWN;
      if (!plausibleRssi(b0)) return B0_FADES;
      if (b0 < prev) return B0_RSSI;
      prev = b0;
    }
    return B0_UNKNOWN;
  }

  /**
   * How well `frames` frames at `o` read as consecutive frames of one remote at `resolution`;
   * -1 when any frame is invalid or the headers do not form one remote's chain. Leaves the
   * header reading in #candInternal / #candSystem / #candB0.
   */
  #score(o: number, resolution: Resolution, frames: number): number {
    const buf = this.#buf;
    const { remote, headerMode } = this.#options;
    const s = buf[o + 1] as number;
    const first0 = buf[o] as number;
    const forcedB0 = headerMode === 'rssi' ? B0_RSSI_FORCED : headerMode === 'fades' ? B0_FADES : B0_UNKNOWN;
    let internal = remote !== 'external';
    let external = remote !== 'internal';
    let positive = !plausibleRssi(first0);
    let fell = false;
    let channels = 0;
    let zeroWords = 0;
    let recurring = 0;
    let layout1 = INVALID;
    let layout2 = INVALID;
    let prev0 = first0;
    let prevWord = (first0 << 8) | s;
    let zeroByte0 = first0 === 0;
    for (let k = 0; k < frames; k++) {
      const f = o + k * FRAME_SIZE;
      const layout = slotLayout(buf, f, resolution);
      if (layout === INVALID) return -1;
      if (k > 0) {
        const b0 = buf[f] as number;
        const word = (b0 << 8) | (buf[f + 1] as number);
        if (internal && (buf[f + 1] !== s || !byte0Follows(prev0, b0, forcedB0))) internal = false;
        if (external && !countFollows(prevWord, word)) external = false;
        if (!internal && !external) return -1;
        if (b0 === 0) zeroByte0 = true;
        if (!plausibleRssi(b0)) positive = true;
        else if (prev0 >= 0x80 && b0 < prev0) fell = true;
        prev0 = b0;
        prevWord = word;
      }
      if (layout === layout2) recurring++;
      layout2 = layout1;
      layout1 = layout;
      channels |= layoutChannels(layout);
      zeroWords += countZeroWords(buf, f);
    }
    const info = systemInfo(s);
    if (internal && external) {
      // Both readings hold. §8.3 names four system bytes; a count below 256 (`00 xx`, the
      // external and clone header) is external; an unlisted byte 1 over a byte 0 that is never
      // zero is a system byte to ignore, as is any byte 1 an internal remote of this stream sent.
      internal = remote === 'internal' || info !== undefined ||
        (s !== 0 && (!zeroByte0 || (this.#remote === 'internal' && this.#system === s)));
    }
    let score = 10 * frames + recurring - zeroWords;
    if (internal) {
      // Only a system byte of §8.3 is evidence of an internal remote.
      if (info !== undefined) score += 4;
      if (info?.resolution === resolution) score += 2;
    } else if (prevWord < 256) {
      score += 1;
    }
    // A header of 0xFFFF is an empty slot's filler more often than a fade count at its limit.
    if (((first0 << 8) | s) === 0xffff) score -= 3;
    // Transmitters send channels 0…N-1: a contiguous set is the signature of the right reading.
    if ((channels & (channels + 1)) === 0) score += 2;
    this.#candInternal = internal;
    this.#candSystem = s;
    this.#candB0 = forcedB0 !== B0_UNKNOWN ? forcedB0 : positive ? B0_FADES : fell ? B0_RSSI : B0_UNKNOWN;
    return score;
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
    if (this.#resolution === null) return 'Not locked on to frames yet.';
    if (!this.#locked) return 'Looking for frames again: the format changed or the frames stopped making sense.';
    const res = this.#resolution;
    const sys = this.#system === null ? undefined : systemInfo(this.#system);
    const hex = (v: number) => `0x${v.toString(16).padStart(2, '0').toUpperCase()}`;
    let remote = 'external remote (or a receiver that sends no system byte): bytes 0–1 are a UINT16 fade count';
    if (this.#remote === 'internal') {
      const b0 = this.#b0Mode === B0_UNKNOWN
        ? '; byte 0 has stayed at values that are fades above 155 or SPM4649T RSSI, without falling: not yet known which'
        : this.#b0Mode === B0_FADES ? '' : '; byte 0 is SPM4649T RSSI';
      remote = sys
        ? `internal remote (system byte ${hex(this.#system ?? 0)}, ${sys.name})${b0}`
        : `internal remote (system byte ${hex(this.#system ?? 0)} is none of the four in §8.3: ignored)${b0}`;
    }
    switch (this.#reason) {
      case 'override': return `${res} resolution set by the user; ${remote}.`;
      case 'internal-remote': return `${res} resolution from the internal remote's system byte (on another port: it holds the key for every remote); ${remote}.`;
      case 'system-byte': return `${res} resolution from the system byte, confirmed by the channel IDs; ${remote}.`;
      case 'system-byte-contradicted':
        return `${res} resolution inferred from the channel IDs: the system byte says ${sys?.resolution ?? '?'} but its channel IDs only make sense at ${res}; ${remote}.`;
      default: return `${res} resolution inferred from the channel IDs (no valid system byte); ${remote}.`;
    }
  }

  #event(event: DecoderEvent): void {
    if (this.#onEvent !== undefined) this.#onEvent(event);
  }

  /** Records a pushed chunk's end (stream offset) and time. */
  #addChunk(end: number, time: number, perByte: boolean): void {
    if (this.#chunkTail === this.#chunkEnds.length) {
      const live = this.#chunkTail - this.#chunkHead;
      if (this.#chunkHead >= live) {
        this.#chunkEnds.copyWithin(0, this.#chunkHead, this.#chunkTail);
        this.#chunkTimes.copyWithin(0, this.#chunkHead, this.#chunkTail);
        this.#chunkPerByte.copyWithin(0, this.#chunkHead, this.#chunkTail);
      } else {
        const size = this.#chunkEnds.length * 2;
        const ends = new Float64Array(size);
        const times = new Float64Array(size);
        const perBytes = new Uint8Array(size);
        ends.set(this.#chunkEnds.subarray(this.#chunkHead, this.#chunkTail));
        times.set(this.#chunkTimes.subarray(this.#chunkHead, this.#chunkTail));
        perBytes.set(this.#chunkPerByte.subarray(this.#chunkHead, this.#chunkTail));
        this.#chunkEnds = ends;
        this.#chunkTimes = times;
        this.#chunkPerByte = perBytes;
      }
      this.#chunkTail = live;
      this.#chunkHead = 0;
    }
    const i = this.#chunkTail++;
    this.#chunkEnds[i] = end;
    this.#chunkTimes[i] = time;
    this.#chunkPerByte[i] = perByte ? 1 : 0;
  }

  /**
   * Sets `frame.timeUs` to the time of the byte at buffer index `o`: its own time, or its
   * chunk's time less one byte time for each byte after it in the chunk. Frames are emitted in
   * stream order, so chunks before `o` are done with and dropped here. (It assigns rather than
   * returns: a double returned from a call that is not inlined is boxed, one allocation a frame.)
   */
  #stampTime(frame: DecodedFrame, o: number): void {
    const x = this.#base + o;
    this.#dropChunksBefore(x);
    const i = this.#chunkHead;
    if (this.#chunkPerByte[i] === 1) frame.timeUs = (this.#byteTimes as Float64Array)[o] as number;
    else frame.timeUs = (this.#chunkTimes[i] as number) - ((this.#chunkEnds[i] as number) - 1 - x) * BYTE_TIME_US;
  }

  /** Forgets the records of chunks that end at or before stream offset `x` (keeps the last one). */
  #dropChunksBefore(x: number): void {
    while (this.#chunkHead < this.#chunkTail - 1 && (this.#chunkEnds[this.#chunkHead] as number) <= x) this.#chunkHead++;
  }

  /** Makes room for `n` more bytes: compacts first, grows (doubling) only when full. */
  #reserve(n: number): void {
    const need = this.#tail - this.#head + n;
    const byteTimes = this.#byteTimes;
    if (this.#head > 0 && (this.#tail + n > this.#buf.length || this.#head >= this.#buf.length >> 1)) {
      this.#buf.copyWithin(0, this.#head, this.#tail);
      byteTimes?.copyWithin(0, this.#head, this.#tail);
      this.#base += this.#head;
      this.#tail -= this.#head;
      this.#head = 0;
    }
    if (this.#tail + n <= this.#buf.length) return;
    let capacity = this.#buf.length * 2;
    while (capacity < need) capacity *= 2;
    const buf = new Uint8Array(capacity);
    buf.set(this.#buf.subarray(0, this.#tail));
    this.#buf = buf;
    if (byteTimes !== null) {
      const times = new Float64Array(capacity);
      times.set(byteTimes.subarray(0, this.#tail));
      this.#byteTimes = times;
    }
  }
}
