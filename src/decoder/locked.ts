/**
 * The locked path: how a frame is accepted once the decoder knows the format. The third of the
 * decoder's three parts, and the one rule for every frame after a lock:
 *
 * - Frames acquisition confirmed go out as they stand.
 * - A frame is emitted when it continues the last one (header.ts: same remote, fade count risen
 *   by less than FADE_STEP) and the whole next frame is valid and continues it: one frame
 *   period of latency. A frame whose slot layout is new must also not overlap a frame that
 *   continues the stream (the front of one frame glued to the back of the next after lost
 *   bytes reads as a new layout).
 * - A frame that fails starts a search for the nearest offset where a known layout continues the
 *   stream; what lies between is discarded and counted. Where nothing continues (a rebind, a
 *   system byte that changed, a fade count that jumped, another satellite) it acquires afresh.
 *
 * Each byte is read once: confirming a frame reads the next one into the staged slot set
 * (`state.ts`), which the frame shows when that one is emitted in turn.
 *
 * Every pass of `nextFrame` emits a frame, consumes at least one byte, waits for input, or turns
 * an unlock into an acquisition, which itself consumes or locks with frames it has confirmed
 * (emitted unconditionally): so it always returns after bounded work.
 */
import { acquire, chainStartsAt, rotateShifts, silenceInside } from './acquire.js';
import { NEED_MORE } from './byte0.js';
import { byteAt, type FrameSlots, INVALID, phaseBitsAfterFirst, readFrame, showSlots, slotDisorder, slotLayout } from './frame.js';
import { formatOf, setReason } from './format.js';
import { B0_FADES, B0_RSSI, B0_UNKNOWN, byte0Follows, countFollows, FADE_STEP, plausibleRssi } from './header.js';
import { FRAME_SIZE } from './spec.js';
import { type Core, type DecoderState, discard, event, knownLayout, learnLayout, unlock } from './state.js';
import type { DecodedFrame } from './types.js';

/** How far a locked decoder searches for a frame that continues the stream before it acquires afresh. */
const MAX_RESYNC_BYTES = 8 * FRAME_SIZE;
const NOT_FOUND = -1;

/** The next frame, or undefined when more bytes are needed (the decoder's `next()`). */
export function nextFrame(d: Core): DecodedFrame | undefined {
  for (;;) {
    if (!d.s.locked) {
      if (!acquire(d)) return undefined;
      continue;
    }
    const frame = lockedStep(d);
    if (frame !== null) return frame;
  }
}

/**
 * The locked path's common case, decided in one pass: the frame at the head is the staged one
 * (it continues the last frame: checked when it was staged), its layout is known, byte 0's
 * reading is settled, and the whole next frame is in, valid and continues it (`continues`).
 * Then it is shown (`show`) exactly as the rest of `lockedStep` would emit it, and the next
 * frame is staged in turn. Anything else returns null and the rest of `lockedStep` decides.
 * A hot function (bench/README.md, "Why the hot paths are written as they are").
 */
function steadyStep(d: Core): DecodedFrame | null {
  const { s, w } = d;
  const o = w.head;
  const n = o + FRAME_SIZE;
  const at = w.base + o;
  if (
    at !== s.stagedAt ||
    n + FRAME_SIZE > w.tail ||
    at < s.confirmedUntil ||
    !s.haveLast ||
    s.ambiguous ||
    s.alignAlts !== 0 ||
    s.b0Mode === B0_UNKNOWN
  ) {
    return null;
  }
  const layout = s.stagedLayout;
  const buf = w.buf;
  if (
    !knownLayout(s, layout) ||
    !continues(s, byteAt(buf, o), byteAt(buf, o + 1), byteAt(buf, n), byteAt(buf, n + 1)) ||
    silenceInside(d, n)
  )
    return null;
  const next = readFrame(buf, w.buf32, n, s.resolution, s.shown);
  if (next === INVALID) return null;
  const slots = s.staged;
  s.staged = s.shown;
  s.shown = slots;
  s.stagedAt = at + FRAME_SIZE;
  s.stagedLayout = next;
  return show(d, o, slots);
}

