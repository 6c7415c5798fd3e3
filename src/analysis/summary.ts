/**
 * Decoding a whole capture, and the summary `satscope info` prints. Pure: the capture is
 * already in memory, and the caller chooses how to show the result.
 */
import type { Capture, CaptureIssue, CaptureTiming } from '../capture/index.js';
import { captureChunks } from '../capture/index.js';
import { SpektrumDecoder, type DecoderOptions } from '../decoder/index.js';
import type { LinkEpisode, LinkMonitor, LinkStats } from '../decoder/index.js';
import { LinkSeries, monitorWithSeries } from './series.js';
import {
  BYTE_TIME_US,
  channelName,
  channelResolution,
  CHANNEL_COUNT,
  servoToMicros,
  systemInfo,
  USB_CHUNK_JITTER_US,
  type Resolution,
} from '../decoder/index.js';
import type { DecodedFrame, DecoderStats, FormatInfo } from '../decoder/index.js';

export interface DecodeCaptureOptions extends DecoderOptions {
  /** Which serial port of a multi-port capture to decode. Default 0. */
  port?: number;
  /** Width of the bins of the returned `series`, µs. Default 1 s. */
  binUs?: number;
  /** Start of the series' bin 0, µs. Default: the capture's first recorded time (`captureSpan`). */
  originUs?: number;
}

/** The delivery jitter to assume for a capture's timing until it is measured: USB batching for chunk times, none for a logic analyser's. */
export function timingJitterUs(timing: CaptureTiming): number {
  return timing === 'per-chunk' ? USB_CHUNK_JITTER_US : 0;
}

/**
 * The earliest and latest time recorded in a capture on any port (data bytes and events), on
 * the capture's clock, µs; NaN for both without timing. Every surface starts and ends a capture
 * here: the report's time zero, replay's timeline, the end at which the link's state is judged.
 */
export function captureSpan(capture: Capture): { startUs: number; endUs: number } {
  let start = Infinity;
  let end = -Infinity;
  for (const chunk of captureChunks(capture)) {
    if (chunk.bytes.length === 0) continue;
    const bt = chunk.byteTimesUs;
    const first = bt ? (bt[0] as number) : chunk.timeUs - (chunk.bytes.length - 1) * BYTE_TIME_US;
    const last = bt ? (bt[bt.length - 1] as number) : chunk.timeUs;
    if (first < start) start = first;
    if (last > end) end = last;
  }
  for (const e of capture.events) {
    if (e.timeUs < start) start = e.timeUs;
    if (e.timeUs > end) end = e.timeUs;
  }
  return start <= end ? { startUs: start, endUs: end } : { startUs: NaN, endUs: NaN };
}

/**
 * §8: "the internal remote provides the key for … all remotes". The resolution an external
 * remote takes: that of an internal remote whose system byte is one of the four valid ones,
 * or undefined when there is none among `formats`.
 */
export function resolutionKey(formats: Iterable<FormatInfo>): Resolution | undefined {
  let key: Resolution | undefined;
  for (const f of formats) {
    if (f.remote === 'internal' && f.system !== null && f.systemValid && systemInfo(f.system) !== undefined && f.resolution !== null)
      key = f.resolution;
  }
  return key;
}

/**
 * Feeds one port of a capture through a decoder and a link monitor, chunk by chunk with the
 * chunk's recorded time, as live data would arrive, and ends the link at the capture's end
 * (`captureSpan`), as replay does. `onFrame` gets each borrowed frame and the link monitor,
 * which has already counted it. `series` holds the link's binned series.
 */
export function decodeCapture(
  capture: Capture,
  options: DecodeCaptureOptions,
  onFrame: (frame: DecodedFrame, link: LinkMonitor) => void,
): { decoder: SpektrumDecoder; link: LinkMonitor; series: LinkSeries } {
  const { port = 0, binUs = 1_000_000, originUs, ...decoderOptions } = options;
  const span = captureSpan(capture);
  const decoder = new SpektrumDecoder(decoderOptions);
  const series = new LinkSeries(binUs, originUs ?? span.startUs);
  const link = monitorWithSeries({ jitterUs: timingJitterUs(capture.timing) }, series);
  const drain = (): void => {
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) {
      link.frame(f);
      series.frame(f, link);
      onFrame(f, link);
    }
  };
  for (const chunk of captureChunks(capture, port)) {
    decoder.push(chunk.bytes, chunk.time);
    drain();
  }
  decoder.end();
  drain();
  link.finish(span.endUs);
  series.extendTo(span.endUs);
  return { decoder, link, series };
}

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
  let bytes = 0;
  for (const chunk of captureChunks(capture, port)) bytes += chunk.bytes.length;
  return {
    kind: capture.kind,
    timing: capture.timing,
    port,
    bytes,
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
