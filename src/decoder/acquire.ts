/**
 * Acquisition: where frames start, and how to read them, from the bytes (no sync byte; timing
 * only where each byte has its own time: no frame has a silence inside it). The second of the decoder's three parts: plain functions over the decoder's
 * `Core` that read its window and, in `acquire`, take the lock.
 *
 * It reads four frames from each of the next 48 start offsets under both resolutions and under
 * one header model (header.ts: an internal remote, one system byte in every frame and a fade
 * byte that only rises, slowly; an external one, a UINT16 fade count that only rises, slowly).
 * Every slot must hold a valid channel ID (or 0xFFFF, or VTX) with no repeats. Contiguous
 * channel sets, layouts that recur every other frame and a system byte that agrees with the
 * resolution score higher (`scoreChain`). The chain's first frame must carry channels: filler
 * (runs of 0xFF are frames of seven empty slots) never locks. The winning chain's frames are
 * emitted as they stand (`confirmedUntil`).
 */
import {
  byteAt,
  channelEvidence,
  countZeroWords,
  INVALID,
  layoutChannels,
  phaseBitsAfterFirst,
  slotDisorder,
  slotLayout,
} from './frame.js';
import { formatOf, setReason } from './format.js';
import {
  B0_FADES,
  B0_RSSI,
  B0_RSSI_FORCED,
  B0_UNKNOWN,
  byte0Follows,
  byte0FollowsAcquiring,
  countFollows,
  countFollowsAcquiring,
  plausibleRssi,
} from './header.js';
import { FRAME_SIZE, type Resolution, systemInfo } from './spec.js';
import { type Core, discard, event, knownLayout } from './state.js';
import { byte0Evidence, byte0Still, NEED_MORE } from './byte0.js';
import type { Withheld } from './types.js';

/** Frames looked at before a lock. Pinned by the golden output (3 or 5 change it). */
const ACQUIRE_FRAMES = 4;
/**
 * Fewest of them that must chain for a lock: two frames that happen to parse are common. 4 fails
 * decoder.damage.test.ts (frames lost beside damage in the real PX4 captures); 2 changes no test.
 */
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
 * Bytes of channel words that are not filler (`channelEvidence`) the first frame of a chain
 * must carry for a lock: more than a header's two, which is all a shifted reading of frames of
 * filler slots finds. A transmitter sends four channels or more, and every frame it sends
 * carries four or more (a pair of 8 to 12 channels, 5 to 7 in each), one such byte each at
 * least (a centred channel's low byte is 0x00). 2 fails decoder.filler.test.ts (a channel
 * invented from filler); 4 changes no test.
 */
const EVIDENCE_BYTES = 3;

/**
 * A frame's bytes leave the receiver back to back: 16 bytes with a silence of this much inside
 * them are no frame, where the bytes have times of their own (a logic analyser's). Frames are
 * 9.6 ms apart or more; flight stacks end a frame on a silence of 5 ms.
 */
const SILENCE_IN_FRAME_US = 3_000;

/** Whether the 16 bytes at `o` have a silence inside them (`SILENCE_IN_FRAME_US`): then they are no frame. */
export function silenceInside(d: Core, o: number): boolean {
  return d.w.silenceWithin(o, FRAME_SIZE, SILENCE_IN_FRAME_US);
}

/** A start acquisition may lock on: its score (-1: none), shift from the head and resolution; `filler`: see bestStart. */
interface Best {
  score: number;
  shift: number;
  resolution: Resolution;
  filler: boolean;
}

/** Both resolutions, in the order a tie goes to. */
const RESOLUTIONS = [2048, 1024] as const;

/** The options scoreChain reads with no option forced. */
const FREE = { remote: 'auto', headerMode: 'auto' } as const;

