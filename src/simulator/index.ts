/**
 * satscope/simulator: a simulated Spektrum remote receiver. Produces realistic serial byte
 * streams with per-byte times and the ground truth a decoder must recover. Pure ECMAScript:
 * no DOM, no Node, no timers; deterministic from a seed.
 */
export { Simulator, simulate, type SimChunk, type SimulatorOptions } from './simulator.js';
export type { ChannelMotion, DamageOptions, FadeOptions, Scenario, TimingOptions } from './scenario.js';
export type { SimTruth, TruthFrame } from './truth.js';
export { preset, presets, PRESET_NAMES } from './presets.js';
export {
  encodeExternalFrame,
  encodeInternalFrame,
  encodeServo1024,
  encodeServo2048,
  encodeVtx,
  encodeXPlus,
  type InternalHeader,
  type VtxSettings,
} from './encode.js';
export { crsfStream, sbusStream, srxl2Stream } from './protocols.js';
