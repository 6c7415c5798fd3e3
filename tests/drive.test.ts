/**
 * Driving a flight controller, the library's part: the built-in scenarios for every receiver,
 * played and written as the worker writes them, decode in SatScope's own decoder to exactly
 * the frames intended; the schedule keeps a silence of over 5 ms before every frame however
 * late its timer wakes, and never sends a backlog.
 */
import { readFileSync } from 'node:fs';
import { describe, expect, it } from 'vitest';
import { SpektrumDecoder } from '../src/decoder/decoder.js';
import { BYTE_TIME_US } from '../src/decoder/spec.js';
import { builtinScenarios, type DriveReceiver } from '../src/drive/builtins.js';
import { DrivePlayer, type DriveWrite } from '../src/drive/player.js';
import { parseDriveScenario, type DriveScenario } from '../src/drive/scenario.js';
import { MIN_SILENCE_US, WriteSchedule } from '../src/drive/schedule.js';
import { Prng } from '../src/simulator/prng.js';

/** Every system and remote with 12 channels, and the smallest layouts (4 channels) of two. */
const RECEIVERS: DriveReceiver[] = [
  ...[0x01, 0x12, 0xa2, 0xb2].flatMap((system) => (['internal', 'external'] as const).map((remote) => ({ system, remote, channels: 12 }))),
  { system: 0x01, remote: 'external', channels: 4 },
  { system: 0xb2, remote: 'internal', channels: 4 },
];

/** The writes' bytes on one line, each byte at its write's time plus its place at 115200 baud. */
function line(writes: readonly DriveWrite[]): { bytes: Uint8Array; times: Float64Array } {
  const n = writes.reduce((a, w) => a + w.bytes.length, 0);
  const bytes = new Uint8Array(n);
  const times = new Float64Array(n);
  let k = 0;
  for (const w of writes) {
    bytes.set(w.bytes, k);
    for (let i = 0; i < w.bytes.length; i++) times[k + i] = w.atUs + i * BYTE_TIME_US;
    k += w.bytes.length;
  }
  return { bytes, times };
}

/** Decodes `writes` and checks every frame against what was sent: returns how many intended frames were not read. */
function expectExact(scenario: DriveScenario, writes: readonly DriveWrite[]): number {
  const sent = new Map(writes.filter((w) => w.frame !== null).map((w) => [w.atUs, w]));
  const { bytes, times } = line(writes);
  const decoder = new SpektrumDecoder();
  decoder.push(bytes, times);
  decoder.end();
  let read = 0;
  for (let f = decoder.next(); f; f = decoder.next()) {
    const w = sent.get(f.timeUs);
    const at = `${scenario.name} at ${(f.timeUs / 1e3).toFixed(1)} ms`;
    expect(w, `${at}: a frame that was not sent`).toBeDefined();
    const truth = w?.frame;
    expect(truth?.damage ?? null, at).toBeNull();
    expect(Array.from(f.bytes), at).toEqual(Array.from(w?.bytes ?? []));
    const channels = Array.from({ length: f.count }, (_, i) => ({ id: f.ids[i], pos: f.positions[i] }));
    expect(channels, at).toEqual(truth?.channels);
    expect(f.resolution, at).toBe(truth?.resolution);
    read++;
  }
  return writes.filter((w) => w.frame !== null && w.frame.damage === null).length - read;
}

