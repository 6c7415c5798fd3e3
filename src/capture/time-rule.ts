/**
 * The rule every capture's times go through as it is read: a time that jumps is damage, told
 * once and stepped over, and every byte is kept. Every reader applies it (the salvaging reader,
 * the reading in parts, the capture kept from a walk, the Saleae import), so every surface that
 * reads a capture (the CLI, the report, the doctor, the page's replay) sees the same times, and
 * nothing downstream (series, link monitor, doctor) meets a time that could make its cost follow
 * the span of the times instead of the data.
 *
 * A time is in line when it is a finite number no larger than `TIME_MAX_US` and follows the last
 * time in line: no more than `TIME_BACK_TOLERANCE_US` before it, no more than `TIME_MAX_GAP_US`
 * after it. One that is not is judged with the next time in line after it:
 * - the next one follows the last time in line, not it: a single wrong time (a spike), dated at
 *   the next time in line (its bytes came no later: a burst, never a gap);
 * - the next one follows it and not the last time in line: the clock stepped; it and every time
 *   after it are moved by the same amount so that the stream goes on from the last time in line
 *   (what happened in the step cannot be known, so no gap is made up for it);
 * - a time in line whose next time follows the last time in line but not it is a spike too.
 * Times after the last one in line take its time; a run with none in line is untimed (NaN).
 * Negative times are times (a logic analyser's pre-trigger bytes): only a jump is damage.
 */
import type { Capture, CaptureEvent, CaptureIssue, CaptureTiming } from './model.js';

/**
 * How far a time may go back and still be in line: a recording's ports share one clock, and
 * their chunks reach the recorder a little out of order.
 */
export const TIME_BACK_TOLERANCE_US = 100_000;

/**
 * The longest forward jump that is a gap in the stream (a receiver unplugged, a recording left
 * running), one day: no session pauses longer, and a clock that leaps further is broken.
 */
export const TIME_MAX_GAP_US = 86_400_000_000;

/** The largest time a clock may give, in µs (about 142 years): beyond it a double no longer holds whole µs. */
export const TIME_MAX_US = 2 ** 52;

/** A time any clock could give. */
function plausible(t: number): boolean {
  return t >= -TIME_MAX_US && t <= TIME_MAX_US;
}

/** Whether `t` follows `last` (both plausible). */
function follows(last: number, t: number): boolean {
  return t >= last - TIME_BACK_TOLERANCE_US && t <= last + TIME_MAX_GAP_US;
}

/**
 * Whether the time `t` needs no stepping over after `last`, the time before it (NaN: `t` is the
 * first): a walk over a file's records that finds every time so can play them as recorded.
 */
export function timeInLine(last: number, t: number): boolean {
  return plausible(t) && (Number.isNaN(last) || follows(last, t));
}

/** What the rule did to one run of times. */
interface RunDamage {
  /** Times that were stepped over (dated at the time before them), and the first of them: where, and what it said. */
  spikes: number;
  firstSpike: number;
  firstSpikeUs: number;
  firstSpikeAfterUs: number;
  /** Steps of the clock, and the first: where, by how much. */
  steps: number;
  firstStep: number;
  firstStepUs: number;
  /** No time in the run was in line: it is untimed now. */
  untimed: boolean;
}

/**
 * Whether every time of `times[from, to)` is plausible and follows the one before it: then the
 * rule changes none (each is in line, and so is the next after it). A recording's times are, and
 * this tight pass over them is what reading it costs.
 */
function allInLine(times: Float64Array, from: number, to: number): boolean {
  if (from === to) return true;
  let last = times[from] ?? NaN;
  if (!plausible(last)) return false;
  for (let i = from + 1; i < to; i++) {
    const t = times[i] as number;
    if (!(t >= last - TIME_BACK_TOLERANCE_US && t <= last + TIME_MAX_GAP_US && t <= TIME_MAX_US && t >= -TIME_MAX_US)) return false;
    last = t;
  }
  return true;
}