/** One step of the locked path: a frame, undefined when more bytes are needed, null to go round again. */
function lockedStep(d: Core): DecodedFrame | null | undefined {
  const steady = steadyStep(d);
  if (steady !== null) return steady;
  const { s, w } = d;
  const o = w.head;
  const avail = w.tail - o;
  if (avail < FRAME_SIZE) {
    if (w.ended && avail > 0) discard(d, o, avail, 'end-of-stream');
    return undefined;
  }
  if (s.alignAlts !== 0) {
    // The alignment is not proven: the readings a few bytes off are weighed first.
    const weighed = weighAlignment(d, o);
    if (weighed !== 0) return weighed === NEED_MORE ? undefined : null;
  }
  const at = w.base + o;
  // Bytes with a silence inside them (where each byte has its own time) are no frame.
  const layout = at === s.stagedAt ? s.stagedLayout : silenceInside(d, o) ? INVALID : slotLayout(w.buf, o, s.resolution);
  if (at < s.confirmedUntil && layout !== INVALID) return emit(d, o, layout);
  if (layout !== INVALID && countMoved(d, o, layout)) rereadExternal(d, o);
  // A staged frame is known to continue the last one: it was checked when it was staged.
  const fits = layout !== INVALID && (at === s.stagedAt || fitsLast(d, o));
  if (fits) {
    // The whole next frame must be in: a header alone is too weak (`00 00` read one byte
    // late is `00 0c`, a count that rose by 12).
    if (avail < 2 * FRAME_SIZE) {
      if (!w.ended) return undefined;
      // The stream's last frame: whole when the stream ends with it, or when what is left
      // after it starts with a header that continues it (a truncated last frame).
      if (knownLayout(s, layout) && (avail === FRAME_SIZE || (avail >= FRAME_SIZE + 2 && standsAlone(d, o, layout, o + FRAME_SIZE)))) {
        return emit(d, o, layout);
      }
      discard(d, o, avail, 'end-of-stream');
      return undefined;
    }
    const next = follows(d, o, o + FRAME_SIZE) && !silenceInside(d, o + FRAME_SIZE) ? stageNext(d, o, layout) : INVALID;
    if (next !== INVALID) {
      if (knownLayout(s, layout)) return emitStaged(d, o, layout, next);
      // A new layout: make sure no frame that continues the stream starts inside this one.
      const q = search(d, o + 1, o + FRAME_SIZE - 1);
      if (q === NEED_MORE) return undefined;
      if (q === NOT_FOUND) return emitStaged(d, o, layout, next);
      resync(d, o, q);
      return null;
    }
  }
  if (!fits && layout !== INVALID && countJumped(d, o, layout)) {
    // The same remote goes on after lost frames (its fade count jumped): no frame that
    // continues the old count starts inside this one.
    const q = search(d, o + 1, o + FRAME_SIZE - 1);
    if (q === NEED_MORE) return undefined;
    if (q === NOT_FOUND) {
      s.jumpTrusted = true;
      return emit(d, o, layout);
    }
  }
  // The frame at o does not continue the stream (or the next one does not continue it).
  return findContinuation(d, o, layout, fits);
}

/**
 * Reads the frame at `o` (its layout `layout`, continuing the last frame) into the staged set,
 * unless it is there, and the frame after it into the shown set (the borrowed frame's, free
 * until the next emit). Returns the next frame's layout, INVALID when it is no frame (the frame
 * at `o` stays staged).
 */
function stageNext(d: Core, o: number, layout: number): number {
  const { s, w } = d;
  const at = w.base + o;
  if (s.stagedAt !== at) {
    readFrame(w.buf, w.buf32, o, s.resolution, s.staged);
    s.stagedAt = at;
    s.stagedLayout = layout;
  }
  return readFrame(w.buf, w.buf32, o + FRAME_SIZE, s.resolution, s.shown);
}

/** Emits the frame at `o`, staged with the frame after it (layout `next`) read: that one is staged in turn. */
function emitStaged(d: Core, o: number, layout: number, next: number): DecodedFrame {
  const { s } = d;
  const reading = s.b0Mode;
  // emit() shows the staged set and stages the shown one, which holds the next frame: staged,
  // as it continues this one, unless emitting it decided how byte 0 reads (then it is checked again).
  const frame = emit(d, o, layout);
  if (s.b0Mode === reading) {
    s.stagedAt = frame.offset + FRAME_SIZE;
    s.stagedLayout = next;
  }
  return frame;
}

/**
 * The frame at `o` does not continue the stream, or the frame after it does not continue it:
 * find where frames go on. Returns the frame at `o` when it is whole after all, null when the
 * caller should go round again (bytes were discarded, or the lock was let go), undefined when
 * more bytes are needed.
 */
