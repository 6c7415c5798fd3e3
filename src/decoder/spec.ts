/**
 * Constants and pure conversions from the Spektrum Remote Receiver Interfacing spec, Rev G
 * (2019-01-22). Each constant names the section it comes from.
 */

/** §7.1: every packet is 16 bytes, sent at 115200 8N1. */
export const FRAME_SIZE = 16;
/** §7.1: line rate. One byte is 10 bits on the wire (start, 8 data, stop). */
export const BAUD_RATE = 115_200;
/** Time one byte occupies on the wire at 115200 8N1, in µs (≈ 86.8). */
export const BYTE_TIME_US = 10_000_000 / BAUD_RATE;

/**
 * When a byte of a chunk arrived, for a chunk timed by its last byte's arrival: `bytesAfter`
 * bytes (each `byteTimeUs` on the line) before it. The one rule for dating a byte that came
 * without a time of its own: the decoder's frames and events, the span, the doctor and replay.
 */
export function byteInChunkUs(chunkTimeUs: number, bytesAfter: number, byteTimeUs = BYTE_TIME_US): number {
  return chunkTimeUs - bytesAfter * byteTimeUs;
}
/** §7.1: a frame every 11 or 22 ms. */
export const FRAME_PERIOD_11MS_US = 11_000;
export const FRAME_PERIOD_22MS_US = 22_000;
/**
 * How late a chunk's arrival time can be from USB batching alone: an FTDI adapter's latency
 * timer holds bytes up to 16 ms, plus scheduling. Use it as `LinkMonitor`'s `jitterUs` for
 * chunk-timed (WebSerial, .sscap) data; 0 for logic-analyser times.
 */
export const USB_CHUNK_JITTER_US = 20_000;
/** §7.1: Spektrum's failsafe timer: one second of "hold last", then failsafe. */
export const FAILSAFE_TIMEOUT_US = 1_000_000;
/** §8: seven 16-bit servo slots follow the two header bytes. */
export const SLOTS_PER_FRAME = 7;
/** Real receivers fill unused slots with 0xFFFF (not in the spec; PX4 and ArduPilot skip it). */
export const EMPTY_SLOT = 0xffff;

/** §8.1: 1024 mode (DSM2 22 ms only). */
export const MASK_1024_CHANID = 0xfc00;
export const MASK_1024_SXPOS = 0x03ff;
/** §8.2: 2048 mode (every other protocol). */
export const MASK_2048_PHASE = 0x8000;
export const MASK_2048_CHANID = 0x7800;
export const MASK_2048_SXPOS = 0x07ff;

/** §8.6: channel ID 12 in 2048 mode carries X-Plus channels 12–19. */
export const XPLUS_CHANNEL_ID = 12;
export const XPLUS_FIRST = 12;
export const XPLUS_LAST = 19;
/** §8.6: an X-Plus slot's position is its low 9 bits, scaled to the 2047 scale (× 4). */
export const MASK_XPLUS_POS = 0x01ff;
export const XPLUS_POSITION_SHIFT = 2;
/** §8.5: IDs 0–11 are ordinary channels. */
export const MAX_NORMAL_CHANNEL = 11;
/** Channels 0–19 (12 normal + 8 X-Plus). */
export const CHANNEL_COUNT = 20;

/**
 * Spektrum VTX control (not in Rev G): when bytes 12–15 masked with 0xF000F000 equal
 * 0xE000E000 (both words' top nibble 0xE) the last two slots carry VTX settings, not channels,
 * as real satellites send them and as ArduPilot and Betaflight test.
 */
export const VTX_MASK = 0xf000f000;
export const VTX_MARKER = 0xe000e000;

/** §8.3: the only allowed values of the internal remote's system byte. */
export const SYSTEM_DSM2_22MS_1024 = 0x01;
export const SYSTEM_DSM2_11MS_2048 = 0x12;
export const SYSTEM_DSMX_22MS_2048 = 0xa2;
export const SYSTEM_DSMX_11MS_2048 = 0xb2;

/** Servo resolution: 10-bit (1024) or 11-bit (2048) channel words (§9). */
export type Resolution = 1024 | 2048;