/** The rule over `times[from, to)`, in place. */
function stepOverRun(times: Float64Array, from: number, to: number): RunDamage {
  const d: RunDamage = {
    spikes: 0,
    firstSpike: -1,
    firstSpikeUs: NaN,
    firstSpikeAfterUs: NaN,
    steps: 0,
    firstStep: -1,
    firstStepUs: NaN,
    untimed: false,
  };
  if (allInLine(times, from, to)) return d;
  let last = NaN;
  let offset = 0;
  /** The next plausible time after `i` (its index), found once for every index: the walk stays linear. */
  let next = from;
  let unknown = 0;
  for (let i = from; i < to; i++) {
    const raw = times[i] ?? NaN;
    let inLine = false;
    if (plausible(raw)) {
      const t = raw + offset;
      if (next <= i) next = i + 1;
      while (next < to && !plausible(times[next] ?? NaN)) next++;
      const hasNext = next < to;
      const n = (times[next] ?? NaN) + offset;
      if (Number.isNaN(last)) inLine = !hasNext || follows(t, n);
      else if (follows(last, t)) inLine = !(hasNext && !follows(t, n) && follows(last, n));
      else if (hasNext && follows(t, n) && !follows(last, n)) {
        if (d.steps++ === 0) {
          d.firstStep = i;
          d.firstStepUs = t - last;
        }
        offset += last - t;
        times[i] = last;
        continue;
      }
      if (inLine) {
        times[i] = t;
        last = t;
        continue;
      }
    } else if (Number.isNaN(raw)) unknown++;
    // Not in line: stepped over, dated below.
    if (d.spikes++ === 0) {
      d.firstSpike = i;
      d.firstSpikeUs = raw;
      d.firstSpikeAfterUs = last;
    }
    times[i] = NaN;
  }
  if (Number.isNaN(last)) {
    // Nothing in line: an untimed run (NaN all through) is no damage; times that could not be are.
    d.untimed = true;
    if (unknown === to - from) d.spikes = 0;
    return d;
  }
  // A time stepped over is dated at the next time in line: its bytes came no later than the
  // next chunk's, so they read as a burst of delivery, never as a gap the link did not have.
  // Those after the last time in line take that time.
  let after = last;
  for (let i = to - 1; i >= from; i--) {
    const t = times[i] ?? NaN;
    if (Number.isNaN(t)) times[i] = after;
    else after = t;
  }
  return d;
}

/** A time for a message: seconds when a clock could say it, else as it is. */
function said(t: number): string {
  if (Number.isNaN(t)) return 'NaN';
  return Number.isFinite(t) && Math.abs(t) < 1e12 ? `${(t / 1e6).toFixed(6)} s` : `${t} µs`;
}

/** A length of time for a message. */
function span(us: number): string {
  const s = Math.abs(us) / 1e6;
  const amount = s >= 86_400 ? `${(s / 86_400).toPrecision(3)} days` : s >= 3600 ? `${(s / 3600).toFixed(1)} h` : `${s.toFixed(3)} s`;
  return `${amount} ${us < 0 ? 'back' : 'forward'}`;
}

/** The issues for one run's damage: `what` names its times ("chunk", "byte"), `where` the run ("", "port 1: "), `at` where index `i`'s bytes start. */
function issuesOf(d: RunDamage, what: string, where: string, total: number, at: (i: number) => number): CaptureIssue[] {
  const issues: CaptureIssue[] = [];
  if (d.spikes > 0) {
    const first = d.firstSpikeUs;
    const why = Number.isNaN(d.firstSpikeAfterUs) ? 'before any time in line' : `after ${said(d.firstSpikeAfterUs)}`;
    issues.push({
      kind: 'bad-time',
      offset: at(d.firstSpike),
      length: 0,
      message:
        `${where}${d.spikes} of ${total} ${what} times jump out of line (the first, ${what} ${d.firstSpike}, says ${said(first)} ${why}); ` +
        (d.untimed ? 'no time holds, so it is read untimed' : 'each is dated at the next time in line') +
        '; every byte is kept',
    });
  }
  if (d.steps > 0) {
    issues.push({
      kind: 'bad-time',
      offset: at(d.firstStep),
      length: 0,
      message:
        `${where}the clock steps ${d.steps === 1 ? 'once' : `${d.steps} times`} (the first, at ${what} ${d.firstStep}, ${span(d.firstStepUs)}): ` +
        'the times after a step are moved to go on from the time before it (what happened in the step is not known); every byte is kept',
    });
  }
  return issues;
}

