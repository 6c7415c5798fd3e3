/**
 * Grading a flight controller's reading of what Drive sent: which of its channels follows which
 * receiver channel, how far its values are from the spec's (§9: 903 + 0.583 × position µs in
 * 2048 mode, 1.166 in 1024), how long a step takes to reach it, and when it reports the receiver
 * lost and back, and whether it holds still while nothing sent moves (a frame it misreads, an
 * empty slot, X-Plus, a VTX frame, damage, a lying system byte or a format switch, shows as a
 * jump the transmitter never sent). The readings are the flight controller's own (MSP_RC and its arming-disable
 * flags, or MAVLink RC_CHANNELS and its failsafe state) on the player's clock; what cannot be
 * told from them is said so, never guessed.
 */
import { CHANNEL_NAMES, servoToMicros } from '../decoder/spec.js';
import type { DriveStepTime, DriveWrite } from './player.js';

/** What the flight controller said at a moment (µs on the player's clock). */
export interface FcReading {
  atUs: number;
  /** Its channels, µs, in its own order. */
  channels: readonly number[];
  /** Whether it reports the receiver lost (RXLOSS, RC_LINK, RC failsafe); null when it does not say. */
  rxLoss: boolean | null;
}

/** One graded check. */
export interface DriveCheck {
  id: 'channel-map' | 'values' | 'latency' | 'failsafe' | 'steady';
  /** What the spec or the link needs, with its section. */
  expects: string;
  /** What the flight controller did, measured. */
  found: string;
  verdict: 'pass' | 'fail' | 'unknown';
}

/** A receiver channel's value as sent at each frame: [time of the frame, µs by the spec]. */
type Track = [number, number][];

/** The channels each frame sent, by receiver channel ID (0–11), in time order. */
function tracks(sent: readonly DriveWrite[]): Map<number, Track> {
  const out = new Map<number, Track>();
  for (const w of sent) {
    const f = w.frame;
    if (f === null || f.damage !== null) continue;
    for (const c of f.channels) {
      if (c.id > 11) continue;
      let t = out.get(c.id);
      if (t === undefined) out.set(c.id, (t = []));
      t.push([w.atUs, servoToMicros(c.pos, f.resolution)]);
    }
  }
  return out;
}

/** The value a track had at `atUs` (its last frame at or before it), NaN before its first. */
function valueAt(track: Track, atUs: number): number {
  let lo = 0;
  let hi = track.length - 1;
  if (hi < 0 || (track[0] as [number, number])[0] > atUs) return Number.NaN;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if ((track[mid] as [number, number])[0] <= atUs) lo = mid;
    else hi = mid - 1;
  }
  return (track[lo] as [number, number])[1];
}

function correlation(a: readonly number[], b: readonly number[]): number {
  const n = a.length;
  let ma = 0;
  let mb = 0;
  for (let i = 0; i < n; i++) {
    ma += a[i] as number;
    mb += b[i] as number;
  }
  ma /= n;
  mb /= n;
  let sab = 0;
  let saa = 0;
  let sbb = 0;
  for (let i = 0; i < n; i++) {
    const x = (a[i] as number) - ma;
    const y = (b[i] as number) - mb;
    sab += x * y;
    saa += x * x;
    sbb += y * y;
  }
  return saa > 0 && sbb > 0 ? sab / Math.sqrt(saa * sbb) : Number.NaN;
}

const median = (xs: number[]): number => {
  const s = xs.slice().sort((a, b) => a - b);
  return s.length === 0 ? Number.NaN : (s[(s.length - 1) >> 1] as number);
};

/** The longest delay a channel is looked for at when its order is found, and the step between the delays tried. */
const MAX_LAG_US = 300_000;
const LAG_STEP_US = 25_000;

/** The result of grading: each check, and the map found (the flight controller's channel index → the receiver channel ID it follows). */
export interface DriveGrade {
  checks: DriveCheck[];
  map: Map<number, number>;
}

