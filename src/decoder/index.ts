/**
 * satscope: decode Spektrum satellite ("remote receiver") serial streams: the decoder, the
 * link monitor, frame snapshots, the stream adapter and the spec's constants. Every public name
 * of the core is exported here. Capture files are `satscope/capture`, whole-capture analysis,
 * the health report and the doctor `satscope/report`: importing the core pulls in neither.
 */
export { SpektrumDecoder, type DecoderOptions } from './decoder.js';
export {
  HOLD_MIN_US,
  LinkMonitor,
  PERIOD_SNAP_US,
  holdThresholdUs,
  isFrameInterval,
  nominalPeriodOf,
  type LinkEpisode,
  type LinkOptions,
  type LinkRestart,
  type LinkState,
  type LinkStats,
  type MissedBasis,
} from './link.js';
export { LEDGER_WINDOW_US } from './ledger.js';
export type { DecoderCheckpoint, LinkCheckpoint } from './checkpoint.js';
export { readFrameFields, type FrameFields, type SlotFields, type SlotKind } from './fields.js';
export { copyFrame, type ChannelValue, type FrameSnapshot } from './snapshot.js';
export { decodeStream, type TimedChunk } from './stream.js';
export type {
  DecodedFrame,
  DecoderEvent,
  DecoderStats,
  FormatInfo,
  HeaderMode,
  HeaderReading,
  RemoteKind,
  ResolutionReason,
  VtxControl,
} from './types.js';
export {
  BAUD_RATE,
  BYTE_TIME_US,
  CHANNEL_COUNT,
  CHANNEL_NAMES,
  channelResolution,
  EMPTY_SLOT,
  FAILSAFE_TIMEOUT_US,
  FRAME_SIZE,
  FRAME_PERIOD_11MS_US,
  FRAME_PERIOD_22MS_US,
  PULSE_MAX_US,
  PULSE_MIN_US,
  USB_CHUNK_JITTER_US,
  SYSTEM_DSM2_11MS_2048,
  SYSTEM_DSM2_22MS_1024,
  SYSTEM_DSMX_11MS_2048,
  SYSTEM_DSMX_22MS_2048,
  SYSTEM_TYPES,
  XPLUS_FIRST,
  XPLUS_LAST,
  channelName,
  servoToMicros,
  servoToPercent,
  systemInfo,
  type Resolution,
  type SystemInfo,
} from './spec.js';
