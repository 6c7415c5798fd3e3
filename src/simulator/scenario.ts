/**
 * What a simulated receiver does: the scenario options, their defaults and their validation.
 * All times are µs; scenario event times (dropouts, X-Plus windows, VTX bursts) count from the
 * first frame slot, and repeat every `cycleUs` when that is set.
 */
import { BYTE_TIME_US, CHANNEL_COUNT, FRAME_SIZE, systemInfo } from '../decoder/spec.js';
import type { Resolution } from '../decoder/spec.js';
import type { HeaderMode, RemoteKind } from '../decoder/types.js';
import type { VtxSettings } from './encode.js';
import { channelLayout } from './layouts.js';

/**
 * How one channel moves, in % travel (±100 % ≈ positions 341/1707 in 2048 mode, 171/853 in
 * 1024 mode; ±150 % is the full range, clamped to 0–2047 / 0–1023).
 */
export type ChannelMotion =
  /** Held at one position. */
  | { kind: 'fixed'; percent: number }
  /** `centre + amplitude × sin(2π t / periodUs + phase)`. */
  | { kind: 'sine'; centre?: number; amplitude: number; periodUs: number; phase?: number }
  /** A random walk of ±`step` % per frame slot, reflected at `min`/`max` (default ±100). */
  | { kind: 'walk'; step: number; start?: number; min?: number; max?: number }
  /** A switch: `levels` in turn, each held for `holdUs`. */
  | { kind: 'steps'; levels: readonly number[]; holdUs: number };

/** A time window in the scenario's timeline. */
export interface Window {
  atUs: number;
  durationUs: number;
}

/** How the simulated receiver's fade counter starts and counts lost frames. */
export interface FadeOptions {
  /** The counter's first value (e.g. 250 internal or 65530 external to see it wrap). Default 0. */
  start?: number;
  /** Probability that a frame slot is lost (nothing sent, counter + 1). Default 0.002. */
  lossRate?: number;
  /** Probability per sent frame that the counter goes up anyway (a fade the link recovered from). Default 0.001. */
  randomRate?: number;
}

export interface RssiOptions {
  /** The level the signal wanders around, dBm. Default -62. */
  meanDbm?: number;
  /** The level swings slowly by ± this (as the model flies near and far), dB. Default 18. */
  swingDb?: number;
  /** Period of that swing, µs. Default 20 s. */
  swingPeriodUs?: number;
  /** Standard deviation of the per-frame random step, dB. Default 0.7. */
  stepDb?: number;
}

export interface XPlusOptions {
  /** How many X-Plus channels (1–8): X+1 … X+n, i.e. channels 12 … 11+n. */
  channels: number;
  /** When X-Plus is on; always when absent. */
  window?: Window;
}

export interface VtxOptions {
  /** A burst of VTX frames every `everyUs`, the first at `firstUs` (default `everyUs`). */
  everyUs: number;
  firstUs?: number;
  /** VTX frames per burst (default 3): the next eligible frames (first slot phase 0). */
  burst?: number;
  /** Settings sent, one per burst in turn. */
  settings: readonly VtxSettings[];
}

/** When the simulated receiver sends its bytes: the start, the byte time, and frame and byte jitter. */
export interface TimingOptions {
  /** Time of the first frame slot. Default 1000. */
  startUs?: number;
  /** µs per byte: 86.8 at 115200 8N1 (default), e.g. 88.6 for some clones. */
  byteTimeUs?: number;
  /** Each frame starts up to ± this far from its nominal slot. Default 8. */
  frameJitterUs?: number;
  /** Each byte time is off by up to ± this. Default 0.02. */
  byteJitterUs?: number;
}

/** Line damage the simulator adds: truncated frames, noise bytes, flipped bits, a start in mid-frame. */
export interface DamageOptions {
  /** Probability per frame of losing `1…truncateMaxBytes` random bytes (the rest keep their times). */
  truncateRate?: number;
  /** Default 9 (the PX4 capture has frames of 14 and 7 bytes). */
  truncateMaxBytes?: number;
  /** Probability per frame slot of a burst of random bytes in the idle gap. */
  noiseRate?: number;
  /** Default 6. */
  noiseMaxBytes?: number;
  /** Probability per frame of one flipped bit. A flip may or may not be detectable. */
  bitFlipRate?: number;
  /** Leave out the first k bytes of the first frame, so the stream starts mid-frame. */
  startMidFrame?: number;
}

