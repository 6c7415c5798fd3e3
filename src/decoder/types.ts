import type { Resolution } from './spec.js';

/** Which header a remote sends (spec §8.2, §8.3): internal (fades or RSSI, then a system byte) or external (a UINT16 fade count). */
export type RemoteKind = 'internal' | 'external';

/** What byte 0 of an internal remote's frame carries (§8.3, §8.3.1). */
export type HeaderMode = 'fades' | 'rssi';

/**
 * How the decoder reads byte 0 of the remote it is locked on: a header mode, or 'unknown' while
 * an internal remote's byte 0 has stayed ≥ 0x80 without falling (fades above 127 and SPM4649T
 * RSSI look alike until one rises past 255 or the other falls).
 */
export type HeaderReading = HeaderMode | 'unknown';

/**
 * Spektrum VTX control carried in the last two slots (bytes 12–15) instead of channels.
 * Fields follow the layout PX4 and Betaflight read.
 */
export interface VtxControl {
  /** The raw 32-bit value of bytes 12–15. */
  raw: number;
  /** Band index, 0–7 (Fatshark, Raceband, E, B, A as the transmitter numbers them). */
  band: number;
  /** Channel index within the band, 0–15. */
  channel: number;
  /** Power index, 0–7. */
  power: number;
  /** 0 = US, 1 = EU. */
  region: number;
  /** Pit mode on. */
  pit: boolean;
}

/**
 * One decoded frame. The decoder hands out the same object each time: it is a borrowed view,
 * valid until the next call to `next()`, `push()`, `end()` or `reset()`. Copy what you keep
 * (`copyFrame()` does it for you). Its arrays are borrowed too, and may be other arrays in the
 * next frame (the decoder fills one set while the frame shows the other): read them through
 * the frame each time rather than keep them.
 */
export interface DecodedFrame {
  /** Sequence number of the frame since the decoder was created or last reset (0, 1, 2, …). */
  index: number;
  /** Byte offset of the frame's first byte in the stream pushed so far. */
  offset: number;
  /**
   * Time of the frame's first byte in the caller's clock, in µs: exact with per-byte times,
   * estimated (chunk time less the bytes after it at 115200 baud) with chunk times, NaN
   * when no time was given.
   */
  timeUs: number;
  remote: RemoteKind;
  /** The system byte of an internal remote (§8.3), `null` for an external one. */
  system: number | null;
  resolution: Resolution;
  /** Fade counter: UINT8 for an internal remote, UINT16 for an external one; `null` in RSSI mode. */
  fades: number | null;
  /** Fades since the previous frame, with the counter's wrap; 0 on the first frame. */
  fadesDelta: number;
  /** RSSI in dBm (SPM4649T, §8.3.1), -128 on loss; `null` when byte 0 carries fades. */
  rssi: number | null;
  /** How many channel values this frame carries (`ids[0..count)`, `positions[0..count)`). */
  count: number;
  /** Channel IDs 0–19 of the slots that carry a channel, in slot order. Borrowed, length 7. */
  ids: Uint8Array;
  /**
   * Servo positions, same order as `ids`: 0–1023 or 0–2047; X-Plus values are scaled to the
   * 2047 scale (§8.6). Borrowed, length 7.
   */
  positions: Uint16Array;
  /** The seven raw slot words, in order, as sent. Borrowed, length 7. */
  words: Uint16Array;
  /** Spektrum VTX control in slots 6–7, or `null`. Borrowed. */
  vtx: VtxControl | null;
  /** The 16 raw bytes. Borrowed. */
  bytes: Uint8Array;
}

/** Why the decoder believes the resolution it uses. */
export type ResolutionReason =
  /** The caller fixed it. */
  | 'override'
  /** Taken from the internal remote of the same system (another port): it holds the key for all remotes (§8). */
  | 'internal-remote'
  /** The internal remote's system byte names it and the channel IDs agree (or cannot tell). */
  | 'system-byte'
  /** No valid system byte: inferred from which reading gives consistent channel IDs. */
  | 'channel-ids'
  /** The system byte names one resolution but the channel IDs only make sense in the other. */
  | 'system-byte-contradicted'
  /** Nothing decided yet. */
  | 'unknown';

