/**
 * The helper's half of a long capture's replay pass (replay-split.ts): some of its ports decoded
 * straight from the file's records as the file is read a slice at a time, while the worker reads
 * the whole file and decodes the others. It sends what the worker merges: the overview of its
 * ports so far and the checkpoints made since the last report, then the same at the end with the
 * count of chunks and bytes it walked, which the worker checks against the capture it read.
 */
import { type SlicedFile, walkDataRecords } from '../capture/index.js';
import type { Overview } from './protocol.js';
import { type Checkpoint, ReplayPass } from './replay-pass.js';

/** What the helper decodes: `ports` of `file`, on the span the worker's pass uses. */
export interface FilePassJob {
  /** A File (Blob) in the browser. */
  file: SlicedFile;
  ports: number[];
  /**
   * Records on these ports have their CRC checked too (besides those of `ports`): ports the file's
   * start did not show, whose records may be ours with a damaged port byte.
   */
  alsoChecked: number[];
  /** Read at a time (tests; default walkDataRecords's). */
  sliceBytes?: number | undefined;
  resolution: 'auto' | 1024 | 2048;
  originUs: number;
  endUs: number;
}

export type FilePassReport =
  | { type: 'progress'; overview: Overview; checkpoints: Checkpoint[] }
  | { type: 'done'; overview: Overview; checkpoints: Checkpoint[]; chunks: number; dataBytes: number }
  | { type: 'failed'; why: string };

/** A report at most this often: the worker draws the overview about once a second. */
const PROGRESS_MS = 250;

/**
 * Decodes `job`, reporting as it goes; `stopped` is asked between slices (true: it ends quietly).
 * Never throws: whatever goes wrong is a `failed` report, and the worker decodes those ports itself.
 */
export async function passOverFile(
  job: FilePassJob,
  report: (r: FilePassReport, transfer: Transferable[]) => void,
  now: () => number,
  stopped: () => boolean = () => false,
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
    const { ports, alsoChecked, sliceBytes } = job;
    // Every record decoded here is checked: nothing from a damaged one is ever shown.
    const checked = (port: number): boolean => ports.includes(port) || alsoChecked.includes(port);
    const goOn = (): boolean => {
      if (stopped()) return false;
      if (now() - lastMs >= PROGRESS_MS) {
        lastMs = now();
        const r = news();
        report({ type: 'progress', ...r }, transfer(r.overview));
      }
      return true;
    };
    const walked = await walkDataRecords(job.file, (bytes, start, end, timeUs, port) => pass.feed(bytes, start, end, timeUs, port), {
      goOn,
      checked,
      ...(sliceBytes === undefined ? {} : { sliceBytes }),
    });
    if (walked === null) return;
    pass.finish();
    const r = news();
    report({ type: 'done', ...r, ...walked }, transfer(r.overview));
  } catch (error) {
    report({ type: 'failed', why: error instanceof Error ? error.message : String(error) }, []);
  }
}