function findContinuation(d: Core, o: number, layout: number, fits: boolean): DecodedFrame | null | undefined {
  const { s } = d;
  const q = search(d, o + 1, o + MAX_RESYNC_BYTES);
  if (q === NEED_MORE) return undefined;
  // This remote's own chain that starts right after this frame (or at it) is the remote going
  // on after its count fell (a restart), not noise to skip on the way to a frame that
  // happens to fit the old count further on.
  const internal = s.remote === 'internal';
  const restartAfter = internal && q !== NOT_FOUND && q > o + FRAME_SIZE && ownChainAt(d, o + FRAME_SIZE);
  if (fits && (q === NOT_FOUND ? lastOfItsKind(d, o, layout) : (restartAfter && knownLayout(s, layout)) || standsAlone(d, o, layout, q))) {
    // This frame is whole: what follows it up to q is noise, or something new starts after it.
    return emit(d, o, layout);
  }
  if (!fits && internal && q !== NOT_FOUND && q >= o + FRAME_SIZE && ownChainAt(d, o)) {
    unlock(s);
    return null;
  }
  if (q !== NOT_FOUND) {
    resync(d, o, q);
    return null;
  }
  // Nothing continues within reach: the format may have changed. Acquire afresh from here.
  unlock(s);
  return null;
}

/** Whether the header at `o` continues the last emitted frame under the lock's model. */
function fitsLast(d: Core, o: number): boolean {
  const { s } = d;
  const buf = d.w.buf;
  if (s.haveLast) return continues(s, s.last0, s.last1, byteAt(buf, o), byteAt(buf, o + 1));
  // The first frame after a lock: an internal remote's own system byte (and RSSI read as such).
  return s.remote !== 'internal' || (buf[o + 1] === s.system && (s.b0Mode !== B0_RSSI || byteAt(buf, o) >= 0x80));
}

/** Whether the frame at `b` can be the frame right after the one at `a` under the lock's model. */
function follows(d: Core, a: number, b: number): boolean {
  const buf = d.w.buf;
  return continues(d.s, byteAt(buf, a), byteAt(buf, a + 1), byteAt(buf, b), byteAt(buf, b + 1));
}

/** The header rule of the lock: whether header `next0 next1` can come right after `prev0 prev1`. */
function continues(s: DecoderState, prev0: number, prev1: number, next0: number, next1: number): boolean {
  if (s.remote === 'internal') return next1 === s.system && byte0Follows(prev0, next0, s.b0Mode);
  return countFollows((prev0 << 8) | prev1, (next0 << 8) | next1);
}

/**
 * Whether the frame at `o` is the same internal remote going on with a fade count that jumped:
 * a known layout, its own system byte, and a whole next frame that continues it.
 */
function countJumped(d: Core, o: number, layout: number): boolean {
  const { s, w } = d;
  const buf = w.buf;
  // An external count has no system byte to vouch for it: a jump there may be an internal
  // remote taking over (`00 00` then `00 B2`), which acquisition decides.
  if (s.remote !== 'internal' || !knownLayout(s, layout) || o + 2 * FRAME_SIZE > w.tail) return false;
  if (buf[o + 1] !== s.system || (s.b0Mode === B0_RSSI && !plausibleRssi(byteAt(buf, o)))) return false;
  // Fades rise: a fall is something else (a restarted receiver, RSSI), for acquisition to read.
  if (s.b0Mode !== B0_RSSI && s.haveLast && ((byteAt(buf, o) - s.last0) & 0xff) >= 0x80) return false;
  return slotLayout(buf, o + FRAME_SIZE, s.resolution) !== INVALID && follows(d, o, o + FRAME_SIZE);
}

/**
 * The nearest offset in [from, to] where frames continue: a frame with a known layout that
 * continues the stream, confirmed by the frame after it; or, before that one, a frame that
 * stands alone (see standsAlone). NOT_FOUND, or NEED_MORE when the answer depends on bytes
 * that have not arrived.
 */