/** Tries to lock at the head. Returns false when it needs more bytes (or the stream is done). */
export function acquire(d: Core): boolean {
  const p = d.w.head;
  const avail = d.w.tail - p;
  const window = ACQUIRE_FRAMES * FRAME_SIZE + ACQUIRE_SHIFTS - 1;
  if (avail < window && !d.w.ended) return false;
  const lost = d.s.everLocked ? 'noise' : 'before-lock';
  if (avail < FRAME_SIZE) {
    if (avail > 0) discard(d, p, avail, d.s.everLocked ? 'end-of-stream' : 'before-lock');
    return false;
  }
  const forced = d.s.opts.resolution;
  const auto = forced === 'auto' && d.s.opts.remote === 'auto' && d.s.opts.headerMode === 'auto';
  // Starts the last pass scored nothing at are not scored again: on noise, two thirds of a pass.
  const known = auto ? Math.max(0, d.s.noStartBelow - (d.w.base + p)) : 0;
  let best = bestStart(d, p, avail, forced === 'auto' ? 0 : forced, false, known);
  if (best.filler) withhold(d, 'filler', p);
  else if (!auto) best = matchForced(d, p, avail, best);
  if (best.score < 0 || (best.shift >= ACQUIRE_COMMIT && avail >= window)) {
    // No alignment starting in these 16 bytes works (or the best starts too late to commit).
    // Where none of the ACQUIRE_SHIFTS starts did, each with all its frames here, the next
    // pass (the same state: discarding changes none) would score the rest of them the same.
    // (A start refused for the frame before it may read otherwise once that frame goes.)
    if (auto && best.score < 0 && !best.filler && !d.chain.lateRefused && avail >= window) d.s.noStartBelow = d.w.base + p + ACQUIRE_SHIFTS;
    discard(d, p, Math.min(FRAME_SIZE, avail), lost);
    return true;
  }
  let o = p + best.shift;
  const resolution = best.resolution;
  // Score again to leave the winner's header reading in the scratch fields.
  scoreChain(d, o, resolution, Math.min(ACQUIRE_FRAMES, Math.floor((avail - best.shift) / FRAME_SIZE)));
  let frames = d.chain.frames;
  let skipped = d.chain.skipped;
  const internal = d.chain.internal;
  const system = d.chain.system;
  // A start that scored best can be a frame late (its chain's layouts recur better): take in
  // the frames before it that the chain continues from.
  while (o - FRAME_SIZE >= p && chainsInto(d, o - FRAME_SIZE, o, resolution, internal, system)) {
    o -= FRAME_SIZE;
    frames++;
    if (skipped >= 0) skipped++;
  }
  // An external remote's frames may read as well a few words off (`shiftedReadings`): take the
  // likelier alignment, and say it is not proven until a header moves as no fade count does.
  let alts = 0;
  if (!internal) {
    // A proven alignment goes on where the new chain starts right where the last frame ended
    // (frames lost in a dropout leave no bytes: the count jumps, the alignment does not) or
    // its count goes on.
    const proven = d.s.haveLast && d.s.remote === 'external' && d.s.alignAlts === 0 && d.s.resolution === resolution;
    const goesOn =
      d.w.base + o === d.s.lastEnd || countFollows((d.s.last0 << 8) | d.s.last1, (byteAt(d.w.buf, o) << 8) | byteAt(d.w.buf, o + 1));
    if (!(proven && goesOn)) {
      alts = shiftedReadings(d, o, resolution, frames);
    }
    const j = alts >>> 16;
    alts &= 0xffff;
    if (j > 0) {
      alts = rotateShifts(alts | 1, j) & ~1;
      o += j;
      scoreChain(d, o, resolution, Math.min(ACQUIRE_FRAMES, Math.floor((d.w.tail - o) / FRAME_SIZE)));
      frames = d.chain.frames;
      skipped = d.chain.skipped;
      while (o - FRAME_SIZE >= p && chainsInto(d, o - FRAME_SIZE, o, resolution, false, 0)) {
        o -= FRAME_SIZE;
        frames++;
        if (skipped >= 0) skipped++;
      }
    }
  }
  const sameRemote =
    d.s.haveLast &&
    d.s.remote === (internal ? 'internal' : 'external') &&
    (internal ? d.s.system === system : true) &&
    d.s.resolution === resolution;
  let b0Mode = d.chain.b0;
  // The same remote going on keeps what its byte 0 was shown to be: where byte 0 goes on, and
  // where it jumped across a break with the layouts it used before (a 1.5 s dropout takes a
  // fade count from 40 to 176, which reads as RSSI as well until it moves).
  if (
    internal &&
    b0Mode === B0_UNKNOWN &&
    sameRemote &&
    (byte0Follows(d.s.last0, byteAt(d.w.buf, o), d.s.b0Mode) || chainKnown(d, o, resolution, frames))
  )
    b0Mode = d.s.b0Mode;
  if (internal && b0Mode === B0_UNKNOWN) {
    // Byte 0 has only been a plausible RSSI and never fallen: read further along the chain before deciding.
    const evidence = byte0Evidence(d, o, resolution, system);
    if (evidence === NEED_MORE) return false;
    b0Mode = evidence;
  }
  // Byte 0 still under a §8.3 system byte reads as an external count whose low byte is that
  // byte as well (18, 162, 178, 434 ...): the bytes tell only when byte 0 moves (internal) or
  // byte 1 does (external; see `countMoved` in locked.ts). A remote shown internal that goes on stays so.
  const ambiguous =
    internal &&
    d.s.opts.remote === 'auto' &&
    b0Mode !== B0_RSSI_FORCED &&
    systemInfo(system) !== undefined &&
    byte0Still(d, o, frames) &&
    !(sameRemote && !d.s.ambiguous);
  if (o > p) discard(d, p, o - p, lost);
  if (d.s.resolution !== resolution) d.s.layoutCount = 0;
  // A count that jumped across the break is the receiver's own when the same remote goes on
  // with layouts it used before (a shifted reading of the stream makes layouts of its own).
  d.s.jumpTrusted = sameRemote && chainKnown(d, o, resolution, frames);
  if (!sameRemote) d.s.haveLast = false;
  const changed =
    d.s.everLocked &&
    (d.s.remote !== (internal ? 'internal' : 'external') ||
      d.s.system !== (internal ? system : null) ||
      d.s.resolution !== resolution ||
      (d.s.alignAlts !== 0) !== (alts !== 0));
  d.s.locked = true;
  d.s.noStartBelow = 0;
  d.s.stagedAt = -1;
  d.s.everLocked = true;
  d.s.forcedMismatch = null;
  d.s.withheld = null;
  // Each frame of the chain is confirmed by the one after it; the last waits for its own next
  // (or the stream's end) like any other, and so does a frame with a damaged header.
  const confirmed = skipped >= 0 ? skipped : frames - (d.w.ended && o + frames * FRAME_SIZE >= d.w.tail - FRAME_SIZE ? 0 : 1);
  d.s.confirmedUntil = d.w.base + o + confirmed * FRAME_SIZE;
  d.s.resolution = resolution;
  d.s.remote = internal ? 'internal' : 'external';
  d.s.system = internal ? system : null;
  d.s.b0Mode = internal ? b0Mode : B0_FADES;
  d.s.ambiguous = ambiguous;
  d.s.alignAlts = alts;
  d.s.altLast.fill(-1);
  setReason(d.s, resolution);
  event(d, { type: 'locked', offset: d.w.base + o, format: formatOf(d.s) });
  if (changed) event(d, { type: 'format-changed', offset: d.w.base + o, format: formatOf(d.s) });
  return true;
}

