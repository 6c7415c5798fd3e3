/**
 * The decoded frames of one port of a capture (the one being replayed, or the live session's
 * recording) as the file `satscope decode` writes: the library's decode of that port and its
 * line formatter, the same frames and the same text. A span keeps the frames whose time falls
 * in it, as a user selects part of a capture; without timing there is no span, only the whole.
 */
import { decodeCapture } from '../report/capture-pass.js';
import { formatCsvHeader, formatCsvLine, formatJsonLine } from '../report/frame-text.js';
import type { Capture } from '../capture/model.js';

export interface FramesExport {
  port: number;
  format: 'csv' | 'jsonl';
  /** Capture clock, µs; null: from the start, to the end. */
  fromUs: number | null;
  toUs: number | null;
  resolution: 'auto' | 1024 | 2048;
}

/** Lines are encoded a block at a time, so the text of a long capture is never one string. */
const BLOCK_LINES = 4096;

/** The file's bytes and how many frames it holds. */
export function framesFile(capture: Capture, o: FramesExport): { data: ArrayBuffer; frames: number } {
  const encoder = new TextEncoder();
  const blocks: Uint8Array[] = [];
  let lines: string[] = o.format === 'csv' ? [formatCsvHeader()] : [];
  let frames = 0;
  const format = o.format === 'csv' ? formatCsvLine : formatJsonLine;
  const from = o.fromUs ?? Number.NEGATIVE_INFINITY;
  const to = o.toUs ?? Number.POSITIVE_INFINITY;
  const whole = o.fromUs === null && o.toUs === null;
  decodeCapture(capture, { port: o.port, resolution: o.resolution }, (f) => {
    // The frame is borrowed: formatted at once.
    if (!whole && !(f.timeUs >= from && f.timeUs <= to)) return;
    lines.push(format(f));
    frames++;
    if (lines.length >= BLOCK_LINES) {
      blocks.push(encoder.encode(`${lines.join('\n')}\n`));
      lines = [];
    }
  });
  if (lines.length > 0) blocks.push(encoder.encode(`${lines.join('\n')}\n`));
  const out = new Uint8Array(blocks.reduce((n, b) => n + b.length, 0));
  let at = 0;
  for (const b of blocks) {
    out.set(b, at);
    at += b.length;
  }
  return { data: out.buffer, frames };
}
