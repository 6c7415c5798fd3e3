/**
 * What byte 0 of an internal remote's chain says at a lock: whether it stands still (an
 * external count whose low byte is a §8.3 system byte reads the same), and whether it is a fade
 * count or SPM4649T RSSI where every value so far could be either. Acquisition (acquire.ts)
 * asks; the header model's rules (header.ts) answer frame by frame.
 */
import { byteAt, INVALID, slotLayout } from './frame.js';
import { B0_FADES, B0_RSSI, B0_UNKNOWN, byte0FollowsAcquiring, plausibleRssi } from './header.js';
import { FRAME_SIZE, type Resolution } from './spec.js';
import type { Core } from './state.js';

/** The answer depends on bytes that have not arrived. */
export const NEED_MORE = -2;

/**
 * Frames read, at most, to decide whether an internal remote's byte 0 is a fade count or
 * SPM4649T RSSI when every value so far could be either (a fade count of 156…226 reads as
 * -100…-30 dBm). RSSI wanders both ways; fades only rise. Without a fall or a value no RSSI
 * takes in this many frames the decoder says it does not know. Unpinned: 7 or 9 change no test.
 */
const HEADER_EVIDENCE_FRAMES = 8;

/** Whether byte 0 is the same in each of the `frames` frames from `o`. */
export function byte0Still(d: Core, o: number, frames: number): boolean {
  const b0 = byteAt(d.w.buf, o);
  for (let k = 1; k < frames; k++) if (byteAt(d.w.buf, o + k * FRAME_SIZE) !== b0) return false;
  return true;
}

/**
 * Reads byte 0 along the chain at `o` (an internal remote whose byte 0 has only been a plausible
 * RSSI): B0_FADES on a value no RSSI takes, B0_RSSI on a fall, B0_UNKNOWN after HEADER_EVIDENCE_FRAMES
 * without either (or where the chain ends), NEED_MORE when more bytes could decide it.
 */
export function byte0Evidence(d: Core, o: number, resolution: Resolution, system: number): number {
  const buf = d.w.buf;
  let prev = byteAt(buf, o);
  for (let k = 1; k < HEADER_EVIDENCE_FRAMES; k++) {
    const f = o + k * FRAME_SIZE;
    if (f + FRAME_SIZE > d.w.tail) return d.w.ended ? B0_UNKNOWN : NEED_MORE;
    const b0 = byteAt(buf, f);
    if (buf[f + 1] !== system || slotLayout(buf, f, resolution) === INVALID || !byte0FollowsAcquiring(prev, b0, B0_UNKNOWN))
      return B0_UNKNOWN;
    if (!plausibleRssi(b0)) return B0_FADES;
    if (b0 < prev) return B0_RSSI;
    prev = b0;
  }
  return B0_UNKNOWN;
}