/**
 * Says why bytes that read as frames give none (`format.withheld`), with a format-changed
 * event when the reason is new: it stands until a lock.
 */
function withhold(d: Core, why: Withheld, o: number): void {
  if (d.s.withheld === why) return;
  d.s.withheld = why;
  event(d, { type: 'format-changed', offset: d.w.base + o, format: formatOf(d.s) });
}

/** Whether `layout` is the layout of one of the `frames` frames from `o`. */
function layoutInChain(d: Core, layout: number, o: number, frames: number, resolution: Resolution): boolean {
  for (let k = 0; k < frames; k++) if (slotLayout(d.w.buf, o + k * FRAME_SIZE, resolution) === layout) return true;
  return false;
}

/**
 * Whether the frame at `a` is valid, has a layout of the chain that starts at `b`, and its
 * header continues into frame `b`'s as acquisition chains them.
 */
function chainsInto(d: Core, a: number, b: number, resolution: Resolution, internal: boolean, system: number): boolean {
  const buf = d.w.buf;
  const layout = slotLayout(buf, a, resolution);
  if (
    layout === INVALID ||
    silenceInside(d, a) ||
    !layoutInChain(d, layout, b, Math.min(ACQUIRE_FRAMES, Math.floor((d.w.tail - b) / FRAME_SIZE)), resolution)
  )
    return false;
  if (internal) {
    const mode = d.s.opts.headerMode === 'rssi' ? B0_RSSI_FORCED : d.s.opts.headerMode === 'fades' ? B0_FADES : B0_UNKNOWN;
    return buf[a + 1] === system && buf[b + 1] === system && byte0FollowsAcquiring(byteAt(buf, a), byteAt(buf, b), mode);
  }
  return countFollowsAcquiring((byteAt(buf, a) << 8) | byteAt(buf, a + 1), (byteAt(buf, b) << 8) | byteAt(buf, b + 1));
}

