/**
 * What a flight controller's UART makes of the bytes the page wrote to the pty: bytes grouped by
 * the silence between them (the pty has no wire: a group is what one read of the pty returned,
 * so the reader's own lateness merges frames too), and the distribution of their timing.
 */
import { BYTE_TIME_US } from '../../src/decoder/spec.js';

export interface PtyChunk {
  bytes: Uint8Array;
  tUs: number;
}

/** A burst of bytes with no silence of 3 ms inside: one frame to a flight controller. */
export interface Burst {
  startUs: number;
  endUs: number;
  length: number;
}

export function bursts(chunks: readonly PtyChunk[]): Burst[] {
  const out: Burst[] = [];
  for (const c of chunks) {
    // A chunk's arrival is its last byte's: its first left the wire (length - 1) bytes earlier.
    const startUs = c.tUs - (c.bytes.length - 1) * BYTE_TIME_US;
    const last = out[out.length - 1];
    if (last !== undefined && startUs - last.endUs < 3000) {
      last.endUs = c.tUs;
      last.length += c.bytes.length;
    } else out.push({ startUs, endUs: c.tUs, length: c.bytes.length });
  }
  return out;
}

export const quantile = (sorted: readonly number[], q: number): number =>
  sorted[Math.min(sorted.length - 1, Math.floor(q * sorted.length))] ?? Number.NaN;

/** The bursts' figures: how many, of which lengths, their start-to-start intervals and the silences between them (ms, min/p1/p50/p99/max). */
export function burstFigures(b: readonly Burst[]) {
  const lengths = new Map<number, number>();
  for (const x of b) lengths.set(x.length, (lengths.get(x.length) ?? 0) + 1);
  const intervals = b
    .slice(1)
    .map((x, i) => x.startUs - (b[i]?.startUs ?? 0))
    .sort((p, q) => p - q);
  const silences = b
    .slice(1)
    .map((x, i) => x.startUs - (b[i]?.endUs ?? 0))
    .sort((p, q) => p - q);
  const ms = (us: number) => +(us / 1000).toFixed(2);
  return {
    groups: b.length,
    frames: b.reduce((n, x) => n + x.length / 16, 0),
    lengths: Object.fromEntries(lengths),
    intervalMs: [0, 0.01, 0.5, 0.99, 1].map((q) => ms(quantile(intervals, q))),
    shortestSilenceMs: ms(silences[0] ?? 0),
    spanUs: (b.at(-1)?.startUs ?? 0) - (b[0]?.startUs ?? 0),
  };
}
