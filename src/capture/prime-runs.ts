/**
 * A record walk's per-run method (`records(bytes, view, from, to)`, as record-walk.ts's `runs`
 * calls it: CaptureBuilder's, RecordTally's) called on no records a dozen times, from its
 * class's constructor, before its first real run.
 *
 * That first run is a whole piece of the file (about 140,000 records), and the engine compiles
 * the loop while the run is still in it. The stores after the loop have no type feedback yet
 * (an engine keeps a function's feedback only after a few calls), so the compiled code leaves at
 * them at the end of every later run and each starts again in the interpreter. Run empty first,
 * the stores have their feedback when the loop is compiled, and the code stays (bench/README.md).
 */

/** A walk's per-run method: records one after the other, `bytes[from, to)`. */
export type RecordRuns = (bytes: Uint8Array, view: DataView, from: number, to: number) => void;

/** More calls than an engine waits for before it keeps a function's type feedback. */
const PRIMING_CALLS = 12;

/** Calls `run` on an empty range PRIMING_CALLS times: it must change nothing when from === to. */
export function primeRuns(run: RecordRuns): void {
  const none = new Uint8Array(0);
  const view = new DataView(none.buffer);
  for (let k = 0; k < PRIMING_CALLS; k++) run(none, view, 0, 0);
}
