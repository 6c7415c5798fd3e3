/**
 * A long capture's replay pass on two cores, overview first: as soon as the file's start and end
 * are read, its ports are decoded straight from the file (replay-file-pass.ts) in two halves,
 * the first half in this worker and the later half in a helper worker, and the overview is drawn
 * from both as they go. The file is read once, a piece at a time, each piece walked by this
 * worker's half and then by the helper's (readInPieces); the helper's half keeps the capture as
 * it walks it (`keptCapture`), and hands it over at the end without a copy, so that it plays as
 * soon as both halves are done. A file that does not prove intact is read again and parsed
 * (salvaged) as any other.
 *
 * The halves count only for a capture found intact (or cut off inside its last record, where
 * both halves found the file ending), on the same span, with every checkpoint on the chunk the
 * capture's own order puts it (`checkpointChunks`) and with the capture's chunk and byte
 * counts. A half that fails or disagrees is decoded again from the capture, here; the overview
 * and seeks are then exactly the one-worker pass's.
 */
import type { Capture, ParsedCapture } from '../../capture/model.js';
import { captureTimesInOrder, seedChunkFacts } from '../../capture/facts.js';
import { seedCaptureSpan } from '../../report/capture-span.js';
import type { Clock } from '../host.js';
import { addOverviews } from './overview.js';
import { PieceReader, type ReadableFile } from './piece-reader.js';
import type { Overview } from '../protocol.js';
import { HelperRun, type PassHelperMaker, inThisWorker } from './replay-helper.js';
import type { ExpectedSize } from './replay-preview.js';
import { CHECKPOINT_US, type Checkpoint, type OverviewPass, ReplayPass, checkpointDue } from './replay-pass.js';

/**
 * Where the replay pass's checkpoints fall in `capture` (its rule, `checkpointDue`, from
 * `originUs`), and the latest arrival fed before each.
 */
export function checkpointChunks(capture: Capture, originUs: number): { chunk: number; fedUntilUs: number }[] {
  const out: { chunk: number; fedUntilUs: number }[] = [];
  const times = capture.chunkTimesUs;
  if (captureTimesInOrder(capture)) {
    // Each is the first chunk at or after the due time, and the latest before it the one before.
    let next = originUs + CHECKPOINT_US;
    for (let from = 0; ; ) {
      let lo = from;
      let hi = times.length;
      while (lo < hi) {
        const mid = (lo + hi) >>> 1;
        if ((times[mid] ?? Number.NaN) >= next) hi = mid;
        else lo = mid + 1;
      }
      if (lo === times.length) return out;
      out.push({ chunk: lo, fedUntilUs: lo === 0 ? Number.NEGATIVE_INFINITY : (times[lo - 1] ?? Number.NaN) });
      next = checkpointDue(next, times[lo] ?? Number.NaN);
      from = lo + 1;
    }
  }
  // The next due time and the latest arrival, in a typed array (spanOf says why: a cold pass).
  const at = new Float64Array([originUs + CHECKPOINT_US, Number.NEGATIVE_INFINITY]);
  for (let i = 0; i < times.length; i++) {
    const t = times[i] ?? Number.NaN;
    // Only a chunk at or past the due time can get one (a NaN time never does).
    if (t >= (at[0] ?? Number.NaN)) {
      out.push({ chunk: i, fedUntilUs: at[1] ?? Number.NaN });
      at[0] = checkpointDue(at[0] ?? Number.NaN, t);
    }
    if (t > (at[1] ?? Number.NaN)) at[1] = t;
  }
  return out;
}

export class SplitPass implements OverviewPass {
  /** The file passes still counted. */
  #runs: HelperRun[];
  /** Ports decoded here from the capture: those of a pass that failed or disagreed, and any no pass has. */
  readonly #parts: ReplayPass[] = [];
  /** Ports whose pass was dropped before the capture was read: decoded from it once it is. */
  #orphans: number[] = [];
  #capture: Capture | null = null;
  #truth: { chunk: number; fedUntilUs: number }[] = [];
  /** Checkpoints of each run found where the capture puts them. */
  readonly #matched = new Map<HelperRun, number>();

