/** Frames the decoder tests build by hand: a DSMX 2048 frame pair, as a DX-series transmitter sends 10 channels. */
import { encodeInternalFrame, encodeServo2048 } from '../src/simulator/encode.js';

/** The slots of frame `i % 2` of a DSMX pair (10 channels; the first slot's phase bit marks frame 0), positions drifting with `t`. */
export function dsmxSlots(i: number, t: number): number[] {
  const p = (x: number) => 1024 + Math.round(300 * Math.sin(t + x));
  const channels = i % 2 === 0 ? [1, 5, 2, 3, 0, 7, 6] : [1, 5, 2, 3, 4, 8, 9];
  return channels.map((ch, k) => encodeServo2048(ch, p(ch), k === 0 && i % 2 === 0 ? 1 : 0));
}

/** Both frames of a DSMX pair from an internal remote with this fade count and system byte. */
export function dsmxPair(fades: number, system: number, t: number): Uint8Array[] {
  return [0, 1].map((i) => encodeInternalFrame({ fades, system }, dsmxSlots(i, t)));
}