/** A simulated receiver and link. Only `system` is required. */
export interface Scenario {
  name?: string;
  /** Seed of every random choice. Default 1. */
  seed?: number;
  /**
   * The protocol actually in use, as its §8.3 system byte (0x01, 0x12, 0xA2, 0xB2): it sets
   * the frame period and the data resolution.
   */
  system: number;
  /** Default 'internal'. */
  remote?: RemoteKind;
  /** 'zero': a clone whose bytes 0–1 are always 00 00. Default 'spec'. */
  header?: 'spec' | 'zero';
  /**
   * Internal remote only: the system byte sent, when the receiver lies (e.g. 0xB2 with
   * 1024-format data, or 0x01 with 2048 data). Must be one of the four allowed values.
   */
  systemByte?: number;
  /** Internal remote only: 'rssi' for an SPM4649T (byte 0 is signed dBm). Default 'fades'. */
  headerMode?: HeaderMode;
  /** Ordinary channels 1–12. Default 7. */
  channels?: number;
  /** X-Plus channels (2048 only): a count 0–8 or options. Default 0. */
  xplus?: number | XPlusOptions;
  fades?: FadeOptions;
  rssi?: RssiOptions;
  /** Times where the receiver sends nothing (the fade counter counts the missed slots). */
  dropouts?: readonly Window[];
  vtx?: VtxOptions;
  /** Motion per channel ID (0–19), replacing the defaults. */
  motion?: Readonly<Record<number, ChannelMotion>>;
  timing?: TimingOptions;
  damage?: DamageOptions;
  /** Repeat the timeline (dropouts, X-Plus window, VTX bursts, stick motion is unaffected) every this many µs. */
  cycleUs?: number;
  /** A suggested length for fixtures and tests, µs. Not enforced. */
  durationUs?: number;
}

/** A scenario with every default filled in. */
export interface ResolvedScenario {
  name: string;
  seed: number;
  system: number;
  periodUs: number;
  periodMs: 11 | 22;
  resolution: Resolution;
  remote: RemoteKind;
  header: 'spec' | 'zero';
  /** The byte sent in byte 1 by an internal remote with a 'spec' header, else `null`. */
  systemByte: number | null;
  headerMode: HeaderMode;
  channels: number;
  xplus: { channels: number; window: Window | null };
  fades: Required<FadeOptions>;
  rssi: Required<RssiOptions>;
  dropouts: Window[];
  vtx: { everyUs: number; firstUs: number; burst: number; settings: VtxSettings[] } | null;
  motion: ChannelMotion[];
  timing: Required<TimingOptions>;
  damage: Required<DamageOptions>;
  cycleUs: number | null;
  durationUs: number;
}

const DEFAULT_MOTION: readonly ChannelMotion[] = [
  /* 0 throttle */ { kind: 'sine', centre: 0, amplitude: 100, periodUs: 7_000_000, phase: -Math.PI / 2 },
  /* 1 aileron */ { kind: 'sine', centre: 0, amplitude: 80, periodUs: 3_100_000 },
  /* 2 elevator */ { kind: 'sine', centre: 5, amplitude: 70, periodUs: 4_300_000, phase: 1 },
  /* 3 rudder */ { kind: 'walk', step: 1.5 },
  /* 4 gear */ { kind: 'steps', levels: [-100, 100], holdUs: 5_000_000 },
  /* 5 aux 1 */ { kind: 'steps', levels: [-100, 0, 100], holdUs: 3_000_000 },
  /* 6 aux 2: full range, clamped at both ends */ { kind: 'sine', centre: 0, amplitude: 160, periodUs: 11_000_000 },
  /* 7 aux 3 */ { kind: 'fixed', percent: -100 },
  /* 8 aux 4 */ { kind: 'fixed', percent: 100 },
  /* 9 aux 5 */ { kind: 'fixed', percent: 0 },
  /* 10 aux 6 */ { kind: 'walk', step: 3, min: -150, max: 150 },
  /* 11 aux 7 */ { kind: 'sine', centre: 20, amplitude: 60, periodUs: 17_000_000 },
  /* X+1 */ { kind: 'sine', centre: 0, amplitude: 100, periodUs: 5_000_000 },
  /* X+2 */ { kind: 'steps', levels: [-100, 100], holdUs: 2_000_000 },
  /* X+3 */ { kind: 'fixed', percent: 0 },
  /* X+4 */ { kind: 'walk', step: 2 },
  /* X+5 */ { kind: 'sine', centre: 0, amplitude: 150, periodUs: 9_000_000, phase: 2 },
  /* X+6 */ { kind: 'fixed', percent: 100 },
  /* X+7 */ { kind: 'steps', levels: [-100, -50, 0, 50, 100], holdUs: 1_500_000 },
  /* X+8 */ { kind: 'fixed', percent: -100 },
];

