/**
 * The push decoder: bytes in (`push`), frames out (`next`). It finds frames without a sync
 * byte and without trusting timing, infers the stream's format, and never throws on bytes.
 *
 * How it finds frames. Frames are 16 bytes back to back in the byte stream; only a truncated
 * or corrupted frame, or noise, shifts the alignment. Content alone decides where a frame
 * starts, so the result is identical however the bytes are chunked and whatever times come
 * with them:
 *
 * - Unlocked, it looks at four frames from each of the next 48 start offsets and scores each
 *   under both resolutions: every slot must hold a valid channel ID (or
 *   0xFFFF, or VTX), no ID may repeat within a frame, the header bytes must behave like a header
 *   (the same valid system byte in every frame, or a slowly rising UINT16 fade count), and
 *   channel sets that are contiguous, layouts that recur every other frame and a system byte
 *   that agrees with the resolution score higher.
 * - Locked, a frame whose slot layout the transmitter has already used and whose header fits
 *   is emitted as soon as its 16 bytes are in. A frame with a new layout or a surprising header
 *   waits for the next frame to confirm the alignment (one frame of latency, rarely).
 * - A frame that fails starts a search for the nearest offset where frames continue; what lies
 *   between is discarded and counted (a truncated frame when it overlaps the next one).
 */
import {
  BYTE_TIME_US, FRAME_SIZE, systemInfo, type Resolution,
} from './spec.js';
import { createFrame, createVtx, countZeroWords, INVALID, isVtxFrame, layoutChannels, readSlots, slotLayout } from './frame.js';
import type {
  DecodedFrame, DecoderEvent, DecoderStats, FormatInfo, HeaderMode, RemoteKind, ResolutionReason,
} from './types.js';

export interface DecoderOptions {
  /** Fix the servo resolution instead of inferring it (e.g. from the internal remote). Default 'auto'. */
  resolution?: 'auto' | Resolution;
  /** Who fixed `resolution`, for `format`: the user (default) or the internal remote of the system. */
  resolutionFrom?: 'user' | 'internal-remote';
  /** Fix the remote kind instead of inferring it from the header bytes. Default 'auto'. */
  remote?: 'auto' | RemoteKind;
  /** What byte 0 of an internal remote carries. 'auto' (default) detects SPM4649T RSSI. */
  headerMode?: 'auto' | HeaderMode;
  /** Called synchronously for locks, discards, resyncs and format changes. */
  onEvent?: (event: DecoderEvent) => void;
}

/** Frames looked at before the first lock. */
const ACQUIRE_FRAMES = 4;
/**
 * Start offsets compared before locking. A damaged frame can hide the real alignment's first
 * start while a shifted reading that happens to parse (a 1024-mode internal remote read two bytes
 * late looks like an external one whose fade count is channel 0's position) starts earlier. The
 * real start after damage lies at most a frame after any such reading, so candidates over three
 * frames of starts are compared, but a lock is only taken in the first two: a best candidate in
 * the third frame waits until the window has slid on.
 */
const ACQUIRE_SHIFTS = 3 * FRAME_SIZE;
const ACQUIRE_COMMIT = 2 * FRAME_SIZE;
/** A UINT16 fade count that rises by more than this between two frames is suspect (≈ 22 s of loss at 11 ms). */
const MAX_FADE_STEP = 2048;
/** How far a locked decoder searches for the next frame before it starts over. */
const MAX_RESYNC_BYTES = 8 * FRAME_SIZE;
/** Slot layouts remembered (a transmitter uses two to four). */
const LAYOUT_MEMORY = 16;
const INITIAL_CAPACITY = 4096;

const NEED_MORE = -2;

/**
 * SPM4649T RSSI (§8.3.1): -42 dBm (strong) … -92 dBm (weak), -128 on loss. Values from -20 to
 * -110 are accepted to allow for receivers beyond the documented range.
 */
function plausibleRssi(byte: number): boolean {
  return byte === 0x80 || (byte >= 0x92 && byte <= 0xec);
}

export class SpektrumDecoder {
  #options: Required<Omit<DecoderOptions, 'onEvent' | 'resolutionFrom'>>;
  readonly #onEvent: ((event: DecoderEvent) => void) | undefined;