/**
 * The best-scoring start among the next ACQUIRE_SHIFTS offsets, at one resolution or (0) both.
 * None (score -1, `filler`) when a chain that starts without channels (see
 * EVIDENCE_BYTES) reads better than any that starts with them: those are then shifted
 * readings of the filler and its headers (`00 B2` then seven 0xFFFF slots, read a byte
 * early, has a channel 6 at 0x2FF), not frames.
 */
function bestStart(d: Core, p: number, avail: number, only: 0 | Resolution, free: boolean, known = 0): Best {
  d.chain.fillerScore = -1;
  d.chain.lateRefused = false;
  let score = -1;
  let shift = 0;
  let resolution: Resolution = 2048;
  // Where no start can carry a channel, no chain leads: all that is left to learn is whether
  // the bytes parse as filler, which the first reading that parses tells (runs of 0xFF or
  // 0x00 would otherwise be scored at every shift, both ways, again every 16 bytes).
  const canLead = leadable(d, p, avail);
  // The first `known` starts scored nothing at the last pass (`noStartBelow`): they would again.
  for (let s = known; s < ACQUIRE_SHIFTS; s++) {
    if (!canLead && d.chain.fillerScore > -1) break;
    const frames = Math.min(ACQUIRE_FRAMES, Math.floor((avail - s) / FRAME_SIZE));
    if (frames < 1) break;
    for (const r of RESOLUTIONS) {
      if (only !== 0 && only !== r) continue;
      const v = scoreChain(d, p + s, r, frames, free);
      if (v > score) {
        score = v;
        shift = s;
        resolution = r;
      }
    }
  }
  const filler = d.chain.fillerScore > score;
  return { score: filler ? -1 : score, shift, resolution, filler };
}

/**
 * Whether a frame starting at one of the next ACQUIRE_SHIFTS offsets has EVIDENCE_BYTES bytes
 * other than 0x00 and 0xFF after its header: what `channelEvidence` needs at the least, so
 * where none has, no chain can lead.
 */
