/** Owned copies of frames, for anything that keeps a frame past the next `next()` call. */
import { channelResolution, servoToMicros } from './spec.js';
import type { DecodedFrame, RemoteKind, VtxControl } from './types.js';
import type { Resolution } from './spec.js';

/** One channel value in a snapshot. */
export interface ChannelValue {
  /** Channel ID 0–19 (12–19 are X+1 … X+8). */
  id: number;
  /** Servo position: 0–1023 or 0–2047; X-Plus on the 2047 scale. */
  pos: number;
  /** Pulse width in µs (§9), rounded. */
  us: number;
}

/** A frame as plain data: owned, JSON-friendly, safe to keep or post to another thread. */
export interface FrameSnapshot {
  index: number;
  offset: number;
  /** µs, NaN without timing. */
  timeUs: number;
  remote: RemoteKind;
  system: number | null;
  resolution: Resolution;
  fades: number | null;
  fadesDelta: number;
  rssi: number | null;
  channels: ChannelValue[];
  vtx: VtxControl | null;
  /** The 16 raw bytes (a copy). */
  bytes: Uint8Array;
}

/** Copies a borrowed frame into a snapshot you own. */
export function copyFrame(frame: DecodedFrame): FrameSnapshot {
  const channels: ChannelValue[] = [];
  const { ids, positions } = frame;
  for (let i = 0; i < frame.count; i++) {
    const id = ids[i];
    const pos = positions[i];
    if (id === undefined || pos === undefined) break; // count is at most the arrays' length (7)
    channels.push({ id, pos, us: servoToMicros(pos, channelResolution(id, frame.resolution)) });
  }
  return {
    index: frame.index,
    offset: frame.offset,
    timeUs: frame.timeUs,
    remote: frame.remote,
    system: frame.system,
    resolution: frame.resolution,
    fades: frame.fades,
    fadesDelta: frame.fadesDelta,
    rssi: frame.rssi,
    channels,
    vtx: frame.vtx === null ? null : { ...frame.vtx },
    bytes: frame.bytes.slice(),
  };
}
