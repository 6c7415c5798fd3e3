/**
 * Grading a flight controller against what Drive sent, on a fake one that follows Betaflight's
 * documented rules (tests/fake-fc.ts): its channel order found from a sweep, its values against
 * §9's, the time a step takes to reach it, and when it reports the receiver lost and back.
 */
import { describe, expect, it } from 'vitest';
import { builtinScenarios } from '../src/drive/builtins.js';
import { type FcReading, gradeDrive } from '../src/drive/grade.js';
import { DrivePlayer, type DriveWrite } from '../src/drive/player.js';
import type { DriveScenario } from '../src/drive/scenario.js';
import { FakeFc, type FakeFcOptions } from './fake-fc.js';

/** Plays `name` into a fake flight controller, reading it every `pollUs` as MSP would. */
function drive(name: string, fc: FakeFcOptions, pollUs = 20_000): { sent: DriveWrite[]; readings: FcReading[] } {
  const scenario = builtinScenarios({ system: 0xb2, remote: 'internal', channels: 12 }).find((s) => s.name === name) as DriveScenario;
  const sent = new DrivePlayer(scenario).writesUntil(Number.POSITIVE_INFINITY);
  const flight = new FakeFc(fc);
  const readings: FcReading[] = [];
  let k = 0;
  const end = (sent.at(-1)?.atUs ?? 0) + 2_000_000;
  for (let t = 0; t < end; t += pollUs) {
    for (; k < sent.length && (sent[k] as DriveWrite).atUs <= t; k++)
      flight.write((sent[k] as DriveWrite).bytes, (sent[k] as DriveWrite).atUs);
    readings.push(flight.state(t));
  }
  return { sent, readings };
}

const check = (g: ReturnType<typeof gradeDrive>, id: string) => g.checks.find((c) => c.id === id);

describe('grading a flight controller', () => {
  it('finds the channel order from a sweep: right with map TAER1234, wrong with the default AETR1234', () => {
    const right = gradeDrive(...(Object.values(drive('sweep', { resolution: 2048, map: 'TAER1234' })) as [DriveWrite[], FcReading[]]));
    expect(check(right, 'channel-map')?.verdict).toBe('pass');
    expect([...right.map].slice(0, 4)).toEqual([
      [0, 1],
      [1, 2],
      [2, 3],
      [3, 0],
    ]);
    const wrong = gradeDrive(...(Object.values(drive('sweep', { resolution: 2048, map: 'AETR1234' })) as [DriveWrite[], FcReading[]]));
    expect(check(wrong, 'channel-map')).toMatchObject({ verdict: 'fail' });
    expect(check(wrong, 'channel-map')?.found).toMatch(/channel 1 follows Throttle, not Aileron/);
  });

  it("measures Betaflight's scale against §9's: some 57 µs off at full stick", () => {
    const g = gradeDrive(...(Object.values(drive('sweep', { resolution: 2048 })) as [DriveWrite[], FcReading[]]));
    const values = check(g, 'values');
    expect(values?.verdict).toBe('fail');
    const worst = Number(/(-?\d+) µs at the most/.exec(values?.found ?? '')?.[1]);
    expect(Math.abs(worst)).toBeGreaterThan(50);
    expect(Math.abs(worst)).toBeLessThan(62);
  });

  it('times steps to the poll, and the receiver lost and back across the dropouts', () => {
    const steps = gradeDrive(...(Object.values(drive('steps', { resolution: 2048 })) as [DriveWrite[], FcReading[]]));
    const lag = check(steps, 'latency');
    expect(lag?.verdict).toBe('pass');
    const median = Number(/: ([\d.]+) ms median/.exec(lag?.found ?? '')?.[1]);
    expect(median).toBeGreaterThan(0);
    expect(median).toBeLessThanOrEqual(40);
    const drops = gradeDrive(...(Object.values(drive('dropouts', { resolution: 2048 })) as [DriveWrite[], FcReading[]]));
    const fs = check(drops, 'failsafe');
    expect(fs?.verdict).toBe('pass');
    // 1.2 s and 5 s silences: lost after about Betaflight's 100 ms (to the 20 ms poll).
    const after = [...(fs?.found ?? '').matchAll(/lost after (\d+) ms/g)].map((m) => Number(m[1]));
    expect(after.length).toBeGreaterThanOrEqual(2);
    for (const a of after) expect(a).toBeGreaterThanOrEqual(100);
    for (const a of after) expect(a).toBeLessThanOrEqual(130);
  });

  it('says unknown where the flight controller tells nothing', () => {
    const { sent, readings } = drive('dropouts', { resolution: 2048 });
    const g = gradeDrive(
      sent,
      readings.map((r) => ({ ...r, rxLoss: null })),
    );
    expect(check(g, 'failsafe')?.verdict).toBe('unknown');
    expect(gradeDrive(sent, []).checks.map((c) => c.verdict)).toEqual(['unknown', 'unknown', 'unknown', 'unknown']);
  });
});
