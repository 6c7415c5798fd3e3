/**
 * The first look at a long .sscap before the whole file has been read (reading a day's capture
 * takes seconds): its first PREVIEW_BYTES and its last TAIL_BYTES each read as a capture of
 * their own (every record carries its own sync marker and CRC, and the reader skips the part of
 * a record a cut leaves). The start gives the records to decode first; the end gives where the
 * capture ends, so that the page can place the part read on the whole span at once.
 */
import type { Capture } from '../../capture/model.js';
import type { SlicedFile } from '../../capture/record-walk.js';
import { captureChunksByPort, capturePorts } from '../../capture/facts.js';
import { hasCaptureMagic } from '../../capture/layout.js';
import { parseCapture } from '../../capture/reader.js';
import { captureSpan } from '../../analysis/capture-span.js';

/** A file this large gets a preview: under it, reading it whole is as quick. */
const PREVIEW_MIN_BYTES = 32 << 20;
/** The start read first: some 25 minutes of two remotes at 11 ms. */
const PREVIEW_BYTES = 8 << 20;
/** The end read for the last recorded time. */
const TAIL_BYTES = 64 << 10;

export interface Preview {
  /** The capture's first records. */
  head: Capture;
  ports: number[];
  /** The first recorded time, and the last (from the file's end). */
  startUs: number;
  endUs: number;
  /** The whole capture's size, guessed from the start's: room for its columns. */
  expected: ExpectedSize;
}

/** A capture's chunks (in all and of each port, 0–255) and data bytes, guessed from its file's start (3 % more). */
export interface ExpectedSize {
  records: number;
  dataBytes: number;
  chunksByPort: number[];
}

/** How much is read (tests read small files): by default PREVIEW_MIN_BYTES, PREVIEW_BYTES and TAIL_BYTES. */
export interface PreviewSizes {
  minBytes: number;
  headBytes: number;
  tailBytes: number;
  /** Then read at a time by the passes that decode it straight from the file (replay-split.ts; default 4 MiB). */
  sliceBytes?: number;
}

const SIZES: PreviewSizes = { minBytes: PREVIEW_MIN_BYTES, headBytes: PREVIEW_BYTES, tailBytes: TAIL_BYTES };

/** Whether a file of `size` bytes is long enough to get a preview (and a pass split with a helper). */
export function previewed(size: number, sizes: PreviewSizes = SIZES): boolean {
  return size >= Math.max(sizes.minBytes, sizes.headBytes + sizes.tailBytes);
}

/** The preview of `file`, or null when it is not a long .sscap with chunk times whose start and end read. */
export async function previewOf(file: SlicedFile, sizes: PreviewSizes = SIZES): Promise<Preview | null> {
  const { headBytes, tailBytes } = sizes;
  const size = file.size;
  if (!previewed(size, sizes)) return null;
  let head: Capture;
  let tail: Capture;
  let headerLength = 0;
  try {
    const start = new Uint8Array(await file.slice(0, headBytes).arrayBuffer());
    if (!hasCaptureMagic(start)) return null;
    const parsed = parseCapture(start);
    head = parsed;
    // The header as the reader found it, then the file's last bytes: a capture whose first record is cut.
    ({ headerLength } = parsed);
    const end = new Uint8Array(headerLength + tailBytes);
    end.set(start.subarray(0, headerLength));
    end.set(new Uint8Array(await file.slice(size - tailBytes, size).arrayBuffer()), headerLength);
    tail = parseCapture(end);
  } catch {
    // Whatever is wrong (a damaged start, a file that cannot be read), reading the whole file says it.
    return null;
  }
  if (head.timing !== 'per-chunk' || tail.timing !== 'per-chunk') return null;
  const startUs = captureSpan(head).startUs;
  const endUs = captureSpan(tail).endUs;
  if (!Number.isFinite(startUs) || !Number.isFinite(endUs) || endUs < startUs) return null;
  // The start's share of the file holds its share of the records, give or take.
  const scale = (1.03 * size) / Math.max(1, headBytes - headerLength);
  const expected = {
    records: Math.ceil(head.chunkEnds.length * scale),
    dataBytes: Math.ceil(head.bytes.length * scale),
    chunksByPort: Array.from(captureChunksByPort(head), (n) => Math.ceil(n * scale)),
  };
  return { head, ports: capturePorts(head), startUs, endUs, expected };
}
