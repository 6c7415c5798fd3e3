/**
 * The header model: how bytes 0–1 of one frame may follow the last frame's (spec §8.2–8.3).
 * An internal remote sends a system byte (byte 1) that never changes and, in byte 0, a fade
 * count that only rises, slowly (or SPM4649T RSSI, which wanders both ways); an external
 * remote sends a UINT16 fade count that only rises, slowly. Acquisition and the locked path
 * both chain frames by these rules, with a tighter step while acquiring.
 */

/** How byte 0 of an internal remote is read: a fade count, SPM4649T RSSI, not yet known, or RSSI because the caller said so. */
export const B0_FADES = 0;
export const B0_RSSI = 1;
export const B0_UNKNOWN = 2;
export const B0_RSSI_FORCED = 3;

/**
 * The largest rise of a fade counter between two consecutive frames that continues the chain
 * (≈ 90 ms of lost frames at 11 ms; an external count that lands on a §8.3 system byte, 0x12
 * say, is then more likely an internal remote taking over). A larger rise, or any fall that is
 * not a wrap, breaks the chain: the decoder acquires again and reports the jump (`fade-jump`).
 * 9 changes the golden output of damaged streams; 7 changes no test.
 */
export const FADE_STEP = 8;
/**
 * The rise a fade count may take between the frames of a chain that acquisition confirms (and
 * emits as it stands): counts rarely move from one frame to the next, while a frame glued from
 * two (a foreign byte read as its fade count) moves them anywhere. 2 fails decoder.header.test.ts
 * (a fade count that jumps across a dropout); 4 changes no test.
 */
const ACQUIRE_FADE_STEP = 3;

/**
 * §8.3.1: SPM4649T RSSI is -42 (strong) … -92 dBm (weak), -128 on loss. A byte 0 ≥ 0x80 outside
 * -30 … -100 dBm (with a margin for receivers beyond the documented range) is a fade count.
 */
export function plausibleRssi(byte: number): boolean {
  return byte === 0x80 || (byte >= 0x9c && byte <= 0xe2);
}

/** Whether byte 0 of an internal remote can go from `prev` to `next` between consecutive frames, read as `mode`. */
export function byte0Follows(prev: number, next: number, mode: number): boolean {
  return byte0Reads(((next - prev) & 0xff) < FADE_STEP, prev, next, mode);
}

/**
 * byte0Follows with acquisition's tight step, and no wrap: 0xFF, an empty slot's byte, read as
 * a fade count would otherwise "wrap" to the next frame's 0.
 */
export function byte0FollowsAcquiring(prev: number, next: number, mode: number): boolean {
  return byte0Reads(next >= prev && next - prev < ACQUIRE_FADE_STEP, prev, next, mode);
}

/** Whether byte 0 goes from `prev` to `next` read as `mode`, given whether it rose as a fade count may. */
function byte0Reads(rise: boolean, prev: number, next: number, mode: number): boolean {
  if (mode === B0_RSSI_FORCED) return true;
  if (mode === B0_FADES) return rise;
  if (mode === B0_RSSI) return plausibleRssi(next);
  return rise || (plausibleRssi(prev) && plausibleRssi(next));
}

/** Whether an external remote's UINT16 fade count can go from `prev` to `next` between consecutive frames. */
export function countFollows(prev: number, next: number): boolean {
  return ((next - prev) & 0xffff) < FADE_STEP;
}

/** countFollows with acquisition's tight step, and no wrap. */
export function countFollowsAcquiring(prev: number, next: number): boolean {
  return next >= prev && next - prev < ACQUIRE_FADE_STEP;
}