function leadable(d: Core, p: number, avail: number): boolean {
  const buf = d.w.buf;
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
function matchForced(d: Core, p: number, avail: number, best: Best): Best {
  if (best.score < 0 && d.s.withheld === 'forced') return best;
  const free = bestStart(d, p, avail, 0, true);
  if (free.score < 0) return free;
  if (best.score >= 0 && (best.shift - free.shift) % FRAME_SIZE === 0) return best;
  const frames = Math.min(ACQUIRE_FRAMES, Math.floor((avail - free.shift) / FRAME_SIZE));
  const forced = d.s.opts.resolution;
  let score = -1;
  let resolution: Resolution = free.resolution;
  for (const r of forced === 'auto' ? RESOLUTIONS : [forced]) {
    const v = scoreChain(d, p + free.shift, r, frames);
    if (v > score) {
      score = v;
      resolution = r;
    }
  }
  if (score >= 0) return { score, shift: free.shift, resolution, filler: false };
  d.s.forcedMismatch = forced !== 'auto' && free.resolution !== forced ? free.resolution : null;
  withhold(d, 'forced', p);
  return { score: -1, shift: 0, resolution, filler: false };
}

/** Whether every frame of the chain at `o` has a layout the lock knows. */
function chainKnown(d: Core, o: number, resolution: Resolution, frames: number): boolean {
  for (let k = 0; k < frames; k++) if (!knownLayout(d.s, slotLayout(d.w.buf, o + k * FRAME_SIZE, resolution))) return false;
  return true;
}

/**
 * How well the frames at `o` (up to `frames`) read as consecutive frames of one remote at
 * `resolution`; -1 when fewer than MIN_CHAIN do. The chain ends at the first invalid frame or header
 * that does not continue it (a damaged frame ahead shortens it, and a shorter chain scores
 * less). Leaves the reading and its length in `d.chain`.
 */
function scoreChain(d: Core, o: number, resolution: Resolution, frames: number, free = false): number {
  const buf = d.w.buf;
  const { remote, headerMode } = free ? FREE : d.s.opts;
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
    if (slotLayout(buf, f, resolution) === INVALID || silenceInside(d, f)) {
      chainI = Math.min(chainI, k);
      chainE = Math.min(chainE, k);
      break;
    }
    if (k === 0) continue;
    const p = f - FRAME_SIZE;
    if (chainI > k) {
      if (buf[f + 1] === s && byte0FollowsAcquiring(byteAt(buf, good), byteAt(buf, f), forcedB0)) good = f;
      else if (damaged < 0 && info !== undefined && k < frames - 1) damaged = k;
      else chainI = k;
    }
    if (chainE > k && !countFollowsAcquiring((byteAt(buf, p) << 8) | byteAt(buf, p + 1), (byteAt(buf, f) << 8) | byteAt(buf, f + 1)))
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
    d.s.haveLast &&
    countFollows((d.s.last0 << 8) | d.s.last1, (byteAt(buf, o) << 8) | s) &&
    ((byteAt(buf, o) << 8) | s) !== ((d.s.last0 << 8) | d.s.last1);
  const preferInternal =
    remote === 'internal' || info !== undefined || (s !== 0 && !zeroByte0 && !countGoesOn && d.s.remote === 'internal');
  const internal = chainI > chainE || (chainI === chainE && preferInternal);
  const length = internal ? chainI : chainE;
  const skipped = internal && damaged >= 0 && damaged < length ? damaged : -1;
  // Where the stream ends too: fewer frames are no evidence (its last frames may go). An
  // unlisted system byte (read as one only after an internal remote) needs a full window.
  if (length < (internal && info === undefined ? ACQUIRE_FRAMES : MIN_CHAIN)) return -1;
  if (internal && info !== undefined && info.resolution !== resolution && (free || d.s.opts.resolution === 'auto')) {
    // Contradict a §8.3 system byte only where its resolution cannot read the frames.
    let readable = 0;
    for (let k = 0; k < length; k++) if (slotLayout(buf, o + k * FRAME_SIZE, info.resolution) !== INVALID) readable++;
    if (readable === length) return -1;
  }
  let positive = false;
  let fell = false;
  let channels = 0;
  let zeroWords = 0;
  let phaseBits = 0;
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
    if (resolution === 2048) phaseBits += phaseBitsAfterFirst(buf, f, layout);
  }
  if (!internal && readsInternalLate(d, o, resolution, length)) {
    d.chain.lateRefused = true;
    return -1;
  }
  // Transmitters repeat their layouts (a pair of frames, mostly): a first frame whose layout
  // comes nowhere else in the chain may be damage (a stray byte that made a slot), not a frame.
  if (length >= MIN_CHAIN && !layoutInChain(d, slotLayout(buf, o, resolution), o + FRAME_SIZE, length - 1, resolution)) return -1;
  // The weights rank readings that all chain (bestStart keeps the highest). What pins each was
  // measured by removing it alone and running the decoder's tests (2026-11-29): the chain
  // length and the system-byte bonus change the golden output (tests/golden: the SPM4649T
  // fixture); the others change no test's result, golden included. They order candidates that
  // the tests never put side by side: a test that does is owed before any of them changes.
  // Chain length dominates: a longer chain of valid frames is the likelier reading.
  let score = 10 * length;
  // Layouts that recur every other frame (a transmitter's pair): the right alignment. Unpinned.
  score += recurring;
  // Zero words (0x0000) in slots are rarer in real frames than in a shifted reading. Unpinned.
  score -= zeroWords;
  // A phase bit past a frame's first slot: a reading shifted off the frames (an external
  // remote's count, which reads as a slot, makes such a reading chain as well as the real one).
  score -= 2 * phaseBits;
  // A frame skipped over for a damaged header makes the chain weaker. Unpinned.
  if (skipped >= 0) score -= 5;
  if (internal) {
    // A §8.3 system byte in every frame is strong evidence of an internal remote. Pinned by golden.
    if (info !== undefined) score += 8;
    // ... and more so when its resolution is the one read. Unpinned.
    if (info?.resolution === resolution) score += 2;
  } else if (((byteAt(buf, o) << 8) | s) < 256) {
    // An external count below 256 (`00 xx`): most external remotes and clones. Unpinned.
    score += 1;
  }
  // A header of 0xFFFF is an empty slot's filler more often than a fade count at its limit. Unpinned.
  if (((byteAt(buf, o) << 8) | s) === 0xffff) score -= 3;
  // Transmitters send channels 0…N-1: a contiguous set is the signature of the right reading. Unpinned.
  if ((channels & (channels + 1)) === 0) score += 2;
  // A chain whose first frame carries no channel is filler that happens to parse (or
  // filler whose chain runs into the frames after it): never a lock, but bestStart weighs it
  // against the other readings.
  if (!leads) {
    if (score > d.chain.fillerScore) d.chain.fillerScore = score;
    return -1;
  }
  d.chain.internal = internal;
  d.chain.system = s;
  d.chain.frames = length;
  d.chain.skipped = skipped;
  d.chain.b0 = forcedB0 !== B0_UNKNOWN ? forcedB0 : positive ? B0_FADES : fell ? B0_RSSI : B0_UNKNOWN;
  return score;
}