function fail(scenario: string, message: string): never {
  throw new TypeError(`scenario ${scenario}: ${message}`);
}

function finite(name: string, where: string, v: number, min: number, max: number): number {
  if (!Number.isFinite(v) || v < min || v > max) fail(where, `${name} must be ${min}…${max}, got ${v}`);
  return v;
}

function checkWindow(where: string, w: Window): Window {
  finite('window atUs', where, w.atUs, 0, Number.MAX_SAFE_INTEGER);
  finite('window durationUs', where, w.durationUs, 0, Number.MAX_SAFE_INTEGER);
  return { atUs: w.atUs, durationUs: w.durationUs };
}

function checkMotion(where: string, id: number, m: ChannelMotion): ChannelMotion {
  switch (m.kind) {
    case 'fixed':
      finite(`motion[${id}].percent`, where, m.percent, -200, 200);
      return { ...m };
    case 'sine':
      finite(`motion[${id}].periodUs`, where, m.periodUs, 1, Number.MAX_SAFE_INTEGER);
      finite(`motion[${id}].amplitude`, where, m.amplitude, 0, 400);
      return { ...m };
    case 'walk':
      finite(`motion[${id}].step`, where, m.step, 0, 100);
      if ((m.min ?? -100) >= (m.max ?? 100)) fail(where, `motion[${id}] needs min < max`);
      return { ...m };
    case 'steps':
      if (m.levels.length === 0) fail(where, `motion[${id}].levels is empty`);
      finite(`motion[${id}].holdUs`, where, m.holdUs, 1, Number.MAX_SAFE_INTEGER);
      return { ...m, levels: m.levels.slice() };
    default:
      return fail(where, `motion[${id}] has an unknown kind`);
  }
}

/**
 * Fills in defaults and checks a scenario.
 *
 * @throws TypeError on an option the simulator cannot honour.
 */