/**
 * Grades `readings` against `sent`. The flight controller is expected to read the receiver's
 * channels 0–3 (throttle, aileron, elevator, rudder) as its throttle, roll, pitch and yaw in
 * the order `expectedMap` gives (its channel index → receiver channel ID; Betaflight and iNav
 * with `map TAER1234`: roll 1, pitch 2, yaw 3, throttle 0).
 */
export function gradeDrive(
  sent: readonly DriveWrite[],
  readings: readonly FcReading[],
  expectedMap: readonly number[] = [1, 2, 3, 0],
  steps: readonly Pick<DriveStepTime, 'note' | 'endUs'>[] = [],
): DriveGrade {
  const byId = tracks(sent);
  const live = readings.filter((r) => r.rxLoss !== true);
  const checks: DriveCheck[] = [];
  // Which receiver channel each of the flight controller's channels follows: the best
  // correlation over the readings while the link was up, among channels that moved.
  const map = new Map<number, number>();
  const fcCount = Math.max(0, ...readings.map((r) => r.channels.length));
  for (let j = 0; j < fcCount; j++) {
    const fc = live.map((r) => r.channels[j] ?? Number.NaN);
    let best = Number.NaN;
    let bestId = -1;
    for (const [id, track] of byId) {
      // At the flight controller's own delay, whatever it is (up to MAX_LAG_US).
      for (let lag = 0; lag <= MAX_LAG_US; lag += LAG_STEP_US) {
        const sentAt = live.map((r) => valueAt(track, r.atUs - lag));
        const ok = sentAt.map((v, i) => Number.isFinite(v) && Number.isFinite(fc[i] as number));
        const c = correlation(
          fc.filter((_, i) => ok[i]),
          sentAt.filter((_, i) => ok[i]),
        );
        if (c > 0.9 && !(c <= best)) {
          best = c;
          bestId = id;
        }
      }
    }
    if (bestId >= 0) map.set(j, bestId);
  }
  const name = (id: number | undefined) => (id === undefined ? 'nothing that moved' : (CHANNEL_NAMES[id] ?? `channel ${id}`));
  // Judged on the channels that followed a stick; one that followed none is said, not failed
  // (a stick the scenario or the user never moved says nothing of the order).
  const wrong = expectedMap
    .map((id, j) => (!map.has(j) || map.get(j) === id ? null : `its channel ${j + 1} follows ${name(map.get(j))}, not ${name(id)}`))
    .filter((x) => x !== null);
  const unseen = expectedMap.filter((_, j) => !map.has(j));
  const still =
    unseen.length > 0 ? ` (${unseen.map((id) => name(id)).join(', ')}: no channel followed ${unseen.length === 1 ? 'it' : 'them'})` : '';
  checks.push({
    id: 'channel-map',
    expects: `Channels 1-4 read as ${expectedMap.map((id) => name(id)).join(', ')} (§8.5: the receiver's channel IDs name them).`,
    found:
      map.size === 0 ? 'No channel followed any stick that moved.' : `${wrong.length === 0 ? 'As expected' : wrong.join('; ')}${still}.`,
    verdict: unseen.length === expectedMap.length ? 'unknown' : wrong.length === 0 ? 'pass' : 'fail',
  });
  // How far its values are from the spec's, over the mapped channels, where the value sent had
  // stood still for `STEADY_US` (a reading of a moving stick measures the latency too).
  const errors: number[] = [];
  for (const [j, id] of map) {
    const track = byId.get(id) as Track;
    for (const r of live) {
      const want = valueAt(track, r.atUs);
      const got = r.channels[j];
      if (Number.isFinite(want) && got !== undefined && steady(track, r.atUs, want)) errors.push(got - want);
    }
  }
  if (errors.length === 0)
    checks.push({ id: 'values', expects: 'Values as §9 converts them.', found: 'No reading to compare.', verdict: 'unknown' });
  else {
    const worst = errors.reduce((a, e) => (Math.abs(e) > Math.abs(a) ? e : a), 0);
    checks.push({
      id: 'values',
      expects: 'Each value as §9 converts it (903 + 0.583 × position µs at 2048, 1.166 at 1024), within 2 µs.',
      found: `Off by ${Math.round(median(errors))} µs (median), ${Math.round(worst)} µs at the most, over ${errors.length} readings.`,
      verdict: Math.abs(worst) <= 2 ? 'pass' : 'fail',
    });
  }
  checks.push(latency(byId, map, live));
  checks.push(failsafe(sent, readings));
  checks.push(steadiness(byId, sent, readings, steps));
  return { checks, map };
}

