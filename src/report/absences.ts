/**
 * The times a port's adapter was away: each from a stop (a "device lost", live or recorded) to
 * the port's next data with a time, or, while none has come, to now. The doctor keeps one a
 * port as it is fed; a recording's are walked from its chunks (`recordedAbsences`): the one rule
 * for both, so the doctor and the report say the same.
 */

/** A port's absences so far. */
export interface Absences {
  /** Where the absence going on began (NaN: none). */
  fromUs: number;
  /** Absences over, their time in all, and where the first began (NaN: none yet). */
  count: number;
  totalUs: number;
  firstUs: number;
}

/** None yet. */
export function noAbsences(): Absences {
  return { fromUs: Number.NaN, count: 0, totalUs: 0, firstUs: Number.NaN };
}

/** The port stopped at `timeUs` (a stop without a time is left out; a second one before data changes nothing). */
export function absenceStarts(a: Absences, timeUs: number): void {
  if (Number.isFinite(timeUs) && Number.isNaN(a.fromUs)) a.fromUs = timeUs;
}

/** Data came at `timeUs`: the absence going on ends there. */
export function absenceEnds(a: Absences, timeUs: number): void {
  if (Number.isNaN(a.fromUs) || !Number.isFinite(timeUs)) return;
  a.count++;
  a.totalUs += Math.max(0, timeUs - a.fromUs);
  if (Number.isNaN(a.firstUs)) a.firstUs = a.fromUs;
  a.fromUs = Number.NaN;
}

/** The absences up to `nowUs`, the one going on counted to there. */
export function absencesUntil(a: Absences, nowUs: number): Omit<Absences, 'fromUs'> {
  const open = Number.isNaN(a.fromUs) ? null : a.fromUs;
  if (open === null) return { count: a.count, totalUs: a.totalUs, firstUs: a.firstUs };
  return { count: a.count + 1, totalUs: a.totalUs + Math.max(0, nowUs - open), firstUs: Number.isNaN(a.firstUs) ? open : a.firstUs };
}
