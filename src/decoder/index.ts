/**
 * satscope: decode Spektrum satellite ("remote receiver") serial streams: the decoder, the
 * link monitor, frame snapshots, the stream adapter and the spec's constants. Every public name
 * of the core is exported here. Capture files are `satscope/capture`, whole-capture analysis,
 * the health report and the doctor `satscope/report`: importing the core pulls in neither.
 */
export { SpektrumDecoder, type DecoderOptions } from './decoder.js';
export type { DecoderCheckpoint, LinkCheckpoint } from './checkpoint.js';
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
export type { LinkEpisode } from './episode.js';
export { LinkMonitor } from './link.js';
export type { LinkOptions, LinkRestart, LinkState, LinkStats, MissedBasis } from './link-types.js';
export { readFrameFields, type FrameFields, type SlotFields, type SlotKind } from './fields.js';
export { copyFrame, type ChannelValue, type FrameSnapshot } from './snapshot.js';
export { decodeStream, type TimedChunk } from './stream.js';
export {
  BAUD_RATE,
  BYTE_TIME_US,
  CHANNEL_COUNT,
  FAILSAFE_TIMEOUT_US,
  FRAME_SIZE,
  SYSTEM_TYPES,
  channelName,
  servoToMicros,
  servoToPercent,
  systemInfo,
  type Resolution,
  type SystemInfo,
} from './spec.js';