  /**
   * @param runs file passes on disjoint ports, on the same span (`originUs`, `endUs`) and resolution
   * @param wake called when a run has reported (the replay draws on, and steps what is left)
   */
  constructor(
    runs: HelperRun[],
    readonly resolution: 'auto' | 1024 | 2048,
    readonly originUs: number,
    readonly endUs: number,
    wake: () => void,
  ) {
    this.#runs = runs;
    for (const run of runs) {
      this.#matched.set(run, 0);
      run.onReport = () => {
        this.#check();
        wake();
      };
    }
  }

  /**
   * The capture read whole: the runs count if it is intact and on their span; every port of
   * `ports` no run decodes (or that of a run dropped) is decoded from it here.
   */
  adopt(capture: Capture, ports: readonly number[], span: { startUs: number; endUs: number }): void {
    this.#capture = capture;
    if (!this.#intactAsWalked(capture) || span.startUs !== this.originUs || span.endUs !== this.endUs) {
      for (const run of this.#runs) this.#drop(run);
    }
    this.#truth = checkpointChunks(capture, this.originUs);
    this.#check();
    const covered = new Set([...this.#runs.flatMap((r) => r.job.ports), ...this.#parts.flatMap((p) => p.ports)]);
    const rest = ports.filter((p) => !covered.has(p) && !this.#orphans.includes(p));
    this.#decodeHere([...this.#orphans, ...rest]);
    this.#orphans = [];
  }

  /**
   * Whether the capture is intact as far as the runs walked: with no issue at all, or (a recording
   * cut off) only the reader's `truncated-record` where every run found the file ending inside one.
   */
  #intactAsWalked(capture: Capture): boolean {
    const [issue, ...more] = capture.issues;
    if (issue === undefined) return this.#runs.every((r) => r.walked.cutAt === undefined);
    return more.length === 0 && issue.kind === 'truncated-record' && this.#runs.every((r) => r.walked.cutAt === issue.offset);
  }

  get done(): boolean {
    return this.#capture !== null && this.#parts.every((p) => p.done) && this.#runs.every((r) => r.done);
  }

  get waiting(): boolean {
    return !this.done && this.#parts.every((p) => p.done);
  }

  step(budgetMs: number, now: () => number): boolean {
    this.#check();
    this.#parts.find((p) => !p.done)?.step(budgetMs, now);
    return this.done;
  }

  #decodeHere(ports: number[]): void {
    const capture = this.#capture;
    if (capture === null) this.#orphans.push(...ports);
    else if (ports.length > 0)
      this.#parts.push(
        new ReplayPass(
          capture,
          [...ports].sort((a, b) => a - b),
          this.resolution,
          this.originUs,
          this.endUs,
        ),
      );
  }

  #drop(run: HelperRun): void {
    run.stop();
    this.#runs = this.#runs.filter((r) => r !== run);
    this.#matched.delete(run);
    this.#decodeHere(run.job.ports);
  }