describe('drive scenarios', () => {
  it('the example in docs/drive.md is a scenario, and plays as it says', () => {
    const doc = readFileSync(new URL('../docs/drive.md', import.meta.url), 'utf8');
    const json = /```json\n([\s\S]*?)```/.exec(doc)?.[1] ?? '';
    const s = parseDriveScenario(json);
    expect(s.steps.map((st) => st.receiver === undefined)).toEqual([false, true, false]);
    const writes = new DrivePlayer(s).writesUntil(8_000_000);
    // Frames in the first 3 s and the last 3 s, none in the 1.5 s between.
    expect(writes.some((w) => w.atUs > 3_000_000 && w.atUs < 4_500_000)).toBe(false);
    expect(writes.filter((w) => w.atUs >= 4_500_000).length).toBeGreaterThan(250);
  });

  it('every built-in scenario for every receiver decodes to exactly the frames sent', () => {
    let scenarios = 0;
    for (const rx of RECEIVERS) {
      for (const s of builtinScenarios(rx)) {
        // Each one survives a round trip through its shared form (JSON).
        const scenario = parseDriveScenario(JSON.stringify(s));
        const player = new DrivePlayer(scenario);
        const writes = player.writesUntil(Number.POSITIVE_INFINITY);
        expect(player.done).toBe(true);
        // A frame not read: only the few a change of format costs the decoder to follow, and
        // those next to damage (the README's claim: the damage plus one frame).
        const changes = scenario.steps.length - 1;
        const damage = writes.filter((w) => w.frame === null || w.frame.damage !== null).length;
        const missing = expectExact(scenario, writes);
        expect(missing, `${scenario.name} for ${JSON.stringify(rx)}`).toBeLessThanOrEqual(3 * changes + 2 * damage);
        if (damage === 0 && changes === 0) expect(missing, `${scenario.name} for ${JSON.stringify(rx)}`).toBe(0);
        scenarios++;
      }
    }
    expect(scenarios).toBe(RECEIVERS.length * 11);
  });

  it('gives the same writes however the clock asks for them', () => {
    const [sweep] = builtinScenarios({ system: 0xb2, remote: 'internal', channels: 12 });
    const whole = new DrivePlayer(sweep as DriveScenario).writesUntil(Number.POSITIVE_INFINITY);
    const player = new DrivePlayer(sweep as DriveScenario);
    const rng = new Prng(5);
    const pieces: DriveWrite[] = [];
    for (let t = 0; !player.done; t += rng.uniform(0, 40_000)) pieces.push(...player.writesUntil(t));
    expect(pieces.map((w) => [w.atUs, Array.from(w.bytes)])).toEqual(whole.map((w) => [w.atUs, Array.from(w.bytes)]));
  });

  it('holds a channel where the user puts it, and never lets the throttle past its ceiling', () => {
    const [steps] = builtinScenarios({ system: 0xb2, remote: 'internal', channels: 7 }).filter((s) => s.name === 'steps');
    const player = new DrivePlayer(steps as DriveScenario, { throttleCeilingPercent: 20 });
    player.setChannel(2, 50);
    const writes = player.writesUntil(Number.POSITIVE_INFINITY);
    const of = (id: number) => writes.flatMap((w) => w.frame?.channels.filter((c) => c.id === id).map((c) => c.pos) ?? []);
    // 2048 mode: +20 % is 1024 + 0.2 × 2048 / 3, +50 % 1024 + 0.5 × 2048 / 3.
    expect(Math.max(...of(0))).toBe(Math.round(1024 + (20 * 2048) / 300));
    expect(new Set(of(2))).toEqual(new Set([Math.round(1024 + (50 * 2048) / 300)]));
  });

  it('refuses a scenario it cannot play, saying where', () => {
    expect(() => parseDriveScenario('{')).toThrow(/JSON/);
    expect(() => parseDriveScenario({ name: 'x', title: 't', steps: [] })).toThrow(/steps/);
    expect(() => parseDriveScenario({ name: 'x', title: 't', steps: [{ note: 'n', durationUs: -1 }] })).toThrow(/step 1: durationUs/);
    expect(() =>
      parseDriveScenario({ name: 'x', title: 't', steps: [{ note: 'n', durationUs: 1e6, receiver: { system: 0x33 } }] }),
    ).toThrow(/step 1: .*system/);
    expect(() =>
      parseDriveScenario({ name: 'x', title: 't', steps: [{ note: 'n', durationUs: 1e6, receiver: { system: 0x01, xplus: 2 } }] }),
    ).toThrow(/X-Plus/);
  });
});

