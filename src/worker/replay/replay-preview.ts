/**
 * The first look at a long .sscap before the whole file has been read (reading a day's capture
 * takes seconds): its first PREVIEW_BYTES and its last TAIL_BYTES each read as a capture of
 * their own (every record carries its own sync marker and CRC, and the reader skips the part of
 * a record a cut leaves). The start gives the records to decode first; the end gives where the
 * capture ends, so that the page can place the part read on the whole span at once. The
 * capture's size (room for its columns) comes from its index when it has one that checks out
 * and was closed; else it is guessed from the start's.
 */
import type { Capture } from '../../capture/model.js';
import type { SlicedFile } from '../../capture/record-walk.js';
import { captureChunksByPort, capturePorts } from '../../capture/facts.js';
import { hasCaptureMagic } from '../../capture/layout.js';
import { parseCapture } from '../../capture/reader.js';
import { captureSpan } from '../../report/capture-span.js';
import { type CaptureTotals, readCaptureTotals } from '../../capture/capture-index.js';

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
  /** The whole capture's size, from its index or guessed from the start's: room for its columns. */
  expected: ExpectedSize;
  /** Whether `expected` is the index's count rather than a guess. */
  indexed: boolean;
}

/** A capture's chunks (in all and of each port, 0–255) and data bytes: counted by its index, or guessed from its file's start (3 % more). */
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
  let totals: CaptureTotals | null = null;
  try {
    const start = new Uint8Array(await file.slice(0, headBytes).arrayBuffer());
    if (!hasCaptureMagic(start)) return null;
    const parsed = parseCapture(start);
    head = parsed;
    // The header as the reader found it, then the file's last bytes: a capture whose first record is cut.
    ({ headerLength } = parsed);
    const last = new Uint8Array(await file.slice(size - tailBytes, size).arrayBuffer());
    const end = new Uint8Array(headerLength + tailBytes);
    end.set(start.subarray(0, headerLength));
    end.set(last, headerLength);
    tail = parseCapture(end);
    // The final index segment lies in the bytes just read (a segment is at most 8.3 KB).
    totals = await readCaptureTotals(size, headerLength, async (offset, length) =>
      offset >= size - tailBytes
        ? last.subarray(offset - (size - tailBytes), offset - (size - tailBytes) + length)
        : new Uint8Array(await file.slice(offset, offset + length).arrayBuffer()),
    );
  } catch {
    // Whatever is wrong (a damaged start, a file that cannot be read), reading the whole file says it.
    return null;
  }
  if (head.timing !== 'per-chunk' || tail.timing !== 'per-chunk') return null;
  const startUs = captureSpan(head).startUs;
  const endUs = captureSpan(tail).endUs;
  if (!Number.isFinite(startUs) || !Number.isFinite(endUs) || endUs < startUs) return null;
  const indexed = totals !== null;
  return {
    head,
    ports: capturePorts(head),
    startUs,
    endUs,
    expected: totals !== null ? counted(totals) : guessed(head, size, headBytes - headerLength),
    indexed,
  };
}

/** The sizes a closed index counts. */
function counted(index: CaptureTotals): ExpectedSize {
  const chunksByPort = new Array<number>(256).fill(0);
  for (const p of index.ports) chunksByPort[p.port] = p.records;
  return { records: index.dataRecords, dataBytes: index.ports.reduce((n, p) => n + p.bytes, 0), chunksByPort };
}

/** The sizes guessed from the records of the file's first `headRecordBytes`: their share of the file holds their share of the records, give or take. */
function guessed(head: Capture, size: number, headRecordBytes: number): ExpectedSize {
  const scale = (1.03 * size) / Math.max(1, headRecordBytes);
  return {
    records: Math.ceil(head.chunkEnds.length * scale),
    dataBytes: Math.ceil(head.bytes.length * scale),
    chunksByPort: Array.from(captureChunksByPort(head), (n) => Math.ceil(n * scale)),
  };
}