function search(d: Core, from: number, to: number): number {
  const { s, w } = d;
  const resolution = s.resolution;
  const buf = w.buf;
  let alone = NOT_FOUND;
  let aloneLayout = INVALID;
  for (let q = from; q <= to; q++) {
    if (q + 2 * FRAME_SIZE > w.tail) return w.ended ? NOT_FOUND : NEED_MORE;
    const layout = slotLayout(buf, q, resolution);
    if (layout === INVALID || !fitsLast(d, q) || !knownLayout(s, layout)) continue;
    if (slotLayout(buf, q + FRAME_SIZE, resolution) !== INVALID && follows(d, q, q + FRAME_SIZE)) {
      return alone !== NOT_FOUND && standsAlone(d, alone, aloneLayout, q) ? alone : q;
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
function standsAlone(d: Core, o: number, layout: number, q: number): boolean {
  const { s } = d;
  if (q < o + FRAME_SIZE || !knownLayout(s, layout)) return false;
  const buf = d.w.buf;
  const n = o + FRAME_SIZE;
  // An external count (often `00 00`) is too weak a header to stand on: zero bytes abound in slots.
  return s.remote === 'internal' && buf[n + 1] === s.system && byte0Follows(byteAt(buf, o), byteAt(buf, n), s.b0Mode);
}

/**
 * Whether the frame at `o` may be the last of the stream's current kind (nothing within reach
 * continues it): its layout is known and a new kind of stream starts right where it ends
 * (two valid frames at any resolution whose headers continue each other), so that nothing
 * was lost inside it.
 */
function lastOfItsKind(d: Core, o: number, layout: number): boolean {
  const { s, w } = d;
  if (!knownLayout(s, layout)) return false;
  const a = o + FRAME_SIZE;
  if (s.haveLast && a + FRAME_SIZE <= w.tail && slotLayout(w.buf, a, s.resolution) !== INVALID && fitsLast(d, a)) return false;
  return chainStartsAt(d, a) === 1;
}

/**
 * Whether two valid frames of this internal remote start at `a`: its system byte in both and
 * a byte 0 that goes on from one to the other. Needs only bytes the search has already seen.
 */
function ownChainAt(d: Core, a: number): boolean {
  const { s, w } = d;
  const buf = w.buf;
  const b = a + FRAME_SIZE;
  if (b + FRAME_SIZE > w.tail) return false;
  return (
    buf[a + 1] === s.system &&
    buf[b + 1] === s.system &&
    slotLayout(buf, a, s.resolution) !== INVALID &&
    slotLayout(buf, b, s.resolution) !== INVALID &&
    byte0Follows(byteAt(buf, a), byteAt(buf, b), s.b0Mode)
  );
}

/**
 * Whether the frame at `o` (valid, its layout `layout`) shows that the internal remote the
 * lock may have misread (`ambiguous`) is an external one whose count moved in its low byte:
 * byte 1, a true system byte that never changes, rose as a count does from the last frame,
 * with a layout the lock knows, and the whole next frame goes on as that count (a flipped
 * bit in byte 1 goes back).
 */
function countMoved(d: Core, o: number, layout: number): boolean {
  const { s, w } = d;
  if (!s.ambiguous || !s.haveLast || !knownLayout(s, layout) || o + 2 * FRAME_SIZE > w.tail) return false;
  const buf = w.buf;
  const last = (s.last0 << 8) | s.last1;
  const count = (byteAt(buf, o) << 8) | byteAt(buf, o + 1);
  if (count === last || !countFollows(last, count)) return false;
  const next = (byteAt(buf, o + FRAME_SIZE) << 8) | byteAt(buf, o + FRAME_SIZE + 1);
  return slotLayout(buf, o + FRAME_SIZE, s.resolution) !== INVALID && countFollows(count, next);
}

/** The lock read an external remote as internal (`ambiguous`): it reads it as the external one it is from here. */
function rereadExternal(d: Core, o: number): void {
  const { s } = d;
  s.remote = 'external';
  s.system = null;
  s.b0Mode = B0_FADES;
  s.ambiguous = false;
  s.stagedAt = -1;
  setReason(s, s.resolution);
  event(d, { type: 'format-changed', offset: d.w.base + o, format: formatOf(s) });
}

/**
 * Whether the lock's header fell at the frame at `o` or the one after it, as no fade count does
 * (a fall of less than half the range: more is a wrap): a held stick's word read as the count
 * that moved down.
 */
function headerFell(d: Core, o: number): boolean {
  const { s } = d;
  const buf = d.w.buf;
  const last = (s.last0 << 8) | s.last1;
  const a = (byteAt(buf, o) << 8) | byteAt(buf, o + 1);
  const b = (byteAt(buf, o + FRAME_SIZE) << 8) | byteAt(buf, o + FRAME_SIZE + 1);
  return ((a - last) & 0xffff) >= 0x8000 || ((b - a) & 0xffff) >= 0x8000;
}

/** Discards the bytes from `o` up to `q`, where frames continue. */
function resync(d: Core, o: number, q: number): void {
  d.s.stats.resyncs++;
  d.s.stats.badFrames++;
  // Bytes went: a shifted reading's last header is no measure across them.
  if (d.s.alignAlts !== 0) d.s.altLast.fill(-1);
  event(d, { type: 'resync', offset: d.w.base + q });
  discard(d, o, q - o, q - o < FRAME_SIZE ? 'truncated-frame' : 'noise');
}

/** Emits the frame at `o`, its layout `layout`. */
function emit(d: Core, o: number, layout: number): DecodedFrame {
  const { s, w } = d;
  learnLayout(s, layout);
  if (s.remote === 'internal' && s.haveLast) settleByte0(d, o);
  // The slots: read while confirming the frame before (staged), or now.
  if (s.stagedAt === w.base + o) {
    const staged = s.staged;
    s.staged = s.shown;
    s.shown = staged;
    s.stagedAt = -1;
  } else readFrame(w.buf, w.buf32, o, s.resolution, s.shown);
  return show(d, o, s.shown);
}

/**
 * Shows the frame at `o` with its slots `slots`: its time, its header read under the lock's
 * model (byte 0's reading settled), its slots; and counts it. The one place a frame is written.
 * Kept whole rather than split into helpers: the JIT then compiles it as one unit wherever it
 * is called from (bench/README.md, "Why the hot paths are written as they are").
 */
function show(d: Core, o: number, slots: FrameSlots): DecodedFrame {
  const { s, w, frame } = d;
  const buf = w.buf;
  const at = w.base + o;
  frame.index = s.stats.frames;
  frame.offset = at;
  w.dateNext(at);
  frame.timeUs = w.when[0] ?? Number.NaN;
  frame.resolution = s.resolution;
  frame.remote = s.remote;
  const b0 = byteAt(buf, o);
  const b1 = byteAt(buf, o + 1);
  // The header under the lock's model.
  if (s.remote !== 'internal') {
    const count = (b0 << 8) | b1;
    frame.system = null;
    frame.rssi = null;
    frame.fades = count;
    frame.fadesDelta = s.haveLast ? fadeDelta(d, o, (s.last0 << 8) | s.last1, count, 0xffff) : 0;
  } else {
    frame.system = b1;
    const mode = s.b0Mode;
    if (mode === B0_FADES) {
      frame.rssi = null;
      frame.fades = b0;
      frame.fadesDelta = s.haveLast ? fadeDelta(d, o, s.last0, b0, 0xff) : 0;
    } else if (mode === B0_UNKNOWN) {
      frame.rssi = null;
      frame.fades = null;
      frame.fadesDelta = 0;
    } else {
      frame.rssi = b0 >= 0x80 ? b0 - 0x100 : b0;
      frame.fades = null;
      frame.fadesDelta = 0;
    }
  }
  s.last0 = b0;
  s.last1 = b1;
  s.haveLast = true;
  s.lastEnd = at + FRAME_SIZE;
  s.jumpTrusted = false;
  showSlots(frame, slots);
  const stats = s.stats;
  stats.frames++;
  stats.frameBytes += FRAME_SIZE;
  stats.pendingBytes -= FRAME_SIZE;
  stats.emptySlots += slots.empty;
  if (slots.hasVtx) stats.vtxFrames++;
  w.head = o + FRAME_SIZE;
  return frame;
}

/**
 * What an internal remote's frame at `o` tells about byte 0, before it is shown. Byte 0 moved
 * under a still byte 1: an internal remote (an external count moves its low byte first), the
 * reading stands, only surer (no event). Undecided: a value no RSSI takes says fades, a fall
 * says RSSI.
 */
function settleByte0(d: Core, o: number): void {
  const { s } = d;
  const b0 = byteAt(d.w.buf, o);
  if (s.ambiguous && b0 !== s.last0) s.ambiguous = false;
  if (s.b0Mode !== B0_UNKNOWN) return;
  if (!plausibleRssi(b0)) s.b0Mode = B0_FADES;
  else if (b0 < s.last0) s.b0Mode = B0_RSSI;
  else return;
  event(d, { type: 'format-changed', offset: d.w.base + o, format: formatOf(s) });
}

/**
 * Fades since the last frame. Within a chain the rise is below FADE_STEP. A larger one only
 * comes after a new lock: it is the receiver's own count (and counted) when the same remote
 * continues with layouts it used before and the counter rose by less than half its range;
 * anything else is reported as a `fade-jump` and counts nothing.
 */
function fadeDelta(d: Core, o: number, from: number, to: number, mask: number): number {
  const delta = (to - from) & mask;
  if (delta < FADE_STEP) return delta;
  const counted = d.s.jumpTrusted && delta <= mask >> 1;
  if (!counted) d.s.stats.fadeJumps++;
  event(d, { type: 'fade-jump', offset: d.w.base + o, from, to, counted });
  return counted ? delta : 0;
}

/**
 * Weighs the readings of the stream a few bytes off the lock's (`alignAlts`, from acquisition's
 * `shiftedReadings`) at the frame at `o`, with the frame after it in. Where the lock's frame
 * and the next are valid and continue each other, the bytes are whole: a shifted reading whose
 * frame there is no frame (the count it reads as a channel changed ID), or whose header fell
 * as no fade count does (a held stick that moved down), is refuted (a rise, however large, is
 * what a count does across lost frames, and without byte times nothing shows them); when none is left the alignment is proven (a
 * `format-changed` event). Where instead the lock's own header stops continuing (its "count"
 * was a stick) while a shifted reading's goes on, the stream is read again at that reading
 * from here: the bytes before it are discarded, its header is the last count, the layouts
 * learnt are forgotten, and a `format-changed` event says so (proven when no other reading held). Elsewhere (damage) nothing is
 * judged. Returns 0 to go on with the frame at `o`, 1 after a re-read, NEED_MORE for bytes.
 */
function weighAlignment(d: Core, o: number): number {
  const { s, w } = d;
  const buf = w.buf;
  const n = o + FRAME_SIZE;
  if (n + FRAME_SIZE > w.tail) return w.ended ? 0 : NEED_MORE;
  const resolution = s.resolution;
  const whole =
    !silenceInside(d, o) &&
    !silenceInside(d, n) &&
    slotLayout(buf, o, resolution) !== INVALID &&
    slotLayout(buf, n, resolution) !== INVALID;
  const holds = whole && fitsLast(d, o) && follows(d, o, n);
  let held = 0;
  let judged = 0;
  let best = -1;
  let least = 0;
  for (let j = 1; j < FRAME_SIZE; j++) {
    const bit = 1 << j;
    if ((s.alignAlts & bit) === 0) continue;
    const a = o + j;
    const layout = silenceInside(d, a) ? INVALID : slotLayout(buf, a, resolution);
    const count = (byteAt(buf, a) << 8) | byteAt(buf, a + 1);
    const last = s.altLast[j] ?? -1;
    if (layout === INVALID || (resolution === 2048 && phaseBitsAfterFirst(buf, a, layout) > 0)) continue;
    // A fall is no count's; a jump up is a count's across lost frames as well as a stick's.
    if (last >= 0 && ((count - last) & 0xffff) >= 0x8000) continue;
    held |= bit;
    if (last < 0) continue;
    judged |= bit;
    const v = slotDisorder(layout);
    if (best < 0 || v < least) {
      best = j;
      least = v;
    }
  }
  if (holds) {
    for (let j = 1; j < FRAME_SIZE; j++) if ((held & (1 << j)) !== 0) s.altLast[j] = (byteAt(buf, o + j) << 8) | byteAt(buf, o + j + 1);
    if (held !== s.alignAlts) {
      s.alignAlts = held;
      if (held === 0) event(d, { type: 'format-changed', offset: w.base + o, format: formatOf(s) });
    }
    return 0;
  }
  if (!whole || !s.haveLast || best < 0 || !headerFell(d, o)) {
    // Damage, a count that jumped (frames lost: the lock's reading may be right), or nothing to
    // weigh against yet: judge afresh after it.
    s.altLast.fill(-1);
    return 0;
  }
  // The lock's header broke where a shifted reading's goes on: that reading is the stream.
  // The other readings that held, seen from there, are weighed afresh from the next frame.
  const last = s.altLast[best] ?? 0;
  const rest = rotateShifts(judged, best) & ~1;
  s.altLast.fill(-1);
  const at = w.base + o + best;
  discard(d, o, best, 'noise');
  s.alignAlts = rest;
  s.last0 = last >> 8;
  s.last1 = last & 0xff;
  s.layoutCount = 0;
  s.stagedAt = -1;
  s.confirmedUntil = 0;
  s.jumpTrusted = false;
  event(d, { type: 'format-changed', offset: at, format: formatOf(s) });
  return 1;
}