/** How long a value sent must have stood still for a reading to measure the flight controller's scale. */
const STEADY_US = 200_000;

/** Whether `track` held `value` for the `STEADY_US` before `atUs` (every frame in it within 1 µs). */
function steady(track: Track, atUs: number, value: number): boolean {
  if (!(valueAt(track, atUs - STEADY_US) === value)) return false;
  for (let i = track.length - 1; i >= 0; i--) {
    const [t, v] = track[i] as [number, number];
    if (t > atUs) continue;
    if (t < atUs - STEADY_US) return true;
    if (Math.abs(v - value) > 1) return false;
  }
  return true;
}

/** From a step in a sent channel (over 200 µs from one frame to the next) to the first reading closer to the new value than the old. */
function latency(byId: Map<number, Track>, map: Map<number, number>, live: readonly FcReading[]): DriveCheck {
  const lags: number[] = [];
  for (const [j, id] of map) {
    const track = byId.get(id) as Track;
    for (let i = 1; i < track.length; i++) {
      const [t, v] = track[i] as [number, number];
      const before = (track[i - 1] as [number, number])[1];
      if (Math.abs(v - before) < 200) continue;
      const r = live.find(
        (x) => x.atUs >= t && Math.abs((x.channels[j] ?? Number.NaN) - v) < Math.abs((x.channels[j] ?? Number.NaN) - before),
      );
      if (r !== undefined) lags.push(r.atUs - t);
    }
  }
  const gaps = live.slice(1).map((r, i) => r.atUs - (live[i] as FcReading).atUs);
  const poll = median(gaps);
  const expects = 'A step reaches the flight controller within two frames (44 ms at 22 ms), told to within its reading interval.';
  if (lags.length === 0) return { id: 'latency', expects, found: 'No step was sent and read.', verdict: 'unknown' };
  const ms = (us: number) => `${(us / 1000).toFixed(1)} ms`;
  return {
    id: 'latency',
    expects,
    found: `${lags.length} steps: ${ms(median(lags))} median, ${ms(Math.max(...lags))} at the most (read every ${ms(poll)}, so to within that).`,
    verdict: median(lags) <= 2 * 22_000 + poll ? 'pass' : 'fail',
  };
}

/** Each silence of the sent frames over 100 ms: when the flight controller said the receiver was lost, and back. */
function failsafe(sent: readonly DriveWrite[], readings: readonly FcReading[]): DriveCheck {
  const frames = sent.filter((w) => w.frame !== null).map((w) => w.atUs);
  const said = readings.filter((r) => r.rxLoss !== null);
  const expects =
    "Receiver lost reported within the stack's timeout after frames stop (§7.1: hold, failsafe after 1 s), and back once they return.";
  if (said.length === 0)
    return { id: 'failsafe', expects, found: 'The flight controller does not report its receiver state here.', verdict: 'unknown' };
  const parts: string[] = [];
  let missed = 0;
  if (!said.some((r) => r.rxLoss === false)) {
    return { id: 'failsafe', expects, found: 'It never reported the receiver live: it read none of the frames.', verdict: 'fail' };
  }
  const lastFrame = frames.at(-1) ?? Number.NaN;
  for (let i = 1; i < frames.length; i++) {
    const last = frames[i - 1] as number;
    const next = frames[i] as number;
    if (next - last < 100_000) continue;
    const lost = said.find((r) => r.atUs > last && r.atUs < next && r.rxLoss === true);
    const back = said.find((r) => r.atUs >= next && r.rxLoss === false);
    const gap = `${((next - last) / 1000).toFixed(0)} ms silence`;
    if (lost === undefined) {
      // A silence past a second that it never reported.
      if (next - last >= 1_000_000) missed++;
      parts.push(`${gap}: not reported`);
      continue;
    }
    // Still lost with frames coming for 2 s after the silence: it did not come back.
    if (back === undefined && lastFrame - next >= 2_000_000) missed++;
    parts.push(
      `${gap}: lost after ${((lost.atUs - last) / 1000).toFixed(0)} ms, back ${back === undefined ? 'never' : `after ${((back.atUs - next) / 1000).toFixed(0)} ms`}`,
    );
  }
  if (parts.length === 0) return { id: 'failsafe', expects, found: 'No silence was sent.', verdict: 'unknown' };
  return { id: 'failsafe', expects, found: `${parts.join('; ')}.`, verdict: missed > 0 ? 'fail' : 'pass' };
}

