/**
 * One half of a long capture's replay pass (replay-split.ts): some of its ports decoded straight
 * from the file's records as the file arrives, in the worker or in its helper. It reports what
 * the worker merges: the overview of its ports so far and the checkpoints made since the last
 * report, then the same at the end with the count of chunks and bytes it walked, which the
 * worker checks against the capture it reads.
 */
import { CaptureBuilder } from '../../capture/capture-builder.js';
import type { ChunkFacts } from '../../capture/facts.js';
import type { ParsedCapture } from '../../capture/model.js';
import { RecordTally } from '../../capture/record-tally.js';
import { recordTimeUs, type SlicedFile, walkDataRecords } from '../../capture/record-walk.js';
import { stopsPort } from '../../report/doctor-events.js';
import { type CaptureSpan, spanBetween } from '../../report/capture-span.js';
import { BYTE_TIME_US } from '../../decoder/spec.js';
import type { Overview } from '../protocol.js';
import { ArrivingFile } from './arriving-file.js';
import { type Checkpoint, ReplayPass } from './replay-pass.js';
import type { ExpectedSize } from './replay-preview.js';

/** What a half decodes: `ports` of a file of `size` bytes, on the span the worker's pass uses. */
export interface FilePassJob {
  size: number;
  ports: number[];
  /**
   * Records on these ports have their CRC checked too (besides those of `ports`): ports the file's
   * start did not show, whose records may be ours with a damaged port byte.
   */
  alsoChecked: number[];
  /** Read at a time (tests; default walkDataRecords's). */
  sliceBytes?: number | undefined;
  /**
   * The capture is kept as its records are walked (CaptureBuilder), and handed over when done
   * (the helper's half), so that the file need not be read and parsed again for playback.
   */
  keep?: boolean | undefined;
  /**
   * The capture's chunk facts and span are found as its records are walked (RecordTally), and
   * handed over when done: the other half keeps the capture, and they are seeded into it.
   */
  tally?: boolean | undefined;
  /** The capture's size, from its index or guessed from the file's start (`Preview.expected`): room for what is kept or tallied is made before the walk. */
  expected?: ExpectedSize | undefined;
  resolution: 'auto' | 1024 | 2048;
  originUs: number;
  endUs: number;
}

export type FilePassReport =
  /**
   * After each slice: how far into the file the walk has got (the worker sends no more than a
   * few pieces ahead of it), and the buffers of the pieces walked past, given back (transferred)
   * for the worker to read the next pieces into.
   */
  | { type: 'walked'; to: number; spare: ArrayBuffer[] }
  | { type: 'progress'; overview: Overview; checkpoints: Checkpoint[] }
  | {
      type: 'done';
      overview: Overview;
      checkpoints: Checkpoint[];
      chunks: number;
      dataBytes: number;
      /** Where the file ends inside a record (`WalkedRecords.cutAt`): what was walked ends there. */
      cutAt?: number | undefined;
      /** Every record walked, for a job that keeps them: the capture, if every record on every port proves intact. */
      kept?: ParsedCapture | undefined;
      /** What the walk found of the capture's chunks, for a job that tallies them (`tally`). */
      facts?: WalkedFacts | undefined;
    }
  | { type: 'failed'; why: string };

/** The capture's chunk facts and span, as a file pass found them walking its records. */
export type WalkedFacts = ChunkFacts & { span: CaptureSpan };

const utf8 = new TextDecoder();

/** A report at most this often: the worker draws the overview about once a second. */
const PROGRESS_MS = 250;

/**
 * Decodes `job` from `file`, reporting as it goes; `stopped` is asked between slices (true: it
 * ends quietly); `passed` takes the buffers of the pieces walked past, to give back (a helper's
 * ArrivingFile). Never throws: whatever goes wrong is a `failed` report, and the worker decodes
 * those ports itself.
 */