/** What a §8.3 system byte says: its name, resolution and frame period (`systemInfo`). */
export interface SystemInfo {
  /** The system byte value. */
  readonly value: number;
  readonly protocol: 'DSM2' | 'DSMX';
  readonly periodMs: 11 | 22;
  /** The same frame period in µs (FRAME_PERIOD_11MS_US or FRAME_PERIOD_22MS_US): the one place a system byte gives it. */
  readonly periodUs: number;
  readonly resolution: Resolution;
  /** e.g. "DSMX 11 ms 2048". */
  readonly name: string;
}

/** A system byte's entry: its name and period in µs follow from what it says (§8.3). */
function system(value: number, protocol: SystemInfo['protocol'], periodMs: 11 | 22, resolution: Resolution): SystemInfo {
  const periodUs = periodMs === 11 ? FRAME_PERIOD_11MS_US : FRAME_PERIOD_22MS_US;
  return { value, protocol, periodMs, periodUs, resolution, name: `${protocol} ${periodMs} ms ${resolution}` };
}

const SYSTEMS: readonly SystemInfo[] = [
  system(SYSTEM_DSM2_22MS_1024, 'DSM2', 22, 1024),
  system(SYSTEM_DSM2_11MS_2048, 'DSM2', 11, 2048),
  system(SYSTEM_DSMX_22MS_2048, 'DSMX', 22, 2048),
  system(SYSTEM_DSMX_11MS_2048, 'DSMX', 11, 2048),
];

/** §8.3: the protocol a system byte names, or `undefined` for any other value. */
export function systemInfo(value: number): SystemInfo | undefined {
  for (const s of SYSTEMS) if (s.value === value) return s;
  return undefined;
}

/** All four allowed system bytes with what they mean (§8.3). */
export const SYSTEM_TYPES: readonly SystemInfo[] = SYSTEMS;

/** §8.5 and §8.6: channel names, 0–11 then X+1 … X+8. */
export const CHANNEL_NAMES: readonly string[] = [
  'Throttle',
  'Aileron',
  'Elevator',
  'Rudder',
  'Gear',
  'Aux 1',
  'Aux 2',
  'Aux 3',
  'Aux 4',
  'Aux 5',
  'Aux 6',
  'Aux 7',
  'X+1',
  'X+2',
  'X+3',
  'X+4',
  'X+5',
  'X+6',
  'X+7',
  'X+8',
];

/** The name of channel `id` (0–19), or `Ch N` outside that range. */
export function channelName(id: number): string {
  return CHANNEL_NAMES[id] ?? `Ch ${id}`;
}

/**
 * §8.6: the resolution a channel's position is on. X-Plus values (channels 12–19) are scaled to
 * the 2047 scale whatever the link's resolution; channels 0–11 follow the link.
 */
export function channelResolution(id: number, linkResolution: Resolution): Resolution {
  return id >= XPLUS_FIRST ? 2048 : linkResolution;
}

/** §9.1: full range 903–2097 µs; the offset is the pulse width of position 0. */
export const PULSE_MIN_US = 903;
export const PULSE_MAX_US = 2097;
/** §9.2 and §9.3: µs per step. */
export const US_PER_STEP_1024 = 1.166;
export const US_PER_STEP_2048 = 0.583;

/**
 * §9: servo position to pulse width in µs, rounded to the nearest µs
 * (`round(pos × 0.583) + 903` in 2048 mode, `round(pos × 1.166) + 903` in 1024 mode).
 */
export function servoToMicros(position: number, resolution: Resolution): number {
  return Math.round(position * (resolution === 2048 ? US_PER_STEP_2048 : US_PER_STEP_1024)) + PULSE_MIN_US;
}

/**
 * §9.1: position as % travel, where ±100 % is positions ≈ 341…1707 (2048 mode) or
 * ≈ 170.5…853.5 (1024 mode) and the full range is ±150 %.
 */
export function servoToPercent(position: number, resolution: Resolution): number {
  const centre = resolution / 2;
  return ((position - centre) / (resolution / 3)) * 100;
}