/**
 * Whether the external reading at `o` is an internal remote's stream read at the wrong offset:
 * a slot whose low byte is a §8.3 system byte, where frames starting at that slot (as their
 * header) are valid internal frames with that system byte, for as many frames as the reading
 * has. A 1024-mode internal remote read two bytes late otherwise looks like an external one
 * whose fade count is channel 0's position.
 */
function readsInternalLate(d: Core, o: number, resolution: Resolution, length: number): boolean {
  const buf = d.w.buf;
  for (let i = 0; i < 7; i++) {
    const system = byteAt(buf, o + 3 + 2 * i);
    if (systemInfo(system) === undefined) continue;
    let agree = 0;
    for (let h = o + 2 + 2 * i - FRAME_SIZE; h + FRAME_SIZE <= d.w.tail && h < o + length * FRAME_SIZE; h += FRAME_SIZE) {
      if (h >= d.w.head && buf[h + 1] === system && slotLayout(buf, h, resolution) !== INVALID) agree++;
    }
    if (agree >= Math.max(2, length - 1)) return true;
  }
  return false;
}

/**
 * Whether a stream starts at `a` as acquisition would lock on it: a chain of frames of one
 * remote at either resolution (two frames that parse are common in slot bytes read as
 * headers, so it takes the same evidence as a lock).
 */