export function resolveScenario(s: Scenario): ResolvedScenario {
  const name = s.name ?? 'unnamed';
  const info = systemInfo(s.system);
  if (!info) fail(name, `system must be 0x01, 0x12, 0xA2 or 0xB2, got ${s.system}`);
  const remote = s.remote ?? 'internal';
  if (remote !== 'internal' && remote !== 'external') fail(name, `remote must be 'internal' or 'external'`);
  const header = s.header ?? 'spec';
  if (header !== 'spec' && header !== 'zero') fail(name, `header must be 'spec' or 'zero'`);
  const headerMode = s.headerMode ?? 'fades';
  if (headerMode !== 'fades' && headerMode !== 'rssi') fail(name, `headerMode must be 'fades' or 'rssi'`);
  if (headerMode === 'rssi' && (remote !== 'internal' || header !== 'spec')) {
    fail(name, 'RSSI mode exists only on an internal remote with a real header (§8.3.1)');
  }
  if (s.systemByte !== undefined) {
    if (remote !== 'internal' || header !== 'spec') fail(name, 'systemByte needs an internal remote with a real header');
    if (!systemInfo(s.systemByte)) fail(name, `systemByte must be one of the four allowed values, got ${s.systemByte}`);
  }
  const systemByte = remote === 'internal' && header === 'spec' ? (s.systemByte ?? s.system) : null;

  const channels = s.channels ?? 7;
  const xo: XPlusOptions = typeof s.xplus === 'number' ? { channels: s.xplus } : (s.xplus ?? { channels: 0 });
  finite('xplus.channels', name, xo.channels, 0, 8);
  if (!Number.isInteger(xo.channels)) fail(name, 'xplus.channels must be an integer');
  try {
    channelLayout(info.resolution, info.periodMs, channels, xo.channels > 0);
  } catch (e) {
    fail(name, (e as Error).message);
  }

  const fo = s.fades ?? {};
  const fades: Required<FadeOptions> = {
    start: finite('fades.start', name, fo.start ?? 0, 0, Number.MAX_SAFE_INTEGER),
    lossRate: finite('fades.lossRate', name, fo.lossRate ?? 0.002, 0, 0.9),
    randomRate: finite('fades.randomRate', name, fo.randomRate ?? 0.001, 0, 1),
  };
  const ro = s.rssi ?? {};
  const rssi: Required<RssiOptions> = {
    meanDbm: finite('rssi.meanDbm', name, ro.meanDbm ?? -62, -92, -42),
    swingDb: finite('rssi.swingDb', name, ro.swingDb ?? 18, 0, 50),
    swingPeriodUs: finite('rssi.swingPeriodUs', name, ro.swingPeriodUs ?? 20_000_000, 1, Number.MAX_SAFE_INTEGER),
    stepDb: finite('rssi.stepDb', name, ro.stepDb ?? 0.7, 0, 20),
  };

  let vtx: ResolvedScenario['vtx'] = null;
  if (s.vtx) {
    const v = s.vtx;
    finite('vtx.everyUs', name, v.everyUs, 1, Number.MAX_SAFE_INTEGER);
    if (v.settings.length === 0) fail(name, 'vtx.settings is empty');
    vtx = {
      everyUs: v.everyUs,
      firstUs: finite('vtx.firstUs', name, v.firstUs ?? v.everyUs, 0, Number.MAX_SAFE_INTEGER),
      burst: finite('vtx.burst', name, v.burst ?? 3, 1, 1000),
      settings: v.settings.map((x) => ({ ...x })),
    };
  }

  const motion: ChannelMotion[] = [];
  for (let id = 0; id < CHANNEL_COUNT; id++) {
    const m = s.motion?.[id] ?? DEFAULT_MOTION[id]!;
    motion.push(checkMotion(name, id, m));
  }

  const to = s.timing ?? {};
  const timing: Required<TimingOptions> = {
    startUs: finite('timing.startUs', name, to.startUs ?? 1000, 0, Number.MAX_SAFE_INTEGER),
    byteTimeUs: finite('timing.byteTimeUs', name, to.byteTimeUs ?? BYTE_TIME_US, 10, 400),
    frameJitterUs: finite('timing.frameJitterUs', name, to.frameJitterUs ?? 8, 0, 500),
    byteJitterUs: finite('timing.byteJitterUs', name, to.byteJitterUs ?? 0.02, 0, 5),
  };
  const periodUs = info.periodUs;
  // Frame, jitter and a noise burst must fit in one period so byte times stay in order.
  if (FRAME_SIZE * timing.byteTimeUs + 2 * timing.frameJitterUs + 2000 > periodUs) {
    fail(name, 'byteTimeUs and frameJitterUs leave no idle gap between frames');
  }
  if (timing.byteJitterUs * 2 >= timing.byteTimeUs) fail(name, 'byteJitterUs is too large');

  const d = s.damage ?? {};
  const damage: Required<DamageOptions> = {
    truncateRate: finite('damage.truncateRate', name, d.truncateRate ?? 0, 0, 1),
    truncateMaxBytes: finite('damage.truncateMaxBytes', name, d.truncateMaxBytes ?? 9, 1, FRAME_SIZE - 1),
    noiseRate: finite('damage.noiseRate', name, d.noiseRate ?? 0, 0, 1),
    noiseMaxBytes: finite('damage.noiseMaxBytes', name, d.noiseMaxBytes ?? 6, 1, 16),
    bitFlipRate: finite('damage.bitFlipRate', name, d.bitFlipRate ?? 0, 0, 1),
    startMidFrame: finite('damage.startMidFrame', name, d.startMidFrame ?? 0, 0, FRAME_SIZE - 1),
  };
  for (const k of ['truncateMaxBytes', 'noiseMaxBytes', 'startMidFrame'] as const) {
    if (!Number.isInteger(damage[k])) fail(name, `damage.${k} must be an integer`);
  }
  const noiseRoom = periodUs - FRAME_SIZE * timing.byteTimeUs - 2 * timing.frameJitterUs - 1000;
  if (damage.noiseMaxBytes * timing.byteTimeUs > noiseRoom) fail(name, 'noise bursts do not fit in the idle gap');

  const cycleUs = s.cycleUs ?? null;
  if (cycleUs !== null) finite('cycleUs', name, cycleUs, periodUs, Number.MAX_SAFE_INTEGER);

  return {
    name,
    seed: (s.seed ?? 1) >>> 0,
    system: s.system,
    periodUs,
    periodMs: info.periodMs,
    resolution: info.resolution,
    remote,
    header,
    systemByte,
    headerMode,
    channels,
    xplus: { channels: xo.channels, window: xo.window ? checkWindow(name, xo.window) : null },
    fades,
    rssi,
    dropouts: (s.dropouts ?? []).map((w) => checkWindow(name, w)),
    vtx,
    motion,
    timing,
    damage,
    cycleUs,
    durationUs: finite('durationUs', name, s.durationUs ?? 3_000_000, 0, Number.MAX_SAFE_INTEGER),
  };
}

/** The default motion of channel `id` (0–19). */
export function defaultMotion(id: number): ChannelMotion | undefined {
  return DEFAULT_MOTION[id];
}
