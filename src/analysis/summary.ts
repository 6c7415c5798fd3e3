/**
 * The summary `satscope info` prints: one port of a capture decoded (`decodeCapture`) and summed
 * up. Pure: the capture is already in memory, and the caller chooses how to show the result.
 */
import type { Capture, CaptureIssue } from '../capture/index.js';
import type { LinkEpisode, LinkStats } from '../decoder/index.js';
import { channelName, channelResolution, CHANNEL_COUNT, servoToMicros } from '../decoder/index.js';
import type { DecoderStats, FormatInfo } from '../decoder/index.js';
import { decodeCapture, type DecodeCaptureOptions } from './capture-pass.js';

export interface ChannelSummary {
  id: number;
  name: string;
  frames: number;
  minUs: number;
  maxUs: number;
  lastUs: number;
}

export interface CaptureSummary {
  kind: Capture['kind'];
  timing: Capture['timing'];
  port: number;
  bytes: number;
  /** From the first to the last frame's time, µs; NaN without timing. */
  durationUs: number;
  format: FormatInfo;
  decoder: DecoderStats;
  link: LinkStats;
  episodes: LinkEpisode[];
  channels: ChannelSummary[];
  /** Format changes the decoder made along the way (e.g. an external remote whose fades looked like a system byte). */
  formatChanges: number;
  issues: readonly CaptureIssue[];
}

/** Decodes a capture (one port) and sums it up. */
export function summarizeCapture(capture: Capture, options: DecodeCaptureOptions = {}): CaptureSummary {
  const frames = new Uint32Array(CHANNEL_COUNT);
  const min = new Float64Array(CHANNEL_COUNT).fill(Infinity);
  const max = new Float64Array(CHANNEL_COUNT).fill(-Infinity);
  const last = new Float64Array(CHANNEL_COUNT);
  let firstUs = NaN;
  let lastUs = NaN;
  let formatChanges = 0;
  const userEvent = options.onEvent;
  const { decoder, link } = decodeCapture(
    capture,
    {
      ...options,
      onEvent: (e) => {
        if (e.type === 'format-changed') formatChanges++;
        userEvent?.(e);
      },
    },
    (f) => {
      if (Number.isNaN(firstUs)) firstUs = f.timeUs;
      lastUs = f.timeUs;
      for (let i = 0; i < f.count; i++) {
        const id = f.ids[i] as number;
        const us = servoToMicros(f.positions[i] as number, channelResolution(id, f.resolution));
        frames[id] = (frames[id] as number) + 1;
        if (us < (min[id] as number)) min[id] = us;
        if (us > (max[id] as number)) max[id] = us;
        last[id] = us;
      }
    },
  );
  const channels: ChannelSummary[] = [];
  for (let id = 0; id < CHANNEL_COUNT; id++) {
    const n = frames[id] as number;
    if (n > 0)
      channels.push({
        id,
        name: channelName(id),
        frames: n,
        minUs: min[id] as number,
        maxUs: max[id] as number,
        lastUs: last[id] as number,
      });
  }
  const port = options.port ?? 0;
  return {
    kind: capture.kind,
    timing: capture.timing,
    port,
    bytes: decoder.stats.bytes,
    durationUs: lastUs - firstUs,
    format: decoder.format,
    decoder: { ...decoder.stats },
    link: { ...link.stats },
    episodes: link.episodes.map((e) => ({ ...e })),
    channels,
    formatChanges,
    issues: capture.issues,
  };
}