export function chainStartsAt(d: Core, a: number): 0 | 1 | typeof NEED_MORE {
  // The answer must not depend on how the bytes were chunked: wait for a whole window.
  if (d.w.tail - a < ACQUIRE_FRAMES * FRAME_SIZE && !d.w.ended) return NEED_MORE;
  const frames = Math.min(ACQUIRE_FRAMES, Math.floor((d.w.tail - a) / FRAME_SIZE));
  if (frames < MIN_CHAIN) return 0;
  const forced = d.s.opts.resolution;
  return (forced !== 1024 && scoreChain(d, a, 2048, frames) >= 0) || (forced !== 2048 && scoreChain(d, a, 1024, frames) >= 0) ? 1 : 0;
}

/**
 * The byte shifts (bit j for j = 1…15) at which the external remote's frames at `o` read as
 * well, with nothing the bytes show against them: as many frames (up to ACQUIRE_FRAMES)
 * starting j bytes later, each valid (every slot a valid ID, no repeats), no phase bit past a
 * frame's first slot, and a header that never falls (a fade count only rises; by how much
 * between two frames nothing tells without byte times, where frames lost leave no trace). An
 * external remote that sends one frame shape (22 ms, up to 7 channels: no pair, no phase bit)
 * and a fade count that is also a servo word (at 1024 one below 12288, at 2048 one below
 * 26624 or, with the phase bit, read first) reads so a word early or late: a held stick's
 * word (or an empty slot) as the count, the count as a channel. Only a header that falls (a
 * stick moving down), or a slot ID changing, tells them apart; the locked path weighs them
 * frame by frame (`weighAlignment` in locked.ts).
 *
 * In bits 16 and up, the likelier shift: the one whose slots are in the order a single-shape
 * transmitter sends (slotDisorder: IDs ascending, empty slots last), which the count read as a
 * channel breaks in every shifted reading of such a frame; ties keep the reading at `o` (0),
 * then the lower shift. A preference only: the spec leaves the slot order to the transmitter
 * (§8.5), so the format says the alignment is not proven.
 */
function shiftedReadings(d: Core, o: number, resolution: Resolution, frames: number): number {
  const buf = d.w.buf;
  const need = Math.min(frames, ACQUIRE_FRAMES);
  let alts = 0;
  let best = 0;
  let least = -1;
  for (let j = 0; j < FRAME_SIZE && need >= MIN_CHAIN; j++) {
    const a = o + j;
    let disorder = 0;
    let k = 0;
    for (; k < need && a + (k + 1) * FRAME_SIZE <= d.w.tail; k++) {
      const f = a + k * FRAME_SIZE;
      const layout = slotLayout(buf, f, resolution);
      if (layout === INVALID || silenceInside(d, f) || (resolution === 2048 && phaseBitsAfterFirst(buf, f, layout) > 0)) break;
      const count = (byteAt(buf, f) << 8) | byteAt(buf, f + 1);
      if (k > 0 && ((count - ((byteAt(buf, f - FRAME_SIZE) << 8) | byteAt(buf, f - FRAME_SIZE + 1))) & 0xffff) >= 0x8000) break;
      disorder += slotDisorder(layout);
    }
    if (j > 0 && k < need) continue;
    if (j > 0) alts |= 1 << j;
    if (least < 0 || disorder < least) {
      least = disorder;
      best = j;
    }
  }
  return alts | (best << 16);
}

/** Shifts (bit j: j bytes after an alignment) seen from the alignment `j` bytes later (bit 0 is the alignment itself). */
export function rotateShifts(mask: number, j: number): number {
  return ((mask >>> j) | (mask << (FRAME_SIZE - j))) & 0xffff;
}
