/**
 * satscope/simulator: a simulated Spektrum remote receiver. Produces realistic serial byte
 * streams with per-byte times and the ground truth a decoder must recover. Pure ECMAScript:
 * no DOM, no Node, no timers; deterministic from a seed.
 */
export {
  SHIFT_1024_CHANID,
  SHIFT_2048_CHANID,
  SHIFT_XPLUS_SUBID,
  MASK_XPLUS_VALUE,
  VTX_BAND_SHIFT,
  VTX_CHANNEL_SHIFT,
  VTX_PIT_SHIFT,
  VTX_REGION_SHIFT,
  VTX_POWER_MASK,
  VTX_MARKER,
  VTX_MARKER_MASK,
  encodeServo1024,
  encodeServo2048,
  encodeXPlus,
  xplusPosition,
  encodeVtx,
  vtxWords,
  vtxControl,
  isVtxRaw,
  encodeInternalFrame,
  encodeExternalFrame,
  isValidSystemByte,
} from './encode.js';
export type { VtxSettings, InternalHeader } from './encode.js';

export { channelLayout, describeLayout } from './layouts.js';
export type { FrameLayout, LayoutSlot } from './layouts.js';

export { Prng, deriveSeed } from './prng.js';

export { resolveScenario, defaultMotion } from './scenario.js';
export type {
  Scenario,
  ResolvedScenario,
  ChannelMotion,
  Window,
  FadeOptions,
  RssiOptions,
  XPlusOptions,
  VtxOptions,
  TimingOptions,
  DamageOptions,
} from './scenario.js';

export { Simulator, simulate } from './simulator.js';
export type { SimulatorOptions, SimChunk } from './simulator.js';

export { toFixtureFrame, toFixtureNoise, toFixtureGap } from './truth.js';
export type {
  TruthChannel,
  TruthFrame,
  TruthNoise,
  TruthGap,
  SimTruth,
  FrameDamage,
  FixtureFrame,
} from './truth.js';

export { preset, presets, PRESET_NAMES, demoScenario, CLONE_BYTE_TIME_US } from './presets.js';

export { UART_115200_8N1, characterTimeUs, lineSignal, uartReceive, receiveAs, noiseSignal } from './line.js';
export type { Parity, SerialFormat, Transmission, LineSignal, UartErrorKind, UartError, UartResult } from './line.js';
export {
  SBUS_FORMAT,
  CRSF_FORMAT,
  spektrumTransmission,
  srxlV1Stream,
  srxl2Stream,
  ibusStream,
  sbusStream,
  crsfStream,
  type StreamOptions,
} from './protocols.js';
