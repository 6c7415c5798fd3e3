/**
 * Named scenarios for tests, fixtures and benchmarks, and the web app's demo.
 */
import { SYSTEM_DSM2_11MS_2048, SYSTEM_DSM2_22MS_1024, SYSTEM_DSMX_11MS_2048, SYSTEM_DSMX_22MS_2048 } from '../decoder/spec.js';
import type { Scenario } from './scenario.js';

/** A clone's byte time (88.6 µs instead of 86.8 µs; see the captures README). */
export const CLONE_BYTE_TIME_US = 88.6;

const SECOND = 1_000_000;

const PRESET_LIST: readonly Scenario[] = [
  // Every system type × internal/external, with a spread of channel counts.
  { name: 'dsm2-22ms-1024-internal', system: SYSTEM_DSM2_22MS_1024, remote: 'internal', channels: 6, seed: 101 },
  { name: 'dsm2-22ms-1024-external', system: SYSTEM_DSM2_22MS_1024, remote: 'external', channels: 8, seed: 102, fades: { start: 40 } },
  { name: 'dsm2-11ms-2048-internal', system: SYSTEM_DSM2_11MS_2048, remote: 'internal', channels: 7, seed: 103 },
  { name: 'dsm2-11ms-2048-external', system: SYSTEM_DSM2_11MS_2048, remote: 'external', channels: 10, seed: 104, fades: { start: 40 } },
  { name: 'dsmx-22ms-2048-internal', system: SYSTEM_DSMX_22MS_2048, remote: 'internal', channels: 7, seed: 105 },
  { name: 'dsmx-22ms-2048-external', system: SYSTEM_DSMX_22MS_2048, remote: 'external', channels: 12, seed: 106, fades: { start: 40 } },
  { name: 'dsmx-11ms-2048-internal', system: SYSTEM_DSMX_11MS_2048, remote: 'internal', channels: 10, seed: 107 },
  { name: 'dsmx-11ms-2048-external', system: SYSTEM_DSMX_11MS_2048, remote: 'external', channels: 12, seed: 108, fades: { start: 40 } },
  // A clone that sends 00 00 in bytes 0–1 and spaces bytes 88.6 µs (like dsm_x_data.txt).
  {
    name: 'clone-zero-header',
    system: SYSTEM_DSMX_11MS_2048,
    header: 'zero',
    channels: 10,
    timing: { byteTimeUs: CLONE_BYTE_TIME_US },
    seed: 109,
  },
  // Internal remotes whose system byte contradicts the data.
  { name: 'lying-b2-with-1024-data', system: SYSTEM_DSM2_22MS_1024, systemByte: SYSTEM_DSMX_11MS_2048, channels: 7, seed: 110 },
  { name: 'lying-01-with-2048-data', system: SYSTEM_DSMX_11MS_2048, systemByte: SYSTEM_DSM2_22MS_1024, channels: 10, seed: 111 },
  // SPM4649T: RSSI in byte 0, -128 after a loss.
  {
    name: 'rssi-spm4649t',
    system: SYSTEM_DSMX_11MS_2048,
    headerMode: 'rssi',
    channels: 7,
    fades: { lossRate: 0.01 },
    seed: 112,
  },
  // DX9 with X-Plus: 12 channels + X+1…X+4 rotating in the 7th slot (like the DX9 captures).
  { name: 'xplus-dx9', system: SYSTEM_DSMX_11MS_2048, channels: 12, xplus: 4, seed: 113 },
  // All eight X-Plus channels, so phase-1 X-Plus words (X+5…X+8) appear.
  { name: 'xplus-8', system: SYSTEM_DSMX_11MS_2048, remote: 'external', channels: 12, xplus: 8, seed: 114, fades: { start: 40 } },
  // VTX control every 0.5 s, three frames per burst.
  {
    name: 'vtx',
    system: SYSTEM_DSMX_11MS_2048,
    channels: 10,
    vtx: {
      everyUs: 0.5 * SECOND,
      burst: 3,
      settings: [
        { band: 1, channel: 3, power: 2, region: 0, pit: false },
        { band: 4, channel: 7, power: 5, region: 1, pit: true },
        { band: 0, channel: 0, power: 0, region: 0, pit: false },
      ],
    },
    seed: 115,
  },
  // 12 channels without X-Plus: one 0xFFFF per frame (two per pair); 6 channels on 22 ms: one per frame.
  { name: 'empty-slots-12ch', system: SYSTEM_DSMX_11MS_2048, channels: 12, seed: 116 },
  { name: 'empty-slots-22ms-5ch', system: SYSTEM_DSMX_22MS_2048, channels: 5, seed: 117 },
  // Fade counters starting just below their wrap.
  {
    name: 'fade-wrap-internal',
    system: SYSTEM_DSMX_11MS_2048,
    channels: 7,
    fades: { start: 250, lossRate: 0.02, randomRate: 0.02 },
    seed: 118,
  },
  {
    name: 'fade-wrap-external',
    system: SYSTEM_DSMX_11MS_2048,
    remote: 'external',
    channels: 7,
    fades: { start: 65530, lossRate: 0.02, randomRate: 0.02 },
    seed: 119,
  },
  // A short dropout (hold last) and one over a second (failsafe), then recovery.
  {
    name: 'dropouts-failsafe',
    system: SYSTEM_DSMX_11MS_2048,
    channels: 10,
    dropouts: [
      { atUs: 0.5 * SECOND, durationUs: 0.2 * SECOND },
      { atUs: 1.2 * SECOND, durationUs: 1.3 * SECOND },
    ],
    durationUs: 3.2 * SECOND,
    seed: 120,
  },
  // A bad line: starts mid-frame, truncated frames, noise between frames, flipped bits.
  {
    name: 'damaged-line',
    system: SYSTEM_DSMX_11MS_2048,
    header: 'zero',
    channels: 10,
    damage: { startMidFrame: 3, truncateRate: 0.03, noiseRate: 0.03, bitFlipRate: 0.01 },
    seed: 121,
  },
  // Dropouts and line damage together.
  {
    name: 'dropouts-and-damage',
    system: SYSTEM_DSMX_11MS_2048,
    channels: 12,
    xplus: 4,
    dropouts: [
      { atUs: 0.4 * SECOND, durationUs: 0.15 * SECOND },
      { atUs: 1.0 * SECOND, durationUs: 1.2 * SECOND },
    ],
    fades: { lossRate: 0.005 },
    damage: { startMidFrame: 5, truncateRate: 0.02, noiseRate: 0.02, bitFlipRate: 0.01 },
    durationUs: 3 * SECOND,
    seed: 122,
  },
];

