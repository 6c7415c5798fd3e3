/**
 * The summary `satscope info` prints: one port of a capture decoded (`decodeCapture`) and summed
 * up. Pure: the capture is already in memory, and the caller chooses how to show the result.
 */
import type { AnyCapture } from '../capture/capture-windows.js';
import type { Capture, CaptureIssue } from '../capture/model.js';
import type { LinkEpisode } from '../decoder/episode.js';
import type { LinkStats } from '../decoder/link-types.js';
import { channelName, channelResolution, CHANNEL_COUNT, servoToMicros } from '../decoder/spec.js';
import type { DecodedFrame, DecoderStats, FormatInfo } from '../decoder/types.js';
import { decodeCapture, type DecodeCaptureOptions } from './capture-pass.js';

/** One channel over a capture: its name, how many frames carried it, its range and last value in µs. */
export interface ChannelSummary {
  id: number;
  name: string;
  frames: number;
  minUs: number;
  maxUs: number;
  lastUs: number;
}

/** One port of a capture decoded (`summarizeCapture`): what `satscope info` prints. */
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
  /** Frames decoded while where frames start was not proven (`format.alignmentUnproven`): their channels and fades may be misread. */
  unprovenFrames: number;
  issues: readonly CaptureIssue[];
}

/**
 * Each channel's frames and pulse widths (µs), frame by frame; fields, not a closure over mutable
 * locals, for the per-frame loop. `satscope info` prints them, and the page shows them live.
 */
export class ChannelRanges {
  readonly frames = new Uint32Array(CHANNEL_COUNT);
  readonly min = new Float64Array(CHANNEL_COUNT).fill(Infinity);
  readonly max = new Float64Array(CHANNEL_COUNT).fill(-Infinity);
  readonly last = new Float64Array(CHANNEL_COUNT);
  firstUs = NaN;
  lastUs = NaN;

  frame(f: DecodedFrame): void {
    if (Number.isNaN(this.firstUs)) this.firstUs = f.timeUs;
    this.lastUs = f.timeUs;
    const { ids, positions } = f;
    for (let i = 0; i < f.count; i++) {
      const id = ids[i] ?? 0;
      const us = servoToMicros(positions[i] ?? 0, channelResolution(id, f.resolution));
      this.frames[id] = (this.frames[id] ?? 0) + 1;
      if (us < (this.min[id] ?? Infinity)) this.min[id] = us;
      if (us > (this.max[id] ?? -Infinity)) this.max[id] = us;
      this.last[id] = us;
    }
  }

  /** The channels that appeared, in ID order. */
  channels(): ChannelSummary[] {
    const out: ChannelSummary[] = [];
    for (let id = 0; id < CHANNEL_COUNT; id++) {
      const n = this.frames[id] ?? 0;
      if (n > 0)
        out.push({
          id,
          name: channelName(id),
          frames: n,
          minUs: this.min[id] ?? Infinity,
          maxUs: this.max[id] ?? -Infinity,
          lastUs: this.last[id] ?? 0,
        });
    }
    return out;
  }
}

/** Decodes a capture (one port) and sums it up. */
export function summarizeCapture(capture: AnyCapture, options: DecodeCaptureOptions = {}): CaptureSummary {
  const ranges = new ChannelRanges();
  let formatChanges = 0;
  let unproven = false;
  let unprovenFrames = 0;
  const userEvent = options.onEvent;
  const { decoder, link } = decodeCapture(
    capture,
    {
      ...options,
      onEvent: (e) => {
        if (e.type === 'format-changed') formatChanges++;
        if (e.type === 'format-changed' || e.type === 'locked') unproven = e.format.alignmentUnproven;
        userEvent?.(e);
      },
    },
    (f) => {
      if (unproven) unprovenFrames++;
      ranges.frame(f);
    },
  );
  const port = options.port ?? 0;
  return {
    kind: capture.kind,
    timing: capture.timing,
    port,
    bytes: decoder.stats.bytes,
    durationUs: ranges.lastUs - ranges.firstUs,
    format: decoder.format,
    decoder: { ...decoder.stats },
    link: { ...link.stats },
    episodes: link.episodes.map((e) => ({ ...e })),
    channels: ranges.channels(),
    formatChanges,
    unprovenFrames,
    issues: capture.issues,
  };
}