/** A silence between frames this long is a dropout (the flight controller may rightly move). */
const DROPOUT_US = 100_000;
/**
 * Frames that came this long with no silence over `GAP_US` between them (the writer skips a
 * frame when its timer wakes late, and a flight controller may lose one more to a merge): one
 * that reports the receiver lost then rejected them.
 */
const FLOWING_US = 1_000_000;
const GAP_US = 50_000;

/**
 * Readings taken when nothing sent had moved (no channel's value by §9 changed, no dropout) for
 * `STEADY_US` are grouped by the values sent then: each of the flight controller's channels must
 * read one value for one set of values sent, whenever it was sent (before and after a rebind,
 * under either system byte). A reading off its group's usual value by over 2 µs is a value the
 * transmitter never sent (a frame misread). And with frames flowing for `FLOWING_US`, it must
 * not say the receiver is lost.
 */
function steadiness(
  byId: Map<number, Track>,
  sent: readonly DriveWrite[],
  readings: readonly FcReading[],
  steps: readonly Pick<DriveStepTime, 'note' | 'endUs'>[],
): DriveCheck {
  const expects =
    'While nothing sent changes, every channel holds its value and the receiver stays live: §8 frames with empty slots (0xFFFF), X-Plus, VTX or a changing system byte carry no new stick values.';
  // When anything sent moved: a channel came or moved (by more than 1 µs from where it last
  // stood, so a slow sweep counts too), or the frames paused (where they came back).
  const moves: number[] = [];
  for (const track of byId.values()) {
    let stood = Number.NaN;
    for (const [t, v] of track)
      if (!(Math.abs(v - stood) <= 1)) {
        moves.push(t);
        stood = v;
      }
  }
  const frames = sent.filter((w) => w.frame !== null).map((w) => w.atUs);
  const resumed: number[] = [];
  const afterGap: number[] = [];
  for (let i = 1; i < frames.length; i++) {
    const gap = (frames[i] as number) - (frames[i - 1] as number);
    if (gap > DROPOUT_US) resumed.push(frames[i] as number);
    if (gap > GAP_US) afterGap.push(frames[i] as number);
  }
  moves.push(...resumed);
  moves.sort((a, b) => a - b);
  const firstFrame = frames[0] ?? Number.POSITIVE_INFINITY;
  // Frames had been coming at `t` for this long since the last silence of `since` (none missing for DROPOUT_US), or 0.
  const flowingFor = (t: number, since: readonly number[] = resumed): number => {
    const last = lastAtOrBefore(frames, t);
    return t - last > DROPOUT_US ? 0 : t - Math.max(firstFrame, lastAtOrBefore(since, t));
  };
  const where = (t: number) => {
    const note = steps.find((st) => t < st.endUs)?.note;
    return `at ${(t / 1e6).toFixed(1)} s${note === undefined ? '' : ` (${note})`}`;
  };
  // Readings that had nothing move in the STEADY_US before them, frames flowing, by the values sent.
  const groups = new Map<string, FcReading[]>();
  const tracks = [...byId.values()];
  let lostWhileFlowing: FcReading | null = null;
  let lostCount = 0;
  for (const r of readings) {
    const since = lastAtOrBefore(moves, r.atUs);
    const flowing = flowingFor(r.atUs);
    if (r.rxLoss === true && flowingFor(r.atUs, afterGap) >= FLOWING_US) {
      lostCount++;
      lostWhileFlowing ??= r;
    }
    if (!(flowing >= STEADY_US && r.atUs - since >= STEADY_US) || r.rxLoss === true) continue;
    const key = tracks.map((track) => Math.round(valueAt(track, r.atUs) * 10)).join(' ');
    const group = groups.get(key);
    if (group === undefined) groups.set(key, [r]);
    else group.push(r);
  }
  // Each channel's misreadings, by the value read and the value it held: how many, and when first.
  const jumps = new Map<string, { first: number; count: number }>();
  let jumpCount = 0;
  let steadyReadings = 0;
  for (const group of groups.values()) {
    steadyReadings += group.length;
    const width = Math.max(...group.map((r) => r.channels.length));
    for (let j = 0; j < width; j++) {
      const values = group.map((r) => r.channels[j] ?? Number.NaN);
      const usual = mode(values);
      for (const [k, v] of values.entries()) {
        if (!(Math.abs(v - usual) > 2)) continue;
        jumpCount++;
        const key = `its channel ${j + 1} read ${v} µs and ${usual} µs for one value sent`;
        const at = (group[k] as FcReading).atUs;
        const seen = jumps.get(key);
        if (seen === undefined) jumps.set(key, { first: at, count: 1 });
        else {
          seen.count++;
          if (at < seen.first) seen.first = at;
        }
      }
    }
  }
  const findings: string[] = [];
  if (jumpCount > 0) {
    const worst = [...jumps].sort((a, b) => b[1].count - a[1].count).slice(0, 3);
    const told = worst.map(([what, { first, count }]) => `${what} (${count}×, first ${where(first)})`);
    const more = jumps.size > worst.length ? `; and ${jumps.size - worst.length} more` : '';
    findings.push(`${jumpCount} reading${jumpCount === 1 ? '' : 's'} of a value never sent: ${told.join('; ')}${more}`);
  }
  if (lostWhileFlowing !== null)
    findings.push(
      `receiver reported lost ${lostCount} time${lostCount === 1 ? '' : 's'} while frames had come for a second with no gap over ${GAP_US / 1000} ms, first ${where(lostWhileFlowing.atUs)}`,
    );
  if (findings.length > 0) return { id: 'steady', expects, found: `${findings.join('; ')}.`, verdict: 'fail' };
  if (steadyReadings === 0) return { id: 'steady', expects, found: 'Nothing sent stood still long enough to tell.', verdict: 'unknown' };
  return {
    id: 'steady',
    expects,
    found: `Held every channel over ${steadyReadings} readings while nothing sent moved, and never lost the receiver while frames came.`,
    verdict: 'pass',
  };
}

/** The last of the sorted `times` at or before `t`, or -Infinity. */
function lastAtOrBefore(times: readonly number[], t: number): number {
  let lo = 0;
  let hi = times.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if ((times[mid] as number) <= t) lo = mid + 1;
    else hi = mid;
  }
  return lo === 0 ? Number.NEGATIVE_INFINITY : (times[lo - 1] as number);
}

/** The most common value (the first of equals). */
function mode(values: readonly number[]): number {
  const counts = new Map<number, number>();
  let best = Number.NaN;
  let bestCount = 0;
  for (const v of values) {
    const n = (counts.get(v) ?? 0) + 1;
    counts.set(v, n);
    if (n > bestCount) {
      best = v;
      bestCount = n;
    }
  }
  return best;
}