/**
 * Events whose times do not fit the chunks around them (after the chunk before, by the rule;
 * no later than the chunk after, within the tolerance) are dated at the chunk before them (or,
 * with none, the one after). An event of unknown time (NaN) stays unknown.
 */
function stepOverEvents(
  events: readonly CaptureEvent[],
  times: Float64Array,
): { events: readonly CaptureEvent[]; bad: number; first: number } {
  let out: CaptureEvent[] | null = null;
  let bad = 0;
  let first = -1;
  events.forEach((e, k) => {
    if (Number.isNaN(e.timeUs)) return;
    const before = times[e.chunkIndex - 1] ?? NaN;
    const after = times[e.chunkIndex] ?? NaN;
    const fits =
      plausible(e.timeUs) &&
      (Number.isNaN(before) || follows(before, e.timeUs)) &&
      (Number.isNaN(after) || e.timeUs <= after + TIME_BACK_TOLERANCE_US);
    if (fits) return;
    out ??= events.slice();
    out[k] = { ...e, timeUs: Number.isNaN(before) ? after : before };
    if (bad++ === 0) first = k;
  });
  return { events: out ?? events, bad, first };
}

/**
 * `capture` with the rule applied (see above): its time columns are changed in place, and what
 * was stepped over is in its issues (kind `bad-time`). A capture whose times are all in line is
 * returned as it is. Readers call this once, on the capture they made.
 */
export function stepOverBadTimes<C extends Capture>(capture: C): C {
  const { timing, chunkEnds, chunkTimesUs, byteTimesUs } = capture;
  if (timing === 'none') return capture;
  const issues: CaptureIssue[] = [];
  let anyTimed = false;
  let events = capture.events;
  if (timing === 'per-byte' && byteTimesUs !== undefined) {
    // One run a port: each port is one chunk, and its byte times are its own clock.
    let from = 0;
    for (let c = 0; c < chunkEnds.length; c++) {
      const to = chunkEnds[c] ?? from;
      const d = stepOverRun(byteTimesUs, from, to);
      issues.push(...issuesOf(d, 'byte', `port ${capture.chunkPorts[c] ?? 0}: `, to - from, (i) => i));
      if (!d.untimed) anyTimed = true;
      if (to > from) chunkTimesUs[c] = byteTimesUs[to - 1] ?? NaN;
      from = to;
    }
  } else {
    // One run for every port: they share the recorder's clock.
    const d = stepOverRun(chunkTimesUs, 0, chunkTimesUs.length);
    issues.push(...issuesOf(d, 'chunk', '', chunkTimesUs.length, (i) => (i > 0 ? (chunkEnds[i - 1] ?? 0) : 0)));
    anyTimed = !d.untimed;
    const e = stepOverEvents(events, chunkTimesUs);
    if (e.bad > 0) {
      const first = capture.events[e.first];
      issues.push({
        kind: 'bad-time',
        offset: 0,
        length: 0,
        message: `${e.bad} event time(s) do not fit the data around them (the first, "${first?.text ?? ''}", says ${said(first?.timeUs ?? NaN)}): each is dated at the data before it`,
      });
      events = e.events;
    }
  }
  if (issues.length === 0) return capture;
  const newTiming: CaptureTiming = anyTimed ? timing : 'none';
  const repaired: C = { ...capture, timing: newTiming, events, issues: [...capture.issues, ...issues] };
  if (newTiming === 'none' && timing === 'per-byte') {
    chunkTimesUs.fill(NaN);
    delete (repaired as { byteTimesUs?: Float64Array }).byteTimesUs;
  }
  return repaired;
}
