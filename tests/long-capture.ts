/** A long capture of two remotes for the replay tests, and what the library says about it up to a time. */
import type { Capture } from '../src/capture/model.js';
import { encodeCapture } from '../src/capture/writer.js';
import { LinkMonitor } from '../src/decoder/link.js';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { USB_CHUNK_JITTER_US } from '../src/decoder/spec.js';
import { preset } from '../src/simulator/presets.js';
import { simulate } from '../src/simulator/simulator.js';
import { usbChunks } from './feeds.js';

export const MINUTE = 60e6;

/** Two remotes for 12 minutes (longer than a fresh decode's 10-minute history), the internal one with dropouts and a failsafe. */
export function longCapture(): Uint8Array {
  return longCaptureWithSeed(3);
}

/**
 * Two remotes for `minutes` (12 by default), the internal one with dropouts at 2, 5 (into
 * failsafe) and 9.5 minutes.
 */
export function longCaptureWithSeed(seed: number, minutes = 12): Uint8Array {
  const a = simulate(
    {
      ...preset('dsmx-11ms-2048-internal'),
      seed,
      dropouts: [
        { atUs: 2 * MINUTE, durationUs: 300_000 },
        { atUs: 5 * MINUTE, durationUs: 1_500_000 },
        { atUs: 9.5 * MINUTE, durationUs: 200_000 },
      ],
    },
    minutes * MINUTE,
  );
  const b = simulate({ ...preset('dsmx-11ms-2048-external'), seed: 4 }, minutes * MINUTE);
  const records = [
    ...usbChunks(a.bytes, a.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs, port: 0 })),
    ...usbChunks(b.bytes, b.timesUs).map((c) => ({ type: 'data' as const, bytes: c.bytes, timeUs: c.timeUs + 3, port: 1 })),
  ].sort((x, y) => x.timeUs - y.timeUs);
  return encodeCapture({ baudRate: 115200 }, records);
}

/** What a library decoder and link monitor say about `port` fed every chunk of it that arrived by `untilUs`. */
export function libraryUpTo(capture: Capture, port: number, untilUs: number) {
  const decoder = new SpektrumDecoder();
  const link = new LinkMonitor({ jitterUs: USB_CHUNK_JITTER_US });
  for (let i = 0; i < capture.chunkEnds.length; i++) {
    if (capture.chunkPorts[i] !== port || (capture.chunkTimesUs[i] ?? Infinity) > untilUs) continue;
    decoder.push(capture.bytes.subarray(i === 0 ? 0 : capture.chunkEnds[i - 1], capture.chunkEnds[i]), capture.chunkTimesUs[i]);
    for (let f = decoder.next(); f !== undefined; f = decoder.next()) link.frame(f);
  }
  return { decoder: { ...decoder.stats }, link: { ...link.stats } };
}