/** What the decoder has decided about the stream's format, and why. */
export interface FormatInfo {
  /** True once the decoder has locked on to frames. */
  locked: boolean;
  resolution: Resolution | null;
  resolutionReason: ResolutionReason;
  /** A sentence a person can read: what was decided from what. */
  explanation: string;
  remote: RemoteKind | null;
  /** The system byte the internal remote sends (valid or not; see `systemValid`), `null` for an external remote. */
  system: number | null;
  /** Whether `system` is one of the four values of §8.3 (others are ignored: the resolution then comes from the channel IDs). */
  systemValid: boolean;
  /** What byte 0 carries; 'unknown' while the evidence cannot tell fades from RSSI (frames then carry neither). */
  headerMode: HeaderReading;
  /**
   * Set while the resolution is forced and no frame fits it, but frames fit this other
   * resolution: nothing is decoded, and that is a setting, not link loss.
   */
  forcedMismatch: Resolution | null;
  /** Why bytes that read as frames give none, while not locked (see `Withheld`); null otherwise. */
  withheld: Withheld | null;
  /**
   * True while the lock reads an internal remote whose header could as well be an external
   * remote's UINT16 fade count whose low byte is a §8.3 system byte (`00 B2`: internal, 0 fades,
   * DSMX 11 ms; or external, 178 fades): byte 0 has not moved under it. The decoder reads the
   * likelier internal remote and says it is not sure; byte 0 moving settles it (internal), the
   * count moving in byte 1 re-reads it as external from there (a `format-changed` event, not a
   * new remote).
   */
  remoteAmbiguous: boolean;
  /**
   * True while the frame alignment is not proven: an external remote sending one frame shape
   * (22 ms, up to 7 channels: no phase bit, no pair), whose UINT16 fade count is also a valid
   * servo word, reads as well with its frames starting some words earlier or later (a held
   * stick's word read as the fade count, the fade count read as a channel). The decoder reads
   * the likelier alignment (slots in the order transmitters send them) and says it is not sure;
   * the header of either reading falling as no fade count does (a stick moving down), or a
   * shifted frame that stops being one, decides (a `format-changed` event, with a re-read from
   * there when the lock's own reading fell). A rise decides nothing: a count jumps so across
   * lost frames. Frames decoded while it is true are not proven.
   */
  alignmentUnproven: boolean;
}

/**
 * Why the decoder gives no frame from bytes that read as frames:
 * - 'filler': they carry no channel, only 0xFFFF empty slots or 0x00/0xFF filler (runs of
 *   0xFF parse as frames of seven empty slots), which is no evidence of a transmitter;
 * - 'forced': they are frames, but not under the resolution, remote or header mode the caller
 *   forced (see also `forcedMismatch`).
 */
export type Withheld = 'filler' | 'forced';

/** Counters. Every byte pushed ends up in exactly one of `frameBytes`, `discardedBytes` or `pendingBytes`. */
export interface DecoderStats {
  bytes: number;
  frames: number;
  frameBytes: number;
  /** Bytes dropped: noise, truncated frames, bytes before lock. */
  discardedBytes: number;
  /** Bytes held until more arrive. */
  pendingBytes: number;
  /** Times the decoder lost alignment and found it again. */
  resyncs: number;
  /** 16-byte candidates rejected after lock (truncated or corrupted frames). */
  badFrames: number;
  /** Slots that held 0xFFFF. */
  emptySlots: number;
  /** Frames that carried VTX control. */
  vtxFrames: number;
  /** Fade counts that jumped in a way the decoder could not attribute to the receiver (not counted as fades). */
  fadeJumps: number;
}

/**
 * Something the decoder did that an inspector or log may want to show, at stream offset
 * `offset`, delivered to `onEvent` as it is decided (in `next()` or `end()`).
 *
 * `timeUs` is the time of the byte at `offset` by the rule a frame's time follows: exact with
 * per-byte times, estimated (chunk time less the bytes after it at 115200 baud) with chunk
 * times, NaN when no time was given or the byte at `offset` has not arrived (a resync at the
 * end of what was pushed). Events are few; computing it costs nothing on the frame path.
 */
export type DecoderEvent =
  | { type: 'locked'; offset: number; timeUs: number; format: FormatInfo }
  | {
      type: 'discarded';
      offset: number;
      timeUs: number;
      length: number;
      reason: 'before-lock' | 'noise' | 'truncated-frame' | 'end-of-stream';
      /**
       * The discarded bytes (`length` of them, from `offset`). Borrowed: a view of the decoder's
       * buffer, valid only during the `onEvent` call, like a frame's `bytes`; copy what you keep.
       */
      bytes: Uint8Array;
    }
  | { type: 'resync'; offset: number; timeUs: number }
  | { type: 'format-changed'; offset: number; timeUs: number; format: FormatInfo }
  /**
   * The fade count jumped across a break in the stream from `from` to `to`. `counted`: it is the
   * same remote's own count going on (it is in `fadesDelta`); otherwise it counts nothing.
   */
  | { type: 'fade-jump'; offset: number; timeUs: number; from: number; to: number; counted: boolean };