  /** Drops every run that failed or, once the capture is read, disagrees with it. */
  #check(): void {
    // One that failed (a damaged record, a read that failed) drops all: a damaged port byte puts
    // a record on another port, and what that port's pass decodes is then not the capture.
    if (this.#runs.some((r) => r.failed !== null)) {
      for (const run of [...this.#runs]) this.#drop(run);
      return;
    }
    for (const run of [...this.#runs]) {
      if (this.#capture === null) continue;
      let k = this.#matched.get(run) ?? 0;
      const truth = this.#truth;
      let agrees = true;
      for (; agrees && k < run.checkpoints.length; k++) {
        const a = run.checkpoints[k];
        const b = truth[k];
        agrees = a !== undefined && b !== undefined && a.chunk === b.chunk && a.fedUntilUs === b.fedUntilUs;
      }
      this.#matched.set(run, k);
      if (agrees && run.done) agrees = k === truth.length && walkedAll(run, this.#capture);
      if (!agrees) this.#drop(run);
    }
  }

  /**
   * Whether `overview()` would be complete, without making it (adding the halves' overviews up
   * is a pass over their bins, worth making only when it is sent): as addOverviews judges it,
   * complete when every part is.
   */
  get overviewComplete(): boolean {
    const parts = this.#runs.length + this.#parts.length;
    return (
      parts > 0 && this.#orphans.length === 0 && this.#runs.every((r) => r.overview?.complete === true) && this.#parts.every((p) => p.done)
    );
  }

  overview(): Overview {
    const parts = [...this.#runs.map((r) => r.overview ?? addOverviews([], this.originUs)), ...this.#parts.map((p) => p.overview())];
    if (this.#orphans.length > 0) parts.push(addOverviews([], this.originUs));
    return addOverviews(parts, this.originUs);
  }

  /**
   * The latest checkpoint every port has (a run's only once found where the capture puts it) that
   * a replay at `targetUs` may start from, `historyUs` before it at least.
   */
  checkpointFor(targetUs: number, historyUs: number): Checkpoint | undefined {
    if (this.#capture === null) return undefined;
    let count = this.#truth.length;
    for (const p of this.#parts) count = Math.min(count, p.checkpoints.length);
    for (const run of this.#runs) count = Math.min(count, this.#matched.get(run) ?? 0);
    const before = targetUs - historyUs;
    let lo = 0;
    let hi = count;
    while (lo < hi) {
      const mid = (lo + hi) >>> 1;
      if ((this.#truth[mid]?.fedUntilUs ?? Number.POSITIVE_INFINITY) <= before) lo = mid + 1;
      else hi = mid;
    }
    const k = lo - 1;
    const at = this.#truth[k];
    if (at === undefined) return undefined;
    const ports = new Map<number, Checkpoint['ports'] extends Map<number, infer V> ? V : never>();
    for (const source of [...this.#runs, ...this.#parts]) for (const [port, cp] of source.checkpoints[k]?.ports ?? []) ports.set(port, cp);
    return { chunk: at.chunk, fedUntilUs: at.fedUntilUs, ports };
  }

  stop(): void {
    for (const run of this.#runs) run.stop();
  }
}

/**
 * The pass of a long capture of two ports or more on two workers (replay-split.ts), started on
 * the file: the first half of the ports here, the later half in a helper; null without a helper.
 */
export function startSplit(
  file: Blob,
  ports: number[],
  span: { originUs: number; endUs: number; resolution: 'auto' | 1024 | 2048 },
  expected: ExpectedSize | undefined,
  helper: PassHelperMaker | undefined,
  clock: Clock,
  sliceBytes: number | undefined,
  wake: () => void,
): { pass: SplitPass; mine: HelperRun; theirs: HelperRun } | null {
  if (ports.length < 2 || helper === undefined) return null;
  const half = ports.length >> 1;
  const { originUs, endUs, resolution } = span;
  const job = (mine: number[], alsoChecked: number[]) => ({
    size: file.size,
    ports: mine,
    alsoChecked,
    resolution,
    originUs,
    endUs,
    sliceBytes,
  });
  // The helper keeps the capture as it walks (the file is not parsed again; the columns are
  // transferred here at the end): this worker's half also reads the file and passes it on.
  const theirs = HelperRun.start(helper, { ...job(ports.slice(half), []), sliceBytes: sliceBytes ?? PIECE_BYTES, keep: true, expected });
  if (theirs === null) return null;
  // This half also checks records on ports the file's start did not show: ours with a damaged
  // port byte, perhaps. It walks in short slices: between them the pieces read go on to the helper.
  // It also finds the capture's chunk facts and span as it walks (`keptCapture`).
  const mine = HelperRun.start(inThisWorker(clock), {
    ...job(
      ports.slice(0, half),
      [...Array(256).keys()].filter((p) => !ports.includes(p)),
    ),
    sliceBytes: sliceBytes ?? HERE_SLICE_BYTES,
    tally: true,
    expected,
  });
  if (mine === null) {
    theirs.stop();
    return null;
  }
  return { pass: new SplitPass([mine, theirs], resolution, originUs, endUs, wake), mine, theirs };
}

/**
 * The capture the helper kept as it walked the file, when it is the capture parseCapture would
 * read: both halves walked the file to its end, this worker's checking every record but those
 * on the helper's ports, the helper checking those and the events; so nothing in it is damaged.
 * It must also hold what this worker's half walked (its chunks and bytes; the checkpoints are
 * checked against it next, `adopt`). Null otherwise: the file is then read and parsed (and
 * salvaged) as any other. The chunk facts and span this worker's half found walking the same
 * records are seeded into it: the replay plays it with no pass over its columns.
 */
export function keptCapture(mine: HelperRun, theirs: HelperRun): ParsedCapture | null {
  const kept = theirs.kept;
  if (kept === null || !mine.done || !theirs.done || mine.failed !== null || theirs.failed !== null) return null;
  if (!walkedAll(mine, kept)) return null;
  // Times stepped over as the capture was kept (bad-time) are not the ones the walk tallied.
  if (mine.facts !== null && kept.issues.length === 0) {
    seedChunkFacts(kept, mine.facts);
    seedCaptureSpan(kept, mine.facts.span);
  }
  return kept;
}

/** Whether a run walked every chunk and byte of `capture` (its counts, as it reported them when done). */
function walkedAll(run: HelperRun, capture: Capture): boolean {
  return run.walked.chunks === capture.chunkEnds.length && run.walked.dataBytes === capture.bytes.length;
}

/**
 * Read at a time from the File: its pieces are what the halves of a split pass are fed, and the
 * helper's slices. The helper gets a piece only once this worker's half has walked it: short
 * pieces start it sooner (longer than any header and this half's slices, as readInPieces needs).
 */
const PIECE_BYTES = 4 << 20;
/**
 * This worker's half walks its pieces this much at a time: between slices, the pieces it has
 * walked past go on to the helper, and more are read.
 */
const HERE_SLICE_BYTES = 1 << 20;
/**
 * Pieces read ahead of where either half has got: enough for either half to walk on while the
 * other is held up, the helper first of all, as it makes room for the capture it keeps (0.35 s
 * of the day capture's open). With 3, this worker's half waited for it there and the helper then
 * waited on and off for pieces: 9.25-10.02 times the baseline against 10.19-10.71 (three
 * interleaved pairs of runs of five opens).
 */
export const AHEAD_PIECES = 6;

/**
 * `file` read once, a piece at a time, a few pieces ahead of where the halves have got. Each
 * piece goes to this worker's half as it arrives, and once that half has walked past it, to the
 * helper's: the piece itself, transferred; the helper gives it back once walked, and the file's
 * next piece is read into it. Neither half copies a piece, and after the first few no piece is
 * new memory (a copy for one half, a slice of its own for the other and a new buffer a piece
 * were each the whole file written into memory the system had to map afresh). The helper walks
 * a little behind this worker, and it has the longer walk anyway (it keeps the capture). A read
 * that fails fails both. Nothing is kept here: the helper's half keeps the capture.
 */
export async function readInPieces(file: ReadableFile, mine: HelperRun, theirs: HelperRun, pieceBytes = PIECE_BYTES): Promise<void> {
  const reader = new PieceReader(file, pieceBytes);
  /** Settles once piece k has gone on to the helper (in order). */
  const handedOver: Promise<void>[] = [];
  try {
    for (let k = 0; ; k++) {
      // Never far ahead: what is read waits in memory. A piece goes on once this half has walked
      // past it, which it can with the next piece read (pieces are longer than its slices and
      // than any header), and the helper never waits for more than a few pieces.
      await handedOver[k - AHEAD_PIECES];
      const from = reader.at;
      const piece = await reader.next(theirs.takeSpare());
      if (piece === null) break;
      const end = reader.at;
      mine.feed(piece);
      handedOver.push(
        (handedOver.at(-1) ?? Promise.resolve()).then(async () => {
          // Transferred once nothing here reads it any more; the helper is never far behind.
          await mine.reached(end);
          await theirs.reached(from - AHEAD_PIECES * pieceBytes);
          theirs.feed(piece);
        }),
      );
    }
    await handedOver.at(-1);
  } catch (error) {
    reader.stop();
    mine.fail(String(error));
    theirs.fail(String(error));
    throw error;
  }
}