  #buf = new Uint8Array(INITIAL_CAPACITY);
  #view = new DataView(this.#buf.buffer);
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
  #resolution: Resolution | null = null;
  #reason: ResolutionReason = 'unknown';
  #remote: RemoteKind | null = null;
  #system: number | null = null;
  #headerMode: HeaderMode = 'fades';
  /** Fade count (or -1) of the last emitted frame, for deltas and header checks. */
  #lastFades = -1;
  #layouts = new Int32Array(LAYOUT_MEMORY);
  #layoutCount = 0;
  #layoutNext = 0;

  readonly #frame = createFrame();
  readonly #vtx = createVtx();
  readonly #stats: DecoderStats = {
    bytes: 0, frames: 0, frameBytes: 0, discardedBytes: 0, pendingBytes: 0,
    resyncs: 0, badFrames: 0, emptySlots: 0, vtxFrames: 0,
  };

  /** Acquisition scratch: the best candidate's header reading. */
  #candInternal = false;
  #candRssi = false;
  #candSystem = 0;
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
   * is emitted without a following frame to confirm it; a partial one is discarded).
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
    if (!this.#locked) return;
    if (resolution === 'auto' ? this.#reason === 'override' || this.#reason === 'internal-remote' : resolution !== this.#resolution) {
      this.#locked = false;
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
    this.#resolution = null;
    this.#reason = 'unknown';
    this.#remote = this.#system = null;
    this.#headerMode = 'fades';
    this.#lastFades = -1;
    this.#layoutCount = this.#layoutNext = 0;
    this.#frame.index = -1;
    const s = this.#stats;
    s.bytes = s.frames = s.frameBytes = s.discardedBytes = s.pendingBytes = 0;
    s.resyncs = s.badFrames = s.emptySlots = s.vtxFrames = 0;
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
      headerMode: this.#headerMode,
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
      if (layout !== INVALID) {
        const fit = this.#headerFits(o);
        if (fit && this.#knownLayout(layout)) return this.#emit(o, layout);
        if (avail < 2 * FRAME_SIZE) {
          if (!this.#ended) return undefined;
          return this.#emit(o, layout);
        }
        if (slotLayout(this.#buf, o + FRAME_SIZE, resolution) !== INVALID && this.#pairConsistent(o, o + FRAME_SIZE)) {
          if (!fit) this.#reinterpret(o);
          return this.#emit(o, layout);
        }
      }
      // This frame does not continue the stream: find where frames continue.
      const q = this.#search(o, layout !== INVALID && this.#headerFits(o));
      if (q === NEED_MORE) return undefined;
      this.#stats.resyncs++;
      if (q < 0) {
        // Nothing continues within reach: the format may have changed. Start over.
        this.#locked = false;
        this.#layoutCount = 0;
        if (layout !== INVALID && this.#headerFits(o)) return this.#emit(o, layout);
        continue;
      }
      this.#event({ type: 'resync', offset: this.#base + q });
      if (layout !== INVALID && q >= o + FRAME_SIZE && this.#headerFits(o)) {
        // The frame was good; what follows it up to q is noise.
        const frame = this.#emit(o, layout);
        if (q > o + FRAME_SIZE) this.#discard(o + FRAME_SIZE, q - o - FRAME_SIZE, 'noise');
        return frame;
      }
      this.#stats.badFrames++;
      this.#discard(o, q - o, q - o < FRAME_SIZE ? 'truncated-frame' : 'noise');
    }
  }

  // ---- locked path -------------------------------------------------------------------------

  /** Whether the header at `o` is what the lock expects (false: unsure, let the next frame decide). */
  #headerFits(o: number): boolean {
    const view = this.#view;
    if (this.#remote === 'internal') {
      if (view.getUint8(o + 1) !== this.#system) return false;
      return this.#headerMode !== 'rssi' || view.getUint8(o) >= 0x80;
    }
    if (this.#lastFades < 0) return true;
    return ((view.getUint16(o) - this.#lastFades) & 0xffff) < MAX_FADE_STEP;
  }

  /**
   * Whether two frames' headers could be consecutive headers of one remote. While an internal
   * remote's system byte matches, the next frame must carry it too (a truncated frame followed
   * by a shifted one can otherwise pass as a rising UINT16 fade count). When it does not match,
   * the next frame must not carry it either: one corrupted byte is a bad frame, not a new format.
   */
  #pairConsistent(a: number, b: number): boolean {
    const view = this.#view;
    const remote = this.#options.remote;
    const b1 = view.getUint8(a + 1);
    const next1 = view.getUint8(b + 1);
    if (this.#locked && this.#remote === 'internal') {
      if (b1 === this.#system) {
        // RSSI turns into fades only if the next frame's byte 0 is positive too.
        if (this.#headerMode === 'rssi' && view.getUint8(a) < 0x80) return next1 === b1 && view.getUint8(b) < 0x80;
        return next1 === b1;
      }
      if (next1 === this.#system || remote === 'internal') return false;
    }
    if (remote !== 'external' && b1 === next1) return true;
    return remote !== 'internal' && ((view.getUint16(b) - view.getUint16(a)) & 0xffff) < MAX_FADE_STEP;
  }

  /** Whether the fade count (which only rises, with its wrap) could go from frame a to frame b. */
  #fadesRise(a: number, b: number): boolean {
    const view = this.#view;
    if (this.#remote === 'internal') return this.#headerMode === 'rssi' || ((view.getUint8(b) - view.getUint8(a)) & 0xff) < 0x80;
    return ((view.getUint16(b) - view.getUint16(a)) & 0xffff) < MAX_FADE_STEP;
  }

  /** A confirmed frame whose header surprised the lock: adopt what it says. */
  #reinterpret(o: number): void {
    const view = this.#view;
    const b0 = view.getUint8(o);
    const b1 = view.getUint8(o + 1);
    const auto = this.#options;
    if (this.#remote === 'internal' && b1 !== this.#system && auto.remote === 'auto') {
      const sameNext = view.getUint8(o + FRAME_SIZE + 1) === b1;
      if (sameNext && systemInfo(b1) !== undefined) {
        this.#system = b1;
      } else {
        this.#remote = 'external';
        this.#system = null;
        this.#headerMode = 'fades';
        this.#lastFades = -1;
      }
      if (this.#reason === 'system-byte' || this.#reason === 'system-byte-contradicted') this.#setReason(this.#resolution as Resolution);
      this.#event({ type: 'format-changed', offset: this.#base + o, format: this.format });
    } else if (this.#remote === 'internal' && this.#headerMode === 'rssi' && b0 < 0x80 && auto.headerMode === 'auto') {
      // RSSI is never positive: byte 0 was a fade count after all.
      this.#headerMode = 'fades';
      this.#event({ type: 'format-changed', offset: this.#base + o, format: this.format });
    }
  }

  /**
   * The nearest offset after `o` where frames continue, or -1 when none within reach, or
   * NEED_MORE when the answer depends on bytes that have not arrived. Evidence is tried from
   * strong to weak, each over the whole reach, so a run of frames that only happen to parse (a
   * truncated or shifted frame can make that happen) never wins over the real next frame a few
   * bytes later:
   * 1. a frame with a known layout and a header that fits the lock;
   * 2. a frame whose header fits, confirmed by a valid next frame;
   * 3. two valid frames in a row with consistent headers (a new layout, a rebind).
   */
  #search(o: number, plausible: boolean): number {
    const resolution = this.#resolution as Resolution;
    const last = o + MAX_RESYNC_BYTES;
    for (let q = o + 1; q <= last; q++) {
      if (q + FRAME_SIZE > this.#tail) {
        if (!this.#ended) return NEED_MORE;
        break;
      }
      const layout = slotLayout(this.#buf, q, resolution);
      if (layout === INVALID || !this.#headerFits(q) || !this.#knownLayout(layout)) continue;
      // Overlapping a frame that parses and sits where the last one ended says that frame lost
      // bytes; the frame after q must agree (a frame made of one stray byte and the next frame's
      // first fifteen reads a fade count that then goes backwards).
      if (!plausible || q >= o + FRAME_SIZE) return q;
      if (q + 2 * FRAME_SIZE > this.#tail) {
        if (!this.#ended) return NEED_MORE;
        return q;
      }
      if (slotLayout(this.#buf, q + FRAME_SIZE, resolution) !== INVALID && this.#pairConsistent(q, q + FRAME_SIZE) && this.#fadesRise(q, q + FRAME_SIZE)) return q;
    }
    for (let tier = 2; tier <= 3; tier++) {
      for (let q = o + 1; q <= last; q++) {
        if (q + FRAME_SIZE > this.#tail) break;
        if (slotLayout(this.#buf, q, resolution) === INVALID) continue;
        const fits = this.#headerFits(q);
        if (tier === 2 && !fits) continue;
        if (q + 2 * FRAME_SIZE > this.#tail) {
          if (!this.#ended) return NEED_MORE;
          if (fits) return q;
          continue;
        }
        if (slotLayout(this.#buf, q + FRAME_SIZE, resolution) !== INVALID && this.#pairConsistent(q, q + FRAME_SIZE)) {
          return q;
        }
      }
    }
    return -1;
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
    const view = this.#view;
    const frame = this.#frame;
    const resolution = this.#resolution as Resolution;
    frame.index++;
    frame.offset = this.#base + o;
    this.#stampTime(frame, o);
    frame.resolution = resolution;
    const remote = this.#remote as RemoteKind;
    frame.remote = remote;
    let fades: number;
    if (remote === 'internal') {
      frame.system = view.getUint8(o + 1);
      if (this.#headerMode === 'rssi') {
        frame.rssi = view.getInt8(o);
        frame.fades = null;
        fades = -1;
      } else {
        fades = view.getUint8(o);
        frame.rssi = null;
        frame.fades = fades;
      }
      frame.fadesDelta = fades >= 0 && this.#lastFades >= 0 ? (fades - this.#lastFades) & 0xff : 0;
    } else {
      fades = view.getUint16(o);
      frame.system = null;
      frame.rssi = null;
      frame.fades = fades;
      frame.fadesDelta = this.#lastFades >= 0 ? (fades - this.#lastFades) & 0xffff : 0;
    }
    this.#lastFades = fades;
    const empty = readSlots(frame, this.#buf, o, resolution, isVtxFrame(this.#buf, o), this.#vtx);
    const s = this.#stats;
    s.frames++;
    s.frameBytes += FRAME_SIZE;
    s.pendingBytes -= FRAME_SIZE;
    s.emptySlots += empty;
    if (frame.vtx !== null) s.vtxFrames++;
    this.#head = o + FRAME_SIZE;
    return frame;
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
    if (avail < FRAME_SIZE) {
      if (avail > 0) this.#discard(p, avail, this.#everLocked ? 'end-of-stream' : 'before-lock');
      return false;
    }
    const forced = this.#options.resolution;
    const resolutions: readonly Resolution[] = forced === 'auto' ? [2048, 1024] : [forced];
    let bestScore = -1;
    let bestShift = 0;
    let bestResolution: Resolution = 2048;
    let bestInternal = false;
    let bestRssi = false;
    let bestSystem = 0;
    for (let shift = 0; shift < ACQUIRE_SHIFTS; shift++) {
      const frames = Math.min(ACQUIRE_FRAMES, Math.floor((avail - shift) / FRAME_SIZE));
      if (frames < 1) break;
      for (const resolution of resolutions) {
        const score = this.#score(p + shift, resolution, frames);
        if (score > bestScore) {
          bestScore = score;
          bestShift = shift;
          bestResolution = resolution;
          bestInternal = this.#candInternal;
          bestRssi = this.#candRssi;
          bestSystem = this.#candSystem;
        }
      }
    }
    if (bestScore < 0 || (bestShift >= ACQUIRE_COMMIT && avail >= window)) {
      // No alignment starting in these 16 bytes works (or the best starts too late to commit).
      this.#discard(p, Math.min(FRAME_SIZE, avail), this.#everLocked ? 'noise' : 'before-lock');
      return true;
    }
    if (bestShift > 0) this.#discard(p, bestShift, this.#everLocked ? 'noise' : 'before-lock');
    const o = p + bestShift;
    this.#locked = true;
    this.#everLocked = true;
    this.#resolution = bestResolution;
    this.#remote = bestInternal ? 'internal' : 'external';
    this.#system = bestInternal ? bestSystem : null;
    this.#headerMode = bestRssi ? 'rssi' : 'fades';
    this.#lastFades = -1;
    this.#layoutCount = 0;
    this.#setReason(bestResolution);
    this.#event({ type: 'locked', offset: this.#base + o, format: this.format });
    return true;
  }

  /**
   * How well `frames` frames at `o` read as frames of one remote at `resolution`; -1 when any
   * frame is invalid or the headers do not behave like headers. Leaves the header reading in
   * #candInternal / #candRssi.
   */
  #score(o: number, resolution: Resolution, frames: number): number {
    const view = this.#view;
    const { remote, headerMode } = this.#options;
    // An internal remote sends one system byte; allow one corrupted frame among the four.
    let b1 = view.getUint8(o + 1);
    let same = 0;
    for (let k = 0; k < frames; k++) if (view.getUint8(o + k * FRAME_SIZE + 1) === b1) same++;
    if (same < frames - 1 && frames > 1) {
      b1 = view.getUint8(o + FRAME_SIZE + 1);
      same = 0;
      for (let k = 0; k < frames; k++) if (view.getUint8(o + k * FRAME_SIZE + 1) === b1) same++;
    }
    const majority = same >= frames - 1 && same >= Math.min(2, frames);
    const internal = remote === 'internal' ? majority : remote === 'auto' && majority && systemInfo(b1) !== undefined;
    let external = remote !== 'internal';
    let implausibleRssi = 0;
    let channels = 0;
    let zeroWords = 0;
    let recurring = 0;
    let prevFades = view.getUint16(o);
    let layout1 = INVALID;
    let layout2 = INVALID;
    for (let k = 0; k < frames; k++) {
      const f = o + k * FRAME_SIZE;
      const layout = slotLayout(this.#buf, f, resolution);
      if (layout === INVALID) return -1;
      if (!plausibleRssi(view.getUint8(f))) implausibleRssi++;
      if (k > 0) {
        const fades = view.getUint16(f);
        if (((fades - prevFades) & 0xffff) >= MAX_FADE_STEP) external = false;
        prevFades = fades;
      }
      if (layout === layout2) recurring++;
      layout2 = layout1;
      layout1 = layout;
      channels |= layoutChannels(layout);
      zeroWords += countZeroWords(this.#buf, f);
    }
    if (!internal && !external) return -1;
    let score = 10 * frames + recurring - zeroWords;
    if (internal) {
      // A start on the corrupted frame scores below a start on clean ones.
      score += 4 - 3 * (frames - same);
      if (systemInfo(b1)?.resolution === resolution) score += 2;
    } else if (view.getUint16(o) < 256) {
      score += 1;
    }
    // Transmitters send channels 0…N-1: a contiguous set is the signature of the right reading.
    if ((channels & (channels + 1)) === 0) score += 2;
    this.#candInternal = internal;
    // §8.3.1: negative byte 0 from the start means RSSI (one corrupted frame allowed).
    this.#candRssi = internal && (headerMode === 'rssi' || (headerMode === 'auto' && implausibleRssi <= (frames > 1 ? 1 : 0)));
    this.#candSystem = b1;
    return score;
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
    if (this.#resolution === null) return 'Not locked on to frames yet.';
    if (!this.#locked) return 'Looking for frames again: the format changed or the frames stopped making sense.';
    const res = this.#resolution;
    const sys = this.#system === null ? undefined : systemInfo(this.#system);
    const hex = (v: number) => `0x${v.toString(16).padStart(2, '0').toUpperCase()}`;
    const remote = this.#remote === 'internal'
      ? `internal remote (system byte ${hex(this.#system ?? 0)}${sys ? `, ${sys.name}` : ''})`
      : 'external remote (or a receiver that sends no system byte): bytes 0–1 are a UINT16 fade count';
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
    this.#view = new DataView(buf.buffer);
    if (byteTimes !== null) {
      const times = new Float64Array(capacity);
      times.set(byteTimes.subarray(0, this.#tail));
      this.#byteTimes = times;
    }
  }
}