export async function passOverFile(
  job: FilePassJob,
  file: SlicedFile,
  report: (r: FilePassReport, transfer: Transferable[]) => void,
  now: () => number,
  stopped: () => boolean = () => false,
  passed: (walkedTo: number) => ArrayBuffer[] = () => [],
): Promise<void> {
  try {
    const pass = new ReplayPass(null, job.ports, job.resolution, job.originUs, job.endUs);
    let sent = 0;
    let lastMs = now();
    const news = (): { overview: Overview; checkpoints: Checkpoint[] } => {
      const checkpoints = pass.checkpoints.slice(sent);
      sent = pass.checkpoints.length;
      return { overview: pass.overview(), checkpoints };
    };
    const transfer = (o: Overview): Transferable[] => [o.t.buffer, o.fadeRate.buffer, o.lost.buffer];
    const { ports, alsoChecked, sliceBytes, size } = job;
    const kept = job.keep === true ? new CaptureBuilder() : null;
    const tally = job.tally === true ? new RecordTally(BYTE_TIME_US) : null;
    if (job.expected !== undefined) {
      kept?.reserve(job.expected.records, job.expected.dataBytes);
      tally?.reserve(job.expected.chunksByPort);
    }
    // Every record decoded here is checked: nothing from a damaged one is ever shown.
    const check = new Uint8Array(256);
    for (const port of [...ports, ...alsoChecked]) check[port] = 1;
    const checked = (port: number): boolean => check[port] === 1;
    const goOn = (walkedTo: number): boolean => {
      if (stopped()) return false;
      // The first slice tells how much of the file is records' payload: room for the rest at that rate.
      kept?.expect(walkedTo, size);
      const spare = passed(walkedTo);
      report({ type: 'walked', to: walkedTo, spare }, spare);
      if (now() - lastMs >= PROGRESS_MS) {
        lastMs = now();
        const r = news();
        report({ type: 'progress', ...r }, transfer(r.overview));
      }
      return true;
    };
    const walked = await walkDataRecords(file, (bytes, view, start, end, port) => pass.feedRecord(bytes, view, start, end, port), {
      goOn,
      checked,
      // A recorded stop ("device lost") is the adapter's absence, not the link's (LinkMonitor.stopped).
      events: (bytes, view, start, end, port) => {
        if (stopsPort(utf8.decode(bytes.subarray(start, end)))) pass.stopped(port, recordTimeUs(view, start));
      },
      ...(kept === null && tally === null
        ? {}
        : {
            runs: (bytes: Uint8Array, view: DataView, from: number, to: number) => {
              kept?.records(bytes, view, from, to);
              tally?.records(bytes, view, from, to);
            },
          }),
      ...(sliceBytes === undefined ? {} : { sliceBytes }),
    });
    if (walked === null) return;
    pass.finish();
    const r = news();
    const { chunks, dataBytes, header, cutAt } = walked;
    // A file that ends inside a record is not intact: it is parsed, and its cut said.
    const capture = cutAt === undefined ? kept?.capture(header) : undefined;
    // The columns go to the worker without a copy (from a helper worker: transferred).
    const columns =
      capture === undefined ? [] : [capture.bytes, capture.chunkEnds, capture.chunkTimesUs, capture.chunkPorts].map((c) => c.buffer);
    let facts: WalkedFacts | undefined;
    if (tally !== null) {
      const { firstUs, lastUs, ...found } = tally.facts();
      facts = { ...found, span: spanBetween(firstUs, lastUs) };
    }
    report({ type: 'done', ...r, chunks, dataBytes, cutAt, kept: capture, facts }, [
      ...transfer(r.overview),
      ...(columns as ArrayBuffer[]),
    ]);
  } catch (error) {
    report({ type: 'failed', why: error instanceof Error ? error.message : String(error) }, []);
  }
}

/** What a helper is sent: its job, then the file's pieces in order (or that the file failed). */
export type HelperMessage = { job: FilePassJob } | { piece: Uint8Array } | { failed: string };

/**
 * A helper's side (replay-helper-worker.ts, and bench/replay.mjs's thread): the messages it is
 * sent, its reports to `post`.
 */
export function helperReceiver(post: (r: FilePassReport, transfer: Transferable[]) => void, now: () => number): (m: HelperMessage) => void {
  let file: ArrivingFile | null = null;
  return (m) => {
    if ('job' in m) {
      // Pieces walked past go back to the worker, to be read into again.
      const arriving = new ArrivingFile(m.job.size, true);
      file = arriving;
      void passOverFile(m.job, arriving, post, now, undefined, (to) => arriving.passed(to));
    } else if ('piece' in m) file?.push(m.piece);
    else file?.fail(new Error(m.failed));
  };
}