const ONE_HOUR = {
  name: 'hour',
  title: 'An hour of DSMX 11 ms.',
  steps: [{ note: 'on', durationUs: 3600e6, receiver: { system: 0xb2, remote: 'internal', channels: 8 } }],
};

describe('the write schedule', () => {
  /** Runs `scenario` through a schedule whose timer wakes `lateUs()` after it asked. */
  function run(scenario: DriveScenario, lateUs: () => number): { written: { at: number; w: DriveWrite }[]; schedule: WriteSchedule } {
    const schedule = new WriteSchedule(new DrivePlayer(scenario));
    const written: { at: number; w: DriveWrite }[] = [];
    let now = 0;
    for (;;) {
      const due = schedule.nextDueUs();
      if (Number.isNaN(due)) break;
      now = Math.max(now, due) + lateUs();
      for (let w = schedule.take(now); w !== null; w = schedule.take(now)) written.push({ at: now, w });
    }
    return { written, schedule };
  }

  it('on time: every frame written when due, the period exact', () => {
    const [sweep] = builtinScenarios({ system: 0xb2, remote: 'internal', channels: 12 });
    const { written, schedule } = run(sweep as DriveScenario, () => 0);
    const s = schedule.stats;
    expect(s).toMatchObject({ skipped: 0, delayed: 0 });
    expect(s.frames).toBe(written.length);
    // Percentiles are told to the 0.1 ms bin.
    expect(Math.abs((s.interval?.p50 ?? 0) - 11_000)).toBeLessThanOrEqual(100);
    expect(s.interval?.max).toBeLessThan(11_100);
  });

  it('late and jittery: a silence of over 5 ms before every frame, no backlog, what was skipped counted', () => {
    for (const name of ['sweep', 'damage', 'period-switch'] as const) {
      const scenario = builtinScenarios({ system: 0xb2, remote: 'external', channels: 12 }).find((s) => s.name === name) as DriveScenario;
      const rng = new Prng(11);
      // A timer that wakes 0–4 ms late, and now and then 30 ms (a busy worker).
      const { written, schedule } = run(scenario, () => (rng.chance(0.02) ? 30_000 : rng.uniform(0, 4_000)));
      const frames = written.filter((x) => x.w.frame !== null);
      for (let i = 1; i < frames.length; i++) {
        const prev = frames[i - 1] as { at: number; w: DriveWrite };
        const silence = (frames[i] as { at: number }).at - (prev.at + prev.w.bytes.length * BYTE_TIME_US);
        expect(silence, `${name}: frame ${i}`).toBeGreaterThanOrEqual(MIN_SILENCE_US);
      }
      const s = schedule.stats;
      expect(s.minSilenceUs).toBeGreaterThanOrEqual(MIN_SILENCE_US);
      expect(s.skipped, name).toBeGreaterThan(0);
      // Every frame the player made was written or counted as skipped.
      const made = new DrivePlayer(scenario).writesUntil(Number.POSITIVE_INFINITY).filter((w) => w.frame !== null).length;
      expect(s.frames + s.skipped, name).toBe(made);
      // What was written still decodes to exactly the frames it carried.
      expect(
        expectExact(
          scenario,
          frames.map((x) => ({ ...x.w, atUs: x.at })),
        ),
      ).toBeLessThanOrEqual(3 * (scenario.steps.length - 1) + 3 * s.skipped);
    }
  });

  it('a writer that slept an hour skips what fell due, a second at a time, and sends the newest frame', () => {
    const player = new DrivePlayer(parseDriveScenario(JSON.stringify(ONE_HOUR)));
    const schedule = new WriteSchedule(player);
    expect(schedule.take(1_000)?.frame).not.toBeNull();
    const w = schedule.take(3_000e6);
    expect(w?.frame).not.toBeNull();
    expect(w?.atUs).toBeGreaterThan(3_000e6 - 11_000);
    expect(schedule.stats.skipped).toBeGreaterThan(270_000);
  });
});