/** The names of the presets. */
export const PRESET_NAMES: readonly string[] = PRESET_LIST.map((p) => p.name!);

// `structuredClone` is not in lib ES2022; presets are plain JSON-safe data, so this copies them.
function clone(s: Scenario): Scenario {
  return JSON.parse(JSON.stringify(s)) as Scenario;
}

/**
 * A fresh copy of preset `name` (change it freely), or of the demo scenario for 'demo'.
 *
 * @throws RangeError for an unknown name.
 */
export function preset(name: string): Scenario {
  if (name === 'demo') return demoScenario();
  const p = PRESET_LIST.find((x) => x.name === name);
  if (!p) throw new RangeError(`unknown preset ${name}; known: ${PRESET_NAMES.join(', ')}, demo`);
  return clone(p);
}

/** Fresh copies of all presets (not including the demo). */
export function presets(): Scenario[] {
  return PRESET_LIST.map(clone);
}

/**
 * The web app's demo: a DSMX 11 ms internal remote with 12 channels, sticks moving, fades now
 * and then, a VTX change, an X-Plus pass (X+1…X+4 for 10 s), a short dropout (hold last) and
 * one of 1.6 s (failsafe) with recovery. The timeline repeats every 40 s, forever.
 */
export function demoScenario(seed = 2024): Scenario {
  return {
    name: 'demo',
    seed,
    system: SYSTEM_DSMX_11MS_2048,
    remote: 'internal',
    channels: 12,
    xplus: { channels: 4, window: { atUs: 8 * SECOND, durationUs: 10 * SECOND } },
    fades: { start: 0, lossRate: 0.004, randomRate: 0.002 },
    dropouts: [
      { atUs: 4 * SECOND, durationUs: 0.25 * SECOND },
      { atUs: 27 * SECOND, durationUs: 1.6 * SECOND },
    ],
    vtx: {
      everyUs: 40 * SECOND,
      firstUs: 21 * SECOND,
      burst: 4,
      settings: [
        { band: 4, channel: 1, power: 3, region: 0, pit: false },
        { band: 4, channel: 5, power: 1, region: 0, pit: true },
      ],
    },
    cycleUs: 40 * SECOND,
    durationUs: 40 * SECOND,
  };
}
